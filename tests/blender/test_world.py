"""World lighting against Cycles' direct light: Suzanne and a torus with
Subdivision Surface on a floor, lit only by each of three HDRIs that ship
with Blender (its studio lights forest, city and sunset), with diffuse materials and with Principled roughness
0.3. Combined PSNR over covered pixels; the background behind objects on an
opaque film; a mutation check: the HDRI turned 90 degrees by a Mapping node
still agrees, and an unturned render compared with Cycles' turned one does
not. An occlusion check: the floor under a ball is darker than the open
floor by the ratio Cycles gives, and not without the world's shadows; the same in Blender's default grey world
under a sun, whose uniform light is shadowed like an HDRI's. A
world split by Light Path's Is Camera Ray lights the objects with the HDRI
while the camera sees a plain backdrop, as in Cycles; Texture Coordinate's
Window and Camera colour the background as Cycles' camera rays see them.

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup --python tests/blender/test_world.py

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
# Issue targets over covered pixels: 30 dB diffuse, 28 dB glossy.
MIN_DIFFUSE_DB = float(os.environ.get("MP_WORLD_MIN_DB", "30"))
MIN_GLOSSY_DB = float(os.environ.get("MP_WORLD_MIN_GLOSSY_DB", "28"))


def material(name, color, glossy):
    return ru.principled_material(name, color, 0.3) if glossy else ru.diffuse_material(name, color)


def hdri_path(name):
    folder = bpy.utils.system_resource("DATAFILES", path="studiolights/world")
    path = os.path.join(folder, name)
    assert os.path.exists(path), f"Blender's studio light {path} is missing"
    return path


def set_world(scene, hdri, rotation_z):
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    env = nodes.new("ShaderNodeTexEnvironment")
    env.image = bpy.data.images.load(hdri_path(hdri), check_existing=True)
    coords = nodes.new("ShaderNodeTexCoord")
    mapping = nodes.new("ShaderNodeMapping")
    mapping.inputs["Rotation"].default_value[2] = rotation_z
    links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], env.inputs["Vector"])
    background = nodes["Background"]
    links.new(env.outputs["Color"], background.inputs["Color"])
    background.inputs["Strength"].default_value = 1.0


def build_scene(hdri, rotation_z=0.0, glossy=False):
    scene = ru.reset_scene()
    ru.add_suzanne_torus_floor(lambda name, color: material(name, color, glossy))
    set_world(scene, hdri, rotation_z)
    ru.add_camera(scene, (0.0, -6.0, 3.2), (0.2, 0.0, 0.4), lens=40.0)
    return scene


def render(engine, scene, transparent=True, samples=16):
    if engine == "CYCLES":
        ru.setup_cycles(scene, samples=256)
    return ru.render_passes(scene, engine, W, H, samples=samples, transparent=transparent)["rgba"]


def covered_psnr(mp, cy):
    """PSNR over the pixels both renderers cover fully (a pixel in from
    the edges, where their antialiasing differs)."""
    inside = ru.covered_interior(mp, cy, margin=1)
    assert inside.sum() > 0.2 * inside.size, "the objects and floor should cover the frame"
    return ru.psnr(mp[inside][:, :3], cy[inside][:, :3])


def compare(hdri, rotation_z=0.0, glossy=False):
    mp = render("MICROPOLY", build_scene(hdri, rotation_z, glossy))
    cy = render("CYCLES", build_scene(hdri, rotation_z, glossy))
    return mp, cy


def floor_regions(scene, centre, radius):
    """Pixel masks of the floor (z = 0) seen past a ball at `centre`: under
    its overhang (0.45 to 0.85 radii from its contact point) and in the open
    (3 to 4.5 radii), from the camera's rays through the pixel centres."""
    bpy.context.view_layer.update()  # the camera's matrix_world
    cam = scene.camera
    lens, sensor = cam.data.lens, cam.data.sensor_width
    ys, xs = np.mgrid[0:H, 0:W].astype(np.float64)
    rays = np.stack([((xs + 0.5) / W - 0.5) * sensor / lens, (0.5 - (ys + 0.5) / H) * sensor * H / W / lens,
                     -np.ones_like(xs)], axis=-1)
    rot = np.array(cam.matrix_world.to_3x3())
    rays = rays @ rot.T
    origin = np.array(cam.matrix_world.translation)
    t_floor = -origin[2] / rays[..., 2]
    hit = origin + rays * t_floor[..., None]
    # Rays that meet the ball first see the ball, not the floor.
    oc = origin - np.array(centre)
    a = np.sum(rays * rays, axis=-1)
    b = np.sum(rays * oc, axis=-1)
    disc = b * b - a * (oc @ oc - radius * radius)
    blocked = disc > 0
    dist = np.hypot(hit[..., 0] - centre[0], hit[..., 1] - centre[1]) / radius
    floor = (t_floor > 0) & ~blocked
    return floor & (dist > 0.45) & (dist < 0.85), floor & (dist > 3.0) & (dist < 4.5)


def occlusion_ratio(rgba, under, open_floor):
    lum = rgba[..., :3] @ np.array([0.2126, 0.7152, 0.0722])
    return float(lum[under].mean() / lum[open_floor].mean())


def occlusion_scene(directions=None):
    scene = ru.reset_scene()
    bpy.ops.mesh.primitive_plane_add(size=12.0)
    bpy.context.object.data.materials.append(ru.diffuse_material("Floor", (0.6, 0.6, 0.6)))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=(0.0, 0.0, 0.6), segments=48, ring_count=24)
    ball = bpy.context.object
    ball.data.materials.append(ru.diffuse_material("Ball", (0.6, 0.6, 0.6)))
    ru.shade_smooth(ball)
    set_world(scene, "forest.exr", 0.0)
    ru.add_camera(scene, (0.0, -5.0, 4.0), (0.0, 0.0, 0.3), lens=35.0)
    if directions is not None:
        scene.micropoly.world_shadow_directions = directions
    return scene


def check_occlusion():
    """The floor under a ball against the open floor, as Cycles darkens it."""
    cy_scene = occlusion_scene()
    under, open_floor = floor_regions(cy_scene, (0.0, 0.0, 0.6), 0.6)
    assert under.sum() >= 20 and open_floor.sum() >= 200, (under.sum(), open_floor.sum())
    cy = occlusion_ratio(render("CYCLES", cy_scene), under, open_floor)
    mp = occlusion_ratio(render("MICROPOLY", occlusion_scene()), under, open_floor)
    unshadowed = occlusion_ratio(render("MICROPOLY", occlusion_scene(directions=0)), under, open_floor)
    print(f"occlusion: floor under the ball / open floor: Cycles {cy:.3f}, Micropoly {mp:.3f}, "
          f"Micropoly without world shadows {unshadowed:.3f}")
    assert cy < 0.8, f"Cycles should darken the floor under the ball ({cy:.3f})"
    assert abs(mp / cy - 1.0) <= 0.10, f"occlusion ratio {mp:.3f} against Cycles' {cy:.3f}"
    assert abs(unshadowed / cy - 1.0) > 0.10, "the check should fail without the world's shadows"


def default_world_scene(directions=None):
    """The ball on the floor in Blender's default world (a Background of
    plain grey 0.0508) under a sun whose shadow falls beside the ball."""
    scene = occlusion_scene(directions)
    world = scene.world
    for node in list(world.node_tree.nodes):
        if node.type not in ("BACKGROUND", "OUTPUT_WORLD"):
            world.node_tree.nodes.remove(node)
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (0.0508, 0.0508, 0.0508, 1.0)
    background.inputs["Strength"].default_value = 1.0
    sun = ru.add_sun(scene, (math.radians(40.0), 0.0, math.radians(60.0)), energy=2.0)
    ru.set_cast_shadow(sun.data, True)
    return scene


def check_default_world():
    """A uniform world is shadowed like any other: the floor under the ball
    darkens as in Cycles (within 0.02 of its ratio), and the frame agrees
    over covered pixels; with the world's shadows off it would not."""
    cy_scene = default_world_scene()
    under, open_floor = floor_regions(cy_scene, (0.0, 0.0, 0.6), 0.6)
    ru.setup_cycles(cy_scene, samples=256, shadows=True)
    cy = ru.render_passes(cy_scene, "CYCLES", W, H, samples=16)["rgba"]
    mp = ru.render_passes(default_world_scene(), "MICROPOLY", W, H, samples=16)["rgba"]
    open_sky = ru.render_passes(default_world_scene(directions=0), "MICROPOLY", W, H, samples=16)["rgba"]
    ru.save_side_by_side(OUTPUT, "world_default_grey", cy, mp)
    ratios = [occlusion_ratio(img, under, open_floor) for img in (cy, mp, open_sky)]
    db = covered_psnr(mp, cy)
    print(f"default grey world and a sun: floor under the ball / open floor: Cycles {ratios[0]:.3f}, "
          f"Micropoly {ratios[1]:.3f}, without the world's shadows {ratios[2]:.3f}; {db:.1f} dB over covered pixels")
    assert abs(ratios[1] - ratios[0]) <= 0.02, f"darkening {ratios[1]:.3f} against Cycles' {ratios[0]:.3f}"
    assert abs(ratios[2] - ratios[0]) > 0.02, "the check should fail without the world's shadows"
    assert db >= 30.0, f"default world: {db:.1f} dB < 30"


def split_world(scene, backdrop):
    """The HDRI world, with a Light Path's Is Camera Ray mixing in a plain
    `backdrop` colour for what the camera sees (an artist's usual split:
    the HDRI lights the scene, the camera sees a studio colour)."""
    nodes, links = scene.world.node_tree.nodes, scene.world.node_tree.links
    hdri = nodes["Background"]
    plain = nodes.new("ShaderNodeBackground")
    plain.inputs["Color"].default_value = (*backdrop, 1.0)
    path = nodes.new("ShaderNodeLightPath")
    mix = nodes.new("ShaderNodeMixShader")
    links.new(path.outputs["Is Camera Ray"], mix.inputs["Fac"])
    links.new(hdri.outputs["Background"], mix.inputs[1])
    links.new(plain.outputs["Background"], mix.inputs[2])
    links.new(mix.outputs["Shader"], nodes["World Output"].inputs["Surface"])


def check_camera_ray_split():
    """Objects lit by the HDRI while the camera sees a plain backdrop: the
    world's light is what Cycles' background light evaluates (Is Camera Ray
    0), the backdrop what its camera rays see. Lit by the backdrop instead,
    the objects would not match."""
    backdrop = (0.3, 0.32, 0.36)

    def scene_of(split):
        scene = build_scene("forest.exr")
        if split:
            split_world(scene, backdrop)
        else:  # the backdrop everywhere, through a node so its light is shadowed as well
            world = scene.world.node_tree
            rgb = world.nodes.new("ShaderNodeRGB")
            rgb.outputs[0].default_value = (*backdrop, 1.0)
            world.links.new(rgb.outputs[0], world.nodes["Background"].inputs["Color"])
        return scene

    mp = render("MICROPOLY", scene_of(True), transparent=False)
    cy = render("CYCLES", scene_of(True), transparent=False)
    ru.save_side_by_side(OUTPUT, "world_camera_ray_split", cy, mp)
    lit_by_backdrop = render("CYCLES", scene_of(False), transparent=False)
    mp_t, cy_t = render("MICROPOLY", scene_of(True)), render("CYCLES", scene_of(True))
    objects = ru.covered_interior(mp_t, cy_t, margin=1)
    behind = (mp_t[..., 3] < 0.001) & (cy_t[..., 3] < 0.001)
    assert behind.sum() > 100, "the backdrop should show above the floor"
    lit = ru.psnr(mp[objects][:, :3], cy[objects][:, :3])
    wrong = ru.psnr(mp[objects][:, :3], lit_by_backdrop[objects][:, :3])
    seen = float(np.abs(mp[behind][:, :3] - np.array(backdrop)).max())
    print(f"camera ray split: objects {lit:.1f} dB against Cycles ({wrong:.1f} dB against Cycles lit by the "
          f"backdrop); the backdrop behind them within {seen:.4f} of its colour")
    assert lit >= MIN_GLOSSY_DB and wrong < MIN_GLOSSY_DB, (lit, wrong)
    assert seen <= 0.01, seen


def check_view_coordinates():
    """Texture Coordinate's Window and Camera in a world: the background
    behind the frame, coloured (Window x, Window y, Camera x + 0.5), as
    Cycles' camera rays see it (a camera turned and shifted)."""
    def scene_of():
        scene = ru.reset_scene()
        cam = ru.add_camera(scene, (1.0, -6.0, 2.0), (0.0, 0.0, 1.0), lens=40.0)
        cam.data.shift_x = 0.1
        world = bpy.data.worlds.new("View coordinates")
        scene.world = world
        world.use_nodes = True
        nodes, links = world.node_tree.nodes, world.node_tree.links
        coords = nodes.new("ShaderNodeTexCoord")
        window, camera = nodes.new("ShaderNodeSeparateXYZ"), nodes.new("ShaderNodeSeparateXYZ")
        links.new(coords.outputs["Window"], window.inputs[0])
        links.new(coords.outputs["Camera"], camera.inputs[0])
        lift = nodes.new("ShaderNodeMath")
        lift.inputs[1].default_value = 0.5
        links.new(camera.outputs["X"], lift.inputs[0])
        colour = nodes.new("ShaderNodeCombineXYZ")
        links.new(window.outputs["X"], colour.inputs[0])
        links.new(window.outputs["Y"], colour.inputs[1])
        links.new(lift.outputs[0], colour.inputs[2])
        links.new(colour.outputs[0], nodes["Background"].inputs["Color"])
        return scene

    mp = render("MICROPOLY", scene_of(), transparent=False)
    cy = render("CYCLES", scene_of(), transparent=False)
    ru.save_side_by_side(OUTPUT, "world_view_coordinates", cy, mp)
    db = ru.psnr(mp[..., :3], cy[..., :3])
    spread = float(cy[..., :3].reshape(-1, 3).std(axis=0).min())
    print(f"view coordinates in the world: {db:.1f} dB against Cycles (Cycles' channels vary by {spread:.3f})")
    assert spread > 0.05, "the coordinates should vary across the frame"
    assert db >= 40.0, db


def check_rib():
    """The HDRI scene exported to RIB renders in micropoly-render as F12
    renders it: the world's program, its image and the background."""
    scene = build_scene("city.exr", math.pi / 3, glossy=True)
    diff = ru.rib_against_f12(scene, W, H, 16, ["micropoly_environmentlight"])
    if diff is None:
        return
    print(f"RIB: micropoly-render against F12, max difference {diff * 255:.2f}/255")
    assert diff <= 1.0 / 255.0 + 1e-6, diff


def main():
    ru.enable_addon()
    for hdri in ("forest.exr", "city.exr", "sunset.exr"):
        mp, cy = compare(hdri)
        ru.save_side_by_side(OUTPUT, f"world_{hdri}", cy, mp)
        db = covered_psnr(mp, cy)
        print(f"{hdri}: diffuse, Micropoly vs Cycles {db:.1f} dB over covered pixels")
        turned_mp, turned_cy = compare(hdri, math.pi / 2)
        turned = covered_psnr(turned_mp, turned_cy)
        ignored = covered_psnr(mp, turned_cy)
        print(f"{hdri}: turned 90 degrees {turned:.1f} dB; rotation ignored {ignored:.1f} dB")
        glossy_mp, glossy_cy = compare(hdri, glossy=True)
        ru.save_side_by_side(OUTPUT, f"world_glossy_{hdri}", glossy_cy, glossy_mp)
        glossy = covered_psnr(glossy_mp, glossy_cy)
        print(f"{hdri}: Principled roughness 0.3, {glossy:.1f} dB over covered pixels")
        # The world behind the objects on an opaque film.
        back_mp = render("MICROPOLY", build_scene(hdri), transparent=False)
        back_cy = render("CYCLES", build_scene(hdri), transparent=False)
        behind = ~ru.covered_interior(mp, cy, margin=0) & (cy[..., 3] < 0.001)
        background = ru.psnr(back_mp[behind][:, :3], back_cy[behind][:, :3]) if behind.any() else math.inf
        print(f"{hdri}: background {background:.1f} dB over {int(behind.sum())} pixels")
        assert db >= MIN_DIFFUSE_DB, f"{hdri}: diffuse {db:.1f} dB < {MIN_DIFFUSE_DB}"
        assert turned >= MIN_DIFFUSE_DB and ignored < MIN_DIFFUSE_DB, (turned, ignored)
        assert glossy >= MIN_GLOSSY_DB, f"{hdri}: glossy {glossy:.1f} dB < {MIN_GLOSSY_DB}"
        assert background >= 35.0, f"{hdri}: background {background:.1f} dB"
    check_occlusion()
    check_default_world()
    check_camera_ray_split()
    check_view_coordinates()
    check_rib()
    return 0


ru.run_test(main)
