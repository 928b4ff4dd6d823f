"""The randomized suite (issue 14): scans nobody tuned the engine on, drawn by `make-scan --random SEED`.

    python3 -m bench.random_suite --cli build/relief-snake --make-scan build/make-scan --seeds 0:200 \\
        --jobs 2 [--variant NAME=OPTIONS ...] [--real-scan DIR] --out DIR

For every seed it generates one scan (cached by seed under DIR/scans, keyed by the make-scan binary),
segments it with every variant through the CLI as a user would (the typed h is the true step times a
factor drawn from x0.5 to x2.0), scores the result with `make-scan score --mesh` and classifies it:

* **accurate**: mean distance contour->truth and truth->contour both <= 1 average edge AND area-weighted
  IoU >= the scan's one-edge floor (the area-weighted IoU of the true region against itself grown by
  every vertex within one average edge of the true boundary: what a contour one edge off would score);
  otherwise **wrong** (a run with no result is wrong too);
* **claimed right**: exit code 0 and status `converged`; anything else is **flagged** (exit code 3 with
  status `doubtful` or `iteration_cap` and the result written, an error exit such as a collapse, a
  runaway or a timeout).

It writes DIR/report.md (variants side by side: accuracy, wrong results flagged, right results flagged,
refusals, times, and the per-axis breakdown of the failures) and DIR/results.json (every row).

A variant is NAME=OPTIONS: OPTIONS is split like a shell line; a token NAME=VALUE becomes
`--option NAME=VALUE`, any other token is passed to the CLI untouched (`--step-height auto`,
`--w-int 0.5`; a variant that sets --step-height or --w-int replaces the suite's own).
"""
from __future__ import annotations

import argparse
import concurrent.futures as futures
import datetime as dt
import hashlib
import json
import math
import shlex
import shutil
import statistics
import subprocess
import sys
import threading
import time
from pathlib import Path

if __package__ in (None, ""):  # run as a script: bench/random_suite.py
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.cases import PAPER, PAPER_W_INT
from bench.report import table
from bench.run import EXIT_DOUBTFUL, REPO, machine_info, run_engine, runaway_limit

# Today's defaults (engine of December 2026), spelled out so the variant stays the same when the
# defaults change.
OLD_DEFAULTS = ("--w-int 0.25 --max-iterations 3000 tau=0.2 epsilon=0.2 q_samples=5 exact_q=0 max_turn_degrees=160 "
                "lock_interval=10 feature_contrast=0.25 scale_feature_with_spacing=1 convex_barrier=0 remove_loops=1 "
                "foot_snap=0 refine_levels=1 nearest_resampling=1 neighbourhood=sphere plane_fit=vertex_areas "
                "planarity_one_ring=1 refit_step_height=0 repair_background=0 foot_snap_blended=0 wall_foot=0 retry_estimate=off "
                "region_check_textured_smoothing=0")
# auto-side: the CLI's own defaults, h and an open contour's relief side both left to the engine (the
# other variants give the truth's side, as a user who names it would; on closed scans it is auto-h).
BUILTIN_VARIANTS = {"defaults": "", "paper": f"--w-int {PAPER_W_INT} " + " ".join(PAPER),
                    "auto-h": "--step-height auto", "auto-side": "--step-height auto --relief-side auto",
                    "old-defaults": OLD_DEFAULTS}

# Issue 14's targets (printed beside the measurements; the benchmark never fails on them).
TARGET_ACCURATE = 0.97
TARGET_RIGHT_FLAGGED = 0.05
MEAN_LIMIT = 1.0  # average edges, both ways

# The per-axis breakdown: categorical axes as drawn, numeric ones in buckets.
CATEGORICAL_AXES = ["shape", "background", "texture", "picks_on_texture", "step", "detail", "detail_near_edge",
                    "start", "open", "graded"]
NUMERIC_AXES = {
    "h_edges": [1, 2, 4, 8, 13.01],
    "triangles": [15000, 30000, 60000, 120000, 250001],
    "typed_factor": [0.5, 0.7, 0.9, 1.1, 1.4, 2.0001],
    "noise": [0, 1e-12, 0.025, 0.0501],
    "jitter": [0, 0.12, 0.24, 0.341],
}

REAL_SCAN = REPO.parent / "shared" / "data" / "real-eyebrow"


def log(*args):
    print("random-suite:", *args, file=sys.stderr, flush=True)


def parse_seeds(text: str) -> list[int]:
    """Seeds from a comma list whose items are "A:B" (A <= seed < B) or one seed: "0:200,1000:1200,7"."""
    seeds: list[int] = []
    try:
        for item in (x.strip() for x in text.split(",")):
            if not item:
                continue
            if ":" in item:
                a, b = item.split(":", 1)
                seeds.extend(range(int(a), int(b)))
            else:
                seeds.append(int(item))
    except ValueError:
        raise SystemExit(f"random-suite: --seeds must be a comma list of A:B ranges or whole numbers, got '{text}'")
    if not seeds:
        raise SystemExit(f"random-suite: --seeds names no seed ('{text}'); give e.g. 0:200 or 0:200,1000:1200")
    return seeds


def variant_args(options: str) -> list[str]:
    """CLI arguments of a variant's OPTIONS string (see the module docstring)."""
    out = []
    for token in shlex.split(options):
        if not token.startswith("-") and "=" in token:
            out += ["--option", token]
        else:
            out.append(token)
    return out


def parse_variant(text: str) -> tuple[str, str]:
    name, sep, options = text.partition("=")
    if not name:
        raise SystemExit(f"random-suite: --variant needs NAME=OPTIONS (or a built-in name), got '{text}'")
    if not sep:
        if name not in BUILTIN_VARIANTS:
            raise SystemExit(f"random-suite: unknown built-in variant '{name}'; built-ins: "
                             + ", ".join(BUILTIN_VARIANTS) + "; or give NAME=OPTIONS")
        return name, BUILTIN_VARIANTS[name]
    return name, options


def bucket(axis: str, value) -> str:
    if axis in NUMERIC_AXES:
        edges = NUMERIC_AXES[axis]
        for lo, hi in zip(edges, edges[1:]):
            if lo <= value < hi:
                if axis == "noise" and hi <= 1e-12:
                    return "0"
                return f"{lo:g}-{hi:.3g}" if axis != "triangles" else f"{lo // 1000:g}k-{hi // 1000:g}k"
        return "other"
    return str(value).lower() if isinstance(value, bool) else str(value)


class Suite:
    def __init__(self, cli: Path, make_scan: Path, work: Path, timeout: float, threads: int, keep_results: bool):
        for exe in (cli, make_scan):
            if not exe.is_file():
                raise SystemExit(f"random-suite: {exe} not found; build the relief-snake and make-scan targets")
        self.cli, self.make_scan = cli, make_scan
        self.timeout, self.threads, self.keep_results = timeout, threads, keep_results
        # Scans are cached per make-scan binary: a rebuilt generator regenerates them.
        digest = hashlib.sha256(make_scan.read_bytes()).hexdigest()[:12]
        scans_root = work / "scans"
        scans_root.mkdir(parents=True, exist_ok=True)
        for old in scans_root.iterdir():
            if old.is_dir() and old.name != digest and len(old.name) == 12:
                shutil.rmtree(old, ignore_errors=True)
        self.scans = scans_root / digest
        self.scans.mkdir(exist_ok=True)
        self.results = work / "runs"
        self.results.mkdir(exist_ok=True)
        self.locks: dict[int, threading.Lock] = {}
        self.locks_lock = threading.Lock()

    def scan(self, seed: int) -> tuple[Path | None, dict | None, str | None]:
        """(prefix, truth, error): generated once per seed (PREFIX.json is written last by make-scan)."""
        with self.locks_lock:
            lock = self.locks.setdefault(seed, threading.Lock())
        with lock:
            prefix = self.scans / f"seed-{seed}"
            truth_path = Path(f"{prefix}.json")
            if not truth_path.is_file():
                r = subprocess.run([str(self.make_scan), "--random", str(seed), "--out", str(prefix)],
                                   capture_output=True, text=True)
                if r.returncode != 0:
                    return None, None, "make-scan failed: " + (r.stderr.strip().splitlines() or ["?"])[-1]
            try:
                return prefix, json.loads(truth_path.read_text()), None
            except (OSError, ValueError) as e:
                return None, None, f"unreadable truth {truth_path}: {e}"

    def run(self, case: dict, variant: str, options: str) -> dict:
        """One engine run on one case, scored and classified. case: {name, mesh, truth_path, truth,
        typed_step_height}. Never raises for engine failures."""
        truth = case["truth"]
        extra = variant_args(options)
        row = {"case": case["name"], "variant": variant, "axes": truth.get("axes", {}), "error": None,
               "status": None, "has_result": False, "accurate": False, "flagged": True, "outcome": None}
        out = self.results / f"{case['name']}.{variant}.json"
        out.unlink(missing_ok=True)
        cmd = [str(self.cli), "segment", str(case["mesh"]), "--picks", ",".join(map(str, truth["picks"]))]
        if "--step-height" not in extra:
            cmd += ["--step-height", repr(case["typed_step_height"])]
        if not truth.get("closed", truth.get("picks_closed", True)):
            cmd += ["--open"]
            if "--relief-side" not in extra:
                cmd += ["--relief-side", truth["relief_side"]]
        elif "--relief-side" in extra:  # a variant's side is for open contours (the CLI refuses it on closed ones)
            k = extra.index("--relief-side")
            extra = extra[:k] + extra[k + 2:]
        cmd += extra
        if self.threads and not any(a.startswith("threads=") for a in extra):
            cmd += ["--option", f"threads={self.threads}"]
        cmd += ["--out", str(out)]
        row["command"] = shlex.join([Path(cmd[0]).name] + cmd[1:])
        limit, expected = runaway_limit(truth)
        if expected == 0:  # a boundary given as points (the real scan): about one point per edge
            expected = 2 * len(truth["boundary"])
            limit = max(limit, 8 * expected)
        proc = run_engine(cmd, self.timeout, limit, expected)
        row.update(wall_seconds=proc["wall_seconds"], peak_mb=proc["peak_mb"], exit_code=proc["exit_code"])
        last = (proc["stderr"].splitlines() or [f"exit code {proc['exit_code']}"])[-1]
        if proc["killed"]:
            row["error"] = proc["killed"]
            row["outcome"] = "runaway" if proc["killed"].startswith("runaway") else "timeout"
        elif proc["exit_code"] not in (0, EXIT_DOUBTFUL) or not out.is_file():
            row["error"] = last
            row["outcome"] = ("usage error" if proc["exit_code"] == 2 else
                              "collapsed" if "collapse" in last else "error")
        if row["error"]:
            out.unlink(missing_ok=True)
            return row
        try:
            result = json.loads(out.read_text())
        except (OSError, ValueError) as e:
            row.update(error=f"unreadable result: {e}", outcome="error")
            return row
        row["has_result"] = True
        row["status"] = result.get("status")
        row["outcome"] = row["status"]
        row["message"] = result.get("message")
        row["notes"] = result.get("notes", [])
        timing = result.get("timing", {})
        row["engine_seconds"] = timing.get("segment_seconds", timing.get("seconds"))
        row["load_seconds"] = timing.get("load_seconds")
        params = result.get("parameters", {})
        for key in ("step_height", "w_int", "relief_side"):
            if key in params:
                row[f"used_{key}"] = params[key]
        # The h the engine used against the true step: typed, or with --step-height auto the
        # estimate after the engine's refit along the contour (what it reports as used). The first
        # estimate, from the picks alone, is kept apart (h_estimate_ratio).
        step_h = result.get("step_height") if isinstance(result.get("step_height"), dict) else {}
        used_h = step_h.get("used", params.get("step_height"))
        true_h = truth.get("true_step_height", truth.get("h"))
        if isinstance(used_h, (int, float)) and true_h:
            row["h_ratio"] = used_h / true_h
        if isinstance(step_h.get("estimate"), (int, float)) and true_h:
            row["h_estimate_ratio"] = step_h["estimate"] / true_h
        # The step the engine measured at the result's edge (typed h or not).
        if isinstance(step_h.get("measured"), (int, float)) and true_h:
            row["h_measured_ratio"] = step_h["measured"] / true_h
        # The same against the rim the relief's edge reaches (make-scan's edge_step_height): below h
        # where a drop or an edge groove keeps the surface from reaching h. Absent from older scans.
        rim = truth.get("edge_step_height")
        if isinstance(rim, (int, float)) and rim > 0:
            if isinstance(used_h, (int, float)):
                row["h_rim_ratio"] = used_h / rim
            if isinstance(step_h.get("measured"), (int, float)):
                row["h_measured_rim_ratio"] = step_h["measured"] / rim
        row["flagged"] = not (proc["exit_code"] == 0 and row["status"] == "converged")
        sc = subprocess.run([str(self.make_scan), "score", str(case["truth_path"]), str(out), "--mesh",
                             str(case["mesh"])], capture_output=True, text=True)
        if not self.keep_results:
            out.unlink(missing_ok=True)
        if sc.returncode != 0:
            row["error"] = "scoring failed: " + (sc.stderr.strip().splitlines() or ["?"])[-1]
            return row
        s = json.loads(sc.stdout)
        row["score"] = s
        row["accurate"] = (s["mean_to_truth"] <= MEAN_LIMIT and s["mean_from_truth"] <= MEAN_LIMIT and
                           s["iou_area"] >= s["iou_floor_area"])
        return row


def random_case(suite: Suite, seed: int) -> dict:
    prefix, truth, error = suite.scan(seed)
    if error:
        return {"name": f"seed-{seed}", "error": error}
    return {"name": f"seed-{seed}", "seed": seed, "mesh": Path(f"{prefix}.ply"), "truth_path": Path(f"{prefix}.json"),
            "truth": truth, "typed_step_height": truth["typed_step_height"]}


def real_cases(real_dir: Path, work: Path) -> list[dict]:
    """The real scan's cases, each with a truth file in make-scan's format. Its boundary points are
    unordered, so each is a one-point polyline: distances are to the nearest boundary point."""
    truth = json.loads((real_dir / "truth.json").read_text())
    out = []
    (work / "real").mkdir(parents=True, exist_ok=True)
    for name, c in truth["cases"].items():
        t = {"average_edge": truth["average_edge"], "relief_vertices": c["relief_vertices"], "picks": c["picks"],
             "open": c["open"], "closed": not c["open"], "picks_closed": not c["open"],
             "relief_side": c.get("relief_side", "left"), "boundary": [[p] for p in c["boundary_points"]],
             "boundary_closed": [False] * len(c["boundary_points"]), "h": c["step_height"],
             "axes": {"real": name}}
        path = work / "real" / f"{name}.json"
        path.write_text(json.dumps(t))
        out.append({"name": name, "mesh": real_dir / "scan.ply", "truth_path": path, "truth": t,
                    "typed_step_height": c["step_height"]})
    return out


# --- summaries ----------------------------------------------------------------------------

def pct(n, d):
    return f"{100.0 * n / d:.1f}%" if d else "—"


def quantile(xs, q):
    xs = sorted(xs)
    if not xs:
        return None
    return xs[min(len(xs) - 1, max(0, math.ceil(q * len(xs)) - 1))]


def reasons(wrong: list[dict]) -> dict:
    """Why wrong results are wrong: no result, mean distance only, IoU only, or both."""
    out = {"no result": 0, "mean distance > 1 edge only": 0, "IoU < floor only": 0, "both": 0}
    for r in wrong:
        s = r.get("score")
        if not s:
            out["no result"] += 1
            continue
        far = max(s["mean_to_truth"], s["mean_from_truth"]) > MEAN_LIMIT
        low = s["iou_area"] < s["iou_floor_area"]
        out["both" if far and low else "mean distance > 1 edge only" if far else "IoU < floor only"] += 1
    return out


def summarize(rows: list[dict]) -> dict:
    n = len(rows)
    ratios = [r["h_ratio"] for r in rows if r.get("h_ratio")]
    first = [r["h_estimate_ratio"] for r in rows if r.get("h_estimate_ratio")]
    measured = [r["h_measured_ratio"] for r in rows if r.get("h_measured_ratio")]
    rim_used = [r["h_rim_ratio"] for r in rows if r.get("h_rim_ratio")]
    rim_measured = [r["h_measured_rim_ratio"] for r in rows if r.get("h_measured_rim_ratio")]

    def in_range(xs):  # the share of all runs with a ratio in x0.75 … x1.33 (None: no run has one)
        return sum(0.75 <= x <= 1.33 for x in xs) / n if xs else None
    accurate = [r for r in rows if r["accurate"]]
    wrong = [r for r in rows if not r["accurate"]]
    times = [r["wall_seconds"] for r in rows if r.get("wall_seconds") is not None]
    engine = [r["engine_seconds"] for r in rows if r.get("engine_seconds") is not None]
    outcomes: dict[str, int] = {}
    for r in rows:
        outcomes[r["outcome"] or "?"] = outcomes.get(r["outcome"] or "?", 0) + 1
    return {
        "runs": n,
        "accurate": len(accurate),
        "accuracy_rate": len(accurate) / n if n else None,
        "wrong": len(wrong),
        "wrong_flagged": sum(r["flagged"] for r in wrong),
        "wrong_converged": sum(not r["flagged"] for r in wrong),
        "wrong_flagged_share": sum(r["flagged"] for r in wrong) / len(wrong) if wrong else None,
        "right_flagged": sum(r["flagged"] for r in accurate),
        "right_flagged_share": sum(r["flagged"] for r in accurate) / len(accurate) if accurate else None,
        "refused": sum(not r["has_result"] for r in rows),
        "refusal_rate": sum(not r["has_result"] for r in rows) / n if n else None,
        "accurate_and_converged": sum(r["accurate"] and not r["flagged"] for r in rows),
        "wall_seconds_median": statistics.median(times) if times else None,
        "wall_seconds_p95": quantile(times, 0.95),
        "engine_seconds_median": statistics.median(engine) if engine else None,
        "engine_seconds_p95": quantile(engine, 0.95),
        "outcomes": outcomes,
        "wrong_by_reason": reasons(wrong),
        # Over all runs: a run that ends without an h (refused) counts as out of range.
        "h_within_075_133": in_range(ratios),
        "h_estimate_within_075_133": in_range(first),
        "h_measured_within_075_133": in_range(measured),
        "h_used_within_rim": in_range(rim_used),
        "h_measured_within_rim": in_range(rim_measured),
    }


def axis_breakdown(rows: list[dict]) -> dict:
    """{axis: {value: {runs, accurate, wrong_converged, wrong_flagged}}}."""
    out: dict = {}
    for axis in CATEGORICAL_AXES + list(NUMERIC_AXES):
        cells: dict = {}
        for r in rows:
            if axis not in r["axes"]:
                continue
            c = cells.setdefault(bucket(axis, r["axes"][axis]), {"runs": 0, "accurate": 0, "wrong_converged": 0,
                                                                  "wrong_flagged": 0})
            c["runs"] += 1
            c["accurate"] += r["accurate"]
            c["wrong_converged"] += (not r["accurate"]) and not r["flagged"]
            c["wrong_flagged"] += (not r["accurate"]) and r["flagged"]
        out[axis] = dict(sorted(cells.items()))
    return out


def fmt(x, digits=2):
    if x is None:
        return "—"
    return f"{x:.{digits}f}"


def write_report(config, variants, rows_by_variant, real_rows, real_note, machine, wall) -> str:
    names = list(variants)
    summaries = {v: summarize(rows_by_variant[v]) for v in names}
    L = ["# Randomized suite (issue 14)", ""]
    L.append(f"Generated by `python3 -m bench.random_suite` on {config['date']}: {config['seeds_text']} "
             f"({config['n_seeds']} seeds, one random scan each), {len(names)} variant(s), {config['jobs']} runs at a "
             f"time, engine threads {config['threads'] or 'all'} per run. Commit `{machine['commit']}`"
             + (" (uncommitted changes)" if machine["dirty"] else "") + f"; {machine['cpu']}, {machine['cores']} "
             f"cores; wall time {wall / 60:.1f} min. A benchmark, not a test: it reports, it never fails.")
    L.append("")
    L.append("**Accurate** = mean distance contour→truth and truth→contour both ≤ 1 average edge, and "
             "area-weighted IoU ≥ the scan's **one-edge floor** (the area-weighted IoU of the true relief "
             "against itself grown by every vertex within one average edge of the true boundary). Anything else "
             "is **wrong** (no result is wrong too). **Flagged** = not (exit code 0 and status `converged`): "
             "`doubtful`, `iteration_cap`, an error exit (collapse), a runaway or a timeout. The typed h is "
             "the true step times a factor drawn log-uniformly from x0.5 to x2.0; the scan's axes are drawn by "
             "`make-scan --random SEED` (bench/README.md lists the distributions).")
    L.append("")
    L.append("Variants: " + "; ".join(f"**{v}** = " + (f"`{variants[v]}`" if variants[v] else "the engine's defaults")
                                      for v in names) + ".")
    L.append("")
    L.append("## Summary")
    L.append("")
    rows = []

    def share(key):  # a summary's share as a percentage, "—" where no run had the value
        return lambda s: pct(s[key], 1) if s.get(key) is not None else "—"

    def line(label, target, fn):
        rows.append([label, target] + [fn(summaries[v]) for v in names])

    line("runs", "", lambda s: str(s["runs"]))
    line("accurate", f"≥ {TARGET_ACCURATE:.0%}", lambda s: f"{s['accurate']} ({pct(s['accurate'], s['runs'])})")
    line("wrong", "", lambda s: str(s["wrong"]))
    line("wrong and flagged", "all", lambda s: f"{s['wrong_flagged']} of {s['wrong']} ({pct(s['wrong_flagged'], s['wrong'])})")
    line("**wrong and `converged`** (silent failures)", "0", lambda s: f"**{s['wrong_converged']}**")
    line("right but flagged", f"≤ {TARGET_RIGHT_FLAGGED:.0%} of right",
         lambda s: f"{s['right_flagged']} of {s['accurate']} ({pct(s['right_flagged'], s['accurate'])})")
    line("refused (no result)", "", lambda s: f"{s['refused']} ({pct(s['refused'], s['runs'])})")
    line("accurate and converged", "", lambda s: f"{s['accurate_and_converged']} ({pct(s['accurate_and_converged'], s['runs'])})")
    line("h used (typed, or with `--step-height auto` the estimate after the refit along the contour) within "
         "x0.75 … x1.33 of the true step (of all runs: one without a result counts as out of range)", "",
         share("h_within_075_133"))
    line("the step measured at the result's edge (`step_height.measured`, typed h or not) within x0.75 … x1.33 "
         "(of all runs)", "≥ 95% with `--step-height auto`",
         share("h_measured_within_075_133"))
    line("the step measured at the result's edge within x0.75 … x1.33 of the **rim** the relief's edge reaches "
         "(make-scan's `edge_step_height`: h, or less where a drop or an edge groove keeps the surface below h)",
         "", share("h_measured_within_rim"))
    line("h used within x0.75 … x1.33 of the rim", "",
         share("h_used_within_rim"))
    line("`--step-height auto`: the first estimate (from the picks alone) within x0.75 … x1.33", "",
         share("h_estimate_within_075_133"))
    line("CLI wall seconds, median / p95", "", lambda s: f"{fmt(s['wall_seconds_median'])} / {fmt(s['wall_seconds_p95'])}")
    line("engine seconds, median / p95", "", lambda s: f"{fmt(s['engine_seconds_median'])} / {fmt(s['engine_seconds_p95'])}")
    line("outcomes", "", lambda s: ", ".join(f"{k} {n}" for k, n in sorted(s["outcomes"].items())))
    line("why the wrong ones are wrong", "", lambda s: ", ".join(f"{k} {n}" for k, n in s["wrong_by_reason"].items()))
    L.append(table(["", "target"] + names, rows))
    L.append("")
    L.append("Wall seconds include reading the PLY file; engine seconds are `timing.segment_seconds`.")
    L.append("")

    # Per-axis breakdown.
    L.append("## Where the failures come from (per axis)")
    L.append("")
    L.append("Each cell: accurate / runs, then the wrong results that were `converged` (silent) and flagged. "
             "Numeric axes are bucketed.")
    L.append("")
    breakdowns = {v: axis_breakdown(rows_by_variant[v]) for v in names}
    for axis in CATEGORICAL_AXES + list(NUMERIC_AXES):
        values = sorted({k for v in names for k in breakdowns[v].get(axis, {})})
        if not values:
            continue
        L.append(f"### {axis}")
        L.append("")
        trows = []
        for value in values:
            cells = [f"`{value}`"]
            for v in names:
                c = breakdowns[v][axis].get(value)
                cells.append("—" if not c else f"{c['accurate']}/{c['runs']}, silent {c['wrong_converged']}, "
                                               f"flagged {c['wrong_flagged']}")
            trows.append(cells)
        L.append(table([axis] + names, trows))
        L.append("")

    # Silent failures.
    L.append("## Silent failures (wrong and `converged`)")
    L.append("")
    for v in names:
        silent = [r for r in rows_by_variant[v] if not r["accurate"] and not r["flagged"]]
        L.append(f"**{v}**: {len(silent)}" + (":" if silent else "."))
        L.append("")
        if silent:
            trows = []
            for r in silent:
                a, s = r["axes"], r.get("score", {})
                trows.append([r["case"], a.get("shape"), a.get("background"), a.get("texture"), a.get("step"),
                              a.get("detail"), a.get("start"), fmt(a.get("h_edges"), 1), a.get("triangles"),
                              fmt(a.get("typed_factor")), fmt(s.get("iou_area"), 3), fmt(s.get("iou_floor_area"), 3),
                              fmt(s.get("mean_to_truth")), fmt(s.get("mean_from_truth"))])
            L.append(table(["case", "shape", "background", "texture", "step", "detail", "start", "h / edge",
                            "triangles", "typed h factor", "IoU (area)", "floor", "mean →", "mean ←"], trows))
            L.append("")

    # Real scan.
    L.append("## Real scan")
    L.append("")
    if real_rows:
        trows = []
        for v in names:
            for r in real_rows.get(v, []):
                s = r.get("score", {})
                trows.append([r["case"], v, r["outcome"], "yes" if r["accurate"] else "**no**",
                              "yes" if r["flagged"] else "no", fmt(s.get("iou_area"), 3), fmt(s.get("iou_floor_area"), 3),
                              fmt(s.get("mean_to_truth")), fmt(s.get("mean_from_truth")), fmt(r.get("wall_seconds")),
                              r.get("error") or ""])
        L.append(real_note)
        L.append("")
        L.append(table(["case", "variant", "outcome", "accurate", "flagged", "IoU (area)", "floor", "mean →",
                        "mean ←", "wall s", "error"], trows))
    else:
        L.append(real_note)
    L.append("")
    L.append("## Reproduce")
    L.append("")
    L.append(f"`{config['command']}`. One scan: `make-scan --random SEED --out PREFIX`; every engine command line "
             "is in `results.json` (`command`).")
    L.append("")
    return "\n".join(L)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cli", default="build/relief-snake")
    ap.add_argument("--make-scan", default="build/make-scan")
    ap.add_argument("--seeds", default="0:200", help="a comma list of A:B ranges (A <= seed < B) and seeds: 0:200,1000:1200")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--variant", action="append", default=[],
                    help="NAME=OPTIONS or a built-in name (" + ", ".join(BUILTIN_VARIANTS) + "); repeatable; "
                         "none given: all of those")
    ap.add_argument("--threads", type=int, default=1, help="engine threads per run (0: the engine's default)")
    ap.add_argument("--timeout", type=float, default=60,
                    help="seconds before one run is killed (and counted as a flagged failure)")
    ap.add_argument("--real-scan", default=str(REAL_SCAN),
                    help="folder with scan.ply and truth.json run as extra cases ('' to skip)")
    ap.add_argument("--keep-results", action="store_true", help="keep every result JSON in OUT/runs")
    ap.add_argument("--out", default=str(REPO / "bench" / "results" / "random"))
    args = ap.parse_args(argv)

    t0 = time.monotonic()
    seeds = parse_seeds(args.seeds)
    variants = dict(parse_variant(v) for v in (args.variant or list(BUILTIN_VARIANTS)))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    suite = Suite(Path(args.cli).resolve(), Path(args.make_scan).resolve(), out, args.timeout, args.threads,
                  args.keep_results)

    cases: list[dict] = []
    real_note = ""
    real_dir = Path(args.real_scan) if args.real_scan else None
    if real_dir and (real_dir / "truth.json").is_file() and (real_dir / "scan.ply").is_file():
        real = real_cases(real_dir, out)
        real_note = (f"`{real_dir}` ({len(real)} open contours; typed h = the truth's step height; distances to the "
                     "nearest of the truth's boundary points, which are unordered and lie on the label edge).")
    else:
        real = []
        real_note = (f"Not run: `{real_dir}` was not found (the real scan lives in ../shared/data, beside the repository)."
                     if real_dir else "Not run (--real-scan '').")
        log(real_note)

    jobs = [(seed, v) for seed in seeds for v in variants] + [(c["name"], v) for c in real for v in variants]
    real_by_name = {c["name"]: c for c in real}
    log(f"{len(seeds)} seeds x {len(variants)} variants ({', '.join(variants)}) + {len(real)} real cases, "
        f"{args.jobs} at a time")

    def do(job):
        key, v = job
        case = real_by_name[key] if key in real_by_name else random_case(suite, key)
        if case.get("error"):
            return key, v, {"case": case["name"], "variant": v, "axes": {}, "error": case["error"], "status": None,
                            "has_result": False, "accurate": False, "flagged": True, "outcome": "no scan"}
        return key, v, suite.run(case, v, variants[v])

    rows_by_variant = {v: [] for v in variants}
    real_rows = {v: [] for v in variants}
    done = 0
    with futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        for key, v, row in pool.map(do, jobs):
            done += 1
            (real_rows if key in real_by_name else rows_by_variant)[v].append(row)
            s = row.get("score") or {}
            log(f"{done}/{len(jobs)} {row['case']} [{v}]: {row['outcome']}, "
                + ("accurate" if row["accurate"] else "WRONG") + (", flagged" if row["flagged"] else "")
                + (f", IoU {s['iou_area']:.3f} (floor {s['iou_floor_area']:.3f}), mean {s['mean_to_truth']:.2f}/"
                   f"{s['mean_from_truth']:.2f}" if s else f" ({row.get('error')})"))

    wall = time.monotonic() - t0
    config = {"date": dt.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z"), "seeds_text": args.seeds,
              "n_seeds": len(seeds), "jobs": args.jobs, "threads": args.threads,
              "command": "python3 -m bench.random_suite " + " ".join(shlex.quote(a) for a in (argv or sys.argv[1:]))}
    machine = machine_info()
    report = write_report(config, variants, rows_by_variant, real_rows, real_note, machine, wall)
    summary = {v: summarize(rows_by_variant[v]) for v in variants}
    data = {"config": config, "machine": machine, "variants": variants, "summary": summary,
            "axes": {v: axis_breakdown(rows_by_variant[v]) for v in variants},
            "rows": rows_by_variant, "real": real_rows, "real_note": real_note, "wall_seconds": wall}
    for name, text in (("report.md", report), ("results.json", json.dumps(data, indent=1, default=str))):
        tmp = out / (name + ".tmp")
        tmp.write_text(text)
        tmp.replace(out / name)
    for v in variants:
        s = summary[v]
        log(f"[{v}] accurate {s['accurate']}/{s['runs']}, wrong and converged {s['wrong_converged']}, "
            f"right flagged {s['right_flagged']}, refused {s['refused']}, median {fmt(s['wall_seconds_median'])} s")
    log(f"wrote {out / 'report.md'} in {wall / 60:.1f} min")
    return 0


if __name__ == "__main__":
    sys.exit(main())
