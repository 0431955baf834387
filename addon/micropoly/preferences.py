# SPDX-License-Identifier: GPL-3.0-or-later
"""Add-on preferences: which OpenCL device renders."""

import atexit
import threading

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


def _start_opencl():
    # Loading the OpenCL drivers and listing their devices is the slowest part
    # of making the first renderer (about 80 ms with PoCL, out of 90 ms).
    # Doing it once in the background when the add-on registers means the
    # first F12 or Rendered viewport does not wait for it; later calls find
    # the drivers loaded. Failures are left for the render to report.
    def start():
        try:
            from . import _native

            _native.list_devices()
        except Exception:
            pass

    thread = threading.Thread(target=start, name="micropoly-opencl-start", daemon=True)
    thread.start()
    # A thread still inside the drivers when Python shuts down would be torn
    # down as it takes the GIL back, which can abort the process: wait for it.
    atexit.register(thread.join, 10.0)


def register():
    bpy.utils.register_class(MicropolyPreferences)
    _start_opencl()


def unregister():
    bpy.utils.unregister_class(MicropolyPreferences)
