#!/usr/bin/env python3
"""Relief Snake benchmark (issue 4): accuracy, sensitivity, speed and memory on generated scans.

Run through `make bench` (scripts/bench.sh builds relief-snake and make-scan and installs
matplotlib/numpy first), or directly:

    python3 bench/run_bench.py --build-dir build [--out bench/results] [--jobs 2] [--quick]

It generates every scan with `make-scan` (exact ground truth), segments it with the
`relief-snake` CLI as a user would, scores it with `make-scan score`, and writes
`report.md` plus PNG plots to the output folder. It is a benchmark, not a test: it
reports every number it measures and never fails on one. A case whose engine run fails
(non-zero exit, collapse, timeout) becomes a row with the error message.

Sections:
  * suite: the situations the paper claims (Figure 6 duck analogue at ~290k triangles,
    far and zigzag starts, curved backgrounds, sharp/blended steps, a drop inside the
    edge, an open noisy contour, the decimated duck, slots of mouth 2..8 average edges),
    each run with the default options, the paper's method (PAPER) and one-change variants;
  * sensitivity (the ~290k Figure 6 duck, for SWEEP_CONFIGS): h factor, W_int, noise;
  * speed and memory: the ~290k duck per phase beside the paper's Figure 6, and a scaling
    series 50k..2M triangles (run one at a time so timings are not shared with another run).

Timing is the engine's `timing.segment_seconds` (mesh already loaded); `timing.load_seconds`
(file parsing) is reported separately. Peak memory is the child's ru_maxrss, which includes
parsing the file and holding the result JSON, not only the engine.
"""
from __future__ import annotations

import argparse
import concurrent.futures as futures
import datetime as dt
import json
import math
import os
import platform
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

# --- what the paper reports (Section 8.1, Figure 6: 287,446 triangles, average edge
# 0.21 mm, h = 1.0 mm, 2.4 GHz CPU with 1 GB RAM) ---------------------------------------
PAPER_FIG6 = {
    "triangles": 287446,
    "average_edge_over_h": 0.21,
    "phases": {  # name: (iterations, snaxels at the end, seconds)
        "preprocess": (None, None, None),  # not reported separately in the paper
        "coarse": (131, 175, 21.0),
        "refine": (459, 1136, 60.0),
        "stabilise": (94, None, 10.0),
    },
    "total_seconds": 91.0,
}

# Targets of issue 4 (printed beside the measurements; nothing fails on them).
TARGET_MEAN, TARGET_P95, TARGET_IOU = 0.5, 1.5, 0.97
TARGET_290K_S, TARGET_1M_S, TARGET_2M_MB = 1.0, 3.0, 1024.0

# The paper's method as printed: every option that departs from it switched off (explicitly,
# so the variant stays the paper's whatever the engine's defaults are). Readings where the
# paper is silent (where resampled snaxels go, when a phase has converged) are not options.
PAPER = ["neighbourhood=geodesic", "plane_fit=vertices", "planarity_one_ring=0", "remove_loops=0", "exact_q=0",
         "convex_barrier=0"]

# Variants measured side by side on the suite (docs/design.md, "Departures from the paper").
# "default" is the engine's defaults; "paper" is PAPER; the others change one or two things
# against the paper's planarity (geodesic ball, vertex fit) with the engine's other defaults.
# Add a variant here: one line.
VARIANTS = [
    ("default", []),
    ("paper", PAPER),
    ("geodesic", ["neighbourhood=geodesic", "plane_fit=vertices"]),
    ("geodesic-no-one-ring", ["neighbourhood=geodesic", "plane_fit=vertices", "planarity_one_ring=0"]),
    ("geodesic-no-loop-removal", ["neighbourhood=geodesic", "plane_fit=vertices", "remove_loops=0"]),
    ("geodesic-walk-resampling", ["neighbourhood=geodesic", "plane_fit=vertices", "nearest_resampling=0"]),
    ("geodesic-exact-q", ["neighbourhood=geodesic", "plane_fit=vertices", "exact_q=1"]),
    ("geodesic-area", ["neighbourhood=geodesic", "plane_fit=area"]),
    ("geodesic-vertex-areas", ["neighbourhood=geodesic", "plane_fit=vertex_areas"]),
    ("euclidean", ["neighbourhood=euclidean", "plane_fit=vertices"]),
    ("euclidean-vertex-areas", ["neighbourhood=euclidean", "plane_fit=vertex_areas"]),
    ("sphere", ["neighbourhood=sphere", "plane_fit=vertices"]),
    ("sphere-vertex-areas", ["neighbourhood=sphere", "plane_fit=vertex_areas"]),
    ("sphere-area", ["neighbourhood=sphere", "plane_fit=area"]),
    ("coarse-to-fine", ["refine_levels=0"]),
    ("foot-snap", ["foot_snap=1"]),
    ("foot-snap+coarse-to-fine", ["foot_snap=1", "refine_levels=0"]),
    ("convex-barrier", ["convex_barrier=1"]),
]

# The sensitivity sweeps run for these configurations.
SWEEP_CONFIGS = [("default", []), ("paper", PAPER), ("foot-snap", ["foot_snap=1"])]


@dataclass
class Scan:
    """A make-scan invocation; generated once, shared by every run that needs it."""
    key: str
    args: list[str]
    prefix: Path | None = None
    truth: dict | None = None
    summary: dict | None = None
    error: str | None = None
    lock: threading.Lock = field(default_factory=threading.Lock)


@dataclass
class Case:
    name: str
    scan: str            # key into the scan table
    what: str            # what it exercises
    h_factor: float = 1.0
    w_int: float | None = None
    options: list[str] = field(default_factory=list)


def scan_args(shape="duck", triangles=150000, step="blended", background="plane", start="near",
              noise=0.0, drop=False, slots=None):
    args = ["--shape", shape, "--triangles", str(triangles), "--step", step, "--background", background,
            "--start", start, "--seed", "1"]
    if noise:
        args += ["--noise", repr(noise)]
    if drop:
        args += ["--drop"]
    if slots:
        args += ["--slots", ",".join(str(s) for s in slots)]
    return args


SLOT_WIDTHS = [2, 3, 4, 6, 8]
SLOTS_MIN_IOU = 0.9  # below this the slots case failed as a whole; per-slot "entered" means nothing
POOL_THREADS = 1  # engine threads per run in the accuracy/sensitivity pool


def suite_scans(quick: bool):
    big = 120000 if quick else 290000
    mid = 60000 if quick else 150000
    small = 40000 if quick else 100000
    return {
        "duck-290k": scan_args(triangles=big),
        "duck-290k-sharp": scan_args(triangles=big, step="sharp"),
        "duck-47k": scan_args(triangles=47000),
        "duck-far": scan_args(triangles=mid, start="far"),
        "duck-zigzag": scan_args(triangles=mid, start="zigzag"),
        "duck-cylinder": scan_args(triangles=mid, background="cylinder"),
        "duck-sphere": scan_args(triangles=mid, background="sphere"),
        "duck-saddle": scan_args(triangles=mid, background="saddle"),
        "rectangle-sharp": scan_args(shape="rectangle", triangles=small, step="sharp"),
        "disk-blended": scan_args(shape="disk", triangles=small),
        "duck-drop": scan_args(triangles=mid, drop=True),
        "open-noisy": scan_args(shape="open", triangles=small, noise=0.03),
        "slots": scan_args(shape="slots", triangles=mid, slots=SLOT_WIDTHS),
    }


SUITE = [
    Case("duck-fig6", "duck-290k", "Figure 6 analogue: deep concavity, blended step, near start"),
    Case("duck-sharp", "duck-290k-sharp", "same duck with a sharp step (one triangle wide)"),
    Case("duck-47k", "duck-47k", "the duck decimated to ~47k triangles (Figure 8(b) analogue)"),
    Case("duck-far", "duck-far", "start contour far from the relief"),
    Case("duck-zigzag", "duck-zigzag", "zigzag start contour (Figure 7(a))"),
    Case("duck-cylinder", "duck-cylinder", "cylinder background (curved one way, zero Gaussian curvature)"),
    Case("duck-sphere", "duck-sphere", "sphere background (positive Gaussian curvature)"),
    Case("duck-saddle", "duck-saddle", "saddle background (negative Gaussian curvature)"),
    Case("rectangle-sharp", "rectangle-sharp", "sharp step with sharp corners"),
    Case("disk-blended", "disk-blended", "blended step, convex outline"),
    Case("duck-drop", "duck-drop", "relief drops to 0.3 h within 1.5 h inside its edge"),
    Case("open-noisy", "open-noisy", "open contour ending on the mesh boundary, noise sigma 0.03 h"),
    Case("slots", "slots", "slots of mouth 2, 3, 4, 6, 8 average edges, depth 5 h"),
]

H_FACTORS = [0.3, 0.45, 0.6, 0.7, 0.8, 0.9, 1.0, 1.2, 1.4, 1.6, 1.8, 2.0]
W_INTS = [0.125, 0.25, 0.5, 0.75, 1.0]
NOISES = [0.0, 0.02, 0.04, 0.06, 0.08, 0.09, 0.1]
SCALING = [50000, 100000, 200000, 290000, 500000, 1000000, 2000000]


PROGRESS = re.compile(r"^relief-snake: (\w+)\s+iteration\s+(\d+),\s+(\d+) snaxels")
RUNAWAY_FACTOR = 8


def runaway_limit(truth):
    """Snaxel count beyond which a run is a runaway: RUNAWAY_FACTOR x the snaxels the true
    outline needs at the refinement spacing (half an average edge), and at least 4000."""
    length = 0.0
    for line in truth["boundary"]:
        for a, b in zip(line, line[1:]):
            length += math.dist(a, b)
    expected = int(length / (0.5 * truth["average_edge"]))
    return max(4000, RUNAWAY_FACTOR * expected), expected


def log(*args):
    print("bench:", *args, file=sys.stderr, flush=True)


# --- running the tools ---------------------------------------------------------------

class Runner:
    def __init__(self, build_dir: Path, work: Path, timeout: float):
        self.cli = build_dir / "relief-snake"
        self.make_scan = build_dir / "make-scan"
        for exe in (self.cli, self.make_scan):
            if not exe.is_file():
                raise SystemExit(f"bench: {exe} not found; build the relief-snake and make-scan targets")
        self.work = work
        self.timeout = timeout
        self.scans: dict[str, Scan] = {}
        self.counter = 0
        self.counter_lock = threading.Lock()

    def add_scan(self, key, args):
        if key not in self.scans:
            self.scans[key] = Scan(key, args)

    def scan(self, key) -> Scan:
        s = self.scans[key]
        with s.lock:
            if s.prefix is None and s.error is None:
                prefix = self.work / key
                r = subprocess.run([str(self.make_scan), *s.args, "--out", str(prefix)], capture_output=True,
                                   text=True)
                if r.returncode != 0:
                    s.error = "make-scan failed: " + (r.stderr.strip().splitlines() or ["?"])[-1]
                else:
                    s.summary = json.loads(r.stdout)
                    s.truth = json.loads(Path(f"{prefix}.truth.json").read_text())
                    s.prefix = prefix
        return s

    def drop_scan(self, key):
        s = self.scans[key]
        with s.lock:
            if s.prefix is not None:
                for suffix in (".ply", ".truth.json"):
                    Path(f"{s.prefix}{suffix}").unlink(missing_ok=True)
                s.prefix, s.truth = None, None
                s.error = "dropped"

    def segment(self, scan: Scan, h_factor=1.0, w_int=None, options=()):
        """Runs relief-snake segment; returns a row dict (never raises for engine failures)."""
        row = {"ok": False, "error": None, "status": None, "phases": [], "options": list(options),
               "h_factor": h_factor, "w_int": w_int}
        if scan.error:
            row["error"] = scan.error
            return row
        truth = scan.truth
        row.update(triangles=truth["triangles"], vertices=truth["vertices"],
                   average_edge=truth["average_edge"], h=truth["h"])
        with self.counter_lock:
            self.counter += 1
            tag = self.counter
        out = self.work / f"result-{tag}.json"
        cmd = [str(self.cli), "segment", f"{scan.prefix}.ply", "--picks", ",".join(map(str, truth["picks"])),
               "--step-height", repr(h_factor * truth["h"]), "--out", str(out)]
        if w_int is not None:
            cmd += ["--w-int", repr(w_int)]
        if not truth.get("picks_closed", True):
            cmd += ["--open", "--relief-side", truth.get("relief_side", "left")]
        for o in options:
            cmd += ["--option", o]
        row["command"] = " ".join(Path(c).name if i == 0 else c for i, c in enumerate(cmd))
        # Progress lines on stderr ("relief-snake: refine  iteration 1050, 24899 snaxels") let us
        # stop a runaway snake (a reversed loop that deflation inflates without bound) early
        # instead of waiting for the iteration cap: more than `limit` snaxels is reported as such.
        limit, expected = runaway_limit(truth)
        start = time.monotonic()
        p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, errors="replace")
        killed = {"why": None}
        tail = []

        def kill(why):
            if killed["why"] is None:
                killed["why"] = why
                try:
                    os.kill(p.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass

        def read():
            for line in p.stderr:
                line = line.rstrip("\n")
                tail.append(line)
                del tail[:-5]
                m = PROGRESS.match(line)
                if m and int(m.group(3)) > limit:
                    kill(f"runaway: the snake grew to {int(m.group(3)):,} snaxels in the {m.group(1)} phase "
                         f"(iteration {m.group(2)}; the true outline needs ~{expected:,}); killed")

        reader = threading.Thread(target=read, daemon=True)
        reader.start()
        timer = threading.Timer(self.timeout, lambda: kill(f"timeout after {self.timeout:.0f} s; killed"))
        timer.start()
        _, status, usage = os.wait4(p.pid, 0)
        timer.cancel()
        p.returncode = os.waitstatus_to_exitcode(status)
        reader.join()
        p.stderr.close()
        row["wall_seconds"] = time.monotonic() - start
        row["peak_mb"] = usage.ru_maxrss / 1024.0  # Linux: kilobytes
        row["exit_code"] = p.returncode
        stderr = "\n".join(tail)
        if killed["why"]:
            row["error"] = killed["why"]
            out.unlink(missing_ok=True)
            return row
        if p.returncode != 0:
            row["error"] = (stderr.splitlines() or [f"exit code {p.returncode}"])[-1]
            out.unlink(missing_ok=True)
            return row
        try:
            result = json.loads(out.read_text())
        except (OSError, ValueError) as e:
            row["error"] = f"unreadable result: {e}"
            return row
        row["status"] = result.get("status")
        row["phases"] = result.get("phases", [])
        row["load_seconds"] = result["timing"]["load_seconds"]
        row["engine_seconds"] = result["timing"]["segment_seconds"]
        row["planarity_vertices"] = result.get("planarity_vertices")
        row["snaxels"] = len(result.get("contour", []))
        row["parameters"] = result.get("parameters", {})
        row["notes"] = result.get("notes", [])
        sc = subprocess.run([str(self.make_scan), "score", f"{scan.prefix}.truth.json", str(out)],
                            capture_output=True, text=True)
        if sc.returncode != 0:
            row["error"] = "scoring failed: " + (sc.stderr.strip().splitlines() or ["?"])[-1]
        else:
            row["score"] = json.loads(sc.stdout)
            row["ok"] = True
        if "slots" in truth:
            found = set(result.get("relief_vertices", []))
            row["slots"] = []
            for slot in truth["slots"]:
                verts = slot["vertices"]
                uncovered = sum(1 for v in verts if v not in found) / len(verts) if verts else float("nan")
                row["slots"].append({"width_edges": slot["width_edges"], "width": slot["width"],
                                     "vertices": len(verts), "uncovered": uncovered})
        out.unlink(missing_ok=True)
        return row


# --- formatting ------------------------------------------------------------------------

def f(x, digits=2):
    if x is None:
        return "—"
    if isinstance(x, float) and x != x:
        return "n/a"
    return f"{x:.{digits}f}"


def mark(ok):
    return "yes" if ok else "**no**"


def meets(row):
    s = row.get("score")
    if not row.get("ok") or not s:
        return False
    return (s["mean_to_truth"] <= TARGET_MEAN and s["mean_from_truth"] <= TARGET_MEAN and
            s["p95_to_truth"] <= TARGET_P95 and s["p95_from_truth"] <= TARGET_P95 and s["iou"] >= TARGET_IOU)


def accuracy_cells(row):
    if not row.get("ok"):
        return ["FAILED", "—", "—", "—", "—", "—"]
    s = row["score"]
    return [row["status"], f(s["iou"], 3), f(s["mean_to_truth"]), f(s["p95_to_truth"]), f(s["mean_from_truth"]),
            f(s["p95_from_truth"])]


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(lines)


def phase(row, name):
    for p in row.get("phases", []):
        if p["name"] == name:
            return p
    return None


def machine_info():
    model = platform.processor() or "?"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    mem = "?"
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal"):
                mem = f"{int(line.split()[1]) / 1024 / 1024:.1f} GB"
    except OSError:
        pass

    def git(*args):
        r = subprocess.run(["git", *args], cwd=REPO, capture_output=True, text=True)
        return r.stdout.strip() if r.returncode == 0 else "?"

    commit = git("rev-parse", "HEAD")
    dirty = git("status", "--porcelain", "--untracked-files=no")
    return {"cpu": model, "cores": os.cpu_count(), "memory": mem, "os": platform.platform(),
            "python": platform.python_version(), "commit": commit,
            "dirty": bool(dirty) and dirty != "?", "dirty_files": dirty.splitlines() if dirty != "?" else []}


# --- plots ----------------------------------------------------------------------------

def plot_sweep(plt, path, rows, xkey, xlabel, title, xmark=None):
    """IoU (left axis) and both mean distances (right axis, log) against x, one line style per
    sweep configuration (solid: the first, usually the engine's defaults)."""
    fig, ax1 = plt.subplots(figsize=(7.5, 5))
    ax2 = ax1.twinx()
    styles = ["-", "--", ":", "-."]
    configs = [c for c, _ in SWEEP_CONFIGS if any(r.get("config") == c for r in rows)]
    tops = [1.0]
    for ci, cname in enumerate(configs):
        mine = sorted((r for r in rows if r.get("config") == cname), key=lambda r: r[xkey])
        ok = [r for r in mine if r.get("ok")]
        bad = [r for r in mine if not r.get("ok")]
        ls = styles[ci % len(styles)]
        xs = [r[xkey] for r in ok]
        ax1.plot(xs, [r["score"]["iou"] for r in ok], "o" + ls, color="tab:blue", label=f"IoU ({cname})")
        ax2.plot(xs, [r["score"]["mean_to_truth"] for r in ok], "s" + ls, color="tab:red",
                 label=f"mean dist contour→truth ({cname})")
        ax2.plot(xs, [r["score"]["mean_from_truth"] for r in ok], "^" + ls, color="tab:orange",
                 label=f"mean dist truth→contour ({cname})")
        if bad:
            ax1.plot([r[xkey] for r in bad], [0.0] * len(bad), "kx" if ci == 0 else "k+", markersize=10,
                     label=f"failed run ({cname})")
        tops += [r["score"]["mean_to_truth"] for r in ok] + [r["score"]["mean_from_truth"] for r in ok]
    ax1.axhline(TARGET_IOU, color="tab:blue", lw=0.8, alpha=0.5)
    ax2.axhline(TARGET_MEAN, color="tab:red", lw=0.8, alpha=0.5)
    if xmark is not None:
        ax1.axvline(xmark, color="gray", lw=0.8, ls="--")
    ax1.set_xlabel(xlabel)
    ax1.set_ylabel("IoU (line: target 0.97)", color="tab:blue")
    ax2.set_ylabel("mean distance, average edges, log (line: target 0.5)", color="tab:red")
    ax1.set_ylim(0, 1.02)
    ax2.set_yscale("log")
    ax2.set_ylim(0.1, max(tops) * 1.5)
    h1, l1 = ax1.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax1.legend(h1 + h2, l1 + l2, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, fontsize=7)
    ax1.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_scaling(plt, path, rows):
    ok = [r for r in rows if r.get("ok") or r.get("engine_seconds") is not None]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    n = [r["triangles"] for r in ok]
    if ok:
        ax1.loglog(n, [r["engine_seconds"] for r in ok], "o-", label="engine total (excl. file reading)")
        ax1.loglog(n, [r["load_seconds"] for r in ok], "s--", label="file reading (load_seconds)")
        # Linear reference through the smallest point.
        ax1.loglog([n[0], n[-1]], [ok[0]["engine_seconds"], ok[0]["engine_seconds"] * n[-1] / n[0]], ":",
                   color="gray", label="linear growth from the first point")
    ax1.plot([290000], [TARGET_290K_S], "r*", markersize=12, label="targets (290k ≤ 1 s, 1M ≤ 3 s)")
    ax1.plot([1000000], [TARGET_1M_S], "r*", markersize=12)
    ax1.set_xlabel("triangles")
    ax1.set_ylabel("seconds")
    ax1.set_title("time vs mesh size (duck, blended step)")
    ax1.legend(fontsize=8)
    ax1.grid(True, which="both", alpha=0.3)
    all_rows = [r for r in rows if r.get("peak_mb")]
    ax2.loglog([r["triangles"] for r in all_rows], [r["peak_mb"] for r in all_rows], "o-",
               label="peak RSS of relief-snake (includes file parsing)")
    ax2.plot([2000000], [TARGET_2M_MB], "r*", markersize=12, label="target: ≤ 1 GB at 2M")
    ax2.set_xlabel("triangles")
    ax2.set_ylabel("MB")
    ax2.set_title("peak memory vs mesh size")
    ax2.legend(fontsize=8)
    ax2.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_phases(plt, path, row):
    names = ["preprocess", "coarse", "refine", "stabilise"]
    ours = [(phase(row, n) or {}).get("seconds", 0) for n in names]
    paper = [PAPER_FIG6["phases"][n][2] or 0 for n in names]
    fig, ax = plt.subplots(figsize=(7, 4))
    x = range(len(names))
    ax.bar([i - 0.2 for i in x], paper, 0.4, label=f"paper (2.4 GHz, total {PAPER_FIG6['total_seconds']:.0f} s)")
    ax.bar([i + 0.2 for i in x], ours, 0.4, label=f"ours (total {row.get('engine_seconds', 0):.2f} s)")
    ax.set_yscale("symlog", linthresh=0.1)
    ax.set_xticks(list(x), names)
    ax.set_ylabel("seconds (symlog)")
    ax.set_title(f"Figure 6 analogue ({row.get('triangles', 0):,} triangles): seconds per phase")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# --- the bench -------------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build-dir", default=os.environ.get("BUILD_DIR", "build"))
    ap.add_argument("--out", default=str(REPO / "bench" / "results"))
    ap.add_argument("--jobs", type=int, default=int(os.environ.get("BENCH_JOBS", "2")),
                    help="parallel runs for the accuracy and sensitivity sections (speed runs alone)")
    ap.add_argument("--timeout", type=float, default=float(os.environ.get("BENCH_TIMEOUT", "600")),
                    help="seconds before one engine run is killed and reported as a failure")
    ap.add_argument("--repeats", type=int, default=3,
                    help="speed runs per size up to 1M triangles (the median is reported; 2M runs once)")
    ap.add_argument("--quick", action="store_true", help="smaller meshes and sweeps, for trying the bench out")
    ap.add_argument("--keep-scans", action="store_true", help="keep the generated scans in OUT/scans")
    args = ap.parse_args()

    t_start = time.monotonic()
    started = dt.datetime.now().astimezone()
    load_start = os.getloadavg()
    build_dir = Path(args.build_dir)
    if not build_dir.is_absolute():
        build_dir = REPO / build_dir
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for old in list(out.glob("*.png")) + [out / "report.md", out / "results.json"]:
        old.unlink(missing_ok=True)
    work = out / "scans" if args.keep_scans else Path(tempfile.mkdtemp(prefix="relief-bench-"))
    work.mkdir(parents=True, exist_ok=True)
    runner = Runner(build_dir, work, args.timeout)

    quick = args.quick
    h_factors = [0.3, 0.6, 1.0, 1.4, 2.0] if quick else H_FACTORS
    w_ints = [0.125, 0.25, 1.0] if quick else W_INTS
    noises = [0.0, 0.05, 0.1] if quick else NOISES
    scaling = [50000, 100000, 290000] if quick else SCALING
    sens_triangles = 120000 if quick else 290000  # the Figure 6 analogue: the paper's h range is for it

    for key, a in suite_scans(quick).items():
        runner.add_scan(key, a)
    for nz in noises:
        if nz:
            runner.add_scan(f"sens-noise-{nz}", scan_args(triangles=sens_triangles, noise=nz))
    big_key = "duck-290k"
    for n in scaling:
        key = big_key if n == 290000 and not quick else f"scale-{n}"
        runner.add_scan(key, scan_args(triangles=n))

    results = {"suite": {}, "sens_h": [], "sens_wint": [], "sens_noise": [], "scaling": [], "fig6_speed": None}

    # 1. Speed and memory first, one run at a time: the scaling series (duck, blended, near
    # start); the ~290k point is the Figure 6 analogue's speed run.
    log(f"speed: scaling series {', '.join(f'{n // 1000}k' for n in scaling)} (one run at a time)")
    for n in scaling:
        key = big_key if n == 290000 and not quick else f"scale-{n}"
        t0 = time.monotonic()
        s = runner.scan(key)
        # Repeat the smaller sizes and keep the run with the median engine time (timings on a
        # shared machine vary); results are deterministic, only the seconds differ.
        runs = [runner.segment(s) for _ in range(args.repeats if n <= 1000000 else 1)]
        timed = sorted((r for r in runs if r.get("engine_seconds") is not None), key=lambda r: r["engine_seconds"])
        row = timed[len(timed) // 2] if timed else runs[0]
        row["engine_seconds_all"] = [r["engine_seconds"] for r in runs if r.get("engine_seconds") is not None]
        row["scan_key"] = key
        results["scaling"].append(row)
        if key == big_key:
            results["fig6_speed"] = row
        elif n >= 500000:
            runner.drop_scan(key)  # free disk: big scans are used once
        log(f"  {n:>8} triangles: {'ok' if row['ok'] else 'FAILED: ' + str(row['error'])}, engine "
            f"{f(row.get('engine_seconds'))} s, load {f(row.get('load_seconds'))} s, peak {f(row.get('peak_mb'), 0)} MB"
            f" ({time.monotonic() - t0:.0f} s with generation)")

    # 2. Accuracy suite x variants, and the sensitivity sweeps, in a pool.
    jobs = []
    for case in SUITE:
        for vname, vopts in VARIANTS:
            if (case.name, vname) in results["suite"]:
                continue
            jobs.append(("suite", (case.name, vname), case.scan, dict(h_factor=case.h_factor, w_int=case.w_int,
                                                                     options=case.options + vopts)))
    for cname, copts in SWEEP_CONFIGS:
        for hf in h_factors:
            jobs.append(("sens_h", (cname, hf), "duck-290k", dict(h_factor=hf, options=copts)))
        for w in w_ints:
            jobs.append(("sens_wint", (cname, w), "duck-290k", dict(w_int=w, options=copts)))
        for nz in noises:
            jobs.append(("sens_noise", (cname, nz), f"sens-noise-{nz}" if nz else "duck-290k", dict(options=copts)))
    log(f"accuracy: {len(jobs)} runs ({len(SUITE)} cases x {len(VARIANTS)} variants, sensitivity sweeps), "
        f"{args.jobs} at a time")

    def do(job):
        section, key, scan_key, kw = job
        # Two runs at a time, each on one thread (results do not depend on the thread count;
        # docs/design.md), so their seconds are single-thread times without contention.
        kw = dict(kw, options=list(kw.get("options", [])) + [f"threads={POOL_THREADS}"])
        row = runner.segment(runner.scan(scan_key), **kw)
        row["scan_key"] = scan_key
        return section, key, row

    done = 0
    with futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        for section, key, row in pool.map(do, jobs):
            done += 1
            if section == "suite":
                results["suite"][key] = row
                label = f"{key[0]} [{key[1]}]"
            else:
                row["config"], row["x"] = key
                results[section].append(row)
                label = f"{section} {key[0]} {key[1]}"
            sc = row.get("score") or {}
            log(f"  {done}/{len(jobs)} {label}: " +
                (f"{row['status']} IoU {f(sc.get('iou'), 3)} mean {f(sc.get('mean_to_truth'))}/"
                 f"{f(sc.get('mean_from_truth'))} engine {f(row.get('engine_seconds'))} s" if row["ok"]
                 else f"FAILED: {row['error']}"))

    wall = time.monotonic() - t_start
    if not args.keep_scans:
        shutil.rmtree(work, ignore_errors=True)

    # 3. Plots and report.
    plots = []
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        plot_sweep(plt, out / "sensitivity_h.png", results["sens_h"], "x", "h given / true step height",
                   f"Accuracy vs h (duck, {sens_triangles // 1000}k triangles, blended)", xmark=1.0)
        # (each sweep: the engine's defaults and the paper's method, see SWEEP_CONFIGS)
        plot_sweep(plt, out / "sensitivity_wint.png", results["sens_wint"], "x", "W_int (refinement)",
                   f"Accuracy vs W_int (duck, {sens_triangles // 1000}k triangles)", xmark=0.25)
        plot_sweep(plt, out / "sensitivity_noise.png", results["sens_noise"], "x",
                   "noise sigma / h (Gaussian, along the normal)",
                   f"Accuracy vs noise (duck, {sens_triangles // 1000}k triangles)")
        plot_scaling(plt, out / "scaling.png", results["scaling"])
        fig6 = results.get("fig6_speed") or results["suite"].get(("duck-fig6", "default"))
        if fig6 and fig6.get("phases"):
            plot_phases(plt, out / "fig6_phases.png", fig6)
        plots = sorted(p.name for p in out.glob("*.png"))
    except Exception as e:  # a missing matplotlib must not lose the report
        log(f"plots skipped: {e!r}")
        plots_error = repr(e)
    else:
        plots_error = None

    report = write_report(results, machine_info(), started, wall, load_start, os.getloadavg(), build_dir, quick,
                          dict(h_factors=h_factors, w_ints=w_ints, noises=noises, scaling=scaling,
                               sens_triangles=sens_triangles), plots, plots_error, args.jobs)
    (out / "report.md").write_text(report)
    serial = {k: ({f"{kk[0]}/{kk[1]}": vv for kk, vv in v.items()} if k == "suite" else v) for k, v in results.items()}
    (out / "results.json").write_text(json.dumps(serial, indent=1, default=str))
    log(f"wrote {out / 'report.md'} and {len(plots)} plots in {wall / 60:.1f} min")
    return 0


def write_report(results, machine, started, wall, load_start, load_end, build_dir, quick, sweeps, plots,
                 plots_error, jobs):
    suite = results["suite"]
    L = []
    L.append("# Relief Snake benchmark")
    L.append("")
    L.append("Generated by `make bench` (`bench/run_bench.py`). Every number below was measured in this run; "
             "the paper's numbers are quoted from its Section 8.1. A benchmark, not a test: nothing here fails.")
    if quick:
        L.append("")
        L.append("**QUICK MODE** (`--quick`): smaller meshes and sweeps; not the reference suite.")
    L.append("")
    L.append("## Machine and run")
    L.append("")
    dirty = " (working tree had uncommitted changes: " + ", ".join(
        d.strip() for d in machine["dirty_files"][:12]) + ")" if machine["dirty"] else ""
    L.append(table(["what", "value"], [
        ["date", started.strftime("%Y-%m-%d %H:%M %Z")],
        ["git commit", f"`{machine['commit']}`{dirty}"],
        ["CPU", f"{machine['cpu']}, {machine['cores']} cores (as seen by the OS)"],
        ["memory", machine["memory"]],
        ["OS / Python", f"{machine['os']} / {machine['python']}"],
        ["binaries", f"`{build_dir}/relief-snake`, `{build_dir}/make-scan` (CMake Release)"],
        ["bench wall time", f"{wall:.0f} s ({wall / 60:.1f} min), scans generated included, build excluded"],
        ["load average (1 min) at start / end", f"{load_start[0]:.2f} / {load_end[0]:.2f}"],
        ["parallelism", f"speed section: one run at a time, engine threads = all cores (its default); "
                        f"accuracy and sensitivity: {jobs} runs at a time, each with `--option threads={POOL_THREADS}` "
                        "(single-thread seconds; results do not depend on the thread count)"],
    ]))
    L.append("")
    L.append("Units: distances are in average edge lengths of the scan's mesh (`make-scan score`); the contour "
             "is resampled every 1/4 edge and compared with the dense true boundary at the foot of the step, "
             "both ways (contour→truth and truth→contour). IoU is over the relief vertex sets. "
             "*Engine seconds* = `timing.segment_seconds` of the CLI (mesh already in memory); file reading "
             "(`timing.load_seconds`) is listed separately. *Peak MB* = ru_maxrss of the `relief-snake` "
             "process, which **includes parsing the file** and building the result JSON.")
    L.append("")

    # Targets.
    fig6 = results.get("fig6_speed") or suite.get(("duck-fig6", "default"), {})
    scaling = results["scaling"]

    def at(n):
        for r in scaling:
            if r.get("triangles") and abs(r["triangles"] - n) / n < 0.02:
                return r
        return None

    r1m, r2m = at(1000000), at(2000000)
    default_rows = [suite[(c.name, "default")] for c in SUITE if (c.name, "default") in suite]
    n_meet = sum(meets(r) for r in default_rows)
    tol = tolerance_range([r for r in results["sens_h"] if r.get("config") == "default"])
    tol_paper = tolerance_range([r for r in results["sens_h"] if r.get("config") == "paper"])
    tol_foot = tolerance_range([r for r in results["sens_h"] if r.get("config") == "foot-snap"])
    slots_row = suite.get(("slots", "default"))
    entered = None
    slots_valid = bool(slots_row and slots_row.get("ok") and slots_row["score"]["iou"] >= SLOTS_MIN_IOU)
    if slots_valid and slots_row.get("slots"):
        widths_in = [s["width_edges"] for s in slots_row["slots"] if s["uncovered"] >= 0.5]
        entered = min(widths_in) if widths_in else None
    L.append("## Targets (issue 4) against this run")
    L.append("")
    trows = []
    if fig6:
        is_290k = bool(fig6.get("triangles")) and abs(fig6["triangles"] - 290000) / 290000 < 0.02
        trows.append([f"Figure 6 analogue ({fig6.get('triangles', 0):,} triangles), engine time",
                      f"≤ {TARGET_290K_S:g} s at ~290k",
                      f"{f(fig6.get('engine_seconds'))} s" if fig6.get("engine_seconds") is not None else
                      f"failed: {fig6.get('error')}",
                      mark(fig6.get("engine_seconds") is not None and fig6["engine_seconds"] <= TARGET_290K_S)
                      if is_290k else "— (not ~290k)"])
    if r1m:
        trows.append(["1M triangles, engine time", f"≤ {TARGET_1M_S:g} s",
                      f"{f(r1m.get('engine_seconds'))} s" if r1m.get("engine_seconds") is not None else
                      f"failed: {r1m.get('error')}",
                      mark(r1m.get("engine_seconds") is not None and r1m["engine_seconds"] <= TARGET_1M_S)])
    if r2m:
        trows.append(["2M triangles, peak memory (incl. file parsing)", f"≤ {TARGET_2M_MB:.0f} MB",
                      f"{f(r2m.get('peak_mb'), 0)} MB", mark(r2m.get("peak_mb", 1e9) <= TARGET_2M_MB)])
    growth = growth_exponent(scaling)
    if growth is not None:
        top = [r for r in scaling if r.get("engine_seconds") and r.get("triangles")][-2:]
        local = (math.log(top[1]["engine_seconds"] / top[0]["engine_seconds"]) /
                 math.log(top[1]["triangles"] / top[0]["triangles"])) if len(top) == 2 else None
        trows.append(["growth of engine time with size", "≤ linear (exponent ≤ 1)",
                      f"exponent {growth:.2f} (log-log fit, all sizes)" +
                      (f"; {local:.2f} between the two largest sizes" if local is not None else ""),
                      mark(growth <= 1.05)])
    trows.append(["suite cases meeting mean ≤ 0.5, p95 ≤ 1.5 (both ways), IoU ≥ 0.97 (default options)",
                  f"all {len(SUITE)}", f"{n_meet} of {len(default_rows)}", mark(n_meet == len(SUITE))])
    trows.append([f"h range with the same accuracy ({sweeps['sens_triangles'] // 1000}k duck sweep, default options)",
                  "x0.6 … x1.4 (the paper's range for Figure 6)",
                  (tol if tol else "none of the sweep points") + f"; the paper's method here: {tol_paper or 'none'}"
                  + f"; with `foot_snap=1`: {tol_foot or 'none'}",
                  mark(tol_ok([r for r in results["sens_h"] if r.get("config") == "default"]))])
    trows.append(["narrowest slot mouth entered (≥ 50% of its vertices uncovered)", "paper: 4–6 average edges",
                  (f"{entered:g} average edges" if entered is not None else "none entered") if slots_valid else
                  "n/a: the slots case itself failed (" + (f"IoU {slots_row['score']['iou']:.3f}"
                                                            if slots_row and slots_row.get("ok") else
                                                            str((slots_row or {}).get("error"))) + ")", "—"])
    L.append(table(["target", "wanted", "measured", "met"], trows))
    L.append("")

    # Figure 6 comparison.
    L.append("## Figure 6 analogue: per phase, beside the paper")
    L.append("")
    if fig6 and fig6.get("phases"):
        ae = fig6.get("average_edge", 0) / fig6.get("h", 1)
        L.append(f"Ours: duck, blended step, {fig6['triangles']:,} triangles, average edge {ae:.3f} h, h = 1, "
                 f"W_int = 0.25, default options; status `{fig6['status']}`. Paper: {PAPER_FIG6['triangles']:,} "
                 f"triangles, average edge 0.21 mm, h = 1.0 mm, 2.4 GHz CPU. "
                 + ("Our run: the speed section's (alone on the machine, engine threads = all cores), the median of "
                    f"{len(fig6['engine_seconds_all'])} runs (" +
                    ", ".join(f"{x:.3f}" for x in fig6["engine_seconds_all"]) + " s)."
                    if fig6.get("engine_seconds_all") else
                    "Our run: the accuracy section's (one thread, next to another run)."))
        L.append("")
        rows = []
        for name in ["preprocess", "coarse", "refine", "stabilise"]:
            p = phase(fig6, name) or {}
            pi, ps, pt = PAPER_FIG6["phases"][name]
            rows.append([name, pi if pi is not None else "—", p.get("iterations", "—"),
                         ps if ps is not None else "—", p.get("snaxels", "—"),
                         f"{pt:g}" if pt is not None else "— (not reported)", f(p.get("seconds"), 3)])
        rows.append(["**total (engine)**", sum(v[0] or 0 for v in PAPER_FIG6["phases"].values()), sum((phase(fig6, n) or {}).get("iterations", 0)
                                                      for n in ["coarse", "refine", "stabilise"]),
                     "", "", f"{PAPER_FIG6['total_seconds']:g}", f"**{f(fig6.get('engine_seconds'), 3)}**"])
        rows.append(["file reading (separate)", "—", "—", "—", "—", "—", f(fig6.get("load_seconds"), 3)])
        L.append(table(["phase", "paper iterations", "our iterations", "paper snaxels", "our snaxels",
                        "paper seconds", "our seconds"], rows))
        L.append("")
        L.append(f"Peak memory of that run: {f(fig6.get('peak_mb'), 0)} MB (includes file parsing). "
                 f"Planarity was computed at {fig6.get('planarity_vertices', 0):,} of "
                 f"{fig6.get('vertices', 0):,} vertices.")
        if "fig6_phases.png" in plots:
            L.append("")
            L.append("![phases](fig6_phases.png)")
    else:
        L.append(f"The Figure 6 analogue run failed: {fig6.get('error') if fig6 else 'not run'}")
    L.append("")

    # Accuracy.
    L.append("## Accuracy on the suite (default options)")
    L.append("")
    L.append("mean/p95 →: contour to true boundary; ←: true boundary to contour; in average edges. "
             f"Targets: mean ≤ {TARGET_MEAN}, p95 ≤ {TARGET_P95}, IoU ≥ {TARGET_IOU}. Engine seconds here are "
             f"single-thread (`--option threads={POOL_THREADS}`, two runs at a time); the speed sections below "
             "use all cores.")
    L.append("")
    rows = []
    for c in SUITE:
        r = suite.get((c.name, "default"))
        if r is None:
            continue
        tri = f"{r['triangles']:,}" if r.get("triangles") else "—"
        ae = f(r["average_edge"] / r["h"], 3) if r.get("average_edge") else "—"
        rows.append([f"`{c.name}`", c.what, tri, ae, *accuracy_cells(r), f(r.get("engine_seconds")),
                     f(r.get("peak_mb"), 0), mark(meets(r)) if r.get("ok") else "**no**",
                     "" if r.get("ok") else f"`{r.get('error')}`"])
    L.append(table(["case", "what", "triangles", "edge / h", "status", "IoU", "mean →", "p95 →", "mean ←", "p95 ←",
                    "engine s", "peak MB", "targets met", "error"], rows))
    L.append("")
    caps = [c.name for c in SUITE if suite.get((c.name, "default"), {}).get("status") == "iteration_cap"]
    if caps:
        L.append("Hit the iteration cap (status `iteration_cap`; the contour is still scored): " +
                 ", ".join(f"`{n}`" for n in caps) + ". Failed runs of the other variants are listed under "
                 "\"Departures from the paper\".")
        L.append("")

    # Slots.
    L.append("## Concavities: slots of mouth 2–8 average edges")
    L.append("")
    L.append("Per slot: the fraction of the mesh vertices inside the slot (background, depth 5 h) that the "
             "result leaves outside the relief region — 1.0: the snake went to the bottom of the slot; "
             "0.0: it bridged the mouth. *Entered* = at least half uncovered, counted only when the whole case "
             f"has IoU ≥ {SLOTS_MIN_IOU} (a snake that lost the relief also leaves the slots uncovered). The paper: the snake does not "
             "enter mouths narrower than 4–6 average edges.")
    L.append("")
    srows = []
    for vname, _ in VARIANTS:
        r = suite.get(("slots", vname))
        if not r:
            continue
        if not r.get("ok"):
            srows.append([vname, "FAILED", f"`{r.get('error')}`", "", "", ""])
            continue
        valid = r["score"]["iou"] >= SLOTS_MIN_IOU
        for s in r.get("slots", []):
            srows.append([vname, f"{s['width_edges']:g}", f(s["width"] / r["h"], 2), s["vertices"],
                          f(s["uncovered"], 2),
                          ("yes" if s["uncovered"] >= 0.5 else "no") if valid else
                          f"n/a (case IoU {r['score']['iou']:.3f})"])
    L.append(table(["variant", "mouth (average edges)", "mouth (h)", "slot vertices", "uncovered fraction",
                    "entered"], srows))
    L.append("")

    # Side by side.
    L.append("## Departures from the paper, side by side")
    L.append("")
    L.append("Variants: " + "; ".join(f"**{n}** = " + (" ".join(f"`--option {o}`" for o in opts) if opts else
                                                       "engine defaults") for n, opts in VARIANTS) +
             ". Each cell: IoU (worst of the two mean distances, worst of the two p95), in average edges; "
             "✓ = every accuracy target met. Engine seconds of every variant are in `results.json`.")
    L.append("")
    header = ["case"] + [v for v, _ in VARIANTS] + ["best IoU"]
    rows, notes = [], []
    tally = {v: {"met": 0, "failed": 0, "better": 0, "worse": 0, "same": 0, "seconds": 0.0, "runs": 0}
             for v, _ in VARIANTS}
    for c in SUITE:
        cells = [f"`{c.name}`"]
        ious = []
        base = suite.get((c.name, "default"), {})
        base_iou = base["score"]["iou"] if base.get("ok") else -1.0
        for vname, _ in VARIANTS:
            r = suite.get((c.name, vname))
            t = tally[vname]
            if r is None:
                cells.append("not run")
                ious.append(-1.0)
                continue
            t["runs"] += 1
            if r.get("ok"):
                sc = r["score"]
                worst_mean = max(sc["mean_to_truth"], sc["mean_from_truth"])
                worst_p95 = max(sc["p95_to_truth"], sc["p95_from_truth"])
                cells.append(f"{sc['iou']:.3f} ({worst_mean:.2f}, {worst_p95:.2f})" + (" ✓" if meets(r) else "") +
                             (" cap" if r.get("status") == "iteration_cap" else ""))
                ious.append(sc["iou"])
                t["met"] += meets(r)
                t["seconds"] += r.get("engine_seconds") or 0
            else:
                cells.append("FAILED")
                notes.append(f"`{c.name}` [{vname}]: {r.get('error')}")
                ious.append(-1.0)
                t["failed"] += 1
            if vname != "default":
                d = ious[-1] - base_iou
                t["better" if d >= 0.005 else "worse" if d <= -0.005 else "same"] += 1
        top = max(ious)
        winners = [VARIANTS[i][0] for i, x in enumerate(ious) if top - x < 0.005 and x >= 0]
        cells.append("—" if top < 0 else ("all" if len(winners) == len(VARIANTS) else ", ".join(winners)))
        rows.append(cells)
    L.append(table(header, rows))
    L.append("")
    L.append("\"cap\": the run hit the iteration cap (status `iteration_cap`). \"best IoU\": variants within 0.005 "
             "of the best IoU for that case.")
    L.append("")
    if notes:
        L.append("Failed runs:")
        L.append("")
        L += [f"- {n}" for n in notes]
        L.append("")
    srows = []
    for vname, opts in VARIANTS:
        t = tally[vname]
        srows.append([vname, " ".join(f"`{o}`" for o in opts) or "—", f"{t['met']} of {t['runs']}", t["failed"],
                      "—" if vname == "default" else t["better"], "—" if vname == "default" else t["worse"],
                      "—" if vname == "default" else t["same"], f"{t['seconds']:.1f}"])
    L.append("Per variant (IoU compared with the default case by case; a difference under 0.005 counts as the same; "
             "a failed run counts as IoU −1):")
    L.append("")
    L.append(table(["variant", "options", "cases meeting all accuracy targets", "failed runs", "better than default",
                    "worse", "same", "engine seconds, sum over successful runs"], srows))
    L.append("")

    # Sensitivity.
    L.append("## Sensitivity (duck, blended step, %dk triangles: the Figure 6 analogue)" % (sweeps["sens_triangles"] // 1000))
    L.append("")
    L.append("Three configurations: **default** (the engine's defaults), **paper** (" +
             " ".join(f"`{o}`" for o in PAPER) + ") and **foot-snap** (`foot_snap=1`). Engine seconds are "
             "single-thread.")
    L.append("")
    for key, title, xname, png in [("sens_h", "h given / true step", "h factor", "sensitivity_h.png"),
                                   ("sens_wint", "W_int", "W_int", "sensitivity_wint.png"),
                                   ("sens_noise", "noise sigma / h", "noise", "sensitivity_noise.png")]:
        L.append(f"### Accuracy vs {title}")
        L.append("")
        if png in plots:
            L.append(f"![{key}]({png})")
            L.append("")
        rows = []
        for r in sorted(results[key], key=lambda r: ([c for c, _ in SWEEP_CONFIGS].index(r.get("config", "default"))
                                                      if r.get("config") in dict(SWEEP_CONFIGS) else 99, r["x"])):
            rows.append([r.get("config", "default"), f"{r['x']:g}", *accuracy_cells(r), f(r.get("engine_seconds")),
                         mark(meets(r)) if r.get("ok") else "**no**", "" if r.get("ok") else f"`{r.get('error')}`"])
        L.append(table(["config", xname, "status", "IoU", "mean →", "p95 →", "mean ←", "p95 ←", "engine s",
                        "targets met", "error"], rows))
        L.append("")
    for cname, rng in (("default", tol), ("paper", tol_paper), ("foot-snap", tol_foot)):
        L.append(f"{cname}: all accuracy targets hold for h in " + (f"{rng} of the true step" if rng else
                 "no contiguous range around x1") + f" (sweep points {', '.join(f'{x:g}' for x in sweeps['h_factors'])}).")
        L.append("")

    # Scaling.
    L.append("## Speed and memory vs mesh size (duck, blended step, near start; one run at a time)")
    L.append("")
    L.append("Engine threads: all cores (the default). Sizes up to 1M run several times; the row is the run with "
             "the median engine time (phases from that run). Peak MB is the whole `relief-snake` process: it "
             "includes reading and parsing the PLY file and writing the result JSON.")
    L.append("")
    if "scaling.png" in plots:
        L.append("![scaling](scaling.png)")
        L.append("")
    rows = []
    for r in scaling:
        ph = {n: (phase(r, n) or {}).get("seconds") for n in ["preprocess", "coarse", "refine", "stabilise"]}
        tgt = ""
        if r.get("triangles") and abs(r["triangles"] - 290000) / 290000 < 0.02:
            tgt = f"≤ {TARGET_290K_S:g} s"
        elif r.get("triangles") and abs(r["triangles"] - 1e6) / 1e6 < 0.02:
            tgt = f"≤ {TARGET_1M_S:g} s"
        elif r.get("triangles") and abs(r["triangles"] - 2e6) / 2e6 < 0.02:
            tgt = f"peak ≤ {TARGET_2M_MB:.0f} MB"
        rows.append([f"{r.get('triangles', 0):,}", f(r.get("average_edge", 0) / r.get("h", 1), 3),
                     f(r.get("load_seconds"), 2), f(ph["preprocess"], 3), f(ph["coarse"], 3), f(ph["refine"], 3),
                     f(ph["stabilise"], 3), f(r.get("engine_seconds"), 3), spread(r), tgt, f(r.get("peak_mb"), 0),
                     f"{r['planarity_vertices']:,}" if r.get("planarity_vertices") else "—",
                     f(r["score"]["iou"], 3) if r.get("ok") else "FAILED",
                     "" if r.get("ok") else f"`{r.get('error')}`"])
    L.append(table(["triangles", "edge / h", "file reading s", "preprocess s", "coarse s", "refine s", "stabilise s",
                    "engine total s", "runs (min–max s)", "target", "peak MB", "planarity vertices", "IoU", "error"], rows))
    L.append("")
    if growth is not None:
        L.append(f"Log-log fit of engine seconds against triangles over the series: exponent {growth:.2f} "
                 "(1.0 = linear).")
        L.append("")
    if plots_error:
        L.append(f"Plots were not drawn: {plots_error}")
        L.append("")
    L.append("## Reproduce")
    L.append("")
    L.append("`make bench` (or `scripts/bench.sh`; `python3 bench/run_bench.py --build-dir DIR [--quick] "
             "[--keep-scans]`). Every engine command line is in `results.json` (`command`), with all raw numbers.")
    L.append("")
    return "\n".join(L)


def spread(row):
    xs = row.get("engine_seconds_all") or []
    if len(xs) < 2:
        return str(len(xs))
    return f"{len(xs)} ({min(xs):.3f}–{max(xs):.3f})"


def tolerance_range(rows):
    """The contiguous range of sweep h factors around 1.0 where every accuracy target holds."""
    pts = sorted(rows, key=lambda r: r["x"])
    ok = [meets(r) for r in pts]
    idx = [i for i, r in enumerate(pts) if abs(r["x"] - 1.0) < 1e-9]
    if not idx or not ok[idx[0]]:
        return None
    lo = hi = idx[0]
    while lo > 0 and ok[lo - 1]:
        lo -= 1
    while hi + 1 < len(pts) and ok[hi + 1]:
        hi += 1
    return f"x{pts[lo]['x']:g} … x{pts[hi]['x']:g}"


def tol_ok(rows):
    pts = {round(r["x"], 6): meets(r) for r in rows}
    needed = [x for x in pts if 0.6 - 1e-9 <= x <= 1.4 + 1e-9]
    return bool(needed) and all(pts[x] for x in needed)


def growth_exponent(rows):
    import math
    pts = [(math.log(r["triangles"]), math.log(r["engine_seconds"])) for r in rows
           if r.get("engine_seconds") and r.get("triangles")]
    if len(pts) < 3:
        return None
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx if sxx > 0 else None


if __name__ == "__main__":
    sys.exit(main())
