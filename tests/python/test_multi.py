"""Several reliefs: segment with repeated --picks, relief-snake detect, Mesh.segment_many and Mesh.detect.

Plates come from `make-scan --plate SEED` (several reliefs, two of them touching at different heights;
truth per relief) or, for the module, a grid with two disks built here.
"""
import json
import math
import os
import random
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BUILD_DIR = Path(os.environ.get("RELIEF_SNAKE_BUILD_DIR", ROOT / "build")).resolve()
if str(BUILD_DIR) not in sys.path:
    sys.path.insert(0, str(BUILD_DIR))
try:
    import relief_snake_core as core
except ImportError as exc:  # a suite that cannot run must fail, not skip
    pytest.fail(f"relief_snake_core not importable from {BUILD_DIR} ({exc}): build it", pytrace=False)


def run(*args, timeout=300):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=timeout)


def iou(a, b):
    a, b = set(a), set(b)
    return len(a & b) / len(a | b) if a | b else 1.0


@pytest.fixture(scope="module")
def plate(tmp_path_factory):
    """A 60k-triangle plate (seed 2: two touching boxes, two disks, one tiny disk) and its truth."""
    prefix = tmp_path_factory.mktemp("plate") / "plate"
    r = run(BUILD_DIR / "make-scan", "--plate", 2, "--triangles", 60000, "--out", prefix)
    assert r.returncode == 0, r.stderr
    return Path(f"{prefix}.ply"), json.loads(Path(f"{prefix}.truth.json").read_text())


def test_detect_cli_finds_every_relief(plate, tmp_path):
    mesh, truth = plate
    out = tmp_path / "detect.json"
    r = run(BUILD_DIR / "relief-snake", "detect", mesh, "--out", out)
    assert r.returncode in (0, 3), r.stderr[-2000:]
    assert "candidate 1:" in r.stderr and r.stdout == ""
    doc = json.loads(out.read_text())
    assert doc["format"] == "relief-snake-detect/1"
    assert not Path(f"{out}.part").exists()
    min_area = doc["parameters"]["min_area"]
    assert doc["parameters"]["min_area_given"] is False
    for relief in truth["reliefs"]:
        best = max((iou(c["relief_vertices"], relief["vertices"]) for c in doc["candidates"]), default=0)
        if relief["area"] >= min_area:
            assert best >= 0.9, (relief["shape"], relief["h"], best)
        else:
            assert best == 0, "the relief below the minimum area was proposed"
    for c in doc["candidates"]:
        # each candidate is a result document plus its detection record
        assert c["format"] == "relief-snake-result/1" and c["status"] in ("converged", "doubtful")
        assert len(c["contour"]) >= 3 and c["step_height"]["used"] > 0
        assert 0 < c["detection"]["score"] <= 1 and c["detection"]["area"] >= min_area
        assert len(c["parameters"]["picks"]) >= 6
        assert max(iou(c["relief_vertices"], t["vertices"]) for t in truth["reliefs"]) >= 0.5, "false candidate"
    assert doc["timing"]["detect_seconds"] > 0 and doc["background"]["region_vertices"] > 0


def test_segment_with_several_pick_groups(plate, tmp_path):
    mesh, truth = plate
    cli = BUILD_DIR / "relief-snake"
    # The outline picks of detect's components (no snake) are picks around each relief.
    proposal = tmp_path / "components.json"
    r = run(cli, "detect", mesh, "--no-refine", "--quiet", "--out", proposal)
    assert r.returncode == 0, r.stderr
    candidates = json.loads(proposal.read_text())["candidates"]
    assert all(c["status"] == "unrefined" for c in candidates)
    separate = [c for c in candidates if c["detection"]["plateau"] == 0][:2]
    assert len(separate) == 2
    groups = [",".join(map(str, c["parameters"]["picks"])) for c in separate]
    out = tmp_path / "many.json"
    r = run(cli, "segment", mesh, "--picks", groups[0], "--picks", groups[1], "--out", out)
    assert r.returncode in (0, 3), r.stderr[-2000:]
    assert "relief 2/2" in r.stderr
    doc = json.loads(out.read_text())
    assert doc["format"] == "relief-snake-results/1" and len(doc["reliefs"]) == 2
    assert doc["overlaps"] == []
    assert sum(doc["counts"].values()) == 2
    for entry, group in zip(doc["reliefs"], groups):
        assert entry["format"] == "relief-snake-result/1"
        assert entry["parameters"]["picks"] == [int(p) for p in group.split(",")]
        assert max(iou(entry["relief_vertices"], t["vertices"]) for t in truth["reliefs"]) >= 0.9
    # One group: the single-result document, as before.
    single = tmp_path / "one.json"
    r = run(cli, "segment", mesh, "--picks", groups[0], "--quiet", "--out", single)
    assert r.returncode in (0, 3), r.stderr
    one = json.loads(single.read_text())
    assert one["format"] == "relief-snake-result/1" and "reliefs" not in one
    assert one["relief_vertices"] == doc["reliefs"][0]["relief_vertices"]


def test_segment_groups_that_overlap_are_reported(plate, tmp_path):
    mesh, _ = plate
    cli = BUILD_DIR / "relief-snake"
    proposal = tmp_path / "components.json"
    assert run(cli, "detect", mesh, "--no-refine", "--quiet", "--out", proposal).returncode == 0
    picks = json.loads(proposal.read_text())["candidates"][0]["parameters"]["picks"]
    group = ",".join(map(str, picks))
    shifted = ",".join(map(str, picks[3:] + picks[:3]))  # the same outline from another start
    out = tmp_path / "twice.json"
    r = run(cli, "segment", mesh, "--picks", group, "--picks", shifted, "--quiet", "--out", out)
    assert r.returncode == 3, r.stderr
    doc = json.loads(out.read_text())
    assert len(doc["overlaps"]) == 1 and doc["overlaps"][0]["reliefs"] == [0, 1]
    assert min(doc["overlaps"][0]["share"]) > 0.5
    for k, entry in enumerate(doc["reliefs"]):
        assert entry["status"] == "doubtful"
        assert any(f"relief {1 - k}" in reason for reason in entry["reasons"])


def test_detect_cli_no_relief_and_errors(tmp_path):
    cli = BUILD_DIR / "relief-snake"
    prefix = tmp_path / "empty"
    r = run(BUILD_DIR / "make-scan", "--plate", 3, "--empty", "--background", "cylinder", "--noise", 0.02,
            "--triangles", 30000, "--out", prefix)
    assert r.returncode == 0, r.stderr
    out = tmp_path / "none.json"
    r = run(cli, "detect", f"{prefix}.ply", "--quiet", "--out", out)
    assert r.returncode == 0, r.stderr
    doc = json.loads(out.read_text())
    assert doc["candidates"] == [] and any("no relief" in n for n in doc["notes"])

    def one_line(result, code, *words):
        assert result.returncode == code, (result.returncode, result.stderr)
        lines = result.stderr.splitlines()
        assert len(lines) == 1 and lines[0].startswith("relief-snake: "), result.stderr
        for w in words:
            assert w in lines[0], (w, lines[0])

    mesh = f"{prefix}.ply"
    one_line(run(cli, "detect", mesh, "--min-area", "-1"), 2, "--min-area")
    one_line(run(cli, "detect", mesh, "--min-area", "x"), 2, "number")
    one_line(run(cli, "detect", mesh, "--frobnicate"), 2, "unknown option")
    one_line(run(cli, "detect"), 2, "MESH")
    one_line(run(cli, "detect", mesh, "--region-vertices", tmp_path / "missing.txt"), 1, "cannot read")
    bad = tmp_path / "bad.txt"
    bad.write_text("1 2 three\n")
    one_line(run(cli, "detect", mesh, "--region-vertices", bad), 1, "three")
    far = tmp_path / "far.txt"
    far.write_text("[0, 1, 99999999]")
    one_line(run(cli, "detect", mesh, "--region-vertices", far), 1, "99999999")
    one_line(run(cli, "detect", mesh, "--option", "tau=7"), 2, "tau")
    # A region given as a list: only those vertices are searched (no relief there either).
    region = tmp_path / "region.json"
    region.write_text(json.dumps(list(range(0, 5000))))
    r = run(cli, "detect", mesh, "--region-vertices", region, "--quiet")
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["background"]["region_vertices"] <= 5000


# --- the module -----------------------------------------------------------------------------

def two_disks(n=90, size=80.0, h=1.0, seed=3):
    """z = 0 with two disks of radius 8 at x = -18 and x = +18 raised by h (sharp), jittered grid."""
    rng = random.Random(seed)
    step = size / (n - 1)
    vertices, truth = [], [set(), set()]
    for j in range(n):
        for i in range(n):
            x, y = -size / 2 + i * step, -size / 2 + j * step
            if 0 < i < n - 1 and 0 < j < n - 1:
                x += rng.uniform(-0.3, 0.3) * step
                y += rng.uniform(-0.3, 0.3) * step
            z = 0.0
            for k, cx in enumerate((-18.0, 18.0)):
                if math.hypot(x - cx, y) < 8:
                    z = h
                    truth[k].add(len(vertices))
            vertices.append((x, y, z))
    triangles = []
    for j in range(n - 1):
        for i in range(n - 1):
            a, b, c, d = j * n + i, j * n + i + 1, (j + 1) * n + i, (j + 1) * n + i + 1
            triangles += [(a, b, d), (a, d, c)] if (i + j) % 2 else [(a, b, c), (b, d, c)]

    def ring(cx, r=11.0, count=10):
        out = []
        for k in range(count):
            t = 2 * math.pi * k / count
            px, py = cx + r * math.cos(t), r * math.sin(t)
            out.append(min(range(len(vertices)), key=lambda v: (vertices[v][0] - px) ** 2 + (vertices[v][1] - py) ** 2))
        return out

    return vertices, triangles, [ring(-18.0), ring(18.0)], truth


@pytest.fixture(scope="module")
def disks():
    return two_disks()


def test_mesh_segment_many(disks):
    vertices, triangles, groups, truth = disks
    mesh = core.Mesh(vertices, triangles)
    calls = []
    doc = mesh.segment_many(groups, 1.0, progress=lambda i, phase, it, n, contour: calls.append((i, phase)))
    assert doc["format"] == "relief-snake-results/1" and doc["status"] == "converged"
    assert sorted({i for i, _ in calls}) == [0, 1]
    for entry, group, true in zip(doc["reliefs"], groups, truth):
        assert entry["status"] == "converged" and entry["parameters"]["picks"] == group
        assert isinstance(entry["contour"][0], tuple)
        assert iou(entry["relief_vertices"], true) >= 0.9
    # One group through segment_many is the same relief as segment().
    one = mesh.segment(groups[0], 1.0)
    assert one["relief_vertices"] == doc["reliefs"][0]["relief_vertices"]


def test_mesh_segment_many_arguments(disks):
    vertices, triangles, groups, _ = disks
    mesh = core.Mesh(vertices, triangles)
    with pytest.raises(core.Error, match="groups is empty"):
        mesh.segment_many([])
    with pytest.raises(TypeError, match="groups"):
        mesh.segment_many(groups[0])  # a flat list of picks, not a list of groups
    with pytest.raises(TypeError, match="groups"):
        mesh.segment_many(None)
    with pytest.raises(core.Error, match=r"groups\[1\].*not a vertex index"):
        mesh.segment_many([groups[0], [1, 2, len(vertices)]])
    with pytest.raises(core.Error, match="max_overlap_share"):
        mesh.segment_many(groups, max_overlap_share=2)
    with pytest.raises(TypeError, match="tauu"):
        mesh.segment_many(groups, tauu=0.2)
    with pytest.raises(core.Cancelled):
        mesh.segment_many(groups, 1.0, progress=lambda *a: False)
    with pytest.raises(ZeroDivisionError):
        mesh.segment_many(groups, 1.0, progress=lambda *a: 1 / 0)
    # A group that cannot run is recorded, the other still segments.
    doc = mesh.segment_many([groups[0], [groups[1][0], groups[1][1]]], 1.0)
    assert doc["reliefs"][0]["status"] == "converged"
    assert doc["reliefs"][1]["status"] == "failed" and "at least 3" in doc["reliefs"][1]["message"]
    assert doc["counts"]["failed"] == 1 and doc["status"] == "doubtful"


def test_mesh_detect(disks):
    vertices, triangles, _, truth = disks
    mesh = core.Mesh(vertices, triangles)
    seen = set()
    doc = mesh.detect(progress=lambda i, phase, it, n, contour: seen.add(i))
    assert doc["format"] == "relief-snake-detect/1"
    assert len(doc["candidates"]) == 2 and seen == {0, 1}
    for true in truth:
        assert max(iou(c["relief_vertices"], true) for c in doc["candidates"]) >= 0.9
    for c in doc["candidates"]:
        assert c["status"] == "converged" and isinstance(c["contour"][0], tuple)
        assert abs(c["step_height"]["used"] - 1.0) < 0.2 and c["detection"]["score"] > 0.8
    # Only the left half: one relief.
    left = [v for v, p in enumerate(vertices) if p[0] < 0]
    half = mesh.detect(left, refine=False)
    assert len(half["candidates"]) == 1 and half["candidates"][0]["status"] == "unrefined"
    assert iou(half["candidates"][0]["relief_vertices"], truth[0]) > 0.6
    assert mesh.detect(min_area=10000.0, refine=False)["candidates"] == []


def test_mesh_detect_progress_before_refining(disks):
    """The background fits and the components call progress (phase 'background', then
    'candidates' with their count) before the snake's phases; a cancel there stops at once."""
    vertices, triangles, _, _ = disks
    mesh = core.Mesh(vertices, triangles)
    calls = []
    doc = mesh.detect(progress=lambda i, phase, it, n, contour: calls.append((i, phase, it, contour)))
    assert [c[1] for c in calls[:4]] == ["background"] * 3 + ["candidates"]
    assert [c[2] for c in calls[:3]] == [0, 1, 2] and {c[0] for c in calls[:4]} == {0}
    assert calls[3][2] >= len(doc["candidates"]) == 2
    assert all(c[3] in (None, []) for c in calls[:4])  # nothing to draw yet
    assert not {"background", "candidates"} & {c[1] for c in calls[4:]}
    for stop in (1, 4):
        seen = []
        with pytest.raises(core.Cancelled):
            mesh.detect(progress=lambda i, phase, it, n, contour: seen.append(phase) or len(seen) < stop)
        assert len(seen) == stop and seen[-1] == ("background" if stop == 1 else "candidates")


def test_mesh_detect_arguments(disks):
    vertices, triangles, _, _ = disks
    mesh = core.Mesh(vertices, triangles)
    with pytest.raises(core.Error, match="min_area"):
        mesh.detect(min_area=-1)
    with pytest.raises(TypeError, match="min_area"):
        mesh.detect(min_area="big")
    with pytest.raises(core.Error, match="region_vertices is empty"):
        mesh.detect([])
    with pytest.raises(core.Error, match="not a vertex index"):
        mesh.detect([0, 1, len(vertices) + 5])
    with pytest.raises(core.Error, match="background_degree"):
        mesh.detect(background_degree=9)
    with pytest.raises(TypeError, match="region_vertices"):
        mesh.detect([0.5, 1.5])
    with pytest.raises(core.Cancelled):
        mesh.detect(progress=lambda *a: False)


@pytest.mark.parametrize("method", ["segment_many", "detect"])
def test_several_reliefs_release_the_gil_and_refuse_reentry(disks, method):
    """The add-on's Detect and Segment Pick Groups run these in a worker thread while Blender's
    main thread keeps drawing: the GIL must be released outside the progress callback, and a call
    on the same Mesh from inside its own callback must fail at once instead of deadlocking."""
    import threading
    import time
    vertices, triangles, groups, _ = disks
    mesh = core.Mesh(vertices, triangles)

    def call(progress=None):
        if method == "segment_many":
            return mesh.segment_many(groups, 1.0, progress=progress)
        return mesh.detect(progress=progress)

    stamps, stop, started = [], threading.Event(), threading.Event()

    def spin():
        started.set()
        while not stop.is_set():
            stamps.append(time.perf_counter())

    t = threading.Thread(target=spin)
    t.start()
    started.wait()
    try:
        t0 = time.perf_counter()
        call()  # no callback: the spinning thread runs only if the GIL is released
        t1 = time.perf_counter()
    finally:
        stop.set()
        t.join()
    elapsed = t1 - t0
    assert elapsed > 0.01, "%s too fast (%.4f s) to observe the GIL" % (method, elapsed)
    middle = [s for s in stamps if t0 + 0.25 * elapsed < s < t0 + 0.75 * elapsed]
    assert len(middle) > 100, (len(middle), elapsed)

    inner = []

    def reenter(*args):
        if not inner:
            for again in (lambda: mesh.detect(refine=False), lambda: mesh.segment_many(groups, 1.0),
                          lambda: mesh.segment(groups[0], 1.0)):
                try:
                    again()
                    inner.append("returned")
                except RuntimeError as exc:
                    inner.append(str(exc))
        return False  # cancel the outer run

    with pytest.raises(core.Cancelled):
        call(reenter)
    assert len(inner) == 3 and all("own progress callback" in text for text in inner), inner
    assert call()["format"].startswith("relief-snake-")  # nothing left locked
