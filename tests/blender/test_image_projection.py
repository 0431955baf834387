"""Image Texture projections (Flat, Box with and without blending, Sphere,
Tube), Micropoly against Cycles (run by blender -b, or by a Python with the
bpy module).

Five flat-shaded icospheres in a row, seen from the side and a little above
by an orthographic camera, each with an Emission shader fed by an Image
Texture node through Generated coordinates, one projection per sphere. The
image is smooth and periodic (sines of u and v in its three channels), so
shading at grid vertices (shading rate 1/4) and interpolating between them
stays close to Cycles' per-sample lookup except along Box projection's hard
seams. Both render at 16 samples per pixel. Each sphere is compared on the
interior of its silhouette (two pixels in): PSNR >= 35 dB per projection.
Prints a table. Exits non-zero on failure.

Observed in Blender 3.4: 39.8 dB (Box without blending, whose hard seams
Micropoly ramps over one micropolygon) to 56.4 dB. Mutations checked:
mirroring none of Box's projections drops both Box cases to 12 dB; Tube's
longitude measured from +x instead of +y drops Tube to 15 dB."""

import math
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import render_utils as ru  # noqa: E402

MIN_PSNR = 35.0
CASES = [("Flat", "FLAT", 0.0), ("Box, blend 0", "BOX", 0.0), ("Box, blend 0.3", "BOX", 0.3),
         ("Sphere", "SPHERE", 0.0), ("Tube", "TUBE", 0.0)]
SPACING = 2.6
TILE = 96


def periodic_image():
    """Smooth colours, periodic in u and v: no step where Sphere and Tube wrap."""
    v, u = np.meshgrid((np.arange(64) + 0.5) / 64, (np.arange(128) + 0.5) / 128, indexing="ij")
    rgba = np.ones((64, 128, 4))
    rgba[..., 0] = 0.5 + 0.4 * np.sin(2 * math.pi * 2 * u)
    rgba[..., 1] = 0.5 + 0.4 * np.cos(2 * math.pi * 3 * v)
    rgba[..., 2] = 0.5 + 0.3 * np.sin(2 * math.pi * (u + v))
    return ru.png_image("projection", rgba, "sRGB")


def build_scene():
    scene = ru.reset_scene()
    image = periodic_image()
    for k, (name, projection, blend) in enumerate(CASES):
        bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=4, radius=1.0, location=(k * SPACING, 0.0, 0.0))
        obj = bpy.context.active_object
        obj.rotation_euler = (0.3, 0.2, 0.4 * k)  # Generated coordinates follow the object
        bpy.ops.object.shade_flat()
        mat, emission = ru.emission_material("projection_" + projection.lower() + str(k))
        nt = mat.node_tree
        coords = nt.nodes.new("ShaderNodeTexCoord")
        tex = nt.nodes.new("ShaderNodeTexImage")
        tex.image = image
        tex.projection = projection
        tex.projection_blend = blend
        nt.links.new(coords.outputs["Generated"], tex.inputs["Vector"])
        nt.links.new(tex.outputs["Color"], emission.inputs["Color"])
        obj.data.materials.append(mat)
    middle = 0.5 * (len(CASES) - 1) * SPACING
    ru.add_camera(scene, (middle, -8.0, 2.0), (middle, 0.0, 0.0), ortho_scale=len(CASES) * SPACING)
    return scene


def main():
    scene = build_scene()
    width, height = len(CASES) * TILE, int(1.4 * TILE)
    ru.setup_cycles(scene, samples=16, adaptive_subdivision=False)
    scene.micropoly.shading_rate = 0.25
    ref = ru.render_passes(scene, "CYCLES", width, height)["rgba"]
    ours = ru.render_passes(scene, "MICROPOLY", width, height)["rgba"]
    interior = ru.covered_interior(ref, ours)
    failures = []
    print(f"{'projection':18s} {'PSNR dB':>8s} {'pixels':>7s}")
    for k, (name, _, _) in enumerate(CASES):
        mask = np.zeros_like(interior)
        mask[:, k * TILE:(k + 1) * TILE] = True
        mask &= interior
        if mask.sum() < 1500:
            failures.append(f"{name}: only {mask.sum()} interior pixels")
            continue
        value = ru.psnr(ours[mask][:, :3], ref[mask][:, :3], peak=1.0)
        print(f"{name:18s} {value:8.1f} {int(mask.sum()):7d}")
        if not value >= MIN_PSNR:
            failures.append(f"{name}: {value:.1f} dB < {MIN_PSNR} dB")
    return ru.verdict(failures, f"{len(CASES)} projections within {MIN_PSNR} dB of Cycles")


ru.run_test(main)
