"""The Sky Texture (Nishita before Blender 5.0, Single and Multiple
Scattering from 5.0) against Cycles:

- the sky alone: an empty scene, the camera looking at the horizon with the
  sun outside the frame, on an opaque film; and the same with the sun
  turned to the other side, which must not agree (the sky is not
  symmetric about the view);
- the sun's disc: Cycles looking at the sun through a long lens against
  the disc's centre radiance the native precomputation gives (Micropoly's
  baked world spreads the disc's light over a few of its texels, so its
  own render of the disc is not compared);
- the sky lighting a scene: Suzanne and a torus with Subdivision Surface on
  a floor, diffuse materials, lit only by the sky with its sun disc (sun 35
  degrees up); Combined PSNR over the pixels both renders cover (alpha > 0
  on a transparent film), Cycles' direct light as the reference.

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup --python tests/blender/test_world_sky.py

MICROPOLY_TEST_OUTPUT=folder saves Cycles | Micropoly | difference x4 there.
"""
import math
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import render_utils as ru  # noqa: E402

OUTPUT = os.environ.get("MICROPOLY_TEST_OUTPUT")  # a folder for Cycles | Micropoly | difference images

W, H = 160, 120
SKY_MIN_DB = float(os.environ.get("MP_SKY_MIN_DB", "35"))
LIT_MIN_DB = float(os.environ.get("MP_SKY_LIT_MIN_DB", "28"))
# Nishita's sun gives about 100 (Y) of irradiance at this height: a dim
# Background keeps the lit scene near 1.
LIT_STRENGTH = 0.02


def sky_models():
    """The physical sky models the running Blender's node offers."""
    probe = bpy.data.worlds.new("probe")
    probe.use_nodes = True
    node = probe.node_tree.nodes.new("ShaderNodeTexSky")
    items = [i.identifier for i in node.bl_rna.properties["sky_type"].enum_items]
    bpy.data.worlds.remove(probe)
    return [m for m in ("NISHITA", "SINGLE_SCATTERING", "MULTIPLE_SCATTERING") if m in items]


def sky_world(scene, model, elevation, rotation, strength):
    world = scene.world
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    sky = nodes.new("ShaderNodeTexSky")
    sky.sky_type = model
    sky.sun_disc = True
    sky.sun_elevation = elevation
    sky.sun_rotation = rotation
    sky.altitude = 100.0
    background = next(n for n in nodes if n.type == "BACKGROUND")
    links.new(sky.outputs["Color"], background.inputs["Color"])
    background.inputs["Strength"].default_value = strength


def sky_scene(model, rotation):
    """Nothing but the sky; the camera looks along +Y, slightly up, so the
    frame holds sky and the ground's fade below the horizon."""
    scene = ru.reset_scene()
    sky_world(scene, model, math.radians(35.0), rotation, 1.0)
    ru.add_camera(scene, (0.0, 0.0, 0.0), (0.0, 10.0, 1.2), lens=35.0)
    return scene


def lit_scene(model):
    scene = ru.reset_scene()
    ru.add_suzanne_torus_floor(ru.diffuse_material)
    # The sun in front, to the left: shadows fall towards the camera's right.
    sky_world(scene, model, math.radians(35.0), math.radians(150.0), LIT_STRENGTH)
    ru.add_camera(scene, (0.0, -6.0, 3.2), (0.2, 0.0, 0.4), lens=40.0)
    return scene


def sun_disc_agreement(model):
    """Relative difference between Cycles' sun seen through an 8 m lens (the
    frame 0.26 degrees wide, inside the 0.545 degree disc) at the frame's
    centre and the native values (mean of the disc's lowest and highest
    points, where limb darkening is 1), in linear Rec.709."""
    from mathutils import Vector

    from micropoly import _native

    elevation, rotation = math.radians(35.0), math.radians(150.0)
    scene = ru.reset_scene()
    sky_world(scene, model, elevation, rotation, 1.0)
    sun = Vector((math.cos(elevation) * math.sin(rotation), math.cos(elevation) * math.cos(rotation),
                  math.sin(elevation)))
    ru.add_camera(scene, (0.0, 0.0, 0.0), tuple(10.0 * sun), lens=8000.0)
    ru.setup_cycles(scene, samples=16)
    cy = ru.render_passes(scene, "CYCLES", 32, 32, samples=16, transparent=False)["rgba"]
    node = next(n for n in scene.world.node_tree.nodes if n.type == "TEX_SKY")
    values = _native.nishita_sky_sun(model=model, sun_size=node.sun_size, sun_elevation=elevation,
                                     sun_rotation=rotation, altitude=node.altitude)
    xyz = 0.5 * (np.array(values["sun_bottom"]) + np.array(values["sun_top"]))
    xyz_to_rec709 = np.array([[3.2404542, -1.5371385, -0.4985314], [-0.9692660, 1.8760108, 0.0415560],
                              [0.0556434, -0.2040259, 1.0572252]])
    expected = xyz_to_rec709 @ xyz
    centre = cy[15:17, 15:17, :3].mean(axis=(0, 1))
    return float(np.max(np.abs(centre - expected) / expected))


def render(scene, engine, transparent):
    if engine == "CYCLES":
        ru.setup_cycles(scene, samples=256)
    return ru.render_passes(scene, engine, W, H, samples=16, transparent=transparent)["rgba"]


def main():
    ru.enable_addon()
    models = sky_models()
    print(f"Blender {bpy.app.version_string}: sky models {models}")
    for model in models:
        sun_error = sun_disc_agreement(model)
        print(f"{model}: the sun disc's centre within {100 * sun_error:.2f}% of Cycles'")
        assert sun_error < 0.005, f"{model}: the sun disc is {100 * sun_error:.2f}% off Cycles'"
        # The sun 60 degrees right of the view (out of the frame), then 60 left.
        right, left = math.radians(60.0), math.radians(-60.0)
        mp = render(sky_scene(model, right), "MICROPOLY", False)
        cy = render(sky_scene(model, right), "CYCLES", False)
        cy_left = render(sky_scene(model, left), "CYCLES", False)
        scale = max(float(cy[..., :3].max()), 1e-6)
        ru.save_side_by_side(OUTPUT, f"world_sky_{model}", cy / scale, mp / scale)
        sky_db = ru.psnr(mp[..., :3], cy[..., :3])
        mirrored_db = ru.psnr(mp[..., :3], cy_left[..., :3])
        ratio = float(mp[..., :3].mean() / max(cy[..., :3].mean(), 1e-12))
        print(f"{model}: sky alone {sky_db:.1f} dB (mean ratio {ratio:.4f}); "
              f"against the sun on the other side {mirrored_db:.1f} dB")
        assert sky_db >= SKY_MIN_DB, f"{model}: the sky {sky_db:.1f} dB < {SKY_MIN_DB}"
        assert mirrored_db < SKY_MIN_DB, f"{model}: the sun's side makes no difference ({mirrored_db:.1f} dB)"

        mp = render(lit_scene(model), "MICROPOLY", True)
        cy = render(lit_scene(model), "CYCLES", True)
        ru.save_side_by_side(OUTPUT, f"world_sky_lit_{model}", cy, mp)
        covered = (mp[..., 3] > 0.0) & (cy[..., 3] > 0.0)
        lit_db = ru.psnr(mp[..., :3][covered], cy[..., :3][covered])
        ratio = float(mp[..., :3][covered].mean() / max(cy[..., :3][covered].mean(), 1e-12))
        print(f"{model}: lit scene {lit_db:.1f} dB over {int(covered.sum())} covered pixels "
              f"(mean ratio {ratio:.4f})")
        assert lit_db >= LIT_MIN_DB, f"{model}: the lit scene {lit_db:.1f} dB < {LIT_MIN_DB}"
    return 0


ru.run_test(main)
