"""DEVELOPMENT-ONLY stand-in for the native relief_snake_core, used by run_tests.py only when
RELIEF_SNAKE_FAKE_CORE=1 (before the engine landed). It is NOT a segmentation: it marks the
vertices higher than h/2 above z = 0 and returns the pick polygon as the contour, which is
enough to exercise the Blender plumbing on dev/make_disk_scan.py's flat disk scan."""

import math
import time

__version__ = "0.0-fake"


class Error(ValueError):
    pass


class Cancelled(Exception):
    pass


def _pt(v, i):
    return (float(v[3 * i]), float(v[3 * i + 1]), float(v[3 * i + 2]))


def segment(vertices, triangles, picks, step_height, *, w_int=0.25, open_contour=False,
            relief_side="left", max_iterations=3000, progress=None):
    t0 = time.perf_counter()
    nv = len(vertices) // 3
    if len(picks) < (2 if open_contour else 3):
        raise Error("need more picks")
    if not step_height > 0:
        raise Error("step height must be > 0")
    if any(not 0 <= p < nv for p in picks):
        raise Error("pick out of range")
    # Pick polygon pushed onto make_disk_scan.py's disk rim (r = 0.35), densified.
    contour = []
    for k in range(len(picks)):
        a, b = _pt(vertices, picks[k]), _pt(vertices, picks[(k + 1) % len(picks)])
        for t in (0.0, 0.5):
            x, y = a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])
            r = math.hypot(x, y) or 1.0
            contour.append((0.35 * x / r, 0.35 * y / r, 0.0))
    for it in range(3):
        if progress is not None and progress("coarse", it, len(contour), contour) is False:
            raise Cancelled("cancelled")
        time.sleep(0.01)
    relief = [i for i in range(nv) if vertices[3 * i + 2] > step_height / 2]
    return {"status": "converged", "closed": not open_contour, "contour": contour,
            "relief_vertices": relief,
            "phases": [{"name": "coarse", "iterations": 3, "snaxels": len(contour), "seconds": 0.03,
                        "converged": True}],
            "parameters": {"w_int": w_int}, "planarity_vertices": nv, "notes": [],
            "mesh_report": "fake", "seconds": time.perf_counter() - t0}


def measure(vertices, i, j):
    a, b = _pt(vertices, i), _pt(vertices, j)
    return math.dist(a, b)


def mesh_report(vertices, triangles):
    return "%d vertices, %d triangles (fake)" % (len(vertices) // 3, len(triangles) // 3)
