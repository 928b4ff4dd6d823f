"""The module's input reading on hostile and unusual arguments (issue 11, part 4).

Rows that are Vector-like objects, custom sequences, ranges and numpy rows; buffers of every
supported type and stride; wrong types and values named by position; containers mutated by
their own items' __float__; a segment() re-entered from its own progress callback. The last
test runs this file again in a child interpreter under PYTHONMALLOC=debug, where a
use-after-free of an item shows up as a crash or garbage."""
import array
import gc
import os
import subprocess
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BUILD_DIR = os.environ.get("RELIEF_SNAKE_BUILD_DIR", os.path.join(ROOT, "build"))
if BUILD_DIR not in sys.path:
    sys.path.insert(0, BUILD_DIR)

try:
    import relief_snake_core as core
except ImportError as exc:  # a suite that cannot run must fail, not skip
    pytest.fail("relief_snake_core not importable from %s (%s)" % (BUILD_DIR, exc), pytrace=False)

try:
    import numpy as np
except ImportError:
    np = None
needs_numpy = pytest.mark.skipif(np is None, reason="numpy not installed")

V = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (1.0, 1.0, 0.5)]
F = [(0, 1, 2), (1, 3, 2)]
EXPECTED = core.mesh_report(V, F)


class Vector:
    """Like Blender's mathutils.Vector: a sequence of floats made on each access."""

    def __init__(self, xyz):
        self._xyz = list(xyz)

    def __len__(self):
        return 3

    def __getitem__(self, i):
        if not -3 <= i < 3:
            raise IndexError(i)
        return float(self._xyz[i])  # a new object each time: no one else holds it


class Rows:
    """A custom sequence whose rows exist only while they are used."""

    def __init__(self, rows):
        self._rows = rows

    def __len__(self):
        return len(self._rows)

    def __getitem__(self, i):
        if not -len(self._rows) <= i < len(self._rows):
            raise IndexError(i)
        return Vector(self._rows[i])


class Floaty:
    def __init__(self, x):
        self.x = x

    def __float__(self):
        return float(self.x)


def assert_error(excinfo, *words):
    message = str(excinfo.value)
    assert message and "\n" not in message, message
    for w in words:
        assert w in message, (w, message)


# --- accepted forms --------------------------------------------------------------------------

@pytest.mark.parametrize("vertices", [
    [Vector(p) for p in V],
    Rows(V),
    tuple(tuple(p) for p in V),
    [list(p) for p in V],
    [x for p in V for x in p],                                 # flat
    array.array("d", [x for p in V for x in p]),
    array.array("f", [x for p in V for x in p]),
    memoryview(array.array("d", [x for p in V for x in p])),
    [[Floaty(x) for x in p] for p in V],
])
def test_vertex_forms(vertices):
    assert core.mesh_report(vertices, F) == EXPECTED


@pytest.mark.parametrize("triangles", [
    [range(3), (1, 3, 2)],
    (range(0, 3), [1, 3, 2]),
    array.array("i", [0, 1, 2, 1, 3, 2]),
    array.array("q", [0, 1, 2, 1, 3, 2]),
    array.array("l", [0, 1, 2, 1, 3, 2]),
    array.array("I", [0, 1, 2, 1, 3, 2]),
    memoryview(array.array("i", [0, 1, 2, 1, 3, 2])).cast("B").cast("i"),
])
def test_triangle_forms(triangles):
    assert core.mesh_report(V, triangles) == EXPECTED


@needs_numpy
@pytest.mark.parametrize("dtype", ["float32", "float64"])
def test_numpy_vertices_of_any_stride(dtype):
    a = np.array(V, dtype=dtype)
    for view in [a, np.asfortranarray(a), a[::-1][::-1], np.repeat(a, 2, axis=0)[::2], np.hstack([a, a])[:, :3]]:
        assert core.mesh_report(view, F) == EXPECTED
    wide = np.zeros((4, 6), dtype=dtype)
    wide[:, ::2] = a
    assert core.mesh_report(wide[:, ::2], F) == EXPECTED      # column stride 2
    assert core.mesh_report(list(a), F) == EXPECTED           # list of numpy rows
    assert core.mesh_report([row for row in a], F) == EXPECTED
    assert core.mesh_report(a.ravel(), F) == EXPECTED


@needs_numpy
@pytest.mark.parametrize("dtype", ["int32", "int64", "uint32"])
def test_numpy_triangles_of_any_stride(dtype):
    t = np.array(F, dtype=dtype)
    assert core.mesh_report(V, t) == EXPECTED
    assert core.mesh_report(V, np.asfortranarray(t)) == EXPECTED
    assert core.mesh_report(V, t[::-1][::-1]) == EXPECTED
    assert core.mesh_report(V, list(t)) == EXPECTED
    reversed_rows = t[::-1]
    assert core.mesh_report(V, reversed_rows) == core.mesh_report(V, [F[1], F[0]])


# --- refused forms: TypeError / ValueError naming the position and the value ---------------

@pytest.mark.parametrize("vertices, exc, words", [
    ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, "a", 1)], TypeError, ["vertices[3][1]", "str", "'a'"]),
    ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, None, 1)], TypeError, ["vertices[3][1]", "None"]),
    ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1)], ValueError, ["row 3", "2 values"]),
    ([(0, 0, 0), (1, 0, 0), (0, 1, 0), 5], ValueError, ["multiple of 3"]),
    ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (True, 0, 0)], TypeError, ["vertices[3][0]", "bool"]),
    ({"a": 1}, TypeError, ["vertices", "dict"]),
    (b"\0" * 36, TypeError, ["vertices", "bytes"]),
    (42, TypeError, ["vertices", "int"]),
])
def test_bad_vertices_name_position_and_value(vertices, exc, words):
    with pytest.raises(exc) as e:
        core.Mesh(vertices, F)
    assert_error(e, *words)
    assert isinstance(e.value, core.Error)  # also the module's documented error


@pytest.mark.parametrize("triangles, exc, words", [
    ([(0, 1, 2), (1, 3, 2.0)], TypeError, ["triangles[1][2]", "float"]),
    ([(0, 1, 2), (1, 3, "2")], TypeError, ["triangles[1][2]", "str"]),
    ([(0, 1, 2), (1, 3, 2 ** 70)], ValueError, ["triangles", "64 bits"]),
    ([(0, 1, 2), (1, 3, 9)], ValueError, ["triangle 1", "9", "out of range"]),
    (array.array("d", [0, 1, 2]), TypeError, ["triangles", "integers"]),
])
def test_bad_triangles_name_position_and_value(triangles, exc, words):
    with pytest.raises(exc) as e:
        core.Mesh(V, triangles)
    assert_error(e, *words)


def test_bad_picks_name_position():
    m = core.Mesh(V, F)
    with pytest.raises(TypeError) as e:
        m.segment([0, 1, "2"], 0.5)
    assert_error(e, "picks[2]", "str")
    with pytest.raises(TypeError) as e:
        m.segment([0, 1, (2, 3)], 0.5)
    assert_error(e, "picks[2]", "single integers")


def test_failing_items_are_reported_not_crashed():
    class Broken:
        def __len__(self):
            return 3

        def __getitem__(self, i):
            raise RuntimeError("boom")

    class BadFloat:
        def __float__(self):
            raise RuntimeError("no")

    with pytest.raises(TypeError) as e:
        core.Mesh([Broken()] * 4, F)
    assert_error(e, "vertices[0][0]", "__getitem__")
    with pytest.raises(TypeError) as e:
        core.Mesh([(0, 0, 0), (1, 0, 0), (0, 1, 0), (BadFloat(), 0, 0)], F)
    assert_error(e, "vertices[3][0]", "float")


def test_items_that_mutate_their_container_are_safe():
    """An item's __float__ empties the list that holds it: the reader must hold its own references."""
    rows = []

    class Evil:
        def __init__(self, x):
            self.x = x

        def __float__(self):
            rows.clear()
            gc.collect()
            return float(self.x)

    rows.extend([[Evil(x) for x in p] for p in V])
    try:
        report = core.mesh_report(rows, F)
    except core.Error as e:  # the list shrank under the reader: a clean refusal is fine too
        assert "\n" not in str(e)
    else:
        assert report == EXPECTED


def test_allow_partial_skips_and_reports():
    bad_v = V + [(float("nan"), 0.0, 0.0)]
    bad_f = F + [(0, 1, 4), (0, 1, 99)]
    with pytest.raises(core.Error):
        core.Mesh(bad_v, bad_f)
    m = core.Mesh(bad_v, bad_f, allow_partial=True)
    assert m.n_faces == 2
    assert "partial load: 2 invalid faces skipped" in m.report
    assert "1 invalid vertex ignored" in m.report
    assert core.mesh_report(bad_v, bad_f, allow_partial=True) == m.report


# --- re-entrancy ------------------------------------------------------------------------------

def grid_scan(n=30):
    verts, tris = [], []
    for j in range(n):
        for i in range(n):
            verts.append((float(i), float(j), 1.0 if 9 <= i <= 20 and 9 <= j <= 20 else 0.0))
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            tris += [(a, a + 1, a + n + 1), (a, a + n + 1, a + n)]
    picks = [j * n + i for i, j in [(5, 5), (24, 5), (24, 24), (5, 24)]]
    return verts, tris, picks


def test_reentrant_segment_from_its_own_callback_raises():
    verts, tris, picks = grid_scan()
    m = core.Mesh(verts, tris)
    inner = []

    def progress(phase, iteration, snaxels, contour):
        if not inner:
            try:
                m.segment(picks, 1.0)
            except RuntimeError as e:
                inner.append(str(e))
            return False  # cancel the outer run
        return False

    with pytest.raises(core.Cancelled):
        m.segment(picks, 1.0, progress=progress)
    assert inner and "its own progress callback" in inner[0]
    # The Mesh is usable afterwards (nothing left locked).
    assert m.segment(picks, 1.0, max_iterations=5)["status"]


@pytest.mark.skipif(os.environ.get("RELIEF_SNAKE_DEBUG_MALLOC_CHILD") == "1", reason="already the child")
def test_this_file_under_pythonmalloc_debug():
    env = dict(os.environ, PYTHONMALLOC="debug", RELIEF_SNAKE_DEBUG_MALLOC_CHILD="1", RELIEF_SNAKE_BUILD_DIR=BUILD_DIR)
    p = subprocess.run([sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider", __file__],
                       env=env, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-3000:]
