"""The scenes of tests/blender/test_texture_filtering.py, which
bench/texture_bench.py writes as RIB too: a checkerboard floor receding to
the horizon and a small distant card of a busy image, both glowing
(Emission of an Image Texture), on a black world."""
import math

import bpy
import numpy as np

import render_utils as ru


def checker_pixels(size=64, checks=8):
    y, x = np.mgrid[0:size, 0:size] // (size // checks)
    v = ((x + y) % 2).astype(np.float32) * 0.9 + 0.05
    rgba = np.ones((size, size, 4), dtype=np.float32)
    rgba[..., 0], rgba[..., 1], rgba[..., 2] = v, v * 0.8 + 0.1, v * 0.6
    return rgba


def busy_pixels(size=256):
    """Pixel noise over fine diagonal stripes: detail at every frequency."""
    rng = np.random.default_rng(7)
    y, x = np.mgrid[0:size, 0:size].astype(np.float32)
    stripes = 0.5 + 0.5 * np.sin((x + 2.0 * y) * 2.7)
    rgba = np.ones((size, size, 4), dtype=np.float32)
    for c in range(3):
        rgba[..., c] = np.clip(0.6 * stripes + 0.4 * rng.random((size, size)), 0.0, 1.0)
    return rgba


def image_material(name, image, repeat):
    """Emission of an Image Texture (Linear) through UV x `repeat` (Mapping)."""
    m, emission = ru.emission_material(name)
    nt = m.node_tree
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = image
    tex.interpolation = "Linear"
    if repeat != 1.0:
        coords = nt.nodes.new("ShaderNodeTexCoord")
        mapping = nt.nodes.new("ShaderNodeMapping")
        mapping.inputs["Scale"].default_value = (repeat, repeat, 1.0)
        nt.links.new(coords.outputs["UV"], mapping.inputs["Vector"])
        nt.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
    nt.links.new(tex.outputs["Color"], emission.inputs["Color"])
    return m


def floor_scene(forward=0.0):
    """A 400 m checkerboard floor, each check 0.5 m, seen from 1.2 m up
    towards the horizon; the camera moved `forward` metres along it."""
    scene = ru.reset_scene()
    bpy.ops.mesh.primitive_plane_add(size=400.0)
    image = ru.png_image("checker", checker_pixels(), "sRGB")
    bpy.context.object.data.materials.append(image_material("floor", image, 100.0))
    cam = ru.add_camera(scene, (0.3, -2.0 + forward, 1.2), (0.3, 30.0 + forward, 0.0), lens=35.0)
    cam.data.clip_end = 1000.0
    return scene


def card_scene():
    """A 1 m card of a busy 256 x 256 image, 14 m away, turned 50 degrees."""
    scene = ru.reset_scene()
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.0, 0.0, 0.0), rotation=(math.radians(90.0), 0.0,
                                                                                  math.radians(50.0)))
    image = ru.png_image("busy", busy_pixels(), "sRGB")
    bpy.context.object.data.materials.append(image_material("card", image, 1.0))
    ru.add_camera(scene, (0.0, -14.0, 0.0), (0.0, 0.0, 0.0), lens=100.0)
    return scene
