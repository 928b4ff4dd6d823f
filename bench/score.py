"""Scoring the suite's rows against the issue's targets."""
from __future__ import annotations

import math

from .cases import TARGET_IOU, TARGET_MEAN, TARGET_P95

def meets(row):
    s = row.get("score")
    if not row.get("ok") or not s:
        return False
    return (s["mean_to_truth"] <= TARGET_MEAN and s["mean_from_truth"] <= TARGET_MEAN and
            s["p95_to_truth"] <= TARGET_P95 and s["p95_from_truth"] <= TARGET_P95 and s["iou"] >= TARGET_IOU)



def tolerance_range(rows):
    """The contiguous range of sweep h factors around 1.0 where every accuracy target holds."""
    pts = sorted(rows, key=lambda r: r["x"])
    ok = [meets(r) for r in pts]
    idx = [i for i, r in enumerate(pts) if abs(r["x"] - 1.0) < 1e-9]
    if not idx or not ok[idx[0]]:
        return None
    lo = hi = idx[0]
    while lo > 0 and ok[lo - 1]:
        lo -= 1
    while hi + 1 < len(pts) and ok[hi + 1]:
        hi += 1
    return f"x{pts[lo]['x']:g} … x{pts[hi]['x']:g}"


def tol_ok(rows):
    pts = {round(r["x"], 6): meets(r) for r in rows}
    needed = [x for x in pts if 0.6 - 1e-9 <= x <= 1.4 + 1e-9]
    return bool(needed) and all(pts[x] for x in needed)


def growth_exponent(rows):
    import math
    pts = [(math.log(r["triangles"]), math.log(r["engine_seconds"])) for r in rows
           if r.get("engine_seconds") and r.get("triangles")]
    if len(pts) < 3:
        return None
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx if sxx > 0 else None


