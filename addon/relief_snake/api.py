"""Scripting API of the Relief Snake add-on.

    import relief_snake.api as rs            # or: from <package> import api as rs
    result = rs.segment_object(obj, picks=[12, 40, 77, 103], step_height=1.0)
    h = rs.measure(obj, 12, 13)

segment_object() reads the object's mesh data (no modifiers; Edit Mode changes are
flushed first), runs the native engine (relief_snake_core) and, when write=True,
stores the relief vertices in a vertex group and the contour in a curve object.
Nothing is written unless the engine succeeded. Distances and step heights are
in the object's local space (the engine sees object coordinates).
"""

import time

from . import ordering

__all__ = ["load_core", "EngineError", "segment_object", "apply_result", "measure", "selected_picks"]

_core = None


class EngineError(RuntimeError):
    """Any failure worth a one-line user report (bad input, engine error, missing module)."""


def load_core():
    """The native module: bundled next to the add-on, else from sys.path."""
    global _core
    if _core is None:
        try:
            from . import relief_snake_core as core
        except ImportError:
            try:
                import relief_snake_core as core
            except ImportError as exc:
                raise EngineError(
                    "Native module relief_snake_core not found (%s): build it (make build) or install "
                    "the packaged add-on" % exc) from None
        _core = core
    return _core


def _mesh_object(obj):
    if obj is None or getattr(obj, "type", None) != 'MESH':
        raise EngineError("Select a mesh object first (the active object is %s)"
                          % ("none" if obj is None else "a %s" % obj.type.lower()))
    return obj


def selected_picks(obj):
    """Picks from the selection: (picks, info) where info is None or a sentence
    saying the angle fallback was used (click order missing or partial)."""
    from . import mesh_io
    _mesh_object(obj)
    mesh_io.sync_edit_mode(obj)
    selected, history, positions, normals = mesh_io.read_selection(obj)
    return ordering.order_picks(selected, history, positions, normals)


def measure(obj, i, j):
    """Distance (object space) between vertices i and j of a mesh object."""
    _mesh_object(obj)
    from . import mesh_io
    mesh_io.sync_edit_mode(obj)
    n = len(obj.data.vertices)
    for k in (i, j):
        if not 0 <= k < n:
            raise EngineError("Vertex %d does not exist (the mesh has %d vertices)" % (k, n))
    return ordering.distance(mesh_io.vertex_position(obj.data, i), mesh_io.vertex_position(obj.data, j))


def segment_object(obj, picks, step_height, *, w_int=0.25, open_contour=False, relief_side="left",
                   max_iterations=3000, progress=None, write=True, group_name="Relief",
                   make_curve=True, options=None):
    """Segment the relief marked by `picks` (vertex indices, in order) on mesh object `obj`.

    `options` (dict, optional): the engine's advanced options by name, e.g.
    {"exact_q": True}; relief_snake_core.advanced_options() lists them.

    Returns the engine's result dict (status, closed, contour [(x, y, z)] in object
    space, relief_vertices, phases, ...) plus "timing": {"read", "engine", "write"}
    seconds. Raises EngineError with the engine's one-line message on failure, and
    relief_snake_core.Cancelled if `progress` returned False. With write=True the
    vertex group `group_name` and (make_curve) the curve "<obj>_ReliefContour" are
    replaced; on any failure nothing is written.
    """
    core = load_core()
    job = prepare(obj, picks, step_height, w_int=w_int, open_contour=open_contour,
                  relief_side=relief_side, max_iterations=max_iterations, options=options)
    result = run(core, job, progress)
    if write:
        apply_result(obj, result, group_name=group_name, make_curve=make_curve)
    return result


def prepare(obj, picks, step_height, *, w_int=0.25, open_contour=False, relief_side="left",
            max_iterations=3000, options=None):
    """Validate and read everything the engine needs (main thread, bpy access).

    Returns a job dict for run(); raises EngineError."""
    from . import mesh_io
    _mesh_object(obj)
    t0 = time.perf_counter()
    try:
        kwargs = ordering.validate_options(len(picks), step_height, w_int, open_contour, relief_side)
    except ValueError as exc:
        raise EngineError(str(exc)) from None
    mesh_io.sync_edit_mode(obj)
    vertices, triangles = mesh_io.read_buffers(obj.data)
    if not triangles:
        raise EngineError("The mesh %r has no faces: Relief Snake needs a triangle/polygon surface" % obj.name)
    nv = len(vertices) // 3
    picks = [int(p) for p in picks]
    bad = [p for p in picks if not 0 <= p < nv]
    if bad:
        raise EngineError("Pick %d is not a vertex of %r (it has %d vertices)" % (bad[0], obj.name, nv))
    kwargs["max_iterations"] = int(max_iterations)
    for name, value in (options or {}).items():
        if name in kwargs or name in ("progress",):
            raise EngineError("Option %r is a main argument of segment_object(), not an advanced option" % name)
        kwargs[name] = value
    return {"vertices": vertices, "triangles": triangles, "picks": picks,
            "step_height": float(step_height), "kwargs": kwargs, "num_vertices": nv,
            "read_seconds": time.perf_counter() - t0}


def run(core, job, progress=None):
    """The engine call; no bpy access, so it may run in a worker thread."""
    t0 = time.perf_counter()
    try:
        result = core.segment(job["vertices"], job["triangles"], job["picks"], job["step_height"],
                              progress=progress, **job["kwargs"])
    except (core.Error, TypeError) as exc:  # TypeError: an unknown advanced option
        raise EngineError(str(exc)) from None
    result = dict(result)
    result["timing"] = {"read": job["read_seconds"], "engine": time.perf_counter() - t0, "write": 0.0}
    return result


def apply_result(obj, result, *, group_name="Relief", make_curve=True):
    """Write a successful result: vertex group and (optionally) the contour curve.

    Checks first that the mesh still has the vertex count the engine saw."""
    from . import mesh_io
    t0 = time.perf_counter()
    relief = result.get("relief_vertices", [])
    nv = len(obj.data.vertices)
    if any(not 0 <= i < nv for i in relief):
        raise EngineError("The mesh changed while segmenting; run Relief Snake again")
    if not group_name:
        raise EngineError("Give the vertex group a name")
    contour = result.get("contour", [])
    mesh_io.write_vertex_group(obj, group_name, relief)
    if make_curve and len(contour) >= 2:
        mesh_io.write_curve(obj, contour, result.get("closed", True))
    timing = result.setdefault("timing", {})
    timing["write"] = time.perf_counter() - t0
    return result


from .extraction import extract_object, apply_relief, add_displace  # noqa: E402,F401 (extraction imports this module)
