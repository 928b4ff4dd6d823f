"""The relief-snake command-line tool, run as a user would: exit codes, stdout, stderr."""
import json
import math
import subprocess
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def cli(build_dir):
    exe = build_dir / "relief-snake"
    if not exe.is_file():
        pytest.fail(f"{exe} not found: build the relief-snake target")
    return exe


def run(exe, *args, timeout=120):
    return subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True, timeout=timeout)


@pytest.fixture
def grid_obj(tmp_path):
    """3 x 3 vertices, spacing 2, on z = 0 (8 triangles), plus an unused vertex 9 at (5, 5, 5)."""
    lines = [f"v {2 * i} {2 * j} 0" for j in range(3) for i in range(3)] + ["v 5 5 5"]
    for j in range(2):
        for i in range(2):
            a = j * 3 + i + 1  # OBJ indices are 1-based
            b, c, d = a + 1, a + 3, a + 4
            lines += [f"f {a} {b} {d}", f"f {a} {d} {c}"]
    path = tmp_path / "grid.obj"
    path.write_text("\n".join(lines) + "\n")
    return path


def assert_one_error_line(result, code):
    assert result.returncode == code, (result.returncode, result.stderr)
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("relief-snake: ")
    assert len(lines[0]) > len("relief-snake: ") + 5
    assert result.stdout == ""
    return lines[0]


def test_help_and_no_arguments(cli):
    r = run(cli, "--help")
    assert r.returncode == 0
    assert "relief-snake segment MESH" in r.stdout and "measure" in r.stdout and "info" in r.stdout
    r = run(cli)
    assert r.returncode == 2
    assert "usage" in r.stderr


def test_measure_prints_one_number(cli, grid_obj):
    r = run(cli, "measure", grid_obj, 0, 8)
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""
    assert math.isclose(float(r.stdout.strip()), 4 * math.sqrt(2), rel_tol=1e-12)
    assert len(r.stdout.split()) == 1
    r = run(cli, "measure", grid_obj, 4, 4)
    assert float(r.stdout) == 0.0


def test_info_reports_the_mesh(cli, grid_obj):
    r = run(cli, "info", grid_obj)
    assert r.returncode == 0, r.stderr
    assert "triangles: 8\n" in r.stdout
    assert "components: 1\n" in r.stdout
    assert "unreferenced vertices: 1\n" in r.stdout
    assert "boundary edges: 8\n" in r.stdout
    assert "input vertices: 10\n" in r.stdout


@pytest.mark.parametrize(
    "args, code, words",
    [
        (["segment", "{missing}", "--picks", "1,2,3", "--step-height", "1"], 1, ["missing.obj"]),
        (["segment", "{mesh}", "--picks", "1,x,3", "--step-height", "1"], 2, ["'x'"]),
        (["segment", "{mesh}", "--picks", "1,2", "--step-height", "1"], 2, ["at least 3"]),
        (["segment", "{mesh}", "--picks", "0,1,42", "--step-height", "1"], 1, ["42", "out of range"]),
        (["segment", "{mesh}", "--picks", "0,1,9", "--step-height", "1"], 1, ["9", "no face"]),
        (["segment", "{mesh}", "--picks", "0,1,4", "--step-height", "0"], 2, ["> 0"]),
        (["segment", "{mesh}", "--picks", "0,1,4", "--step-height", "-1"], 2, ["> 0"]),
        (["segment", "{mesh}", "--picks", "0,1,4", "--step-height", "nan"], 2, ["finite number"]),
        (["segment", "{mesh}", "--picks", "0,1,4", "--step-height", "abc"], 2, ["'abc'"]),
        (["segment", "{mesh}", "--picks", "0,1,4"], 2, ["--step-height"]),
        (["segment", "{mesh}", "--step-height", "1"], 2, ["--picks"]),
        (["segment", "{mesh}", "--picks", "0,1,4", "--step-height", "1", "--bogus"], 2, ["--bogus"]),
        (["segment", "{mesh}", "--picks", "0,1,4", "--step-height", "1", "--relief-side", "left"], 2, ["--open"]),
        (["segment", "{mesh}", "--picks", "0,1", "--step-height", "1", "--open", "--relief-side", "up"], 2, ["'up'"]),
        (["segment", "{mesh}", "--picks", "0,1,4", "--step-height", "1", "--w-int", "2"], 2, ["--w-int"]),
        (["measure", "{mesh}", "0", "99"], 1, ["99", "out of range"]),
        (["measure", "{mesh}", "0"], 2, ["MESH I J"]),
        (["measure", "{mesh}", "0", "-3"], 2, ["-3"]),
        (["info", "{bad}"], 1, ["bad.xyz", "OBJ, PLY, STL or OFF"]),
        (["frobnicate"], 2, ["frobnicate"]),
    ],
)
def test_errors_are_one_line_with_exit_code(cli, grid_obj, tmp_path, args, code, words):
    bad = tmp_path / "bad.xyz"
    bad.write_text("0 0 0\n")
    values = {"mesh": grid_obj, "missing": tmp_path / "missing.obj", "bad": bad}
    line = assert_one_error_line(run(cli, *[a.format(**values) for a in args]), code)
    for w in words:
        assert w in line, line


def test_garbage_mesh_file_fails_cleanly(cli, tmp_path):
    path = tmp_path / "garbage.ply"
    path.write_bytes(b"ply\nformat ascii 1.0\nelement vertex 99999999\nproperty float x\nend_header\n1\n")
    assert "garbage.ply" in assert_one_error_line(run(cli, "info", path), 1)
    path = tmp_path / "empty.obj"
    path.write_text("")
    assert "empty.obj" in assert_one_error_line(run(cli, "measure", path, 0, 1), 1)


def test_segment_synthetic_scan(cli, build_dir, tmp_path):
    make_scan = build_dir / "make-scan"
    if not make_scan.is_file():
        pytest.fail(f"{make_scan} not found: build the make-scan target")
    prefix = tmp_path / "disk"
    r = subprocess.run([str(make_scan), "--shape", "disk", "--triangles", "60000", "--step", "blended",
                        "--out", str(prefix)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    truth = json.loads(Path(f"{prefix}.truth.json").read_text())
    out = tmp_path / "result.json"
    picks = ",".join(str(p) for p in truth["picks"])
    r = run(cli, "segment", f"{prefix}.ply", "--picks", picks, "--step-height", truth["h"], "--out", out, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout == ""
    assert "loaded" in r.stderr and "coarse" in r.stderr  # progress on stderr
    result = json.loads(out.read_text())

    # Schema.
    for key in ["status", "closed", "contour", "relief_vertices", "phases", "parameters", "mesh",
                "planarity_vertices", "notes", "timing"]:
        assert key in result, key
    assert result["status"] in ("converged", "iteration_cap")
    assert result["closed"] is True
    assert len(result["contour"]) >= 3 and all(len(p) == 3 for p in result["contour"])
    assert [p["name"] for p in result["phases"]][-3:] == ["coarse", "refine", "stabilise"]
    for phase in result["phases"]:
        assert set(phase) == {"name", "iterations", "snaxels", "seconds", "converged"}
    params = result["parameters"]
    assert params["step_height"] == truth["h"] and params["picks"] == truth["picks"]
    assert params["open"] is False and params["w_int"] == 0.25 and params["max_iterations"] == 3000
    for key in ["coarse_spacing", "refine_spacing", "alpha_coarse", "beta_coarse", "alpha_refine", "beta_refine",
                "gamma", "sigma_background", "sigma_s", "w_f", "w_d", "average_edge"]:
        assert key in params, key
    assert result["mesh"]["triangles"] == truth["triangles"]
    assert result["planarity_vertices"] > 0
    assert result["timing"]["load_seconds"] >= 0 and result["timing"]["segment_seconds"] > 0

    # The relief found is mostly the true relief.
    found, true = set(result["relief_vertices"]), set(truth["relief_vertices"])
    assert found, "no relief vertices"
    precision = len(found & true) / len(found)
    recall = len(found & true) / len(true)
    assert precision >= 0.9, (precision, recall)
    assert recall >= 0.8, (precision, recall)
