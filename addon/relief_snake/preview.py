"""Viewport drawing of the evolving snake during an interactive run (gpu module).

The shader is created on first draw, never at import or in background mode (there is
no GPU context there). The built-in shader's name changed in Blender 4.0.
"""

import bpy

_shader = None
_handle = None
_state = {"points": [], "closed": True, "color": (1.0, 0.45, 0.0, 1.0)}


def builtin_shader_name(version=None):
    """'3D_UNIFORM_COLOR' before Blender 4.0, 'UNIFORM_COLOR' from 4.0 on."""
    version = bpy.app.version if version is None else version
    return '3D_UNIFORM_COLOR' if tuple(version) < (4, 0, 0) else 'UNIFORM_COLOR'


def _get_shader():
    global _shader
    if _shader is None:
        import gpu
        _shader = gpu.shader.from_builtin(builtin_shader_name())
    return _shader


def _draw():
    pts = _state["points"]
    if len(pts) < 2:
        return
    import gpu
    from gpu_extras.batch import batch_for_shader
    shader = _get_shader()
    coords = list(pts) + ([pts[0]] if _state["closed"] else [])
    batch = batch_for_shader(shader, 'LINE_STRIP', {"pos": coords})
    gpu.state.line_width_set(3.0)
    gpu.state.depth_test_set('NONE')  # the snake lies on the surface: draw it on top
    shader.bind()
    shader.uniform_float("color", _state["color"])
    batch.draw(shader)
    gpu.state.line_width_set(1.0)


def set_contour(points, matrix_world=None, closed=True):
    """Show `points` ((x, y, z), object space; mapped by matrix_world when given)."""
    if matrix_world is not None:
        from mathutils import Vector
        points = [tuple(matrix_world @ Vector(p)) for p in points]
    _state["points"] = list(points)
    _state["closed"] = bool(closed)


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
        bpy.types.SpaceView3D.draw_handler_remove(_handle, 'WINDOW')
        _handle = None
    _state["points"] = []


def is_active():
    return _handle is not None
