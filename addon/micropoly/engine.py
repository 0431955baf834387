# SPDX-License-Identifier: GPL-3.0-or-later
"""The Micropoly render engine as Blender sees it (registered by __init__)."""

import bpy


class MicropolyRenderEngine(bpy.types.RenderEngine):
    bl_idname = "MICROPOLY"
    bl_label = "Micropoly"
    bl_use_preview = False

    def render(self, depsgraph):
        from . import render_session

        render_session.render_final(self, depsgraph)


def register():
    bpy.utils.register_class(MicropolyRenderEngine)


def unregister():
    bpy.utils.unregister_class(MicropolyRenderEngine)
