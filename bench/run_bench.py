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
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

if __package__ in (None, ""):  # run as a script: bench/run_bench.py
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.cases import (H_FACTORS, NOISES, POOL_THREADS, SCALING, SUITE, SWEEP_CONFIGS, VARIANTS, W_INTS, scan_args,
                         suite_scans)
from bench.plots import plot_phases, plot_scaling, plot_sweep
from bench.report import f, write_report
from bench.run import REPO, Runner, log, machine_info

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


if __name__ == "__main__":
    sys.exit(main())
