"""Scene settings shown in the sidebar panel (scene.relief_snake)."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, StringProperty

SIDE_ITEMS = (
    ('LEFT', "Left", "The relief lies left of the open contour, walking along the picks seen from outside"),
    ('RIGHT', "Right", "The relief lies right of the open contour, walking along the picks seen from outside"),
)


class ReliefSnakeSettings(bpy.types.PropertyGroup):
    step_height: FloatProperty(
        name="Step Height", description="h: height of the relief's step, in object units "
        "(Measure sets it from two selected vertices)", default=0.0, min=0.0, soft_max=100.0,
        precision=4, subtype='DISTANCE')
    w_int: FloatProperty(
        name="W_int", description="Weight of the internal (smoothness) energy during refinement; "
        "the paper uses 0.25", default=0.25, min=0.01, max=1.0)
    open_contour: BoolProperty(
        name="Open Contour", description="The relief touches the mesh boundary: the contour ends there",
        default=False)
    relief_side: EnumProperty(name="Relief Side", items=SIDE_ITEMS, default='LEFT',
                              description="Open contours: which side of the picks the relief is on")
    group_name: StringProperty(name="Vertex Group", default="Relief",
                               description="Vertex group that receives the relief vertices (replaced)")
    make_curve: BoolProperty(name="Contour Curve", default=True,
                             description="Also create a curve object along the final contour")
    # Last run, for the panel (written only after a successful run).
    last_summary: StringProperty(name="Last Run", default="")
    last_phases: StringProperty(name="Last Phases", default="")  # one phase per line


classes = (ReliefSnakeSettings,)
