"""Real-window tests of the add-on: Debian's Blender 3.4 on a virtual screen (Xvfb), driven by
real X events (xdotool: clicks, typing, key presses), with screenshots kept as artefacts.

    python3 tests/blender/ui/harness.py --zip build/dist/relief_snake-0.1.0-legacy.zip \
        --build-dir build --out build/blender-ui-artifacts [--scenario artist|crash|all]

Each scenario is one Blender session: tests/blender/ui/driver.py runs inside Blender (a
bpy.app.timers coroutine) and asks this process for events through files in a control
directory (request N.json -> reply N.reply.json); this process moves the mouse, clicks,
types and screenshots with xdotool/xwd, and finds the panel's widgets by the theme colours
the driver reports (the Segment button is the tallest tool-coloured band of the sidebar).
A session fails if the driver reports a failed check, if Blender dies (a segfault is reported
as such), or if it runs past its time limit. Exit status: 0 when every scenario passed.
"""

import argparse
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import screen  # noqa: E402

WIDTH, HEIGHT = 1100, 760


class Display:
    """An Xvfb server on a free display number."""

    def __init__(self):
        self.proc = None
        for n in range(90, 140):
            if not os.path.exists("/tmp/.X11-unix/X%d" % n) and not os.path.exists("/tmp/.X%d-lock" % n):
                self.name = ":%d" % n
                break
        else:
            raise RuntimeError("no free X display number in :90..:139")

    def __enter__(self):
        self.proc = subprocess.Popen(["Xvfb", self.name, "-screen", "0", "%dx%dx24" % (WIDTH, HEIGHT), "-nolisten",
                                      "tcp", "+extension", "GLX"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        sock = "/tmp/.X11-unix/X" + self.name[1:]
        deadline = time.time() + 20
        while not os.path.exists(sock):
            if self.proc.poll() is not None or time.time() > deadline:
                raise RuntimeError("Xvfb %s did not start" % self.name)
            time.sleep(0.1)
        return self

    def __exit__(self, *exc):
        if self.proc and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()


class Session:
    def __init__(self, display, args, scenario, out_dir):
        self.display, self.args, self.scenario = display, args, scenario
        self.out = out_dir
        self.env = dict(os.environ, DISPLAY=display.name)
        self.tmp = tempfile.mkdtemp(prefix="relief-snake-ui-")
        self.control = os.path.join(self.tmp, "control")
        os.makedirs(self.control)
        # A private user config: installing the zip must not touch the user's Blender.
        self.env.update(BLENDER_USER_CONFIG=os.path.join(self.tmp, "config"),
                        BLENDER_USER_SCRIPTS=os.path.join(self.tmp, "scripts"), HOME=self.tmp)
        # Blender's session directory (blender_XXXXXX) too: the harness ends Blender with a signal,
        # which skips Blender's own clean-up, so it goes where the session's clean-up removes it.
        os.makedirs(os.path.join(self.tmp, "tmp"))
        self.env.update(TMPDIR=os.path.join(self.tmp, "tmp"), TMP=os.path.join(self.tmp, "tmp"))
        self.window = None
        self.log = []

    # -- X helpers --------------------------------------------------------------------------
    def xdo(self, *argv, check=True):
        r = subprocess.run(["xdotool"] + [str(a) for a in argv], env=self.env, capture_output=True, text=True,
                           timeout=30)
        if check and r.returncode != 0:
            raise RuntimeError("xdotool %s failed: %s" % (" ".join(map(str, argv)), r.stderr.strip()))
        return r.stdout.strip()

    def find_window(self, timeout=60):
        deadline = time.time() + timeout
        while time.time() < deadline:
            r = subprocess.run(["xdotool", "search", "--onlyvisible", "--name", "Blender"], env=self.env,
                               capture_output=True, text=True, timeout=10)
            ids = r.stdout.split()
            if ids:
                return ids[-1]
            time.sleep(0.5)
        raise RuntimeError("no Blender window appeared within %d s" % timeout)

    def focus(self, x, y):
        """Pointer over (x, y), keyboard focus on Blender's window (no window manager: set it
        directly; retried, since a busy Blender may not answer at once)."""
        for attempt in range(4):
            try:
                # Two moves: Blender activates the button under the pointer on a motion event, and
                # a key or click sent before that goes to whatever was active before.
                self.xdo("mousemove", x + 1, y)
                time.sleep(0.2)
                self.xdo("mousemove", x, y)
                time.sleep(0.2)
                self.xdo("windowfocus", self.window)
                return
            except (RuntimeError, subprocess.TimeoutExpired) as exc:
                last = exc
                time.sleep(0.5 * (attempt + 1))
        raise RuntimeError("could not focus Blender's window: %s" % last)

    def shot(self, name=None):
        img = screen.grab(self.display.name, self.env)
        if name:
            img.save_png(os.path.join(self.out, "%s-%s.png" % (self.scenario, name)))
        return img

    # -- requests from the driver -------------------------------------------------------------
    def do(self, req):
        kind = req["do"]
        reply = {"ok": True}
        if kind == "click":
            self.focus(*req["at"])
            for key in req.get("modifiers", []):
                self.xdo("keydown", key)
            self.xdo("click", req.get("button", 1))
            for key in reversed(req.get("modifiers", [])):
                self.xdo("keyup", key)
        elif kind == "move":
            self.focus(*req["at"])
        elif kind == "key":
            self.focus(*req["at"])
            self.xdo("key", "--clearmodifiers", "--delay", 60, *req["keys"])
        elif kind == "type":
            self.xdo("type", "--delay", 60, req["text"])
        elif kind == "scroll":
            self.focus(*req["at"])
            for key in req.get("modifiers", []):
                self.xdo("keydown", key)
            self.xdo("click", "--repeat", req.get("times", 1), "--delay", 150, 5 if req.get("down", True) else 4)
            for key in reversed(req.get("modifiers", [])):
                self.xdo("keyup", key)
        elif kind == "screenshot":
            self.shot(req["name"])
        elif kind == "find_bands":
            img = self.shot(req.get("name"))
            bands = img.bands(tuple(req["rect"]), tuple(req["rgb"]), req.get("tol", 4), req.get("min_width", 0.5))
            reply["bands"] = bands
        elif kind == "tabs":
            img = self.shot(req.get("name"))
            reply["runs"] = [r for r in img.column_runs(req["x"], req["y0"], req["y1"]) if r[1] - r[0] >= 12]
        elif kind == "count":
            img = self.shot(req.get("name"))
            lo, hi = req["lo"], req["hi"]
            reply["count"] = img.count(tuple(req["rect"]), lambda p: all(lo[k] <= p[k] <= hi[k] for k in range(3)))
        else:
            raise ValueError("unknown request %r" % kind)
        return reply

    def run(self, timeout):
        cmd = [self.args.blender, "--factory-startup", "--window-geometry", "0", "0", str(WIDTH), str(HEIGHT),
               "--python-exit-code", "1", "--python", os.path.join(HERE, "driver.py"), "--",
               "--control", self.control, "--scenario", self.scenario, "--zip", os.path.abspath(self.args.zip),
               "--build-dir", os.path.abspath(self.args.build_dir)] + (["--search"] if self.args.search else [])
        blender_log = open(os.path.join(self.out, "%s-blender.log" % self.scenario), "w")
        proc = subprocess.Popen(cmd, env=self.env, stdout=blender_log, stderr=subprocess.STDOUT,
                                start_new_session=True)
        deadline = time.time() + timeout
        self.t_start = time.time()
        self.trace = open(os.path.join(self.out, "%s-requests.log" % self.scenario), "w")
        n = 0
        failure = None
        try:
            while True:
                if time.time() > deadline:
                    failure = "timed out after %d s (last request %d)" % (timeout, n)
                    break
                code = proc.poll()
                if code is not None:
                    if code < 0:
                        failure = "Blender died from signal %s (%s)" % (
                            -code, signal.Signals(-code).name if -code in signal.Signals._value2member_map_ else "?")
                    break
                req_path = os.path.join(self.control, "%d.json" % n)
                if os.path.exists(req_path):
                    with open(req_path) as f:
                        req = json.load(f)
                    if self.window is None:
                        self.window = self.find_window()
                    t_req = time.time()
                    try:
                        reply = self.do(req)
                    except Exception as exc:  # tell the driver; it decides whether that fails the test
                        reply = {"ok": False, "error": "%s: %s" % (type(exc).__name__, exc)}
                    self.trace.write("%6.1f %3d %.2fs %s -> %s\n" % (time.time() - self.t_start, n, time.time() - t_req,
                                                                  json.dumps(req)[:200], json.dumps(reply)[:200]))
                    self.trace.flush()
                    tmp = os.path.join(self.control, "%d.reply.tmp" % n)
                    with open(tmp, "w") as f:
                        json.dump(reply, f)
                    os.replace(tmp, os.path.join(self.control, "%d.reply.json" % n))
                    n += 1
                    continue
                time.sleep(0.05)
        finally:
            if proc.poll() is None:
                if failure:
                    try:
                        self.shot("timeout")
                    except Exception:
                        pass
                os.killpg(proc.pid, signal.SIGTERM)
                try:
                    proc.wait(10)
                except subprocess.TimeoutExpired:
                    os.killpg(proc.pid, signal.SIGKILL)
                    proc.wait()
            blender_log.close()
        result_path = os.path.join(self.control, "result.json")
        result = json.load(open(result_path)) if os.path.exists(result_path) else None
        if result is None and failure is None:
            failure = "Blender exited (%s) without a result" % proc.returncode
        shutil.copy(os.path.join(self.control, "log.txt"), os.path.join(self.out, "%s-driver.log" % self.scenario)) \
            if os.path.exists(os.path.join(self.control, "log.txt")) else None
        return failure, result


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--zip", required=True, help="the legacy add-on zip to install")
    p.add_argument("--build-dir", default="build", help="for make-scan")
    p.add_argument("--out", default="build/blender-ui-artifacts")
    p.add_argument("--blender", default="blender")
    p.add_argument("--scenario", default="all", choices=("all", "artist", "crash"))
    p.add_argument("--search", action="store_true",
                   help="press Segment through F3 search (for add-on versions without the tall Segment button)")
    p.add_argument("--timeout", type=int, default=240, help="seconds per scenario")
    args = p.parse_args()
    for tool in ("Xvfb", "xdotool", "xwd", args.blender):
        if shutil.which(tool) is None:
            sys.exit("harness: %s is missing: run scripts/install-blender.sh" % tool)
    os.makedirs(args.out, exist_ok=True)
    scenarios = ("crash", "artist") if args.scenario == "all" else (args.scenario,)
    failed = []
    for name in scenarios:
        t0 = time.time()
        with Display() as display:
            session = Session(display, args, name, args.out)
            try:
                failure, result = session.run(args.timeout)
            finally:
                # The session's private config and control files; its logs and screenshots are in args.out.
                shutil.rmtree(session.tmp, ignore_errors=True)
        checks = (result or {}).get("checks", [])
        for c in checks:
            print("ui %-7s %s %s%s" % (name, "ok  " if c["ok"] else "FAIL", c["name"],
                                      "" if c["ok"] else ": " + c.get("detail", "")))
        bad = [c for c in checks if not c["ok"]]
        if failure or bad or not checks:
            failed.append(name)
            print("ui %-7s FAILED: %s (%.0f s; logs in %s)" % (name, failure or "%d check(s) failed" % len(bad),
                                                               time.time() - t0, args.out))
        else:
            print("ui %-7s passed: %d checks in %.0f s" % (name, len(checks), time.time() - t0))
    print("ui: screenshots and logs in %s" % os.path.abspath(args.out))
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
