"""`relief-snake batch MANIFEST.json --out DIR [options]` (python3 -m relief_snake_batch).

Exit codes: 0 every entry ok; 3 some doubtful, none failed; 1 some failed, crashed or timed out, or
the run could not start (one line); 2 a usage or manifest error (one line; nothing ran); 130 Ctrl-C.
"""
from __future__ import annotations

import argparse
import fcntl
import os
import shutil
import signal
import sys
import time
from pathlib import Path

from . import executors, records, summary as summary_mod
from .entry_run import STATUSES, cancel_all, utc_now
from .manifest import ManifestError, load_manifest

PREFIX = "relief-snake batch: "
DEFAULT_TIMEOUT = 600.0


class UsageError(Exception):
    pass


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, not argparse's usage block
        raise UsageError(f"{message} (see relief-snake batch --help)")


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="relief-snake batch", description=(
        "Runs every entry of a manifest (docs/batch.md) through relief-snake segment or detect, each as its "
        "own process, and records each outcome in DIR; a rerun skips the entries that finished and did "
        "not change. Exit codes: 0 all ok, 3 some doubtful, 1 some failed, crashed or timed out, 2 usage "
        "or manifest error."))
    p.add_argument("manifest", metavar="MANIFEST.json", help="the manifest (paths in it are relative to it)")
    p.add_argument("--out", metavar="DIR", required=True, help="where records, results and the summary go")
    p.add_argument("--jobs", metavar="N", type=int, default=None,
                   help="scans run at once on this machine (default: the number of cores)")
    p.add_argument("--timeout", metavar="S", type=float, default=None,
                   help=f"seconds per scan before it is killed (default {DEFAULT_TIMEOUT:g}; an entry's "
                        "\"timeout\" overrides it)")
    p.add_argument("--dask", metavar="SPEC", default=None,
                   help="run on Dask instead: local:N (a LocalCluster of N workers) or tcp://HOST:PORT "
                        "(a running scheduler; workers need the same paths)")
    p.add_argument("--force", action="store_true", help="rerun every entry, finished or not")
    p.add_argument("--cli", metavar="PATH", default=None,
                   help="the relief-snake executable (default: the one that started the batch, "
                        "$RELIEF_SNAKE_CLI, or relief-snake on PATH)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    return p


def _find_cli(given: str | None) -> Path:
    candidate = given or os.environ.get("RELIEF_SNAKE_CLI") or shutil.which("relief-snake")
    if not candidate:
        raise UsageError("no relief-snake executable: give --cli PATH or put relief-snake on PATH")
    path = Path(candidate).expanduser()
    if not path.is_file() or not os.access(path, os.X_OK):
        raise UsageError(f"the relief-snake executable '{candidate}' is not an executable file; give --cli PATH")
    return path.resolve()


class _Progress:
    """tqdm on stderr when it is installed, else one line per finished entry."""

    def __init__(self, total: int, enabled: bool):
        self.total, self.done, self.bar = total, 0, None
        self.enabled = enabled and total > 0
        self.counts = {s: 0 for s in STATUSES}
        if self.enabled:
            try:
                from tqdm import tqdm
            except ImportError:
                tqdm = None
            if tqdm is not None:
                self.bar = tqdm(total=total, unit="scan", desc="relief-snake batch", file=sys.stderr,
                                dynamic_ncols=True, mininterval=0.2)

    def update(self, record: dict) -> None:
        self.done += 1
        self.counts[record["status"]] = self.counts.get(record["status"], 0) + 1
        if not self.enabled:
            return
        line = None
        if record["status"] != "ok":
            line = f"{PREFIX}{record['id']}: {record['status']}: {record['message']}"
        if self.bar is not None:
            if line:
                self.bar.write(line, file=sys.stderr)
            self.bar.set_postfix_str(" ".join(f"{s} {n}" for s, n in self.counts.items() if n), refresh=False)
            self.bar.update(1)
        else:
            print(line or f"{PREFIX}[{self.done}/{self.total}] {record['id']}: ok", file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _terminate(signum, frame):
    raise KeyboardInterrupt


def run(argv: list[str]) -> int:
    args = build_parser().parse_args(argv)
    if args.jobs is not None and args.jobs < 1:
        raise UsageError(f"--jobs must be >= 1, got {args.jobs}")
    if args.jobs is not None and args.dask:
        raise UsageError("--jobs is for the local pool; with --dask the workers set how many scans run at once")
    if args.timeout is not None and not (args.timeout > 0 and args.timeout < float("inf")):
        raise UsageError(f"--timeout must be a number of seconds > 0, got {args.timeout:g}")
    if args.dask:
        try:
            executors.parse_dask_spec(args.dask)
        except ValueError as e:
            raise UsageError(str(e)) from None
    jobs = args.jobs or os.cpu_count() or 1
    timeout = args.timeout or DEFAULT_TIMEOUT
    cli = _find_cli(args.cli)
    try:
        entries = load_manifest(Path(args.manifest))
    except ManifestError as e:
        raise UsageError(f"{args.manifest}: {e}") from None

    out = Path(args.out).resolve()
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {args.out} is a file; give a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
        lock_file = open(out / ".batch.lock", "w")
    except OSError as e:
        print(f"{PREFIX}cannot create the output folder {out}: {e.strerror}", file=sys.stderr)
        return 1
    try:
        fcntl.flock(lock_file, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        print(f"{PREFIX}another batch run is writing to {out}; wait for it or choose another --out", file=sys.stderr)
        return 1

    started, t0 = utc_now(), time.monotonic()
    rows: dict[str, dict] = {}
    tasks = []
    for entry in entries:
        settings = entry.settings_fingerprint()
        record = records.read_record(out, entry)
        if not args.force and records.reusable(out, entry, record, settings):
            rows[entry.id] = {**record, "skipped": True}
            continue
        cache = (record or {}).get("fingerprint", {}).get("mesh") if record else None
        tasks.append(executors.make_task(entry, cli, out, timeout, settings, cache))

    where = f"Dask {args.dask}" if args.dask else f"{jobs} local jobs"
    print(f"{PREFIX}{len(entries)} entries: {len(tasks)} to run on {where}, {len(entries) - len(tasks)} "
          f"finished before (skipped; --force reruns them)", file=sys.stderr, flush=True)
    progress = _Progress(len(tasks), enabled=not args.no_progress)

    def on_done(record: dict) -> None:
        rows[record["id"]] = {**record, "skipped": False}
        progress.update(record)

    # A job scheduler's SIGTERM ends the run like Ctrl-C: running CLIs killed, finished entries kept.
    signal.signal(signal.SIGTERM, _terminate)
    try:
        description = executors.run(tasks, jobs, args.dask, on_done)
    except KeyboardInterrupt:
        cancel_all()
        progress.close()
        print(f"{PREFIX}interrupted: {len(rows)} entries recorded; rerun the same command to go on", file=sys.stderr)
        return 130
    except executors.ExecutorError as e:
        progress.close()
        print(f"{PREFIX}{e}", file=sys.stderr)
        return 1
    progress.close()

    ordered = [rows[e.id] for e in entries if e.id in rows]
    meta = {"manifest": str(Path(args.manifest).resolve()), "out": str(out), "cli": str(cli),
            "executor": description, "started": started, "finished": utc_now(),
            "wall_seconds": round(time.monotonic() - t0, 3), "timeout": timeout, "force": args.force}
    result = summary_mod.make_summary(ordered, meta)
    summary_mod.write_summary(out, result)
    print(summary_mod.printed_table(result))
    print(summary_mod.counts_line(result) + f"; wrote {out / 'summary.md'}")
    return result["exit_code"]


def main(argv: list[str] | None = None) -> int:
    try:
        return run(sys.argv[1:] if argv is None else argv)
    except UsageError as e:
        print(f"{PREFIX}{e}", file=sys.stderr)
        return 2
