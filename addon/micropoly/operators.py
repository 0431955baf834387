# SPDX-License-Identifier: GPL-3.0-or-later
"""File > Export > RenderMan RIB (Micropoly), and export_rib() for scripts."""

import bpy
from bpy.props import StringProperty
from bpy_extras.io_utils import ExportHelper


def export_rib(depsgraph, path):
    """Writes the scene that F12 would render as a RIB file for micropoly-render.
    Returns the list of export warnings."""
    from . import _native, export

    scene = depsgraph.scene
    exported = export.export_final(depsgraph, lambda frame, subframe: scene.frame_set(frame, subframe=subframe))
    _native.write_rib(exported.scene, path)
    return exported.warnings


class MICROPOLY_OT_export_rib(bpy.types.Operator, ExportHelper):
    """Export the scene as RenderMan RIB that micropoly-render renders like F12"""

    bl_idname = "export_scene.micropoly_rib"
    bl_label = "Export RIB (Micropoly)"
    filename_ext = ".rib"
    filter_glob: StringProperty(default="*.rib", options={"HIDDEN"})

    def execute(self, context):
        from . import export

        try:
            warnings = export_rib(context.evaluated_depsgraph_get(), self.filepath)
        except (export.ExportError, RuntimeError) as e:
            self.report({"ERROR"}, f"Micropoly: {e}")
            return {"CANCELLED"}
        for w in warnings:
            self.report({"WARNING"}, f"Micropoly: {w}")
        return {"FINISHED"}


def _menu(self, context):
    self.layout.operator(MICROPOLY_OT_export_rib.bl_idname, text="RenderMan RIB (Micropoly) (.rib)")


def register():
    bpy.utils.register_class(MICROPOLY_OT_export_rib)
    bpy.types.TOPBAR_MT_file_export.append(_menu)


def unregister():
    bpy.types.TOPBAR_MT_file_export.remove(_menu)
    bpy.utils.unregister_class(MICROPOLY_OT_export_rib)
