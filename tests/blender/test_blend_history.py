"""bpy-free tests of addon/relief_snake/blend_history.py (plain Python: pytest, and inside the three
Blenders, where test_addon.py also reads real files against bmesh): small .blend files built here in
each block layout, with an SDNA that places the fields elsewhere than Blender does, so that only a
reader that follows the file's own SDNA finds the history."""

import os
import struct
import sys
import tempfile
import unittest

_ADDON = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "addon", "relief_snake")
sys.path.insert(0, os.path.normpath(_ADDON))
import blend_history  # noqa: E402  (bpy-free module, imported standalone on purpose)


def _pad4(b):
    return b + b"\0" * (-len(b) % 4)


class _Writer:
    """A .blend in one layout: 'old8' (3.x/4.x, 8-byte pointers, little-endian), 'old4be' (4-byte
    pointers, big-endian) or 'v5' (Blender 5.0+ header and 32-byte block headers)."""

    def __init__(self, layout, pad_before_mselect=12):
        self.layout = layout
        self.e = ">" if layout == "old4be" else "<"
        self.ptr = 4 if layout == "old4be" else 8
        self.pad = pad_before_mselect
        self.blocks = []

    def header(self):
        return {"old8": b"BLENDER-v304", "old4be": b"BLENDER_V279", "v5": b"BLENDER17-01v0502"}[self.layout]

    def bhead(self, code, length, old, sdna=0, nr=1):
        if self.layout == "v5":
            return struct.pack(self.e + "4siQqq", code, sdna, old, length, nr)
        return struct.pack(self.e + "4si%sii" % ("Q" if self.ptr == 8 else "I"), code, length, old, sdna, nr)

    def sdna(self, lie_about_mesh_size=False):
        names = [b"*next", b"*prev", b"name[66]", b"pad", b"id", b"loc[%d]" % (self.pad // 4), b"*mselect",
                 b"totselect", b"index", b"type", b"(*func)()"]
        types = [b"char", b"short", b"int", b"void", b"ID", b"Mesh", b"MSelect", b"float"]
        id_size = 2 * self.ptr + 66 + 2
        mesh_size = id_size + self.pad + self.ptr + 4 + 4 + self.ptr
        sizes = [1, 2, 4, 0, id_size, mesh_size + (8 if lie_about_mesh_size else 0), 8, 4]
        T = {n: k for k, n in enumerate(types)}
        N = {n: k for k, n in enumerate(names)}
        structs = [
            (T[b"ID"], [(T[b"void"], N[b"*next"]), (T[b"void"], N[b"*prev"]), (T[b"char"], N[b"name[66]"]),
                        (T[b"short"], N[b"pad"])]),
            (T[b"Mesh"], [(T[b"ID"], N[b"id"]), (T[b"float"], N[b"loc[%d]" % (self.pad // 4)]),
                          (T[b"MSelect"], N[b"*mselect"]), (T[b"int"], N[b"totselect"]), (T[b"int"], N[b"pad"]),
                          (T[b"void"], N[b"(*func)()"])]),
            (T[b"MSelect"], [(T[b"int"], N[b"index"]), (T[b"int"], N[b"type"])]),
        ]
        e = self.e
        out = b"SDNA" + b"NAME" + struct.pack(e + "i", len(names)) + _pad4(b"".join(n + b"\0" for n in names))
        out += b"TYPE" + struct.pack(e + "i", len(types)) + _pad4(b"".join(t + b"\0" for t in types))
        out += b"TLEN" + _pad4(struct.pack(e + "%dH" % len(sizes), *sizes))
        out += b"STRC" + struct.pack(e + "i", len(structs))
        for t, fields in structs:
            out += struct.pack(e + "hh", t, len(fields))
            for ft, fn in fields:
                out += struct.pack(e + "hh", ft, fn)
        return out

    def mesh(self, name, mselect, total):
        e, p = self.e, "Q" if self.ptr == 8 else "I"
        ident = struct.pack(e + p + p, 0, 0) + name.encode().ljust(66, b"\0") + b"\0\0"
        return ident + b"\0" * self.pad + struct.pack(e + p + "ii" + p, mselect, total, 0, 0)

    def add(self, code, data, old=0):
        self.blocks.append((code, data, old))

    def build(self, dna_last=True, lie_about_mesh_size=False):
        out = self.header()
        blocks = list(self.blocks)
        dna = (b"DNA1", self.sdna(lie_about_mesh_size), 0)
        blocks = blocks + [dna] if dna_last else [dna] + blocks
        for code, data, old in blocks:
            out += self.bhead(code, len(data), old) + data
        return out + self.bhead(b"ENDB", 0, 0)


def _selection(e, entries):
    return b"".join(struct.pack(e + "ii", i, t) for i, t in entries)


class ReadSelectHistory(unittest.TestCase):
    def setUp(self):
        fd, self.path = tempfile.mkstemp(suffix=".blend")
        os.close(fd)

    def tearDown(self):
        os.remove(self.path)

    def read(self, data, name="MEScan"):
        with open(self.path, "wb") as f:
            f.write(data)
        return blend_history.read_select_history(self.path, name)

    def scene(self, layout, entries, **kw):
        w = _Writer(layout, **{k: v for k, v in kw.items() if k == "pad_before_mselect"})
        e = w.e
        w.add(b"ME\0\0", w.mesh("MEOther", 0x7000, 1), old=0x6000)
        w.add(b"DATA", _selection(e, [(99, 0)]), old=0x7000)
        w.add(b"ME\0\0", w.mesh("MEScan", 0x5000, len(entries)), old=0x4000)
        w.add(b"DATA", b"\1" * 64, old=0x4800)  # another array of the mesh
        w.add(b"DATA", _selection(e, entries), old=0x5000)
        for k in range(200):  # weights: a block per vertex
            w.add(b"DATA", b"\0" * 8, old=0x10000 + 16 * k)
        return w

    def test_every_layout(self):
        entries = [(12, 0), (840, 0), (5, 2), (77, 0), (12, 0)]
        for layout in ("old8", "old4be", "v5"):
            for pad in (12, 40):  # the history's offset comes from the file's SDNA, not from Blender's
                w = self.scene(layout, entries, pad_before_mselect=pad)
                self.assertEqual(self.read(w.build()), entries, (layout, pad))
                self.assertEqual(self.read(w.build(dna_last=False)), entries, (layout, pad))  # found by the walk
                self.assertEqual(self.read(w.build(), "MEOther"), [(99, 0)], (layout, pad))

    def test_no_history(self):
        w = _Writer("old8")
        w.add(b"ME\0\0", w.mesh("MEScan", 0, 0))
        self.assertEqual(self.read(w.build()), [])

    def test_what_it_refuses(self):
        w = self.scene("old8", [(1, 0), (2, 0)])
        good = w.build()
        self.assertEqual(self.read(good), [(1, 0), (2, 0)])
        cases = {
            "no such mesh": (good, "MEScan2"),
            "cut short": (good[:len(good) // 2], "MEScan"),
            "empty": (b"", "MEScan"),
            "not a .blend": (b"PK\3\4" + good[4:], "MEScan"),
            "unknown v5 format": (good.replace(b"BLENDER-v304", b"BLENDER17-02v0502"[:12], 1), "MEScan"),
            "SDNA sizes that do not add up": (w.build(lie_about_mesh_size=True), "MEScan"),
        }
        for why, (data, name) in cases.items():
            with self.assertRaises(blend_history.Unreadable, msg=why):
                self.read(data, name)
        # The history's block missing (the mesh points at nothing in the file).
        w2 = _Writer("old8")
        w2.add(b"ME\0\0", w2.mesh("MEScan", 0x5000, 2))
        with self.assertRaises(blend_history.Unreadable):
            self.read(w2.build())
        # Shorter than totselect entries.
        w3 = _Writer("old8")
        w3.add(b"ME\0\0", w3.mesh("MEScan", 0x5000, 3))
        w3.add(b"DATA", _selection("<", [(1, 0)]), old=0x5000)
        with self.assertRaises(blend_history.Unreadable):
            self.read(w3.build())


if __name__ == "__main__":
    unittest.main()
