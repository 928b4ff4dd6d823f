"""Where the entries run: a local pool, or Dask (a LocalCluster, or a scheduler's address).

Both call entry_run.run_entry on the same task dicts; results come back as they finish.

The local pool is a ThreadPoolExecutor of --jobs threads, each driving one relief-snake process at a
time: the work and the isolation are in those processes (a segfault ends one CLI, never the pool),
so a thread that waits on one costs nothing, where a ProcessPoolExecutor would put a second Python
process in front of every CLI and break as a whole if one of its workers died.
"""
from __future__ import annotations

import logging
import re
import tempfile
import time
import uuid
import zipfile
from concurrent import futures
from pathlib import Path
from typing import Callable

from .entry_run import cancel_all, run_entry, utc_now
from .manifest import Entry

DASK_SPEC = re.compile(r"^(local:(?P<n>[0-9]+)|(?P<address>(tcp|tls|inproc|ucx)://.+))$")


class ExecutorError(Exception):
    """The executor could not start (Dask missing, scheduler unreachable); one line."""


def make_task(entry: Entry, cli: Path, out: Path, timeout: float, settings: str, mesh_cache: dict | None) -> dict:
    return {"id": entry.id, "index": entry.index, "kind": entry.kind, "cli": str(cli), "mesh": str(entry.mesh),
            "flags": list(entry.flags), "timeout": float(entry.timeout or timeout),
            "region_vertices": str(entry.region_vertices) if entry.region_vertices else None,
            "entry_dir": str(out / "entries" / entry.id), "settings": settings, "mesh_cache": mesh_cache,
            "input_error": entry.input_error}


def lost_record(task: dict, error: BaseException) -> dict:
    """The record of an entry Dask could not run (its worker died, the task could not be unpickled):
    crashed, not final, so a rerun tries it again."""
    from .entry_run import RECORD_FORMAT, RECORD_NAME, write_json_atomic
    first_line = (str(error).strip().splitlines() or [""])[0]
    record = {"format": RECORD_FORMAT, "id": task["id"], "index": task["index"], "kind": task["kind"],
              "status": "crashed", "exit_code": None, "signal": None, "result_status": None, "result": None,
              "extract": None, "message": f"Dask could not run it ({type(error).__name__}: {first_line})",
              "started": None, "finished": utc_now(), "seconds": 0.0, "timeout": task["timeout"],
              "fingerprint": {"settings": task["settings"], "mesh": None}}
    try:
        Path(task["entry_dir"]).mkdir(parents=True, exist_ok=True)
        write_json_atomic(Path(task["entry_dir"]) / RECORD_NAME, record)
    except OSError:
        pass
    return record


def parse_dask_spec(spec: str) -> tuple[int | None, str | None]:
    """'local:N' -> (N, None); 'tcp://host:port' -> (None, address)."""
    m = DASK_SPEC.match(spec)
    if not m or (m.group("n") is not None and int(m.group("n")) < 1):
        raise ValueError(f"--dask must be local:N (N >= 1 workers on this machine) or a scheduler address "
                         f"tcp://HOST:PORT, got '{spec}'")
    return (int(m.group("n")), None) if m.group("n") is not None else (None, m.group("address"))


def run_local(tasks: list[dict], jobs: int, on_done: Callable[[dict], None]) -> None:
    with futures.ThreadPoolExecutor(max_workers=jobs, thread_name_prefix="relief-snake-batch") as pool:
        pending = [pool.submit(run_entry, t) for t in tasks]
        try:
            for f in futures.as_completed(pending):
                record = f.result()
                if record is not None:
                    on_done(record)
        except BaseException:  # Ctrl-C: kill the running CLIs first, or the pool would wait for them
            cancel_all()
            for f in pending:
                f.cancel()
            raise


def _upload_runner(client) -> None:
    """Sends this runner (relief_snake_batch as a zip) to the scheduler, which unpickles the tasks, and to
    every worker, present and future (Client.upload_file), so the cluster needs no copy of it and runs
    the same version as this client."""
    package = Path(__file__).resolve().parent
    with tempfile.TemporaryDirectory(prefix="relief-snake-batch-") as tmp:
        archive = Path(tmp) / f"{package.name}.zip"
        with zipfile.ZipFile(archive, "w") as z:
            for source in sorted(package.glob("*.py")):
                z.write(source, f"{package.name}/{source.name}")
        client.upload_file(str(archive))


def run_dask(tasks: list[dict], spec: str, on_done: Callable[[dict], None]) -> str:
    """Runs the tasks on Dask; returns a description of the cluster (for the summary)."""
    n_workers, address = parse_dask_spec(spec)
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise ExecutorError("--dask needs dask.distributed: python3 -m pip install \"dask[distributed]\" "
                            "(scripts/install-deps.sh installs it)") from None
    cluster = None
    start = time.monotonic()
    try:
        if n_workers is not None:
            # One thread per worker: each runs one CLI at a time, like --jobs N.
            cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None, silence_logs=logging.ERROR)
            client = Client(cluster)
        else:
            client = Client(address, timeout="30s")
    except Exception as e:  # OSError, TimeoutError, or a LocalCluster whose workers did not start
        if cluster is not None:
            cluster.close()
        what = f"cannot reach the Dask scheduler at {address}" if address else f"cannot start a Dask {spec} cluster"
        first_line = (str(e).strip().splitlines() or [type(e).__name__])[0]
        raise ExecutorError(f"{what}: {first_line}") from None
    try:
        if address is not None:
            _upload_runner(client)
        workers = len(client.scheduler_info().get("workers", {}))
        description = f"dask {spec} ({workers} workers, up in {time.monotonic() - start:.1f} s)"
        run_id = uuid.uuid4().hex[:8]
        by_key = {}
        submitted = []
        for t in tasks:
            f = client.submit(run_entry, t, key=f"relief-snake-{t['id']}-{run_id}", pure=False)
            by_key[f.key] = t
            submitted.append(f)
        try:
            for f in as_completed(submitted):
                try:
                    record = f.result()
                except Exception as e:  # the worker died (KilledWorker) or could not run the function
                    record = lost_record(by_key[f.key], e)
                if record is not None:
                    on_done(record)
        except BaseException:
            client.cancel(submitted)
            raise
        return description
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def run(tasks: list[dict], jobs: int, dask: str | None, on_done: Callable[[dict], None]) -> str:
    """Runs every task; returns how (for the summary)."""
    if not tasks:
        return f"dask {dask}" if dask else f"local, {jobs} jobs"
    if dask:
        return run_dask(tasks, dask, on_done)
    run_local(tasks, jobs, on_done)
    return f"local, {jobs} jobs"

