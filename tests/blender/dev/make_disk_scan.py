"""DEVELOPMENT-ONLY: a flat grid with a raised disk, written like make-scan (PREFIX.ply +
PREFIX.truth.json), for testing the plumbing before build/make-scan exists."""

import json
import math
import struct
import sys


def main(prefix, n=60, h=0.2):
    verts, faces = [], []
    r = 0.35
    for j in range(n + 1):
        for i in range(n + 1):
            x, y = i / n - 0.5, j / n - 0.5
            verts.append((x, y, h if math.hypot(x, y) < r else 0.0))
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            faces += [(a, a + 1, a + n + 2), (a, a + n + 2, a + n + 1)]
    with open(prefix + ".ply", "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
                 "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
                 % (len(verts), len(faces))).encode())
        for v in verts:
            f.write(struct.pack("<3f", *v))
        for t in faces:
            f.write(struct.pack("<B3i", 3, *t))
    picks = []
    for k in range(8):
        a = 2 * math.pi * k / 8
        x, y = 0.45 * math.cos(a), 0.45 * math.sin(a)
        picks.append(round((y + 0.5) * n) * (n + 1) + round((x + 0.5) * n))
    truth = {"h": h, "average_edge": 1.0 / n, "triangles": len(faces), "vertices": len(verts),
             "relief_vertices": [i for i, v in enumerate(verts) if v[2] > 0],
             "boundary": [[r * math.cos(2 * math.pi * k / 200), r * math.sin(2 * math.pi * k / 200), 0.0]
                          for k in range(200)],
             "picks": picks, "open": False, "relief_side": "left"}
    with open(prefix + ".truth.json", "w") as f:
        json.dump(truth, f)


if __name__ == "__main__":
    main(sys.argv[1])
