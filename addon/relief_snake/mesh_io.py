"""Blender mesh data in and out: vertex/triangle buffers, selection and click order, the relief
vertex group and the contour curve.

Buffers are array.array (Blender 3.4 from Debian has no numpy); foreach_get/foreach_set copy
straight into them, which is the fast path for 100k+ vertices.

Writes go through one path per mode, the one Blender's own tools use, so that undo sees a
consistent mesh: in Edit Mode the live bmesh (its deform layer) and nothing else, in Object
Mode the mesh data (VertexGroup.add/remove). An existing group is reused and emptied of the
vertices it no longer holds rather than removed and re-created, and an existing contour object
keeps its identity: its curve data is refilled in place. (Removing and re-creating both in Edit
Mode made Blender 3.4 segfault on the next Ctrl+Z; tests/blender/ui/ replays that sequence in a
real window.)
"""

import contextlib
import itertools
import math
import operator
import os
import tempfile
from array import array

import bpy
import bmesh

from . import blend_history

__all__ = ["sync_edit_mode", "live_mesh", "hold_edit_bmesh", "read_buffers", "read_selection", "vertex_position",
           "live_vertex_count", "write_vertex_group", "write_curve", "contour_object_name", "CONTOUR_COLOR"]

CONTOUR_COLOR = (1.0, 0.32, 0.02, 1.0)  # a clear orange, unlike any of Blender's overlay colours
_MATERIAL = "Relief Snake Contour"


def sync_edit_mode(obj):
    """Flush Edit Mode changes to obj.data so reads see what the user sees (a whole-mesh copy:
    the reads of a segmentation use live_mesh instead)."""
    if obj.mode == 'EDIT':
        obj.update_from_editmode()


def _evaluated_is_edit_mesh(obj):
    """True if the depsgraph's mesh of obj in Edit Mode has the edit mesh's vertices as they are:
    nothing (modifiers, shape keys, an armature parent) moves or adds vertices."""
    return (not len(obj.modifiers) and obj.data.shape_keys is None and obj.parent_type != 'ARMATURE')


@contextlib.contextmanager
def live_mesh(obj):
    """The mesh data the user sees now, to read from (never to write to).

    Object Mode: obj.data. Edit Mode: the depsgraph's mesh of the edit mesh (object.to_mesh(), or
    the evaluated object's mesh itself once a to_mesh() converted it). Blender converts the edit
    mesh into it once per edit and keeps it, so reading an unchanged edit mesh again costs no
    conversion, where update_from_editmode() writes the whole edit mesh back into obj.data on
    every call (1.3 s of a 300k-triangle Segment in Blender 3.4). When modifiers or shape keys
    make that mesh differ from the edit mesh, obj.data is flushed as before.
    """
    if obj.mode != 'EDIT':
        yield obj.data
        return
    if _evaluated_is_edit_mesh(obj):
        evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
        n = len(bmesh.from_edit_mesh(obj.data).verts)
        # 3.x: the depsgraph's mesh itself, once an earlier to_mesh() converted it (in place, kept
        # until the next edit), read there without to_mesh()'s copy of the whole mesh (0.01 s at
        # 300k triangles in 3.4). Until then it is a wrapper of the edit mesh with no vertices of its
        # own. 4.0+ copies nothing (the copy shares the arrays), and there the evaluated mesh hides
        # its ".corner_vert" attribute, whose block copy read_buffers needs.
        data = evaluated.data if bpy.app.version < (4, 0, 0) else None
        if n and data is not None and data.as_pointer() != obj.data.as_pointer() and len(data.vertices) == n:
            yield data
            return
        mesh = evaluated.to_mesh()
        try:
            if len(mesh.vertices) == n:
                yield mesh
                return
        finally:
            evaluated.to_mesh_clear()
    obj.update_from_editmode()
    yield obj.data


# Buffer formats that take foreach_get's block copy instead of its per-item loop: Blender 3.x stores
# a loop's vertex as an unsigned int (MLoop.v), 4.0+ as a signed int attribute (".corner_vert").
_LOOP_VERTEX_FORMAT = 'I' if bpy.app.version < (4, 0, 0) else 'i'


def read_buffers(mesh):
    """Vertices and triangles of a Mesh datablock (no modifiers).

    Returns (vertices, triangles): vertices array('f') flat 3*#V (object space), triangles flat
    3*#T 4-byte ints (loop triangles, so n-gons are triangulated the way Blender draws them), in
    the format Blender stores them: array('I') in 3.x, array('i') in 4.0+ (the engine takes both;
    vertex indices are far below 2**31, and a conversion would copy the buffer once more). An
    all-triangle mesh (every scan) reads its loops' vertices directly, in one block copy.
    """
    nv = len(mesh.vertices)
    vertices = array('f', bytes(12 * nv))
    mesh.vertices.foreach_get("co", vertices)
    nl, nf = len(mesh.loops), len(mesh.polygons)
    if nl == 3 * nf:  # all triangles: a triangle's loop triangle is its loops, in order
        corner_vert = mesh.attributes.get(".corner_vert") if _LOOP_VERTEX_FORMAT == 'i' else None
        triangles = array(_LOOP_VERTEX_FORMAT, bytes(4 * nl))
        if corner_vert is not None and corner_vert.domain == 'CORNER' and corner_vert.data_type == 'INT':
            corner_vert.data.foreach_get("value", triangles)
        else:
            mesh.loops.foreach_get("vertex_index", triangles)
        return vertices, triangles
    mesh.calc_loop_triangles()
    nt = len(mesh.loop_triangles)
    triangles = array(_LOOP_VERTEX_FORMAT, bytes(12 * nt))
    mesh.loop_triangles.foreach_get("vertices", triangles)
    return vertices, triangles


def _selection_flags(mesh):
    """#V bytes, 1 for the selected vertices. The ".select_vert" attribute (3.4+) is a block copy
    in 4.0+ (bool buffer); absent, nothing is selected."""
    nv = len(mesh.vertices)
    flags = bytearray(nv)
    attribute = mesh.attributes.get(".select_vert")
    if attribute is None:
        return flags
    if attribute.domain != 'POINT' or attribute.data_type != 'BOOLEAN':  # not Blender's own layer
        mesh.vertices.foreach_get("select", flags)
        return flags
    if bpy.app.version >= (4, 0, 0):
        attribute.data.foreach_get("value", memoryview(flags).cast('?'))
    else:
        attribute.data.foreach_get("value", flags)
    return flags


def _selected_indices(flags):
    raw = bytes(flags)
    out, i = [], raw.find(1)
    while i >= 0:  # bytes.find skips the unselected runs in C
        out.append(i)
        i = raw.find(1, i + 1)
    return out


def _edit_selection(obj):
    """(selected, history, verts) of the edit mesh itself: the selected vertices, the click order
    and the edit bmesh's vertex sequence (with its lookup table). Selecting tags only the selection,
    so the depsgraph's mesh keeps the selection of its last conversion: it cannot be read from there.
    When the select history holds every selected vertex (the usual picking), the selection is the
    history; otherwise every vertex is visited."""
    mesh = obj.data
    bm = bmesh.from_edit_mesh(mesh)
    bm.verts.index_update()
    history = [e.index for e in bm.select_history if isinstance(e, bmesh.types.BMVert) and e.select]
    clicked = set(history)
    if len(clicked) == mesh.total_vert_sel:  # the edit mesh's own count of selected vertices
        selected = sorted(clicked)
    else:
        selected = [v.index for v in bm.verts if v.select]
    bm.verts.ensure_lookup_table()
    return selected, history, bm.verts


def hold_edit_bmesh(obj):
    """Keep obj's edit bmesh's Python handle alive while the result lives (None outside Edit Mode).

    Blender gives an edit bmesh a layer that maps its elements to their Python objects when the
    first of them is made, and removes it when the handle goes; each time, every vertex's data is
    laid out anew (4 to 6 ms at 150k vertices in 3.4 once the mesh has weights). While this is
    held, the read (the click order) and the write (the weights) share one handle: once, not
    once each. If Blender frees the edit bmesh meanwhile (leaving Edit Mode, undo), the handle
    just becomes invalid and the next bmesh.from_edit_mesh() makes a new one."""
    if obj is None or getattr(obj, "type", None) != 'MESH' or obj.mode != 'EDIT':
        return None
    return bmesh.from_edit_mesh(obj.data)


def _history_file_dirs():
    """Where the click order's scratch .blend may go, in order: memory-backed /dev/shm where there
    is one, then the system's temporary folder (None: tempfile's default)."""
    shm = "/dev/shm"
    return ([shm] if os.path.isdir(shm) and os.access(shm, os.W_OK) else []) + [None]


def _stored_history(mesh):
    """The mesh's MSelect array [(index, type)] as stored, through a scratch .blend of the mesh
    alone (bpy.data.libraries.write: a block copy of its arrays, no bmesh) read back by
    blend_history. None if that could not be done (the caller reads it through bmesh)."""
    for folder in _history_file_dirs():
        try:
            fd, path = tempfile.mkstemp(prefix="relief-snake-", suffix=".blend", dir=folder)
        except OSError:
            continue
        os.close(fd)
        try:
            try:
                bpy.data.libraries.write(path, {mesh}, compress=False)
            except (OSError, RuntimeError):  # e.g. a /dev/shm too small for the mesh: the next folder
                continue
            return blend_history.read_select_history(path, "ME" + mesh.name)
        except (blend_history.Unreadable, OSError, TypeError, ValueError):
            return None
        finally:
            with contextlib.suppress(OSError):
                os.remove(path)
    return None


def _bmesh_history(mesh):
    """The click order through a bmesh copy of the whole mesh (the slow, always available way)."""
    bm = bmesh.new()
    try:
        try:  # normals are not needed for the history (3.1+ can skip them)
            bm.from_mesh(mesh, face_normals=False, vertex_normals=False)
        except TypeError:
            bm.from_mesh(mesh)
        return [e.index for e in bm.select_history if isinstance(e, bmesh.types.BMVert) and e.select]
    finally:
        bm.free()


def _click_order(obj, flags):
    """Selected vertices in click order (Blender's select history), possibly partial. flags: the
    selection (_selection_flags) of the mesh the history is read from."""
    mesh = obj.data
    if obj.mode == 'EDIT':
        bm = bmesh.from_edit_mesh(mesh)  # the live edit mesh: no copy; the history is a short list
        bm.verts.index_update()
        return [e.index for e in bm.select_history if isinstance(e, bmesh.types.BMVert) and e.select]
    # Object Mode: the click order is stored with the mesh (MSelect) and bmesh is the only reader
    # in the Python API, at the price of a copy of the whole mesh. The .blend route reads the same
    # array; it is filtered as bmesh does (vertex entries, the first of duplicates, selected ones).
    entries = _stored_history(mesh)
    if entries is None:
        return _bmesh_history(mesh)
    nv, seen, out = len(flags), set(), []
    for index, kind in entries:
        if kind == blend_history.VERTEX and 0 <= index < nv and index not in seen:
            seen.add(index)
            if flags[index]:
                out.append(index)
    return out


def read_selection(obj, mesh=None):
    """Selected vertices and their click order.

    mesh: what live_mesh(obj) gave (default: obj.data, so call sync_edit_mode(obj) first in Edit
    Mode). Returns (selected, history, positions, normals): selected list[int]; history list[int]
    in click order (may be partial or empty); positions and normals mappings {index: (x, y, z)}
    for the selected vertices only (object space), read when looked up.
    """
    mesh = obj.data if mesh is None else mesh
    if obj.mode == 'EDIT' and mesh is not obj.data:
        # From the edit mesh, which also keeps its normals current (the depsgraph's copy would
        # compute them all).
        selected, history, verts = _edit_selection(obj)
    else:
        flags = _selection_flags(mesh)
        selected = _selected_indices(flags)
        history = _click_order(obj, flags) if selected else []
        verts = mesh.vertices
    return selected, history, _VectorsOf(verts, "co", selected), _VectorsOf(verts, "normal", selected)


class _VectorsOf:
    """{index: (x, y, z)} of one vector property of the selected vertices, read when asked: the
    normals are needed only when the click order does not cover the selection (and in Blender 3.4
    the first read of a vertex normal computes every normal of the mesh)."""

    def __init__(self, verts, name, indices):
        self._verts, self._name, self._indices = verts, name, frozenset(indices)

    def __getitem__(self, i):
        if i not in self._indices:
            raise KeyError(i)
        return tuple(getattr(self._verts[i], self._name))

    def __contains__(self, i):
        return i in self._indices

    def __len__(self):
        return len(self._indices)


def vertex_position(mesh, index):
    """(x, y, z) of vertex `index` in object space."""
    return tuple(mesh.vertices[index].co)


def live_vertex_count(obj):
    """The vertex count of what the user edits now: the edit bmesh in Edit Mode."""
    if obj.mode == 'EDIT':
        return len(bmesh.from_edit_mesh(obj.data).verts)
    return len(obj.data.vertices)


def write_vertex_group(obj, name, indices):
    """Make vertex group `name` hold exactly `indices` (weight 1); reuse the group if it exists.

    Edit Mode: through the edit bmesh's deform layer only; Object Mode: through the mesh data.
    Returns the group, which becomes the active one.
    """
    group = obj.vertex_groups.get(name)
    existed = group is not None
    if group is None:
        group = obj.vertex_groups.new(name=name)
    gi = group.index
    if obj.mode == 'EDIT':
        mesh = obj.data
        if obj.vertex_groups.active_index != gi:  # setting it tags the object for a new evaluation
            obj.vertex_groups.active_index = gi
        # With nothing evaluated on top of the edit mesh (no modifiers, no shape keys), the weights
        # change nothing the depsgraph makes, so they are written without tagging the mesh for a new
        # evaluation, which would make the next Segment's read convert the whole edit mesh again.
        # Edit Mode's undo step stores the edit mesh itself, weights included.
        retag = not _evaluated_is_edit_mesh(obj)
        if existed and not (retag and _clear_active_group_in_edit_mode(obj)):
            bm = bmesh.from_edit_mesh(mesh)
            layer = bm.verts.layers.deform.verify()
            # Clear the old members: find them with map/itemgetter (no Python frame per vertex,
            # a third faster over 150k vertices), then delete their weight one by one.
            members = [w for w in map(operator.itemgetter(layer), bm.verts) if gi in w]
            for weights in members:
                del weights[gi]
        bm = bmesh.from_edit_mesh(mesh)
        layer = bm.verts.layers.deform.verify()
        bverts = bm.verts
        bverts.ensure_lookup_table()
        for i in indices:
            bverts[i][layer][gi] = 1.0
        if retag:
            bmesh.update_edit_mesh(mesh, loop_triangles=False, destructive=False)
    else:
        nv = len(obj.data.vertices)
        if nv and existed:
            # Out go only the vertices that will not be in it: the ones that stay keep their weight
            # record (REPLACE sets it to 1), where removing everyone first freed each record and
            # add() allocated it again (a repeat Segment writes the same vertices again).
            group.remove(_complement(nv, indices))
        if len(indices):
            group.add(list(indices), 1.0, 'REPLACE')
    if obj.vertex_groups.active_index != gi:
        obj.vertex_groups.active_index = gi
    return group


def _complement(n, indices):
    """The vertices 0..n-1 not in indices, ascending (itertools.compress: the scan runs in C)."""
    outside = bytearray(b"\1") * n
    for i in indices:
        outside[i] = 0
    return list(itertools.compress(range(n), outside))


def _clear_active_group_in_edit_mode(obj):
    """Take every vertex out of obj's active vertex group in the edit mesh, in C: Blender's own
    "Remove from All" (object.vertex_group_remove_from, use_all_verts), which clears the edit
    bmesh's deform layer without removing the group. Called from inside an operator, it adds no
    undo step of its own. False if it could not run (then the caller clears vertex by vertex)."""
    try:
        with bpy.context.temp_override(object=obj, active_object=obj):
            return 'FINISHED' in bpy.ops.object.vertex_group_remove_from(use_all_groups=False, use_all_verts=True)
    except (RuntimeError, AttributeError, TypeError):  # poll failed, or no temp_override
        return False


def contour_object_name(obj):
    return obj.name + "_ReliefContour"


def _contour_material():
    mat = bpy.data.materials.get(_MATERIAL)
    if mat is None:
        mat = bpy.data.materials.new(_MATERIAL)
        mat.diffuse_color = CONTOUR_COLOR  # Solid shading's material colour
        mat.use_nodes = True
        bsdf = mat.node_tree.nodes.get("Principled BSDF")
        if bsdf is not None:
            bsdf.inputs["Base Color"].default_value = CONTOUR_COLOR
            if "Emission Color" in bsdf.inputs:  # 4.0+
                bsdf.inputs["Emission Color"].default_value = CONTOUR_COLOR
            elif "Emission" in bsdf.inputs:
                bsdf.inputs["Emission"].default_value = CONTOUR_COLOR
    return mat


def write_curve(obj, contour, closed, radius=None, more_contours=()):
    """A 3D POLY curve through `contour` (list of (x, y, z) in obj's object space), parented to
    obj (identity parent inverse, so it sits on the mesh wherever obj is), drawn as an orange
    tube of `radius` (default: 0.6 of the mean point spacing) in front of the mesh.
    more_contours: further closed contours (a relief's holes, a band's second ring), one more
    spline each in the same curve object.

    An existing "<obj>_ReliefContour" curve object is kept and its curve data refilled.
    Returns the curve object.
    """
    name = contour_object_name(obj)
    ob = bpy.data.objects.get(name)
    if ob is not None and ob.type != 'CURVE':
        ob = None  # the name is taken by something else: make a new one beside it
    if ob is None:
        curve = bpy.data.curves.new(name, 'CURVE')
        ob = bpy.data.objects.new(name, curve)
        collections = list(obj.users_collection) or [bpy.context.scene.collection]
        for coll in collections:
            coll.objects.link(ob)
    curve = ob.data
    curve.splines.clear()
    curve.dimensions = '3D'
    splines = [(contour, closed)] + [(c, True) for c in more_contours if len(c) >= 2]
    for points, cyclic in splines:
        spline = curve.splines.new('POLY')
        spline.points.add(len(points) - 1)
        flat = array('f')
        for p in points:
            flat.extend((p[0], p[1], p[2], 1.0))
        spline.points.foreach_set("co", flat)
        spline.use_cyclic_u = bool(cyclic)
    if radius is None:
        # Thick enough to read at the zoom that shows the whole outline (0.6% of its size), and
        # never thinner than its own point spacing: the refinement's half-edge spacing alone gave
        # a hairline that read as dashed over the Edit Mode mesh.
        n = len(contour)
        length = sum(map(math.dist, contour[1:], contour[:-1]))  # in C: no Python frame per point
        axes = list(zip(*contour))
        size = math.dist([min(a) for a in axes], [max(a) for a in axes])
        radius = max(0.6 * length / max(1, n - 1), 0.006 * size)
    curve.bevel_depth = radius
    curve.bevel_resolution = 2
    curve.use_fill_caps = True
    if not curve.materials:
        curve.materials.append(_contour_material())
    ob.color = CONTOUR_COLOR  # Solid shading's object colour, if the viewport uses that
    ob.show_in_front = True
    if ob.parent is not obj:
        ob.parent = obj
    ob.matrix_parent_inverse.identity()  # world = obj.matrix_world @ identity basis
    ob.matrix_basis.identity()
    return ob
