"""The panel's settings (scene.relief_snake), defined once and shared with the Segment operator
(its redo panel shows the same fields), and the add-on's preferences.

Settings survive undo: Blender's undo restores the scene, which used to reset Step Height to
its value when Edit Mode was entered, so the next Segment failed until h was typed again.
What the user sets is remembered here (update callbacks) and put back after undo and redo.
"""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, FloatVectorProperty, IntProperty, StringProperty

SIDE_ITEMS = (
    ('AUTO', "Auto", "The engine decides: the side of the picks that rises (it tries the other side when "
                     "that one's result looks like a wrong side, and the summary names the side used)"),
    ('LEFT', "Left", "The relief lies left of the open outline, walking along the picks seen from outside"),
    ('RIGHT', "Right", "The relief lies right of the open outline, walking along the picks seen from outside"),
)

# Names of the settings the operator shares with the panel, in panel order.
SETTING_NAMES = ("step_height", "estimate_step_height", "smoothness", "auto_smoothness", "open_contour",
                 "relief_side", "group_name", "make_curve", "show_region")

_remembered = {}  # scene name -> {setting: value} as the user last set them


def _remember(settings, _context):
    scene = settings.id_data
    if scene is not None:
        _remembered[scene.name_full] = {n: getattr(settings, n) for n in SETTING_NAMES}


def setting_properties(update=None):
    """The shared settings as bpy.props definitions (a dict for __annotations__)."""
    kw = {"update": update} if update else {}
    return {
        "step_height": FloatProperty(
            name="Step Height", default=0.0, min=0.0, soft_max=100.0, precision=4, subtype='DISTANCE',
            unit='LENGTH',
            description="How high the relief's step rises above the surface around it, in the scene's "
            "length unit shown in the field (measured in the mesh's own coordinates). Measure sets it "
            "from two selected vertices", **kw),
        "estimate_step_height": BoolProperty(
            name="Estimate", default=False,
            description="Let the engine estimate the step height from the picks (needs an engine that "
            "supports it; the result says how sure it is)", **kw),
        "smoothness": FloatProperty(
            name="Smoothness", default=0.25, min=0.01, max=1.0,
            description="How strongly the outline resists bending while it is refined: higher is smoother, "
            "lower follows the step more closely (0.25 is the paper's value)", **kw),
        "auto_smoothness": BoolProperty(
            name="Auto", default=True,
            description="Let the engine choose the smoothness (an engine without that choice uses 0.25)", **kw),
        "open_contour": BoolProperty(
            name="Open Outline", default=False,
            description="The relief runs off the edge of the mesh: the outline ends on the mesh's border", **kw),
        "relief_side": EnumProperty(
            name="Relief Side", items=SIDE_ITEMS, default='AUTO',
            description="Open outlines: which side of the picks the relief is on", **kw),
        "group_name": StringProperty(
            name="Group", default="Relief",
            description="Vertex group that receives the relief's vertices (its old members are replaced)", **kw),
        "make_curve": BoolProperty(
            name="Outline Curve", default=True,
            description="Also make (or update) an orange curve object along the outline", **kw),
        "show_region": BoolProperty(
            name="Show Region", default=True,
            description="Tint the relief region green in the viewport after a run (Object and Edit Mode)", **kw),
    }


class ReliefSnakeSettings(bpy.types.PropertyGroup):
    __annotations__ = dict(setting_properties(update=_remember))
    __annotations__.update({
        # The last run, for the panel (written only after a successful run).
        "last_summary": StringProperty(name="Last Run", default=""),
        "last_details": StringProperty(name="Last Run Details", default=""),  # one line per entry
        "last_warning": StringProperty(name="Last Warning", default=""),
    })


def preferences(context=None):
    """The add-on's preferences, or None when the add-on is not enabled through Blender (tests)."""
    context = context or bpy.context
    addon = context.preferences.addons.get(__package__)
    return addon.preferences if addon is not None else None


class ReliefSnakePreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    threads: IntProperty(
        name="Threads", default=0, min=0, max=256,
        description="Worker threads for the engine (0: as many as the computer has cores)")
    preview_color: FloatVectorProperty(
        name="Preview Colour", subtype='COLOR', size=4, min=0.0, max=1.0, default=(1.0, 0.45, 0.0, 1.0),
        description="Colour of the outline drawn while the engine runs")
    preview_width: FloatProperty(
        name="Preview Width", default=3.0, min=1.0, max=12.0,
        description="Width in pixels of the outline drawn while the engine runs")

    def draw(self, context):
        col = self.layout.column()
        col.prop(self, "threads")
        row = col.row()
        row.prop(self, "preview_color")
        row.prop(self, "preview_width")


@bpy.app.handlers.persistent
def _restore_after_undo(*_args):
    for scene in bpy.data.scenes:
        values = _remembered.get(scene.name_full)
        settings = getattr(scene, "relief_snake", None)
        if not values or settings is None:
            continue
        for name, value in values.items():
            if getattr(settings, name) != value:
                setattr(settings, name, value)


@bpy.app.handlers.persistent
def _forget_on_load(*_args):
    _remembered.clear()


_HANDLERS = ((bpy.app.handlers.undo_post, _restore_after_undo), (bpy.app.handlers.redo_post, _restore_after_undo),
             (bpy.app.handlers.load_post, _forget_on_load))


def register_handlers():
    unregister_handlers()
    for handlers, fn in _HANDLERS:
        handlers.append(fn)


def unregister_handlers():
    # By name too: a reload leaves the previous module's functions in the lists.
    for handlers, fn in _HANDLERS:
        for h in list(handlers):
            if h is fn or (getattr(h, "__name__", None) == fn.__name__
                           and getattr(h, "__module__", None) == fn.__module__):
                handlers.remove(h)


classes = (ReliefSnakeSettings, ReliefSnakePreferences)
