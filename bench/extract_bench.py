#!/usr/bin/env python3
"""Extraction benchmark: accuracy against the analytic background and time, per case.

    python3 bench/extract_bench.py [--build build] [--triangles 100000,290000] [--json OUT]

For each background (plane, cylinder, sphere, saddle) and size, make-scan writes a sharp-step duck;
its true relief vertices stand in for the segmentation, `relief-snake extract` runs on them, and
the outputs are scored: base error (distance of the moved vertices from the true background) and
height error (|height - h| on relief.ply), both over relief vertices more than `--margin` h inside
the true boundary, in units of h; plus the engine's own times (background fill, height map) and,
on a second line, each stage's wall time (`extract --timings`: reading the result, loading the
mesh, Laplacian weights, ring, assembly, ordering, factorisation, solve, height, relief patch,
plane, the conformal map's stages, rasterising, writing the five files). Prints one line per case; the target is under 0.5 s for a 290k-triangle scan's relief (judged on
CPU time, which includes writing the five files; wall times on a loaded machine are printed too).
"""

import argparse
import json
import math
import re
import resource
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def read_ply(path):
    """Binary little-endian PLY: (positions, {property: values}) of its vertices."""
    data = Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    props, nv, element = [], 0, None
    for line in data[:end].decode().splitlines():
        w = line.split()
        if w[:1] == ["element"]:
            element = w[1]
            if element == "vertex":
                nv = int(w[2])
        elif w[:1] == ["property"] and element == "vertex":
            props.append(({"float": "f", "float32": "f", "double": "d", "float64": "d"}[w[1]], w[2]))
    fmt = "<" + "".join(t for t, _ in props)
    size = struct.calcsize(fmt)
    rows = list(struct.iter_unpack(fmt, data[end:end + nv * size]))
    names = [n for _, n in props]
    columns = {n: [r[i] for r in rows] for i, n in enumerate(names)}
    return list(zip(columns["x"], columns["y"], columns["z"])), columns


def distance_to_background(kind, R, p):
    x, y, z = p
    if kind == "plane":
        return abs(z)
    if kind == "cylinder":
        return abs(math.hypot(x, z + R) - R)
    if kind == "sphere":
        return abs(math.sqrt(x * x + y * y + (z + R) ** 2) - R)
    # saddle z = (x^2 - y^2) / 2R: first-order distance
    f = (x * x - y * y) / (2 * R)
    return abs(z - f) / math.sqrt(1 + (x / R) ** 2 + (y / R) ** 2)


class PointGrid:
    """Nearest distance to a set of 3D points (uniform hash grid)."""

    def __init__(self, points, cell):
        self.cell, self.cells = cell, {}
        for p in points:
            self.cells.setdefault(self.key(p), []).append(p)

    def key(self, p):
        return tuple(int(math.floor(c / self.cell)) for c in p)

    def distance(self, p, reach):
        k = self.key(p)
        r = int(math.ceil(reach / self.cell))
        best = float("inf")
        for i in range(k[0] - r, k[0] + r + 1):
            for j in range(k[1] - r, k[1] + r + 1):
                for l in range(k[2] - r, k[2] + r + 1):
                    for q in self.cells.get((i, j, l), ()):
                        best = min(best, math.dist(p, q))
        return best


def run_case(build, background, triangles, margin, work):
    prefix = work / ("%s_%d" % (background, triangles))
    subprocess.run([str(build / "make-scan"), "--background", background, "--triangles", str(triangles),
                    "--seed", "7", "--out", str(prefix)], check=True, capture_output=True)
    truth = json.loads(Path(str(prefix) + ".truth.json").read_text())
    h = truth["h"]
    result = {"relief_vertices": truth["relief_vertices"], "parameters": {"step_height": h},
              "mesh": {"input_vertices": truth["vertices"]}}
    result_path = Path(str(prefix) + ".result.json")
    result_path.write_text(json.dumps(result))
    out = work / ("%s_%d_out" % (background, triangles))
    # CPU seconds of the extract command minus those of loading the same mesh ('info'): the
    # extraction's own work, which a shared machine's load does not inflate the way it does wall time.
    def cpu_of(cmd):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t = time.perf_counter()
        done = subprocess.run(cmd, capture_output=True, text=True)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        return done, after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, time.perf_counter() - t

    _, load_cpu, _ = cpu_of([str(build / "relief-snake"), "info", str(prefix) + ".ply"])
    r, extract_cpu, wall = cpu_of([str(build / "relief-snake"), "extract", str(prefix) + ".ply", str(result_path),
                                   "--out", str(out), "--quiet", "--timings"])
    if r.returncode != 0:
        return {"case": prefix.name, "error": r.stderr.strip()}
    m = re.search(r"background ([0-9.]+) s, height map ([0-9.]+) s", r.stdout)
    fill_s, map_s = float(m.group(1)), float(m.group(2))
    # Each stage's wall time: "relief-snake: timings: read result 0.012 s, load mesh 0.2 s, ..."
    t = re.search(r"timings: (.*)$", r.stdout, re.M)
    stages = {name: float(sec) for name, sec in re.findall(r"([a-z][a-z ]*?) ([0-9.]+) s", t.group(1))} if t else {}
    sidecar = json.loads((out / "height.json").read_text())

    base, _ = read_ply(out / "background.ply")
    relief_pos, relief_cols = read_ply(out / "relief.ply")
    scan_pos, _ = read_ply(str(prefix) + ".ply")
    boundary = [tuple(p) for line in truth["boundary"] for p in line]
    grid = PointGrid(boundary, 2 * h)
    R = truth["spec"].get("radius", 40)
    # Deep relief vertices: more than margin * h from the true boundary (inside the relief).
    region = set(truth["relief_vertices"])
    deep = [i for i in region if grid.distance(scan_pos[i], margin * h) > margin * h]
    base_err = [distance_to_background(background, R, base[i]) for i in deep]
    deep_points = {tuple(scan_pos[i]) for i in deep}
    height_err = [abs(hgt - h) for p, hgt in zip(relief_pos, relief_cols["height"])
                  if (float(p[0]), float(p[1]), float(p[2])) in deep_points]
    return {"case": prefix.name, "triangles": truth["triangles"], "relief_vertices": len(region),
            "scored": len(deep), "base_mean": sum(base_err) / len(base_err) / h, "base_max": max(base_err) / h,
            "height_mean": sum(height_err) / len(height_err) / h, "height_max": max(height_err) / h,
            "ring_rms": sidecar["background"]["ring_rms_residual"] / h,
            "flattening": sidecar["frame"]["flattening"],
            "angle_distortion": sidecar["frame"]["distortion"]["angle_mean"],
            "fill_seconds": fill_s, "map_seconds": map_s, "wall_seconds": wall,
            "extract_cpu_seconds": max(0.0, extract_cpu - load_cpu), "stages": stages}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default=str(ROOT / "build"))
    parser.add_argument("--triangles", default="100000,290000")
    parser.add_argument("--backgrounds", default="plane,cylinder,sphere,saddle")
    parser.add_argument("--margin", type=float, default=1.0, help="score vertices this many h inside (default 1)")
    parser.add_argument("--json", help="also write the rows here")
    args = parser.parse_args()
    build = Path(args.build)
    for tool in ("make-scan", "relief-snake"):
        if not (build / tool).is_file():
            sys.exit("extract_bench: %s not found in %s: build it first (make build)" % (tool, build))
    rows = []
    print("extraction: base and height errors in h over relief vertices > %.1f h inside; engine times" % args.margin)
    with tempfile.TemporaryDirectory(prefix="relief-snake-extract-bench-") as tmp:
        for triangles in (int(t) for t in args.triangles.split(",")):
            for background in args.backgrounds.split(","):
                row = run_case(build, background, triangles, args.margin, Path(tmp))
                rows.append(row)
                if "error" in row:
                    print("%-18s FAILED: %s" % (row["case"], row["error"]))
                    continue
                print("%-16s %7d tri %6d relief: base mean %.4f max %.4f, height mean %.4f max %.4f, ring rms %.2g, "
                      "%s (angle %.4f); fill %.3f s + map %.3f s wall, %.3f s CPU beyond loading (%s 0.5 s)"
                      % (row["case"], row["triangles"], row["relief_vertices"], row["base_mean"], row["base_max"],
                         row["height_mean"], row["height_max"], row["ring_rms"], row["flattening"],
                         row["angle_distortion"], row["fill_seconds"], row["map_seconds"],
                         row["extract_cpu_seconds"], "under" if row["extract_cpu_seconds"] < 0.5 else "OVER"))
                if row["stages"]:
                    shown = ", ".join("%s %.3f" % (k, v) for k, v in row["stages"].items() if v >= 0.0005)
                    print("%-16s   stages (s, wall): %s" % ("", shown))
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2))
    return 0 if all("error" not in r for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
