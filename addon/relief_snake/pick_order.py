"""The order of the picks: the click order Blender recorded, or, when it is missing or
partial, the angle around the picks' centroid. bpy-free (tests/blender/test_pick_order.py)."""

import math

__all__ = ["order_picks", "order_by_angle", "distance"]


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _norm(a):
    return math.sqrt(_dot(a, a))


def _unit(a):
    n = _norm(a)
    return (a[0] / n, a[1] / n, a[2] / n) if n > 0 else (0.0, 0.0, 0.0)


def distance(a, b):
    """Euclidean distance between two 3D points (x, y, z)."""
    return _norm(_sub(a, b))


def order_by_angle(indices, positions, normals=None):
    """Order vertex `indices` by angle around their centroid.

    indices: k vertex indices; positions: k (x, y, z) tuples, one per index;
    normals: k (x, y, z) tuples or None. The angle is measured in the plane of the
    average normal (falling back to the best-fit plane when normals are missing or
    cancel out), counter-clockwise seen from the side the normal points to, so a
    ring of picks around a bump comes out in the same turning sense as clicking
    it counter-clockwise from outside. Starts at the first index given, so the
    result is deterministic. Returns a new list.
    """
    k = len(indices)
    if k != len(positions):
        raise ValueError("order_by_angle: one position per index is needed")
    if k < 3:
        return list(indices)
    c = tuple(sum(p[i] for p in positions) / k for i in range(3))
    n = (0.0, 0.0, 0.0)
    if normals:
        n = _unit(tuple(sum(q[i] for q in normals) for i in range(3)))
    if _norm(n) == 0:
        n = _fit_plane_normal(positions, c)
    # An in-plane frame (u, v) with u . v = 0 and u x v = n.
    seed = (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 1.0, 0.0)
    u = _unit(_cross(n, seed))
    v = _cross(n, u)
    angles = []
    for idx, p in zip(indices, positions):
        d = _sub(p, c)
        angles.append((math.atan2(_dot(d, v), _dot(d, u)), idx))
    start = angles[0][0]
    # Rotate so the first given index stays first (stable start).
    angles.sort(key=lambda t: (t[0] - start) % (2 * math.pi))
    return [idx for _, idx in angles]


def _fit_plane_normal(positions, c):
    """Normal of the plane through `positions` (Newell's method on the given order,
    good enough for a roughly planar ring; z when degenerate)."""
    nx = ny = nz = 0.0
    k = len(positions)
    for i in range(k):
        a = _sub(positions[i], c)
        b = _sub(positions[(i + 1) % k], c)
        nx += (a[1] - b[1]) * (a[2] + b[2])
        ny += (a[2] - b[2]) * (a[0] + b[0])
        nz += (a[0] - b[0]) * (a[1] + b[1])
    n = _unit((nx, ny, nz))
    return n if _norm(n) > 0 else (0.0, 0.0, 1.0)


def order_picks(selected, history, positions, normals=None):
    """Decide the pick order from the selection.

    selected: indices of the selected vertices (any order);
    history: indices in click order (Blender's select history; may be partial or
    hold unselected/stale entries); positions/normals: dicts or sequences indexed
    by vertex index giving (x, y, z).
    Returns (picks, fallback_message): fallback_message is None when the click
    order covered every selected vertex, else a sentence for an INFO report.
    """
    selected = list(dict.fromkeys(selected))
    sel = set(selected)
    ordered = [i for i in dict.fromkeys(history) if i in sel]
    if len(ordered) == len(selected):
        return ordered, None
    pos = [positions[i] for i in selected]
    nor = [normals[i] for i in selected] if normals is not None else None
    picks = order_by_angle(selected, pos, nor)
    if ordered:
        why = "click order covers only %d of %d selected vertices" % (len(ordered), len(selected))
    else:
        why = "no click order recorded"
    return picks, ("Relief Snake: %s; ordered the %d picks by angle around their centroid"
                   % (why, len(selected)))
