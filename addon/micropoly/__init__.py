# SPDX-License-Identifier: GPL-3.0-or-later
"""Micropoly: a Reyes (micropolygon) render engine for Blender.

This file only declares the add-on and registers its parts; the render engine
lives in engine.py and the renderer itself in the native module _native.
Importing the package outside Blender (tests, scripts) gives access to
micropoly._native without touching bpy.
"""

bl_info = {
    "name": "Micropoly",
    "author": "Micropoly developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Render Properties > Render Engine > Micropoly",
    "description": "Reyes micropolygon renderer running in OpenCL",
    "category": "Render",
}

from . import native_module  # noqa: E402

native_module.alias_wheel_module(__package__)

_MODULES = ("properties", "preferences", "engine", "ui", "operators")


def _modules():
    import importlib

    return [importlib.import_module(f".{name}", __package__) for name in _MODULES]


def register():
    for module in _modules():
        module.register()


def unregister():
    for module in reversed(_modules()):
        module.unregister()
