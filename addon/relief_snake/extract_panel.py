"""View3D > Sidebar > Relief > Extract & Apply: a sub-panel of the Relief Snake panel."""

import bpy

from .extract_operators import LAST_EXTRACT, MESH_OT_relief_snake_extract, OBJECT_OT_relief_snake_apply


class VIEW3D_PT_relief_snake_extract(bpy.types.Panel):
    """Sub-panel under Relief Snake: Extract and Apply."""
    bl_label = "Extract & Apply"
    bl_idname = "VIEW3D_PT_relief_snake_extract"
    bl_parent_id = "VIEW3D_PT_relief_snake"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "Relief"

    def draw(self, context):
        layout = self.layout
        layout.operator(MESH_OT_relief_snake_extract.bl_idname, icon='MOD_DISPLACE')
        row = layout.row(align=True)
        op = row.operator(OBJECT_OT_relief_snake_apply.bl_idname, text="Apply as Mesh", icon='MESH_ICOSPHERE')
        op.method = 'MESH'
        op = row.operator(OBJECT_OT_relief_snake_apply.bl_idname, text="Displace", icon='MODIFIER')
        op.method = 'DISPLACE'
        op = layout.operator(OBJECT_OT_relief_snake_apply.bl_idname, text="Apply at Click", icon='RESTRICT_SELECT_OFF')
        op.method = 'MESH'
        op.placement = 'CLICK'
        summary = context.scene.get(LAST_EXTRACT)
        if summary:
            box = layout.box()
            for part in summary.replace("Relief Snake: ", "Last: ").split("; "):
                box.label(text=part)


classes = (VIEW3D_PT_relief_snake_extract,)
