"""Several reliefs in one go (issue 13, part 2): pick groups from vertex groups, and automatic
detection with a list of candidates to accept or reject.

    from relief_snake import multi
    doc = multi.segment_vertex_groups(obj, prefix="Picks")   # one snake per group "Picks*"
    doc = multi.detect_object(obj)                           # candidates, nothing written
    multi.apply_candidates(obj, doc, [0, 2])                 # accepted ones -> groups + curves

Each vertex group whose name starts with the prefix is one relief's picks; a vertex group has no
click order, so its vertices are ordered by angle around their centroid (pick_order). Results are
written like a normal segmentation: a vertex group per relief ("Relief" + what follows the prefix,
e.g. "Picks.Lion" -> "Relief.Lion") and an outline curve "<obj>_<group>Contour" per relief.
Both operators run like Segment: synchronously from execute() (scripts, EXEC_DEFAULT, background
mode), and as modal operators from invoke() in a window: the mesh is read on the main thread, the
engine (mesh intake included) runs in a job.MeshJob worker, a timer shows its progress in the
status bar and the evolving outline in the viewport, and Esc cancels. Nothing is written before
the engine is done, so a cancel or a failure leaves the scene as it was. One interactive run at a
time, Segment's included.
"""

import bpy

from . import api, job, mesh_io, modal_run, pick_order, preview, properties, summary
from .job import MESH_CACHE, EngineError, fingerprint

__all__ = ["groups_from_vertex_groups", "segment_vertex_groups", "detect_object", "apply_candidates",
           "write_relief"]

# The last detection per object (name_full -> document): the candidate list shows it.
DETECTIONS = {}


def _read_mesh(obj):
    """(vertices, triangles) of what the user sees of obj now (Edit Mode: the edit mesh)."""
    api._mesh_object(obj)
    with mesh_io.live_mesh(obj) as live:
        vertices, triangles = mesh_io.read_buffers(live)
    if not triangles:
        raise EngineError("The mesh %r has no faces: Relief Snake needs a triangle/polygon surface" % obj.name)
    return vertices, triangles


def _engine_mesh(obj):
    """The engine Mesh for obj's data (through the add-on's cache, like a normal segmentation)."""
    core = api.load_core()
    vertices, triangles = _read_mesh(obj)
    digest = fingerprint(vertices, triangles)
    mesh = MESH_CACHE.get(obj.name_full, digest)
    if mesh is None:
        try:
            mesh = core.Mesh(vertices, triangles)
        except core.Error as exc:
            raise EngineError(str(exc)) from None
        MESH_CACHE.put(obj.name_full, digest, mesh)
    return core, mesh


def groups_from_vertex_groups(obj, prefix="Picks"):
    """[(group name, picks)] for obj's vertex groups whose name starts with prefix, by name;
    each group's vertices ordered by angle around their centroid."""
    api._mesh_object(obj)
    if not prefix:
        raise EngineError("Give the prefix of the pick groups' names (e.g. Picks)")
    mesh_io.sync_edit_mode(obj)
    members = {g.index: [] for g in obj.vertex_groups if g.name.startswith(prefix)}
    if not members:
        raise EngineError("No vertex group of %r starts with %r: make one per relief (e.g. %s1, %s2) holding "
                          "its picks" % (obj.name, prefix, prefix, prefix))
    data = obj.data
    for v in data.vertices:
        for g in v.groups:
            if g.group in members and g.weight > 0:
                members[g.group].append(v.index)
    out = []
    for g in sorted((g for g in obj.vertex_groups if g.index in members), key=lambda g: g.name):
        picks = members[g.index]
        if len(picks) < 3:
            raise EngineError("Vertex group %r holds %d vertices: a relief needs at least 3 picks around it"
                              % (g.name, len(picks)))
        positions = [tuple(data.vertices[i].co) for i in picks]
        normals = [tuple(data.vertices[i].normal) for i in picks]
        out.append((g.name, pick_order.order_by_angle(picks, positions, normals)))
    return out


def write_relief(obj, result, group_name):
    """One relief: vertex group `group_name` and the curve "<obj>_<group_name>Contour".

    mesh_io.write_curve fills the object's one default contour curve; the default is set aside
    while this relief's curve takes its place, then renamed."""
    api.apply_result(obj, result, group_name=group_name, make_curve=False)
    contour = result.get("contour", [])
    if len(contour) < 2:
        return None
    default = mesh_io.contour_object_name(obj)
    target = "%s_%sContour" % (obj.name, group_name)
    aside = bpy.data.objects.get(default)
    if aside is not None:
        aside.name = default + ".relief-snake-aside"
    existing = bpy.data.objects.get(target)
    if existing is not None and existing.type == 'CURVE':
        existing.name = default
    try:
        ob = mesh_io.write_curve(obj, contour, result.get("closed", True))
        ob.name = target
        ob.data.name = target
    finally:
        if aside is not None:
            aside.name = default
    return ob


def _result_names(names, prefix, result_prefix):
    out = []
    for k, name in enumerate(names):
        rest = name[len(prefix):]
        out.append(result_prefix + rest if rest else "%s%d" % (result_prefix, k + 1))
    return out


def _segment_many(mesh, groups, step_height, options=None, progress=None):
    """The engine's segment_many over [(group name, picks)]; raises EngineError on its errors
    (relief_snake_core.Cancelled passes through)."""
    core = api.load_core()
    try:
        return mesh.segment_many([p for _, p in groups], step_height, progress=progress, **(options or {}))
    except core.Error as exc:
        raise EngineError(str(exc)) from None


def _write_groups(obj, doc, names, prefix, result_prefix="Relief", write=True):
    """Name and (write=True) write the reliefs of a segment_many document: "names" (the pick
    groups) and "written" (the result groups) are added to it. Failed reliefs are not written."""
    doc["names"] = list(names)
    doc["written"] = []
    if write:
        for name, result in zip(_result_names(names, prefix, result_prefix), doc["reliefs"]):
            if result["status"] == "failed":
                continue
            write_relief(obj, result, name)
            doc["written"].append(name)
    return doc


def segment_vertex_groups(obj, prefix="Picks", step_height=None, *, result_prefix="Relief", write=True,
                          options=None):
    """Segment one relief per vertex group named prefix*, in one call (one Segmenter: the
    planarity is reused between reliefs of the same h). Returns the "relief-snake-results/1"
    document with "names" (the pick groups) and "written" (the result groups). Reliefs that could
    not run ("failed") are not written; overlapping ones are written and marked doubtful."""
    groups = groups_from_vertex_groups(obj, prefix)
    _, mesh = _engine_mesh(obj)
    doc = _segment_many(mesh, groups, step_height, options)
    return _write_groups(obj, doc, [n for n, _ in groups], prefix, result_prefix, write)


def _detect(mesh, region_vertices=None, min_area=None, refine=True, options=None, progress=None):
    core = api.load_core()
    try:
        return mesh.detect(region_vertices, min_area=min_area, refine=refine, progress=progress, **(options or {}))
    except core.Error as exc:
        raise EngineError(str(exc)) from None


def detect_object(obj, *, region_vertices=None, min_area=None, refine=True, options=None):
    """Propose the reliefs of obj (relief_snake_core.Mesh.detect); writes nothing. The document
    is kept for the candidate list (DETECTIONS)."""
    api._mesh_object(obj)
    _, mesh = _engine_mesh(obj)
    doc = _detect(mesh, region_vertices, min_area, refine, options)
    DETECTIONS[obj.name_full] = doc
    return doc


def apply_candidates(obj, doc, accepted, *, result_prefix="Relief.Candidate"):
    """Write the accepted candidates (indices into doc["candidates"]) like normal segmentations;
    returns the group names written."""
    written = []
    candidates = doc.get("candidates", [])
    for k in accepted:
        if not 0 <= k < len(candidates):
            raise EngineError("Candidate %d does not exist (the detection has %d)" % (k + 1, len(candidates)))
        name = "%s%d" % (result_prefix, k + 1)
        write_relief(obj, candidates[k], name)
        written.append(name)
    return written


# --- Blender UI ---------------------------------------------------------------------------

class ReliefSnakeCandidate(bpy.types.PropertyGroup):
    accepted: bpy.props.BoolProperty(name="Accept", default=True,
                                     description="Write this candidate as a vertex group and an outline curve")
    status: bpy.props.StringProperty(name="Status")
    step_height: bpy.props.FloatProperty(name="h")
    area: bpy.props.FloatProperty(name="Area")
    score: bpy.props.FloatProperty(name="Score")


def _fill_list(context, doc):
    items = context.scene.relief_snake_candidates
    items.clear()
    for k, c in enumerate(doc["candidates"]):
        item = items.add()
        item.name = "Candidate %d" % (k + 1)
        item.status = c["status"]
        item.step_height = c["step_height"]["used"]
        item.area = c["detection"]["area"]
        item.score = c["detection"]["score"]
        item.accepted = c["status"] == "converged"
    context.scene.relief_snake_candidate_index = 0


def _report_error(op, exc):
    op.report({'ERROR'}, str(exc))
    return {'CANCELLED'}


def busy():
    """The interactive run in progress (Segment's, or one of the operators here), or None."""
    from . import operators
    return _ModalRun.running or operators.MESH_OT_relief_snake_segment._modal


class _ModalRun(modal_run.ModalRun):
    """The interactive run of Detect and Segment Pick Groups (modal_run.py): a job.MeshJob runs the
    engine. Subclasses give _read(context) -> (obj, vertices, triangles, work(mesh, progress),
    progress-bar total or 0), _status_text(snap) and _finish(context, obj, doc)."""

    running = None  # the operator whose run is going (shared by both operators: one at a time)
    _total = 0  # what the progress bar counts to (0: no bar)

    def _set_current_run(self, op):
        _ModalRun.running = op

    def _current_run(self):
        return _ModalRun.running

    def _invoke_modal(self, context):
        if busy() is not None:
            self.report({'ERROR'}, "Relief Snake is already running: wait for it or press Esc")
            return {'CANCELLED'}
        return self._begin_modal(context)

    def _start(self, context):
        obj, vertices, triangles, work, total = self._read(context)
        self._obj_name, self._total = obj.name, total
        self._job = job.MeshJob(api.load_core(), vertices, triangles, work, key=obj.name_full).start()
        prefs = properties.preferences(context)
        if prefs is not None:
            preview.set_style(prefs.preview_color, prefs.preview_width)
        preview.start()
        if total:
            context.window_manager.progress_begin(0, total)
            self._progress_on = True

    def _modal_step(self, context, event):
        if event.type == 'ESC' and event.value == 'PRESS':
            if self._job is not None:
                self._job.cancel()  # the worker stops at its next progress call; its result is dropped
            self.report({'WARNING'}, "Relief Snake cancelled: nothing was changed")
            return {'CANCELLED'}
        if event.type != 'TIMER':
            return {'PASS_THROUGH'}  # keep navigating the view while it runs
        if self._job is None:
            try:
                self._start(context)
            except EngineError as exc:
                self.report({'ERROR'}, str(exc))
                return {'CANCELLED'}
            return {'RUNNING_MODAL'}
        obj = bpy.data.objects.get(self._obj_name)
        run = self._job
        if not run.done:
            snap = run.snapshot()
            if snap.contour is not None and obj is not None and snap.contour_serial != self._shown_serial:
                preview.set_contour(snap.contour, obj.matrix_world, True)
                self._shown_serial = snap.contour_serial
            if self._progress_on:
                context.window_manager.progress_update(min(snap.index, self._total))
            self._status(context, "Relief Snake: %s (Esc cancels)" % self._status_text(snap))
            modal_run.redraw_views(context)
            return {'RUNNING_MODAL'}
        if run.cancelled:
            self.report({'WARNING'}, "Relief Snake cancelled: nothing was changed")
            return {'CANCELLED'}
        if run.error:
            self.report({'ERROR'}, run.error)
            return {'CANCELLED'}
        if obj is None or obj.type != 'MESH':
            self.report({'ERROR'}, "The object was removed while the engine ran; nothing was written")
            return {'CANCELLED'}
        # PASS_THROUGH let the user edit or undo meanwhile: use the result only on the mesh it was made for.
        if api.mesh_changed(obj, run):
            self.report({'ERROR'}, "The mesh changed while the engine ran; nothing was written: run it again")
            return {'CANCELLED'}
        try:
            return self._finish(context, obj, run.result)
        except EngineError as exc:
            self.report({'ERROR'}, str(exc))
            return {'CANCELLED'}


def _phase_text(snap):
    words = summary.PHASE_WORDS.get(snap.stage, snap.stage)
    if snap.stage in ("intake", "segment", "waiting"):
        return "%s, %.0f s" % (words, snap.seconds)
    return "%s, step %d, %d points" % (words, snap.iteration, snap.points)


def _step_height(context):
    settings = context.scene.relief_snake
    return None if getattr(settings, "estimate_step_height", True) else settings.step_height


class MESH_OT_relief_snake_segment_groups(_ModalRun, bpy.types.Operator):
    """Segment one relief per vertex group whose name starts with the prefix (its vertices are the picks)"""
    bl_idname = "mesh.relief_snake_segment_groups"
    bl_label = "Segment Pick Groups"
    bl_options = {'REGISTER', 'UNDO'}

    prefix: bpy.props.StringProperty(name="Prefix", default="Picks",
                                     description="Vertex groups whose name starts with this hold one relief's picks")

    @classmethod
    def poll(cls, context):
        return context.active_object is not None and context.active_object.type == 'MESH'

    def _report_done(self, doc):
        bad = [n for n, r in zip(doc["names"], doc["reliefs"]) if r["status"] != "converged"]
        self.report({'WARNING'} if bad else {'INFO'},
                    "%d reliefs written (%s)%s" % (len(doc["written"]), ", ".join(doc["written"]),
                                                   "; check: " + ", ".join(bad) if bad else ""))
        return {'FINISHED'}

    def execute(self, context):
        try:
            doc = segment_vertex_groups(context.active_object, self.prefix, _step_height(context))
        except EngineError as exc:
            return _report_error(self, exc)
        return self._report_done(doc)

    # -- interactive (_ModalRun) ---------------------------------------------------------------
    def _read(self, context):
        obj = context.active_object
        groups = groups_from_vertex_groups(obj, self.prefix)
        vertices, triangles = _read_mesh(obj)
        self._groups = groups
        h = _step_height(context)
        options = {}
        return obj, vertices, triangles, lambda mesh, progress: _segment_many(mesh, groups, h, options, progress), \
            len(groups)

    def _status_text(self, snap):
        names = [n for n, _ in self._groups]
        if snap.stage in ("intake", "segment", "waiting"):
            return _phase_text(snap)
        k = min(snap.index, len(names) - 1)
        return "relief %d of %d (%s): %s" % (k + 1, len(names), names[k], _phase_text(snap))

    def _finish(self, context, obj, doc):
        _write_groups(obj, doc, [n for n, _ in self._groups], self.prefix)
        return self._report_done(doc)


class MESH_OT_relief_snake_detect(_ModalRun, bpy.types.Operator):
    """Propose the reliefs of the active mesh without picks; accept or reject them in the list"""
    bl_idname = "mesh.relief_snake_detect"
    bl_label = "Detect Reliefs"

    @classmethod
    def poll(cls, context):
        return context.active_object is not None and context.active_object.type == 'MESH'

    def _report_done(self, context, doc):
        _fill_list(context, doc)
        self.report({'INFO'}, "%d candidates found" % len(doc["candidates"]))
        return {'FINISHED'}

    def execute(self, context):
        try:
            doc = detect_object(context.active_object)
        except EngineError as exc:
            return _report_error(self, exc)
        return self._report_done(context, doc)

    # -- interactive (_ModalRun) ---------------------------------------------------------------
    def _read(self, context):
        obj = context.active_object
        vertices, triangles = _read_mesh(obj)
        # Candidates above the background, once the engine says: written by the worker thread into a
        # plain list (never into the operator, which may be gone by then).
        found = self._found = [0]

        def work(mesh, progress):
            def counting(index, phase, iteration, snaxels, contour):
                if phase == "candidates":
                    found[0] = iteration
                return progress(index, phase, iteration, snaxels, contour)
            return _detect(mesh, progress=counting)
        return obj, vertices, triangles, work, 0

    def _status_text(self, snap):
        if snap.stage in ("intake", "waiting"):
            return _phase_text(snap)
        if snap.stage == "segment":  # the engine's first call is a moment away
            return "finding candidates, %.0f s" % snap.seconds
        if snap.stage == "background":  # the engine fits up to three backgrounds (degrees 2, 4, 6)
            return "finding candidates: fitting the background, %.0f s" % snap.seconds
        if snap.stage == "candidates":
            return "%d candidates above the background, %.0f s" % (snap.iteration, snap.seconds)
        found = getattr(self, "_found", [0])[0]
        of = " of %d" % found if found > snap.index else ""
        return "candidate %d%s: %s" % (snap.index + 1, of, _phase_text(snap))

    def _finish(self, context, obj, doc):
        DETECTIONS[obj.name_full] = doc
        return self._report_done(context, doc)


class MESH_OT_relief_snake_apply_candidates(bpy.types.Operator):
    """Write the accepted candidates as vertex groups and outline curves"""
    bl_idname = "mesh.relief_snake_apply_candidates"
    bl_label = "Apply Accepted"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return obj is not None and obj.name_full in DETECTIONS

    def execute(self, context):
        obj = context.active_object
        accepted = [k for k, item in enumerate(context.scene.relief_snake_candidates) if item.accepted]
        try:
            written = apply_candidates(obj, DETECTIONS[obj.name_full], accepted)
        except EngineError as exc:
            return _report_error(self, exc)
        self.report({'INFO'}, "%d candidates written" % len(written))
        return {'FINISHED'}


class RELIEF_UL_candidates(bpy.types.UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        row = layout.row(align=True)
        row.prop(item, "accepted", text="")
        row.label(text=item.name, icon='CHECKMARK' if item.status == "converged" else 'ERROR')
        row.label(text="h %.3g  score %.2f" % (item.step_height, item.score))


class VIEW3D_PT_relief_snake_multi(bpy.types.Panel):
    bl_label = "Several Reliefs"
    bl_idname = "VIEW3D_PT_relief_snake_multi"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "Relief"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self.layout
        layout.operator("mesh.relief_snake_segment_groups", icon='GROUP_VERTEX')
        layout.operator("mesh.relief_snake_detect", icon='VIEWZOOM')
        scene = context.scene
        if len(scene.relief_snake_candidates):
            layout.template_list("RELIEF_UL_candidates", "", scene, "relief_snake_candidates", scene,
                                 "relief_snake_candidate_index", rows=4)
            layout.operator("mesh.relief_snake_apply_candidates", icon='CHECKMARK')


classes = (ReliefSnakeCandidate, MESH_OT_relief_snake_segment_groups, MESH_OT_relief_snake_detect,
           MESH_OT_relief_snake_apply_candidates, RELIEF_UL_candidates, VIEW3D_PT_relief_snake_multi)


def register():
    bpy.types.Scene.relief_snake_candidates = bpy.props.CollectionProperty(type=ReliefSnakeCandidate)
    bpy.types.Scene.relief_snake_candidate_index = bpy.props.IntProperty()


def unregister():
    DETECTIONS.clear()
    del bpy.types.Scene.relief_snake_candidates
    del bpy.types.Scene.relief_snake_candidate_index
