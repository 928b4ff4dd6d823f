"""Lengths in the scene's units, for messages (the fields show them through unit='LENGTH')."""

import bpy


def format_length(scene, value):
    """`value` (mesh coordinates) as the scene shows lengths: '12.5 mm', '0.81 m', or a plain
    number when the scene has no unit system."""
    us = scene.unit_settings
    if us.system == 'NONE':
        return "%.4g" % value
    try:
        return bpy.utils.units.to_string(us.system, 'LENGTH', value * us.scale_length, precision=4)
    except (TypeError, ValueError, AttributeError):
        return "%.4g" % value
