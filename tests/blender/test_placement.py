"""The placement math of Apply (addon/relief_snake/placement.py), in plain Python."""

import math
import unittest

import _addon_path  # noqa: F401  (puts addon/relief_snake/ on sys.path)
import placement  # noqa: E402  (bpy-free module, imported standalone on purpose)


def close(a, b, tol=1e-9):
    return all(abs(x - y) <= tol for x, y in zip(a, b))


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


class RayToLocal(unittest.TestCase):
    def test_translated_scaled_rotated_object(self):
        # world = T(1, 2, 3) Rz(90) S(2): local (x, y, z) -> world (1 - 2y, 2 + 2x, 3 + 2z)
        world = [[0, -2, 0, 1], [2, 0, 0, 2], [0, 0, 2, 3], [0, 0, 0, 1]]
        inverse = [[0, 0.5, 0, -1], [-0.5, 0, 0, 0.5], [0, 0, 0.5, -1.5], [0, 0, 0, 1]]
        origin, direction = placement.ray_to_local(inverse, (1, 2, 13), (0, 0, -1))
        self.assertTrue(close(origin, (0, 0, 5)))
        self.assertTrue(close(direction, (0, 0, -0.5)))
        # the same ray parameter reaches the same point in both spaces
        t = 4.0
        local = tuple(o + t * d for o, d in zip(origin, direction))
        self.assertTrue(close(placement.transform_point(world, local), (1, 2, 13 - t)))

    def test_nearest_hit_ignores_hits_behind_and_misses(self):
        self.assertEqual(placement.nearest_hit([(5.0, "far"), None, (-1.0, "behind"), (2.0, "near")]),
                         (2.0, "near"))
        self.assertIsNone(placement.nearest_hit([None, (-0.5, "behind")]))


class TangentFrame(unittest.TestCase):
    def check_frame(self, n, u, v):
        n = tuple(c / math.sqrt(dot(n, n)) for c in n)
        for a in (u, v):
            self.assertAlmostEqual(dot(a, a), 1.0, places=12)
            self.assertAlmostEqual(dot(a, n), 0.0, places=12)
        self.assertAlmostEqual(dot(u, v), 0.0, places=12)
        cross = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
        self.assertTrue(close(cross, n, 1e-12))  # right-handed: u x v = n

    def test_up_normal_is_the_world_axes(self):
        u, v = placement.tangent_frame((0, 0, 1))
        self.assertTrue(close(u, (1, 0, 0)))
        self.assertTrue(close(v, (0, 1, 0)))

    def test_quarter_turn_is_counter_clockwise_seen_from_outside(self):
        u, v = placement.tangent_frame((0, 0, 1), math.pi / 2)
        self.assertTrue(close(u, (0, 1, 0)))
        self.assertTrue(close(v, (-1, 0, 0)))

    def test_frames_are_orthonormal_for_any_normal(self):
        for n in ((1, 0, 0), (0.95, 0.1, 0.2), (0, -1, 0), (1, 2, 3), (-0.3, 0.2, -5)):
            for angle in (0.0, 0.7, -2.0):
                self.check_frame(n, *placement.tangent_frame(n, angle))

    def test_zero_normal_is_refused(self):
        with self.assertRaises(ValueError):
            placement.tangent_frame((0, 0, 0))


if __name__ == "__main__":
    unittest.main()
