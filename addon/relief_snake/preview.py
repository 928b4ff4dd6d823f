"""Viewport drawing of the evolving outline during an interactive run (gpu module).

The polyline shader draws wide lines on every GPU backend (line_width_set is ignored on Metal
and Vulkan). Its batch is rebuilt only when the contour changes, and the depth and blend state
are put back after drawing. The shader is made on first draw, never at import or in
background mode (there is no GPU context there). The draw handler's id is kept across a
reload of this module, so reloading the add-on cannot leave an orphan handler drawing.
"""

import bpy

if "_handle" not in globals():  # importlib.reload keeps the module dict: keep the live handler's id
    _handle = None
_shader = None
_state = {"points": [], "closed": True, "serial": 0, "batch": None, "batch_serial": -1,
          "color": (1.0, 0.45, 0.0, 1.0), "width": 3.0}


def builtin_shader_name(version=None):
    """The built-in polyline shader: '3D_POLYLINE_UNIFORM_COLOR' before Blender 4.0,
    'POLYLINE_UNIFORM_COLOR' from 4.0 on."""
    version = bpy.app.version if version is None else version
    return '3D_POLYLINE_UNIFORM_COLOR' if tuple(version) < (4, 0, 0) else 'POLYLINE_UNIFORM_COLOR'


def _get_shader():
    global _shader
    if _shader is None:
        import gpu
        _shader = gpu.shader.from_builtin(builtin_shader_name())
    return _shader


def _batch(shader):
    if _state["batch"] is None or _state["batch_serial"] != _state["serial"]:
        from gpu_extras.batch import batch_for_shader
        pts = _state["points"]
        coords = list(pts) + ([pts[0]] if _state["closed"] else [])
        _state["batch"] = batch_for_shader(shader, 'LINE_STRIP', {"pos": coords})
        _state["batch_serial"] = _state["serial"]
    return _state["batch"]


def _draw():
    if len(_state["points"]) < 2:
        return
    import gpu
    shader = _get_shader()
    batch = _batch(shader)
    depth, blend = gpu.state.depth_test_get(), gpu.state.blend_get()
    gpu.state.depth_test_set('NONE')  # the outline lies on the surface: draw it on top
    gpu.state.blend_set('ALPHA')
    try:
        shader.bind()
        shader.uniform_float("viewportSize", gpu.state.viewport_get()[2:])
        shader.uniform_float("lineWidth", float(_state["width"]))
        shader.uniform_float("color", tuple(_state["color"]))
        batch.draw(shader)
    finally:
        gpu.state.depth_test_set(depth)
        gpu.state.blend_set(blend)


def set_style(color=None, width=None):
    if color is not None:
        _state["color"] = tuple(color)
    if width is not None:
        _state["width"] = float(width)


def set_contour(points, matrix_world=None, closed=True):
    """Show `points` ((x, y, z), object space; mapped by matrix_world when given)."""
    if matrix_world is not None:
        from mathutils import Vector
        points = [tuple(matrix_world @ Vector(p)) for p in points]
    _state["points"] = list(points)
    _state["closed"] = bool(closed)
    _state["serial"] += 1


def start():
    """Install the draw handler (interactive sessions only)."""
    global _handle
    if bpy.app.background or _handle is not None:
        return
    _handle = bpy.types.SpaceView3D.draw_handler_add(_draw, (), 'WINDOW', 'POST_VIEW')


def stop():
    """Remove the draw handler and forget the contour."""
    global _handle
    if _handle is not None:
        try:
            bpy.types.SpaceView3D.draw_handler_remove(_handle, 'WINDOW')
        except ValueError:  # already gone (e.g. removed by a previous instance of this module)
            pass
        _handle = None
    _state["points"] = []
    _state["batch"] = None
    _state["serial"] += 1


def is_active():
    return _handle is not None
