"""bpy-free logic of the add-on: ordering picks, validating options, summarising results.

Nothing here imports bpy, so it is tested with plain Python (tests/blender/test_ordering.py)
as well as inside both Blenders.
"""

import math

__all__ = [
    "order_picks",
    "order_by_angle",
    "validate_options",
    "phase_summary",
    "result_summary",
    "timing_summary",
    "distance",
]


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


def validate_options(num_picks, step_height, w_int=0.25, open_contour=False, relief_side="LEFT"):
    """Check operator options before any work; returns the engine keyword arguments.

    Raises ValueError with a one-line message saying what to do.
    """
    need = 2 if open_contour else 3
    if num_picks < need:
        raise ValueError(
            "Select at least %d vertices around the relief (%s contour); %d selected"
            % (need, "an open" if open_contour else "a closed", num_picks))
    if not (step_height > 0 and math.isfinite(step_height)):
        raise ValueError("Step height must be > 0: set it in the Relief panel or measure it from two vertices")
    if not (0 < w_int <= 1):
        raise ValueError("W_int must be in (0, 1]; the paper uses 0.25")
    side = str(relief_side).lower()
    if side not in ("left", "right"):
        raise ValueError("Relief side must be LEFT or RIGHT")
    return {"w_int": float(w_int), "open_contour": bool(open_contour), "relief_side": side}


def phase_summary(result):
    """One line per phase: 'coarse: 131 it, 175 snaxels, 21.0 s'."""
    lines = []
    for p in result.get("phases", []):
        lines.append("%s: %d it, %d snaxels, %.2f s%s" % (
            p.get("name", "?"), int(p.get("iterations", 0)), int(p.get("snaxels", 0)),
            float(p.get("seconds", 0.0)), "" if p.get("converged", True) else " (cap)"))
    return lines


def result_summary(result):
    """A one-line report of a segmentation result dict (see relief_snake_core.segment)."""
    contour = result.get("contour", [])
    relief = result.get("relief_vertices", [])
    return "Relief Snake: %s, %d snaxels (%s), %d relief vertices, %.2f s" % (
        result.get("status", "?"), len(contour), "closed" if result.get("closed", True) else "open",
        len(relief), float(result.get("seconds", 0.0)))


def timing_summary(result):
    """'Blender data: read 0.12 s, write 0.03 s; engine 4.20 s' from result["timing"] (add-on side)."""
    t = result.get("timing", {})
    return "Blender data: read %.2f s, write %.2f s; engine %.2f s" % (
        float(t.get("read", 0.0)), float(t.get("write", 0.0)), float(t.get("engine", 0.0)))
