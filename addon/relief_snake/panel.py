"""View3D > Sidebar > Relief: settings, Measure and Segment, the last run's summary."""

import bpy


class VIEW3D_PT_relief_snake(bpy.types.Panel):
    bl_label = "Relief Snake"
    bl_idname = "VIEW3D_PT_relief_snake"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "Relief"

    def draw(self, context):
        layout = self.layout
        settings = context.scene.relief_snake
        col = layout.column(align=True)
        row = col.row(align=True)
        row.prop(settings, "step_height")
        row.operator("mesh.relief_snake_measure", text="", icon='DRIVER_DISTANCE')
        col.prop(settings, "w_int")
        col = layout.column(align=True)
        col.prop(settings, "open_contour")
        sub = col.row(align=True)
        sub.enabled = settings.open_contour
        sub.prop(settings, "relief_side", expand=True)
        col = layout.column(align=True)
        col.prop(settings, "group_name")
        col.prop(settings, "make_curve")
        layout.operator("mesh.relief_snake_segment", icon='MOD_SMOOTH')
        if settings.last_summary:
            box = layout.box()
            box.label(text=settings.last_summary.replace("Relief Snake: ", "Last: "))
            for line in settings.last_phases.splitlines():
                box.label(text=line)


classes = (VIEW3D_PT_relief_snake,)
