#!/usr/bin/env python3
"""atheris harness for the module's argument handling (issue 11): arbitrary Python values as
vertices, triangles, picks and keywords. Anything but the module's documented errors
(relief_snake_core.Error and its InputTypeError, TypeError, ValueError, RuntimeError from a
re-entrant call, Cancelled) is a finding; so is a crash.

    RELIEF_SNAKE_BUILD_DIR=build python3 fuzz/atheris_module.py -max_total_time=60
"""
import array
import os
import sys

import atheris

BUILD_DIR = os.environ.get("RELIEF_SNAKE_BUILD_DIR", os.path.join(os.path.dirname(__file__), "..", "build"))
sys.path.insert(0, os.path.abspath(BUILD_DIR))

with atheris.instrument_imports():
    pass
import relief_snake_core as core  # noqa: E402  (native: not instrumented, crashes still count)

try:
    import numpy as np
except ImportError:
    np = None

EXPECTED = (core.Error, TypeError, ValueError, RuntimeError, core.Cancelled, OverflowError)


class Seq:
    """A custom sequence whose items are made on access."""

    def __init__(self, items):
        self.items = items

    def __len__(self):
        return len(self.items)

    def __getitem__(self, i):
        return self.items[i]


def number(fdp):
    kind = fdp.ConsumeIntInRange(0, 7)
    if kind == 0:
        return fdp.ConsumeIntInRange(-3, 40)
    if kind == 1:
        return fdp.ConsumeFloat()
    if kind == 2:
        return fdp.ConsumeInt(9)  # up to 2^72
    if kind == 3:
        return fdp.ConsumeUnicode(3)
    if kind == 4:
        return None
    if kind == 5:
        return bool(fdp.ConsumeBool())
    if kind == 6:
        return float(fdp.ConsumeIntInRange(0, 5))
    return fdp.ConsumeIntInRange(0, 8)


def array_like(fdp, depth=0):
    n = fdp.ConsumeIntInRange(0, 12)
    kind = fdp.ConsumeIntInRange(0, 6 if np is not None else 5)
    if kind == 0:  # rows of 3 (or not)
        return [tuple(number(fdp) for _ in range(fdp.ConsumeIntInRange(2, 4))) for _ in range(n)]
    if kind == 1:  # flat
        return [number(fdp) for _ in range(n)]
    if kind == 2:  # array.array of a random type code
        code = "bBhHiIlLqQfd"[fdp.ConsumeIntInRange(0, 11)]
        values = [fdp.ConsumeIntInRange(0, 30) for _ in range(3 * n)]
        return array.array(code, values)
    if kind == 3:  # memoryview, possibly cast
        a = array.array("d", [fdp.ConsumeFloat() for _ in range(3 * n)])
        m = memoryview(a)
        return m.cast("B").cast("d", [n, 3]) if n and fdp.ConsumeBool() else m
    if kind == 4:  # custom sequences of custom rows
        return Seq([Seq([number(fdp) for _ in range(3)]) for _ in range(n)])
    if kind == 5:
        return [range(fdp.ConsumeIntInRange(0, 5)) for _ in range(n)] if depth == 0 else fdp.ConsumeBytes(8)
    dtype = ["float32", "float64", "int32", "int64", "uint32", "float16", ">f8", "int8"][fdp.ConsumeIntInRange(0, 7)]
    a = np.array([[fdp.ConsumeIntInRange(0, 20) for _ in range(3)] for _ in range(max(n, 1))], dtype=dtype)
    view = [a, a.T, a[::-1], a[:, ::2], np.asfortranarray(a), list(a)][fdp.ConsumeIntInRange(0, 5)]
    return view


def test_one(data):
    fdp = atheris.FuzzedDataProvider(data)
    vertices, triangles = array_like(fdp), array_like(fdp)
    partial = fdp.ConsumeBool()
    try:
        which = fdp.ConsumeIntInRange(0, 3)
        if which == 0:
            core.mesh_report(vertices, triangles, allow_partial=partial)
        elif which == 1:
            core.measure(vertices, fdp.ConsumeIntInRange(-2, 10), fdp.ConsumeIntInRange(-2, 10))
        else:
            mesh = core.Mesh(vertices, triangles, allow_partial=partial)
            picks = array_like(fdp, 1)
            kwargs = {}
            if fdp.ConsumeBool():
                kwargs[["tau", "q_samples", "exact_q", "bogus", "threads"][fdp.ConsumeIntInRange(0, 4)]] = number(fdp)
            mesh.segment(picks, fdp.ConsumeFloat(), max_iterations=fdp.ConsumeIntInRange(-1, 5),
                         progress=(lambda *a: fdp.ConsumeBool()) if fdp.ConsumeBool() else None, **kwargs)
    except EXPECTED as e:
        message = str(e)
        if "\n" in message:
            raise AssertionError("multi-line error: %r" % message)


if __name__ == "__main__":
    atheris.Setup(sys.argv, test_one)
    atheris.Fuzz()
