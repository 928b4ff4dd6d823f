"""Whole reliefs (issue 13): inner holes and bands between two pick rings, measured on generated scans.

    python3 -m bench.whole_reliefs [--build build] [--out bench/results/whole-reliefs] [--quick]

Generates each scan with `make-scan` (reliefs with holes: a ring and the letters O, D, A, B; bands round a
cylinder or vase with `make-scan tube`), segments it with the `relief-snake` CLI as a user would, and
scores every contour against its own truth polyline: for holes, each result hole against the nearest true
hole; for bands, each contour against its band edge. Distances are means both ways, in average edges.
Also times a plain duck with `--holes off` and `--holes auto` (the cost of the hole search when there
is no hole). Prints a markdown report and writes it with the raw rows (results.json) to --out. It
reports and never fails on a number.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy.spatial import cKDTree


def run(cmd, timeout=300):
    t0 = time.time()
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    return p, time.time() - t0


def dense(points, closed, step):
    pts = np.asarray(points, dtype=float)
    if closed:
        pts = np.vstack([pts, pts[:1]])
    out = [pts[0]]
    for a, b in zip(pts[:-1], pts[1:]):
        n = max(1, int(np.ceil(np.linalg.norm(b - a) / step)))
        t = np.arange(1, n + 1)[:, None] / n
        out.extend(a + t * (b - a))
    return np.asarray(out)


def match(contour, truth, edge):
    """Mean and max distance both ways between two closed polylines, in average edges."""
    a, b = dense(contour, True, edge / 4), dense(truth, True, edge / 8)
    to_truth = cKDTree(b).query(a)[0] / edge
    from_truth = cKDTree(dense(contour, True, edge / 8)).query(dense(truth, True, edge / 4))[0] / edge
    return {"mean_to_truth": float(to_truth.mean()), "mean_from_truth": float(from_truth.mean()),
            "max_to_truth": float(to_truth.max()), "max_from_truth": float(from_truth.max()),
            "mean": float(0.5 * (to_truth.mean() + from_truth.mean()))}


def iou(a, b):
    a, b = set(a), set(b)
    return len(a & b) / max(1, len(a | b))


def segment(build, mesh, args, out):
    cmd = [os.path.join(build, "relief-snake"), "segment", mesh, "--quiet", "--out", out] + args
    p, seconds = run(cmd)
    if p.returncode not in (0, 3):
        return None, p.stderr.strip().splitlines()[-1] if p.stderr.strip() else f"exit {p.returncode}", seconds
    with open(out) as f:
        return json.load(f), "", seconds


def hole_cases(quick):
    shapes = [("ring", []), ("holed-letter", ["--letter", "O"]), ("holed-letter", ["--letter", "D"]),
              ("holed-letter", ["--letter", "A"]), ("holed-letter", ["--letter", "B", "--stroke-width", "5"])]
    variants = [("plane", "blended", 40000, 1, []), ("cylinder", "sharp", 100000, 2, []),
                ("sphere", "blended", 60000, 3, ["--noise", "0.03"])]
    if quick:
        variants = variants[:1]
    for shape, extra in shapes:
        for background, step, triangles, seed, more in variants:
            name = f"{shape}{extra[1] if extra else ''}-{background}-{step}-{triangles // 1000}k-s{seed}"
            yield name, ["--shape", shape, *extra, "--background", background, "--step", step,
                         "--triangles", str(triangles), "--seed", str(seed), *more]


def band_cases(quick):
    variants = [("cylinder", [], "blended", 60000, 1), ("cylinder", ["--noise", "0.03"], "sharp", 150000, 2),
                ("vase", ["--vase", "0.15"], "blended", 100000, 3), ("vase", ["--vase", "0.1", "--wave", "3"], "sharp", 80000, 4),
                # engraved grooves, rings on the floor (sharp: the truth is the walls' foot on the floor)
                ("groove-cylinder", ["--h", "-1"], "sharp", 60000, 7),
                ("groove-vase", ["--h", "-1", "--vase", "0.12"], "sharp", 120000, 8)]
    if quick:
        variants = variants[:1]
    for background, extra, step, triangles, seed in variants:
        yield (f"band-{background}-{step}-{triangles // 1000}k-s{seed}",
               ["--step", step, "--triangles", str(triangles), "--seed", str(seed), *extra])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=os.environ.get("BUILD_DIR", "build"))
    ap.add_argument("--out", default="bench/results/whole-reliefs")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--auto-h", action="store_true", help="leave h to the engine (default: give the true h)")
    a = ap.parse_args(argv)
    make_scan = os.path.join(a.build, "make-scan")
    os.makedirs(a.out, exist_ok=True)
    rows = {"holes": [], "bands": [], "timing": []}
    h_args = [] if a.auto_h else ["--step-height", "1"]
    with tempfile.TemporaryDirectory() as tmp:
        for name, spec in hole_cases(a.quick):
            prefix = os.path.join(tmp, name)
            p, _ = run([make_scan, *spec, "--out", prefix])
            if p.returncode:
                rows["holes"].append({"case": name, "error": p.stderr.strip()})
                continue
            truth = json.load(open(prefix + ".truth.json"))
            result, error, seconds = segment(a.build, prefix + ".ply",
                                             ["--picks", ",".join(map(str, truth["picks"])), *h_args],
                                             prefix + ".result.json")
            row = {"case": name, "truth_holes": len(truth["holes"]), "seconds": seconds}
            if result is None:
                row["error"] = error
                rows["holes"].append(row)
                continue
            edge = truth["average_edge"]
            distances = []
            found = set()
            for hole in result["holes"]:
                scores = [match(hole, t, edge) for t in truth["holes"]]
                if not scores:
                    distances.append(None)
                    continue
                k = int(np.argmin([s["mean"] for s in scores]))
                found.add(k)
                distances.append(scores[k])
            row.update(status=result["status"], found=len(result["holes"]), matched=len(found),
                       hole_mean=[d["mean"] if d else None for d in distances],
                       hole_max=[max(d["max_to_truth"], d["max_from_truth"]) if d else None for d in distances],
                       iou=iou(result["relief_vertices"], truth["relief_vertices"]),
                       hole_seconds=result["checks"].get("hole_seconds"), reasons=result["reasons"])
            rows["holes"].append(row)
            print(name, json.dumps({k: row[k] for k in ("status", "found", "truth_holes", "hole_mean", "iou")}),
                  flush=True)
        for name, spec in band_cases(a.quick):
            prefix = os.path.join(tmp, name)
            p, _ = run([make_scan, "tube", *spec, "--out", prefix])
            if p.returncode:
                rows["bands"].append({"case": name, "error": p.stderr.strip()})
                continue
            truth = json.load(open(prefix + ".truth.json"))
            result, error, seconds = segment(a.build, prefix + ".ply",
                                             ["--picks", ",".join(map(str, truth["picks"])),
                                              "--band-picks", ",".join(map(str, truth["band_picks"])), *h_args],
                                             prefix + ".result.json")
            row = {"case": name, "seconds": seconds}
            if result is None:
                row["error"] = error
                rows["bands"].append(row)
                continue
            edge = truth["average_edge"]
            first = match(result["contour"], truth["boundary"][0], edge)
            second = match(result["band_contour"], truth["boundary"][1], edge)
            row.update(status=result["status"], first=first["mean"], second=second["mean"],
                       first_max=max(first["max_to_truth"], first["max_from_truth"]),
                       second_max=max(second["max_to_truth"], second["max_from_truth"]),
                       iou=iou(result["relief_vertices"], truth["relief_vertices"]),
                       h_used=result["step_height"]["used"], reasons=result["reasons"])
            rows["bands"].append(row)
            print(name, json.dumps({k: row[k] for k in ("status", "first", "second", "iou")}), flush=True)
        # The cost of the search on a relief without holes.
        for triangles in ([100000] if a.quick else [100000, 290000]):
            prefix = os.path.join(tmp, f"duck-{triangles}")
            run([make_scan, "--shape", "duck", "--triangles", str(triangles), "--step", "blended", "--out", prefix])
            truth = json.load(open(prefix + ".truth.json"))
            for repeat in range(2):
                for mode in ("off", "auto"):
                    result, error, seconds = segment(a.build, prefix + ".ply",
                                                     ["--picks", ",".join(map(str, truth["picks"])), "--holes", mode],
                                                     prefix + f".{mode}.json")
                    rows["timing"].append({"triangles": triangles, "holes": mode, "repeat": repeat,
                                           "segment_seconds": result["timing"]["segment_seconds"] if result else None,
                                           "hole_seconds": result["checks"].get("hole_seconds") if result else None,
                                           "holes_found": len(result["holes"]) if result else None,
                                           "error": error})
    lines = ["# Whole reliefs (issue 13)", "", f"h: {'auto' if a.auto_h else 'given (1)'}", "",
             "## Holes", "", "| case | status | holes found / true | each hole's mean distance (max), edges | IoU | s |",
             "|---|---|---|---|---|---|"]
    for r in rows["holes"]:
        if "error" in r:
            lines.append(f"| {r['case']} | error: {r['error']} | | | | |")
            continue
        each = ", ".join(f"{m:.2f} ({x:.1f})" for m, x in zip(r["hole_mean"], r["hole_max"]) if m is not None)
        lines.append(f"| {r['case']} | {r['status']} | {r['found']} / {r['truth_holes']} (matched {r['matched']}) | "
                     f"{each} | {r['iou']:.3f} | {r['seconds']:.1f} |")
    lines += ["", "## Bands", "", "| case | status | first ring mean (max) | second ring mean (max) | IoU | h used | s |",
              "|---|---|---|---|---|---|---|"]
    for r in rows["bands"]:
        if "error" in r:
            lines.append(f"| {r['case']} | error: {r['error']} | | | | | |")
            continue
        lines.append(f"| {r['case']} | {r['status']} | {r['first']:.2f} ({r['first_max']:.1f}) | "
                     f"{r['second']:.2f} ({r['second_max']:.1f}) | {r['iou']:.3f} | {r['h_used']:.3f} | {r['seconds']:.1f} |")
    lines += ["", "## The search on a relief without holes (duck, h auto)", "",
              "| triangles | holes | repeat | segment s | hole search s | holes found |", "|---|---|---|---|---|---|"]
    for r in rows["timing"]:
        lines.append(f"| {r['triangles']} | {r['holes']} | {r['repeat']} | {r['segment_seconds']} | "
                     f"{r['hole_seconds']} | {r['holes_found']} |")
    report = "\n".join(lines) + "\n"
    with open(os.path.join(a.out, "report.md"), "w") as f:
        f.write(report)
    with open(os.path.join(a.out, "results.json"), "w") as f:
        json.dump(rows, f, indent=1)
    print(report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
