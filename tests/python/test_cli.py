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
        # No h: estimated; a flat grid has no relief to estimate it from.
        (["segment", "{mesh}", "--picks", "0,1,4", "--quiet"], 1, ["step height", "give h"]),
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
    for key in ["format", "status", "message", "reasons", "closed", "contour", "relief_vertices", "step_height",
                "w_int", "checks", "attempts", "phases", "parameters", "mesh", "planarity_vertices", "notes",
                "timing"]:
        assert key in result, key
    # The true h on a clean scan: the self-check holds, so the status is converged and exit code 0.
    assert result["status"] == "converged" and result["message"] == "" and result["reasons"] == []
    assert result["checks"]["step_share"] >= 0.9
    assert result["closed"] is True
    assert len(result["contour"]) >= 3 and all(len(p) == 3 for p in result["contour"])
    assert [p["name"] for p in result["phases"]][-3:] == ["coarse", "refine", "stabilise"]
    for phase in result["phases"]:
        assert set(phase) == {"name", "iterations", "snaxels", "seconds", "converged"}
    params = result["parameters"]
    assert result["step_height"]["given"] == truth["h"] and params["picks"] == truth["picks"]
    assert result["step_height"]["used"] == params["step_height"]
    assert result["w_int"]["given"] is None and result["w_int"]["used"] in (0.25, 0.5, 1.0)
    assert params["open"] is False and params["w_int"] == result["w_int"]["used"] and params["max_iterations"] == 3000
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


def scan_positions(ply):
    """Vertex positions of a make-scan PLY (binary little-endian, float x y z)."""
    import struct
    data = Path(ply).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    assert [l for l in header if l.startswith("property float")] == ["property float x", "property float y",
                                                                     "property float z"]
    n = int(next(l for l in header if l.startswith("element vertex")).split()[2])
    return [struct.unpack_from("<3f", data, end + 12 * k) for k in range(n)]


def test_segment_names_picks_on_one_side_of_the_relief(cli, build_dir, tmp_path):
    """Picks that all lie beside the relief (issue 11): an error or a doubtful result that says so."""
    make_scan = build_dir / "make-scan"
    results = {}
    for name, noise in (("clean", "0"), ("noisy", "0.1")):
        prefix = tmp_path / name
        r = subprocess.run([str(make_scan), "--shape", "disk", "--triangles", "20000", "--noise", noise,
                            "--out", str(prefix)], capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, r.stderr
        P = scan_positions(f"{prefix}.ply")

        def ring(x0, r0, n):  # n picks on a ring of radius r0 around (x0, 0); the disk has radius 12
            return ",".join(str(min(range(len(P)), key=lambda v: (P[v][0] - x0 - r0 * math.cos(2 * math.pi * k / n)) ** 2
                                    + (P[v][1] - r0 * math.sin(2 * math.pi * k / n)) ** 2)) for k in range(n))

        out = tmp_path / f"{name}.json"
        picks = ring(19.2, 1.8, 5) if name == "clean" else ring(22.8, 7.2, 6)
        results[name] = run(cli, "segment", f"{prefix}.ply", "--picks", picks, "--step-height", "1", "--quiet",
                            "--out", out), out
    # A tight cluster beside the relief: the snake finds nothing, and the error says why.
    line = assert_one_error_line(results["clean"][0], 1)
    assert "nothing the picks enclose rises half a step" in line and "all around the relief" in line, line
    # A ring beside it on a noisy scan: the snake settles on the noise; doubtful (exit 3) with the reason.
    r, out = results["noisy"]
    assert r.returncode == 3, r.stderr
    doc = json.loads(out.read_text())
    assert doc["status"] == "doubtful"
    assert any("nothing the picks enclose rises half a step" in reason for reason in doc["reasons"]), doc["reasons"]
    assert doc["checks"]["enclosed_risen_area"] == 0.0


ADVANCED_OPTIONS = ["tau", "epsilon", "q_samples", "exact_q", "max_turn_degrees", "lock_interval",
                    "feature_contrast", "scale_feature_with_spacing", "convex_barrier", "remove_loops",
                    "nearest_resampling", "neighbourhood", "plane_fit", "planarity_one_ring", "threads"]


def test_help_lists_the_advanced_options(cli):
    r = run(cli, "--help")
    assert r.returncode == 0
    assert "--option NAME=VALUE" in r.stdout
    for name in ADVANCED_OPTIONS:
        assert f"\n  {name} " in r.stdout, name


@pytest.mark.parametrize(
    "option, words",
    [
        ("bogus=1", ["'bogus'", "valid names", *ADVANCED_OPTIONS]),
        ("remove_loops", ["NAME=VALUE", "valid names", "tau"]),
        ("=1", ["NAME=VALUE", "valid names"]),
        ("tau=abc", ["tau", "'abc'"]),
        ("tau=1.5", ["tau", "(0, 1)", "'1.5'"]),
        ("epsilon=-0.1", ["epsilon", "[0, 1)"]),
        ("q_samples=2.5", ["q_samples", "whole number"]),
        ("q_samples=0", ["q_samples", "from 1 to 64"]),
        ("q_samples=65", ["q_samples", "from 1 to 64"]),
        ("lock_interval=x", ["lock_interval"]),
        ("max_turn_degrees=181", ["max_turn_degrees", "(0, 180]"]),
        ("feature_contrast=0", ["feature_contrast", "> 0"]),
        ("remove_loops=maybe", ["remove_loops", "0, 1, true or false", "'maybe'"]),
        ("convex_barrier=", ["convex_barrier"]),
        ("neighbourhood=manhattan", ["neighbourhood", "geodesic, euclidean or sphere", "'manhattan'"]),
        ("plane_fit=faces", ["plane_fit", "vertices, vertex_areas or area", "'faces'"]),
        ("planarity_one_ring=2", ["planarity_one_ring"]),
        ("threads=-1", ["threads", ">= 0"]),
    ],
)
def test_bad_advanced_option_is_a_usage_error(cli, grid_obj, option, words):
    # Rejected while parsing the command line: before the mesh is read (exit 2, one line).
    line = assert_one_error_line(run(cli, "segment", grid_obj, "--picks", "0,1,4", "--step-height", "1",
                                     "--option", option), 2)
    for w in words:
        assert w in line, line


def test_advanced_options_reach_the_engine_and_the_report(cli, build_dir, tmp_path):
    make_scan = build_dir / "make-scan"
    if not make_scan.is_file():
        pytest.fail(f"{make_scan} not found: build the make-scan target")
    prefix = tmp_path / "disk"
    r = subprocess.run([str(make_scan), "--shape", "disk", "--triangles", "20000", "--step", "blended",
                        "--out", str(prefix)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    truth = json.loads(Path(f"{prefix}.truth.json").read_text())
    picks = ",".join(str(p) for p in truth["picks"])

    # Defaults: every advanced option is reported under "parameters".
    out = tmp_path / "default.json"
    r = run(cli, "segment", f"{prefix}.ply", "--picks", picks, "--step-height", truth["h"], "--out", out, "--quiet",
            timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    params = json.loads(out.read_text())["parameters"]
    assert params["tau"] == 0.2 and params["epsilon"] == 0.2 and params["q_samples"] == 5
    assert params["max_turn_degrees"] == 160 and params["lock_interval"] == 10
    assert params["feature_contrast"] == 0.25
    assert params["scale_feature_with_spacing"] is True and params["convex_barrier"] is False
    assert params["remove_loops"] is True
    assert params["neighbourhood"] == "sphere" and params["plane_fit"] == "vertex_areas" and params["planarity_one_ring"] is True and params["threads"] == 0

    # Set: repeated --option, both spellings, the last one of a name wins. (The iteration cap only
    # bounds the run time; whether these values segment well is the benchmark's business.)
    out = tmp_path / "set.json"
    r = run(cli, "segment", f"{prefix}.ply", "--picks", picks, "--step-height", truth["h"], "--out", out, "--quiet",
            "--max-iterations", "300",
            "--option", "remove_loops=0", "--option", "remove_loops=1", "--option=tau=0.25",
            "--option", "q_samples=7", "--option", "lock_interval=12", "--option", "convex_barrier=true",
            "--option", "epsilon=0.15", "--option", "max_turn_degrees=150", "--option", "feature_contrast=0.3",
            "--option", "scale_feature_with_spacing=true", "--option", "neighbourhood=euclidean",
            "--option", "threads=1", timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    result = json.loads(out.read_text())
    params = result["parameters"]
    assert params["remove_loops"] is True and params["convex_barrier"] is True
    assert params["tau"] == 0.25 and params["q_samples"] == 7 and params["lock_interval"] == 12
    assert params["epsilon"] == 0.15 and params["max_turn_degrees"] == 150 and params["feature_contrast"] == 0.3
    assert params["neighbourhood"] == "euclidean" and params["threads"] == 1
    assert result["status"] in ("converged", "iteration_cap")
    assert result["relief_vertices"]

    # Booleans switched off, 0/false spellings (a few iterations: this combination need not settle).
    out = tmp_path / "off.json"
    r = run(cli, "segment", f"{prefix}.ply", "--picks", picks, "--step-height", truth["h"], "--out", out, "--quiet",
            "--max-iterations", "20", "--option", "remove_loops=false", "--option", "scale_feature_with_spacing=0",
            "--option", "planarity_one_ring=0",
            timeout=300)
    # 20 iterations stop at the cap: the result is written, with exit code 3 and the reason.
    assert r.returncode == 3, r.stderr[-2000:]
    off = json.loads(out.read_text())
    assert off["status"] == "iteration_cap" and "iteration cap" in off["message"]
    params = off["parameters"]
    assert params["remove_loops"] is False and params["scale_feature_with_spacing"] is False
    assert params["planarity_one_ring"] is False
