"""The interactive run shared by Segment (operators.py), Detect and Segment Pick Groups (multi.py).

The first timer tick reads the mesh (after the status bar said "reading mesh..."), a worker from
job.py runs the engine, later ticks show its progress, Esc cancels at once, and every step runs under
try/finally so that the timer, the progress bar, the preview and the status text go away however the
run ends. Subclasses give:

- ``_start(context)``: read the mesh and start the worker (the first tick);
- ``_modal_step(context, event)``: one tick or event, returning the modal set;
- ``_set_current_run(op)`` / ``_current_run()``: where their run in progress is kept (one at a time).
"""

import bpy

from . import preview


def redraw_views(context):
    screen = context.screen
    if screen is None:
        return
    for area in screen.areas:
        if area.type == 'VIEW_3D':
            area.tag_redraw()


class ModalRun:
    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        return self._invoke_modal(context)

    def _begin_modal(self, context):
        self._job = None
        self._obj_name = None
        self._shown_serial = -1
        self._progress_on = False
        wm = context.window_manager
        # The read happens on the first timer tick, after the status bar has been drawn.
        self._timer = wm.event_timer_add(0.05, window=context.window)
        wm.modal_handler_add(self)
        self._set_current_run(self)
        self._status(context, "Relief Snake: reading mesh... (Esc cancels)")
        return {'RUNNING_MODAL'}

    def _status(self, context, text):
        if context.workspace is not None:
            context.workspace.status_text_set(text)

    def _cleanup(self, context):
        wm = context.window_manager
        if getattr(self, "_timer", None) is not None:
            wm.event_timer_remove(self._timer)
            self._timer = None
        if getattr(self, "_progress_on", False):
            wm.progress_end()
            self._progress_on = False
        preview.stop()
        self._status(context, None)
        if self._current_run() is self:
            self._set_current_run(None)
        redraw_views(context)

    def modal(self, context, event):
        running = False
        try:
            ret = self._modal_step(context, event)
            running = 'RUNNING_MODAL' in ret or 'PASS_THROUGH' in ret
            return ret
        except Exception as exc:  # never leave a timer, a preview or "already running" behind
            if self._job is not None:
                self._job.cancel()
            self.report({'ERROR'}, "Relief Snake failed: %s: %s" % (type(exc).__name__, exc))
            return {'CANCELLED'}
        finally:
            if not running:
                self._cleanup(context)

    def cancel(self, context):
        # Blender ends the modal operator (a file is loaded, the window closes): the worker is
        # asked to stop and winds down in the background; its result is dropped.
        if getattr(self, "_job", None) is not None:
            self._job.cancel()
        self._cleanup(context)
