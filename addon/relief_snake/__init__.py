"""Relief Snake: segment reliefs (carvings, embossings) on scanned triangle meshes.

Select vertices around a relief in click order, set the step height, press Segment:
the relief vertices land in a vertex group and the outline in a curve object.
Scripting: see the `api` submodule.

Modules: pick_order, validation, summary, job and blend_history know nothing of bpy (tested in plain
Python); mesh_io, api, units, properties, preview, operators and panel are the Blender side.
"""

bl_info = {
    "name": "Relief Snake",
    "author": "Relief Snake contributors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > Relief",
    "description": "Segment reliefs on triangle meshes with a snake (active contour) driven by planarity",
    "category": "Mesh",
}

_MODULES = ("pick_order", "validation", "summary", "job", "units", "properties", "blend_history", "mesh_io", "preview",
            "region_faces", "region_view", "api", "operators", "panel", "multi")

if "bpy" in locals():  # script reload (F8 / reload scripts): refresh the submodules
    import importlib
    if "preview" in locals():
        preview.stop()  # noqa: F821  (the previous module's handler, before it is reloaded)
    if "region_view" in locals():
        region_view.stop()  # noqa: F821
    for _name in _MODULES:
        if _name in locals():
            importlib.reload(locals()[_name])

import bpy

from . import pick_order, validation, summary, job, units, properties, mesh_io, preview, api, operators, panel, extract_operators, extract_panel
from . import multi
from . import region_faces, region_view

_classes = (properties.classes + operators.classes + panel.classes + extract_operators.classes + extract_panel.classes
            + tuple(multi.classes))


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.relief_snake = bpy.props.PointerProperty(type=properties.ReliefSnakeSettings)
    multi.register()
    properties.register_handlers()
    region_view.register_handlers()


def unregister():
    # A running worker is asked to stop; its result is dropped (it holds no Blender data).
    job.cancel_all(wait=2.0)
    job.MESH_CACHE.clear()
    for running in (operators.MESH_OT_relief_snake_segment._modal, multi._ModalRun.running):
        if running is not None:
            running._cleanup(bpy.context)
    preview.stop()
    region_view.stop()
    region_view.unregister_handlers()
    properties.unregister_handlers()
    del bpy.types.Scene.relief_snake
    multi.unregister()
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
