"""Add-on tests inside Blender (run by run_tests.py in Blender 3.4, bpy 4.5 and bpy 5.2)."""

import hashlib
import math
import random
import struct
import time
import unittest

import bmesh
import bpy

import plyio

_CFG = {}


# The native suite's bar (tests/native/test_segment.cpp): IoU >= 0.95 with the truth.
IOU_MIN = 0.95


def configure(prefix, truth, open_scan):
    """Called by run_tests.py: the scan files and their ground truth; open_scan is (prefix, truth)
    of the open-contour scan."""
    vertices, faces = plyio.read_ply(prefix + ".ply")
    _CFG.update(prefix=prefix, truth=truth, vertices=vertices, faces=faces)
    open_prefix, open_truth = open_scan
    open_vertices, open_faces = plyio.read_ply(open_prefix + ".ply")
    _CFG["open"] = {"prefix": open_prefix, "truth": open_truth, "vertices": open_vertices, "faces": open_faces}


def addon():
    import relief_snake
    return relief_snake


# -- helpers ----------------------------------------------------------------------------

def clear_scene():
    if bpy.context.object is not None and bpy.context.object.mode != 'OBJECT':
        bpy.ops.object.mode_set(mode='OBJECT')
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    for coll in (bpy.data.meshes, bpy.data.curves):
        for block in list(coll):
            coll.remove(block)
    for coll in (bpy.data.materials,):
        for block in list(coll):
            if block.users == 0:
                coll.remove(block)
    s = bpy.context.scene.relief_snake
    s.last_summary = s.last_details = s.last_warning = ""
    addon().job.MESH_CACHE.clear()


def make_scan_object(name="Scan", scan=None):
    """A mesh object from the duck scan, or from `scan` (a dict with vertices and faces)."""
    scan = scan or _CFG
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(scan["vertices"], [], scan["faces"])
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    return obj


def select_vertices(obj, indices, history=True):
    """Select exactly `indices`; record them as click order (select_history) if asked.
    Works in Object Mode (via the mesh's stored select history) and Edit Mode."""
    mesh = obj.data
    edit = obj.mode == 'EDIT'
    bm = bmesh.from_edit_mesh(mesh) if edit else bmesh.new()
    if not edit:
        bm.from_mesh(mesh)
    bm.verts.ensure_lookup_table()
    for e in list(bm.verts) + list(bm.edges) + list(bm.faces):
        e.select = False
    bm.select_history.clear()
    for i in indices:
        v = bm.verts[i]
        v.select = True
        if history:
            bm.select_history.add(v)
    if edit:
        bmesh.update_edit_mesh(mesh)
    else:
        bm.to_mesh(mesh)
        bm.free()
        mesh.update()


def snapshot():
    """Everything an operator could have changed: objects, meshes' geometry, groups, settings."""
    h = hashlib.sha1()
    state = {"objects": sorted((o.name, o.type, o.parent.name if o.parent else None) for o in bpy.data.objects),
             "curves": sorted(c.name for c in bpy.data.curves)}
    for ob in bpy.data.objects:
        if ob.type == 'MESH':
            if ob.mode == 'EDIT':
                ob.update_from_editmode()
            co = [0.0] * (3 * len(ob.data.vertices))
            ob.data.vertices.foreach_get("co", co)
            h.update(struct.pack("%dd" % len(co), *co))
            state[ob.name] = (len(ob.data.vertices), len(ob.data.polygons),
                              [(g.name, g.index) for g in ob.vertex_groups], ob.vertex_groups.active_index)
    state["coords"] = h.hexdigest()
    s = bpy.context.scene.relief_snake
    state["settings"] = tuple(getattr(s, n) for n in addon().properties.SETTING_NAMES) + (
        s.last_summary, s.last_details, s.last_warning)
    curve = bpy.data.objects.get("Scan_ReliefContour")
    state["curve"] = None if curve is None else [tuple(p.co) for sp in curve.data.splines for p in sp.points]
    return state


def group_members(obj, name):
    group = obj.vertex_groups[name]
    gi = group.index
    out = set()
    for v in obj.data.vertices:
        for g in v.groups:
            if g.group == gi and g.weight > 0:
                out.add(v.index)
    return out


def group_weights(obj, name):
    """{vertex index: weight} of the vertex group `name`, from the edit bmesh in Edit Mode."""
    gi = obj.vertex_groups[name].index
    if obj.mode == 'EDIT':
        bm = bmesh.from_edit_mesh(obj.data)
        layer = bm.verts.layers.deform.active
        if layer is None:
            return {}
        return {v.index: round(v[layer][gi], 6) for v in bm.verts if gi in v[layer]}
    return {v.index: round(g.weight, 6) for v in obj.data.vertices for g in v.groups if g.group == gi}


def set_weights(obj, name, weights):
    """Give vertices {index: weight} in group `name`, as painting would (Edit Mode: the edit bmesh)."""
    gi = obj.vertex_groups[name].index
    if obj.mode == 'EDIT':
        bm = bmesh.from_edit_mesh(obj.data)
        layer = bm.verts.layers.deform.verify()
        bm.verts.ensure_lookup_table()
        for i, w in weights.items():
            bm.verts[i][layer][gi] = w
        return
    for i, w in weights.items():
        obj.vertex_groups[name].add([i], w, 'REPLACE')


def delete_vertices(obj, indices):
    """Delete vertices (and their faces) as an edit would; the selection and its history follow."""
    edit = obj.mode == 'EDIT'
    bm = bmesh.from_edit_mesh(obj.data) if edit else bmesh.new()
    if not edit:
        bm.from_mesh(obj.data)
    bm.verts.ensure_lookup_table()
    bmesh.ops.delete(bm, geom=[bm.verts[i] for i in indices], context='VERTS')
    if edit:
        bmesh.update_edit_mesh(obj.data)
    else:
        bm.to_mesh(obj.data)
        bm.free()
        obj.data.update()


def iou(a, b):
    a, b = set(a), set(b)
    return len(a & b) / max(1, len(a | b))


def boundary_points(truth):
    b = truth["boundary"]
    if b and isinstance(b[0][0], (list, tuple)):  # several polylines
        b = [p for line in b for p in line]
    return b


def distances_to(points, targets, edge=None):
    """For each point, the distance to the nearest target point (uniform grid hashing with cells
    of two average edges: `edge`, by default the duck scan's)."""
    cell = max((edge or truth_edge()) * 2, 1e-9)
    grid = {}
    for t in targets:
        grid.setdefault(tuple(int(math.floor(c / cell)) for c in t), []).append(t)
    out = []
    for p in points:
        key = tuple(int(math.floor(c / cell)) for c in p)
        best = math.inf
        r = 1
        while best == math.inf and r < 64:
            for dx in range(-r, r + 1):
                for dy in range(-r, r + 1):
                    for dz in range(-r, r + 1):
                        for t in grid.get((key[0] + dx, key[1] + dy, key[2] + dz), ()):
                            best = min(best, math.dist(p, t))
            r *= 2
        out.append(best)
    return out


def truth_edge():
    return _CFG["truth"]["average_edge"]


def seg(**kw):
    return bpy.ops.mesh.relief_snake_segment('EXEC_DEFAULT', **kw)


# -- tests ------------------------------------------------------------------------------

class AddonTestCase(unittest.TestCase):
    def setUp(self):
        clear_scene()
        self.truth = _CFG["truth"]
        self.h = float(self.truth["h"])
        self.picks = list(self.truth["picks"])
        self.obj = make_scan_object()

    def tearDown(self):
        clear_scene()

    def assertSegmentationMatchesTruth(self, obj, group="Relief", closed=True):
        members = group_members(obj, group)
        score = iou(members, self.truth["relief_vertices"])
        self.assertGreaterEqual(score, IOU_MIN, "IoU %.3f against the ground truth" % score)
        curve = bpy.data.objects.get(obj.name + "_ReliefContour")
        self.assertIsNotNone(curve, "no contour curve")
        self.assertEqual(curve.type, 'CURVE')
        self.assertIs(curve.parent, obj)
        self.assertEqual(len(curve.data.splines), 1)
        spline = curve.data.splines[0]
        self.assertEqual(spline.type, 'POLY')
        self.assertEqual(spline.use_cyclic_u, closed)
        pts = [tuple(p.co)[:3] for p in spline.points]
        self.assertGreater(len(pts), len(self.picks))  # the snake refines the pick polygon
        edge = self.truth["average_edge"]
        d = sorted(distances_to(pts, boundary_points(self.truth), edge))
        median, p90 = d[len(d) // 2], d[int(0.9 * (len(d) - 1))]
        self.assertLess(median, 2 * edge, "contour median distance to the true boundary %.3g" % median)
        self.assertLess(p90, max(4 * edge, 0.5 * self.h), "contour p90 distance %.3g" % p90)
        return members


class SegmentOperator(AddonTestCase):
    def test_object_mode_segments_the_relief(self):
        select_vertices(self.obj, self.picks)
        self.assertEqual(seg(step_height=self.h), {'FINISHED'})
        self.assertSegmentationMatchesTruth(self.obj)
        s = bpy.context.scene.relief_snake
        self.assertIn("points", s.last_summary)
        self.assertTrue(s.last_details.strip(), "no phase summary")
        self.assertEqual(self.obj.vertex_groups.active.name, "Relief")
        self.assertEqual(self.obj.mode, 'OBJECT')

    def test_scene_settings_feed_the_operator_and_invoke_runs_headless(self):
        select_vertices(self.obj, self.picks)
        s = bpy.context.scene.relief_snake
        s.step_height = self.h
        s.group_name = "Duck"
        try:
            # INVOKE_DEFAULT in background mode must run synchronously, not go modal.
            self.assertEqual(bpy.ops.mesh.relief_snake_segment('INVOKE_DEFAULT'), {'FINISHED'})
        finally:
            s.group_name = "Relief"
        self.assertIn("Duck", self.obj.vertex_groups)
        self.assertNotIn("Relief", self.obj.vertex_groups)
        self.assertSegmentationMatchesTruth(self.obj, "Duck")

    def test_edit_mode_reads_the_unflushed_selection(self):
        bpy.ops.object.mode_set(mode='EDIT')
        # Selected only in the edit bmesh: the mesh data still has nothing selected,
        # so a stale read would fail with "select at least 3 vertices".
        select_vertices(self.obj, self.picks)
        self.assertEqual(seg(step_height=self.h), {'FINISHED'})
        self.assertEqual(self.obj.mode, 'EDIT')
        bpy.ops.object.mode_set(mode='OBJECT')  # the group must survive leaving Edit Mode
        self.assertSegmentationMatchesTruth(self.obj)

    def test_edit_mode_selection_changes_after_a_read_are_seen(self):
        # Selecting tags only the selection, so the depsgraph keeps the mesh it converted for the
        # last read: the selection must come from the edit mesh itself.
        bpy.ops.object.mode_set(mode='EDIT')
        select_vertices(self.obj, self.picks)
        api = addon().api
        picks, _ = api.selected_picks(self.obj)
        self.assertEqual(picks, self.picks)
        api.prepare(self.obj, picks, self.h)  # a read of the buffers too
        bpy.ops.mesh.select_all(action='DESELECT')
        self.assertEqual(api.selected_picks(self.obj)[0], [])  # nothing selected any more
        bm = bmesh.from_edit_mesh(self.obj.data)
        bm.verts.ensure_lookup_table()
        for i in self.picks[:4]:  # select, no update_edit_mesh (no geometry tag)
            bm.verts[i].select = True
            bm.select_history.add(bm.verts[i])
        picks, _ = api.selected_picks(self.obj)
        self.assertEqual(picks, self.picks[:4])
        bpy.ops.object.mode_set(mode='OBJECT')

    def test_edit_mode_geometry_changes_are_seen(self):
        # Every read after an edit, the first (through to_mesh) and the later ones (the depsgraph's
        # mesh that to_mesh converted, read in place), gives the edit mesh as it is.
        bpy.ops.object.mode_set(mode='EDIT')
        api = addon().api

        def edit(vertex, dz):
            bm = bmesh.from_edit_mesh(self.obj.data)
            bm.verts.ensure_lookup_table()
            bm.verts[vertex].co.z += dz
            bmesh.update_edit_mesh(self.obj.data)

        def evaluated_copy():
            evaluated = self.obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
            mesh = evaluated.to_mesh()
            try:
                return addon().mesh_io.read_buffers(mesh)
            finally:
                evaluated.to_mesh_clear()
        edit(0, 123.0)
        for step in (None, (7, 5.0), None, (11, -2.0)):
            if step:
                edit(*step)
            first = api.prepare(self.obj, self.picks, self.h)
            again = api.prepare(self.obj, self.picks, self.h)
            self.assertEqual(first.digest, again.digest)
            self.assertEqual(first.digest, addon().job.fingerprint(*evaluated_copy()))
            self.assertAlmostEqual(again.vertices[2], _CFG["vertices"][0][2] + 123.0, places=3)
        self.assertAlmostEqual(again.vertices[3 * 7 + 2], _CFG["vertices"][7][2] + 5.0, places=3)
        self.assertAlmostEqual(again.vertices[3 * 11 + 2], _CFG["vertices"][11][2] - 2.0, places=3)
        bpy.ops.object.mode_set(mode='OBJECT')

    def test_second_run_replaces_group_and_curve(self):
        select_vertices(self.obj, self.picks)
        self.assertEqual(seg(step_height=self.h), {'FINISHED'})
        first = group_members(self.obj, "Relief")
        self.obj.vertex_groups.new(name="Other")
        self.assertEqual(seg(step_height=self.h), {'FINISHED'})
        names = [g.name for g in self.obj.vertex_groups]
        self.assertEqual(sorted(names), ["Other", "Relief"])
        self.assertEqual(group_members(self.obj, "Relief"), first)  # deterministic, and not accumulated
        curves = [o for o in bpy.data.objects if o.type == 'CURVE']
        self.assertEqual([o.name for o in curves], ["Scan_ReliefContour"])
        self.assertEqual(len(bpy.data.curves), 1, "orphan curve data left behind")

    def test_no_curve_when_make_curve_is_off(self):
        select_vertices(self.obj, self.picks)
        self.assertEqual(seg(step_height=self.h, make_curve=False), {'FINISHED'})
        self.assertIn("Relief", self.obj.vertex_groups)
        self.assertEqual([o for o in bpy.data.objects if o.type == 'CURVE'], [])

    def test_curve_follows_the_object_transform(self):
        self.obj.location = (10.0, -5.0, 2.0)
        self.obj.rotation_euler = (0.3, 0.0, 1.0)
        bpy.context.view_layer.update()
        select_vertices(self.obj, self.picks)
        self.assertEqual(seg(step_height=self.h), {'FINISHED'})
        bpy.context.view_layer.update()
        curve = bpy.data.objects[self.obj.name + "_ReliefContour"]
        diff = [abs(a - b) for ra, rb in zip(curve.matrix_world, self.obj.matrix_world) for a, b in zip(ra, rb)]
        self.assertLess(max(diff), 1e-5)

    def test_undo_restores_the_previous_state(self):
        select_vertices(self.obj, self.picks)
        before = snapshot()
        # The first push only initialises the stack in background mode.
        bpy.ops.ed.undo_push(message="setup")
        bpy.ops.ed.undo_push(message="before relief snake")
        # undo=True: push an undo step like a click in the UI does.
        self.assertEqual(bpy.ops.mesh.relief_snake_segment('EXEC_DEFAULT', True, step_height=self.h),
                         {'FINISHED'})
        self.assertIn("Relief", bpy.data.objects["Scan"].vertex_groups)
        self.assertIn("Scan_ReliefContour", bpy.data.objects)
        bpy.ops.ed.undo()
        self.assertEqual(snapshot(), before)
        self.assertNotIn("Relief", bpy.data.objects["Scan"].vertex_groups)
        self.assertNotIn("Scan_ReliefContour", bpy.data.objects)
        bpy.ops.ed.redo()
        self.assertIn("Relief", bpy.data.objects["Scan"].vertex_groups)
        self.assertIn("Scan_ReliefContour", bpy.data.objects)


    def test_edit_mode_second_run_reuses_the_group_and_the_curve(self):
        # The crash sequence of issue 10, headless: Segment, another group name, Segment twice.
        bpy.ops.object.mode_set(mode='EDIT')
        select_vertices(self.obj, self.picks)
        self.assertEqual(seg(step_height=self.h), {'FINISHED'})
        curve = bpy.data.objects["Scan_ReliefContour"]
        curve_data = curve.data
        self.assertEqual(seg(step_height=self.h, group_name="Relief2"), {'FINISHED'})
        group = self.obj.vertex_groups["Relief2"]
        index = group.index
        self.assertEqual(seg(step_height=self.h, group_name="Relief2"), {'FINISHED'})
        self.assertEqual(self.obj.vertex_groups["Relief2"].index, index, "the group was re-created")
        self.assertEqual([g.name for g in self.obj.vertex_groups], ["Relief", "Relief2"])
        self.assertIs(bpy.data.objects["Scan_ReliefContour"], curve, "the curve object was replaced")
        self.assertIs(bpy.data.objects["Scan_ReliefContour"].data, curve_data)
        self.assertEqual(len(bpy.data.curves), 1)
        self.assertTrue(curve.show_in_front)
        self.assertGreater(curve.data.bevel_depth, 0)
        bpy.ops.object.mode_set(mode='OBJECT')
        self.assertEqual(group_members(self.obj, "Relief"), group_members(self.obj, "Relief2"))
        self.assertSegmentationMatchesTruth(self.obj, "Relief2")

    def test_group_is_cleared_before_it_is_refilled(self):
        select_vertices(self.obj, self.picks)
        group = self.obj.vertex_groups.new(name="Relief")
        group.add([0, 1, 2], 1.0, 'REPLACE')  # not part of the relief (corner of the scan)
        self.assertEqual(seg(step_height=self.h), {'FINISHED'})
        self.assertFalse({0, 1, 2} & group_members(self.obj, "Relief"))
        bpy.ops.object.mode_set(mode='EDIT')
        select_vertices(self.obj, self.picks)
        bm = bmesh.from_edit_mesh(self.obj.data)
        layer = bm.verts.layers.deform.verify()
        bm.verts.ensure_lookup_table()
        gi = self.obj.vertex_groups["Relief"].index
        bm.verts[3][layer][gi] = 1.0
        self.assertEqual(seg(step_height=self.h), {'FINISHED'})
        bpy.ops.object.mode_set(mode='OBJECT')
        self.assertNotIn(3, group_members(self.obj, "Relief"))

    def test_rewriting_a_group_leaves_exactly_the_new_vertices_at_weight_one(self):
        # The group keeps its records for the vertices that stay (Object Mode removes only the
        # others): what stays, what goes, what comes and a weight the user changed between runs.
        io = addon().mesh_io
        nv = len(self.obj.data.vertices)
        other = self.obj.vertex_groups.new(name="Other")
        other.add(list(range(0, nv, 5)), 0.25, 'REPLACE')
        first, second = sorted(range(0, 300, 2)), sorted(range(150, 600, 3))
        for mode in ('OBJECT', 'EDIT'):
            bpy.ops.object.mode_set(mode=mode)
            io.write_vertex_group(self.obj, "Relief", first)
            self.assertEqual(group_weights(self.obj, "Relief"), dict.fromkeys(first, 1.0), mode)
            io.write_vertex_group(self.obj, "Relief", second)
            self.assertEqual(group_weights(self.obj, "Relief"), dict.fromkeys(second, 1.0), mode)
            set_weights(self.obj, "Relief", {second[0]: 0.4, 1: 0.7})  # painted: a member, and an outsider
            io.write_vertex_group(self.obj, "Relief", second)
            self.assertEqual(group_weights(self.obj, "Relief"), dict.fromkeys(second, 1.0), mode)
            io.write_vertex_group(self.obj, "Relief", [])
            self.assertEqual(group_weights(self.obj, "Relief"), {}, mode)
            self.assertEqual(group_weights(self.obj, "Other"), dict.fromkeys(range(0, nv, 5), 0.25), mode)
        bpy.ops.object.mode_set(mode='OBJECT')
        self.assertEqual([g.name for g in self.obj.vertex_groups], ["Other", "Relief"])

    def _spy_engine(self):
        """[(picks, result)] of every run_engine call the operator makes, until the test ends."""
        api, calls = addon().api, []
        real = api.run_engine

        def spy(core, request, *args, **kwargs):
            calls.append((list(request.picks), real(core, request, *args, **kwargs)))
            return calls[-1][1]
        api.run_engine = spy
        self.addCleanup(setattr, api, "run_engine", real)
        return calls

    def test_each_run_uses_the_click_order_of_its_own_selection(self):
        # The same vertices picked again in another order between two runs (the mesh unchanged,
        # so the engine's mesh is reused): the second run segments from the new order.
        calls = self._spy_engine()
        for mode in ('OBJECT', 'EDIT'):
            bpy.ops.object.mode_set(mode=mode)
            for order in (self.picks, self.picks[5:] + self.picks[:5], self.picks[::-1]):
                select_vertices(self.obj, order)
                self.assertEqual(seg(step_height=self.h), {'FINISHED'})
                self.assertEqual(calls[-1][0], order, mode)
        self.assertTrue(all(result["mesh_cached"] for _, result in calls[1:]))
        bpy.ops.object.mode_set(mode='OBJECT')
        self.assertSegmentationMatchesTruth(self.obj)

    def test_an_edit_between_runs_moves_the_group_with_the_vertices(self):
        # Three corner vertices deleted between two runs: every later index shifts, the engine's
        # cached mesh no longer fits (new fingerprint) and the group lands on the shifted vertices.
        calls = self._spy_engine()
        for mode in ('OBJECT', 'EDIT'):
            clear_scene()
            self.obj = make_scan_object()
            bpy.ops.object.mode_set(mode=mode)
            select_vertices(self.obj, self.picks)
            self.assertEqual(seg(step_height=self.h), {'FINISHED'})
            first = calls[-1][1]["relief_vertices"]
            gone = [0, 1, 2]  # a corner of the scan, far from the relief
            delete_vertices(self.obj, gone)

            def moved(i):
                return i - sum(1 for g in gone if g < i)
            self.assertEqual(seg(step_height=self.h), {'FINISHED'})
            picks, result = calls[-1]
            self.assertEqual(picks, [moved(i) for i in self.picks], mode)
            self.assertFalse(result["mesh_cached"], mode)
            bpy.ops.object.mode_set(mode='OBJECT')
            members = group_members(self.obj, "Relief")
            self.assertEqual(members, set(result["relief_vertices"]), mode)
            self.assertGreaterEqual(iou(members, [moved(i) for i in first]), 0.99, mode)
            self.assertGreaterEqual(iou(members, [moved(i) for i in self.truth["relief_vertices"]]), IOU_MIN, mode)

    def test_edit_mode_undo_and_redo(self):
        bpy.ops.object.mode_set(mode='EDIT')
        select_vertices(self.obj, self.picks)
        bpy.ops.ed.undo_push(message="setup")
        bpy.ops.ed.undo_push(message="before relief snake")
        self.assertEqual(bpy.ops.mesh.relief_snake_segment('EXEC_DEFAULT', True, step_height=self.h),
                         {'FINISHED'})
        self.assertEqual(self.obj.mode, 'EDIT')

        def members():
            obj = bpy.data.objects["Scan"]  # undo may re-create the Python objects
            bm = bmesh.from_edit_mesh(obj.data)
            layer = bm.verts.layers.deform.active
            group = obj.vertex_groups.get("Relief")
            if layer is None or group is None:
                return set()
            return {v.index for v in bm.verts if v[layer].get(group.index, 0.0) > 0}
        done = members()
        self.assertGreaterEqual(iou(done, self.truth["relief_vertices"]), IOU_MIN)
        bpy.ops.ed.undo()
        self.assertEqual(members(), set())
        bpy.ops.ed.redo()
        self.assertEqual(members(), done)
        bpy.ops.object.mode_set(mode='OBJECT')
        self.obj = bpy.data.objects["Scan"]

    def test_settings_survive_undo(self):
        s = bpy.context.scene.relief_snake
        bpy.ops.ed.undo_push(message="setup")
        s.step_height = 0.5
        bpy.ops.ed.undo_push(message="h typed")
        s.step_height = self.h  # the user types h; then undoes something else
        self.obj.location.x = 3.0
        bpy.ops.ed.undo_push(message="moved")
        bpy.ops.ed.undo()
        self.obj = bpy.data.objects["Scan"]  # undo re-creates the Python objects
        self.assertEqual(self.obj.location.x, 0.0)  # the undo happened
        s = bpy.context.scene.relief_snake
        self.assertAlmostEqual(s.step_height, self.h, places=6)  # and kept what the user typed

    def test_second_run_reuses_the_engine_mesh_until_the_mesh_changes(self):
        api = addon().api
        first = api.segment_object(self.obj, self.picks, self.h, write=False)
        second = api.segment_object(self.obj, self.picks, self.h, write=False)
        self.assertFalse(first["mesh_cached"])
        self.assertTrue(second["mesh_cached"])
        self.assertEqual(second["relief_vertices"], first["relief_vertices"])
        request = api.prepare(self.obj, self.picks, self.h)
        self.assertFalse(api.mesh_changed(self.obj, request))
        self.obj.data.vertices[5].co.z += 0.01
        self.assertTrue(api.mesh_changed(self.obj, request))
        third = api.segment_object(self.obj, self.picks, self.h, write=False)
        self.assertFalse(third["mesh_cached"])

    def test_auto_smoothness_is_the_default(self):
        select_vertices(self.obj, self.picks)
        self.assertTrue(bpy.context.scene.relief_snake.auto_smoothness)
        api = addon().api
        result = api.segment_object(self.obj, self.picks, self.h, write=False)
        self.assertGreaterEqual(iou(result["relief_vertices"], self.truth["relief_vertices"]), IOU_MIN)
        if isinstance(result.get("w_int"), dict):  # the engine chose: nothing was given to it
            self.assertIsNone(result["w_int"]["given"])
            self.assertIn(result["w_int"]["used"], (0.25, 0.5, 1.0))
        else:  # an engine without its own choice: the add-on used 0.25 and says so
            self.assertTrue(any("0.25" in n for n in result["notes"]), result["notes"])


class ErrorPaths(AddonTestCase):
    def assertErrorLeavesSceneUntouched(self, fragment, **kw):
        before = snapshot()
        with self.assertRaises(RuntimeError) as ctx:
            seg(**kw)
        self.assertIn(fragment.lower(), str(ctx.exception).lower())
        self.assertEqual(snapshot(), before)

    def test_no_selection(self):
        select_vertices(self.obj, [])
        self.assertErrorLeavesSceneUntouched("at least 3", step_height=self.h)

    def test_too_few_picks(self):
        select_vertices(self.obj, self.picks[:2])
        self.assertErrorLeavesSceneUntouched("at least 3", step_height=self.h)

    def test_too_few_picks_open(self):
        select_vertices(self.obj, self.picks[:1])
        self.assertErrorLeavesSceneUntouched("at least 2", step_height=self.h, open_contour=True)

    def test_bad_step_height(self):
        select_vertices(self.obj, self.picks)
        self.assertErrorLeavesSceneUntouched("step height", step_height=0.0)

    def test_non_mesh_active_object(self):
        select_vertices(self.obj, self.picks)
        empty = bpy.data.objects.new("Empty", None)
        bpy.context.scene.collection.objects.link(empty)
        bpy.context.view_layer.objects.active = empty
        self.assertErrorLeavesSceneUntouched("mesh object", step_height=self.h)

    def test_no_active_object(self):
        select_vertices(self.obj, self.picks)
        bpy.context.view_layer.objects.active = None
        self.assertErrorLeavesSceneUntouched("mesh object", step_height=self.h)

    def test_empty_group_name(self):
        select_vertices(self.obj, self.picks)
        self.assertErrorLeavesSceneUntouched("vertex group a name", step_height=self.h, group_name="  ")

    def test_existing_results_survive_a_failed_run(self):
        select_vertices(self.obj, self.picks)
        self.assertEqual(seg(step_height=self.h), {'FINISHED'})
        self.assertErrorLeavesSceneUntouched("step height", step_height=0.0)
        self.assertIn("Scan_ReliefContour", bpy.data.objects)

    def test_engine_error_writes_nothing(self):
        api = addon().api
        real = api.load_core()

        class Failing:
            Error, Cancelled = real.Error, real.Cancelled

            class Mesh:
                def __init__(self, *a):
                    pass

                def segment(self, *a, **k):
                    raise real.Error("the snake collapsed: check the step height")

        select_vertices(self.obj, self.picks)
        api._core = Failing
        try:
            self.assertErrorLeavesSceneUntouched("snake collapsed", step_height=self.h)
        finally:
            api._core = real

    def test_cancel_from_progress_writes_nothing(self):
        api = addon().api
        core = api.load_core()
        calls = []

        def progress(phase, iteration, snaxels, contour):
            calls.append((phase, iteration, snaxels, None if contour is None else len(contour)))
            return len(calls) < 3

        before = snapshot()
        with self.assertRaises(core.Cancelled):
            api.segment_object(self.obj, self.picks, self.h, progress=progress)
        self.assertEqual(len(calls), 3)
        snake_calls = [c for c in calls if c[0] != "preprocess"]  # preprocess: before the snake exists
        self.assertTrue(snake_calls, calls)
        self.assertGreater(snake_calls[0][3], 0, "progress got an empty contour")
        self.assertEqual(snapshot(), before)


class RegionView(AddonTestCase):
    def test_segment_keeps_the_region_to_tint_behind_the_toggle(self):
        region_view = addon().region_view
        region_view.hide()
        select_vertices(self.obj, self.picks)
        self.assertEqual(seg(step_height=self.h, show_region=False), {'FINISHED'})
        self.assertNotIn("Scan", region_view.shown())
        self.assertEqual(seg(step_height=self.h, show_region=True), {'FINISHED'})
        self.assertIn("Scan", region_view.shown())
        region_view.hide("Scan")
        self.assertNotIn("Scan", region_view.shown())

    def test_shader_names(self):
        region_view = addon().region_view
        self.assertEqual(region_view.builtin_shader_name((3, 4, 1)), '3D_UNIFORM_COLOR')
        self.assertEqual(region_view.builtin_shader_name((5, 2, 3)), 'UNIFORM_COLOR')


class PickOrder(AddonTestCase):
    def test_click_order_is_used(self):
        order = self.picks[::-1]
        select_vertices(self.obj, order)
        picks, info = addon().api.selected_picks(self.obj)
        self.assertEqual(picks, order)
        self.assertIsNone(info)

    def test_missing_click_order_falls_back_to_angle(self):
        # Angle order can only recover a ring that is star-shaped about its centroid; the
        # duck's picks bend into the neck, so use the picks whose angle (seen along the
        # plane background's z) keeps increasing in the truth's order.
        cx = sum(_CFG["vertices"][i][0] for i in self.picks) / len(self.picks)
        cy = sum(_CFG["vertices"][i][1] for i in self.picks) / len(self.picks)

        def ang(i):
            x, y = _CFG["vertices"][i][0] - cx, _CFG["vertices"][i][1] - cy
            return math.atan2(y, x)
        sense = 1 if sum(math.remainder(ang(b) - ang(a), 2 * math.pi)
                         for a, b in zip(self.picks, self.picks[1:] + self.picks[:1])) > 0 else -1
        star, total = [self.picks[0]], 0.0
        for i in self.picks[1:]:
            step = sense * math.remainder(ang(i) - ang(star[-1]), 2 * math.pi)
            if step > 0 and total + step < 2 * math.pi:
                star.append(i)
                total += step
        self.assertGreaterEqual(len(star), 5)
        shuffled = star[:]
        random.Random(3).shuffle(shuffled)
        select_vertices(self.obj, shuffled, history=False)
        picks, info = addon().api.selected_picks(self.obj)
        self.assertIn("angle", info)
        k = picks.index(star[0])
        rot = picks[k:] + picks[:k]
        self.assertIn(rot, (star, [star[0]] + star[:0:-1]))

    def test_operator_segments_from_unordered_picks(self):
        # All the picks, no click order: the fallback order may zigzag near the neck,
        # which the snake must absorb (the paper starts from zigzag contours too).
        shuffled = self.picks[:]
        random.Random(3).shuffle(shuffled)
        select_vertices(self.obj, shuffled, history=False)
        self.assertEqual(seg(step_height=self.h), {'FINISHED'})
        self.assertSegmentationMatchesTruth(self.obj)

    def test_partial_click_order_falls_back(self):
        select_vertices(self.obj, self.picks)
        bm = bmesh.new()
        bm.from_mesh(self.obj.data)
        bm.verts.ensure_lookup_table()
        bm.select_history.clear()
        for i in self.picks[:2]:
            bm.select_history.add(bm.verts[i])
        bm.to_mesh(self.obj.data)
        bm.free()
        picks, info = addon().api.selected_picks(self.obj)
        self.assertIn("2 of %d" % len(self.picks), info)


def _bmesh_click_order(mesh):
    """The Object Mode click order the slow way: a bmesh copy of the whole mesh."""
    bm = bmesh.new()
    try:
        bm.from_mesh(mesh)
        return [e.index for e in bm.select_history if isinstance(e, bmesh.types.BMVert) and e.select]
    finally:
        bm.free()


class ObjectModeClickOrder(AddonTestCase):
    """Object Mode reads the click order (the mesh's MSelect array) from a scratch .blend of the mesh
    (mesh_io._stored_history) instead of a bmesh copy. It is read again on every Segment (no cache),
    so it must equal bmesh's reading for any history and follow every change of it."""

    def history(self):
        return addon().mesh_io.read_selection(self.obj)[1]

    def set_history(self, order, selected=None, extra=()):
        """Select `selected` (default: order) and store `order` (plus `extra` elements, e.g. a face)
        as the history, through bmesh.to_mesh as a script would."""
        mesh = self.obj.data
        bm = bmesh.new()
        bm.from_mesh(mesh)
        for seq in (bm.verts, bm.edges, bm.faces):
            seq.ensure_lookup_table()
            for e in seq:
                e.select = False
        bm.select_history.clear()
        for i in (order if selected is None else selected):
            bm.verts[i].select = True
        for i in order:
            bm.select_history.add(bm.verts[i])
        for e in extra:
            e = bm.faces[e[1]] if e[0] == 'FACE' else bm.verts[e[1]]
            e.select = True
            bm.select_history.add(e)
        bm.to_mesh(mesh)
        bm.free()
        mesh.update()

    def test_read_without_bmesh_and_the_same_as_bmesh(self):
        rng = random.Random(11)
        nv = len(self.obj.data.vertices)
        calls = []
        real = addon().mesh_io._bmesh_history
        addon().mesh_io._bmesh_history = lambda mesh: calls.append(mesh) or real(mesh)
        try:
            for trial in range(6):
                order = rng.sample(range(nv), rng.randint(1, 12))
                selected = order[:-2] if trial % 2 and len(order) > 3 else order  # unselected history entries
                extra = [('FACE', rng.randrange(len(self.obj.data.polygons)))] if trial % 3 == 0 else []
                self.set_history(order, selected, extra)
                got = self.history()
                self.assertEqual(got, _bmesh_click_order(self.obj.data), trial)
                self.assertEqual(got, [i for i in order if i in set(selected)], trial)
        finally:
            addon().mesh_io._bmesh_history = real
        self.assertEqual(calls, [], "the .blend route failed and bmesh was used")

    def test_a_new_order_of_the_same_selection_is_seen(self):
        # What no cache keyed by the mesh and its selection could see: the same vertices picked
        # again in another order (Edit Mode and back, the usual way, and by a script).
        order = self.picks[:6]
        select_vertices(self.obj, order)
        self.assertEqual(self.history(), order)
        bpy.context.view_layer.objects.active = self.obj
        bpy.ops.object.mode_set(mode='EDIT')
        select_vertices(self.obj, order[::-1])
        bpy.ops.object.mode_set(mode='OBJECT')
        self.assertEqual(self.history(), order[::-1])
        self.set_history(order[2:] + order[:2])
        self.assertEqual(self.history(), order[2:] + order[:2])

    def test_selection_and_mesh_changes_are_seen(self):
        order = self.picks[:5]
        select_vertices(self.obj, order)
        self.assertEqual(self.history(), order)
        # Deselected (as in the UI: the select flag goes, the history entry may stay): not in the order.
        self.obj.data.vertices[order[1]].select = False
        self.assertEqual(self.history(), [order[0]] + order[2:])
        self.obj.data.vertices[order[1]].select = True
        # A vertex added to the history (a sixth pick).
        self.set_history(order + [self.picks[5]])
        self.assertEqual(self.history(), order + [self.picks[5]])
        # The mesh changes (a vertex moves; a group and weights add a block per vertex to the file).
        self.obj.data.vertices[order[0]].co.z += 0.5
        g = self.obj.vertex_groups.new(name="Weights")
        g.add(list(range(0, len(self.obj.data.vertices), 2)), 0.5, 'REPLACE')
        self.assertEqual(self.history(), order + [self.picks[5]])
        self.assertEqual(self.history(), _bmesh_click_order(self.obj.data))
        # An empty history with a selection: nothing, and the operator falls back to angles.
        self.set_history([], selected=order)
        self.assertEqual(self.history(), [])

    def test_a_renamed_or_long_named_mesh(self):
        order = self.picks[:4]
        select_vertices(self.obj, order)
        self.obj.data.name = "Scan with a long name: " + "x" * 30
        self.assertEqual(self.history(), order)

    def test_a_folder_that_cannot_be_written_is_skipped(self):
        order = self.picks[:5]
        select_vertices(self.obj, order)
        io = addon().mesh_io
        real = io._history_file_dirs
        bmesh_real, calls = io._bmesh_history, []
        io._history_file_dirs = lambda: ["/nonexistent/relief-snake"] + real()
        io._bmesh_history = lambda mesh: calls.append(mesh) or bmesh_real(mesh)
        try:
            self.assertEqual(self.history(), order)
        finally:
            io._history_file_dirs, io._bmesh_history = real, bmesh_real
        self.assertEqual(calls, [], "the next folder was not tried")

    def test_falls_back_to_bmesh_when_the_file_cannot_be_read(self):
        order = self.picks[:5]
        select_vertices(self.obj, order)
        blend = addon().blend_history
        real = blend.read_select_history

        def broken(path, name):
            raise blend.Unreadable("a layout this reader does not know")
        blend.read_select_history = broken
        try:
            self.assertEqual(self.history(), order)
        finally:
            blend.read_select_history = real

    def test_the_scratch_file_leaves_no_trace(self):
        select_vertices(self.obj, self.picks[:4])
        import glob
        import os
        import tempfile
        folders = [f or tempfile.gettempdir() for f in addon().mesh_io._history_file_dirs()]

        def scratch():
            return {p for f in folders for p in glob.glob(os.path.join(f, "relief-snake-*.blend"))}
        before = scratch()
        names = [m.name for m in bpy.data.meshes]
        users, dirty = self.obj.data.users, bpy.data.is_dirty
        self.history()
        self.assertEqual(scratch(), before)
        self.assertEqual([m.name for m in bpy.data.meshes], names)
        self.assertEqual((self.obj.data.users, bpy.data.is_dirty), (users, dirty))

    def test_operator_in_object_mode_uses_the_click_order(self):
        select_vertices(self.obj, self.picks)
        self.assertEqual(seg(step_height=self.h), {'FINISHED'})
        self.assertSegmentationMatchesTruth(self.obj)
        self.assertEqual(self.history(), self.picks)  # the group and curve written did not disturb it


class MeasureAndApi(AddonTestCase):
    def test_measure_sets_the_step_height(self):
        a, b = self.picks[0], self.truth["relief_vertices"][0]
        select_vertices(self.obj, [a, b])
        self.assertEqual(bpy.ops.mesh.relief_snake_measure(), {'FINISHED'})
        expected = math.dist(_CFG["vertices"][a], _CFG["vertices"][b])
        self.assertAlmostEqual(bpy.context.scene.relief_snake.step_height, expected, places=4)
        self.assertAlmostEqual(addon().api.measure(self.obj, a, b), expected, places=4)

    def test_measure_needs_two_vertices(self):
        select_vertices(self.obj, self.picks[:3])
        before = snapshot()
        with self.assertRaises(RuntimeError) as ctx:
            bpy.ops.mesh.relief_snake_measure()
        self.assertIn("exactly two", str(ctx.exception))
        self.assertEqual(snapshot(), before)

    def test_api_segment_without_writing(self):
        before = snapshot()
        result = addon().api.segment_object(self.obj, self.picks, self.h, write=False)
        self.assertEqual(snapshot(), before)
        self.assertGreaterEqual(iou(result["relief_vertices"], self.truth["relief_vertices"]), IOU_MIN)
        self.assertTrue(result["closed"])
        for key in ("read", "engine", "write"):
            self.assertIn(key, result["timing"])
        self.assertTrue(result["phases"])

    def test_api_passes_advanced_options_to_the_engine(self):
        api = addon().api
        result = api.segment_object(self.obj, self.picks, self.h, write=False, options={"tau": 0.25, "threads": 1})
        self.assertEqual(result["parameters"]["tau"], 0.25)
        self.assertEqual(result["parameters"]["threads"], 1)
        before = snapshot()
        with self.assertRaises(api.EngineError) as ctx:
            api.segment_object(self.obj, self.picks, self.h, options={"bogus": 1})
        self.assertIn("bogus", str(ctx.exception))
        with self.assertRaises(api.EngineError) as ctx:
            api.segment_object(self.obj, self.picks, self.h, options={"tau": 5.0})
        self.assertIn("tau", str(ctx.exception))
        with self.assertRaises(api.EngineError):
            api.segment_object(self.obj, self.picks, self.h, options={"w_int": 0.5})
        self.assertEqual(snapshot(), before)

    def test_api_rejects_bad_picks(self):
        api = addon().api
        with self.assertRaises(api.EngineError) as ctx:
            api.segment_object(self.obj, [0, 1, 10 ** 9], self.h)
        self.assertIn("not a vertex", str(ctx.exception))

    def test_preview_makes_no_shader_in_background(self):
        preview = addon().preview
        self.assertEqual(preview.builtin_shader_name((3, 4, 1)), '3D_POLYLINE_UNIFORM_COLOR')
        self.assertEqual(preview.builtin_shader_name((4, 2, 0)), 'POLYLINE_UNIFORM_COLOR')
        preview.start()
        self.assertFalse(preview.is_active())
        self.assertIsNone(preview._shader)


class OpenContour(AddonTestCase):
    """An open relief: a disk cut by the mesh's right edge. The picks run from border to border
    with the relief on their left (truth["relief_side"]); the contour must end on the border and
    its curve must not be cyclic."""

    def setUp(self):
        scan = _CFG["open"]
        clear_scene()
        self.truth = scan["truth"]
        self.h = float(self.truth["h"])
        self.picks = list(self.truth["picks"])
        self.side = self.truth["relief_side"].upper()
        self.assertFalse(self.truth["picks_closed"])
        self.assertIn(self.side, ('LEFT', 'RIGHT'))
        self.other_side = 'RIGHT' if self.side == 'LEFT' else 'LEFT'
        self.obj = make_scan_object(scan=scan)

    def assertEndsOnTheBorder(self, obj):
        spline = bpy.data.objects[obj.name + "_ReliefContour"].data.splines[0]
        ends = [tuple(spline.points[0].co)[:3], tuple(spline.points[-1].co)[:3]]
        line = self.truth["boundary"][0]
        truth_ends = [tuple(line[0]), tuple(line[-1])]
        edge = self.truth["average_edge"]
        for end in ends:
            d = min(math.dist(end, t) for t in truth_ends)
            self.assertLess(d, 2 * edge, "contour end %s is %.3g from the true boundary's ends" % (end, d))
        # one end at each end of the true boundary, not both at the same one
        self.assertNotEqual(min(truth_ends, key=lambda t: math.dist(ends[0], t)),
                            min(truth_ends, key=lambda t: math.dist(ends[1], t)))

    def test_open_contour_segments_the_relief(self):
        select_vertices(self.obj, self.picks)
        self.assertEqual(seg(step_height=self.h, open_contour=True, relief_side=self.side), {'FINISHED'})
        self.assertSegmentationMatchesTruth(self.obj, closed=False)
        self.assertEndsOnTheBorder(self.obj)
        self.assertIn("open outline", bpy.context.scene.relief_snake.last_summary)

    def test_reversed_picks_take_the_other_side(self):
        # The side is relative to the click order: the same picks clicked backwards put the
        # relief on the other side.
        select_vertices(self.obj, self.picks[::-1])
        self.assertEqual(seg(step_height=self.h, open_contour=True, relief_side=self.other_side), {'FINISHED'})
        self.assertSegmentationMatchesTruth(self.obj, closed=False)
        self.assertEndsOnTheBorder(self.obj)

    def test_auto_side_finds_the_relief_and_names_the_side(self):
        # Relief Side Auto (the default): the engine decides the side from the surface, in either
        # click order, and the summary says which side it used.
        settings = bpy.context.scene.relief_snake
        self.assertEqual(settings.bl_rna.properties["relief_side"].default, 'AUTO')
        for picks, side in ((self.picks, self.side), (self.picks[::-1], self.other_side)):
            select_vertices(self.obj, picks)
            self.assertEqual(seg(step_height=self.h, open_contour=True, relief_side='AUTO'), {'FINISHED'})
            self.assertSegmentationMatchesTruth(self.obj, closed=False)
            self.assertIn("relief %s of the picks" % side.lower(), bpy.context.scene.relief_snake.last_summary)

    def test_wrong_side_does_not_find_the_relief_and_says_so(self):
        # Told the relief is on the other side, the snake deflates away from it over flat
        # background: the engine still returns a region (not the relief), and its self-check
        # flags it as doubtful, which the add-on shows as the warning.
        select_vertices(self.obj, self.picks)
        ret = seg(step_height=self.h, open_contour=True, relief_side=self.other_side)
        self.assertEqual(ret, {'FINISHED'})
        score = iou(group_members(self.obj, "Relief"), self.truth["relief_vertices"])
        self.assertLess(score, 0.5, "the wrong relief side still gave IoU %.3f" % score)
        warning = bpy.context.scene.relief_snake.last_warning
        self.assertIn("step", warning, "the doubtful result came without the self-check's warning")



def ring_scan(n=120, size=40.0, inner=5.0, outer=12.0):
    """A raised annulus (h = 1, a sharp step) on a flat grid: a relief with one inner hole.
    Returns the scan dict for make_scan_object, the picks round it and the truth's relief set."""
    step = size / (n - 1)
    vertices, faces, relief = [], [], set()
    for j in range(n):
        for i in range(n):
            x, y = -0.5 * size + i * step, -0.5 * size + j * step
            r = math.hypot(x, y)
            up = inner < r < outer
            if up:
                relief.add(len(vertices))
            vertices.append((x, y, 1.0 if up else 0.0))
    for j in range(n - 1):
        for i in range(n - 1):
            a, b, c, d = j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i
            faces += [(a, b, c), (a, c, d)]
    picks = []
    for k in range(10):
        t = 2 * math.pi * k / 10
        x, y = 15.0 * math.cos(t), 15.0 * math.sin(t)
        picks.append(int(round((y + 0.5 * size) / step)) * n + int(round((x + 0.5 * size) / step)))
    return {"vertices": vertices, "faces": faces}, picks, relief


class WholeReliefs(AddonTestCase):
    """Issue 13: one curve object with one spline per contour; the group leaves the holes out."""

    def test_each_contour_is_a_spline_of_one_curve(self):
        api = addon().api
        outline = [(math.cos(t) * 10, math.sin(t) * 10, 0.0) for t in (2 * math.pi * k / 40 for k in range(40))]
        hole_a = [(p[0] * 0.3 - 3, p[1] * 0.3, 0.0) for p in outline]
        hole_b = [(p[0] * 0.3 + 3, p[1] * 0.3, 0.0) for p in outline]
        result = {"contour": outline, "closed": True, "holes": [hole_a, hole_b], "band_contour": [],
                  "relief_vertices": [0, 1, 2]}
        api.apply_result(self.obj, result)
        curve = bpy.data.objects[self.obj.name + "_ReliefContour"]
        self.assertEqual(len(curve.data.splines), 3)
        self.assertTrue(all(s.use_cyclic_u for s in curve.data.splines))
        self.assertEqual([len(s.points) for s in curve.data.splines], [40, 40, 40])
        self.assertEqual(group_members(self.obj, "Relief"), {0, 1, 2})
        # A second result without holes refills the same object with one spline.
        api.apply_result(self.obj, {"contour": outline, "closed": True, "relief_vertices": [0]})
        self.assertEqual(len(bpy.data.objects[self.obj.name + "_ReliefContour"].data.splines), 1)

    def test_ring_hole_is_left_out_of_the_group(self):
        clear_scene()
        scan, picks, truth = ring_scan()
        obj = make_scan_object("Ring", scan=scan)
        api = addon().api
        result = api.segment_object(obj, picks, 1.0)
        self.assertEqual(len(result["holes"]), 1, result.get("message"))
        curve = bpy.data.objects[obj.name + "_ReliefContour"]
        self.assertEqual(len(curve.data.splines), 2)
        members = group_members(obj, "Relief")
        self.assertGreaterEqual(iou(members, truth), 0.9)
        centre = 60 * 120 + 60  # (0.17, 0.17): in the hole
        self.assertNotIn(centre, members)
        # holes='off' keeps the island in the relief and draws the outline alone.
        result = api.segment_object(obj, picks, 1.0, options={"holes": "off"})
        self.assertEqual(result["holes"], [])
        self.assertIn(centre, group_members(obj, "Relief"))
        self.assertEqual(len(bpy.data.objects[obj.name + "_ReliefContour"].data.splines), 1)


class _Recorder:
    """A window manager and workspace that record what the modal path asks of them (headless
    Blender has no window to add a timer to)."""

    def __init__(self):
        self.calls = []
        self.status = "unset"

    def event_timer_remove(self, timer):
        self.calls.append(("timer_remove", timer))

    def progress_begin(self, lo, hi):
        self.calls.append(("progress_begin", lo, hi))

    def progress_update(self, value):
        self.calls.append(("progress_update", value))

    def progress_end(self):
        self.calls.append(("progress_end",))

    def status_text_set(self, text):
        self.status = text


class _Context:
    """bpy.context with the window manager and workspace replaced by a _Recorder."""

    def __init__(self, recorder):
        self._recorder = recorder

    def __getattr__(self, name):
        if name in ("window_manager", "workspace"):
            return self._recorder
        if name == "screen":
            return None
        return getattr(bpy.context, name)


class _Event:
    def __init__(self, type, value='NOTHING'):
        self.type, self.value = type, value


class ModalPath(AddonTestCase):
    """The interactive run (invoke -> timer ticks -> modal -> cleanup) without a window: the
    operator's own modal(), _modal_step(), _start() and _cleanup() on a stand-in operator whose
    settings are the scene's, ticked by fake TIMER events."""

    def make_operator(self, **settings):
        cls = addon().operators.MESH_OT_relief_snake_segment
        reports = []

        class Stand_in:
            _job = None
            _obj_name = None
            _shown_serial = -1
            _timer = "the timer"
            _progress_on = False

            def report(self, kind, text):
                reports.append((set(kind), text))

        for name in ("modal", "_modal_step", "_start", "_prepare", "_finish", "_cleanup", "_status", "_current_run",
                     "_set_current_run", "_hold_edit_bmesh", "_release_edit_bmesh"):
            setattr(Stand_in, name, getattr(cls, name))
        op = Stand_in()
        s = bpy.context.scene.relief_snake
        for name in addon().properties.SETTING_NAMES:
            setattr(op, name, settings.get(name, getattr(s, name)))
        cls._modal = op  # as invoke() registers it
        return cls, op, reports

    def tick_until_done(self, op, context, limit=6000):
        for _ in range(limit):
            ret = op.modal(context, _Event('TIMER'))
            if 'RUNNING_MODAL' not in ret:
                return ret
            time.sleep(0.01)
        self.fail("the modal run did not end")

    def assertCleanedUp(self, cls, op, recorder):
        self.assertIn(("timer_remove", "the timer"), recorder.calls)
        self.assertIsNone(op._timer)
        self.assertIsNone(cls._modal, "a later Segment would say 'already running'")
        self.assertIsNone(recorder.status)
        self.assertFalse(op._progress_on)

    def test_timer_ticks_run_the_job_and_write_the_result(self):
        select_vertices(self.obj, self.picks)
        cls, op, reports = self.make_operator(step_height=self.h, estimate_step_height=False)
        recorder = _Recorder()
        context = _Context(recorder)
        # Events other than the timer pass through while it runs (the user navigates the view).
        self.assertEqual(op.modal(context, _Event('MOUSEMOVE')), {'PASS_THROUGH'})
        self.assertIs(cls._modal, op)
        ret = self.tick_until_done(op, context)
        self.assertEqual(ret, {'FINISHED'}, reports)
        self.assertIn(("progress_begin", 0, len(addon().operators.PHASES)), recorder.calls)
        self.assertIn(("progress_end",), recorder.calls)
        self.assertCleanedUp(cls, op, recorder)
        self.assertSegmentationMatchesTruth(self.obj)

    def test_edit_mode_holds_one_bmesh_handle_from_the_read_to_the_write(self):
        # The read and the write share one handle (mesh_io.hold_edit_bmesh), dropped once the
        # weights are written; leaving Edit Mode while it is held (Blender frees the edit bmesh)
        # only invalidates it, and the run still writes, now through the mesh data.
        for leave in (False, True):
            clear_scene()
            self.obj = make_scan_object()
            bpy.ops.object.mode_set(mode='EDIT')
            select_vertices(self.obj, self.picks)
            cls, op, reports = self.make_operator(step_height=self.h, estimate_step_height=False)
            recorder = _Recorder()
            context = _Context(recorder)
            self.assertEqual(op.modal(context, _Event('TIMER')), {'RUNNING_MODAL'})  # read, worker started
            self.assertIsNotNone(op._held_bmesh)
            self.assertIs(bmesh.from_edit_mesh(self.obj.data), op._held_bmesh)
            if leave:
                bpy.ops.object.mode_set(mode='OBJECT')
                self.assertFalse(op._held_bmesh.is_valid)
            ret = self.tick_until_done(op, context)
            self.assertEqual(ret, {'FINISHED'}, reports)
            self.assertIsNone(op._held_bmesh)
            self.assertCleanedUp(cls, op, recorder)
            if not leave:
                bpy.ops.object.mode_set(mode='OBJECT')
            self.assertSegmentationMatchesTruth(self.obj)

    def test_esc_cancels_and_writes_nothing(self):
        select_vertices(self.obj, self.picks)
        before = snapshot()
        cls, op, reports = self.make_operator(step_height=self.h, estimate_step_height=False)
        recorder = _Recorder()
        context = _Context(recorder)
        self.assertEqual(op.modal(context, _Event('TIMER')), {'RUNNING_MODAL'})  # the job starts
        self.assertIsNotNone(op._job)
        self.assertEqual(op.modal(context, _Event('ESC', 'PRESS')), {'CANCELLED'})
        self.assertTrue(op._job.cancel_requested)
        self.assertCleanedUp(cls, op, recorder)
        op._job.join(120)
        self.assertTrue(op._job.done)
        self.assertIsNone(op._job.result)  # the worker's result is dropped
        self.assertEqual(snapshot(), before)

    def test_an_exception_in_a_modal_step_leaves_nothing_behind(self):
        select_vertices(self.obj, self.picks)
        before = snapshot()
        cls, op, reports = self.make_operator(step_height=self.h, estimate_step_height=False)
        recorder = _Recorder()
        context = _Context(recorder)
        self.assertEqual(op.modal(context, _Event('TIMER')), {'RUNNING_MODAL'})

        def broken(self, context, event):
            raise KeyError("a bug in a modal step")

        type(op)._modal_step = broken
        self.assertEqual(op.modal(context, _Event('TIMER')), {'CANCELLED'})
        self.assertTrue(any("KeyError" in text for _, text in reports), reports)
        self.assertCleanedUp(cls, op, recorder)
        self.assertTrue(op._job.cancel_requested)  # the worker is told to stop
        op._job.join(120)
        self.assertEqual(snapshot(), before)


# -- several reliefs (issue 13, part 2): pick groups from vertex groups, detect and the candidate list --

def _plate():
    """A plate with several reliefs (make-scan --plate 2, 40k triangles: two touching boxes, two disks
    and a tiny disk) and its truth, made once."""
    if "plate" not in _CFG:
        import json
        import os
        import shutil
        import subprocess
        import tempfile
        build = os.environ.get("RELIEF_SNAKE_BUILD_DIR") or os.path.join(
            os.path.dirname(os.path.abspath(__file__)), "..", "..", "build")
        prefix = os.path.join(tempfile.mkdtemp(prefix="relief-plate-"), "plate")
        subprocess.run([os.path.join(build, "make-scan"), "--plate", "2", "--triangles", "40000", "--out", prefix],
                       check=True, stdout=subprocess.DEVNULL)
        vertices, faces = plyio.read_ply(prefix + ".ply")
        with open(prefix + ".truth.json") as f:
            truth = json.load(f)
        shutil.rmtree(os.path.dirname(prefix), ignore_errors=True)
        _CFG["plate"] = {"vertices": vertices, "faces": faces, "truth": truth}
    return _CFG["plate"]


class SeveralReliefs(AddonTestCase):
    def _plate_object(self):
        return make_scan_object("Plate", _plate())

    def test_detect_lists_candidates_and_applies_the_accepted(self):
        obj = self._plate_object()
        truth = _plate()["truth"]
        self.assertEqual(bpy.ops.mesh.relief_snake_detect(), {'FINISHED'})
        items = bpy.context.scene.relief_snake_candidates
        doc = addon().multi.DETECTIONS[obj.name_full]
        big = [r for r in truth["reliefs"] if r["area"] >= doc["parameters"]["min_area"]]
        self.assertEqual(len(items), len(big))
        # Reject the first candidate, accept every other one.
        for k, item in enumerate(items):
            item.accepted = k != 0
        self.assertEqual(bpy.ops.mesh.relief_snake_apply_candidates(), {'FINISHED'})
        names = [g.name for g in obj.vertex_groups]
        self.assertNotIn("Relief.Candidate1", names)
        for k in range(1, len(items)):
            name = "Relief.Candidate%d" % (k + 1)
            self.assertIn(name, names)
            members = group_members(obj, name)
            self.assertEqual(members, set(doc["candidates"][k]["relief_vertices"]))
            self.assertGreaterEqual(max(iou(members, r["vertices"]) for r in big), 0.9)
            curve = bpy.data.objects.get("Plate_%sContour" % name)
            self.assertIsNotNone(curve)
            self.assertEqual(curve.parent, obj)
        # The default contour curve of a normal segmentation is not taken.
        self.assertIsNone(bpy.data.objects.get("Plate_ReliefContour"))

    def test_pick_groups_from_vertex_groups(self):
        obj = self._plate_object()
        truth = _plate()["truth"]
        # The outline picks of two separate reliefs (from detect without the snake), stored as vertex
        # groups: no click order, so the add-on orders them by angle.
        doc = addon().multi.detect_object(obj, refine=False)
        separate = [c for c in doc["candidates"] if c["detection"]["plateau"] == 0][:2]
        self.assertEqual(len(separate), 2)
        for name, c in zip(("Picks.A", "Picks.B"), separate):
            g = obj.vertex_groups.new(name=name)
            g.add(list(reversed(c["parameters"]["picks"])), 1.0, 'REPLACE')
        obj.vertex_groups.new(name="Other")
        bpy.context.scene.relief_snake.estimate_step_height = True
        self.assertEqual(bpy.ops.mesh.relief_snake_segment_groups(prefix="Picks"), {'FINISHED'})
        for name in ("Relief.A", "Relief.B"):
            members = group_members(obj, name)
            self.assertGreaterEqual(max(iou(members, r["vertices"]) for r in truth["reliefs"]), 0.9, name)
            self.assertIsNotNone(bpy.data.objects.get("Plate_%sContour" % name))
        self.assertNotEqual(group_members(obj, "Relief.A"), group_members(obj, "Relief.B"))

    def test_pick_group_errors(self):
        obj = self._plate_object()
        before = snapshot()
        with self.assertRaisesRegex(RuntimeError, "No vertex group of 'Plate' starts with 'Picks'"):
            bpy.ops.mesh.relief_snake_segment_groups(prefix="Picks")
        self.assertEqual(snapshot(), before)
        g = obj.vertex_groups.new(name="Picks1")
        g.add([0, 1], 1.0, 'REPLACE')
        with self.assertRaisesRegex(addon().job.EngineError, "at least 3"):
            addon().multi.segment_vertex_groups(obj, "Picks")
        self.assertEqual([x.name for x in obj.vertex_groups], ["Picks1"])


class _WindowRecorder(_Recorder):
    """A _Recorder that also takes a timer and a modal handler, and keeps every status text."""

    def __init__(self):
        super().__init__()
        self.statuses = []

    def event_timer_add(self, seconds, window=None):
        self.calls.append(("timer_add", seconds))
        return "the timer"

    def modal_handler_add(self, op):
        self.calls.append(("modal_handler_add",))

    def status_text_set(self, text):
        super().status_text_set(text)
        self.statuses.append(text)


class _WindowContext(_Context):
    window = "a window"


class SeveralReliefsModal(AddonTestCase):
    """Detect and Segment Pick Groups run interactively like Segment: invoke -> timer ticks -> the
    engine in a worker -> the result written on the main thread; Esc cancels and changes nothing.
    Driven headless through the operators' own methods on a stand-in (as ModalPath does)."""

    METHODS = ("_invoke_modal", "_begin_modal", "_current_run", "_set_current_run", "modal", "_modal_step", "_start",
               "_cleanup", "_status", "cancel", "_read", "_status_text", "_finish", "_report_done")

    def setUp(self):
        super().setUp()
        self.plate = make_scan_object("Plate", _plate())
        bpy.context.view_layer.objects.active = self.plate
        self.plate.select_set(True)
        bpy.context.scene.relief_snake_candidates.clear()
        addon().multi.DETECTIONS.clear()

    def tearDown(self):
        addon().multi._ModalRun.running = None
        addon().operators.MESH_OT_relief_snake_segment._modal = None
        super().tearDown()

    def make_operator(self, cls, **attrs):
        reports = []

        class Stand_in:
            _job = None
            _obj_name = None
            _shown_serial = -1
            _timer = None
            _progress_on = False

            def report(self, kind, text):
                reports.append((set(kind), text))

        for name in self.METHODS:
            setattr(Stand_in, name, getattr(cls, name))
        op = Stand_in()
        for k, v in attrs.items():
            setattr(op, k, v)
        return op, reports

    def start(self, cls, **attrs):
        op, reports = self.make_operator(cls, **attrs)
        recorder = _WindowRecorder()
        context = _WindowContext(recorder)
        self.assertEqual(op._invoke_modal(context), {'RUNNING_MODAL'}, reports)
        self.assertIs(addon().multi.busy(), op)
        self.assertEqual(recorder.status, "Relief Snake: reading mesh... (Esc cancels)")  # before any read
        self.assertIsNone(op._job)
        return op, reports, recorder, context

    def tick_until_done(self, op, context, limit=12000):
        for _ in range(limit):
            ret = op.modal(context, _Event('TIMER'))
            if 'RUNNING_MODAL' not in ret:
                return ret
            time.sleep(0.01)
        self.fail("the modal run did not end")

    def assertCleanedUp(self, op, recorder):
        self.assertIn(("timer_remove", "the timer"), recorder.calls)
        self.assertIsNone(op._timer)
        self.assertIsNone(addon().multi.busy(), "a later run would say 'already running'")
        self.assertIsNone(recorder.status)
        self.assertFalse(op._progress_on)

    def pick_groups(self):
        """Picks.A and Picks.B: the outline picks of two separate reliefs (detect without the snake)."""
        doc = addon().multi.detect_object(self.plate, refine=False)
        addon().multi.DETECTIONS.clear()
        separate = [c for c in doc["candidates"] if c["detection"]["plateau"] == 0][:2]
        self.assertEqual(len(separate), 2)
        for name, c in zip(("Picks.A", "Picks.B"), separate):
            g = self.plate.vertex_groups.new(name=name)
            g.add(list(reversed(c["parameters"]["picks"])), 1.0, 'REPLACE')
        bpy.context.scene.relief_snake.estimate_step_height = True

    def test_detect_runs_in_a_worker_and_fills_the_list(self):
        cls = addon().multi.MESH_OT_relief_snake_detect
        op, reports, recorder, context = self.start(cls)
        self.assertEqual(op.modal(context, _Event('MOUSEMOVE')), {'PASS_THROUGH'})  # the view stays usable
        self.assertEqual(op.modal(context, _Event('TIMER')), {'RUNNING_MODAL'})  # reads, starts the worker
        self.assertTrue(op._job.running or op._job.done)
        self.assertEqual(len(bpy.context.scene.relief_snake_candidates), 0)  # nothing before the end
        ret = self.tick_until_done(op, context)
        self.assertEqual(ret, {'FINISHED'}, reports)
        self.assertCleanedUp(op, recorder)
        doc = addon().multi.DETECTIONS[self.plate.name_full]
        truth = _plate()["truth"]
        big = [r for r in truth["reliefs"] if r["area"] >= doc["parameters"]["min_area"]]
        self.assertEqual(len(bpy.context.scene.relief_snake_candidates), len(big))
        self.assertTrue(any(t and "candidate" in t and "Esc cancels" in t for t in recorder.statuses),
                        recorder.statuses)
        self.assertIn(({'INFO'}, "%d candidates found" % len(big)), reports)

    def test_detect_reports_its_first_stages_and_counts_the_candidates(self):
        # The engine calls progress while it fits the background and once it knows the candidates,
        # before any refinement; the status bar says so, then "candidate k of n".
        cls = addon().multi.MESH_OT_relief_snake_detect
        op, _ = self.make_operator(cls)
        obj, vertices, triangles, work, _total = op._read(_WindowContext(_WindowRecorder()))
        calls = []
        doc = work(addon().api.load_core().Mesh(vertices, triangles),
                   lambda index, phase, iteration, snaxels, contour: calls.append((phase, iteration, index)) or True)
        phases = [c[0] for c in calls]
        self.assertEqual(phases[:4], ["background"] * 3 + ["candidates"], phases[:8])
        self.assertNotIn("background", phases[4:])
        found = calls[3][1]
        self.assertGreaterEqual(found, len(doc["candidates"]))
        self.assertEqual(op._found, [found])
        self.assertEqual({c[2] for c in calls[4:]}, set(range(found)))  # each candidate refined after the count
        Snapshot = addon().job.Snapshot
        self.assertIn("fitting the background", op._status_text(Snapshot("background", 1, seconds=2.0)))
        self.assertIn("%d candidates above the background" % found,
                      op._status_text(Snapshot("candidates", found, seconds=2.0)))
        self.assertIn("candidate 2 of %d: refining" % found, op._status_text(Snapshot("refine", 10, 40, index=1)))
        # Cancelled while the background is fitted: the engine stops there, before any refinement.
        calls.clear()
        with self.assertRaises(addon().api.load_core().Cancelled):
            work(addon().api.load_core().Mesh(vertices, triangles),
                 lambda index, phase, iteration, snaxels, contour: calls.append(phase) or False)
        self.assertEqual(calls, ["background"])

    def test_detect_esc_leaves_everything_as_it_was(self):
        items = bpy.context.scene.relief_snake_candidates
        items.add().name = "An earlier candidate"
        before = snapshot()
        cls = addon().multi.MESH_OT_relief_snake_detect
        op, reports, recorder, context = self.start(cls)
        self.assertEqual(op.modal(context, _Event('TIMER')), {'RUNNING_MODAL'})
        for _ in range(3):
            op.modal(context, _Event('TIMER'))
            time.sleep(0.02)
        self.assertFalse(op._job.done, "detect ended before Esc could be tested")
        self.assertEqual(op.modal(context, _Event('ESC', 'PRESS')), {'CANCELLED'})
        self.assertTrue(op._job.cancel_requested)
        self.assertCleanedUp(op, recorder)
        self.assertTrue(op._job.join(120))
        self.assertTrue(op._job.cancelled)
        self.assertIsNone(op._job.result)
        self.assertEqual([i.name for i in items], ["An earlier candidate"])
        self.assertNotIn(self.plate.name_full, addon().multi.DETECTIONS)
        self.assertEqual(snapshot(), before)
        self.assertIn(({'WARNING'}, "Relief Snake cancelled: nothing was changed"), reports)

    def test_pick_groups_run_in_a_worker_and_write_the_reliefs(self):
        self.pick_groups()
        cls = addon().multi.MESH_OT_relief_snake_segment_groups
        op, reports, recorder, context = self.start(cls, prefix="Picks")
        ret = self.tick_until_done(op, context)
        self.assertEqual(ret, {'FINISHED'}, reports)
        self.assertCleanedUp(op, recorder)
        self.assertIn(("progress_begin", 0, 2), recorder.calls)
        self.assertIn(("progress_end",), recorder.calls)
        self.assertTrue(any(t and "of 2 (Picks." in t for t in recorder.statuses), recorder.statuses)
        truth = _plate()["truth"]
        for name in ("Relief.A", "Relief.B"):
            members = group_members(self.plate, name)
            self.assertGreaterEqual(max(iou(members, r["vertices"]) for r in truth["reliefs"]), 0.9, name)
            self.assertIsNotNone(bpy.data.objects.get("Plate_%sContour" % name))

    def test_pick_groups_esc_changes_nothing(self):
        self.pick_groups()
        before = snapshot()
        groups_before = [g.name for g in self.plate.vertex_groups]
        cls = addon().multi.MESH_OT_relief_snake_segment_groups
        op, reports, recorder, context = self.start(cls, prefix="Picks")
        self.assertEqual(op.modal(context, _Event('TIMER')), {'RUNNING_MODAL'})
        op.modal(context, _Event('TIMER'))
        self.assertEqual(op.modal(context, _Event('ESC', 'PRESS')), {'CANCELLED'})
        self.assertCleanedUp(op, recorder)
        self.assertTrue(op._job.join(120))
        self.assertIsNone(op._job.result)
        self.assertEqual([g.name for g in self.plate.vertex_groups], groups_before)
        self.assertEqual(snapshot(), before)
        self.assertIsNone(bpy.data.objects.get("Plate_Relief.AContour"))

    def test_a_mesh_edited_during_the_run_gets_nothing(self):
        self.pick_groups()
        cls = addon().multi.MESH_OT_relief_snake_segment_groups
        op, reports, recorder, context = self.start(cls, prefix="Picks")
        self.assertEqual(op.modal(context, _Event('TIMER')), {'RUNNING_MODAL'})
        self.plate.data.vertices[0].co.z += 0.25  # the user edits while it runs (PASS_THROUGH)
        ret = self.tick_until_done(op, context)
        self.assertEqual(ret, {'CANCELLED'})
        self.assertTrue(any("mesh changed" in text for _, text in reports), reports)
        self.assertNotIn("Relief.A", [g.name for g in self.plate.vertex_groups])
        self.assertCleanedUp(op, recorder)

    def test_one_run_at_a_time(self):
        multi = addon().multi
        segment = addon().operators.MESH_OT_relief_snake_segment
        first, _, recorder, context = self.start(multi.MESH_OT_relief_snake_detect)
        for cls, attrs in ((multi.MESH_OT_relief_snake_detect, {}),
                           (multi.MESH_OT_relief_snake_segment_groups, {"prefix": "Picks"})):
            second, reports = self.make_operator(cls, **attrs)
            self.assertEqual(second._invoke_modal(context), {'CANCELLED'})
            self.assertIn(({'ERROR'}, "Relief Snake is already running: wait for it or press Esc"), reports)
        # Segment refuses too while a several-reliefs run goes, and the other way round.
        seg_op = type("Segment_stand_in", (), {"_invoke_modal": segment._invoke_modal,
                                               "report": lambda self, kind, text: seg_reports.append(text)})()
        seg_reports = []
        self.assertEqual(seg_op._invoke_modal(context), {'CANCELLED'})
        self.assertIn("already running", seg_reports[0])
        self.assertEqual(first.modal(context, _Event('ESC', 'PRESS')), {'CANCELLED'})
        self.assertIsNone(multi.busy())
        segment._modal = "a Segment run"
        second, reports = self.make_operator(multi.MESH_OT_relief_snake_detect)
        self.assertEqual(second._invoke_modal(context), {'CANCELLED'})
        segment._modal = None

    def test_an_exception_in_a_modal_step_leaves_nothing_behind(self):
        before = snapshot()
        cls = addon().multi.MESH_OT_relief_snake_detect
        op, reports, recorder, context = self.start(cls)
        self.assertEqual(op.modal(context, _Event('TIMER')), {'RUNNING_MODAL'})

        def broken(self, context, event):
            raise KeyError("a bug in a modal step")

        type(op)._modal_step = broken
        self.assertEqual(op.modal(context, _Event('TIMER')), {'CANCELLED'})
        self.assertTrue(any("KeyError" in text for _, text in reports), reports)
        self.assertCleanedUp(op, recorder)
        self.assertTrue(op._job.cancel_requested)
        op._job.join(120)
        self.assertEqual(snapshot(), before)

    def test_scripts_still_run_synchronously(self):
        # EXEC_DEFAULT (and invoke in background mode) is execute(): done when the call returns.
        self.assertEqual(bpy.ops.mesh.relief_snake_detect('EXEC_DEFAULT'), {'FINISHED'})
        self.assertGreater(len(bpy.context.scene.relief_snake_candidates), 0)
        self.assertEqual(bpy.ops.mesh.relief_snake_detect('INVOKE_DEFAULT'), {'FINISHED'})
        self.assertIsNone(addon().multi.busy())
