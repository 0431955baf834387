# SPDX-License-Identifier: GPL-3.0-or-later
"""Add-on preferences: which OpenCL device renders."""

import bpy
from bpy.props import EnumProperty

ADDON = __package__


def _device_items(self, context):
    items = [("AUTO", "Automatic", "The first GPU, else the CPU (or MICROPOLY_DEVICE)", 0)]
    try:
        from . import _native

        for d in _native.list_devices():
            items.append((str(d["index"]), f"{d['name']} ({d['type'].upper()})",
                          f"{d['platform']}, {d['version']}", d["index"] + 1))
    except Exception as e:  # no driver, broken module: keep the menu usable
        items.append(("NONE", "No OpenCL devices", str(e), 999))
    # Blender keeps the strings of dynamic enum items only while a reference exists.
    _device_items.cache = items
    return items


class MicropolyPreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON

    device: EnumProperty(name="Device", description="OpenCL device that renders", items=_device_items)

    def draw(self, context):
        self.layout.prop(self, "device")


def device_selector(context):
    """The selector string for micropoly._native.Renderer ('' for automatic)."""
    addon = context.preferences.addons.get(ADDON) if context else None
    if addon is None:
        return ""
    try:
        value = addon.preferences.device
    except (TypeError, ValueError):
        return ""
    return "" if value in ("AUTO", "NONE", "") else value


def register():
    bpy.utils.register_class(MicropolyPreferences)


def unregister():
    bpy.utils.unregister_class(MicropolyPreferences)
