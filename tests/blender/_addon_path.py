"""Puts addon/relief_snake/ on sys.path so its bpy-free modules import standalone (plain pytest)."""
import os
import sys

ADDON = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "addon",
                                      "relief_snake"))
if ADDON not in sys.path:
    sys.path.insert(0, ADDON)
