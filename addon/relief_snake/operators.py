"""Operators: mesh.relief_snake_segment and mesh.relief_snake_measure.

Segment runs synchronously from execute() (background mode, scripts calling with
EXEC_DEFAULT, the redo panel) and as a modal operator from invoke() in an
interactive session: the engine runs in a worker thread, a window timer polls its
progress, the viewport shows the evolving snake, Esc cancels. Everything is computed
before anything is written, so a failure or a cancel leaves the scene untouched.
"""

import threading
import time

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, StringProperty

from . import api, ordering, preview
from .properties import SIDE_ITEMS

PHASES = ("preprocess", "coarse", "refine", "stabilise")
_SETTING_NAMES = ("step_height", "w_int", "open_contour", "relief_side", "group_name", "make_curve")


def _settings(context):
    return context.scene.relief_snake


class MESH_OT_relief_snake_segment(bpy.types.Operator):
    """Segment the relief outlined by the selected vertices (click order) with the relief snake"""
    bl_idname = "mesh.relief_snake_segment"
    bl_label = "Segment Relief"
    bl_options = {'REGISTER', 'UNDO'}

    # Unset properties are taken from the scene settings (the Relief panel).
    step_height: FloatProperty(name="Step Height", default=0.0, min=0.0, precision=4, subtype='DISTANCE',
                               description="h: height of the relief's step, in object units")
    w_int: FloatProperty(name="W_int", default=0.25, min=0.01, max=1.0,
                         description="Internal energy weight during refinement (paper: 0.25)")
    open_contour: BoolProperty(name="Open Contour", default=False,
                               description="The contour ends on the mesh boundary")
    relief_side: EnumProperty(name="Relief Side", items=SIDE_ITEMS, default='LEFT',
                              description="Open contours: side of the picks the relief is on")
    group_name: StringProperty(name="Vertex Group", default="Relief",
                               description="Vertex group receiving the relief vertices (replaced)")
    make_curve: BoolProperty(name="Contour Curve", default=True,
                             description="Create a curve object along the contour (replaced)")

    _running = False  # one interactive run at a time

    @classmethod
    def poll(cls, context):
        # Deliberately lenient: a wrong selection gets an explicit error report instead
        # of a greyed-out button with no explanation.
        return context.scene is not None

    # -- shared steps -----------------------------------------------------------------
    def _fill_from_scene(self, context):
        settings = _settings(context)
        for name in _SETTING_NAMES:
            if not self.properties.is_property_set(name):
                setattr(self, name, getattr(settings, name))

    def _prepare(self, context):
        """Validate and read everything; raises api.EngineError. Writes nothing."""
        obj = context.active_object
        api._mesh_object(obj)
        if not self.group_name.strip():
            raise api.EngineError("Give the vertex group a name (Relief panel or redo panel)")
        api.load_core()
        t0 = time.perf_counter()
        picks, info = api.selected_picks(obj)
        t_select = time.perf_counter() - t0
        job = api.prepare(obj, picks, self.step_height, w_int=self.w_int, open_contour=self.open_contour,
                          relief_side=self.relief_side.lower())
        job["read_seconds"] += t_select  # selection + click order count as data transfer too
        return obj, job, info

    def _finish(self, context, obj, result, info):
        api.apply_result(obj, result, group_name=self.group_name, make_curve=self.make_curve)
        settings = _settings(context)
        settings.last_summary = ordering.result_summary(result)
        settings.last_phases = "\n".join(ordering.phase_summary(result) + [ordering.timing_summary(result)])
        if info:
            self.report({'INFO'}, info)
        for note in result.get("notes", []):
            self.report({'INFO'}, "Relief Snake: %s" % note)
        if result.get("status") == "iteration_cap" or str(result.get("status", "")).lower().startswith("iter"):
            self.report({'WARNING'}, "Relief Snake stopped at the iteration cap; check the contour")
        self.report({'INFO'}, settings.last_summary)
        return {'FINISHED'}

    # -- synchronous ------------------------------------------------------------------
    def execute(self, context):
        self._fill_from_scene(context)
        try:
            obj, job, info = self._prepare(context)
            result = api.run(api.load_core(), job)
            return self._finish(context, obj, result, info)
        except api.EngineError as exc:
            self.report({'ERROR'}, str(exc))
            return {'CANCELLED'}

    # -- interactive ------------------------------------------------------------------
    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        if MESH_OT_relief_snake_segment._running:
            self.report({'ERROR'}, "Relief Snake is already running: wait for it or press Esc")
            return {'CANCELLED'}
        self._fill_from_scene(context)
        try:
            obj, job, info = self._prepare(context)
            core = api.load_core()
        except api.EngineError as exc:
            self.report({'ERROR'}, str(exc))
            return {'CANCELLED'}
        self._obj_name, self._info = obj.name, info
        shared = self._shared = {"phase": "preprocess", "iteration": 0, "snaxels": 0, "contour": None,
                                 "cancel": False, "cancelled": False, "result": None, "error": None,
                                 "done": False}

        def progress(phase, iteration, snaxels, contour):
            # Worker thread: no bpy here, only hand the latest state to the timer.
            shared["phase"], shared["iteration"], shared["snaxels"] = phase, iteration, snaxels
            if contour is not None:  # the engine sends it at most every 0.1 s
                shared["contour"] = contour
            return not shared["cancel"]

        def work():
            try:
                shared["result"] = api.run(core, job, progress)
            except core.Cancelled:
                shared["cancelled"] = True
            except api.EngineError as exc:
                shared["error"] = str(exc)
            except Exception as exc:  # keep the UI alive; report instead of a silent thread death
                shared["error"] = "Relief Snake failed: %s" % exc
            finally:
                shared["done"] = True

        self._thread = threading.Thread(target=work, name="relief-snake", daemon=True)
        MESH_OT_relief_snake_segment._running = True
        self._thread.start()
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        wm.progress_begin(0, len(PHASES))
        preview.start()
        self._status(context, "Relief Snake: preparing... (Esc cancels)")
        return {'RUNNING_MODAL'}

    def _status(self, context, text):
        if context.workspace is not None:
            context.workspace.status_text_set(text)

    def _cleanup(self, context):
        wm = context.window_manager
        if getattr(self, "_timer", None) is not None:
            wm.event_timer_remove(self._timer)
            self._timer = None
        wm.progress_end()
        preview.stop()
        self._status(context, None)
        MESH_OT_relief_snake_segment._running = False
        _redraw_views(context)

    def modal(self, context, event):
        shared = self._shared
        if event.type == 'ESC' and event.value == 'PRESS':
            shared["cancel"] = True
            self._status(context, "Relief Snake: cancelling...")
            return {'RUNNING_MODAL'}
        if event.type != 'TIMER':
            return {'PASS_THROUGH'}  # keep navigating the view while it runs
        obj = bpy.data.objects.get(self._obj_name)
        if not shared["done"]:
            contour = shared["contour"]
            if contour is not None and obj is not None:
                preview.set_contour(contour, obj.matrix_world, not self.open_contour)
            phase = shared["phase"]
            if phase in PHASES:
                context.window_manager.progress_update(PHASES.index(phase))
            if not shared["cancel"]:
                self._status(context, "Relief Snake: %s, iteration %d, %d snaxels (Esc cancels)"
                             % (phase, shared["iteration"], shared["snaxels"]))
            _redraw_views(context)
            return {'RUNNING_MODAL'}
        self._thread.join()
        self._cleanup(context)
        if shared["cancelled"] or shared["cancel"]:
            self.report({'WARNING'}, "Relief Snake cancelled: nothing was changed")
            return {'CANCELLED'}
        if shared["error"]:
            self.report({'ERROR'}, shared["error"])
            return {'CANCELLED'}
        if obj is None or obj.type != 'MESH':
            self.report({'ERROR'}, "The object was removed while segmenting; nothing was written")
            return {'CANCELLED'}
        try:
            return self._finish(context, obj, shared["result"], self._info)
        except api.EngineError as exc:
            self.report({'ERROR'}, str(exc))
            return {'CANCELLED'}

    def cancel(self, context):
        # Blender ends the modal operator (e.g. a file is loaded): stop the worker first.
        self._shared["cancel"] = True
        self._thread.join(timeout=30)
        self._cleanup(context)


class MESH_OT_relief_snake_measure(bpy.types.Operator):
    """Set the step height to the distance between the two selected vertices (object space)"""
    bl_idname = "mesh.relief_snake_measure"
    bl_label = "Measure Step Height"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        return context.scene is not None

    def execute(self, context):
        obj = context.active_object
        try:
            api._mesh_object(obj)
            from . import mesh_io
            mesh_io.sync_edit_mode(obj)
            selected, history, _, _ = mesh_io.read_selection(obj)
            if len(selected) != 2:
                raise api.EngineError("Select exactly two vertices, one at the foot and one at the top of the "
                                      "step (%d selected)" % len(selected))
            h = api.measure(obj, selected[0], selected[1])
        except api.EngineError as exc:
            self.report({'ERROR'}, str(exc))
            return {'CANCELLED'}
        if not h > 0:
            self.report({'ERROR'}, "The two selected vertices coincide: pick two vertices apart")
            return {'CANCELLED'}
        _settings(context).step_height = h
        self.report({'INFO'}, "Relief Snake: step height set to %.4g" % h)
        return {'FINISHED'}


def _redraw_views(context):
    screen = context.screen
    if screen is None:
        return
    for area in screen.areas:
        if area.type == 'VIEW_3D':
            area.tag_redraw()


classes = (MESH_OT_relief_snake_segment, MESH_OT_relief_snake_measure)
