"""Checks of the panel's settings before any work, in plain words, and their translation into
the engine's keyword arguments. bpy-free (tests/blender/test_validation.py).

The engine checks its input too (and has the last word); these checks only give the artist a
message that names the panel's fields instead of the engine's parameters.
"""

import math

__all__ = ["engine_arguments", "PAPER_W_INT"]

PAPER_W_INT = 0.25


def engine_arguments(num_picks, step_height, w_int=None, open_contour=False, relief_side="AUTO"):
    """Check the settings; return (step_height, kwargs) for the engine.

    step_height: h > 0, or None to ask the engine to estimate it;
    w_int: the smoothness weight in (0, 1], or None ("Auto": the engine chooses).
    Raises ValueError with a one-line message saying what to do.
    """
    need = 2 if open_contour else 3
    if num_picks < need:
        raise ValueError(
            "Select at least %d vertices around the relief (%s contour); %d selected"
            % (need, "an open" if open_contour else "a closed", num_picks))
    if step_height is not None and not (step_height > 0 and math.isfinite(step_height)):
        raise ValueError("Step height must be more than 0: type it in the Relief panel, use Measure on two "
                         "vertices, or choose Estimate")
    if w_int is not None and not (0 < w_int <= 1):
        raise ValueError("Smoothness must be between 0 and 1 (0.25 is the paper's value), or Auto")
    side = str(relief_side).lower()
    if side not in ("auto", "left", "right"):
        raise ValueError("Relief side must be AUTO, LEFT or RIGHT")
    h = None if step_height is None else float(step_height)
    return h, {"w_int": None if w_int is None else float(w_int), "open_contour": bool(open_contour),
               "relief_side": side}
