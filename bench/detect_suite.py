"""Automatic detection on generated plates (issue 13, part 2b): `relief-snake detect` as a user runs it.

    python3 bench/detect_suite.py --cli build/relief-snake --make-scan build/make-scan \\
        --seeds 1:11 --backgrounds plane,cylinder,sphere [--noise 0.02] [--triangles 100000] --out DIR

For every seed and background it generates a plate (`make-scan --plate SEED`: 3 to 5 reliefs, one pair
of boxes touching at different heights, one small disk below the minimum area), runs `detect` with the
defaults, and scores the candidates against the truth per relief (vertex-count IoU):

* **found**: a truth relief of at least the minimum area whose best candidate has IoU >= 0.9;
* **missed**: such a relief without one (its best IoU is kept for the distribution);
* **false**: a candidate that overlaps no truth relief with IoU >= 0.5.

Every background is also run without reliefs (`--empty`), where any candidate is false. Prints a table
and writes DIR/detect.json (every row) and DIR/detect.md.
"""
from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path


def iou(a: list[int], b: list[int]) -> float:
    sa, sb = set(a), set(b)
    if not sa and not sb:
        return 1.0
    return len(sa & sb) / len(sa | sb)


def run_case(cli: str, make_scan: str, out: Path, seed: int, background: str, noise: float, triangles: int,
             empty: bool, radius: float, step: str = "blended") -> dict:
    name = f"plate-{seed}-{background}-{radius}-{step}-{noise}-{triangles}{'-empty' if empty else ''}"
    prefix = out / name
    cmd = [make_scan, "--plate", str(seed), "--background", background, "--noise", str(noise), "--radius", str(radius),
           "--triangles", str(triangles), "--step", step, "--out", str(prefix)] + (["--empty"] if empty else [])
    subprocess.run(cmd, check=True, capture_output=True)
    truth = json.loads(Path(f"{prefix}.truth.json").read_text())
    start = time.perf_counter()
    proc = subprocess.run([cli, "detect", f"{prefix}.ply", "--out", f"{prefix}.detect.json", "--quiet"],
                          capture_output=True, text=True)
    wall = time.perf_counter() - start
    if proc.returncode not in (0, 3):
        return {"case": name, "error": proc.stderr.strip(), "wall_seconds": wall}
    doc = json.loads(Path(f"{prefix}.detect.json").read_text())
    min_area = doc["parameters"]["min_area"]
    candidates = [c["relief_vertices"] for c in doc["candidates"]]
    matched = [False] * len(candidates)
    reliefs = []
    for r in truth["reliefs"]:
        ious = [iou(c, r["vertices"]) for c in candidates]
        for k, v in enumerate(ious):
            if v >= 0.5:
                matched[k] = True
        best = max(ious, default=0.0)
        reliefs.append({"shape": r["shape"], "h": r["h"], "area": r["area"], "touches": r["touches"],
                        "expected": r["area"] >= min_area, "best_iou": best})
    expected = [r for r in reliefs if r["expected"]]
    return {"case": name, "seed": seed, "background": background, "noise": noise, "empty": empty,
            "triangles": truth["triangles"], "min_area": min_area,
            "expected": len(expected), "found": sum(r["best_iou"] >= 0.9 for r in expected),
            "false": matched.count(False), "ious": [r["best_iou"] for r in expected], "reliefs": reliefs,
            "statuses": [c["status"] for c in doc["candidates"]],
            "detect_seconds": doc["timing"]["detect_seconds"], "load_seconds": doc["timing"]["load_seconds"],
            "wall_seconds": wall}


def seeds_of(text: str) -> list[int]:
    if ":" in text:
        a, b = text.split(":")
        return list(range(int(a), int(b)))
    return [int(s) for s in text.split(",")]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default="build/relief-snake")
    ap.add_argument("--make-scan", default="build/make-scan")
    ap.add_argument("--seeds", default="1:11")
    ap.add_argument("--backgrounds", default="plane,cylinder,sphere")
    ap.add_argument("--noise", type=float, default=0.0, help="absolute noise sigma (mesh units)")
    ap.add_argument("--radius", type=float, default=120)
    ap.add_argument("--triangles", type=int, default=100000)
    ap.add_argument("--step", default="blended", choices=["blended", "sharp"])
    ap.add_argument("--no-empty", action="store_true", help="skip the plates without reliefs")
    ap.add_argument("--out", default="bench/results/detect")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for background in args.backgrounds.split(","):
        for seed in seeds_of(args.seeds):
            rows.append(run_case(args.cli, args.make_scan, out, seed, background, args.noise, args.triangles, False,
                                 args.radius, args.step))
            print(json.dumps({k: rows[-1].get(k) for k in ("case", "expected", "found", "false", "detect_seconds",
                                                           "error")}), file=sys.stderr)
        if not args.no_empty:
            for seed in seeds_of(args.seeds)[:3]:
                rows.append(run_case(args.cli, args.make_scan, out, seed, background, args.noise, args.triangles,
                                     True, args.radius, args.step))
                print(json.dumps({k: rows[-1].get(k) for k in ("case", "false", "detect_seconds", "error")}),
                      file=sys.stderr)
    lines = ["| background | plates | reliefs expected | found (IoU >= 0.9) | missed | false | IoU min / median | "
             "detect s median / max |", "|---|---|---|---|---|---|---|---|"]
    for background in args.backgrounds.split(","):
        for empty in (False, True):
            sel = [r for r in rows if r.get("background") == background and r.get("empty") == empty]
            if not sel:
                continue
            exp = sum(r["expected"] for r in sel)
            found = sum(r["found"] for r in sel)
            ious = [v for r in sel for v in r["ious"]]
            secs = [r["detect_seconds"] for r in sel]
            lines.append(f"| {background}{' (no relief)' if empty else ''} | {len(sel)} | {exp} | {found} | "
                         f"{exp - found} | {sum(r['false'] for r in sel)} | "
                         f"{(min(ious) if ious else float('nan')):.3f} / "
                         f"{(statistics.median(ious) if ious else float('nan')):.3f} | "
                         f"{statistics.median(secs):.2f} / {max(secs):.2f} |")
    errors = [r for r in rows if "error" in r]
    report = "\n".join(lines) + "\n" + (f"\n{len(errors)} runs failed: {errors}\n" if errors else "")
    report += (f"\nnoise sigma {args.noise}, {args.triangles} triangles, radius {args.radius}, {args.step} steps, "
               f"seeds {args.seeds}\n")
    print(report)
    (out / "detect.md").write_text(report)
    (out / "detect.json").write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
