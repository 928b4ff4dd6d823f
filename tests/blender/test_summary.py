"""bpy-free tests of addon/relief_snake/summary.py: plain words, and the engine's doubts shown."""

import unittest

import _addon_path  # noqa: F401
import summary  # noqa: E402

RESULT = {"status": "converged", "closed": True, "contour": [(0, 0, 0)] * 5, "relief_vertices": [1, 2, 3],
          "step_height": {"used": 1.0, "given": 1.0, "estimate": None, "confidence": 1.0},
          "phases": [{"name": "coarse", "iterations": 131, "snaxels": 175, "seconds": 21.04, "converged": True},
                     {"name": "refine", "iterations": 3000, "snaxels": 900, "seconds": 60.0, "converged": False}],
          "timing": {"load_seconds": 0.2, "segment_seconds": 2.5, "read": 0.1, "write": 0.02, "engine": 2.3}}


class Summaries(unittest.TestCase):
    def test_plain_words(self):
        s = summary.result_summary(RESULT)
        self.assertEqual(s, "Done: closed outline of 5 points, 3 relief vertices, 2.5 s")
        self.assertNotIn("snaxel", " ".join(summary.phase_lines(RESULT)))
        self.assertEqual(summary.phase_lines(RESULT),
                         ["Coarse pass: 131 steps, 175 points, 21.04 s",
                          "Refining: 3000 steps, 900 points, 60.00 s (step limit)"])
        self.assertEqual(summary.timing_line(dict(RESULT, mesh_cached=True)),
                         "Blender data 0.12 s (read 0.10, write 0.02), engine 2.30 s (mesh reused)")

    def test_holes_and_bands_are_counted(self):
        self.assertEqual(summary.result_summary(dict(RESULT, holes=[[(0, 0, 0)] * 3] * 2)),
                         "Done: closed (2 holes) outline of 5 points, 3 relief vertices, 2.5 s")
        self.assertEqual(summary.result_summary(dict(RESULT, holes=[[(0, 0, 0)] * 3])),
                         "Done: closed (1 hole) outline of 5 points, 3 relief vertices, 2.5 s")
        self.assertEqual(summary.result_summary(dict(RESULT, band=True, band_contour=[(0, 0, 0)] * 4)),
                         "Done: band with two outlines of 5 points, 3 relief vertices, 2.5 s")

    def test_open_outlines_name_the_relief_side(self):
        # The side used (given, or decided by the engine) is part of the answer for an open outline.
        self.assertEqual(summary.result_summary(dict(RESULT, closed=False, relief_side="right")),
                         "Done: open outline of 5 points (relief right of the picks), 3 relief vertices, 2.5 s")
        self.assertEqual(summary.result_summary(dict(RESULT, relief_side="left")),
                         "Done: closed outline of 5 points, 3 relief vertices, 2.5 s")

    def test_converged_has_no_warning(self):
        self.assertIsNone(summary.status_warning(RESULT))

    def test_doubtful_shows_the_engines_message_and_reasons(self):
        r = dict(RESULT, status="doubtful", message="The outline may have leaked into the background",
                 reasons=["the region touches the mesh border", "h looks too small"])
        w = summary.status_warning(r)
        self.assertIn("may have leaked", w)
        self.assertIn("touches the mesh border; h looks too small", w)
        self.assertIn("done, but doubtful", summary.result_summary(r).lower())

    def test_iteration_cap_without_message_still_warns(self):
        self.assertIn("step limit", summary.status_warning(dict(RESULT, status="iteration_cap")))

    def test_estimated_step_height_line(self):
        r = dict(RESULT, step_height={"used": 0.8125, "given": None, "estimate": 0.79, "confidence": 0.9})
        self.assertEqual(summary.step_height_line(r, lambda v: "%.3f m" % v),
                         "Estimated step height: 0.812 m (confidence 0.90)")
        self.assertIsNone(summary.step_height_line(RESULT))

    def test_step_measured_at_the_edge(self):
        fmt = lambda v: "%.2f m" % v
        # Estimated: the edge's step is named when it differs from the h the outline was made with.
        r = dict(RESULT, step_height={"used": 0.70, "given": None, "estimate": 0.6, "confidence": 0.9, "measured": 0.81})
        self.assertEqual(summary.step_height_line(r, fmt),
                         "Estimated step height: 0.81 m at the outline's edge, outlined with h = 0.70 m (confidence 0.90)")
        r = dict(RESULT, step_height={"used": 0.80, "given": None, "estimate": 0.6, "confidence": 0.9, "measured": 0.81})
        self.assertEqual(summary.step_height_line(r, fmt), "Estimated step height: 0.80 m (confidence 0.90)")
        # Typed: a line only when the edge's step is far from it.
        r = dict(RESULT, step_height={"used": 1.0, "given": 1.0, "estimate": None, "confidence": 1.0, "measured": 1.2})
        self.assertIsNone(summary.step_height_line(r, fmt))
        r = dict(RESULT, step_height={"used": 1.0, "given": 1.0, "estimate": None, "confidence": 1.0, "measured": 1.6})
        self.assertEqual(summary.step_height_line(r, fmt),
                         "The step at the outline's edge measures 1.60 m, against the h typed (1.00 m)")
        # An engine without the measurement, or none taken.
        r = dict(RESULT, step_height={"used": 1.0, "given": None, "estimate": 1.0, "confidence": 0.5, "measured": None})
        self.assertEqual(summary.step_height_line(r, fmt), "Estimated step height: 1.00 m (confidence 0.50)")


if __name__ == "__main__":
    unittest.main()
