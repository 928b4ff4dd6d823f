"""Relief Snake: segment reliefs (carvings, embossings) on scanned triangle meshes.

Select vertices around a relief in click order, set the step height, press Segment:
the relief vertices land in a vertex group and the contour in a curve object.
Scripting: see the `api` submodule.
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

if "bpy" in locals():  # script reload (F8 / reload scripts): refresh the submodules
    import importlib
    for _name in ("ordering", "properties", "mesh_io", "preview", "api", "operators", "panel"):
        if _name in locals():
            importlib.reload(locals()[_name])

import bpy

from . import ordering, properties, mesh_io, preview, api, operators, panel, extract_operators, extract_panel

_classes = properties.classes + operators.classes + panel.classes + extract_operators.classes + extract_panel.classes


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.relief_snake = bpy.props.PointerProperty(type=properties.ReliefSnakeSettings)


def unregister():
    preview.stop()
    del bpy.types.Scene.relief_snake
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
