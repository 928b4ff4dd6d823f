"""Are two builds' contours identical? The check of a behaviour-unchanged refactor (issue 9).

    python3 -m bench.compare_contours --base BUILD_A/relief-snake --new BUILD_B/relief-snake \\
        --make-scan BUILD_A/make-scan [--seeds 0:40] [--quick] [--variants default,paper] [--jobs 2] \\
        [--work DIR]

Every benchmark case (bench/cases.py SUITE, scans as `make bench` makes them, or --quick's smaller
ones) and every random-suite seed (`make-scan --random SEED`, the typed h the suite uses) is segmented
by both CLIs with the same arguments, from the same scan (made once, by --make-scan), and the two
result documents are compared exactly: `status`, `contour` (every coordinate, bit for bit as JSON
writes them), `relief_vertices`, `closed` and `relief_side`. An error exit must give the same last
stderr line in both. Prints one line per difference and the totals; exits 1 if anything differs.
"""
from __future__ import annotations

import argparse
import concurrent.futures as futures
import hashlib
import json
import shlex
import subprocess
import sys
from pathlib import Path

if __package__ in (None, ""):  # run as a script: bench/compare_contours.py
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.cases import PAPER, PAPER_W_INT, SUITE, suite_scans
from bench.random_suite import parse_seeds

COMPARED = ("status", "contour", "relief_vertices", "closed", "relief_side")
# default: the engine's defaults; the others switch on paths the defaults leave off (the foot
# snap's grid and walks, the exact q search's recorded edge crossings) or the paper's method.
VARIANT_ARGS = {"default": [], "paper": ["--w-int", repr(PAPER_W_INT)] + [a for o in PAPER for a in ("--option", o)],
                "foot-snap": ["--option", "foot_snap=1"], "exact-q": ["--option", "exact_q=1"]}


def make_scan(make_scan_exe: Path, args: list[str], prefix: Path) -> None:
    marker = Path(f"{prefix}.done")
    if marker.is_file():
        return
    r = subprocess.run([str(make_scan_exe), *args, "--out", str(prefix)], capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"compare: make-scan {shlex.join(args)} failed: {r.stderr.strip()}")
    marker.write_text("ok\n")


def bench_cases(exe: Path, work: Path, quick: bool) -> list[dict]:
    scans = suite_scans(quick)
    cases = []
    for case in SUITE:
        prefix = work / "scans" / (("quick-" if quick else "") + case.scan)
        make_scan(exe, scans[case.scan], prefix)
        truth = json.loads(Path(f"{prefix}.truth.json").read_text())
        args = ["--picks", ",".join(map(str, truth["picks"])), "--step-height", repr(case.h_factor * truth["h"])]
        if case.w_int is not None:
            args += ["--w-int", repr(case.w_int)]
        if not truth.get("picks_closed", True):
            args += ["--open", "--relief-side", truth.get("relief_side", "left")]
        for o in case.options:
            args += ["--option", o]
        cases.append({"name": case.name, "mesh": Path(f"{prefix}.ply"), "args": args})
    return cases


def random_cases(exe: Path, work: Path, seeds: list[int]) -> list[dict]:
    cases = []
    for seed in seeds:
        prefix = work / "scans" / f"seed-{seed}"
        make_scan(exe, ["--random", str(seed)], prefix)
        truth = json.loads(Path(f"{prefix}.json").read_text())
        args = ["--picks", ",".join(map(str, truth["picks"])), "--step-height", repr(truth["typed_step_height"])]
        if not truth.get("closed", truth.get("picks_closed", True)):
            args += ["--open", "--relief-side", truth["relief_side"]]
        cases.append({"name": f"seed-{seed}", "mesh": Path(f"{prefix}.ply"), "args": args})
    return cases


def run(cli: Path, case: dict, variant: str, out: Path, threads: int, timeout: float) -> dict:
    """The compared fields of one run; cached beside `out` by the CLI binary's digest, so a
    rerun (or --prepare, which runs only the base) does not redo it."""
    digest = hashlib.sha256(cli.read_bytes()).hexdigest()[:12]
    cached = out.with_name(f"{out.stem}.{digest}.t{threads}.cached.json")
    if cached.is_file():
        return json.loads(cached.read_text())
    fields = run_uncached(cli, case, variant, out, threads, timeout)
    if not str(fields.get("error", "")).startswith("timeout"):
        tmp = cached.with_suffix(".tmp")
        tmp.write_text(json.dumps(fields))
        tmp.replace(cached)
    return fields


def run_uncached(cli: Path, case: dict, variant: str, out: Path, threads: int, timeout: float) -> dict:
    out.unlink(missing_ok=True)
    cmd = [str(cli), "segment", str(case["mesh"]), *case["args"], *VARIANT_ARGS[variant],
           "--option", f"threads={threads}", "--out", str(out)]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"error": f"timeout after {timeout:g} s"}
    if p.returncode not in (0, 3) or not out.is_file():
        return {"error": f"exit {p.returncode}: " + (p.stderr.strip().splitlines() or ["?"])[-1]}
    doc = json.loads(out.read_text())
    out.unlink(missing_ok=True)
    return {k: doc.get(k) for k in COMPARED}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--base", required=True, type=Path, help="the reference build's relief-snake")
    ap.add_argument("--new", required=True, type=Path, help="the changed build's relief-snake")
    ap.add_argument("--make-scan", required=True, type=Path, help="one make-scan for both (the scans are shared)")
    ap.add_argument("--seeds", default="0:40", help="random-suite seeds, A:B or a comma list ('' for none)")
    ap.add_argument("--no-bench", action="store_true", help="skip the benchmark's cases")
    ap.add_argument("--quick", action="store_true", help="the benchmark's smaller --quick scans")
    ap.add_argument("--variants", default="default", help="comma list of: " + ", ".join(VARIANT_ARGS))
    ap.add_argument("--threads", type=int, default=1, help="engine threads per run (0: all cores)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=300)
    ap.add_argument("--work", type=Path, default=Path("build/compare-contours"))
    ap.add_argument("--prepare", action="store_true",
                    help="run (and cache) the base build only, e.g. while the new one is still building")
    a = ap.parse_args(argv)
    for exe in (a.base, a.make_scan) if a.prepare else (a.base, a.new, a.make_scan):
        if not exe.is_file():
            raise SystemExit(f"compare: {exe} not found")
    a.work.mkdir(parents=True, exist_ok=True)
    (a.work / "scans").mkdir(exist_ok=True)
    (a.work / "runs").mkdir(exist_ok=True)
    variants = [v for v in a.variants.split(",") if v]
    for v in variants:
        if v not in VARIANT_ARGS:
            raise SystemExit(f"compare: unknown variant {v!r}; use {', '.join(VARIANT_ARGS)}")
    cases = [] if a.no_bench else bench_cases(a.make_scan, a.work, a.quick)
    cases += random_cases(a.make_scan, a.work, parse_seeds(a.seeds) if a.seeds else [])

    def one(job):
        case, variant = job
        tag = f"{case['name']}.{variant}"
        base = run(a.base, case, variant, a.work / "runs" / f"{tag}.base.json", a.threads, a.timeout)
        if a.prepare:
            return tag, base, base, []
        new = run(a.new, case, variant, a.work / "runs" / f"{tag}.new.json", a.threads, a.timeout)
        diffs = [k for k in sorted(set(base) | set(new)) if base.get(k) != new.get(k)]
        return tag, base, new, diffs

    jobs = [(c, v) for c in cases for v in variants]
    identical = 0
    with futures.ThreadPoolExecutor(max(1, a.jobs)) as pool:
        for tag, base, new, diffs in pool.map(one, jobs):
            status = base.get("status") or base.get("error")
            if diffs:
                detail = "; ".join(f"{k}: {str(base.get(k))[:80]} != {str(new.get(k))[:80]}" for k in diffs)
                print(f"DIFFERENT {tag}: {detail}", flush=True)
            else:
                identical += 1
                print(f"identical {tag} ({status}, {len(base.get('contour') or [])} snaxels)", flush=True)
    if a.prepare:
        print(f"compare: {len(jobs)} base runs cached")
        return 0
    print(f"compare: {len(jobs)} runs, {identical} identical, {len(jobs) - identical} different")
    return 0 if identical == len(jobs) else 1


if __name__ == "__main__":
    sys.exit(main())
