# SPDX-License-Identifier: GPL-3.0-or-later
"""Micropoly's settings, stored on the scene as scene.micropoly."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty

FILTERS = [
    ("BLACKMAN_HARRIS", "Blackman-Harris", "Blackman-Harris window, as Cycles uses"),
    ("GAUSSIAN", "Gaussian", "RenderMan's Gaussian filter"),
    ("BOX", "Box", "Box filter: each pixel averages its own samples"),
    ("TRIANGLE", "Triangle", "Tent filter"),
]

BOUND_SPLIT = [
    ("BOUNDED", "Bounded Memory", "Depth-first workers within a fixed memory budget (Weber et al. 2015)"),
    ("BREADTH", "Breadth-First", "Whole queue per pass, memory grows with the scene (Patney & Owens 2008)"),
]


class MicropolySceneSettings(bpy.types.PropertyGroup):
    samples: IntProperty(name="Samples", description="Samples per pixel for final renders",
                         default=16, min=1, max=1024)
    shading_rate: FloatProperty(name="Shading Rate", description="Area of a micropolygon in pixels; "
                                "smaller is finer and slower", default=1.0, min=0.05, max=64.0)
    viewport_samples: IntProperty(name="Viewport Samples", description="Samples per pixel that Rendered "
                                  "viewport shading refines to", default=16, min=1, max=1024)
    viewport_shading_rate: FloatProperty(name="Viewport Shading Rate", description="Area of a micropolygon "
                                         "in pixels in the Rendered viewport; coarser than final renders keeps "
                                         "the view responsive", default=2.0, min=0.05, max=64.0)
    texture_filter_width: FloatProperty(name="Texture Filter Width", description="Image textures are "
                                        "averaged over this many times each micropolygon's area in the image "
                                        "(MIP-mapped, anisotropic); 0 reads them unfiltered, which aliases "
                                        "where they are minified", default=1.0, min=0.0, max=16.0)
    max_grid_size: IntProperty(name="Split Limit", description="Largest grid, in micropolygons per side, "
                               "that a sub-patch is diced into before it is split instead",
                               default=16, min=2, max=32)
    bound_split_method: EnumProperty(name="Bound & Split", items=BOUND_SPLIT, default="BOUNDED")
    bound_split_memory: FloatProperty(name="Memory Budget", description="Device memory for bound & split, "
                                      "in MiB (bounded method)", default=64.0, min=0.25, max=65536.0)
    use_occlusion_culling: BoolProperty(name="Occlusion Culling", description="Skip surfaces hidden behind "
                                        "what is already rendered before dicing them (the image is the same; "
                                        "off for comparison)", default=True)
    use_sample_culling: BoolProperty(name="Sample Culling", description="Skip surfaces a pixel or two across "
                                     "that fall between the samples before dicing them: distant instances cost "
                                     "the samples they cover (the image is the same; off for comparison)",
                                     default=True)
    filter_type: EnumProperty(name="Pixel Filter", items=FILTERS, default="BLACKMAN_HARRIS")
    filter_width: FloatProperty(name="Filter Width", description="Pixel filter width in pixels, as Cycles "
                                "reads it (Blackman-Harris reaches this far on each side of a pixel's centre)",
                                default=1.5, min=0.5, max=8.0, subtype="PIXEL")
    use_shadows: BoolProperty(name="Shadows", description="Lights cast shadows (each light's Cast Shadow "
                              "and each object's Shadow ray visibility still apply)", default=True)
    shadow_memory: FloatProperty(name="Shadow Memory", description="Device memory for the shadow maps' pages, "
                                 "in MiB; when the view needs more, shadows get coarser", default=256.0, min=8.0,
                                 max=65536.0)
    shadow_shading_rate: FloatProperty(name="Shadow Shading Rate", description="Area of a shadow map's "
                                       "micropolygons in its texels; smaller is finer and slower", default=4.0,
                                       min=0.25, max=64.0)
    world_shadow_directions: IntProperty(name="World Shadow Directions", description="Directions from which the "
                                         "scene shadows its world's light, each a soft shadow map placed where the "
                                         "world is bright; 0 leaves world light unshadowed", default=16, min=0,
                                         max=64)
    motion_steps: IntProperty(name="Motion Steps", description="Accuracy of motion blur: the scene is evaluated "
                              "at 2^steps + 1 times over the shutter (Cycles' per-object steps, for the whole "
                              "scene) and moves linearly between them", default=1, min=1, max=5)
    sample_memory: FloatProperty(name="Sample Memory", description="Device memory for the frame's samples "
                                 "(24 bytes each), in MiB; a frame that needs more renders in buckets that fit",
                                 default=2048.0, min=16.0, max=1048576.0)
    dof_dice_factor: FloatProperty(name="Defocus Dicing", description="Out of focus, micropolygons grow to this "
                                   "fraction of the circle of confusion (RenderMan's focus factor); 0 dices "
                                   "blurred surfaces as sharp ones", default=0.5, min=0.0, max=4.0)


class MicropolyMaterialSettings(bpy.types.PropertyGroup):
    displacement_bound: FloatProperty(
        name="Displacement Bound", description="How far, in object units, displacement can move the surface "
        "(as RenderMan's displacementbound); 0 derives it from the node tree", default=0.0, min=0.0,
        soft_max=10.0, subtype="DISTANCE")


def register():
    bpy.utils.register_class(MicropolySceneSettings)
    bpy.utils.register_class(MicropolyMaterialSettings)
    bpy.types.Scene.micropoly = PointerProperty(type=MicropolySceneSettings)
    bpy.types.Material.micropoly = PointerProperty(type=MicropolyMaterialSettings)


def unregister():
    del bpy.types.Material.micropoly
    del bpy.types.Scene.micropoly
    bpy.utils.unregister_class(MicropolyMaterialSettings)
    bpy.utils.unregister_class(MicropolySceneSettings)
