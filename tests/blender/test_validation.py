"""bpy-free tests of addon/relief_snake/validation.py (plain Python: pytest, and inside the Blenders)."""

import unittest

import _addon_path  # noqa: F401
import validation  # noqa: E402


class EngineArguments(unittest.TestCase):
    def test_valid_settings_become_engine_arguments(self):
        h, kw = validation.engine_arguments(4, 1.5, 0.3, False, 'RIGHT')
        self.assertEqual(h, 1.5)
        self.assertEqual(kw, {"w_int": 0.3, "open_contour": False, "relief_side": "right"})
        self.assertTrue(validation.engine_arguments(2, 1.0, open_contour=True)[1]["open_contour"])
        # The side is the engine's to decide unless the artist names it.
        self.assertEqual(validation.engine_arguments(2, 1.0, open_contour=True)[1]["relief_side"], "auto")

    def test_auto_smoothness_and_estimated_step_height_pass_none(self):
        h, kw = validation.engine_arguments(3, None, None)
        self.assertIsNone(h)
        self.assertIsNone(kw["w_int"])

    def test_bad_settings_say_what_to_do(self):
        for args, words in [((2, 1.0), "at least 3"), ((0, 1.0), "at least 3"), ((3, 0.0), "Step height"),
                            ((3, -1.0), "Step height"), ((3, float("nan")), "Step height"),
                            ((3, float("inf")), "Step height"), ((3, 1.0, 0.0), "Smoothness"),
                            ((3, 1.0, 1.5), "Smoothness")]:
            with self.assertRaises(ValueError) as ctx:
                validation.engine_arguments(*args)
            self.assertIn(words, str(ctx.exception))
        with self.assertRaises(ValueError):
            validation.engine_arguments(1, 1.0, open_contour=True)
        with self.assertRaises(ValueError):
            validation.engine_arguments(3, 1.0, relief_side="up")


if __name__ == "__main__":
    unittest.main()
