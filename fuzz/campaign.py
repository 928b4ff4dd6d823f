#!/usr/bin/env python3
"""The hostile-file campaign of issue 11 (not part of make test: run it by hand or from bench).

    python3 fuzz/campaign.py RELIEF_SNAKE_BINARY VALID_SCAN.ply [--mutants N] [--out DIR]

Runs `relief-snake info` on hand-made malformed files of every format and on N byte mutants
(flips, truncations, inserted digits) of a valid scan, each under a 10 s timeout and a 3 GB
address-space limit, and counts the outcomes: ok, refused (exit 1, one-line message), crash
(signal), hang (timeout), memory (killed by the limit / bad_alloc), multi-line stderr, and
"accepted bad" (exit 0 on a file that is known to be invalid)."""
import argparse
import collections
import os
import random
import resource
import struct
import subprocess
import sys
import tempfile

LIMIT_BYTES = 3 << 30


def limit():
    resource.setrlimit(resource.RLIMIT_AS, (LIMIT_BYTES, LIMIT_BYTES))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


def ply_header(nv, nf, fmt="ascii", vprops=("float x", "float y", "float z"), flist="list uchar int vertex_indices"):
    h = "ply\nformat %s 1.0\nelement vertex %d\n" % (fmt, nv)
    h += "".join("property %s\n" % p for p in vprops)
    h += "element face %d\nproperty %s\nend_header\n" % (nf, flist)
    return h


SQUARE_V = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
SQUARE_F = "3 0 1 2\n3 0 2 3\n"


def malformed():
    """(name, bytes, known_bad): hand-made files; known_bad ones must not be accepted silently."""
    cases = []
    add = lambda name, data, bad=True: cases.append((name, data if isinstance(data, bytes) else data.encode(), bad))
    # PLY grammar
    add("prop_before_element.ply", "ply\nformat ascii 1.0\nproperty float x\nelement vertex 3\nend_header\n0\n0\n0\n")
    add("unnamed_list.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 1\nproperty list uchar int\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    add("no_end_header.ply", "ply\nformat ascii 1.0\nelement vertex 3\n")
    add("unknown_type.ply", ply_header(4, 2, vprops=("float128 x", "float y", "float z")) + SQUARE_V + SQUARE_F)
    add("bad_format.ply", ply_header(4, 2, fmt="binary_middle_endian") + SQUARE_V + SQUARE_F)
    add("negative_count.ply", ply_header(-4, 2) + SQUARE_V + SQUARE_F)
    add("huge_count.ply", ply_header(2 ** 62, 2) + SQUARE_V + SQUARE_F)
    add("too_many_vertices.ply", ply_header(5, 2) + SQUARE_V + SQUARE_F)
    add("too_few_vertices.ply", ply_header(3, 2) + SQUARE_V + SQUARE_F)
    add("truncated.ply", ply_header(4, 2) + SQUARE_V + "3 0 1 2\n3 0")
    add("nan.ply", ply_header(4, 2) + "0 0 0\nnan 0 0\n1 1 0\n0 1 0\n" + SQUARE_F)
    add("inf.ply", ply_header(4, 2) + "0 0 0\ninf 0 0\n1 1 0\n0 1 0\n" + SQUARE_F)
    add("big_finite.ply", ply_header(4, 2) + "0 0 0\n1e300 0 0\n1 1 0\n0 1 0\n" + SQUARE_F)
    add("bad_index.ply", ply_header(4, 2) + SQUARE_V + "3 0 1 9\n3 0 2 3\n")
    add("negative_index.ply", ply_header(4, 2) + SQUARE_V + "3 0 -1 2\n3 0 2 3\n")
    add("garbage_index.ply", ply_header(4, 2) + SQUARE_V + "3 0 x 2\n3 0 2 3\n")
    add("ushort_count.ply", ply_header(4, 2, flist="list ushort int vertex_indices") + SQUARE_V + SQUARE_F, False)
    add("double.ply", ply_header(4, 2, vprops=("double x", "double y", "double z")) + SQUARE_V + SQUARE_F, False)
    binv = b"".join(struct.pack("<fff", *v) for v in [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)])
    hb = ply_header(4, 1, fmt="binary_little_endian").encode()
    add("bin_huge_list.ply", hb + binv + struct.pack("<B", 255) + struct.pack("<i", 0) * 3)
    hb_int = ply_header(4, 1, fmt="binary_little_endian", flist="list int int vertex_indices").encode()
    add("bin_2p31_list.ply", hb_int + binv + struct.pack("<I", 2 ** 31) + struct.pack("<i", 0) * 3)
    add("bin_negative_list.ply", hb_int + binv + struct.pack("<i", -3) + struct.pack("<i", 0) * 3)
    add("bin_truncated.ply", hb + binv[:30])
    add("bin_trailing.ply", hb + binv + struct.pack("<Biii", 3, 0, 1, 2) + b"junk")
    add("bin_ok.ply", hb + binv + struct.pack("<Biii", 3, 0, 1, 2), False)
    add("empty.ply", "")
    # OFF
    add("ok.off", "OFF\n4 2 0\n" + SQUARE_V + SQUARE_F, False)
    add("neg_count_face.off", "OFF\n4 1 0\n" + SQUARE_V + "-3 0 1 2\n")
    add("huge_count_face.off", "OFF\n4 1 0\n" + SQUARE_V + "2147483647 0 1 2\n")
    add("nan.off", "OFF\n4 2 0\n0 0 0\nnan 0 0\n1 1 0\n0 1 0\n" + SQUARE_F)
    add("short.off", "OFF\n300000000 1 0\n0 0 0\n")
    add("truncated.off", "OFF\n4 2 0\n" + SQUARE_V + "3 0 1 2\n3 0")
    add("too_many_vertices.off", "OFF\n5 2 0\n" + SQUARE_V + SQUARE_F)
    add("bad_index.off", "OFF\n4 2 0\n" + SQUARE_V + "3 0 1 7\n3 0 2 3\n")
    add("binary_short.off", b"OFF BINARY\n" + struct.pack("<iii", 10 ** 8, 1, 0))
    add("binary_neg_face.off", b"OFF BINARY\n" + struct.pack("<iii", 4, 1, 0) + binv + struct.pack("<iiiii", -3, 0, 1, 2, 0))
    # OBJ
    add("ok.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n", False)
    add("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 9\nf 1 2 3\n")
    add("garbage_index.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 x\nf 1 2 3\n")
    add("zero_index.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 0 1 2\n")
    add("nan.obj", "v 0 0 0\nv nan 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n")
    add("truncated.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3")
    add("truncated_vertex.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1")
    # STL
    tri = struct.pack("<3f", 0, 0, 1) + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + b"\0\0"
    add("ok.stl", b" " * 80 + struct.pack("<I", 1) + tri, False)
    add("nan.stl", b" " * 80 + struct.pack("<I", 1) + struct.pack("<3f", 0, 0, 1) +
        struct.pack("<9f", 0, 0, 0, float("nan"), 0, 0, 0, 1, 0) + b"\0\0")
    add("count_mismatch.stl", b" " * 80 + struct.pack("<I", 5) + tri)
    add("huge_count.stl", b" " * 80 + struct.pack("<I", 2 ** 32 - 1) + tri)
    add("ascii_truncated.stl", "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n")
    add("ascii_nan.stl", "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex nan 0 0\n"
        "   vertex 0 1 0\n  endloop\n endfacet\nendsolid x\n")
    add("short.stl", b"solid")
    return cases


def mutants(valid, n, rng):
    out = []
    header_end = valid.find(b"end_header\n")
    header_end = len(valid) if header_end < 0 else header_end + 11
    for k in range(n):
        data = bytearray(valid)
        kind = k % 4
        if kind == 0:  # a few flipped bytes in the header
            for _ in range(rng.randint(1, 3)):
                i = rng.randrange(header_end)
                data[i] = rng.randrange(256)
        elif kind == 1:  # flipped bytes anywhere
            for _ in range(rng.randint(1, 8)):
                i = rng.randrange(len(data))
                data[i] ^= 1 << rng.randrange(8)
        elif kind == 2:  # truncation
            data = data[:rng.randrange(len(data))]
        else:  # a digit inserted into the header (counts grow by 10x)
            digits = [i for i in range(header_end) if chr(data[i]).isdigit()]
            if digits:
                i = rng.choice(digits)
                data[i:i] = str(rng.randrange(10)).encode()
        out.append(("mutant_%04d.ply" % k, bytes(data), None))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary")
    ap.add_argument("valid")
    ap.add_argument("--mutants", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    rng = random.Random(args.seed)
    cases = malformed() + mutants(open(args.valid, "rb").read(), args.mutants, rng)
    counts = collections.Counter()
    problems = []
    with tempfile.TemporaryDirectory() as tmp:
        out = args.out or tmp
        os.makedirs(out, exist_ok=True)
        for name, data, bad in cases:
            path = os.path.join(out, name)
            with open(path, "wb") as f:
                f.write(data)
            try:
                p = subprocess.run([args.binary, "info", path], capture_output=True, timeout=10, preexec_fn=limit)
            except subprocess.TimeoutExpired:
                counts["hang"] += 1
                problems.append((name, "hang"))
                continue
            err = p.stderr.decode(errors="replace").strip()
            if p.returncode < 0:
                kind = "crash"
            elif "out of memory" in err or "bad_alloc" in err:
                kind = "memory"
            elif p.returncode == 0:
                kind = "accepted bad" if bad else "ok"
            elif p.returncode == 1:
                kind = "refused" if err.count("\n") == 0 else "multi-line stderr"
            else:
                kind = "exit %d" % p.returncode
            counts[kind] += 1
            if kind not in ("ok", "refused"):
                problems.append((name, kind, err.splitlines()[0][:150] if err else ""))
            if name.startswith(("nan", "big_finite", "ushort", "double", "bin_huge", "neg_count", "huge_count",
                                "prop_before", "unnamed")) and not name.startswith("mutant"):
                print("  %-24s exit %s: %s" % (name, p.returncode, (err.splitlines() or [""])[-1][:140]))
    print("campaign: %d runs: %s" % (len(cases), dict(counts)))
    for pr in problems[:40]:
        print("  problem:", *pr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
