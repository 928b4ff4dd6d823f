"""bpy-free tests of addon/relief_snake/pick_order.py (plain Python: pytest, and inside both Blenders)."""

import math
import os
import random
import sys
import unittest

_ADDON = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "addon", "relief_snake")
sys.path.insert(0, os.path.normpath(_ADDON))
import pick_order as ordering  # noqa: E402  (bpy-free module, imported standalone on purpose)


def _ring(k, radius=1.0, tilt=0.0, centre=(0.3, -0.2, 0.5)):
    """k points counter-clockwise around z (optionally tilted about x), with their normals."""
    pts, nors = [], []
    c, s = math.cos(tilt), math.sin(tilt)
    for i in range(k):
        a = 2 * math.pi * i / k
        x, y = radius * math.cos(a), radius * (0.6 + 0.4 * (i % 2)) * math.sin(a)
        pts.append((centre[0] + x, centre[1] + c * y, centre[2] + s * y))
        nors.append((0.0, -s, c))
    return pts, nors


def _is_cyclic_rotation(a, b):
    if len(a) != len(b):
        return False
    i = b.index(a[0])
    return b[i:] + b[:i] == a


class OrderByAngle(unittest.TestCase):
    def test_shuffled_ring_comes_back_counter_clockwise(self):
        pts, nors = _ring(9)
        idx = list(range(100, 109))
        perm = idx[:]
        random.Random(4).shuffle(perm)
        out = ordering.order_by_angle(perm, [pts[i - 100] for i in perm], [nors[i - 100] for i in perm])
        self.assertEqual(out[0], perm[0])  # starts at the first given
        self.assertTrue(_is_cyclic_rotation(out, idx), out)

    def test_flipped_normal_reverses_the_turning_sense(self):
        pts, nors = _ring(7)
        flipped = [(-n[0], -n[1], -n[2]) for n in nors]
        out = ordering.order_by_angle(list(range(7)), pts, flipped)
        self.assertTrue(_is_cyclic_rotation(out, [0, 6, 5, 4, 3, 2, 1]), out)

    def test_tilted_plane_uses_the_average_normal(self):
        pts, nors = _ring(8, tilt=1.2)
        perm = [3, 0, 6, 1, 7, 2, 5, 4]
        out = ordering.order_by_angle(perm, [pts[i] for i in perm], [nors[i] for i in perm])
        self.assertTrue(_is_cyclic_rotation(out, list(range(8))), out)

    def test_without_normals_the_fitted_plane_still_gives_a_ring(self):
        pts, _ = _ring(6, tilt=0.5)
        perm = [0, 3, 1, 5, 2, 4]
        out = ordering.order_by_angle(perm, [pts[i] for i in perm], None)
        fwd, back = list(range(6)), [0, 5, 4, 3, 2, 1]
        self.assertTrue(_is_cyclic_rotation(out, fwd) or _is_cyclic_rotation(out, back), out)

    def test_mismatched_lengths_raise(self):
        with self.assertRaises(ValueError):
            ordering.order_by_angle([1, 2, 3], [(0, 0, 0)], None)


class OrderPicks(unittest.TestCase):
    def setUp(self):
        pts, nors = _ring(6)
        self.pos = {10 + i: p for i, p in enumerate(pts)}
        self.nor = {10 + i: n for i, n in enumerate(nors)}

    def test_full_click_order_is_kept_even_if_not_angular(self):
        history = [12, 10, 15, 11, 14, 13]
        picks, info = ordering.order_picks(sorted(history), history, self.pos, self.nor)
        self.assertEqual(picks, history)
        self.assertIsNone(info)

    def test_partial_history_falls_back_to_angle_and_says_so(self):
        picks, info = ordering.order_picks([13, 10, 11, 12, 14, 15], [12, 10], self.pos, self.nor)
        self.assertTrue(_is_cyclic_rotation(picks, [10, 11, 12, 13, 14, 15]), picks)
        self.assertIn("2 of 6", info)
        self.assertIn("angle", info)

    def test_missing_history_falls_back(self):
        picks, info = ordering.order_picks([15, 11, 13, 10, 12, 14], [], self.pos, self.nor)
        self.assertTrue(_is_cyclic_rotation(picks, [10, 11, 12, 13, 14, 15]), picks)
        self.assertIn("no click order", info)

    def test_history_entries_not_selected_are_ignored(self):
        picks, info = ordering.order_picks([10, 11, 12], [99, 12, 11, 10, 12], self.pos, self.nor)
        self.assertEqual(picks, [12, 11, 10])
        self.assertIsNone(info)


class Distance(unittest.TestCase):
    def test_distance(self):
        self.assertAlmostEqual(ordering.distance((0, 0, 0), (3, 4, 12)), 13.0)


if __name__ == "__main__":
    unittest.main()
