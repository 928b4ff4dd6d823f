"""A small PLY reader (ascii and binary little/big endian; vertex x y z and face lists)
so the Blender tests build meshes with from_pydata instead of version-specific import
operators. bpy-free."""

import struct

_TYPES = {
    "char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h",
    "ushort": "H", "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I",
    "float": "f", "float32": "f", "double": "d", "float64": "d",
}


def read_ply(path):
    """Returns (vertices [(x, y, z)], faces [(i, j, k, ...)])."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise ValueError("%s is not a PLY file" % path)
    body_start = data.index(b"\n", end) + 1
    header = data[:end].decode("ascii").splitlines()
    fmt = None
    elements = []  # [name, count, [(prop name, type) or (name, ("list", count type, item type))]]
    for line in header:
        words = line.split()
        if not words:
            continue
        if words[0] == "format":
            fmt = words[1]
        elif words[0] == "element":
            elements.append([words[1], int(words[2]), []])
        elif words[0] == "property":
            if words[1] == "list":
                elements[-1][2].append((words[4], ("list", _TYPES[words[2]], _TYPES[words[3]])))
            else:
                elements[-1][2].append((words[2], _TYPES[words[1]]))
    if fmt == "ascii":
        return _read_ascii(data[body_start:].decode("ascii").split(), elements)
    endian = {"binary_little_endian": "<", "binary_big_endian": ">"}.get(fmt)
    if endian is None:
        raise ValueError("unsupported PLY format %r" % fmt)
    return _read_binary(data, body_start, elements, endian)


def _read_binary(data, pos, elements, e):
    vertices, faces = [], []
    for name, count, props in elements:
        simple = all(not isinstance(t, tuple) for _, t in props)
        if simple:
            st = struct.Struct(e + "".join(t for _, t in props))
            names = [n for n, _ in props]
            ix, iy, iz = (names.index(c) for c in "xyz") if name == "vertex" else (0, 0, 0)
            for rec in st.iter_unpack(data[pos:pos + st.size * count]):
                if name == "vertex":
                    vertices.append((rec[ix], rec[iy], rec[iz]))
            pos += st.size * count
            continue
        if name == "face" and len(props) == 1:
            # Fast path: all triangles, so every record is (count=3, i, j, k).
            t = props[0][1]
            rec = struct.Struct(e + t[1] + t[2] * 3)
            end = pos + rec.size * count
            if end <= len(data):
                recs = list(rec.iter_unpack(data[pos:end]))
                if all(r[0] == 3 for r in recs):
                    faces.extend(r[1:] for r in recs)
                    pos = end
                    continue
        for _ in range(count):
            for pname, t in props:
                if isinstance(t, tuple):
                    cs = struct.Struct(e + t[1])
                    (n,) = cs.unpack_from(data, pos)
                    pos += cs.size
                    ist = struct.Struct(e + t[2] * n)
                    items = ist.unpack_from(data, pos)
                    pos += ist.size
                    if name == "face" and pname in ("vertex_indices", "vertex_index"):
                        faces.append(items)
                else:
                    pos += struct.calcsize(e + t)
    return vertices, faces


def _read_ascii(tokens, elements):
    vertices, faces = [], []
    it = iter(tokens)
    for name, count, props in elements:
        for _ in range(count):
            rec = {}
            for pname, t in props:
                if isinstance(t, tuple):
                    n = int(next(it))
                    rec[pname] = tuple(int(next(it)) for _ in range(n))
                else:
                    rec[pname] = float(next(it))
            if name == "vertex":
                vertices.append((rec["x"], rec["y"], rec["z"]))
            elif name == "face":
                faces.append(rec.get("vertex_indices", rec.get("vertex_index")))
    return vertices, faces
