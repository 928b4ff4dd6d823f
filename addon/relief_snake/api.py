"""Scripting API of the Relief Snake add-on, and the one pipeline the Segment operator uses too.

    import relief_snake.api as rs            # or: from <package> import api as rs
    result = rs.segment_object(obj, picks=[12, 40, 77, 103], step_height=1.0)
    h = rs.measure(obj, 12, 13)

The pipeline: prepare() reads the object's mesh data (no modifiers; in Edit Mode the edit
mesh as it is now, mesh_io.live_mesh) into a job.Request on the main thread; job.run_engine() runs the native engine
(relief_snake_core) with no bpy access, so the operator runs it in a worker thread; and
apply_result() writes the relief vertices into a vertex group and the outline into a curve
object. Nothing is written unless the engine succeeded. Distances and step heights are in the
object's local space (the engine sees object coordinates). The engine's Mesh for an object is
cached (job.MESH_CACHE, keyed by the object's name and a fingerprint of its mesh data), so a
second segmentation of an unchanged scan skips mesh intake and reuses the planarity.
"""

import time

from . import pick_order, validation
from .job import MESH_CACHE, EngineError, Request, fingerprint, run_engine

__all__ = ["load_core", "EngineError", "segment_object", "prepare", "run_engine", "apply_result", "measure",
           "selected_picks", "MESH_CACHE"]

_core = None


def load_core():
    """The native module: bundled next to the add-on (legacy zip), else from sys.path (the
    extension's wheel, or a build directory)."""
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


def selected_picks(obj, mesh=None):
    """Picks from the selection: (picks, info) where info is None or a sentence saying the
    angle fallback was used (click order missing or partial). mesh: what mesh_io.live_mesh(obj)
    gave, if the caller holds it (default: read it here)."""
    from . import mesh_io
    _mesh_object(obj)
    if mesh is None:
        with mesh_io.live_mesh(obj) as live:
            return selected_picks(obj, live)
    selected, history, positions, normals = mesh_io.read_selection(obj, mesh)
    return pick_order.order_picks(selected, history, positions, normals)


def measure(obj, i, j):
    """Distance (object space) between vertices i and j of a mesh object."""
    _mesh_object(obj)
    from . import mesh_io
    mesh_io.sync_edit_mode(obj)
    n = len(obj.data.vertices)
    for k in (i, j):
        if not 0 <= k < n:
            raise EngineError("Vertex %d does not exist (the mesh has %d vertices)" % (k, n))
    return pick_order.distance(mesh_io.vertex_position(obj.data, i), mesh_io.vertex_position(obj.data, j))


def prepare(obj, picks, step_height, *, w_int=None, open_contour=False, relief_side="auto",
            max_iterations=3000, options=None, read_seconds=0.0, mesh=None):
    """Validate and read everything the engine needs (main thread, bpy access); writes nothing.

    step_height None asks the engine to estimate h; w_int None lets it choose the smoothness.
    mesh: what mesh_io.live_mesh(obj) gave, if the caller holds it (the operator reads the
    selection from the same one); default: read it here. Returns a job.Request; raises EngineError."""
    from . import mesh_io
    _mesh_object(obj)
    t0 = time.perf_counter()
    try:
        h, kwargs = validation.engine_arguments(len(picks), step_height, w_int, open_contour, relief_side)
    except ValueError as exc:
        raise EngineError(str(exc)) from None
    if mesh is None:
        with mesh_io.live_mesh(obj) as live:
            vertices, triangles = mesh_io.read_buffers(live)
    else:
        vertices, triangles = mesh_io.read_buffers(mesh)
    if not triangles:
        raise EngineError("The mesh %r has no faces: Relief Snake needs a triangle/polygon surface" % obj.name)
    nv = len(vertices) // 3
    picks = [int(p) for p in picks]
    bad = [p for p in picks if not 0 <= p < nv]
    if bad:
        raise EngineError("Pick %d is not a vertex of %r (it has %d vertices)" % (bad[0], obj.name, nv))
    kwargs["max_iterations"] = int(max_iterations)
    for name, value in (options or {}).items():
        if name in kwargs or name in ("progress", "step_height", "picks"):
            raise EngineError("Option %r is a main argument of segment_object(), not an advanced option" % name)
        kwargs[name] = value
    return Request(vertices, triangles, picks, h, kwargs, key=obj.name_full,
                   read_seconds=read_seconds + time.perf_counter() - t0)


def mesh_changed(obj, request):
    """True if obj's mesh data (what the user sees now, Edit Mode included) is not what
    `request` read: the user edited or undid meanwhile."""
    from . import mesh_io
    if obj is None or getattr(obj, "type", None) != 'MESH':
        return True
    if mesh_io.live_vertex_count(obj) != request.num_vertices:
        return True
    with mesh_io.live_mesh(obj) as mesh:
        return fingerprint(*mesh_io.read_buffers(mesh)) != request.digest


def segment_object(obj, picks, step_height, *, w_int=None, open_contour=False, relief_side="auto",
                   max_iterations=3000, progress=None, write=True, group_name="Relief",
                   make_curve=True, options=None, cache=MESH_CACHE):
    """Segment the relief marked by `picks` (vertex indices, in order) on mesh object `obj`.

    step_height: h in object units, or None to let the engine estimate it; w_int: smoothness in
    (0, 1], or None (the engine chooses; an engine without that choice uses 0.25 and says so in
    result["notes"]). `options` (dict, optional): the engine's advanced options by name, e.g.
    {"exact_q": True}; relief_snake_core.advanced_options() lists them. cache: job.MeshCache
    (default the add-on's) or None.

    Returns the engine's result dict (status, closed, contour [(x, y, z)] in object space,
    relief_vertices, phases, ...) plus "timing": {"read", "intake", "engine", "write"} seconds
    and "mesh_cached". Raises EngineError with the engine's one-line message on failure, and
    relief_snake_core.Cancelled if `progress` returned False. With write=True the vertex group
    `group_name` and (make_curve) the curve "<obj>_ReliefContour" are filled (reused if they
    exist); on any failure nothing is written. A status of "doubtful" or "iteration_cap" is
    written too: summary.status_warning(result) says what to check.
    """
    core = load_core()
    request = prepare(obj, picks, step_height, w_int=w_int, open_contour=open_contour,
                      relief_side=relief_side, max_iterations=max_iterations, options=options)
    result = run_engine(core, request, progress, cache)
    if write:
        apply_result(obj, result, group_name=group_name, make_curve=make_curve)
    return result


def apply_result(obj, result, *, group_name="Relief", make_curve=True):
    """Write a successful result: vertex group and (optionally) the outline curve.

    Checks first that the mesh the user edits still has room for every relief vertex."""
    from . import mesh_io
    t0 = time.perf_counter()
    if not group_name or not group_name.strip():
        raise EngineError("Give the vertex group a name")
    relief = result.get("relief_vertices", [])
    nv = mesh_io.live_vertex_count(obj)
    if relief and (min(relief) < 0 or max(relief) >= nv):
        raise EngineError("The mesh changed while segmenting; nothing was written: run Segment again")
    contour = result.get("contour", [])
    mesh_io.write_vertex_group(obj, group_name, relief)
    if make_curve and len(contour) >= 2:
        # One spline per contour: the outline, each inner hole, a band's second ring (issue 13).
        more = list(result.get("holes") or [])
        if result.get("band_contour"):
            more.append(result["band_contour"])
        mesh_io.write_curve(obj, contour, result.get("closed", True), more_contours=more)
    timing = result.setdefault("timing", {})
    timing["write"] = time.perf_counter() - t0
    timing["total"] = timing.get("read", 0.0) + timing.get("engine", 0.0) + timing["write"]
    return result


from .extraction import extract_object, apply_relief, add_displace  # noqa: E402,F401 (extraction imports this module)
