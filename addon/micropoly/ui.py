# SPDX-License-Identifier: GPL-3.0-or-later
"""Render properties panels, and the standard Blender panels Micropoly uses."""

import bpy

ENGINE = "MICROPOLY"

# Built-in panels that apply unchanged to this engine (dimensions, output,
# color management, camera, light and material basics).
STANDARD_PANELS = (
    "RENDER_PT_format", "RENDER_PT_frame_range", "RENDER_PT_time_stretching", "RENDER_PT_stereoscopy",
    "RENDER_PT_output", "RENDER_PT_output_views", "RENDER_PT_encoding", "RENDER_PT_encoding_video",
    "RENDER_PT_encoding_audio", "RENDER_PT_color_management", "RENDER_PT_color_management_curves",
    "RENDER_PT_post_processing", "RENDER_PT_stamp", "RENDER_PT_stamp_note", "RENDER_PT_stamp_burn",
    "DATA_PT_context_camera", "DATA_PT_lens", "DATA_PT_camera", "DATA_PT_camera_display", "DATA_PT_camera_dof",
    "DATA_PT_camera_dof_aperture",
    "DATA_PT_context_light", "DATA_PT_light", "DATA_PT_EEVEE_light", "DATA_PT_EEVEE_light_distance",
    "DATA_PT_spot", "DATA_PT_area", "MATERIAL_PT_preview", "EEVEE_MATERIAL_PT_context_material",
    "EEVEE_MATERIAL_PT_surface", "MATERIAL_PT_viewport", "WORLD_PT_context_world", "EEVEE_WORLD_PT_surface",
    "WORLD_PT_viewport_display", "VIEWLAYER_PT_layer", "VIEWLAYER_PT_layer_passes",
    "VIEWLAYER_PT_eevee_layer_passes_data", "DATA_PT_context_mesh", "DATA_PT_normals", "DATA_PT_uv_texture",
    "DATA_PT_vertex_groups", "DATA_PT_shape_keys", "DATA_PT_customdata",
)


class MicropolyPanel:
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES


class MICROPOLY_PT_sampling(MicropolyPanel, bpy.types.Panel):
    bl_label = "Sampling"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        settings = context.scene.micropoly
        col = layout.column(align=True)
        col.prop(settings, "samples", text="Render Samples")
        col.prop(settings, "viewport_samples", text="Viewport")
        layout.prop(settings, "filter_type")
        layout.prop(settings, "filter_width")


class MICROPOLY_PT_dicing(MicropolyPanel, bpy.types.Panel):
    bl_label = "Dicing"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        settings = context.scene.micropoly
        col = layout.column(align=True)
        col.prop(settings, "shading_rate", text="Render Shading Rate")
        col.prop(settings, "viewport_shading_rate", text="Viewport")
        layout.prop(settings, "max_grid_size")
        layout.prop(settings, "dof_dice_factor")
        layout.prop(settings, "texture_filter_width")


class MICROPOLY_PT_motion_blur(MicropolyPanel, bpy.types.Panel):
    """Render > Motion Blur: Blender's own settings (as Cycles reads them)
    and the number of motion steps."""
    bl_label = "Motion Blur"
    bl_options = {"DEFAULT_CLOSED"}

    def draw_header(self, context):
        self.layout.prop(context.scene.render, "use_motion_blur", text="")

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        scene = context.scene
        layout.active = scene.render.use_motion_blur
        owner = scene.render if hasattr(scene.render, "motion_blur_position") else getattr(scene, "cycles", None)
        if owner is not None and hasattr(owner, "motion_blur_position"):
            layout.prop(owner, "motion_blur_position", text="Position")
        layout.prop(scene.render, "motion_blur_shutter")
        layout.prop(scene.micropoly, "motion_steps")


class MICROPOLY_PT_motion_blur_curve(MicropolyPanel, bpy.types.Panel):
    """Render > Motion Blur > Shutter Curve: how open the shutter is over its time."""
    bl_label = "Shutter Curve"
    bl_parent_id = "MICROPOLY_PT_motion_blur"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        render = context.scene.render
        self.layout.active = render.use_motion_blur
        self.layout.template_curve_mapping(render, "motion_blur_shutter_curve")


class MICROPOLY_PT_bound_split(MicropolyPanel, bpy.types.Panel):
    bl_label = "Bound & Split"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        settings = context.scene.micropoly
        layout.prop(settings, "bound_split_method")
        row = layout.row()
        row.enabled = settings.bound_split_method == "BOUNDED"
        row.prop(settings, "bound_split_memory")
        layout.prop(settings, "use_occlusion_culling")
        layout.prop(settings, "use_sample_culling")
        layout.prop(settings, "sample_memory")


class MICROPOLY_PT_shadows(MicropolyPanel, bpy.types.Panel):
    bl_label = "Shadows"
    bl_options = {"DEFAULT_CLOSED"}

    def draw_header(self, context):
        self.layout.prop(context.scene.micropoly, "use_shadows", text="")

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        settings = context.scene.micropoly
        layout.active = settings.use_shadows
        layout.prop(settings, "shadow_memory")
        layout.prop(settings, "world_shadow_directions")
        layout.prop(settings, "shadow_shading_rate")


class MICROPOLY_PT_light_shadow(MicropolyPanel, bpy.types.Panel):
    """Light > Shadow: the settings Micropoly reads, under the names the running Blender gives them."""
    bl_label = "Shadow"
    bl_context = "data"

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES and context.light is not None

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        light = context.light
        cycles = getattr(light, "cycles", None)
        if cycles is not None and hasattr(cycles, "cast_shadow"):
            layout.prop(cycles, "cast_shadow")
        elif hasattr(light, "use_shadow"):
            layout.prop(light, "use_shadow", text="Cast Shadow")
        if light.type in ("POINT", "SPOT"):
            layout.prop(light, "shadow_soft_size", text="Radius")
            if hasattr(light, "use_soft_falloff"):
                layout.prop(light, "use_soft_falloff")
        elif light.type == "SUN":
            layout.prop(light, "angle")


class MICROPOLY_PT_object_visibility(MicropolyPanel, bpy.types.Panel):
    """Object > Visibility: the ray visibility Micropoly reads (camera and shadow)."""
    bl_label = "Micropoly Visibility"
    bl_context = "object"

    @classmethod
    def poll(cls, context):
        obj = context.object
        return context.engine in cls.COMPAT_ENGINES and obj is not None and hasattr(obj, "visible_shadow")

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        col = layout.column(heading="Ray Visibility")
        col.prop(context.object, "visible_camera", text="Camera")
        col.prop(context.object, "visible_shadow", text="Shadow")


class MICROPOLY_PT_film(MicropolyPanel, bpy.types.Panel):
    bl_label = "Film"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.prop(context.scene.render, "film_transparent")


class MICROPOLY_PT_material_displacement(MicropolyPanel, bpy.types.Panel):
    """Material > Micropoly: the displacement bound; the method is Cycles' own setting."""
    bl_label = "Micropoly Displacement"
    bl_context = "material"

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES and context.material is not None

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        mat = context.material
        if hasattr(mat, "displacement_method"):
            layout.prop(mat, "displacement_method", text="Displacement")
        elif hasattr(mat, "cycles"):
            layout.prop(mat.cycles, "displacement_method", text="Displacement")
        layout.prop(mat.micropoly, "displacement_bound")


CLASSES = (MICROPOLY_PT_sampling, MICROPOLY_PT_dicing, MICROPOLY_PT_bound_split, MICROPOLY_PT_shadows,
           MICROPOLY_PT_film, MICROPOLY_PT_motion_blur, MICROPOLY_PT_motion_blur_curve,
           MICROPOLY_PT_material_displacement, MICROPOLY_PT_light_shadow,
           MICROPOLY_PT_object_visibility)


def _standard_panels():
    for name in STANDARD_PANELS:
        panel = getattr(bpy.types, name, None)
        if panel is not None and hasattr(panel, "COMPAT_ENGINES"):
            yield panel


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    for panel in _standard_panels():
        panel.COMPAT_ENGINES.add(ENGINE)


def unregister():
    for panel in _standard_panels():
        panel.COMPAT_ENGINES.discard(ENGINE)
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
