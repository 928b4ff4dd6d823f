"""Running the tools: make-scan (cached per scan) and the relief-snake CLI, with a timeout and a
runaway check on the snake's progress lines; every engine failure becomes a row, never an exception."""
from __future__ import annotations

import json
import math
import os
import platform
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

from .cases import PAPER_W_INT, Scan

REPO = Path(__file__).resolve().parents[1]

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


EXIT_DOUBTFUL = 3  # relief-snake's exit code for a written result whose status is doubtful or iteration_cap


def run_engine(cmd, timeout, snaxel_limit, expected_snaxels):
    """Runs one relief-snake command and waits for it. Progress lines on stderr ("relief-snake: refine
    iteration 1050, 24899 snaxels") let us stop a runaway snake (a reversed loop that deflation inflates
    without bound) early instead of waiting for the iteration cap: more than `snaxel_limit` snaxels is
    reported as such. Returns {wall_seconds, peak_mb, exit_code, killed (why, or None), stderr (last lines)}."""
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
            if m and int(m.group(3)) > snaxel_limit:
                kill(f"runaway: the snake grew to {int(m.group(3)):,} snaxels in the {m.group(1)} phase "
                     f"(iteration {m.group(2)}; the true outline needs ~{expected_snaxels:,}); killed")

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    timer = threading.Timer(timeout, lambda: kill(f"timeout after {timeout:.0f} s; killed"))
    timer.start()
    _, status, usage = os.wait4(p.pid, 0)
    timer.cancel()
    p.returncode = os.waitstatus_to_exitcode(status)
    reader.join()
    p.stderr.close()
    return {"wall_seconds": time.monotonic() - start, "peak_mb": usage.ru_maxrss / 1024.0,  # Linux: kilobytes
            "exit_code": p.returncode, "killed": killed["why"], "stderr": "\n".join(tail)}


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
        if w_int is None and "refit_step_height=0" in options:
            w_int = PAPER_W_INT  # the paper's method, or a variant of it: the paper's W_int too
        if w_int is not None:
            cmd += ["--w-int", repr(w_int)]
        if not truth.get("picks_closed", True):
            cmd += ["--open", "--relief-side", truth.get("relief_side", "left")]
        for o in options:
            cmd += ["--option", o]
        row["command"] = " ".join(Path(c).name if i == 0 else c for i, c in enumerate(cmd))
        limit, expected = runaway_limit(truth)
        proc = run_engine(cmd, self.timeout, limit, expected)
        row["wall_seconds"] = proc["wall_seconds"]
        row["peak_mb"] = proc["peak_mb"]
        row["exit_code"] = proc["exit_code"]
        if proc["killed"]:
            row["error"] = proc["killed"]
            out.unlink(missing_ok=True)
            return row
        # Exit code 3: the engine doubts its result (status doubtful or iteration_cap) and still wrote it.
        if proc["exit_code"] not in (0, EXIT_DOUBTFUL) or not out.is_file():
            row["error"] = (proc["stderr"].splitlines() or [f"exit code {proc['exit_code']}"])[-1]
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


