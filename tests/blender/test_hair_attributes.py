"""What hair materials read (run by blender -b, or a Python with the bpy
module), against Cycles on the same scene with emission shaders, so the
pictures are the values themselves: a field of tapering strands (a Curves
object) and a small plane beside it, each shown through four materials:

- Hair Info's (Curves Info's) Intercept, Random and Length;
- its Thickness, a float attribute on the points and a colour attribute on
  the curves;
- the default UV (a 2D vector attribute on the curves, the roots' UV) and
  Is Strand;
- its Tangent Normal.

The plane reads Hair Info as zeros, as in Cycles. Then particle hair on a
plane with a UV map: each strand's root UV on the emitter and Hair Info.
Each picture against Cycles' 3D Curves >= 35 dB over the pixels both
cover, silhouettes IoU >= 0.95. Last, the strands under a sun in
Principled Hair whose Random Color and Random Roughness take each strand's
own random number (Random unlinked, as Cycles reads it) >= 32 dB; and the
particle hair moving and growing during the shutter against Cycles' motion
blur >= 30 dB over every pixel either covers. Exits non-zero on failure."""

import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import render_utils as ru  # noqa: E402

RESULTS = []
W, H = 320, 240
CYCLES_SAMPLES = 32
CURVES, KEYS = 500, 8  # what curves_random_add makes, in every version tested
MIN_PSNR = 35.0


def check(name, condition, detail=""):
    RESULTS.append(bool(condition))
    print(f"{'ok  ' if condition else 'FAIL'} {name}" + (f": {detail}" if detail else ""))


def compare(name, ref, got, min_psnr=MIN_PSNR):
    both = (ref[..., 3] > 0.999) & (got[..., 3] > 0.999)
    a, b = ref[both][:, :3], got[both][:, :3]
    p = ru.psnr(a, b, peak=max(float(a.max()), 1e-3)) if both.sum() > 100 else 0.0
    iou = ru.iou(ref[..., 3], got[..., 3])
    check(name, p >= min_psnr and iou >= 0.95 and both.sum() > 1000,
          f"{p:.1f} dB over {int(both.sum())} covered pixels, alpha IoU {iou:.4f}")


def hair_info_node(nodes):
    return nodes.new("ShaderNodeHairInfo")


def material(name, build):
    """An emission material whose colour build(nodes, links) makes."""
    m, emission = ru.emission_material(name)
    nodes, links = m.node_tree.nodes, m.node_tree.links
    links.new(build(nodes, links), emission.inputs["Color"])
    return m


def combine(nodes, links, x, y, z):
    xyz = nodes.new("ShaderNodeCombineXYZ")
    for socket, value in zip(xyz.inputs, (x, y, z)):
        links.new(value, socket)
    return xyz.outputs["Vector"]


def scaled(nodes, links, value, factor):
    math = nodes.new("ShaderNodeMath")
    math.operation = "MULTIPLY"
    links.new(value, math.inputs[0])
    math.inputs[1].default_value = factor
    return math.outputs["Value"]


def info_material(nodes, links):
    info = hair_info_node(nodes)
    return combine(nodes, links, info.outputs["Intercept"], info.outputs["Random"], info.outputs["Length"])


def attribute_material(nodes, links):
    info = hair_info_node(nodes)
    point, curve = nodes.new("ShaderNodeAttribute"), nodes.new("ShaderNodeAttribute")
    point.attribute_name, curve.attribute_name = "stiffness", "tint"
    blue = nodes.new("ShaderNodeSeparateXYZ")
    links.new(curve.outputs["Color"], blue.inputs["Vector"])
    return combine(nodes, links, scaled(nodes, links, info.outputs["Thickness"], 20.0), point.outputs["Fac"],
                   blue.outputs["Z"])


def separate_uv(nodes, links):
    uv = nodes.new("ShaderNodeSeparateXYZ")
    links.new(nodes.new("ShaderNodeTexCoord").outputs["UV"], uv.inputs["Vector"])
    return uv.outputs["X"], uv.outputs["Y"]


def uv_material(nodes, links):
    info = hair_info_node(nodes)
    return combine(nodes, links, *separate_uv(nodes, links), scaled(nodes, links, info.outputs["Is Strand"], 0.5))


def particle_material(nodes, links):
    return combine(nodes, links, *separate_uv(nodes, links), hair_info_node(nodes).outputs["Intercept"])


def tangent_normal_material(nodes, links):
    shift = nodes.new("ShaderNodeVectorMath")
    shift.operation = "MULTIPLY_ADD"
    links.new(hair_info_node(nodes).outputs["Tangent Normal"], shift.inputs[0])
    shift.inputs[1].default_value = (0.5, 0.5, 0.5)
    shift.inputs[2].default_value = (0.5, 0.5, 0.5)
    return shift.outputs["Vector"]


MATERIALS = (("Intercept, Random, Length", info_material),
             ("Thickness and attributes on points and curves", attribute_material),
             ("root UV and Is Strand", uv_material), ("Tangent Normal", tangent_normal_material))


def set_shape(scene):
    if hasattr(scene, "cycles_curves"):
        scene.cycles_curves.shape = "THICK"


def curves_scene():
    """A 25 x 20 grid of strands rising 0.8, bending along x, 0.04 to 0.016
    thick, with a float attribute on the points, a colour and a UV on the
    curves; a 0.5 plane beside them."""
    scene = ru.reset_scene()
    ru.add_camera(scene, (0.0, -3.2, 1.4), (0.0, 0.0, 0.35))
    bpy.ops.mesh.primitive_plane_add(size=0.3, location=(0.45, -1.5, 1.05), rotation=(1.25, 0.0, 0.2))
    bpy.context.object.name = "Card"
    bpy.ops.object.curves_random_add()
    hair = bpy.context.active_object
    hair.name = "Hair"
    hair.location = (0.0, 0.0, 0.0)
    curves = hair.data
    assert (len(curves.curves), len(curves.points)) == (CURVES, CURVES * KEYS)
    gx, gy = np.meshgrid(np.linspace(-1.0, 1.0, 25), np.linspace(-0.8, 0.8, 20))
    t = np.linspace(0.0, 1.0, KEYS)
    pos = np.empty((CURVES, KEYS, 3), dtype=np.float32)
    pos[..., 0] = gx.reshape(-1, 1) + 0.25 * t ** 2 * (1.0 + gy.reshape(-1, 1))
    pos[..., 1] = gy.reshape(-1, 1) + 0.05 * np.sin(7.0 * gx.reshape(-1, 1)) * t
    pos[..., 2] = (0.6 + 0.3 * np.cos(5.0 * gx.reshape(-1, 1) + 3.0 * gy.reshape(-1, 1))) * t
    radii = np.broadcast_to(0.02 - 0.012 * t, (CURVES, KEYS)).astype(np.float32)
    curves.attributes["position"].data.foreach_set("vector", pos.reshape(-1))
    curves.attributes["radius"].data.foreach_set("value", np.ascontiguousarray(radii).reshape(-1))
    rng = np.random.default_rng(3)
    stiffness = curves.attributes.new("stiffness", "FLOAT", "POINT")
    stiffness.data.foreach_set("value", rng.random(CURVES * KEYS).astype(np.float32))
    tint = curves.attributes.new("tint", "FLOAT_COLOR", "CURVE")
    tint.data.foreach_set("color", rng.random(CURVES * 4).astype(np.float32))
    # The default UV is the first 2D vector on the curves, in both renderers.
    if not any(a.domain == "CURVE" and a.data_type == "FLOAT2" for a in curves.attributes):
        curves.attributes.new("surface_uv_coordinate", "FLOAT2", "CURVE")
    for a in curves.attributes:
        if a.domain == "CURVE" and a.data_type == "FLOAT2":
            a.data.foreach_set("vector", rng.random(CURVES * 2).astype(np.float32))
    curves.update_tag()
    return scene, hair


def particle_scene():
    """A 2 x 2 plane (with its UV map) growing 150 hair strands 0.5 long,
    0.04 thick at the root."""
    scene = ru.reset_scene()
    ru.add_camera(scene, (0.0, -3.0, 2.0), (0.0, 0.0, 0.2))
    bpy.ops.mesh.primitive_plane_add(size=2.0, location=(0.0, 0.0, 0.0))
    ground = bpy.context.active_object
    ground.name = "Ground"
    settings = bpy.data.particles.new("Hair")
    settings.type = "HAIR"
    settings.count = 150
    settings.hair_length = 0.5
    settings.child_type = "NONE"
    settings.render_step = settings.display_step = 3
    settings.root_radius, settings.tip_radius, settings.radius_scale = 1.0, 0.4, 0.04
    ground.modifiers.new("Hair", "PARTICLE_SYSTEM")
    ground.particle_systems[0].settings = settings
    return scene, ground


def random_hair_material():
    """Principled Hair (melanin) whose Random Color and Random Roughness
    take the strand's own random number (Random unlinked)."""
    m, out = ru.empty_material("Random hair")
    bsdf = m.node_tree.nodes.new("ShaderNodeBsdfHairPrincipled")
    bsdf.parametrization = "MELANIN"
    for name, value in (("Melanin", 0.5), ("Melanin Redness", 0.4), ("Random Color", 1.0),
                        ("Random Roughness", 0.6)):
        bsdf.inputs[name].default_value = value
    m.node_tree.links.new(bsdf.outputs[0], out.inputs["Surface"])
    return m


def use_material(m, objects):
    for obj in objects:
        obj.data.materials.clear()
        obj.data.materials.append(m)


def main():
    scene, hair = curves_scene()
    card = bpy.data.objects["Card"]
    ru.setup_cycles(scene, samples=CYCLES_SAMPLES)
    set_shape(scene)
    for name, build in MATERIALS:
        use_material(material(name, build), (hair, card))
        compare(f"curves: {name}", ru.render_passes(scene, "CYCLES", W, H)["rgba"],
                ru.render_passes(scene, "MICROPOLY", W, H, samples=16)["rgba"])
    # Lit strands, each of its own melanin and roughness.
    use_material(random_hair_material(), (hair,))
    bpy.data.objects.remove(card)
    ru.add_sun(scene, (math.radians(40), 0.0, math.radians(30)), energy=2.5)
    ru.setup_cycles(scene, samples=128)
    compare("Principled Hair: Random Color and Random Roughness from the strand's Random",
            ru.render_passes(scene, "CYCLES", W, H)["rgba"], ru.render_passes(scene, "MICROPOLY", W, H, samples=16)["rgba"],
            min_psnr=32.0)

    scene, ground = particle_scene()
    ground.data.materials.append(material("Particle", particle_material))
    ru.setup_cycles(scene, samples=CYCLES_SAMPLES)
    set_shape(scene)
    compare("particle hair: root UV on the emitter and Intercept",
            ru.render_passes(scene, "CYCLES", W, H, stored=False)["rgba"],
            ru.render_passes(scene, "MICROPOLY", W, H, samples=16)["rgba"])

    # The same hair moving during the shutter: the emitter slides along x
    # while the strands grow (their shape changes), keys at frames 1 and 3,
    # frame 2 rendered with a shutter of one frame.
    ru.motion_blur(scene)
    settings = ground.particle_systems[0].settings
    for frame, x, length in ((1, -0.25, 0.35), (3, 0.25, 0.65)):
        ground.location.x, settings.hair_length = x, length
        ground.keyframe_insert("location", frame=frame)
        settings.keyframe_insert("hair_length", frame=frame)
    scene.frame_set(2)
    ru.setup_cycles(scene, samples=64)
    ref = ru.render_passes(scene, "CYCLES", W, H, stored=False)["rgba"]
    got = ru.render_passes(scene, "MICROPOLY", W, H, samples=64)["rgba"]  # blur is noise at 16 samples
    p, seen = ru.blurred_psnr(ref, got)
    check("particle hair moving and growing, against Cycles' motion blur", p >= 30.0 and seen > 5000,
          f"{p:.1f} dB over {seen} pixels either covers")
    return 0 if all(RESULTS) else 1


ru.run_test(main)
