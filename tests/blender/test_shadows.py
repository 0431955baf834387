"""Shadows against Cycles with shadows on, direct light only (no bounces,
black world, no denoising):

  - Suzanne and a torus, each with a Subdivision Surface modifier, over a
    floor, lit in turn by a sun, a spot, a point light and a rectangular
    area light, each with no size (hard shadows) and with a large one (soft
    shadows), plus a displaced plane lit at a grazing angle: Combined PSNR
    over the pixels both cover >= 30 dB for hard shadows and >= 28 dB for
    soft ones. The same comparison with Micropoly's shadows switched off
    must fail (the mutation check), so the threshold can tell shadows apart;
  - self-shadowing under a low sun, a closed subdivided sphere and a
    displaced surface: no pixel that Cycles lights (away from its shadow
    edges) is darker in Micropoly by more than 0.05 (shadow acne);
  - a box standing on the floor under a sun: the shadow's edges lie within
    1.5 px of Cycles' (light leaking or peter-panning at the contact would
    move them);
  - five thin leaves stacked under a wide sun over a large ground: each
    leaf's shadow on the next >= 30 dB (with the mutation check);
  - Blender's controls: a light's Cast Shadow off and an object's Shadow ray
    visibility off remove the shadow; an object hidden from the camera
    still casts one; a material with alpha 0.5 lets half the light through
    each of its faces.

MICROPOLY_TEST_OUTPUT=folder writes each case's images there (Cycles,
Micropoly and their difference x4, side by side).
Run: blender -b --factory-startup --python tests/blender/test_shadows.py"""
import math
import os
import sys
import traceback

import bpy
import numpy as np
from mathutils import Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import render_utils as ru  # noqa: E402

SCALE = int(os.environ.get("MICROPOLY_TEST_SCALE", "1"))  # larger images to look at, not for the checks
W, H = 240 * SCALE, 180 * SCALE
HARD_DB, SOFT_DB = 30.0, 28.0
OUTPUT = os.environ.get("MICROPOLY_TEST_OUTPUT")


def subdivided(obj, levels=2):
    obj.modifiers.new("Subdivision", "SUBSURF").render_levels = levels
    bpy.ops.object.shade_smooth()
    return obj


def base_scene():
    """Suzanne and a torus with Subdivision Surface over a floor."""
    scene = ru.reset_scene()
    bpy.ops.mesh.primitive_monkey_add(size=1.6, location=(-0.9, 0.2, 0.0), rotation=(0.0, 0.0, math.radians(-15)))
    subdivided(bpy.context.object).data.materials.append(ru.diffuse_material("grey", (0.8, 0.8, 0.8)))
    bpy.ops.mesh.primitive_torus_add(location=(1.2, 0.4, -0.55), major_radius=0.6, minor_radius=0.22,
                                     rotation=(math.radians(20), 0.0, 0.0))
    subdivided(bpy.context.object, 1).data.materials.append(ru.diffuse_material("torus", (0.7, 0.5, 0.3)))
    floor(scene)
    ru.add_camera(scene, (0.3, -4.8, 2.4), (0.2, 0.3, -0.6), lens=40.0)
    return scene


def floor(scene, size=9.0, z=-0.9):
    bpy.ops.mesh.primitive_plane_add(size=size, location=(0.0, 0.0, z))
    bpy.context.object.data.materials.append(ru.diffuse_material("floor", (0.6, 0.6, 0.55)))
    return bpy.context.object


def add_light(scene, kind, location, target=(0.0, 0.0, -0.5), energy=1000.0, **props):
    return ru.add_aimed_light(scene, kind, location, target, energy, **props)


def render_both(scene, name, cycles_samples, shadows=True):
    ru.setup_cycles(scene, samples=cycles_samples, shadows=shadows)
    cycles = ru.render_passes(scene, "CYCLES", W, H)["rgba"]
    micro = ru.render_passes(scene, "MICROPOLY", W, H, samples=16)["rgba"]
    if OUTPUT:
        os.makedirs(OUTPUT, exist_ok=True)
        diff = np.abs(cycles[..., :3] - micro[..., :3]) * 4.0
        row = np.concatenate([cycles[..., :3], micro[..., :3], diff], axis=1)
        ru.save_png(os.path.join(OUTPUT, name + ".png"), np.power(np.clip(row, 0, 1), 1 / 2.2))
    return cycles, micro


def covered_psnr(cycles, micro):
    both = (cycles[..., 3] > 0.999) & (micro[..., 3] > 0.999)
    ref, got = cycles[both][:, :3], micro[both][:, :3]
    return ru.psnr(ref, got, peak=float(ref.max())), int(both.sum())


def compare(name, scene, threshold, cycles_samples=256, mutation=True):
    """PSNR against Cycles with shadows; with `mutation`, the same scene
    rendered by Micropoly with its shadows off must miss the threshold."""
    cycles, micro = render_both(scene, name, cycles_samples)
    db, covered = covered_psnr(cycles, micro)
    failures = []
    if covered < 0.5 * W * H:
        failures.append(f"only {covered} covered pixels")
    if db < threshold:
        failures.append(f"PSNR {db:.2f} dB < {threshold}")
    shown = f"PSNR {db:.2f} dB"
    if mutation:
        scene.micropoly.use_shadows = False
        unshadowed = ru.render_passes(scene, "MICROPOLY", W, H, samples=16)["rgba"]
        scene.micropoly.use_shadows = True
        db_off, _ = covered_psnr(cycles, unshadowed)
        shown += f", without shadows {db_off:.2f} dB"
        if db_off >= threshold:
            failures.append(f"without shadows Micropoly still reaches {db_off:.2f} dB: the case cannot tell")
    print(f"{'FAIL' if failures else 'ok  '} {name}: {shown}" + "".join(f"\n     {f}" for f in failures))
    return not failures


def sun(scene, angle=0.0, elevation=55.0, azimuth=-35.0, energy=3.0):
    data = bpy.data.lights.new("sun", "SUN")
    data.energy = energy
    data.angle = angle
    obj = bpy.data.objects.new("sun", data)
    obj.rotation_euler = (math.radians(90.0 - elevation), 0.0, math.radians(azimuth))
    scene.collection.objects.link(obj)
    return obj


def case_sun(soft):
    scene = base_scene()
    sun(scene, angle=math.radians(12.0) if soft else 0.0)
    return compare(f"sun {'angle 12 deg' if soft else 'hard'}", scene, SOFT_DB if soft else HARD_DB)


def case_spot(soft):
    scene = base_scene()
    add_light(scene, "SPOT", (1.8, -2.2, 3.6), energy=1500.0, spot_size=math.radians(80), spot_blend=0.15,
              shadow_soft_size=0.6 if soft else 0.0)
    return compare(f"spot {'radius 0.6' if soft else 'hard'}", scene, SOFT_DB if soft else HARD_DB)


def case_point(soft):
    scene = base_scene()
    add_light(scene, "POINT", (1.2, -1.6, 2.6), energy=800.0, shadow_soft_size=0.6 if soft else 0.0)
    return compare(f"point {'radius 0.6' if soft else 'hard'}", scene, SOFT_DB if soft else HARD_DB)


def case_area(soft):
    scene = base_scene()
    size = (1.6, 0.9) if soft else (0.02, 0.02)
    add_light(scene, "AREA", (-1.5, -1.8, 3.2), energy=900.0, shape="RECTANGLE", size=size[0], size_y=size[1])
    return compare(f"area {'1.6 x 0.9' if soft else '0.02 x 0.02'}", scene, SOFT_DB if soft else HARD_DB)


def noise_displaced_material(name, scale, strength, color=(0.75, 0.75, 0.7)):
    return ru.add_noise_displacement(ru.diffuse_material(name, color), scale, strength, detail=3.0)


def displaced_plane(size=6.0, scale=1.2, strength=0.35):
    """A square grid of 16 x 16 faces with Subdivision Surface, displaced by Noise."""
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=16, y_subdivisions=16, size=size, location=(0.0, 0.0, 0.0))
    plane = bpy.context.object
    subdivided(plane, 1)
    plane.data.materials.append(noise_displaced_material("displaced", scale, strength))
    return plane


def wave_displaced_material(name, scale, strength, color=(0.75, 0.75, 0.7)):
    """Ridges: a Wave texture's bands along x, with a little Noise."""
    mat = ru.diffuse_material(name, color)
    wave = mat.node_tree.nodes.new("ShaderNodeTexWave")
    wave.wave_type = "BANDS"
    wave.bands_direction = "X"
    wave.inputs["Scale"].default_value = scale
    wave.inputs["Distortion"].default_value = 4.0
    return ru.add_displacement(mat, wave.outputs["Fac"], strength)


def case_displaced_grazing():
    """Ridges displaced on a plane, under a sun 10 degrees above the horizon
    across them: each ridge shadows the valley behind it."""
    scene = ru.reset_scene()
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=16, y_subdivisions=16, size=8.0)
    plane = bpy.context.object
    subdivided(plane, 1)
    plane.data.materials.append(wave_displaced_material("ridges", 1.5, 0.35))
    sun(scene, elevation=10.0, azimuth=-80.0, energy=4.0)
    # Looking down at the plane's inside: its boundary stays out of view.
    ru.add_camera(scene, (0.0, -1.6, 3.4), (0.0, 0.5, 0.0), lens=35.0)
    return compare("displaced ridges, sun at 10 deg", scene, HARD_DB, cycles_samples=128)


def case_thin_leaves():
    """Five leaves, flattened ellipsoids 12 x 7 cm and 4 mm thick, stacked
    3 cm apart over a 30 m ground under an 11.4 degree sun: each leaf's
    soft shadow on the next. The ground makes the sun's view deep, so a
    blocker search as wide as the scene reads texels as large as a leaf."""
    scene = ru.reset_scene()
    for k in range(5):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, segments=32, ring_count=16,
                                             location=(0.035 * k - 0.07, 0.0, 0.03 * k))
        leaf = bpy.context.object
        leaf.scale = (0.06, 0.035, 0.002)
        leaf.rotation_euler = (0.1 * (k % 2), 0.05, 0.5 * k)
        bpy.ops.object.shade_smooth()
        leaf.data.materials.append(ru.diffuse_material(f"leaf{k}", (0.2, 0.6, 0.15)))
    floor(scene, size=30.0, z=-0.6)
    # Tilted 10 degrees about x, then 25 about y: about 27 degrees from overhead.
    sun(scene, angle=math.radians(11.4)).rotation_euler = (math.radians(10.0), math.radians(-25.0), 0.0)
    ru.add_camera(scene, (0.03, -0.32, 0.3), (0.0, 0.0, 0.05), lens=40.0)
    return compare("thin leaves, sun 11.4 deg over a 30 m ground", scene, HARD_DB)


def lit_interior(cycles_on, cycles_off, margin=2):
    """Pixels Cycles lights fully (shadowed value >= 0.9 of the unshadowed
    one), at least `margin` pixels from any that it does not."""
    lum_on, lum_off = cycles_on[..., :3].mean(-1), cycles_off[..., :3].mean(-1)
    lit = (lum_on >= 0.9 * lum_off) & (lum_off > 0.05) & (cycles_on[..., 3] > 0.999)
    interior = lit.copy()
    for dy in range(-margin, margin + 1):
        for dx in range(-margin, margin + 1):
            interior &= np.roll(np.roll(lit, dy, axis=0), dx, axis=1)
    return interior


def case_acne():
    """A closed subdivided sphere and a displaced surface under a low sun."""
    scene = ru.reset_scene()
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.9, location=(-1.2, 0.6, 0.9))
    subdivided(bpy.context.object).data.materials.append(ru.diffuse_material("sphere", (0.8, 0.8, 0.8)))
    plane = displaced_plane(size=5.0, scale=0.9, strength=0.25)
    plane.location = (0.6, 0.0, 0.0)
    sun(scene, elevation=12.0, azimuth=-70.0, energy=4.0)
    ru.add_camera(scene, (0.0, -6.0, 3.0), (0.0, 0.3, 0.3), lens=40.0)
    cycles, micro = render_both(scene, "acne", 128)
    ru.setup_cycles(scene, samples=64, shadows=False)
    cycles_off = ru.render_passes(scene, "CYCLES", W, H)["rgba"]
    ru.set_cast_shadow(bpy.data.lights["sun"], True)
    lit = lit_interior(cycles, cycles_off)
    darker = (cycles[..., :3].mean(-1) - micro[..., :3].mean(-1))[lit]
    worst = float(darker.max()) if darker.size else 0.0
    bad = int((darker > 0.05).sum())
    ok = lit.sum() > 2000 and bad == 0
    print(f"{'ok  ' if ok else 'FAIL'} acne: {int(lit.sum())} pixels lit in Cycles, {bad} darker in Micropoly by "
          f"more than 0.05 (most {worst:.3f})")
    return ok


def shadow_edges(rgba, lit_value):
    """Pixels of the boundary of the floor's shadow: shadowed (below half the
    lit floor's value) next to lit ones."""
    lum = rgba[..., :3].mean(-1)
    dark = lum < 0.5 * lit_value
    edge = np.zeros_like(dark)
    for axis in (0, 1):
        for shift in (1, -1):
            edge |= dark & ~np.roll(dark, shift, axis=axis)
    edge[:2, :] = edge[-2:, :] = False
    edge[:, :2] = edge[:, -2:] = False
    return np.argwhere(edge)


def case_contact():
    """A box on the floor: its shadow's edges, the contact line included,
    where Cycles puts them."""
    scene = ru.reset_scene()
    floor(scene, size=12.0, z=0.0)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 0.0, 0.5))
    bpy.context.object.data.materials.append(ru.diffuse_material("box", (0.05, 0.05, 0.05)))
    sun(scene, elevation=40.0, azimuth=-150.0, energy=3.0)
    ru.add_camera(scene, (1.6, -4.2, 2.6), (0.3, 0.6, 0.2), lens=35.0)
    cycles, micro = render_both(scene, "contact", 64)
    lit_value = float(np.percentile(cycles[..., :3].mean(-1), 90))
    a, b = shadow_edges(cycles, lit_value), shadow_edges(micro, lit_value)
    if len(a) < 50 or len(b) < 50:
        print(f"FAIL contact: too few shadow edge pixels ({len(a)}, {len(b)})")
        return False
    d = np.sqrt(((a[:, None, :] - b[None, :, :]) ** 2).sum(-1))
    ab, ba = d.min(axis=1), d.min(axis=0)
    worst = float(max(np.percentile(ab, 99), np.percentile(ba, 99)))
    ok = worst <= 1.5
    print(f"{'ok  ' if ok else 'FAIL'} contact: shadow edges within {worst:.2f} px of Cycles' (99th percentile, "
          f"{len(a)} and {len(b)} edge pixels; largest {max(ab.max(), ba.max()):.2f} px)")
    return ok


def case_controls():
    """Blender's controls, in Micropoly and in Cycles: the floor under a box
    floating in the light of an overhead sun, with the light's Cast Shadow
    off, the box's Shadow ray visibility off, the box hidden from the
    camera, and the box's material at alpha 0.5 (a quarter of the light
    through its top and bottom faces)."""
    from bpy_extras.object_utils import world_to_camera_view

    scene = ru.reset_scene()
    floor(scene, size=10.0, z=0.0)
    bpy.ops.mesh.primitive_cube_add(size=1.2, location=(0.0, 0.0, 1.5))
    box = bpy.context.object
    box.data.materials.append(ru.diffuse_material("box", (0.5, 0.5, 0.5)))
    light = sun(scene, elevation=90.0, azimuth=0.0, energy=3.0)
    cam = ru.add_camera(scene, (0.0, -5.0, 3.0), (0.0, 0.0, 0.0), lens=35.0)
    ru.setup_cycles(scene, samples=32, shadows=True)
    p = world_to_camera_view(scene, cam, Vector((0.0, 0.0, 0.0)))
    px, py = int(p.x * W), int((1.0 - p.y) * H)

    def under_box(engine):
        rgba = ru.render_passes(scene, engine, W, H, samples=4)["rgba"]
        return float(rgba[py - 3:py + 4, px - 3:px + 4, :3].mean())

    def both():
        return under_box("MICROPOLY"), under_box("CYCLES")

    shadowed = both()
    ru.set_cast_shadow(light.data, False)
    lit = both()
    ru.set_cast_shadow(light.data, True)
    box.visible_shadow = False
    no_shadow = both()
    box.visible_shadow = True
    box.visible_camera = False
    hidden = both()
    box.visible_camera = True
    mat = box.data.materials[0]
    nodes = mat.node_tree.nodes
    principled = nodes.new("ShaderNodeBsdfPrincipled")
    principled.inputs["Alpha"].default_value = 0.5
    mat.node_tree.links.new(principled.outputs[0], next(n for n in nodes if n.type == "OUTPUT_MATERIAL").inputs[0])
    if hasattr(mat, "blend_method"):
        mat.blend_method = "BLEND"
    half = both()
    print(f"     the floor under the box (Micropoly, Cycles): shadowed {shadowed[0]:.3f}, {shadowed[1]:.3f}; "
          f"Cast Shadow off {lit[0]:.3f}, {lit[1]:.3f}; Shadow visibility off {no_shadow[0]:.3f}, "
          f"{no_shadow[1]:.3f}; hidden from the camera {hidden[0]:.3f}, {hidden[1]:.3f}; alpha 0.5 {half[0]:.3f}, "
          f"{half[1]:.3f}")
    full = lit[1]
    checks = [("the box shadows the floor", shadowed),
              ("Cast Shadow off: no shadow", lit),
              ("Shadow ray visibility off: no shadow", no_shadow),
              ("hidden from the camera, the box still shadows the floor", hidden),
              ("alpha 0.5 lets half through each face", half)]
    # Alpha 0.5 on the box's top and bottom faces lets a quarter through.
    ok = full > 0.2 and shadowed[1] < 0.1 * full and abs(half[1] - 0.25 * full) < 0.05 * full
    if not ok:
        print("FAIL controls: the scene does not show what it should in Cycles")
    for what, (micro, cycles) in checks:
        good = abs(micro - cycles) <= 0.05 * full
        print(f"{'ok  ' if good else 'FAIL'} controls: {what} (Micropoly {micro:.3f}, Cycles {cycles:.3f})")
        ok = ok and good
    return ok


CASES = [
    lambda: case_sun(False), lambda: case_sun(True), lambda: case_spot(False), lambda: case_spot(True),
    lambda: case_point(False), lambda: case_point(True), lambda: case_area(False), lambda: case_area(True),
    case_displaced_grazing, case_acne, case_contact, case_controls, case_thin_leaves,
]


def main():
    print(f"Blender {bpy.app.version_string}")
    only = os.environ.get("MICROPOLY_TEST_ONLY")
    ok = True
    for i, case in enumerate(CASES):
        if only and str(i) not in only.split(","):
            continue
        try:
            ok = case() and ok
        except Exception:
            traceback.print_exc()
            ok = False
    print("shadows agree with Cycles" if ok else "some shadow cases disagree with Cycles")
    return 0 if ok else 1


if __name__ == "__main__":
    ru.run_test(main)
