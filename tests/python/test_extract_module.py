"""relief_snake_core.extract(): the extraction through the Python module."""
import array
import json
import struct
import subprocess
import sys
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def core(build_dir):
    sys.path.insert(0, str(build_dir))
    try:
        import relief_snake_core
    except ImportError as exc:
        pytest.fail(f"relief_snake_core not importable from {build_dir}: {exc}")
    return relief_snake_core


def grid(n=21, size=10.0, bump=None):
    """An n x n grid on z = 0; bump(i, j) -> z for raised vertices."""
    V, F = [], []
    for j in range(n):
        for i in range(n):
            V += [size * i / (n - 1), size * j / (n - 1), bump(i, j) if bump else 0.0]
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            F += [a, a + 1, a + n + 1, a, a + n + 1, a + n]
    return V, F


def test_a_raised_square_comes_off_a_plane(core):
    n = 31
    raised = lambda i, j: 10 <= i <= 20 and 10 <= j <= 20
    V, F = grid(n, 15.0, lambda i, j: 0.5 if raised(i, j) else 0.0)
    relief = [j * n + i for j in range(n) for i in range(n) if raised(i, j)]
    out = core.extract(array.array("d", V), array.array("i", F), relief, 0.5)
    assert out["model"] == "height_field"
    assert out["height_map"]["frame"]["flattening"] == "plane"
    base = out["base_positions"]
    assert len(base) == len(V)
    for k in range(n * n):
        if k in relief:
            assert base[3 * k + 2] == pytest.approx(0.0, abs=1e-9)
            assert out["heights"][k] == pytest.approx(0.5, abs=1e-9)
        else:
            assert base[3 * k:3 * k + 3] == V[3 * k:3 * k + 3]
    m = out["height_map"]
    values = struct.unpack("<%df" % (m["width"] * m["height"]), m["values"])
    inside = [v for v, a in zip(values, m["mask"]) if a]
    assert len(inside) > 100 and max(inside) == pytest.approx(0.5, abs=1e-6)
    r = out["relief"]
    assert len(r["uv"]) == 2 * len(r["vertices"]) and len(r["triangles"]) % 3 == 0
    assert set(relief) <= set(r["vertices"])


def test_errors_raise_the_engine_error(core):
    V, F = grid()
    with pytest.raises(core.Error, match="empty"):
        core.extract(V, F, [], 1.0)
    with pytest.raises(core.Error, match="no background"):
        core.extract(V, F, list(range(len(V) // 3)), 1.0)
    with pytest.raises(core.Error, match="out of range"):
        core.extract(V, F, [5, 10 ** 6], 1.0)
    with pytest.raises(core.Error, match="flattening"):
        core.extract(V, F, [220], 1.0, flatten="cube")
