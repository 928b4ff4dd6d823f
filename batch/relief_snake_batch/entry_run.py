"""One entry: its relief-snake process, its timeout, its record. The same function runs in the local
pool's threads and on Dask workers, so it takes and returns plain dicts (picklable) and imports
nothing outside the standard library.

The CLI runs in its own session (process group), from the entry's folder DIR/entries/ID/, with its
stdout and stderr in stderr.log there. It writes its result to a temporary name that is renamed to
result.json only when the CLI exited with a result (0 or 3), so result.json is never half-written.
A timeout, or any child the CLI left behind, is ended by killing the whole group; the group id stays
reserved until the CLI is reaped (it is waited for with a pidfd or os.waitid(WNOWAIT), neither of
which reaps it), so the kill cannot reach a stranger.
"""
from __future__ import annotations

import datetime
import json
import os
import select
import shutil
import signal
import socket
import subprocess
import threading
import time
from pathlib import Path

RECORD_FORMAT = "relief-snake-batch-record/1"
RECORD_NAME = "record.json"
RESULT_NAME = "result.json"
LOG_NAME = "stderr.log"
EXTRACT_NAME = "extract"
PARTIAL_RESULT = ".result.json.partial"

# Statuses. ok/doubtful/failed are final: a rerun skips them while the entry is unchanged (a failed
# entry failed on its input, which a rerun would read the same way). crashed/timeout are not: a rerun
# tries them again (memory pressure, a loaded machine, a --timeout too short).
FINAL_STATUSES = ("ok", "doubtful", "failed")
STATUSES = ("ok", "doubtful", "failed", "crashed", "timeout")

# Set by the runner on Ctrl-C: entries still running are killed and write no record.
_cancelled = threading.Event()
_live_lock = threading.Lock()
_live: set[int] = set()  # process-group ids of the CLIs running in this process


def utc_now() -> str:
    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="milliseconds")


def write_json_atomic(path: Path, data) -> None:
    """Writes JSON to a temporary name beside `path`, then renames it into place."""
    tmp = path.with_name(f".{path.name}.partial-{os.getpid()}-{threading.get_ident()}")
    with open(tmp, "w") as f:
        json.dump(data, f, indent=2)
        f.write("\n")
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def mesh_identity(path: Path, cached: dict | None = None) -> dict:
    """{size, mtime_ns, sha256} of the mesh file; the sha256 is reused from `cached` (a record's)
    when size and mtime are unchanged, so a rerun does not read every scan again. sha256 is None
    when the file cannot be read."""
    from .manifest import file_sha256
    try:
        st = os.stat(path)
    except OSError:
        return {"size": None, "mtime_ns": None, "sha256": None}
    if cached and cached.get("sha256") and cached.get("size") == st.st_size and cached.get("mtime_ns") == st.st_mtime_ns:
        return dict(cached)
    return {"size": st.st_size, "mtime_ns": st.st_mtime_ns, "sha256": file_sha256(path)}


def cancel_all() -> None:
    """Ctrl-C: kill every CLI this process started and keep their entries unrecorded."""
    _cancelled.set()
    with _live_lock:
        groups = list(_live)
    for group in groups:
        _kill_group(group)


def _kill_group(group: int) -> None:
    try:
        os.killpg(group, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def _wait_for_exit(pid: int, timeout: float) -> bool:
    """Waits until the process exits, without reaping it. False when the timeout passed first.
    A pidfd (Linux 5.3+) wakes us the moment it exits; elsewhere waitid(WNOWAIT) is polled."""
    try:
        fd = os.pidfd_open(pid)
    except (AttributeError, OSError):
        fd = None
    if fd is not None:
        try:
            poller = select.poll()  # not select.select: a worker may hold more than FD_SETSIZE files
            poller.register(fd, select.POLLIN)
            return bool(poller.poll(max(0.0, timeout) * 1000))
        finally:
            os.close(fd)
    deadline = time.monotonic() + timeout
    pause = 0.005
    while True:
        if os.waitid(os.P_PID, pid, os.WEXITED | os.WNOWAIT | os.WNOHANG) is not None:
            return True
        left = deadline - time.monotonic()
        if left <= 0:
            return False
        time.sleep(min(pause, left))
        pause = min(pause * 2, 0.1)


def _last_error_line(log: Path) -> str:
    """The CLI's one-line error: the last 'relief-snake: ' line of its stderr, without the prefix."""
    try:
        with open(log, "rb") as f:
            f.seek(max(0, os.path.getsize(log) - 8192))
            lines = f.read().decode("utf-8", "replace").splitlines()
    except OSError:
        return ""
    for line in reversed(lines):
        if line.startswith("relief-snake: "):
            return line[len("relief-snake: "):].strip()
    return lines[-1].strip()[:300] if lines else ""


def _signal_name(number: int) -> str:
    try:
        return signal.Signals(number).name
    except ValueError:
        return f"signal {number}"


def command_of(task: dict) -> list[str]:
    """The CLI command of an entry (run from its folder)."""
    cmd = [task["cli"], task["kind"], task["mesh"], *task["flags"]]
    if task.get("region_vertices"):
        cmd += ["--region-vertices", task["region_vertices"]]
    return cmd + ["--out", PARTIAL_RESULT]


def run_entry(task: dict) -> dict | None:
    """Runs one entry and writes DIR/entries/ID/record.json; returns the record (None when cancelled).

    task: {id, index, kind, cli, mesh, flags, region_vertices, timeout, entry_dir, settings,
    mesh_cache, input_error} (executors.make_task)."""
    entry_dir = Path(task["entry_dir"])
    started, t0 = utc_now(), time.monotonic()
    record = {"format": RECORD_FORMAT, "id": task["id"], "index": task["index"], "kind": task["kind"],
              "status": "failed", "exit_code": None, "signal": None, "message": "", "result_status": None,
              "result": None, "extract": None, "log": LOG_NAME, "started": started, "finished": None,
              "seconds": 0.0, "timeout": task["timeout"], "host": socket.gethostname(), "pid": os.getpid(),
              "command": None, "mesh": task["mesh"],
              "fingerprint": {"settings": task["settings"], "mesh": None}}
    try:
        entry_dir.mkdir(parents=True, exist_ok=True)
        record["fingerprint"]["mesh"] = mesh_identity(Path(task["mesh"]), task.get("mesh_cache"))
        # What a previous run left is not this run's result.
        for name in (RESULT_NAME, PARTIAL_RESULT):
            (entry_dir / name).unlink(missing_ok=True)
        shutil.rmtree(entry_dir / EXTRACT_NAME, ignore_errors=True)
        if task.get("input_error"):
            record["message"] = task["input_error"]
        else:
            _run_cli(task, entry_dir, record)
    except Exception as e:  # the runner's own trouble (disk full, permissions): this entry's failure
        record["status"], record["message"] = "failed", f"the batch runner could not run it: {e}"
    if _cancelled.is_set():
        return None
    record["finished"] = utc_now()
    record["seconds"] = round(time.monotonic() - t0, 3)
    try:
        write_json_atomic(entry_dir / RECORD_NAME, record)
    except OSError as e:
        record["status"], record["message"] = "failed", f"its record could not be written: {e}"
    return record


def _run_cli(task: dict, entry_dir: Path, record: dict) -> None:
    cmd = command_of(task)
    record["command"] = cmd
    log_path = entry_dir / LOG_NAME
    with open(log_path, "wb") as log:
        p = subprocess.Popen(cmd, cwd=entry_dir, stdin=subprocess.DEVNULL, stdout=log, stderr=log,
                             start_new_session=True)
    with _live_lock:
        _live.add(p.pid)
    try:
        exited = _wait_for_exit(p.pid, task["timeout"])
        # The CLI has exited (or is to be killed) but is not reaped yet: its group id is still ours.
        _kill_group(p.pid)
        code = p.wait()
    finally:
        with _live_lock:
            _live.discard(p.pid)
    partial = entry_dir / PARTIAL_RESULT
    record["exit_code"] = code
    if not exited:
        record["status"], record["exit_code"] = "timeout", None
        record["message"] = (f"no result after {task['timeout']:g} s; killed (give the entry a longer "
                             f"\"timeout\" or the run a longer --timeout)")
    elif code < 0:
        record["status"], record["signal"] = "crashed", _signal_name(-code)
        record["exit_code"] = None
        record["message"] = (f"relief-snake {task['kind']} was killed by {_signal_name(-code)}; see "
                             f"entries/{task['id']}/{LOG_NAME}")
    elif code in (0, 3):
        try:
            document = json.loads(partial.read_text())
        except (OSError, ValueError) as e:
            record["status"] = "failed"
            record["message"] = f"relief-snake exited with code {code} but its result is missing or unreadable ({e})"
        else:
            os.replace(partial, entry_dir / RESULT_NAME)
            record["result"] = RESULT_NAME
            if (entry_dir / EXTRACT_NAME).is_dir():
                record["extract"] = EXTRACT_NAME
            record["result_status"] = document.get("status") if isinstance(document, dict) else None
            record["status"] = "ok" if code == 0 else "doubtful"
            if code == 3:
                message = document.get("message") if isinstance(document, dict) else ""
                record["message"] = message or f"status {record['result_status']}"
    else:
        record["status"] = "failed"
        line = _last_error_line(log_path)
        if code == 2:
            record["message"] = f"relief-snake refused the entry's arguments: {line}"
        else:
            record["message"] = line or f"relief-snake exited with code {code}"
    partial.unlink(missing_ok=True)
