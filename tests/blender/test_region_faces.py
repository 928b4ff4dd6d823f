"""bpy-free tests of addon/relief_snake/region_faces.py (the triangles the viewport tints)."""

import random
import unittest
from array import array

import _addon_path  # noqa: F401  (puts addon/relief_snake/ on sys.path)
import region_faces  # noqa: E402  (bpy-free module, imported standalone on purpose)


def grid(n):
    """A triangulated n x n vertex grid: flat triangle buffer."""
    tris = array('i')
    for i in range(n - 1):
        for j in range(n - 1):
            a, b, c, d = i * n + j, i * n + j + 1, (i + 1) * n + j, (i + 1) * n + j + 1
            tris.extend((a, b, d, a, d, c))
    return tris


class RegionTriangles(unittest.TestCase):
    def test_only_triangles_with_three_relief_corners(self):
        n = 6
        tris = grid(n)
        relief = [i * n + j for i in range(1, 4) for j in range(1, 4)]  # a 3 x 3 block of vertices
        used, local = region_faces.region_triangles(tris, relief, n * n)
        self.assertEqual(len(local), 2 * 2 * 2)  # the block spans 2 x 2 quads
        self.assertEqual(used, sorted(relief))
        for t in local:
            self.assertTrue(all(used[k] in relief for k in t))

    def test_matches_a_plain_loop_on_a_random_region(self):
        n = 40
        tris = grid(n)
        rng = random.Random(5)
        relief = [v for v in range(n * n) if rng.random() < 0.6]
        used, local = region_faces.region_triangles(tris, relief, n * n)
        members = set(relief)
        expected = [tuple(tris[3 * t:3 * t + 3]) for t in range(len(tris) // 3)
                    if all(v in members for v in tris[3 * t:3 * t + 3])]
        self.assertEqual([tuple(used[k] for k in t) for t in local], expected)
        self.assertEqual(used, sorted({v for t in expected for v in t}))

    def test_no_region_triangle(self):
        tris = grid(4)
        self.assertEqual(region_faces.region_triangles(tris, [0, 5], 16), ([], []))  # a lone edge only
        self.assertEqual(region_faces.region_triangles(array('i'), [], 0), ([], []))


if __name__ == "__main__":
    unittest.main()
