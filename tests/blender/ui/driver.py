"""Runs inside an interactive Blender (tests/blender/ui/harness.py starts it on Xvfb):

    blender --factory-startup --python tests/blender/ui/driver.py -- --control DIR --scenario NAME \
        --zip relief_snake-legacy.zip --build-dir build

A coroutine on bpy.app.timers: it sets the scene up, then asks the harness for real X events
(clicks on the panel's buttons, typing, Ctrl+Z, Esc) and screenshots, and checks what Blender
did between them. Results go to DIR/result.json ({"checks": [{name, ok, detail}]}), progress
to DIR/log.txt. Scenarios:
  crash   the sequence that made Blender 3.4 segfault on Ctrl+Z (issue 10), then more undo/redo;
  artist  pick vertices with clicks, Segment, preview colour during the run, the result on screen,
          Ctrl+Z / Ctrl+Shift+Z, Step Height kept across undo, Esc cancels, the error reports.
"""

import hashlib
import json
import math
import os
import subprocess
import sys
import time
import traceback

import bpy
from mathutils import Vector

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))  # tests/blender: plyio


def parse():
    import argparse
    argv = sys.argv[sys.argv.index("--") + 1:]
    p = argparse.ArgumentParser()
    p.add_argument("--control", required=True)
    p.add_argument("--scenario", required=True)
    p.add_argument("--zip", required=True)
    p.add_argument("--build-dir", required=True)
    p.add_argument("--search", action="store_true", help="call Segment from F3 search instead of its button")
    return p.parse_args(argv)


ARGS = parse()
SEARCH = ARGS.search
CHECKS = []
_counter = [0]


def log(msg):
    with open(os.path.join(ARGS.control, "log.txt"), "a") as f:
        f.write("%7.2f %s\n" % (time.perf_counter() - T0, msg))


def check(name, ok, detail=""):
    CHECKS.append({"name": name, "ok": bool(ok), "detail": str(detail)})
    log("%s %s %s" % ("ok  " if ok else "FAIL", name, detail))
    return ok


def finish():
    tmp = os.path.join(ARGS.control, "result.tmp")
    with open(tmp, "w") as f:
        json.dump({"checks": CHECKS}, f, indent=1)
    os.replace(tmp, os.path.join(ARGS.control, "result.json"))
    sys.stdout.flush()
    os._exit(0)


def request(**req):
    """Ask the harness for something (generator: yield from request(...)); returns its reply."""
    n = _counter[0]
    _counter[0] += 1
    tmp = os.path.join(ARGS.control, "%d.tmp" % n)
    with open(tmp, "w") as f:
        json.dump(req, f)
    os.replace(tmp, os.path.join(ARGS.control, "%d.json" % n))
    reply_path = os.path.join(ARGS.control, "%d.reply.json" % n)
    deadline = time.perf_counter() + 60
    while not os.path.exists(reply_path):
        if time.perf_counter() > deadline:
            raise RuntimeError("the harness did not answer request %d (%s)" % (n, req["do"]))
        yield 0.05
    with open(reply_path) as f:
        reply = json.load(f)
    if not reply.get("ok"):
        log("request %s failed: %s" % (req["do"], reply.get("error")))
    return reply


def wait_until(predicate, timeout, step=0.1):
    """Generator: yields until predicate() is true or timeout; returns whether it became true."""
    deadline = time.perf_counter() + timeout
    while time.perf_counter() < deadline:
        if predicate():
            return True
        yield step
    return bool(predicate())


# -- window geometry ---------------------------------------------------------------------------

def window():
    return bpy.context.window_manager.windows[0]


def view3d():
    win = window()
    area = max((a for a in win.screen.areas if a.type == 'VIEW_3D'), key=lambda a: a.width * a.height)
    region = next(r for r in area.regions if r.type == 'WINDOW')
    sidebar = next(r for r in area.regions if r.type == 'UI')
    return win, area, region, sidebar


def to_x(win, x, y):
    """Blender window coordinates (origin bottom left) to X screen coordinates (top left)."""
    return int(win.x + x), int(win.y + win.height - y)


def region_rect(win, region):
    x0, y1 = to_x(win, region.x, region.y)
    x1, y0 = to_x(win, region.x + region.width, region.y + region.height)
    return [x0, y0, x1, y1]


def viewport_centre():
    win, area, region, _ = view3d()
    return list(to_x(win, region.x + region.width // 2, region.y + region.height // 2))


def override():
    win, area, region, _ = view3d()
    return bpy.context.temp_override(window=win, area=area, region=region, screen=win.screen)


def theme_rgb(widget):
    ui = bpy.context.preferences.themes[0].user_interface
    return [int(round(c * 255)) for c in getattr(ui, widget).inner[:3]]


# -- the add-on's state ------------------------------------------------------------------------

def addon_module():
    import relief_snake
    return relief_snake


def running():
    cls = addon_module().operators.MESH_OT_relief_snake_segment
    return getattr(cls, "_modal", None) is not None or bool(getattr(cls, "_running", False))


def job_running():
    op = addon_module().operators.MESH_OT_relief_snake_segment._modal
    return op is not None and getattr(op, "_job", None) is not None and not op._job.done


def members(obj, name):
    """Vertices in group `name` (Edit Mode: the live bmesh), or None if there is no such group."""
    import bmesh
    group = obj.vertex_groups.get(name)
    if group is None:
        return None
    gi = group.index
    if obj.mode == 'EDIT':
        bm = bmesh.from_edit_mesh(obj.data)
        layer = bm.verts.layers.deform.active
        if layer is None:
            return set()
        return {v.index for v in bm.verts if v[layer].get(gi, 0.0) > 0}
    return {v.index for v in obj.data.vertices if any(g.group == gi and g.weight > 0 for g in v.groups)}


def scene_state(obj):
    """A digest of what Segment may change: groups and their members, the outline curve's points."""
    h = hashlib.sha1()
    for g in obj.vertex_groups:
        h.update(("%s:%s;" % (g.name, sorted(members(obj, g.name) or []))).encode())
    curve = bpy.data.objects.get(obj.name + "_ReliefContour")
    if curve is not None:
        for s in curve.data.splines:
            h.update(repr([tuple(p.co) for p in s.points]).encode())
    return h.hexdigest()


def iou(a, b):
    a, b = set(a or ()), set(b or ())
    return len(a & b) / max(1, len(a | b))


def S():
    """The scene settings, fetched again: undo re-creates the Python objects."""
    return bpy.context.scene.relief_snake


def O():
    return bpy.data.objects["Scan"]


# -- steps -------------------------------------------------------------------------------------

def setup(triangles):
    """Install the zip, enable it, load a scan, frame it from the top in Edit Mode."""
    if SEARCH:
        bpy.context.preferences.view.show_developer_ui = True  # F3 finds operators outside menus
    bpy.ops.preferences.addon_install(filepath=ARGS.zip, overwrite=True)
    bpy.ops.preferences.addon_enable(module="relief_snake")
    mod = addon_module()
    check("the add-on installs from the zip and enables", hasattr(bpy.types.Scene, "relief_snake")
          and os.path.dirname(os.path.dirname(mod.__file__)) != os.path.dirname(os.path.dirname(HERE)),
          mod.__file__)
    prefix = os.path.join(ARGS.control, "scan")
    subprocess.run([os.path.join(ARGS.build_dir, "make-scan"), "--shape", "duck", "--background", "plane",
                    "--triangles", str(triangles), "--step", "blended", "--seed", "1", "--out", prefix],
                   check=True, stdout=subprocess.DEVNULL)
    truth = json.load(open(prefix + ".truth.json"))
    import plyio
    verts, faces = plyio.read_ply(prefix + ".ply")
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    mesh = bpy.data.meshes.new("Scan")
    mesh.from_pydata(verts, [], faces)
    obj = bpy.data.objects.new("Scan", mesh)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    win, area, region, sidebar = view3d()
    space = area.spaces.active
    space.show_region_ui = True
    space.overlay.show_floor = False
    with override():
        bpy.ops.view3d.view_axis(type='TOP')
        bpy.ops.view3d.view_all()
        bpy.ops.object.mode_set(mode='EDIT')
        bpy.ops.mesh.select_mode(type='VERT')
        bpy.ops.mesh.select_all(action='DESELECT')
    return obj, truth


def close_splash():
    """Generator: the splash screen (a fresh user config shows it) goes with Esc."""
    yield from request(do="key", at=viewport_centre(), keys=["Escape"])
    yield 0.5


def find_band(widget, name=None, min_width=0.5, pick="tallest", below=None):
    """Generator: the sidebar's band of theme colour `widget` as (x, y) of its centre, or None."""
    win, area, region, sidebar = view3d()
    rect = region_rect(win, sidebar)
    reply = yield from request(do="find_bands", rect=rect, rgb=theme_rgb(widget), tol=3, min_width=min_width, name=name)
    # Bands touching the region's edges are backgrounds, not widgets.
    bands = [b for b in reply.get("bands", []) if b[1] - b[0] >= 8 and b[2] > rect[0] + 4 and b[3] < rect[2] - 4]
    if below is not None:
        bands = [b for b in bands if b[0] > below]
    if not bands:
        return None
    b = max(bands, key=lambda b: b[1] - b[0]) if pick == "tallest" else bands[0]
    return [(b[2] + b[3]) // 2, (b[0] + b[1]) // 2, b[1] - b[0], b[2], b[3]]


def open_relief_tab():
    """Generator: click the sidebar's last tab (add-on tabs come after Item, Tool and View) and
    return the Segment button (the tallest tool-coloured band), or None."""
    win, area, region, sidebar = view3d()
    rect = region_rect(win, sidebar)
    for attempt in range(3):
        reply = yield from request(do="tabs", x=rect[2] - 9, y0=rect[1], y1=rect[3], name="tabs")
        runs = reply.get("runs") or []
        log("sidebar tabs at %s" % runs)
        if runs:
            yield from click([rect[2] - 9, (runs[-1][0] + runs[-1][1]) // 2])
            yield 0.8
        button = yield from find_band("wcol_tool")
        if button is not None and button[2] >= 26:
            return button
        if SEARCH and runs:  # the old panel has no tall button to confirm it
            return [rect[0], rect[1], 0]
    return None


def click(at, modifiers=()):
    yield from request(do="click", at=list(at), modifiers=list(modifiers))


def pick_vertices(obj, picks):
    """Generator: click the picks in the viewport (first plain, then Shift); returns the click order."""
    from bpy_extras.view3d_utils import location_3d_to_region_2d
    win, area, region, _ = view3d()
    rv3d = area.spaces.active.region_3d
    for k, i in enumerate(picks):
        co = obj.matrix_world @ obj.data.vertices[i].co
        p = location_3d_to_region_2d(region, rv3d, co)
        yield from click(to_x(win, region.x + p.x, region.y + p.y), ["shift"] if k else [])
    yield 0.3
    import bmesh
    bm = bmesh.from_edit_mesh(obj.data)
    bm.verts.index_update()
    return [e.index for e in bm.select_history if isinstance(e, bmesh.types.BMVert) and e.select]


def type_into(at, text, check=None, start="Return"):
    """Generator: edit the field under `at` (a number field starts editing with Return on hover,
    a text field with a click: start="click"), select all, type, Return; retried once if check()
    is still false afterwards."""
    at = list(at[:2])
    for attempt in range(2):
        if start == "click":
            yield from click(at)
        else:
            yield from request(do="key", at=at, keys=["Return"])
        yield 0.4
        yield from request(do="key", at=at, keys=["ctrl+a"])
        yield from request(do="type", text=text)
        yield from request(do="key", at=at, keys=["Return"])
        yield 0.5
        # Leave the field: the first click after editing text is otherwise eaten by the field.
        yield from request(do="move", at=viewport_centre())
        yield 0.5
        if check is None or check():
            return


def _segment_marker():
    ops = bpy.context.window_manager.operators
    last = ops[-1] if len(ops) else None
    return (S().last_summary, len(ops), None if last is None else last.as_pointer())


def _press_segment_once(button):
    marker = _segment_marker()
    if SEARCH:
        at = viewport_centre()
        yield from request(do="key", at=at, keys=["F3"])
        yield 0.5
        yield from request(do="type", text="Segment Relief")
        yield 0.8
        yield from request(do="key", at=at, keys=["Return"])
    else:
        yield from click(button[:2])
    # A loaded machine may take seconds to deliver the click, and a short run may be over before
    # this coroutine looks again: a finished run changes the summary or the operator history.
    started = yield from wait_until(lambda: running() or _segment_marker() != marker, 10, 0.02)
    return started


def press_segment(button, wait=True, timeout=90):
    """Generator: click the Segment button (or, with --search, call it from F3 search, as the
    add-on before issue 10 had no button this test can find); with wait, until the run has ended.
    Returns True if it ran."""
    started = False
    for attempt in range(2):  # a click a busy Blender dropped is clicked again
        started = yield from _press_segment_once(button)
        if started:
            break
    if wait:
        yield from wait_until(lambda: not running(), timeout, 0.1)
        yield 0.5
    obj = bpy.data.objects.get("Scan")
    log("Segment pressed: started %s, summary %r, groups %s" % (
        started, S().last_summary, [(g.name, len(members(obj, g.name) or ())) for g in obj.vertex_groups]
        if obj is not None else None))
    return started


def step_height_field(segment_button):
    """Generator: the Step Height field (the first number field below the Segment button)."""
    field = yield from find_band("wcol_num", min_width=0.25, pick="first", below=segment_button[1])
    if field is not None:  # the row also holds Measure and Estimate, same colour: aim at its left part
        field[0] = field[3] + (field[4] - field[3]) // 5
    return field


def group_field(segment_button):
    field = yield from find_band("wcol_text", min_width=0.4, pick="first", below=segment_button[1])
    return field


def report_texts():
    """The window manager's reports (what the status bar and pop-ups showed), newest last."""
    win, area, region, _ = view3d()
    before = set(bpy.data.texts.keys())
    old_type = area.type
    try:
        area.type = 'INFO'
        with bpy.context.temp_override(window=win, area=area, screen=win.screen):
            bpy.ops.info.select_all(action='SELECT')
            bpy.ops.info.report_copy()
        return bpy.context.window_manager.clipboard
    except Exception as exc:
        log("reports unavailable: %s" % exc)
        return ""
    finally:
        area.type = old_type
        for name in set(bpy.data.texts.keys()) - before:
            bpy.data.texts.remove(bpy.data.texts[name])


# -- scenarios ---------------------------------------------------------------------------------

def scenario_crash():
    """Issue 10's sequence: Segment (group Relief), type Relief2, Segment, Segment, Ctrl+Z."""
    obj, truth = setup(20000)
    yield from close_splash()
    button = yield from open_relief_tab()
    if not check("the Relief tab shows the Segment button", button is not None):
        return
    picks = yield from pick_vertices(obj, truth["picks"])
    check("clicking the picks selects them in click order", len(picks) == len(truth["picks"]),
          "%d of %d" % (len(picks), len(truth["picks"])))
    field = yield from step_height_field(button)
    check("the Step Height field is found", field is not None)
    h = float(truth["h"])
    if field is not None:
        yield from type_into(field, "%.6g" % h, lambda: abs(bpy.context.scene.relief_snake.step_height - h) < 1e-4 * h)
    check("Step Height typed", abs(S().step_height - h) < 1e-4 * h, S().step_height)
    yield from press_segment(button)
    check("first Segment fills group Relief", bool(members(O(), "Relief")))
    gfield = yield from group_field(button)
    if check("the Vertex Group field is found", gfield is not None):
        yield from type_into(gfield, "Relief2", lambda: bpy.context.scene.relief_snake.group_name == "Relief2", start="click")
    check("group name typed", S().group_name == "Relief2", S().group_name)
    yield from press_segment(button)
    first = members(O(), "Relief2")
    check("second Segment fills group Relief2", bool(first))
    yield from press_segment(button)
    check("third Segment gives the same Relief2", members(O(), "Relief2") == first)
    yield from request(do="screenshot", name="before-undo")
    at = viewport_centre()
    yield from request(do="key", at=at, keys=["ctrl+z"])
    yield 2.0
    check("Blender is alive after Ctrl+Z", True)
    check("Step Height kept across undo", abs(S().step_height - h) < 1e-4 * h, S().step_height)
    for _ in range(2):
        yield from request(do="key", at=at, keys=["ctrl+z"])
        yield 1.0
    yield from request(do="key", at=at, keys=["ctrl+shift+z"])
    yield 1.0
    check("Blender is alive after more Ctrl+Z and Ctrl+Shift+Z", True)
    check("Step Height still kept", abs(S().step_height - h) < 1e-4 * h, S().step_height)
    yield from request(do="screenshot", name="after-undo")
    # And Segment still works after all that undoing.
    ran = yield from press_segment(button)
    check("Segment works after undo and redo", ran and bool(members(O(), "Relief2")))


def scenario_artist():
    obj, truth = setup(60000)
    prefs = bpy.context.preferences.addons["relief_snake"].preferences
    prefs.threads = 1  # a slower run, so the preview is on screen long enough to be seen
    prefs.preview_color = (0.0, 1.0, 1.0, 1.0)  # cyan: no other cyan on Blender's default screen
    yield from close_splash()
    button = yield from open_relief_tab()
    if not check("the Relief tab shows the Segment button", button is not None):
        return
    yield from request(do="screenshot", name="panel")
    picks = yield from pick_vertices(obj, truth["picks"])
    check("clicking the picks selects them in click order", len(picks) == len(truth["picks"]),
          "%d of %d" % (len(picks), len(truth["picks"])))
    h = float(truth["h"])
    field = yield from step_height_field(button)
    if field is not None:
        yield from type_into(field, "%.6g" % h, lambda: abs(bpy.context.scene.relief_snake.step_height - h) < 1e-4 * h)
    check("Step Height typed", abs(S().step_height - h) < 1e-4 * h, S().step_height)
    yield from request(do="screenshot", name="picked")

    # Segment: the preview (cyan) appears in the viewport while the engine runs.
    win, area, region, _ = view3d()
    vp = region_rect(win, region)
    before = scene_state(O())
    # Slow the engine down (a pause in each progress call) so the run lasts long enough for a
    # screenshot on any machine; the preview path itself is the add-on's own.
    job_mod = addon_module().job
    real_progress = job_mod.SegmentJob._progress

    def slow_progress(self, *args):
        time.sleep(0.05)  # about 20 s in all: a screenshot and its count take 4-5 s on a loaded machine
        return real_progress(self, *args)
    job_mod.SegmentJob._progress = slow_progress
    started = yield from press_segment(button, wait=False)
    check("Segment starts an interactive run", started)
    seen, reply = False, {}
    yield from wait_until(job_running, 15, 0.05)  # the read happens on the run's first timer tick
    for _ in range(20):
        if not job_running():
            break
        yield 0.3
        # The run (the modal operator) was on when the screenshot was asked for: the engine may
        # finish while it is taken, and the cyan preview is drawn only until the run ends.
        was_running = running()
        reply = yield from request(do="count", rect=vp, lo=[0, 180, 180], hi=[100, 255, 255], name="running")
        if reply.get("count", 0) > 50 and was_running:
            seen = True
            break
    check("the preview outline is drawn in the preference colour during the run", seen,
          "cyan pixels: %s" % reply.get("count"))
    yield from wait_until(lambda: not running(), 120, 0.1)
    job_mod.SegmentJob._progress = real_progress
    yield 0.5
    got = members(O(), "Relief")
    score = iou(got, truth["relief_vertices"])
    check("the run fills the group with the relief (IoU >= 0.85)", score >= 0.85, "IoU %.3f" % score)
    check("the outline curve exists, bevelled and in front",
          bpy.data.objects.get("Scan_ReliefContour") is not None
          and bpy.data.objects["Scan_ReliefContour"].data.bevel_depth > 0
          and bpy.data.objects["Scan_ReliefContour"].show_in_front)
    reply = yield from request(do="count", rect=vp, lo=[150, 20, 0], hi=[255, 150, 70], name="result")
    check("the orange outline is visible in the viewport", reply.get("count", 0) > 150,
          "orange pixels: %s" % reply.get("count"))
    # The relief region, tinted green behind the Show Region toggle (on by default).
    green = dict(lo=[0, 110, 0], hi=[110, 255, 130])  # greens only: a grey with g >= 110 has r > 110
    shown = yield from request(do="count", rect=vp, name="region-shown", **green)
    S().show_region = False
    yield 0.5
    hidden = yield from request(do="count", rect=vp, name="region-hidden", **green)
    S().show_region = True
    yield 0.5
    check("the relief region is tinted green in the viewport, and Show Region hides it",
          shown.get("count", 0) > 3000 and shown.get("count", 0) - hidden.get("count", 0) > 2000,
          "green pixels: %s shown, %s hidden" % (shown.get("count"), hidden.get("count")))
    after = scene_state(O())

    # Undo and redo.
    at = viewport_centre()
    yield from request(do="key", at=at, keys=["ctrl+z"])
    yield 1.5
    check("Ctrl+Z takes the relief out of the group", not members(O(), "Relief"), len(members(O(), "Relief") or ()))
    check("Step Height kept across undo", abs(S().step_height - h) < 1e-4 * h, S().step_height)
    yield from request(do="key", at=at, keys=["ctrl+shift+z"])
    yield 1.5
    check("Ctrl+Shift+Z brings it back", members(O(), "Relief") == got)

    # Esc cancels and leaves the scene as it was.
    state = scene_state(O())
    started = yield from press_segment(button, wait=False)
    yield from wait_until(job_running, 5, 0.05)
    yield 0.3
    t = time.perf_counter()
    yield from request(do="key", at=at, keys=["Escape"])
    ended = yield from wait_until(lambda: not running(), 3, 0.05)
    check("Esc ends the run at once", started and ended, "%.2f s" % (time.perf_counter() - t))
    yield 1.0
    check("Esc leaves the scene unchanged", scene_state(O()) == state)
    yield from request(do="screenshot", name="cancelled")

    # Error reports: nothing selected.
    yield from request(do="key", at=at, keys=["alt+a"])
    yield 0.5
    state = scene_state(O())
    yield from press_segment(button)
    yield 0.5
    yield from request(do="screenshot", name="error")
    text = report_texts()
    check("an empty selection reports what to do", "Select at least 3 vertices" in text, text[-300:])
    check("a failed run changes nothing", scene_state(O()) == state)
    del before, after
    yield from apply_at_click()


def apply_at_click():
    """Extract the relief, then Apply at Click: a real click on a plane target under the scan puts
    the relief there (the ray is cast against the target only)."""
    with override():
        bpy.ops.object.mode_set(mode='OBJECT')
        extracted = bpy.ops.mesh.relief_snake_extract() == {'FINISHED'}
    if not check("Extract makes the relief", extracted and bpy.data.objects.get("Scan_Relief") is not None):
        return
    scan = O()
    corners = [scan.matrix_world @ Vector(c) for c in scan.bound_box]
    depth = min(c.z for c in corners) - 5.0
    mesh = bpy.data.meshes.new("Target")
    size = 2 * max(scan.dimensions)
    mesh.from_pydata([(-size, -size, depth), (size, -size, depth), (size, size, depth), (-size, size, depth)], [],
                     [(0, 1, 2, 3)])
    target = bpy.data.objects.new("Target", mesh)
    bpy.context.scene.collection.objects.link(target)
    bpy.context.view_layer.update()
    with override():
        started = bpy.ops.object.relief_snake_apply('INVOKE_DEFAULT', relief="Scan_Relief", target="Target",
                                                    method='MESH', placement='CLICK')
    check("Apply at Click waits for a click", started == {'RUNNING_MODAL'}, started)
    # Click a quarter of the way in from the viewport's left edge: where the ray meets the plane.
    from bpy_extras.view3d_utils import region_2d_to_origin_3d, region_2d_to_vector_3d
    win, area, region, _ = view3d()
    rv3d = area.spaces.active.region_3d
    at = (region.width // 3, region.height // 2)
    origin, direction = region_2d_to_origin_3d(region, rv3d, at), region_2d_to_vector_3d(region, rv3d, at)
    t = (depth - origin.z) / direction.z
    expected = origin + t * direction
    yield from click(to_x(win, region.x + at[0], region.y + at[1]))
    placed = yield from wait_until(lambda: bpy.data.objects.get("Scan_Relief_Applied") is not None, 20, 0.2)
    applied = bpy.data.objects.get("Scan_Relief_Applied")
    if not check("the click puts the relief on the target", placed and applied is not None):
        return
    points = [applied.matrix_world @ v.co for v in applied.data.vertices]
    centre = sum(points, Vector()) / len(points)
    off = math.hypot(centre.x - expected.x, centre.y - expected.y)
    check("the relief lies where the click was, on the target",
          off < 0.1 * max(applied.dimensions) and abs(min(p.z for p in points) - depth) < 0.1,
          "centre %.2f from the click's point; lowest z %.3f, plane at %.3f" % (off, min(p.z for p in points), depth))
    yield 1.0  # let the window redraw before the artefact is taken
    yield from request(do="screenshot", name="applied")


def main_coroutine():
    try:
        if ARGS.scenario == "crash":
            yield from scenario_crash()
        elif ARGS.scenario == "artist":
            yield from scenario_artist()
        else:
            check("known scenario", False, ARGS.scenario)
    except Exception:
        check("driver ran without an exception", False, traceback.format_exc())
    finish()


T0 = time.perf_counter()
_co = main_coroutine()


def _tick():
    try:
        delay = next(_co)
    except StopIteration:
        finish()
        return None
    return float(delay or 0.01)


bpy.app.timers.register(_tick, first_interval=2.0)
