"""The relief region, tinted in the 3D Viewport (gpu module), behind the panel's Show Region toggle.

After a Segment, the region's triangles (region_faces.py) are drawn over the mesh in a translucent
green, in Object and Edit Mode alike, so the relief reads at a glance on a dense scan whose Edit Mode
wireframe hides any face colour (the weight overlay that did this before was invisible in the
real-window screenshots). Nothing is written into the mesh for it, so undo is not involved: the
tint is drawn only while its object, its vertex group and its vertex count are as the run left
them, and it goes when a file is loaded. Its batch is built on first draw, from the buffers the
engine was given (object space, drawn under the object's matrix).
"""

import bpy

from . import region_faces

if "_handle" not in globals():  # importlib.reload keeps the module dict: keep the live handler's id
    _handle = None
_shader = None
_regions = {}  # object name -> {"group", "num_vertices", "triangles", "vertices", "relief", "batch"}
_KEEP = 4  # regions kept (the last ones shown); each holds its mesh's buffers until drawn
COLOR = (0.1, 0.95, 0.3, 0.45)  # translucent green: unlike the orange outline and Blender's own colours


def builtin_shader_name(version=None):
    """The built-in flat-colour shader: '3D_UNIFORM_COLOR' before Blender 4.0, 'UNIFORM_COLOR' from 4.0 on."""
    version = bpy.app.version if version is None else version
    return '3D_UNIFORM_COLOR' if tuple(version) < (4, 0, 0) else 'UNIFORM_COLOR'


def show(obj, group_name, vertices, triangles, relief_vertices):
    """Tint the region of `relief_vertices` on mesh object obj (vertices: flat 3*#V object-space
    floats; triangles: flat 3*#T ints, as the engine read them) while group `group_name` exists."""
    _regions.pop(obj.name, None)
    _regions[obj.name] = {"group": group_name, "num_vertices": len(vertices) // 3, "vertices": vertices,
                          "triangles": triangles, "relief": list(relief_vertices), "batch": None}
    while len(_regions) > _KEEP:
        del _regions[next(iter(_regions))]
    start()
    _redraw()


def hide(name=None):
    """Forget the region of object `name` (all regions if None)."""
    if name is None:
        _regions.clear()
    else:
        _regions.pop(name, None)
    _redraw()


def shown():
    """Names of the objects whose region is kept for drawing."""
    return list(_regions)


def _live_vertex_count(ob):
    if ob.mode == 'EDIT':
        import bmesh
        return len(bmesh.from_edit_mesh(ob.data).verts)
    return len(ob.data.vertices)


def _batch(entry, shader):
    if entry["batch"] is None:
        from gpu_extras.batch import batch_for_shader
        used, local = region_faces.region_triangles(entry["triangles"], entry["relief"], entry["num_vertices"])
        v = entry["vertices"]
        coords = [(v[3 * i], v[3 * i + 1], v[3 * i + 2]) for i in used]
        entry["batch"] = batch_for_shader(shader, 'TRIS', {"pos": coords}, indices=local)
        entry["vertices"] = entry["triangles"] = None  # the batch has what it needs
    return entry["batch"]


def _draw():
    context = bpy.context
    scene = context.scene
    settings = getattr(scene, "relief_snake", None) if scene is not None else None
    if not _regions or settings is None or not settings.show_region:
        return
    import gpu
    global _shader
    if _shader is None:
        _shader = gpu.shader.from_builtin(builtin_shader_name())
    depth, blend = gpu.state.depth_test_get(), gpu.state.blend_get()
    gpu.state.depth_test_set('LESS_EQUAL')  # on the surface, hidden behind what is in front of it
    gpu.state.blend_set('ALPHA')
    # Blender draws the mesh with its own depth offsets (Edit Mode's faces come out nearer than
    # their positions), so the tint at the very same positions would fail the depth test
    # everywhere: pull it towards the viewer the way Blender offsets its overlays.
    rv3d = context.region_data
    gpu.matrix.push_projection()
    gpu.matrix.load_projection_matrix(biased_projection(gpu.matrix.get_projection_matrix(),
                                                        rv3d.view_distance if rv3d is not None else 10.0))
    try:
        for name, entry in list(_regions.items()):
            ob = scene.objects.get(name)
            if (ob is None or ob.type != 'MESH' or not ob.visible_get() or ob.vertex_groups.get(entry["group"]) is None
                    or _live_vertex_count(ob) != entry["num_vertices"]):
                continue
            batch = _batch(entry, _shader)
            gpu.matrix.push()
            try:
                gpu.matrix.multiply_matrix(ob.matrix_world)
                _shader.bind()
                _shader.uniform_float("color", COLOR)
                batch.draw(_shader)
            finally:
                gpu.matrix.pop()
    finally:
        gpu.matrix.pop_projection()
        gpu.state.depth_test_set(depth)
        gpu.state.blend_set(blend)


def biased_projection(projection, view_distance, amount=4.0):
    """`projection` (4x4, row-major indexing) with its depth pulled towards the viewer: Blender's
    GPU_polygon_offset formula, `amount` times its unit offset (orthographic: a constant, scaled by
    the view distance; perspective: the depth term scaled by 1 + 0.25% per unit)."""
    m = projection.copy()
    if m[3][3] > 0.5:  # orthographic
        m[2][3] -= 1e-5 * amount * view_distance
    else:
        m[2][3] *= 1.0 + 0.0025 * amount
    return m


def _redraw():
    wm = bpy.context.window_manager
    for window in (wm.windows if wm is not None else ()):
        for area in window.screen.areas:
            if area.type == 'VIEW_3D':
                area.tag_redraw()


def redraw_on_toggle(_settings, _context):
    """The Show Region toggle's update: redraw the 3D views now."""
    _redraw()


def start():
    """Install the draw handler (interactive sessions only)."""
    global _handle
    if bpy.app.background or _handle is not None:
        return
    _handle = bpy.types.SpaceView3D.draw_handler_add(_draw, (), 'WINDOW', 'POST_VIEW')


def stop():
    """Remove the draw handler and forget every region."""
    global _handle
    if _handle is not None:
        try:
            bpy.types.SpaceView3D.draw_handler_remove(_handle, 'WINDOW')
        except ValueError:  # already gone (removed by a previous instance of this module)
            pass
        _handle = None
    _regions.clear()


@bpy.app.handlers.persistent
def _forget_on_load(*_args):
    _regions.clear()


def register_handlers():
    unregister_handlers()
    bpy.app.handlers.load_post.append(_forget_on_load)


def unregister_handlers():
    for h in list(bpy.app.handlers.load_post):  # by name too: a reload leaves the old module's function
        if h is _forget_on_load or (getattr(h, "__name__", None) == _forget_on_load.__name__
                                    and getattr(h, "__module__", None) == _forget_on_load.__module__):
            bpy.app.handlers.load_post.remove(h)
