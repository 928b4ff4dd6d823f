"""Operators: mesh.relief_snake_segment and mesh.relief_snake_measure; thin glue over
api (read, write) and job (the engine in a worker thread).

Segment runs synchronously from execute() (background mode, scripts calling it with
EXEC_DEFAULT, the redo panel) and as a modal operator from invoke() in an interactive
session: the status bar says "Reading mesh..." before the read, the engine runs in a
job.SegmentJob, a window timer polls its progress, the viewport shows the evolving outline,
Esc cancels at once. Everything is computed before anything is written, so a failure or a
cancel leaves the scene untouched. Every modal step runs under try/finally: whatever happens,
the timer, the draw handler and the status text go away when the run ends.
"""

import time

import bpy

from . import api, job, modal_run, pick_order, preview, properties, region_view, summary, units

PHASES = ("intake", "segment", "coarse", "refine", "stabilise")


def _settings(context):
    return context.scene.relief_snake


def _threads_option(context):
    prefs = properties.preferences(context)
    threads = getattr(prefs, "threads", 0) if prefs is not None else 0
    return {"threads": int(threads)} if threads else {}


class MESH_OT_relief_snake_segment(modal_run.ModalRun, bpy.types.Operator):
    """Outline the relief around the selected vertices (picked in order) and put its vertices in a group"""
    bl_idname = "mesh.relief_snake_segment"
    bl_label = "Segment Relief"
    bl_options = {'REGISTER', 'UNDO'}

    # The panel's settings; the ones a caller does not set are taken from the scene.
    __annotations__ = dict(properties.setting_properties())

    _modal = None  # the interactive run in progress (one at a time)

    @classmethod
    def poll(cls, context):
        # Deliberately lenient: a wrong selection gets an explicit error report instead
        # of a greyed-out button with no explanation.
        return context.scene is not None

    # -- shared steps -----------------------------------------------------------------
    def _fill_from_scene(self, context):
        settings = _settings(context)
        for name in properties.SETTING_NAMES:
            if not self.properties.is_property_set(name):
                setattr(self, name, getattr(settings, name))

    def _prepare(self, context):
        """Validate and read everything; raises api.EngineError. Writes nothing."""
        obj = context.active_object
        api._mesh_object(obj)
        if not self.group_name.strip():
            raise api.EngineError("Give the vertex group a name (Relief panel or redo panel)")
        api.load_core()
        from . import mesh_io
        t0 = time.perf_counter()
        with mesh_io.live_mesh(obj) as mesh:  # one read of the live mesh for the selection and the buffers
            picks, info = api.selected_picks(obj, mesh)
            request = api.prepare(
                obj, picks, None if self.estimate_step_height else self.step_height,
                w_int=None if self.auto_smoothness else self.smoothness, open_contour=self.open_contour,
                relief_side=self.relief_side.lower(), options=_threads_option(context), mesh=mesh)
        request.read_seconds = time.perf_counter() - t0  # selection + click order count as data transfer too
        return obj, request, info

    def _hold_edit_bmesh(self, context):
        """One edit bmesh handle for the read and the write (mesh_io.hold_edit_bmesh)."""
        from . import mesh_io
        self._held_bmesh = mesh_io.hold_edit_bmesh(context.active_object)

    def _cleanup(self, context):
        self._held_bmesh = None  # a run that ends before the write drops the handle here
        modal_run.ModalRun._cleanup(self, context)  # (not super(): the tests run it on a stand-in)

    def _release_edit_bmesh(self, result):
        """Drop the handle once the weights are written; Blender then removes the element layer,
        which is part of writing: its time counts there."""
        t0 = time.perf_counter()
        self._held_bmesh = None
        timing = result.setdefault("timing", {})
        seconds = time.perf_counter() - t0
        timing["write"] = timing.get("write", 0.0) + seconds
        timing["total"] = timing.get("total", 0.0) + seconds

    def _finish(self, context, obj, result, info, request):
        api.apply_result(obj, result, group_name=self.group_name, make_curve=self.make_curve)
        self._release_edit_bmesh(result)
        settings = _settings(context)
        details = summary.phase_lines(result) + [summary.timing_line(result)]
        h_line = summary.step_height_line(result, lambda v: units.format_length(context.scene, v))
        if h_line:
            details.insert(0, h_line)
            used = (result.get("step_height") or {}).get("used")
            if used:
                settings.step_height = float(used)
        warning = summary.status_warning(result) or ""
        settings.last_summary = summary.result_summary(result)
        settings.last_details = "\n".join(details)
        settings.last_warning = warning
        if info:
            self.report({'INFO'}, info)
        for note in result.get("notes", []):
            self.report({'INFO'}, "Relief Snake: %s" % note)
        if warning:
            self.report({'WARNING'}, "Relief Snake: " + warning)
        if self.show_region:
            region_view.show(obj, self.group_name, request.vertices, request.triangles,
                             result.get("relief_vertices", []))
        self.report({'INFO'}, "Relief Snake: " + settings.last_summary)
        return {'FINISHED'}

    # -- synchronous ------------------------------------------------------------------
    def execute(self, context):
        self._fill_from_scene(context)
        self._hold_edit_bmesh(context)
        try:
            obj, request, info = self._prepare(context)
            result = api.run_engine(api.load_core(), request)
            return self._finish(context, obj, result, info, request)
        except api.EngineError as exc:
            self.report({'ERROR'}, str(exc))
            return {'CANCELLED'}
        finally:
            self._held_bmesh = None

    # -- interactive (modal_run.py) ---------------------------------------------------------
    def _set_current_run(self, op):
        MESH_OT_relief_snake_segment._modal = op

    def _current_run(self):
        return MESH_OT_relief_snake_segment._modal

    def _invoke_modal(self, context):
        from . import multi  # Detect and Segment Pick Groups run the same way: one run at a time
        if multi.busy() is not None:
            self.report({'ERROR'}, "Relief Snake is already running: wait for it or press Esc")
            return {'CANCELLED'}
        self._fill_from_scene(context)
        return self._begin_modal(context)

    def _start(self, context):
        self._hold_edit_bmesh(context)  # until the write, or _cleanup
        obj, request, info = self._prepare(context)
        self._obj_name, self._info, self._request = obj.name, info, request
        self._job = job.SegmentJob(api.load_core(), request).start()
        prefs = properties.preferences(context)
        if prefs is not None:
            preview.set_style(prefs.preview_color, prefs.preview_width)
        preview.start()
        context.window_manager.progress_begin(0, len(PHASES))
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
            except api.EngineError as exc:
                self.report({'ERROR'}, str(exc))
                return {'CANCELLED'}
            return {'RUNNING_MODAL'}
        obj = bpy.data.objects.get(self._obj_name)
        run = self._job
        if not run.done:
            snap = run.snapshot()
            if snap.contour is not None and obj is not None and snap.contour_serial != self._shown_serial:
                preview.set_contour(snap.contour, obj.matrix_world, not self.open_contour)
                self._shown_serial = snap.contour_serial
            if snap.stage in PHASES:
                context.window_manager.progress_update(PHASES.index(snap.stage))
            words = summary.PHASE_WORDS.get(snap.stage, snap.stage)
            if snap.stage in ("intake", "segment", "waiting"):
                text = "Relief Snake: %s, %.0f s (Esc cancels)" % (words, snap.seconds)
            else:
                text = "Relief Snake: %s, step %d, %d points (Esc cancels)" % (words, snap.iteration, snap.points)
            self._status(context, text)
            modal_run.redraw_views(context)
            return {'RUNNING_MODAL'}
        if run.cancelled:
            self.report({'WARNING'}, "Relief Snake cancelled: nothing was changed")
            return {'CANCELLED'}
        if run.error:
            self.report({'ERROR'}, run.error)
            return {'CANCELLED'}
        if obj is None or obj.type != 'MESH':
            self.report({'ERROR'}, "The object was removed while segmenting; nothing was written")
            return {'CANCELLED'}
        # PASS_THROUGH let the user edit or undo meanwhile: write only onto the mesh the engine saw.
        if api.mesh_changed(obj, self._request):
            self.report({'ERROR'}, "The mesh changed while segmenting; nothing was written: run Segment again")
            return {'CANCELLED'}
        try:
            return self._finish(context, obj, run.result, self._info, self._request)
        except api.EngineError as exc:
            self.report({'ERROR'}, str(exc))
            return {'CANCELLED'}


class MESH_OT_relief_snake_measure(bpy.types.Operator):
    """Set the step height to the distance between the two selected vertices: one at the foot of the step, one on top"""
    bl_idname = "mesh.relief_snake_measure"
    bl_label = "Measure Step Height"
    # No UNDO: it only sets a panel setting, which the add-on keeps across undo anyway.
    bl_options = {'REGISTER'}

    @classmethod
    def poll(cls, context):
        return context.scene is not None

    def execute(self, context):
        obj = context.active_object
        try:
            api._mesh_object(obj)
            from . import mesh_io
            with mesh_io.live_mesh(obj) as mesh:
                selected, _history, positions, _ = mesh_io.read_selection(obj, mesh)
            if len(selected) != 2:
                raise api.EngineError("Select exactly two vertices, one at the foot and one at the top of the "
                                      "step (%d selected)" % len(selected))
            h = pick_order.distance(positions[selected[0]], positions[selected[1]])
        except api.EngineError as exc:
            self.report({'ERROR'}, str(exc))
            return {'CANCELLED'}
        if not h > 0:
            self.report({'ERROR'}, "The two selected vertices coincide: pick two vertices apart")
            return {'CANCELLED'}
        settings = _settings(context)
        settings.step_height = h
        settings.estimate_step_height = False
        self.report({'INFO'}, "Relief Snake: step height set to %s" % units.format_length(context.scene, h))
        return {'FINISHED'}


classes = (MESH_OT_relief_snake_segment, MESH_OT_relief_snake_measure)
