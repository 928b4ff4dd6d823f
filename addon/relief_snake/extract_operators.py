"""Operators: Extract (mesh.relief_snake_extract) and Apply (object.relief_snake_apply).

Both are undoable (one undo step each), and on failure report the reason and leave the file as it
was (extraction.py removes anything it had created)."""

import bpy
from bpy.props import EnumProperty, FloatProperty, FloatVectorProperty, StringProperty

from . import extraction

FLATTEN_ITEMS = (
    ('AUTO', "Auto", "Plane projection for gentle backgrounds, conformal map for curved ones"),
    ('PLANE', "Plane", "Project onto the background's best-fit plane"),
    ('CONFORMAL', "Conformal", "Least-squares conformal flattening of the background"),
)
PLACEMENT_ITEMS = (
    ('CURSOR', "3D Cursor", "Centre the relief where the 3D cursor is (moved onto the target's surface)"),
    ('CLICK', "Click", "Click on the target's surface in the 3D Viewport to place the relief there (then "
                       "Location holds the point, and scale and rotation stay editable in the redo panel)"),
    ('LOCATION', "Location", "Centre the relief at the given location (moved onto the target's surface)"),
)
METHOD_ITEMS = (
    ('MESH', "New Mesh", "A new mesh lying on the target's surface with the relief's heights"),
    ('DISPLACE', "Displace Modifier", "A Displace modifier on the target, driven by the height map through "
                                      "the target's UV map"),
)
LAST_EXTRACT = "relief_snake_last_extract"  # scene custom property: the last summary, for the panel


def _is_relief(ob):
    return ob is not None and ob.type == 'MESH' and extraction.HEIGHT_ATTRIBUTE in ob.data.attributes


class MESH_OT_relief_snake_extract(bpy.types.Operator):
    """Extract the relief (from the Relief vertex group): a relief mesh with its heights, the object
    without its relief, and a height-map image"""
    bl_idname = "mesh.relief_snake_extract"
    bl_label = "Extract Relief"
    bl_options = {'REGISTER', 'UNDO'}

    pixel_size: FloatProperty(name="Pixel Size", default=0.0, min=0.0, precision=4, subtype='DISTANCE',
                              description="Height-map pixel size in object units (0: half the average edge)")
    flatten: EnumProperty(name="Flatten", items=FLATTEN_ITEMS, default='AUTO',
                          description="How the background under the relief is flattened for the height map")
    directory: StringProperty(name="Image Folder", subtype='DIR_PATH', default="",
                              description="Where to save the height map as EXR (empty: next to the .blend)")

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        return ob is not None and ob.type == 'MESH'

    def execute(self, context):
        settings = context.scene.relief_snake
        ob = context.active_object
        api = extraction._api()
        try:
            out = extraction.extract_object(
                ob, settings.step_height, group_name=settings.group_name, pixel_size=self.pixel_size,
                flatten=self.flatten.lower(), image_dir=bpy.path.abspath(self.directory) if self.directory else None)
        except api.EngineError as exc:
            self.report({'ERROR'}, str(exc))
            return {'CANCELLED'}
        summary = "Relief Snake: " + out["result"]["summary"]
        if out["image_path"] is None:
            summary += " (height map not saved: save the .blend or choose a folder)"
        context.scene[LAST_EXTRACT] = summary
        self.report({'INFO'}, summary)
        return {'FINISHED'}


class OBJECT_OT_relief_snake_apply(bpy.types.Operator):
    """Put an extracted relief onto another mesh object"""
    bl_idname = "object.relief_snake_apply"
    bl_label = "Apply Relief"
    bl_options = {'REGISTER', 'UNDO'}

    relief: StringProperty(name="Relief", default="",
                           description="The extracted relief object (empty: the active or a selected relief)")
    target: StringProperty(name="Target", default="",
                           description="The mesh object to put the relief on (empty: the other selected mesh)")
    method: EnumProperty(name="Method", items=METHOD_ITEMS, default='MESH')
    placement: EnumProperty(name="Placement", items=PLACEMENT_ITEMS, default='CURSOR')
    location: FloatVectorProperty(name="Location", subtype='TRANSLATION', size=3, default=(0.0, 0.0, 0.0))
    rotation: FloatProperty(name="Rotation", subtype='ANGLE', default=0.0,
                            description="Turn the relief about the target's normal")
    scale: FloatProperty(name="Scale", default=1.0, min=1e-4, soft_max=10.0,
                         description="Scale of the relief's footprint and heights")

    @classmethod
    def poll(cls, context):
        return context.mode == 'OBJECT'

    def _objects(self, context):
        relief = bpy.data.objects.get(self.relief) if self.relief else None
        if relief is None:
            active = context.active_object
            candidates = [active] + list(context.selected_objects)
            relief = next((ob for ob in candidates if _is_relief(ob)), None)
        target = bpy.data.objects.get(self.target) if self.target else None
        if target is None:
            target = next((ob for ob in context.selected_objects
                           if ob is not relief and ob.type == 'MESH' and not _is_relief(ob)), None)
        return relief, target

    def draw(self, context):
        layout = self.layout
        layout.prop_search(self, "relief", context.scene, "objects")
        layout.prop_search(self, "target", context.scene, "objects")
        layout.prop(self, "method", expand=True)
        col = layout.column()
        col.enabled = self.method == 'MESH'
        col.prop(self, "placement")
        sub = col.column()
        sub.enabled = self.placement in ('LOCATION', 'CLICK')
        sub.prop(self, "location")
        col.prop(self, "rotation")
        layout.prop(self, "scale")

    def _objects_or_report(self, context):
        relief, target = self._objects(context)
        if relief is None:
            self.report({'ERROR'}, "No extracted relief: select one (made by Extract Relief) or name it")
        elif target is None:
            self.report({'ERROR'}, "No target: select a second mesh object to put the relief on")
        return relief, target

    # -- placement by click: a modal pick on the target's surface ---------------------------
    def invoke(self, context, event):
        if self.placement != 'CLICK' or self.method != 'MESH' or context.window is None:
            return self.execute(context)
        relief, target = self._objects_or_report(context)
        if relief is None or target is None:
            return {'CANCELLED'}
        self._target_name = target.name
        context.window_manager.modal_handler_add(self)
        self._status(context, "Relief Snake: click on %s to place the relief (Esc or right click cancels)"
                     % target.name)
        return {'RUNNING_MODAL'}

    def _status(self, context, text):
        if context.workspace is not None:
            context.workspace.status_text_set(text)

    def modal(self, context, event):
        if event.type in {'ESC', 'RIGHTMOUSE'} and event.value == 'PRESS':
            self._status(context, None)
            self.report({'INFO'}, "Relief Snake: placement cancelled")
            return {'CANCELLED'}
        if event.type != 'LEFTMOUSE' or event.value != 'PRESS':
            return {'PASS_THROUGH'}  # navigate the view meanwhile
        target = bpy.data.objects.get(self._target_name)
        ray = _view_ray(context, event.mouse_x, event.mouse_y)
        if ray is None:
            return {'PASS_THROUGH'}  # a click outside the 3D views: the sidebar, a menu
        point = extraction.surface_hit(target, *ray) if target is not None else None
        if point is None:
            self.report({'WARNING'}, "Relief Snake: click on %s's surface (that click missed it)" % self._target_name)
            return {'RUNNING_MODAL'}
        self._status(context, None)
        # The redo panel re-runs execute(): from here on, the clicked point is the location.
        self.location = tuple(point)
        self.target = self._target_name
        self.placement = 'LOCATION'
        return self.execute(context)

    def execute(self, context):
        api = extraction._api()
        relief, target = self._objects_or_report(context)
        if relief is None or target is None:
            return {'CANCELLED'}
        if self.placement == 'CLICK' and self.method == 'MESH':
            self.report({'ERROR'}, "Placement by click needs the 3D Viewport: from a script, use placement "
                                   "'LOCATION' with a location")
            return {'CANCELLED'}
        try:
            if self.method == 'DISPLACE':
                modifier = extraction.add_displace(relief, target, strength=self.scale)
                self.report({'INFO'}, "Relief Snake: Displace modifier %r on %r" % (modifier.name, target.name))
                return {'FINISHED'}
            location = tuple(self.location) if self.placement == 'LOCATION' else None  # None: the 3D cursor
            ob = extraction.apply_relief(relief, target, location=location, rotation=self.rotation,
                                         scale=self.scale)
        except api.EngineError as exc:
            self.report({'ERROR'}, str(exc))
            return {'CANCELLED'}
        for other in context.selected_objects:
            other.select_set(False)
        ob.select_set(True)
        context.view_layer.objects.active = ob
        self.report({'INFO'}, "Relief Snake: %r put on %r" % (ob.name, target.name))
        return {'FINISHED'}


def _view_ray(context, mouse_x, mouse_y):
    """The world ray (origin, direction) through window pixel (mouse_x, mouse_y) of the 3D
    Viewport under it, or None when no 3D Viewport is there."""
    from bpy_extras import view3d_utils
    screen = context.window.screen if context.window is not None else None
    for area in (screen.areas if screen is not None else ()):
        if area.type != 'VIEW_3D':
            continue
        for region in area.regions:
            if region.type != 'WINDOW' or region.data is None:
                continue
            x, y = mouse_x - region.x, mouse_y - region.y
            if 0 <= x < region.width and 0 <= y < region.height:
                origin = view3d_utils.region_2d_to_origin_3d(region, region.data, (x, y))
                direction = view3d_utils.region_2d_to_vector_3d(region, region.data, (x, y))
                return origin, direction
    return None


classes = (MESH_OT_relief_snake_extract, OBJECT_OT_relief_snake_apply)
