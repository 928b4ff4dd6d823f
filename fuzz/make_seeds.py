#!/usr/bin/env python3
"""Writes the fuzzers' seed corpus: small valid files of every format (fuzz/corpus/intake/),
each prefixed with the format byte of fuzz_entries.hpp, and segment inputs with picks around
the relief of each fixed mesh and each option group (fuzz/corpus/segment/). Deterministic; rerun to regenerate."""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
OBJ, PLY, OFF, STL = 0, 1, 2, 3
PARTIAL = 4


def grid(n=4, double_offset=0.0):
    V = [(i + double_offset, j, 0.25 * ((i * 7 + j * 3) % 3)) for j in range(n) for i in range(n)]
    F = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            F += [(a, a + 1, a + n + 1), (a, a + n + 1, a + n)]
    return V, F


def obj(V, F, quads=False):
    s = "# seed\n" + "".join("v %r %r %r\n" % v for v in V)
    s += "vn 0 0 1\nvt 0 0\n"
    s += "".join("f %d/1/1 %d/1/1 %d/1/1\n" % tuple(i + 1 for i in f) for f in F)
    return s.encode()


def ply_ascii(V, F, count="uchar", coord="float"):
    h = ("ply\nformat ascii 1.0\ncomment seed\nelement vertex %d\nproperty %s x\nproperty %s y\nproperty %s z\n"
         "element face %d\nproperty list %s int vertex_indices\nend_header\n" % (len(V), coord, coord, coord, len(F), count))
    return (h + "".join("%r %r %r\n" % v for v in V) + "".join("3 %d %d %d\n" % f for f in F)).encode()


def ply_binary(V, F, endian="<", coord="double", count="ushort"):
    name = "binary_little_endian" if endian == "<" else "binary_big_endian"
    h = ("ply\nformat %s 1.0\nelement vertex %d\nproperty %s x\nproperty %s y\nproperty %s z\nproperty uchar red\n"
         "element face %d\nproperty list %s uint vertex_indices\nend_header\n" % (name, len(V), coord, coord, coord, len(F), count))
    c = {"double": "d", "float": "f"}[coord]
    n = {"uchar": "B", "ushort": "H", "int": "i"}[count]
    body = b"".join(struct.pack(endian + c * 3 + "B", *v, 200) for v in V)
    body += b"".join(struct.pack(endian + n + "III", 3, *f) for f in F)
    return h.encode() + body


def off(V, F):
    return ("OFF\n# seed\n%d %d 0\n" % (len(V), len(F)) + "".join("%r %r %r\n" % v for v in V)
            + "".join("3 %d %d %d\n" % f for f in F)).encode()


def off_binary(V, F):
    b = b"OFF BINARY\n" + struct.pack("<iii", len(V), len(F), 0)
    b += b"".join(struct.pack("<fff", *v) for v in V)
    b += b"".join(struct.pack("<iiiii", 3, *f, 0) for f in F)
    return b


def stl_ascii(V, F):
    s = "solid seed\n"
    for f in F:
        s += " facet normal 0 0 1\n  outer loop\n" + "".join("   vertex %r %r %r\n" % V[i] for i in f)
        s += "  endloop\n endfacet\n"
    return (s + "endsolid seed\n").encode()


def stl_binary(V, F):
    b = b"solid but binary".ljust(80, b" ") + struct.pack("<I", len(F))
    for f in F:
        b += struct.pack("<3f", 0, 0, 1) + b"".join(struct.pack("<3f", *V[i]) for i in f) + b"\0\0"
    return b


def main():
    V, F = grid()
    seeds = {
        "obj.obj": (OBJ, obj(V, F)),
        "ply_ascii.ply": (PLY, ply_ascii(V, F)),
        "ply_ascii_ushort.ply": (PLY, ply_ascii(V, F, count="ushort", coord="double")),
        "ply_binary_le_double.ply": (PLY, ply_binary(V, F)),
        "ply_binary_be_float.ply": (PLY, ply_binary(V, F, endian=">", coord="float", count="uchar")),
        "off.off": (OFF, off(V, F)),
        "off_binary.off": (OFF, off_binary(V, F)),
        "stl_ascii.stl": (STL, stl_ascii(V, F)),
        "stl_binary.stl": (STL, stl_binary(V, F)),
        "obj_partial.obj": (OBJ | PARTIAL, obj(V, F)[:-9]),
        "ply_offset.ply": (PLY, ply_binary(*grid(3, 1e6))),
    }
    out = os.path.join(HERE, "corpus", "intake")
    os.makedirs(out, exist_ok=True)
    for name, (selector, data) in seeds.items():
        with open(os.path.join(out, name), "wb") as f:
            f.write(bytes([selector]) + data)
    # segment (fuzz_entries.hpp): mesh, [nx, ny, heights], n_picks, picks (u16, index + 1), flags, more,
    # h, w_int, iterations, cancel, extras, [band or hole picks]
    seg = os.path.join(HERE, "corpus", "segment")
    os.makedirs(seg, exist_ok=True)
    for old in os.listdir(seg):
        os.remove(os.path.join(seg, old))

    def picks(points, nx=10):
        return bytes([len(points) - 2]) + b"".join(struct.pack("<H", j * nx + i + 1) for i, j in points)

    def ring_picks(points, nx=10):
        return bytes([len(points) - 3]) + b"".join(struct.pack("<H", j * nx + i + 1) for i, j in points)

    ring = [(1, 1), (8, 1), (8, 8), (1, 8)]
    h1, w, iters = 101, 63, 4  # h = 0.05 * 1.03^101 = 1 edge; W_int 0.25; 5 iterations per phase
    cases = {
        "sharp_disk": (0, ring, 0, 0),
        "blended_disk": (1, ring, 0, 0),
        "ring_disk": (2, ring, 0, 0),
        "step_closed": (3, ring, 0, 0),
        "tilted_disk": (4, ring, 0, 0),
        "flat": (5, ring, 0, 0),
        "open_auto_side": (3, [(4, 0), (4, 5), (4, 9)], 1 | 4, 0),
        "foot_snap": (1, ring, 8, 0),
        "auto_h": (0, ring, 64, 0),
        "geodesic_vertices": (0, ring, 0, 1 | 4),
        "euclidean_area_levels": (4, ring, 0, 2 | 8 | 32),
        "exact_q_barrier": (1, ring, 16 | 32, 64 | 128),
    }
    for name, (mesh, points, flags, more) in cases.items():
        data = bytes([mesh]) + picks(points) + bytes([flags, more, h1, w, iters, 0, 2])
        with open(os.path.join(seg, name), "wb") as f:
            f.write(data)
    # A band (a second ring inside the first) and hole picks on the ring-shaped disk.
    inner = [(4, 4), (5, 4), (5, 5), (4, 5)]
    with open(os.path.join(seg, "band"), "wb") as f:
        f.write(bytes([2]) + picks(ring) + bytes([128, 0, h1, w, iters, 0, 0]) + ring_picks(inner))
    with open(os.path.join(seg, "hole_picks"), "wb") as f:
        f.write(bytes([2]) + picks(ring) + bytes([128, 0, h1, w, iters, 0, 1]) + ring_picks(inner))
    # A mesh from the bytes: an 8 x 8 bump, picks around it.
    n = 8
    heights = bytes(12 if 2 <= i <= n - 3 and 2 <= j <= n - 3 else 0 for j in range(n) for i in range(n))
    own_ring = [(1, 1), (n - 2, 1), (n - 2, n - 2), (1, n - 2)]
    with open(os.path.join(seg, "own_bump"), "wb") as f:
        f.write(bytes([6, n - 3, n - 3]) + heights + picks(own_ring, n) + bytes([0, 0, 150, w, iters, 0, 2]))

if __name__ == "__main__":
    main()
