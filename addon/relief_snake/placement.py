"""Where an applied relief goes, without bpy: the ray of a click in the target's own coordinates,
the nearest of its hits, and the tangent frame at the placement point turned by the user's rotation.

    origin, direction = ray_to_local(inverse_world, world_origin, world_direction)
    u_axis, v_axis = tangent_frame(normal, rotation)

Vectors are (x, y, z) tuples; matrices are 4x4 row lists (as tuple(map(tuple, matrix)) gives
them). extraction.apply_relief and the Apply operator's click placement use it; plain Python
tests it (tests/blender/test_placement.py).
"""

import math

__all__ = ["transform_point", "transform_direction", "ray_to_local", "nearest_hit", "tangent_frame"]


def transform_point(matrix, p):
    """matrix (4x4 rows, affine) applied to the point p."""
    return tuple(sum(matrix[r][c] * p[c] for c in range(3)) + matrix[r][3] for r in range(3))


def transform_direction(matrix, d):
    """matrix's linear part applied to the direction d (no translation)."""
    return tuple(sum(matrix[r][c] * d[c] for c in range(3)) for r in range(3))


def ray_to_local(inverse, origin, direction):
    """A world ray (origin, direction) in the coordinates of an object whose inverted world matrix
    is `inverse`. The direction is not normalised: a point at ray parameter t is the same point
    in both spaces, so hit distances along the ray compare across objects."""
    return transform_point(inverse, origin), transform_direction(inverse, direction)


def nearest_hit(hits):
    """The hit with the smallest ray parameter among (t, payload) pairs with t >= 0; None if none."""
    ahead = [h for h in hits if h is not None and h[0] >= 0]
    return min(ahead, key=lambda h: h[0]) if ahead else None


def _normalised(v):
    length = math.sqrt(sum(c * c for c in v))
    if not length > 0:
        raise ValueError("zero-length vector")
    return tuple(c / length for c in v)


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def tangent_frame(normal, rotation=0.0):
    """(u_axis, v_axis): unit tangents at a surface point with outward `normal`, so that
    (u_axis, v_axis, normal) is right-handed. Unturned, u_axis is the world X axis projected onto
    the tangent plane (the Y axis where the normal lies within 26 degrees of X); `rotation`
    (radians) turns both counter-clockwise about the normal, seen from outside."""
    n = _normalised(normal)
    ref = (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 1.0, 0.0)
    k = _dot(ref, n)
    t = _normalised(tuple(r - k * c for r, c in zip(ref, n)))
    b = _cross(n, t)
    c, s = math.cos(rotation), math.sin(rotation)
    u = tuple(c * x + s * y for x, y in zip(t, b))
    return u, _cross(n, u)
