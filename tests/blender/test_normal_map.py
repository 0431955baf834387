"""Normal Map node, Micropoly against Cycles' direct light (run by blender -b,
or by a Python with the bpy module).

Each case is a diffuse object lit by a sun (no shadows, no bounces) whose
Diffuse BSDF takes its normal from a Normal Map node; Combined must agree
with Cycles at >= 30 dB PSNR on the pixels both cover:

  - tangent space, an image normal map (Non-Color) through the UV map, on a
    subdivided UV sphere (tangents per face corner of the cage, interpolated
    over the limit surface, as Cycles does with adaptive subdivision);
  - the same map at strength 0.6 on a smooth-shaded polygon UV sphere (the
    map tilts the interpolated corner normals);
  - object space, a procedural map on a torus: the surface's own normal
    plus a Noise texture's color as detail, as a baked map holds it;
  - world space, a constant map on a plane turned 60 degrees;
  - tangent space on a cylinder seen end-on: its caps are n-gons, for which
    Blender computes no tangents, so the tangent comes from the UVs' own
    directions on the surface (exact on a flat cap).

The image is a periodic bump field's normals, tilting up to about 35
degrees. Observed in Blender 3.4: see the printed table. Mutations checked:
a flipped bitangent sign, or the map read in object space instead of
tangent space, drop the tangent cases below 25 dB."""

import math
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import render_utils as ru  # noqa: E402

MIN_PSNR = 30.0
W, H = 192, 144


def normal_map_image():
    """Tangent-space normals of h = 0.06 sin(2 pi 4 u) sin(2 pi 3 v) over
    the unit UV square, stored as 0.5 + 0.5 n (Non-Color)."""
    n_u, n_v = 256, 128
    v, u = np.meshgrid((np.arange(n_v) + 0.5) / n_v, (np.arange(n_u) + 0.5) / n_u, indexing="ij")
    a, b = 2 * math.pi * 4, 2 * math.pi * 3
    dh_du = 0.06 * a * np.cos(a * u) * np.sin(b * v)
    dh_dv = 0.06 * b * np.sin(a * u) * np.cos(b * v)
    n = np.stack([-dh_du, -dh_dv, np.ones_like(u)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    rgba = np.ones((n_v, n_u, 4))
    rgba[..., :3] = 0.5 + 0.5 * n
    return ru.png_image("normal_map", rgba, "Non-Color")


def normal_mapped_material(name, space, strength, image=None):
    mat = ru.diffuse_material(name, (0.8, 0.8, 0.8))
    nt = mat.node_tree
    bsdf = next(n for n in nt.nodes if n.type == "BSDF_DIFFUSE")
    nmap = nt.nodes.new("ShaderNodeNormalMap")
    nmap.space = space
    nmap.inputs["Strength"].default_value = strength
    if image is not None:
        tex = nt.nodes.new("ShaderNodeTexImage")  # default vector: the UV map
        tex.image = image
        nt.links.new(tex.outputs["Color"], nmap.inputs["Color"])
    else:
        # An object-space map as a baker writes it: the surface's own normal
        # plus detail (a Noise texture's color), renormalised and encoded.
        coords = nt.nodes.new("ShaderNodeTexCoord")
        noise = nt.nodes.new("ShaderNodeTexNoise")
        noise.inputs["Scale"].default_value = 2.0
        noise.inputs["Detail"].default_value = 1.0
        centred = nt.nodes.new("ShaderNodeVectorMath")
        centred.operation = "MULTIPLY_ADD"
        centred.inputs[1].default_value = (0.8, 0.8, 0.8)
        centred.inputs[2].default_value = (-0.4, -0.4, -0.4)
        detail = nt.nodes.new("ShaderNodeVectorMath")
        detail.operation = "ADD"
        unit = nt.nodes.new("ShaderNodeVectorMath")
        unit.operation = "NORMALIZE"
        encode = nt.nodes.new("ShaderNodeVectorMath")
        encode.operation = "MULTIPLY_ADD"
        encode.inputs[1].default_value = (0.5, 0.5, 0.5)
        encode.inputs[2].default_value = (0.5, 0.5, 0.5)
        nt.links.new(noise.outputs["Color"], centred.inputs[0])
        nt.links.new(coords.outputs["Normal"], detail.inputs[0])
        nt.links.new(centred.outputs["Vector"], detail.inputs[1])
        nt.links.new(detail.outputs["Vector"], unit.inputs[0])
        nt.links.new(unit.outputs["Vector"], encode.inputs[0])
        nt.links.new(encode.outputs["Vector"], nmap.inputs["Color"])
    nt.links.new(nmap.outputs["Normal"], bsdf.inputs["Normal"])
    return mat


def sun(scene):
    ru.add_sun(scene, (0.7, 0.3, 0.4))


def compare(scene, label, camera, target):
    ru.add_camera(scene, camera, target, lens=45)
    sun(scene)
    ru.setup_cycles(scene, samples=16)  # shadows off for both renderers: test_shadows.py covers them
    mp = ru.render_passes(scene, "MICROPOLY", W, H, samples=16)
    cy = ru.render_passes(scene, "CYCLES", W, H, samples=16)
    both = (mp["rgba"][..., 3] > 0.99) & (cy["rgba"][..., 3] > 0.99)
    value = ru.psnr(mp["rgba"][..., :3][both], cy["rgba"][..., :3][both])
    print(f"{label:48s} {value:6.2f} dB over {int(both.sum())} pixels")
    if both.sum() < 3000:
        return [f"{label}: only {both.sum()} covered pixels"]
    return [] if value >= MIN_PSNR else [f"{label}: PSNR {value:.2f} dB < {MIN_PSNR}"]


def case_sphere(subdivided, strength):
    scene = ru.reset_scene()
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, segments=32, ring_count=16)
    obj = bpy.context.active_object
    obj.rotation_euler = (0.2, 0.0, 0.5)
    bpy.ops.object.shade_smooth()
    if subdivided:
        obj.modifiers.new("Subdivision", "SUBSURF")
    obj.data.materials.append(normal_mapped_material("nmap_sphere", "TANGENT", strength, normal_map_image()))
    kind = "subdivided" if subdivided else "polygon"
    return compare(scene, f"tangent space, {kind} sphere, strength {strength}", (0.0, -4.0, 0.8), (0, 0, 0))


def case_object_space():
    scene = ru.reset_scene()
    bpy.ops.mesh.primitive_torus_add(major_segments=32, minor_segments=16, minor_radius=0.4)
    obj = bpy.context.active_object
    obj.modifiers.new("Subdivision", "SUBSURF")
    obj.data.materials.append(normal_mapped_material("nmap_object", "OBJECT", 1.0))
    return compare(scene, "object space, procedural, subdivided torus", (0.0, -3.5, 2.0), (0, 0, 0))


def case_world_space():
    # A world-space map on a plane turned 60 degrees about x: a constant
    # world normal 15 degrees off the plane's own. Read in object space the
    # same colour would point 60 degrees elsewhere.
    scene = ru.reset_scene()
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    obj = bpy.context.active_object
    obj.rotation_euler = (math.radians(60.0), 0.0, 0.0)
    mat = ru.diffuse_material("nmap_world", (0.8, 0.8, 0.8))
    nt = mat.node_tree
    nmap = nt.nodes.new("ShaderNodeNormalMap")
    nmap.space = "WORLD"
    n = np.array([math.sin(math.radians(15.0)), -math.sin(math.radians(60.0)), math.cos(math.radians(60.0))])
    n /= np.linalg.norm(n)
    nmap.inputs["Color"].default_value = (*(0.5 + 0.5 * n), 1.0)
    nt.links.new(nmap.outputs["Normal"], next(n for n in nt.nodes if n.type == "BSDF_DIFFUSE").inputs["Normal"])
    obj.data.materials.append(mat)
    return compare(scene, "world space, constant map, turned plane", (0.0, -3.0, 1.2), (0, 0, 0))


def case_ngon_caps():
    scene = ru.reset_scene()
    bpy.ops.mesh.primitive_cylinder_add(vertices=24, radius=1.0, depth=1.0, end_fill_type="NGON")
    obj = bpy.context.active_object
    obj.data.materials.append(normal_mapped_material("nmap_caps", "TANGENT", 1.0, normal_map_image()))
    return compare(scene, "tangent space, n-gon cap (tangents from UVs)", (0.3, -0.4, 3.5), (0, 0, 0.5))


def main():
    failures = []
    for case in (lambda: case_sphere(True, 1.0), lambda: case_sphere(False, 0.6), case_object_space,
                 case_world_space, case_ngon_caps):
        failures += case()
    return ru.verdict(failures, f"normal maps within {MIN_PSNR} dB of Cycles")


ru.run_test(main)
