"""What the artist reads after a run: the result in plain words, the warning for a result the
engine doubts, the phases and the time split. bpy-free (tests/blender/test_summary.py).

Result dicts are relief_snake_core's (docs/result-format.md); keys this add-on does not find
are treated as absent, so an older or newer engine still gets a summary.
"""

import math

__all__ = ["STATUS_WORDS", "result_summary", "status_warning", "phase_lines", "timing_line",
           "step_height_line", "PHASE_WORDS"]

STATUS_WORDS = {
    "converged": "done",
    "doubtful": "done, but doubtful",
    "iteration_cap": "stopped at the step limit",
    "cancelled": "cancelled",
}

PHASE_WORDS = {
    "intake": "reading the mesh into the engine",
    "segment": "preparing the surface",
    "preprocess": "preparing the surface",
    "coarse": "coarse pass",
    "refine": "refining",
    "stabilise": "settling",
}


def result_summary(result):
    """'Done: closed outline of 412 points, 5123 relief vertices, 1.9 s'; an open outline names the
    side of the picks its relief is on (given, or decided by the engine)."""
    contour = result.get("contour", [])
    relief = result.get("relief_vertices", [])
    status = str(result.get("status", "?"))
    words = STATUS_WORDS.get(status, status.replace("_", " "))
    timing = result.get("timing", {})
    seconds = float(timing.get("total", timing.get("segment_seconds", 0.0)))
    kind = "closed" if result.get("closed", True) else "open"
    holes = len(result.get("holes") or [])
    side = result.get("relief_side")
    side_words = " (relief %s of the picks)" % side if kind == "open" and side in ("left", "right") else ""
    if result.get("band"):
        kind = "band with two"
    elif holes:
        kind += " (%d hole%s)" % (holes, "" if holes == 1 else "s")
    return "%s: %s outline%s of %d points%s, %d relief vertices, %.1f s" % (
        words[:1].upper() + words[1:], kind, "s" if result.get("band") else "",
        len(contour), side_words, len(relief), seconds)


def status_warning(result):
    """The warning sentence for a result the engine is not sure of, or None.

    "doubtful" and "iteration_cap" come with the engine's plain-words `message` (and `reasons`)
    in the contract of issue 14; older engines only say "iteration_cap"."""
    status = str(result.get("status", ""))
    if status not in ("doubtful", "iteration_cap"):
        return None
    message = str(result.get("message") or "").strip()
    if not message:
        message = ("The outline stopped at the step limit before it settled" if status == "iteration_cap"
                   else "The engine is not sure of this outline")
    reasons = [str(r) for r in result.get("reasons", []) if str(r).strip()]
    text = message.rstrip(".") + "."
    if reasons:
        text += " (" + "; ".join(reasons) + ")"
    return text + " Check the outline before using it."


def step_height_line(result, format_length=str):
    """The step height in plain words, or None when there is nothing to say.

    Estimated h: 'Estimated step height: 0.81 m (confidence 0.90)', or, when the step measured at
    the outline's edge differs from the h the outline was made with, 'Estimated step height: 0.81 m
    at the outline's edge, outlined with h = 0.70 m (confidence 0.90)'. Typed h: a line only when
    the edge's step is off it by more than x1.33. The result's step_height is {"used", "given",
    "estimate", "confidence", "measured"} (docs/result-format.md)."""
    sh = result.get("step_height")
    if not isinstance(sh, dict) or not sh.get("used"):
        return None
    used, measured = float(sh["used"]), sh.get("measured")
    measured = float(measured) if isinstance(measured, (int, float)) and measured > 0 else None
    if sh.get("given") is not None:
        if measured is None or 0.75 <= measured / used <= 1.33:
            return None
        return "The step at the outline's edge measures %s, against the h typed (%s)" % (
            format_length(measured), format_length(used))
    if measured is not None and abs(math.log(measured / used)) > math.log(1.05):
        line = "Estimated step height: %s at the outline's edge, outlined with h = %s" % (
            format_length(measured), format_length(used))
    else:
        line = "Estimated step height: %s" % format_length(used)
    if sh.get("confidence") is not None:
        line += " (confidence %.2f)" % float(sh["confidence"])
    return line


def phase_lines(result):
    """One line per phase: 'Coarse pass: 131 steps, 175 points, 2.10 s'."""
    lines = []
    for p in result.get("phases", []):
        name = str(p.get("name", "?"))
        words = PHASE_WORDS.get(name, name)
        lines.append("%s: %d steps, %d points, %.2f s%s" % (
            words[:1].upper() + words[1:], int(p.get("iterations", 0)), int(p.get("snaxels", 0)),
            float(p.get("seconds", 0.0)), "" if p.get("converged", True) else " (step limit)"))
    return lines


def timing_line(result):
    """'Blender data 0.12 s (read 0.10, write 0.02), engine 4.20 s (mesh reused)'."""
    t = result.get("timing", {})
    read, write, engine = (float(t.get(k, 0.0)) for k in ("read", "write", "engine"))
    cached = " (mesh reused)" if result.get("mesh_cached") else ""
    return "Blender data %.2f s (read %.2f, write %.2f), engine %.2f s%s" % (
        read + write, read, write, engine, cached)
