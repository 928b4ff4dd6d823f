"""A mesh's click order (its MSelect array) read from a .blend file, without bpy (plain Python).

In Object Mode Blender keeps the select history with the mesh data (Mesh.mselect), and its Python
API reads it back only through bmesh, which copies the whole mesh (0.7 s of a 300k-triangle
Segment in Blender 3.4). bpy.data.libraries.write() writes the mesh into a .blend in a few tens of
milliseconds instead, and a .blend file describes its own layout (the SDNA block: every struct's
fields, types and sizes), so the MSelect array is found there without assuming any offset:

    entries = read_select_history(path, "MEScan")   # [(index, type)], type 0 = vertex

Both file layouts are read: the one of Blender 2.5 to 4.x ("BLENDER-v304", 24-byte block
headers with 8-byte pointers, 20 with 4-byte ones) and the one of Blender 5.0+ ("BLENDER17-01v0500",
32-byte block headers). Anything unexpected raises Unreadable, so that the caller falls back to
bmesh: this module never guesses.
"""

import mmap
import struct

__all__ = ["Unreadable", "read_select_history", "VERTEX", "EDGE", "FACE"]

VERTEX, EDGE, FACE = 0, 1, 2  # MSelect.type: ME_VSEL, ME_ESEL, ME_FSEL


class Unreadable(ValueError):
    """The file is not laid out as this reader expects (the caller reads the history another way)."""


class _Layout:
    """Pointer size, byte order and block-header format of one .blend file."""

    def __init__(self, head):
        if head[:7] != b"BLENDER":
            raise Unreadable("not a .blend file (no BLENDER header)")
        if head[7:9].isdigit():  # Blender 5.0+: "BLENDER" size(2) "-" format(2) endian version(4)
            size = int(head[7:9])
            if head[9:10] != b"-" or head[10:12] != b"01" or size != 17:
                raise Unreadable("unknown .blend header %r" % head[:17])
            self.header_size, self.pointer = 17, 8
            endian = head[12:13]
            # LargeBHead8: int code; int SDNAnr; uint64 old; int64 len; int64 nr
            fmt = "4siQqq"
            self._order = ("code", "sdna", "old", "len", "nr")
        else:  # "BLENDER" pointer('-' 8 bytes, '_' 4 bytes) endian version(3)
            self.header_size = 12
            self.pointer = {b"-": 8, b"_": 4}.get(head[7:8])
            if self.pointer is None:
                raise Unreadable("unknown pointer size in %r" % head[:12])
            endian = head[8:9]
            # BHead: char code[4]; int len; void *old; int SDNAnr; int nr
            fmt = "4si%sii" % ("Q" if self.pointer == 8 else "I")
            self._order = ("code", "len", "old", "sdna", "nr")
        if endian not in (b"v", b"V"):
            raise Unreadable("unknown byte order in %r" % head[:17])
        self.endian = "<" if endian == b"v" else ">"
        self.bhead = struct.Struct(self.endian + fmt)

    def block(self, buf, offset=0):
        """(code, length, old pointer, nr) of the block header at buf[offset:]."""
        values = dict(zip(self._order, self.bhead.unpack_from(buf, offset)))
        return values["code"], values["len"], values["old"], values["nr"]


_WANTED = ("Mesh", "ID", "MSelect")
_SDNA_CACHE = {}  # DNA1 bytes -> parsed structs (one Blender writes the same SDNA every time)


def _sdna(data, endian, pointer):
    """{struct name: (size, {field name: (offset, type name)})} of the structs this reader needs
    (Mesh, ID, MSelect), from a DNA1 block's data."""
    key = (bytes(data), endian, pointer)
    cached = _SDNA_CACHE.get(key)
    if cached is not None:
        return cached
    pos = 0

    def need(tag):
        nonlocal pos
        if data[pos:pos + 4] != tag:
            raise Unreadable("SDNA: expected %r at %d" % (tag, pos))
        pos += 4

    def count():
        nonlocal pos
        (n,) = struct.unpack_from(endian + "i", data, pos)
        pos += 4
        return n

    def strings(n):
        nonlocal pos
        out = data[pos:].split(b"\0", n)[:n]
        if len(out) != n:
            raise Unreadable("SDNA: a name table is cut short")
        pos += sum(len(x) + 1 for x in out)
        pos = (pos + 3) & ~3
        return [x.decode("latin-1") for x in out]

    need(b"SDNA")
    need(b"NAME")
    names = strings(count())
    need(b"TYPE")
    types = strings(count())
    need(b"TLEN")
    sizes = struct.unpack_from(endian + "%dH" % len(types), data, pos)
    pos = (pos + 2 * len(types) + 3) & ~3
    need(b"STRC")
    structs = {}
    for _ in range(count()):
        type_index, nfields = struct.unpack_from(endian + "hh", data, pos)
        pos += 4
        if types[type_index] not in _WANTED:
            pos += 4 * nfields
            continue
        fields, offset = {}, 0
        pairs = struct.unpack_from(endian + "%dh" % (2 * nfields), data, pos)
        pos += 4 * nfields
        for ftype, fname in zip(pairs[0::2], pairs[1::2]):
            name = names[fname]
            fields[_bare(name)] = (offset, types[ftype])
            offset += _field_size(name, sizes[ftype], pointer)
        if offset != sizes[type_index]:  # DNA structs have no hidden padding: the sum is the size
            raise Unreadable("SDNA: struct %s adds up to %d bytes, not %d" % (types[type_index], offset,
                                                                               sizes[type_index]))
        structs[types[type_index]] = (sizes[type_index], fields)
    _SDNA_CACHE.clear()
    _SDNA_CACHE[key] = structs
    return structs


def _bare(name):
    """'*mselect' -> 'mselect', 'name[66]' -> 'name', '(*func)()' -> 'func'."""
    return name.strip("*()").split("[")[0].split(")")[0].lstrip("*")


def _field_size(name, type_size, pointer):
    dims = 1
    rest = name
    while "[" in rest:
        start, end = rest.index("["), rest.index("]")
        dims *= int(rest[start + 1:end])
        rest = rest[end + 1:]
    is_pointer = name.startswith("*") or name.startswith("(")
    return dims * (pointer if is_pointer else type_size)


def _mesh_layout(structs):
    """The offsets this reader needs, from the parsed SDNA."""
    try:
        mesh_size, mesh_fields = structs["Mesh"]
        _, id_fields = structs["ID"]
        msel_size, msel_fields = structs["MSelect"]
        return {"mesh_size": mesh_size, "name": mesh_fields["id"][0] + id_fields["name"][0],
                "mselect": mesh_fields["mselect"][0], "totselect": mesh_fields["totselect"][0],
                "msel_size": msel_size, "index": msel_fields["index"][0], "type": msel_fields["type"][0]}
    except KeyError as exc:
        raise Unreadable("SDNA has no %s" % exc) from None


def _find_dna(data, layout):
    """(offset, length) of the DNA1 block's data. Blender writes it last, just before ENDB: found
    from the end and checked (its header, and ENDB right after it closing the file), else found by
    walking every block header (a mesh with weights writes one block per vertex)."""
    size = layout.bhead.size
    at = data.rfind(b"SDNA")
    if at >= size:
        code, length, _, _ = layout.block(data, at - size)
        end = at + length
        if code == b"DNA1" and end + size == len(data) and layout.block(data, end)[0] == b"ENDB":
            return at, length
    for code, pos, length, _ in _blocks(data, layout):
        if code == b"DNA1":
            return pos, length
    raise Unreadable("no SDNA block")


def _blocks(data, layout):
    """(code, data offset, length, old pointer) of each block up to ENDB."""
    pos, size = layout.header_size, layout.bhead.size
    while True:
        if pos + size > len(data):
            raise Unreadable("the file ends without an ENDB block")
        code, length, old, _ = layout.block(data, pos)
        pos += size
        if code == b"ENDB":
            return
        if length < 0 or pos + length > len(data):
            raise Unreadable("a block runs past the end of the file")
        yield code, pos, length, old
        pos += length


def read_select_history(path, id_name):
    """[(index, type)] of the MSelect array of the Mesh block named id_name (the ID name with its
    two-letter code, e.g. "MEScan") in the .blend at path, in click order as stored (duplicates and
    all). Raises Unreadable if the file is not laid out as expected or holds no such mesh."""
    try:
        with open(path, "rb") as f, mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as data:
            return _read(data, id_name)  # mapped, not read: only a few blocks of it are looked at
    except Unreadable:
        raise
    except (struct.error, ValueError, IndexError) as exc:  # cut short or malformed (an empty file included)
        raise Unreadable("malformed .blend: %s" % exc) from None


def _read(data, id_name):
    layout = _Layout(data[:17])
    at, length = _find_dna(data, layout)
    offsets = _mesh_layout(_sdna(data[at:at + length], layout.endian, layout.pointer))
    wanted = None  # (mselect pointer, totselect) once the mesh's block is found
    # Blender writes a mesh's select history right after the mesh's own block, before its
    # attribute arrays and weights: the walk stops there.
    for code, pos, length, old in _blocks(data, layout):
        if code == b"ME\0\0" and wanted is None:
            found = _mesh_select(data[pos:pos + length], id_name, layout, offsets)
            if found is not None:
                if found[1] <= 0 or found[0] == 0:
                    return []
                wanted = found
        elif wanted is not None and code == b"DATA" and old == wanted[0]:
            n = wanted[1]
            if length < n * offsets["msel_size"]:
                raise Unreadable("the mesh's select history block is short")
            return _entries(data[pos:pos + n * offsets["msel_size"]], n, layout, offsets)
    raise Unreadable("no mesh %r with its select history in the file" % id_name)


def _mesh_select(block, id_name, layout, offsets):
    """(mselect pointer, totselect) of a Mesh block if it is named id_name, else None."""
    if len(block) < offsets["mesh_size"]:
        raise Unreadable("a Mesh block is shorter than struct Mesh")
    wanted = id_name.encode("utf-8") + b"\0"
    start = offsets["name"]
    if block[start:start + len(wanted)] != wanted:
        return None
    ptr = "Q" if layout.pointer == 8 else "I"
    (pointer,) = struct.unpack_from(layout.endian + ptr, block, offsets["mselect"])
    (total,) = struct.unpack_from(layout.endian + "i", block, offsets["totselect"])
    return pointer, total


def _entries(raw, total, layout, offsets):
    e, step = layout.endian + "i", offsets["msel_size"]
    return [(struct.unpack_from(e, raw, k * step + offsets["index"])[0],
             struct.unpack_from(e, raw, k * step + offsets["type"])[0]) for k in range(total)]
