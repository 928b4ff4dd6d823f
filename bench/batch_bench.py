"""relief-snake batch: the same archive locally (--jobs) and on a Dask LocalCluster, timed end to end.

    python3 bench/batch_bench.py [--build-dir build] [--scans 50] [--triangles 3000] [--jobs 2]

Makes --scans scans with make-scan (disks, rectangles, ducks), runs `relief-snake batch` on them with
--jobs N, then with --dask local:N, each into a fresh folder, then once more on the Dask folder (a rerun
that skips everything), and prints, per run, the wall time of the whole command (Python start, Dask's
cluster start and stop included), the runner's own wall time (summary.json), and the seconds spent in
the entries. Prints numbers only; asserts nothing about speed.
"""
import argparse
import json
import subprocess
import sys
import tempfile
import time
from concurrent import futures
from pathlib import Path

SHAPES = ("disk", "rectangle", "duck")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build-dir", default="build")
    ap.add_argument("--scans", type=int, default=50)
    ap.add_argument("--triangles", type=int, default=3000)
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args(argv)
    build = Path(args.build_dir).resolve()
    cli, make_scan = build / "relief-snake", build / "make-scan"
    for exe in (cli, make_scan):
        if not exe.is_file():
            print(f"batch_bench: {exe} not found: build the relief-snake and make-scan targets", file=sys.stderr)
            return 1
    with tempfile.TemporaryDirectory(prefix="batch-bench-") as tmp:
        root = Path(tmp)

        def make(i):
            prefix = root / f"scan-{i:03d}"
            subprocess.run([str(make_scan), "--shape", SHAPES[i % 3], "--triangles", str(args.triangles),
                            "--seed", str(i), "--out", str(prefix)], check=True, capture_output=True)
            return {"mesh": prefix.name + ".ply", "picks": prefix.name + ".truth.json"}

        with futures.ThreadPoolExecutor(4) as pool:
            entries = list(pool.map(make, range(1, args.scans + 1)))
        manifest = root / "manifest.json"
        manifest.write_text(json.dumps({"defaults": {"options": {"threads": 1}}, "entries": entries}))
        print(f"{args.scans} scans of ~{args.triangles} triangles, {args.jobs} jobs / workers")
        print(f"{'run':<28} {'command s':>10} {'runner s':>9} {'in entries s':>13} {'ran':>5} {'ok':>5}")
        runs = [("local --jobs", "local", ["--jobs", str(args.jobs)]),
                ("dask LocalCluster", "dask", ["--dask", f"local:{args.jobs}"]),
                ("dask rerun (all skipped)", "dask", ["--dask", f"local:{args.jobs}"])]
        for name, folder, extra in runs:
            out = root / f"out-{folder}"
            start = time.monotonic()
            r = subprocess.run([str(cli), "batch", str(manifest), "--out", str(out), "--no-progress", *extra],
                               capture_output=True, text=True)
            seconds = time.monotonic() - start
            if r.returncode not in (0, 3):
                print(f"batch_bench: {name} exited {r.returncode}: {r.stderr.strip()[-500:]}", file=sys.stderr)
                return 1
            s = json.loads((out / "summary.json").read_text())
            print(f"{name:<28} {seconds:>10.2f} {s['wall_seconds']:>9.2f} {s['entry_seconds_ran']:>13.2f} "
                  f"{s['ran']:>5} {s['counts']['ok']:>5}  {s['executor']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
