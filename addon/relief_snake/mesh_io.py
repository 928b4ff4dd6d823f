"""Blender mesh data in and out: vertex/triangle buffers, selection and click order,
the relief vertex group and the contour curve.

Buffers are array.array (Blender 3.4 from Debian has no numpy); foreach_get/foreach_set
copy straight into them, which is the fast path for 100k+ vertices.
"""

from array import array

import bpy
import bmesh

__all__ = [
    "sync_edit_mode",
    "read_buffers",
    "read_selection",
    "vertex_position",
    "write_vertex_group",
    "write_curve",
    "remove_object_and_data",
    "contour_object_name",
]


def sync_edit_mode(obj):
    """Flush Edit Mode changes to obj.data so reads see what the user sees."""
    if obj.mode == 'EDIT':
        obj.update_from_editmode()


def read_buffers(mesh):
    """Vertices and triangles of a Mesh datablock (no modifiers).

    Returns (vertices, triangles): vertices array('f') flat 3*#V (object space),
    triangles array('i') flat 3*#T (loop triangles, so n-gons are triangulated the
    way Blender draws them).
    """
    nv = len(mesh.vertices)
    vertices = array('f', bytes(12 * nv))
    mesh.vertices.foreach_get("co", vertices)
    mesh.calc_loop_triangles()
    nt = len(mesh.loop_triangles)
    triangles = array('i', bytes(12 * nt))
    mesh.loop_triangles.foreach_get("vertices", triangles)
    return vertices, triangles


def read_selection(obj):
    """Selected vertices and their click order.

    Returns (selected, history, positions, normals): selected list[int]; history
    list[int] in click order (may be partial/empty); positions and normals dicts
    {index: (x, y, z)} for the selected vertices only (object space).
    Call sync_edit_mode(obj) first in Edit Mode.
    """
    mesh = obj.data
    if obj.mode == 'EDIT':
        bm = bmesh.from_edit_mesh(mesh)
        own = False
    else:
        # Object Mode: the click order is stored with the mesh (MSelect) and
        # bmesh reads it back into select_history.
        bm = bmesh.new()
        bm.from_mesh(mesh)
        own = True
    try:
        bm.verts.index_update()
        history = [e.index for e in bm.select_history if isinstance(e, bmesh.types.BMVert) and e.select]
    finally:
        if own:
            bm.free()
    nv = len(mesh.vertices)
    flags = array('b', bytes(nv))
    mesh.vertices.foreach_get("select", flags)
    selected = [i for i, f in enumerate(flags) if f]
    verts = mesh.vertices
    positions = {i: tuple(verts[i].co) for i in selected}
    normals = {i: tuple(verts[i].normal) for i in selected}
    return selected, history, positions, normals


def vertex_position(mesh, index):
    """(x, y, z) of vertex `index` in object space."""
    return tuple(mesh.vertices[index].co)


def write_vertex_group(obj, name, indices):
    """Put `indices` (weight 1) into vertex group `name`, replacing an older one of that name.

    Works in Object and Edit Mode (in Edit Mode through the bmesh deform layer,
    since VertexGroup.add is refused there). Returns the new group.
    """
    old = obj.vertex_groups.get(name)
    if old is not None:
        obj.vertex_groups.remove(old)
    group = obj.vertex_groups.new(name=name)
    if obj.mode == 'EDIT':
        mesh = obj.data
        bm = bmesh.from_edit_mesh(mesh)
        layer = bm.verts.layers.deform.verify()
        bm.verts.ensure_lookup_table()
        gi = group.index
        bverts = bm.verts
        for i in indices:
            bverts[i][layer][gi] = 1.0
        bmesh.update_edit_mesh(mesh, loop_triangles=False, destructive=False)
    elif len(indices):
        group.add(list(indices), 1.0, 'REPLACE')
    obj.vertex_groups.active_index = group.index
    return group


def contour_object_name(obj):
    return obj.name + "_ReliefContour"


def remove_object_and_data(ob):
    """Delete object `ob` and its curve data if nothing else uses it."""
    data = ob.data
    bpy.data.objects.remove(ob, do_unlink=True)
    if isinstance(data, bpy.types.Curve) and data.users == 0:
        bpy.data.curves.remove(data)


def write_curve(obj, contour, closed):
    """A 3D POLY curve through `contour` (list of (x, y, z) in obj's object space),
    parented to obj with an identity parent inverse so it sits on the mesh wherever
    obj is. Replaces an older "<obj>_ReliefContour" curve. Returns the new object.
    """
    name = contour_object_name(obj)
    old = bpy.data.objects.get(name)
    if old is not None and old.type == 'CURVE':
        remove_object_and_data(old)
    curve = bpy.data.curves.new(name, 'CURVE')
    curve.dimensions = '3D'
    spline = curve.splines.new('POLY')
    spline.points.add(len(contour) - 1)
    flat = array('f')
    for p in contour:
        flat.extend((p[0], p[1], p[2], 1.0))
    spline.points.foreach_set("co", flat)
    spline.use_cyclic_u = bool(closed)
    ob = bpy.data.objects.new(name, curve)
    collections = list(obj.users_collection) or [bpy.context.scene.collection]
    for coll in collections:
        coll.objects.link(ob)
    ob.parent = obj
    ob.matrix_parent_inverse.identity()  # world = obj.matrix_world @ identity basis
    return ob
