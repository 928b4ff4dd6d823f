"""View3D > Sidebar > Relief: Segment first, then the settings, then the last run in a
collapsible sub-panel whose lines wrap to the sidebar's width."""

import textwrap

import bpy


def _wrap(layout, context, text, icon='NONE'):
    """Labels for `text`, wrapped to the region's width (Blender's labels cut, they never wrap)."""
    region = context.region
    scale = context.preferences.view.ui_scale
    chars = max(16, int((region.width if region else 300) / (7.0 * scale)) - 6)  # room for the icon
    first = True
    for paragraph in text.splitlines():
        for line in textwrap.wrap(paragraph, chars) or [""]:
            layout.label(text=line, icon=icon if first else 'NONE')
            first = False


class VIEW3D_PT_relief_snake(bpy.types.Panel):
    bl_label = "Relief Snake"
    bl_idname = "VIEW3D_PT_relief_snake"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "Relief"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = False
        settings = context.scene.relief_snake
        row = layout.row()
        row.scale_y = 1.5  # the main action: big, and first (tests/blender/ui/ find it by its colour)
        row.operator("mesh.relief_snake_segment", text="Segment", icon='MOD_SMOOTH')

        col = layout.column(align=True)
        col.label(text="Step Height")
        row = col.row(align=True)
        sub = row.row(align=True)
        sub.enabled = not settings.estimate_step_height
        sub.prop(settings, "step_height", text="")
        row.operator("mesh.relief_snake_measure", text="", icon='DRIVER_DISTANCE')
        row.prop(settings, "estimate_step_height", text="Estimate", toggle=True)

        col = layout.column(align=True)
        col.label(text="Smoothness")
        row = col.row(align=True)
        sub = row.row(align=True)
        sub.enabled = not settings.auto_smoothness
        sub.prop(settings, "smoothness", text="")
        row.prop(settings, "auto_smoothness", text="Auto", toggle=True)

        col = layout.column(align=True)
        col.prop(settings, "open_contour")
        sub = col.row(align=True)
        sub.enabled = settings.open_contour
        sub.prop(settings, "relief_side", expand=True)

        col = layout.column(align=True)
        col.label(text="Vertex Group")
        col.prop(settings, "group_name", text="")
        row = layout.row(align=True)
        row.prop(settings, "make_curve", text="Curve")
        row.prop(settings, "show_region", text="Show Region")


class VIEW3D_PT_relief_snake_result(bpy.types.Panel):
    bl_label = "Last Result"
    bl_idname = "VIEW3D_PT_relief_snake_result"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "Relief"
    bl_parent_id = "VIEW3D_PT_relief_snake"

    @classmethod
    def poll(cls, context):
        return bool(context.scene.relief_snake.last_summary)

    def draw(self, context):
        settings = context.scene.relief_snake
        col = self.layout.column(align=True)
        _wrap(col, context, settings.last_summary, icon='CHECKMARK')
        if settings.last_warning:
            col.separator()
            _wrap(col, context, settings.last_warning, icon='ERROR')
        if settings.last_details:
            col.separator()
            _wrap(col, context, settings.last_details)


classes = (VIEW3D_PT_relief_snake, VIEW3D_PT_relief_snake_result)
