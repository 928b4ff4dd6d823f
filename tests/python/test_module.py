"""relief_snake_core: buffers in, errors out, progress/cancellation, GIL, Mesh reuse, results.

Runs without numpy (numpy cases are skipped when it is missing). The module is
found in the build directory: $RELIEF_SNAKE_BUILD_DIR, else ./build (as in conftest.py);
a missing module fails the suite. RELIEF_SNAKE_TEST_BUDGET (seconds, default 60) bounds each
segmentation so a runaway engine fails instead of hanging.
"""
import array
import math
import os
import random
import subprocess
import sys
import threading
import time

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BUILD_DIR = os.environ.get("RELIEF_SNAKE_BUILD_DIR", os.path.join(ROOT, "build"))
if BUILD_DIR not in sys.path:
    sys.path.insert(0, BUILD_DIR)

try:
    import relief_snake_core as core
except ImportError as exc:  # a suite that cannot run must fail, not skip
    pytest.fail("relief_snake_core not importable from %s (%s): build it (make build) or set "
                "RELIEF_SNAKE_BUILD_DIR" % (BUILD_DIR, exc), pytrace=False)

try:
    import numpy as np
except ImportError:  # Blender's Python has no numpy: the module must not need it
    np = None
needs_numpy = pytest.mark.skipif(np is None, reason="numpy not installed")


# --- a synthetic scan: a disk relief of radius R and step h on a jittered grid ----------------

def disk_scan(n=48, size=40.0, radius=9.0, h=1.0, jitter=0.3, seed=1):
    """Plane z=0 with the disk r < radius raised to z=h (sharp step), on an n x n jittered grid.

    Returns (vertices as list of (x, y, z), triangles as list of (i, j, k) counter-clockwise
    seen from +z, picks: 8 vertices on a ring of radius radius + 3 h in counter-clockwise
    order, truth: set of the relief's vertices, h, radius)."""
    rng = random.Random(seed)
    step = size / (n - 1)
    vertices = []
    for j in range(n):
        for i in range(n):
            x, y = -size / 2 + i * step, -size / 2 + j * step
            if 0 < i < n - 1 and 0 < j < n - 1:
                x += rng.uniform(-jitter, jitter) * step
                y += rng.uniform(-jitter, jitter) * step
            vertices.append((x, y, h if math.hypot(x, y) < radius else 0.0))
    triangles = []
    for j in range(n - 1):
        for i in range(n - 1):
            a, b, c, d = j * n + i, j * n + i + 1, (j + 1) * n + i, (j + 1) * n + i + 1
            if (i + j) % 2:
                triangles += [(a, b, d), (a, d, c)]
            else:
                triangles += [(a, b, c), (b, d, c)]
    picks = []
    for k in range(8):
        t = 2 * math.pi * k / 8
        px, py = (radius + 3 * h) * math.cos(t), (radius + 3 * h) * math.sin(t)
        picks.append(min(range(len(vertices)),
                         key=lambda v: (vertices[v][0] - px) ** 2 + (vertices[v][1] - py) ** 2))
    truth = {v for v, p in enumerate(vertices) if p[2] > 0}
    return vertices, triangles, picks, truth, h, radius


@pytest.fixture(scope="module")
def scan():
    return disk_scan()


def flat(rows):
    return [x for row in rows for x in row]


SQUARE_V = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (1.0, 1.0, 0.5)]
SQUARE_F = [(0, 1, 2), (1, 3, 2)]


def assert_one_line_error(excinfo, *words):
    message = str(excinfo.value)
    assert message and "\n" not in message
    for w in words:
        assert w in message, (w, message)


# --- module surface -----------------------------------------------------------------------------

def test_version_and_exception_types():
    assert core.__version__ == "0.1.0"
    assert issubclass(core.Error, ValueError)
    assert issubclass(core.Cancelled, Exception) and not issubclass(core.Cancelled, ValueError)


def test_importable_and_usable_without_numpy():
    # Blender 3.4 from Debian ships without numpy: block it and use the module with array.array only.
    code = (
        "import sys, array; sys.modules['numpy'] = None; sys.path.insert(0, sys.argv[1]);"
        "import relief_snake_core as c;"
        "m = c.Mesh(array.array('d', [0,0,0, 1,0,0, 0,1,0]), array.array('i', [0,1,2]));"
        "print(m.n_vertices, m.n_faces, c.measure(array.array('f', [0,0,0, 3,4,0]), 0, 1))"
    )
    out = subprocess.run([sys.executable, "-c", code, os.path.dirname(core.__file__)], capture_output=True,
                         text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["3", "1", "5.0"]


# --- buffers in ---------------------------------------------------------------------------------

def reference_mesh():
    return core.Mesh(SQUARE_V, SQUARE_F)


def same_mesh(m, tol=0.0):
    ref = reference_mesh()
    assert (m.n_vertices, m.n_faces) == (ref.n_vertices, ref.n_faces) == (4, 2)
    assert m.average_edge == pytest.approx(ref.average_edge, rel=tol, abs=tol)
    assert m.measure(0, 3) == pytest.approx(ref.measure(0, 3), rel=tol, abs=tol)


@pytest.mark.parametrize("vcode", ["d", "f"])
@pytest.mark.parametrize("fcode", ["i", "l", "q", "I", "L"])
def test_array_array_buffers(vcode, fcode):
    same_mesh(core.Mesh(array.array(vcode, flat(SQUARE_V)), array.array(fcode, flat(SQUARE_F))), tol=1e-6)


def test_nested_and_flat_lists_and_tuples():
    same_mesh(core.Mesh([list(v) for v in SQUARE_V], [list(f) for f in SQUARE_F]))
    same_mesh(core.Mesh(tuple(SQUARE_V), tuple(SQUARE_F)))
    same_mesh(core.Mesh(flat(SQUARE_V), flat(SQUARE_F)))
    # integer coordinates are numbers too
    m = core.Mesh([(0, 0, 0), (2, 0, 0), (0, 2, 0)], [(0, 1, 2)])
    assert m.measure(1, 2) == pytest.approx(math.sqrt(8))


def test_memoryview_like_blender_foreach_get():
    # Blender: mesh.vertices.foreach_get("co", buf) into array.array('f'), passed on as memoryview.
    verts = array.array("f", [0.0]) * (3 * len(SQUARE_V))
    verts[:] = array.array("f", flat(SQUARE_V))
    tris = array.array("i", flat(SQUARE_F))
    same_mesh(core.Mesh(memoryview(verts), memoryview(tris)), tol=1e-6)
    # raw bytes reinterpreted with cast(), as add-ons do with foreach_get into bytearray
    raw = bytearray(array.array("d", flat(SQUARE_V)).tobytes())
    same_mesh(core.Mesh(memoryview(raw).cast("d"), memoryview(bytearray(tris.tobytes())).cast("i")))


def test_non_contiguous_memoryview_is_read_through_strides():
    interleaved = array.array("d")
    for v in SQUARE_V:
        for x in v:
            interleaved.extend([x, -999.0])  # every other value is junk
    view = memoryview(interleaved)[::2]
    assert not view.c_contiguous
    same_mesh(core.Mesh(view, SQUARE_F))


@needs_numpy
@pytest.mark.parametrize("vdtype", ["float32", "float64"])
@pytest.mark.parametrize("fdtype", ["int32", "int64", "uint32"])
def test_numpy_arrays(vdtype, fdtype):
    V = np.array(SQUARE_V, dtype=vdtype)
    F = np.array(SQUARE_F, dtype=fdtype)
    same_mesh(core.Mesh(V, F), tol=1e-6)              # 2D n x 3
    same_mesh(core.Mesh(V.ravel(), F.ravel()), tol=1e-6)  # 1D 3n


@needs_numpy
def test_numpy_non_contiguous_and_fortran_order():
    V = np.array(SQUARE_V)
    wide = np.zeros((4, 6))
    wide[:, ::2] = V
    same_mesh(core.Mesh(wide[:, ::2], np.asfortranarray(np.array(SQUARE_F))))
    assert core.measure(wide[:, ::2], 0, 3) == pytest.approx(math.sqrt(2.25))


# --- bad buffers out ----------------------------------------------------------------------------

@pytest.mark.parametrize("vertices, words", [
    (array.array("i", [0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0]), ["vertices", "float"]),
    (b"\x00" * 96, ["vertices", "float"]),
    (array.array("d", [0.0] * 11), ["vertices", "multiple of 3"]),
    ([(0.0, 0.0), (1.0, 0.0)], ["vertices", "row 0", "expected 3"]),
    ([(0, 0, 0), (1, 0, 0), (0, 1, 0), ("a", 1, 1)], ["vertices", "numbers"]),
    ([], ["vertices", "empty"]),
    (None, ["vertices", "None"]),
    ("0 0 0 1 0 0 0 1 0", ["vertices"]),
    ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (float("nan"), 1, 1)], ["vertex 3", "NaN"]),
    (array.array("d", [0, 0, 0, 1, 0, 0, 0, 1, 0, 1, float("inf"), 0]), ["vertex 3", "inf"]),
])
def test_bad_vertices_raise_error(vertices, words):
    with pytest.raises(core.Error) as excinfo:
        core.Mesh(vertices, SQUARE_F)
    assert_one_line_error(excinfo, *words)
    with pytest.raises(ValueError):  # the documented base class
        core.mesh_report(vertices, SQUARE_F)


@pytest.mark.parametrize("triangles, words", [
    (array.array("d", flat(SQUARE_F)), ["triangles", "integers"]),
    ([(0.0, 1.0, 2.0)], ["triangles", "integers"]),
    (array.array("i", [0, 1, 2, 1]), ["triangles", "multiple of 3"]),
    ([(0, 1, 4)], ["triangle 0", "4", "out of range"]),
    ([(0, 1, 2), (-1, 1, 2)], ["triangle 1", "-1", "out of range"]),
    ([], ["triangles", "empty"]),
])
def test_bad_triangles_raise_error(triangles, words):
    with pytest.raises(core.Error) as excinfo:
        core.Mesh(SQUARE_V, triangles)
    assert_one_line_error(excinfo, *words)


@needs_numpy
def test_bad_numpy_shapes_and_dtypes():
    with pytest.raises(core.Error) as e:
        core.Mesh(np.zeros((4, 4)), SQUARE_F)
    assert_one_line_error(e, "3 columns")
    with pytest.raises(core.Error) as e:
        core.Mesh(np.zeros((2, 2, 3)), SQUARE_F)
    assert_one_line_error(e, "dimensions")
    with pytest.raises(core.Error) as e:
        core.Mesh(np.array(SQUARE_V, dtype=np.float16), SQUARE_F)
    assert_one_line_error(e, "float32 or float64")
    with pytest.raises(core.Error) as e:
        core.Mesh(np.array(SQUARE_V, dtype=">f8"), SQUARE_F)
    assert_one_line_error(e, "byte order")
    with pytest.raises(core.Error) as e:
        core.Mesh(SQUARE_V, np.array(SQUARE_F, dtype=np.uint64) + np.uint64(2 ** 63))
    assert_one_line_error(e, "triangles")


def test_measure():
    V = [(0, 0, 0), (3, 4, 0), (1, 1, 1)]
    assert core.measure(V, 0, 1) == 5.0
    assert core.measure(array.array("f", flat(V)), 1, 0) == 5.0
    assert core.measure(V, 2, 2) == 0.0
    m = core.Mesh(V, [(0, 1, 2)])
    assert m.measure(0, 1) == pytest.approx(5.0)
    for i, j in [(0, 3), (-1, 0)]:
        with pytest.raises(core.Error) as e:
            core.measure(V, i, j)
        assert_one_line_error(e, "out of range")
    with pytest.raises(ValueError):
        m.measure(0, 7)


def test_mesh_report_and_properties(scan):
    V, F, _, _, _, _ = scan
    m = core.Mesh(V, F)
    assert m.n_vertices == len(V) and m.n_faces == len(F)
    assert isinstance(m.report, str) and "\n" not in m.report and str(len(F)) in m.report
    assert core.mesh_report(V, F) == m.report
    assert 0.5 < m.average_edge < 1.5  # 40 / 47 grid spacing, diagonals and jitter
    assert m.report in repr(m)


# --- keyword and pick checking ------------------------------------------------------------------

@pytest.mark.parametrize("kwargs, words", [
    (dict(step_height=0.0), ["step_height"]),
    (dict(step_height=-1.0), ["step_height"]),
    (dict(step_height=float("nan")), ["step_height"]),
    (dict(step_height=float("inf")), ["step_height"]),
    (dict(relief_side="up"), ["relief_side", "left", "right"]),
    (dict(w_int=0.0), ["w_int"]),
    (dict(w_int=1.5), ["w_int"]),
    (dict(max_iterations=0), ["max_iterations"]),
    (dict(progress=42), ["progress", "callable"]),
])
def test_bad_keywords_raise_error(scan, kwargs, words):
    V, F, picks, _, h, _ = scan
    args = dict(step_height=h)
    args.update(kwargs)
    step = args.pop("step_height")
    with pytest.raises(core.Error) as e:
        core.segment(V, F, picks, step, **args)
    assert_one_line_error(e, *words)
    with pytest.raises(core.Error):
        core.Mesh(V, F).segment(picks, step, **args)


def test_advanced_options_are_listed_with_their_defaults():
    opts = core.advanced_options()
    names = [o["name"] for o in opts]
    assert len(names) == len(set(names))
    for name in ["tau", "epsilon", "q_samples", "exact_q", "neighbourhood", "plane_fit", "remove_loops",
                 "nearest_resampling", "threads"]:
        assert name in names, name
    for o in opts:
        assert set(o) == {"name", "type", "range", "help", "default"}
        assert o["type"] in ("number", "integer", "boolean", "choice")
        assert isinstance(o["default"], {"number": float, "integer": int, "boolean": bool, "choice": str}[o["type"]])
    assert {o["name"]: o["default"] for o in opts}["tau"] == 0.2


@pytest.mark.parametrize("kwargs, error, words", [
    (dict(bogus=1), TypeError, ["bogus", "advanced options", "tau"]),
    (dict(tau=1.5), core.Error, ["tau", "(0, 1)"]),
    (dict(tau="0.2"), core.Error, ["tau", "number"]),
    (dict(q_samples=2.5), core.Error, ["q_samples", "int"]),
    (dict(q_samples=True), core.Error, ["q_samples", "int"]),
    (dict(exact_q=1), core.Error, ["exact_q", "True or False"]),
    (dict(neighbourhood="manhattan"), core.Error, ["neighbourhood", "geodesic", "sphere", "manhattan"]),
    (dict(plane_fit=3), core.Error, ["plane_fit", "str"]),
])
def test_bad_advanced_options(scan, kwargs, error, words):
    V, F, picks, _, h, _ = scan
    for call in (lambda: core.segment(V, F, picks, h, **kwargs), lambda: core.Mesh(V, F).segment(picks, h, **kwargs)):
        with pytest.raises(error) as e:
            call()
        message = str(e.value)
        assert "\n" not in message
        for w in words:
            assert w in message, (w, message)


def test_advanced_options_reach_the_engine(scan, disk_result):
    V, F, picks, _, h, _ = scan
    r = core.segment(V, F, picks, h, progress=deadline(), tau=0.25, q_samples=7, exact_q=True,
                     neighbourhood="geodesic", plane_fit="area", threads=1)
    p = r["parameters"]
    assert p["tau"] == 0.25 and p["q_samples"] == 7 and p["exact_q"] is True and p["threads"] == 1
    assert p["neighbourhood"] == "geodesic" and p["plane_fit"] == "area"
    defaults = {o["name"]: o["default"] for o in core.advanced_options()}
    for name, value in defaults.items():  # the defaults, reported
        assert disk_result["parameters"][name] == value, name
    assert r["relief_vertices"] != disk_result["relief_vertices"] or r["contour"] != disk_result["contour"]


def test_keywords_are_keyword_only(scan):
    V, F, picks, _, h, _ = scan
    with pytest.raises(TypeError):
        core.segment(V, F, picks, h, 0.25)


@pytest.mark.parametrize("picks, words", [
    ([0, 1, 10 ** 7], ["pick", "10000000"]),
    ([0, -1, 5], ["pick", "-1"]),
    ([0.5, 1, 2], ["picks", "integers"]),
    (None, ["picks"]),
    (array.array("d", [0, 1, 2]), ["picks", "integers"]),
])
def test_bad_picks_raise_error(scan, picks, words):
    V, F, _, _, h, _ = scan
    with pytest.raises(core.Error) as e:
        core.segment(V, F, picks, h)
    assert_one_line_error(e, *words)


def test_too_few_picks_is_an_error(scan):
    V, F, picks, _, h, _ = scan
    with pytest.raises(core.Error) as e:
        core.segment(V, F, picks[:2], h)  # closed contour: at least 3
    assert_one_line_error(e)


# --- segmentation -------------------------------------------------------------------------------

PHASES = {"preprocess", "coarse", "refine", "stabilise"}


# A 4.4k-triangle disk takes well under a second; a run past this budget is a failure, not a hang.
BUDGET_SECONDS = float(os.environ.get("RELIEF_SNAKE_TEST_BUDGET", "60"))


class OverBudget(Exception):
    pass


def deadline(seconds=BUDGET_SECONDS):
    """A progress callback that fails the segmentation once it runs longer than `seconds`."""
    start = time.perf_counter()

    def progress(phase, iteration, snaxels, contour):
        if time.perf_counter() - start > seconds:
            raise OverBudget("segmentation still in %s after %.0f s (iteration %d, %d snaxels)"
                             % (phase, seconds, iteration, snaxels))

    return progress


@pytest.fixture(scope="module")
def disk_result(scan):
    V, F, picks, _, h, _ = scan
    return core.segment(V, F, picks, h, progress=deadline())


def test_result_dict_structure(scan, disk_result):
    V, _, _, _, h, _ = scan
    r = disk_result
    # The same document the CLI writes (docs/result-format.md).
    assert set(r) == {"format", "status", "message", "reasons", "closed", "relief_side", "contour",
                      "relief_vertices", "step_height", "w_int", "checks", "attempts", "phases", "parameters",
                      "notes", "planarity_vertices", "mesh", "timing",
                      "holes", "hole_checks", "band", "band_contour"}  # whole reliefs (issue 13)
    assert r["holes"] == [] and r["hole_checks"] == [] and r["band"] is False and r["band_contour"] == []
    assert r["format"] == "relief-snake-result/1"
    assert r["status"] == "converged" and r["reasons"] == [] and r["relief_side"] is None
    assert r["closed"] is True
    assert len(r["contour"]) >= 3
    assert all(isinstance(p, tuple) and len(p) == 3 and all(isinstance(x, float) for x in p) for p in r["contour"])
    assert all(isinstance(v, int) and 0 <= v < len(V) for v in r["relief_vertices"])
    assert len(set(r["relief_vertices"])) == len(r["relief_vertices"])
    assert r["phases"] and all(set(p) == {"name", "iterations", "snaxels", "seconds", "converged"}
                               for p in r["phases"])
    assert {p["name"] for p in r["phases"]} <= PHASES
    params = r["parameters"]
    for key in ["coarse_spacing", "refine_spacing", "alpha_coarse", "beta_coarse", "alpha_refine", "beta_refine",
                "gamma", "sigma_background", "sigma_s", "w_int", "w_f", "w_d", "average_edge", "step_height",
                "open", "relief_side", "max_iterations"]:
        assert key in params, key
    assert r["step_height"]["given"] == h and params["step_height"] == r["step_height"]["used"]
    assert r["w_int"]["given"] is None and params["w_int"] == r["w_int"]["used"] and params["open"] is False
    assert params["relief_side"] == "left" and params["max_iterations"] == 3000
    assert isinstance(r["planarity_vertices"], int) and r["planarity_vertices"] > 0
    assert all(isinstance(n, str) for n in r["notes"])
    assert r["mesh"]["summary"] == core.mesh_report(*scan[:2])
    t = r["timing"]
    assert t["segment_seconds"] > 0 and t["segment_seconds"] >= sum(p["seconds"] for p in r["phases"]) * 0.99


def test_disk_relief_is_found(scan, disk_result):
    V, _, _, truth, h, radius = scan
    found = set(disk_result["relief_vertices"])
    iou = len(found & truth) / len(found | truth)
    assert iou > 0.85, iou
    # the contour runs along the step, not around the picks (which are 3 h outside)
    off = [abs(math.hypot(x, y) - radius) for x, y, _ in disk_result["contour"]]
    assert sum(off) / len(off) < 0.75 * h


def test_mesh_reuse_gives_the_same_result_twice(scan, disk_result):
    V, F, picks, _, h, _ = scan
    m = core.Mesh(V, F)
    first = m.segment(picks, h, progress=deadline())
    second = m.segment(picks, h, progress=deadline())
    for r in (first, second):
        assert r["relief_vertices"] == disk_result["relief_vertices"]
        assert r["contour"] == pytest.approx(disk_result["contour"])
        assert r["status"] == disk_result["status"]


def test_inputs_in_other_forms_give_the_same_segmentation(scan, disk_result):
    V, F, picks, _, h, _ = scan
    r = core.segment(array.array("d", flat(V)), array.array("q", flat(F)), array.array("l", picks), h,
                     progress=deadline())
    assert r["relief_vertices"] == disk_result["relief_vertices"]


# --- progress and cancellation --------------------------------------------------------------------

def test_progress_arguments(scan):
    V, F, picks, _, h, _ = scan
    calls = []

    budget = deadline()

    def progress(phase, iteration, snaxels, contour):
        calls.append((phase, iteration, snaxels, contour))
        budget(phase, iteration, snaxels, contour)  # returns None: continue

    result = core.segment(V, F, picks, h, progress=progress)
    assert calls
    seen_phases = set()
    for phase, iteration, snaxels, contour in calls:
        assert isinstance(phase, str) and phase in PHASES
        assert isinstance(iteration, int) and iteration >= 0
        if phase == "preprocess":  # before the snake exists: h estimate and planarity
            assert snaxels == 0 and contour in (None, [])
            continue
        assert isinstance(snaxels, int) and snaxels > 0
        if phase not in seen_phases:  # every phase's first call carries the contour
            assert contour is not None
            seen_phases.add(phase)
        if contour is None:
            continue
        assert snaxels == len(contour)
        assert isinstance(contour, list)
        assert all(isinstance(p, tuple) and len(p) == 3 and all(isinstance(x, float) for x in p) for p in contour)
    assert {c[0] for c in calls} <= {p["name"] for p in result["phases"]}


def test_progress_returning_false_cancels(scan):
    V, F, picks, _, h, _ = scan
    calls = []

    def progress(phase, iteration, snaxels, contour):
        calls.append(iteration)
        return len(calls) < 3

    with pytest.raises(core.Cancelled):
        core.segment(V, F, picks, h, progress=progress)
    assert len(calls) == 3  # no calls after the cancel
    with pytest.raises(core.Cancelled):
        core.Mesh(V, F).segment(picks, h, progress=lambda *a: False)


def test_progress_exception_is_reraised(scan):
    V, F, picks, _, h, _ = scan

    class Boom(RuntimeError):
        pass

    boom = Boom("from the callback")
    calls = []

    def progress(*args):
        calls.append(args)
        raise boom

    m = core.Mesh(V, F)
    with pytest.raises(Boom) as e:
        m.segment(picks, h, progress=progress)
    assert e.value is boom and len(calls) == 1
    # the mesh is still usable afterwards
    assert m.segment(picks, h, progress=deadline())["relief_vertices"]


def test_gil_is_released_during_segmentation(scan, disk_result):
    # disk_result first: it proves the segmentation ends (this test cannot use a deadline callback)
    V, F, picks, _, h, _ = scan
    m = core.Mesh(V, F)
    stamps = []
    stop = threading.Event()
    started = threading.Event()

    def spin():
        started.set()
        while not stop.is_set():
            stamps.append(time.perf_counter())

    t = threading.Thread(target=spin)
    t.start()
    started.wait()
    try:
        t0 = time.perf_counter()
        m.segment(picks, h)  # no progress callback: the only way the thread runs is a released GIL
        t1 = time.perf_counter()
    finally:
        stop.set()
        t.join()
    elapsed = t1 - t0
    assert elapsed > 0.01, "segmentation too fast (%.4f s) to observe the GIL" % elapsed
    # With the GIL held the thread would be frozen for the whole call: require that it kept
    # running in the middle half of the call, away from the Python code at either end.
    middle = [s for s in stamps if t0 + 0.25 * elapsed < s < t0 + 0.75 * elapsed]
    assert len(middle) > 100, (len(middle), elapsed)


def test_two_threads_on_one_mesh(scan, disk_result):
    V, F, picks, _, h, _ = scan
    m = core.Mesh(V, F)
    results = [None, None]

    def run(k):
        results[k] = m.segment(picks, h, progress=deadline())

    threads = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=600)
    assert all(r is not None and r["relief_vertices"] == disk_result["relief_vertices"] for r in results)
