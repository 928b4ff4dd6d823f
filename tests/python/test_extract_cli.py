"""relief-snake extract and segment --extract, run as a user would: files, sidecar, errors."""
import json
import struct
import re
import subprocess
import zlib
from pathlib import Path

import pytest

FILES = ("background.ply", "relief.ply", "height.exr", "height.png", "height.json")


@pytest.fixture(scope="session")
def cli(build_dir):
    exe = build_dir / "relief-snake"
    if not exe.is_file():
        pytest.fail(f"{exe} not found: build the relief-snake target")
    return exe


@pytest.fixture(scope="session")
def scan(build_dir, tmp_path_factory):
    """A sharp duck on a cylinder (30k triangles) with its truth."""
    tool = build_dir / "make-scan"
    if not tool.is_file():
        pytest.fail(f"{tool} not found: build the make-scan target")
    prefix = tmp_path_factory.mktemp("scan") / "duck"
    subprocess.run([str(tool), "--background", "cylinder", "--triangles", "30000", "--seed", "2", "--out",
                    str(prefix)], check=True, capture_output=True)
    truth = json.loads(Path(str(prefix) + ".truth.json").read_text())
    return Path(str(prefix) + ".ply"), truth


def run(exe, *args, timeout=300):
    return subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True, timeout=timeout)


def read_ply(path):
    """Binary little-endian PLY as written by relief-snake: (positions, properties dict, faces)."""
    data = Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    assert header[1] == "format binary_little_endian 1.0"
    nv = nf = 0
    props, element = [], None
    for line in header:
        words = line.split()
        if words[:1] == ["element"]:
            element = words[1]
            if element == "vertex":
                nv = int(words[2])
            else:
                nf = int(words[2])
        elif words[:1] == ["property"] and element == "vertex":
            props.append((words[1], words[2]))
    fmt = "<" + "".join("d" if t == "double" else "f" for t, _ in props)
    size = struct.calcsize(fmt)
    rows = [struct.unpack_from(fmt, data, end + k * size) for k in range(nv)]
    names = [n for _, n in props]
    columns = {n: [r[i] for r in rows] for i, n in enumerate(names)}
    positions = list(zip(columns["x"], columns["y"], columns["z"]))
    offset = end + nv * size
    faces = []
    for _ in range(nf):
        count = data[offset]
        faces.append(struct.unpack_from("<%di" % count, data, offset + 1))
        offset += 1 + 4 * count
    return positions, columns, faces


def read_input_ply(path):
    """The scan (make-scan's binary PLY, float coordinates) as float positions."""
    data = Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    nv = next(int(l.split()[2]) for l in header if l.startswith("element vertex"))
    kinds = []
    in_vertex = False
    for l in header:
        if l.startswith("element"):
            in_vertex = l.startswith("element vertex")
        elif l.startswith("property") and in_vertex:
            kinds.append(l.split()[1])
    fmt = "<" + "".join({"float": "f", "double": "d", "float32": "f", "float64": "d"}[k] for k in kinds)
    size = struct.calcsize(fmt)
    return [struct.unpack_from(fmt, data, end + k * size)[:3] for k in range(nv)]


def read_png16(path):
    """A 16-bit grey + alpha PNG (no filters beyond the five standard ones): (width, height, grey, alpha)."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            assert (depth, colour) == (16, 4)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride, bpp = 4 * width, 4
    rows, prev = [], bytearray(stride)
    for j in range(height):
        kind = raw[j * (stride + 1)]
        line = bytearray(raw[j * (stride + 1) + 1:(j + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    grey = [struct.unpack_from(">H", r, 4 * i)[0] for r in rows for i in range(width)]
    alpha = [struct.unpack_from(">H", r, 4 * i + 2)[0] for r in rows for i in range(width)]
    return width, height, grey, alpha


@pytest.fixture(scope="session")
def extracted(cli, scan, tmp_path_factory):
    mesh, truth = scan
    out = tmp_path_factory.mktemp("extract") / "out"
    picks = ",".join(map(str, truth["picks"]))
    r = run(cli, "segment", mesh, "--picks", picks, "--step-height", truth["h"], "--quiet", "--extract", out)
    assert r.returncode == 0, r.stderr
    return mesh, truth, out, r


def test_segment_extract_writes_the_five_files_and_one_line(extracted):
    mesh, truth, out, r = extracted
    for name in FILES + ("result.json",):
        assert (out / name).is_file(), name
    assert not [p for p in out.iterdir() if "partial" in p.name]
    lines = r.stdout.splitlines()
    assert len(lines) == 1 and lines[0].startswith("relief-snake: extracted "), r.stdout


def test_background_ply_keeps_every_vertex_outside_the_relief(extracted):
    mesh, truth, out, _ = extracted
    result = json.loads((out / "result.json").read_text())
    relief = set(result["relief_vertices"])
    original = read_input_ply(mesh)
    positions, _, faces = read_ply(out / "background.ply")
    assert len(positions) == len(original) == truth["vertices"]
    assert len(faces) == truth["triangles"]
    outside_changed = sum(1 for i, (p, q) in enumerate(zip(positions, original)) if i not in relief and p != q)
    assert outside_changed == 0
    moved = sum(1 for i in relief if positions[i] != original[i])
    assert moved > 0.5 * len(relief)


def test_relief_ply_heights_and_sidecar(extracted):
    mesh, truth, out, _ = extracted
    _, columns, faces = read_ply(out / "relief.ply")
    assert {"height", "u", "v"} <= set(columns)
    heights = columns["height"]
    h = truth["h"]
    # The relief's top is at h (sharp step), its foot at 0.
    assert max(heights) == pytest.approx(h, abs=0.05 * h)
    assert min(heights) == pytest.approx(0, abs=0.05 * h)
    top = sorted(heights)[len(heights) // 2:]
    assert sum(abs(x - h) for x in top) / len(top) < 0.05 * h
    sidecar = json.loads((out / "height.json").read_text())
    assert sidecar["frame"]["flattening"] == "conformal"  # a cylinder is not gentle at this size
    assert sidecar["pixel_size"] > 0 and sidecar["width"] > 10 and sidecar["height"] > 10
    lo, hi = sidecar["height_range"]
    assert lo < 0.1 * h and hi == pytest.approx(h, abs=0.05 * h)


def test_png_reads_back_in_the_sidecars_scale(extracted):
    mesh, truth, out, _ = extracted
    sidecar = json.loads((out / "height.json").read_text())
    width, height, grey, alpha = read_png16(out / "height.png")
    assert (width, height) == (sidecar["width"], sidecar["height"])
    scale, offset = sidecar["png"]["scale"], sidecar["png"]["offset"]
    inside = [offset + g * scale for g, a in zip(grey, alpha) if a == 65535]
    assert len(inside) == sidecar["covered_pixels"]
    assert all(a in (0, 65535) for a in alpha)
    assert min(inside) == pytest.approx(sidecar["height_range"][0], abs=scale)
    assert max(inside) == pytest.approx(sidecar["height_range"][1], abs=scale)
    assert (out / "height.exr").read_bytes()[:4] == b"\x76\x2f\x31\x01"  # the OpenEXR magic number


def test_extract_from_a_result_file_with_options(cli, extracted, tmp_path):
    mesh, truth, out, _ = extracted
    r = run(cli, "extract", mesh, out / "result.json", "--out", tmp_path / "x", "--pixel-size", 0.5,
            "--flatten", "plane")
    assert r.returncode == 0, r.stderr
    sidecar = json.loads((tmp_path / "x" / "height.json").read_text())
    assert sidecar["pixel_size"] == 0.5
    assert sidecar["frame"]["flattening"] == "plane"


STAGES = ["read result", "load mesh", "weights", "ring", "assembly", "ordering", "factorisation", "solve",
          "height", "relief", "plane", "conformal assembly", "conformal ordering", "conformal factorisation",
          "conformal solve", "conformal distortion", "rasterise", "write"]


def test_extract_timings_prints_every_stage_once(cli, extracted, tmp_path):
    mesh, _, out, _ = extracted
    r = run(cli, "extract", mesh, out / "result.json", "--out", tmp_path / "t", "--flatten", "conformal", "--timings")
    assert r.returncode == 0, r.stderr
    lines = [l for l in r.stdout.splitlines() if l.startswith("relief-snake: timings: ")]
    assert len(lines) == 1, r.stdout
    found = re.findall(r"([a-z][a-z ]*?) ([0-9.]+) s", lines[0][len("relief-snake: timings: "):])
    assert [name for name, _ in found] == STAGES
    seconds = dict((name, float(value)) for name, value in found)
    # The conformal map was asked for, so its factorisation ran and took some time.
    assert seconds["conformal factorisation"] > 0 and seconds["factorisation"] > 0
    total = float(re.search(r"wrote .* in ([0-9.]+) s total", r.stdout).group(1))
    assert sum(seconds.values()) <= total + 0.01
    # Without the flag: the one summary line only.
    plain = run(cli, "extract", mesh, out / "result.json", "--out", tmp_path / "p", "--quiet")
    assert plain.returncode == 0 and "relief-snake: timings:" not in plain.stdout


def one_error_line(r, code):
    assert r.returncode == code, (r.returncode, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("relief-snake: "), r.stderr
    return lines[0]


def test_errors_are_one_line_and_write_nothing(cli, extracted, tmp_path):
    mesh, truth, out, _ = extracted
    result = json.loads((out / "result.json").read_text())

    def variant(name, **changes):
        path = tmp_path / name
        data = dict(result, **changes)
        path.write_text(json.dumps(data))
        return path

    target = tmp_path / "never"
    wrong_count = variant("count.json", mesh=dict(result["mesh"], input_vertices=result["mesh"]["input_vertices"] + 1))
    assert "vertices but this mesh has" in one_error_line(run(cli, "extract", mesh, wrong_count, "--out", target), 1)
    out_of_range = variant("range.json", relief_vertices=result["relief_vertices"] + [10 ** 7])
    assert "out of range" in one_error_line(run(cli, "extract", mesh, out_of_range, "--out", target), 1)
    empty = variant("empty.json", relief_vertices=[])
    assert "empty" in one_error_line(run(cli, "extract", mesh, empty, "--out", target), 1)
    everything = variant("all.json", relief_vertices=list(range(truth["vertices"])))
    assert "no background" in one_error_line(run(cli, "extract", mesh, everything, "--out", target), 1)
    assert not target.exists()
    # A result without the mesh's vertex count: checked against the mesh, and said so.
    no_count = tmp_path / "nocount.json"
    no_count.write_text(json.dumps({"relief_vertices": result["relief_vertices"], "parameters": {"step_height": 1}}))
    r = run(cli, "extract", mesh, no_count, "--out", tmp_path / "ok")
    assert r.returncode == 0, r.stderr
    assert "does not record its mesh's vertex count" in r.stderr
    # Usage errors: exit 2.
    one_error_line(run(cli, "extract", mesh, out / "result.json"), 2)
    one_error_line(run(cli, "extract", mesh, out / "result.json", "--out", target, "--flatten", "cube"), 2)
    one_error_line(run(cli, "extract", mesh, out / "result.json", "--out", target, "--pixel-size", "-1"), 2)
    one_error_line(run(cli, "extract", mesh, "--out", target), 2)
    assert not target.exists()


def test_segment_extract_with_several_pick_groups_is_refused_up_front(cli, scan, tmp_path):
    """--extract takes one relief; with two --picks it says so before segmenting anything."""
    mesh, truth = scan
    picks = ",".join(map(str, truth["picks"]))
    target = tmp_path / "two"
    line = one_error_line(run(cli, "segment", mesh, "--picks", picks, "--picks", picks, "--step-height", "1",
                              "--extract", target), 2)
    assert "one --picks" in line
    assert not target.exists()
