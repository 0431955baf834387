# SPDX-License-Identifier: GPL-3.0-or-later
"""Add-on preferences: which OpenCL device renders."""

import atexit

import bpy
from bpy.props import EnumProperty

from . import final_renderers, warm_up

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


def _start_warm_up():
    # Loading the OpenCL drivers and building the kernels is the slowest
    # part of a first render (seconds on the CPU). Done in the background when
    # the add-on registers, the first F12 or Rendered viewport finds them
    # built (warm_up.py), and so for the material programs of each file
    # opened; where Blender does not warm up (background mode), the drivers
    # alone are loaded. A thread still inside the drivers when Python shuts down would
    # be torn down as it takes the GIL back, which can abort the process: it
    # is stopped and waited for at exit.
    global _exit_hook
    selector = _selector_now()
    wanted = warm_up.wanted()
    warm_up.start(selector, final_renderers.shared(), build=wanted)
    if wanted:
        try:
            materials = list(bpy.data.materials)
        except AttributeError:  # Blender's start: the file is not loaded yet
            materials = []
        warm_up.add_file_materials(materials, selector, final_renderers.shared())
        warm_up.show_in_status_bar()
    if not _exit_hook:
        atexit.register(warm_up.stop)
        _exit_hook = True


def _selector_now():
    try:
        return device_selector(bpy.context)
    except Exception:  # preferences not loaded yet
        return ""


@bpy.app.handlers.persistent
def _file_loaded(*_):
    if not warm_up.wanted():
        return
    warm_up.add_file_materials(list(bpy.data.materials), _selector_now(), final_renderers.shared())
    warm_up.show_in_status_bar()


_exit_hook = False


def register():
    bpy.utils.register_class(MicropolyPreferences)
    _start_warm_up()
    if _file_loaded not in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.append(_file_loaded)


def unregister():
    if _file_loaded in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_file_loaded)
    warm_up.hide_from_status_bar()
    bpy.utils.unregister_class(MicropolyPreferences)
