"""Whole reliefs (issue 13) through the CLI and the module: inner holes and bands between two pick rings.

Scans come from make-scan (a ring, the letter B, a band round a cylinder); every check compares with
the truth make-scan wrote.
"""
import json
import math
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
    pytest.fail("relief_snake_core not importable from %s (%s): build it (make build) or set "
                "RELIEF_SNAKE_BUILD_DIR" % (BUILD_DIR, exc), pytrace=False)


def run(*args, timeout=180):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=timeout)


def make_scan(tmp, name, *args):
    prefix = os.path.join(str(tmp), name)
    r = run(os.path.join(BUILD_DIR, "make-scan"), *args, "--out", prefix)
    assert r.returncode == 0, r.stderr
    with open(prefix + ".truth.json") as f:
        return prefix + ".ply", json.load(f)


def read_ply(path):
    """Vertices and triangles of make-scan's binary PLY (float32 xyz, uchar count + int32 indices)."""
    import struct
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    nv = int(next(l for l in header if l.startswith("element vertex")).split()[-1])
    nf = int(next(l for l in header if l.startswith("element face")).split()[-1])
    vertices = list(struct.iter_unpack("<3f", data[end:end + 12 * nv]))
    faces, offset = [], end + 12 * nv
    for _ in range(nf):
        faces.append(struct.unpack_from("<3i", data, offset + 1))
        offset += 13
    return vertices, faces


def distance_to(points, polyline):
    """Mean distance of the points to the polyline's (dense) points."""
    total = 0.0
    for p in points:
        total += min(math.dist(p, q) for q in polyline[::2])
    return total / len(points)


def picks_arg(picks):
    return ",".join(map(str, picks))


def iou(a, b):
    a, b = set(a), set(b)
    return len(a & b) / max(1, len(a | b))


@pytest.fixture(scope="module")
def ring(tmp_path_factory):
    return make_scan(tmp_path_factory.mktemp("ring"), "ring", "--shape", "ring", "--step", "blended",
                     "--triangles", "30000")


@pytest.fixture(scope="module")
def tube(tmp_path_factory):
    return make_scan(tmp_path_factory.mktemp("tube"), "tube", "tube", "--triangles", "40000")


CLI = os.path.join(BUILD_DIR, "relief-snake")


def segment_cli(mesh, *args):
    r = run(CLI, "segment", mesh, "--quiet", *args)
    assert r.returncode in (0, 3), r.stderr
    return r.returncode, json.loads(r.stdout)


def test_cli_finds_the_ring_hole(ring):
    mesh, truth = ring
    code, result = segment_cli(mesh, "--picks", picks_arg(truth["picks"]), "--step-height", "1")
    assert code == 0 and result["status"] == "converged", result["message"]
    assert len(result["holes"]) == len(truth["holes"]) == 1
    assert result["hole_checks"][0]["holds"] is True
    edge = truth["average_edge"]
    assert distance_to(result["holes"][0], truth["holes"][0]) < edge
    assert iou(result["relief_vertices"], truth["relief_vertices"]) > 0.9
    assert result["parameters"]["holes"] == "auto"
    assert result["checks"]["holes"] == 1


def test_cli_holes_off_keeps_the_island(ring):
    mesh, truth = ring
    _, on = segment_cli(mesh, "--picks", picks_arg(truth["picks"]), "--step-height", "1")
    _, off = segment_cli(mesh, "--picks", picks_arg(truth["picks"]), "--step-height", "1", "--holes", "off")
    assert off["holes"] == [] and off["parameters"]["holes"] == "off"
    assert set(on["relief_vertices"]) < set(off["relief_vertices"])


def test_cli_hole_picks(ring):
    mesh, truth = ring
    vertices, _ = read_ply(mesh)
    # Six vertices on a circle of radius 5 in the hole (radius 9), in order round it.
    hole = []
    for k in range(6):
        t = 2 * math.pi * k / 6
        target = (5 * math.cos(t), 5 * math.sin(t))
        hole.append(min(range(len(vertices)), key=lambda v: (vertices[v][0] - target[0]) ** 2 +
                        (vertices[v][1] - target[1]) ** 2))
    code, result = segment_cli(mesh, "--picks", picks_arg(truth["picks"]), "--step-height", "1",
                               "--hole-picks", picks_arg(hole))
    assert code == 0, result["message"]
    assert len(result["holes"]) == 1 and result["hole_checks"][0]["from_picks"] is True
    assert result["parameters"]["hole_picks"] == [hole]
    assert distance_to(result["holes"][0], truth["holes"][0]) < truth["average_edge"]


def test_cli_band_between_two_rings(tube):
    mesh, truth = tube
    code, result = segment_cli(mesh, "--picks", picks_arg(truth["picks"]), "--band-picks",
                               picks_arg(truth["band_picks"]), "--step-height", "1")
    assert code == 0, result["message"]
    assert result["band"] is True and len(result["band_contour"]) > 20
    edge = truth["average_edge"]
    assert distance_to(result["contour"], truth["boundary"][0]) < edge
    assert distance_to(result["band_contour"], truth["boundary"][1]) < edge
    assert iou(result["relief_vertices"], truth["relief_vertices"]) > 0.9
    assert "band_step_share" in result["checks"]


@pytest.mark.parametrize("args, words", [
    (["--holes", "maybe"], "--holes must be"),
    (["--hole-picks", "1,2"], "at least 3"),
    (["--band-picks", "1,2"], "at least 3"),
])
def test_cli_usage_errors(ring, args, words):
    mesh, truth = ring
    r = run(CLI, "segment", mesh, "--quiet", "--picks", picks_arg(truth["picks"]), *args)
    assert r.returncode == 2
    assert words in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_cli_hole_pick_out_of_range(ring):
    mesh, truth = ring
    r = run(CLI, "segment", mesh, "--quiet", "--picks", picks_arg(truth["picks"]), "--hole-picks", "1,2,99999999")
    assert r.returncode == 1
    assert "99999999" in r.stderr and len(r.stderr.strip().splitlines()) == 1


# --- the module ---------------------------------------------------------------------------------

def test_module_holes_and_options(ring):
    mesh_path, truth = ring
    vertices, faces = read_ply(mesh_path)
    mesh = core.Mesh(vertices, faces)
    result = mesh.segment(truth["picks"], 1.0)
    assert result["status"] == "converged", result["message"]
    assert len(result["holes"]) == 1
    assert isinstance(result["holes"][0][0], tuple)  # points as tuples, like "contour"
    off = mesh.segment(truth["picks"], 1.0, holes="off")
    assert off["holes"] == []
    small = mesh.segment(truth["picks"], 1.0, min_hole_area=1000)
    assert small["holes"] == [] and any("minimum hole area" in n for n in small["notes"])
    with pytest.raises(core.Error, match="holes must be"):
        mesh.segment(truth["picks"], 1.0, holes="sometimes")
    with pytest.raises(core.Error, match="hole_picks"):
        mesh.segment(truth["picks"], 1.0, hole_picks=5)
    with pytest.raises(core.Error, match="at least 3"):
        mesh.segment(truth["picks"], 1.0, hole_picks=[[1, 2]])


def test_module_band(tube):
    mesh_path, truth = tube
    vertices, faces = read_ply(mesh_path)
    result = core.segment(vertices, faces, truth["picks"], 1.0, band_picks=truth["band_picks"])
    assert result["status"] == "converged", result["message"]
    assert len(result["band_contour"]) > 20 and isinstance(result["band_contour"][0], tuple)
    assert result["parameters"]["band_picks"] == truth["band_picks"]
    assert iou(result["relief_vertices"], truth["relief_vertices"]) > 0.9
