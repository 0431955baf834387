"""Hair shading in Blender (run by blender -b, or a Python with the bpy
module) against Cycles' direct light with shadows, under a sun and an area
light:

- three thick strands, one each of the Principled Hair BSDF by melanin and
  by direct colour and of the Hair BSDF's reflection: PSNR >= 35 dB over
  the pixels both cover, and each strand's mean colour within 5 %;
- the three strands moving across the frame, motion-blurred: >= 30 dB
  against Cycles' motion blur over every pixel either image covers;
- a head (a sphere) with particle hair, 400 guides and 4,000 strands
  interpolated between them, about a pixel wide, Principled Hair by
  melanin, casting shadows onto the skin and onto themselves: >= 30 dB
  over covered pixels against Cycles' 3D Curves (Micropoly's round tubes)
  and against its Rounded Ribbons (Micropoly's ribbons; Cycles renders
  these in the session: Blender places interpolated children differently
  in each).

Exits non-zero on failure."""

import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import render_utils as ru  # noqa: E402

RESULTS = []
W, H = 320, 240
CYCLES_SAMPLES = 256
CURVES, KEYS = 500, 8  # what curves_random_add makes, in every version tested


def check(name, condition, detail=""):
    RESULTS.append(bool(condition))
    print(f"{'ok  ' if condition else 'FAIL'} {name}" + (f": {detail}" if detail else ""))


def hair_material(name, kind, **inputs):
    """Principled Hair (parametrisation `kind`: MELANIN, COLOR, ABSORPTION;
    Chiang's model where there is a choice) or the Hair BSDF (kind
    REFLECTION), with the given inputs."""
    m, out = ru.empty_material(name)
    nodes = m.node_tree.nodes
    if kind == "REFLECTION":
        bsdf = nodes.new("ShaderNodeBsdfHair")
        bsdf.component = "Reflection"
    else:
        bsdf = nodes.new("ShaderNodeBsdfHairPrincipled")
        bsdf.parametrization = kind
        if hasattr(bsdf, "model"):
            bsdf.model = "CHIANG"
    for key, value in inputs.items():
        bsdf.inputs[key].default_value = value
    m.node_tree.links.new(bsdf.outputs[0], out.inputs["Surface"])
    return m


def add_curves(name, material):
    """A Curves object of CURVES strands of KEYS points, at the origin."""
    bpy.ops.object.curves_random_add()
    hair = bpy.context.active_object
    hair.name = name
    hair.location = (0.0, 0.0, 0.0)
    hair.data.materials.append(material)
    assert (len(hair.data.curves), len(hair.data.points)) == (CURVES, CURVES * KEYS)
    return hair


def set_strands(hair, pos, radii):
    hair.data.attributes["position"].data.foreach_set("vector", np.ascontiguousarray(pos, np.float32).reshape(-1))
    hair.data.attributes["radius"].data.foreach_set("value", np.ascontiguousarray(radii, np.float32).reshape(-1))
    hair.data.update_tag()


def lights(scene):
    ru.add_sun(scene, (math.radians(40), 0.0, math.radians(30)), energy=2.5)
    ru.add_aimed_light(scene, "AREA", (-2.0, -2.5, 2.5), (0.0, 0.0, 0.3), 250.0, size=1.0)


def strands_scene():
    """Three strands 0.3 thick across the frame, each its own material (the
    rest of each object's strands far aside)."""
    scene = ru.reset_scene()
    ru.add_camera(scene, (0.0, -3.2, 1.4), (0.0, 0.0, 0.35))
    lights(scene)
    materials = [hair_material("Melanin", "MELANIN", Melanin=0.5, **{"Melanin Redness": 0.3}),
                 hair_material("Colour", "COLOR", Color=(0.6, 0.3, 0.15, 1.0), Roughness=0.4),
                 hair_material("Reflection", "REFLECTION", Color=(0.8, 0.5, 0.3, 1.0))]
    t = np.linspace(0.0, 1.0, KEYS)
    for k, (x, material) in enumerate(zip((-0.8, 0.0, 0.8), materials)):
        pos = np.zeros((CURVES, KEYS, 3), np.float32)
        pos[:, :, 0] = 50.0
        pos[0, :, 0] = x + 0.15 * (k - 1) * t ** 2
        pos[0, :, 1] = 0.3 * (k - 1) * np.sin(3.0 * t)
        pos[0, :, 2] = -1.5 + 4.0 * t
        radii = np.zeros((CURVES, KEYS), np.float32)
        radii[0] = 0.15
        set_strands(add_curves(f"Strand{k}", material), pos, radii)
    return scene


def moving_strands_scene():
    """The three strands, moving 0.4 to the right during a shutter of one
    frame (linear keys at frames 1 and 3, frame 2 rendered)."""
    scene = strands_scene()
    r = scene.render
    r.use_motion_blur = True
    r.motion_blur_shutter = 1.0
    (r if hasattr(r, "motion_blur_position") else scene.cycles).motion_blur_position = "CENTER"
    bpy.context.preferences.edit.keyframe_new_interpolation_type = "LINEAR"
    for obj in scene.objects:
        if obj.type == "CURVES":
            obj.location.x = -0.4
            obj.keyframe_insert("location", frame=1)
            obj.location.x = 0.4
            obj.keyframe_insert("location", frame=3)
    scene.frame_set(2)
    return scene


def head_scene():
    """A sphere of radius 0.5 (diffuse skin) with a hair particle system:
    400 guide strands 0.35 long and 10 children interpolated between them
    for each (4,000 strands), 0.01 thick at the root, tapering to nothing."""
    scene = ru.reset_scene()
    ru.add_camera(scene, (0.0, -3.0, 1.0), (0.0, 0.0, 0.3))
    lights(scene)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, segments=48, ring_count=24, location=(0.2, 0.0, 0.3))
    head = bpy.context.active_object
    head.name = "Head"
    head.data.materials.append(ru.diffuse_material("Skin", (0.8, 0.6, 0.5)))
    head.data.materials.append(hair_material("Hair", "MELANIN", Melanin=0.35, **{"Melanin Redness": 0.6}))
    ru.shade_smooth(head)
    # The settings are made whole before the system uses them: hair that a
    # system has already grown keeps its roots when its count changes.
    settings = bpy.data.particles.new("Hair")
    settings.type = "HAIR"
    settings.count = 400
    settings.hair_length = 0.35
    settings.child_type = "INTERPOLATED"
    settings.rendered_child_count = 10
    setattr(settings, "child_nbr" if hasattr(settings, "child_nbr") else "child_percent", 10)  # the viewport's
    settings.render_step = settings.display_step = 3
    settings.root_radius, settings.tip_radius, settings.radius_scale = 1.0, 0.0, 0.01
    settings.material = 2
    head.modifiers.new("Hair", "PARTICLE_SYSTEM")
    head.particle_systems[0].settings = settings
    return scene, head


def compare(name, ref, got, min_psnr):
    both = (ref[..., 3] > 0.999) & (got[..., 3] > 0.999)
    a, b = ref[both][:, :3], got[both][:, :3]
    p = ru.psnr(a, b, peak=float(a.max())) if both.sum() > 100 else 0.0
    iou = ru.iou(ref[..., 3], got[..., 3])
    check(name, p >= min_psnr and iou >= 0.95 and both.sum() > 1000,
          f"{p:.1f} dB over {int(both.sum())} covered pixels, alpha IoU {iou:.4f}")
    return both


def set_shape(scene, shape):
    if hasattr(scene, "cycles_curves"):
        scene.cycles_curves.shape = shape


def main():
    scene = strands_scene()
    ru.setup_cycles(scene, samples=CYCLES_SAMPLES, shadows=True)
    set_shape(scene, "THICK")
    ref = ru.render_passes(scene, "CYCLES", W, H)["rgba"]
    got = ru.render_passes(scene, "MICROPOLY", W, H, samples=16)["rgba"]
    both = compare("three strands (melanin, colour, Hair BSDF reflection)", ref, got, 35.0)
    # Each strand's own pixels: the frame's thirds.
    for k, name in enumerate(("Principled Hair by melanin", "Principled Hair by colour", "Hair BSDF reflection")):
        part = both.copy()
        part[:, : k * W // 3] = False
        part[:, (k + 1) * W // 3:] = False
        r, g = ref[part][:, :3].mean(0), got[part][:, :3].mean(0)
        check(f"{name}: mean colour", part.sum() > 500 and np.all(np.abs(g / r - 1.0) <= 0.05),
              f"{np.round(g, 4)} against {np.round(r, 4)}")

    scene = moving_strands_scene()
    ru.setup_cycles(scene, samples=CYCLES_SAMPLES, shadows=True)
    set_shape(scene, "THICK")
    ref = ru.render_passes(scene, "CYCLES", W, H)["rgba"]
    got = ru.render_passes(scene, "MICROPOLY", W, H, samples=64)["rgba"]  # blur is noise at 16 samples
    # Blurred: few pixels are wholly covered, so colour and alpha (colour
    # premultiplied) are compared wherever either image has any.
    seen = (ref[..., 3] > 0.01) | (got[..., 3] > 0.01)
    p = ru.psnr(ref[seen], got[seen], peak=float(ref[seen].max()))
    check("the strands moving, against Cycles' motion blur", p >= 30.0 and seen.sum() > 5000,
          f"{p:.1f} dB over {int(seen.sum())} pixels either covers")

    scene, head = head_scene()
    from micropoly import export

    exported = export.export_scene(bpy.context.evaluated_depsgraph_get())
    check("particle hair: the head and its hair", exported.scene.patch_set_count == 1 and exported.objects == 2,
          f"{exported.objects} objects, {exported.scene.patch_set_count} patch sets")
    ru.setup_cycles(scene, samples=CYCLES_SAMPLES, shadows=True)
    # Cycles renders the head in this session: Blender places interpolated
    # children differently in each (render_utils.render_passes, stored).
    # Micropoly draws each shape as Cycles does: round tubes for 3D Curves,
    # ribbons facing each view for Rounded Ribbons (docs/blender.md, Curves).
    for shape, name in (("THICK", "3D Curves"), ("RIBBONS", "Rounded Ribbons")):
        set_shape(scene, shape)
        got = ru.render_passes(scene, "MICROPOLY", W, H, samples=16)["rgba"]
        compare(f"a head of 4,000 interpolated strands against Cycles' {name}",
                ru.render_passes(scene, "CYCLES", W, H, stored=False)["rgba"], got, 30.0)
    return 0 if all(RESULTS) else 1


ru.run_test(main)
