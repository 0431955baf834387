"""Vectors that node trees read about the shading point, Micropoly against
Cycles (run by blender -b, or by a Python with the bpy module).

Each case is one subdivided UV sphere (Subdivision Surface, smooth), turned
about an oblique axis and scaled unevenly, seen by a perspective camera with
a shifted lens, with an Emission shader fed by the vector under test through
a smooth sine (so any vector becomes a colour in range):

  - Geometry: Position, Normal, Incoming, Tangent (all world space);
  - Texture Coordinate: Normal (object space), Reflection (world space),
    Camera (Cycles' camera space, +Z forward) and Window (the image's
    normalised coordinates);
  - Tangent node: radial about X, and along a UV map (MikkTSpace);
  - normals made by nodes: Bump (world-space distance, a wave on Object
    coordinates), Normal Map in object and in tangent space (constant
    colours), Vector Math on Geometry's Normal;
  - Fresnel and Layer Weight (Facing) with Geometry's Normal linked.

Compared on each sphere's pixels both renderers cover, two pixels in from
its silhouette: PSNR >= 35 dB per case (peak: the case's largest value),
but >= 30 dB for Bump in Blender 3.x, whose Cycles takes the height's
difference over a whole pixel's footprint in two arbitrary directions (4.0
on: a tenth of it): the bumped normals' correlation with Micropoly's grows
with resolution there (0.87, 0.96, 0.98 at 64, 128, 256 pixels a sphere;
0.998 in 4.5 at 128).
Micropoly shades at grid vertices (shading rate 1/4), Cycles per sample
with adaptive subdivision at one pixel; both at 16 samples per pixel.

Observed: 32-78 dB in 3.4 (Bump the lowest), 45-78 dB in 4.5 and 5.0
(Normal Map in object space, constant per object, 115 dB everywhere). Mutation: with node vectors in object space (Micropoly before it
followed Cycles into world space, Camera, Window, Reflection and the Tangent
node then giving zero) the twelve cases that read world-space vectors fall
to 4.7-12.9 dB; Position, Texture Coordinate Normal, Fresnel and Layer
Weight, whose results do not depend on that, stay where they are."""

import os
import sys
import tempfile

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import render_utils as ru  # noqa: E402

TILE = 72
COLS = 5
MIN_PSNR = 35.0


def _vmath(nt, op, a, b=None, scale=None):
    n = nt.nodes.new("ShaderNodeVectorMath")
    n.operation = op
    nt.links.new(a, n.inputs[0])
    if b is not None:
        if isinstance(b, tuple):
            n.inputs[1].default_value = b
        else:
            nt.links.new(b, n.inputs[1])
    if scale is not None:
        n.inputs["Scale"].default_value = scale
    return n.outputs["Value" if op in ("DOT_PRODUCT", "LENGTH", "DISTANCE") else "Vector"]


def as_colour(nt, vector, frequency):
    """0.5 + 0.4 sin(frequency v + 0.7) per component: a smooth colour in
    range for any vector (the phase keeps zero vectors off mid-grey)."""
    phase = _multiply_add(nt, vector, frequency, 0.7)
    return _multiply_add(nt, _vmath(nt, "SINE", phase), 0.4, 0.5)


def _multiply_add(nt, vector, scale, offset):
    n = nt.nodes.new("ShaderNodeVectorMath")
    n.operation = "MULTIPLY_ADD"
    nt.links.new(vector, n.inputs[0])
    n.inputs[1].default_value = (scale,) * 3
    n.inputs[2].default_value = (offset,) * 3
    return n.outputs["Vector"]


def _node(nt, kind, **props):
    n = nt.nodes.new(kind)
    for k, v in props.items():
        setattr(n, k, v)
    return n


def _geometry(nt, output):
    return _node(nt, "ShaderNodeNewGeometry").outputs[output]


def _coords(nt, output):
    return _node(nt, "ShaderNodeTexCoord").outputs[output]


def _bump(nt):
    wave = _node(nt, "ShaderNodeTexWave", wave_type="BANDS", bands_direction="DIAGONAL")
    wave.inputs["Scale"].default_value = 0.8
    nt.links.new(_coords(nt, "Object"), wave.inputs["Vector"])
    bump = _node(nt, "ShaderNodeBump")
    bump.inputs["Distance"].default_value = 0.08
    nt.links.new(wave.outputs["Fac"], bump.inputs["Height"])
    return bump.outputs["Normal"]


def _normal_map(nt, space, colour):
    n = _node(nt, "ShaderNodeNormalMap", space=space)
    n.inputs["Color"].default_value = (*colour, 1.0)
    return n.outputs["Normal"]


def _fresnel(nt):
    n = _node(nt, "ShaderNodeFresnel")
    n.inputs["IOR"].default_value = 1.8
    nt.links.new(_geometry(nt, "Normal"), n.inputs["Normal"])
    return _node_value_colour(nt, n.outputs["Fac"])


def _facing(nt):
    n = _node(nt, "ShaderNodeLayerWeight")
    n.inputs["Blend"].default_value = 0.3
    nt.links.new(_geometry(nt, "Normal"), n.inputs["Normal"])
    return _node_value_colour(nt, n.outputs["Facing"])


def _node_value_colour(nt, value):
    comb = _node(nt, "ShaderNodeCombineXYZ")
    for i in range(3):
        nt.links.new(value, comb.inputs[i])
    return comb.outputs[0]


def build_cases():
    """(name, function(node tree) -> colour socket)."""
    return [
        ("Geometry Position", lambda nt: as_colour(nt, _geometry(nt, "Position"), 1.3)),
        ("Geometry Normal", lambda nt: as_colour(nt, _geometry(nt, "Normal"), 3.0)),
        ("Geometry Incoming", lambda nt: as_colour(nt, _geometry(nt, "Incoming"), 6.0)),
        ("Geometry Tangent", lambda nt: as_colour(nt, _geometry(nt, "Tangent"), 3.0)),
        ("Texture Coordinate Normal", lambda nt: as_colour(nt, _coords(nt, "Normal"), 3.0)),
        ("Texture Coordinate Reflection", lambda nt: as_colour(nt, _coords(nt, "Reflection"), 3.0)),
        ("Texture Coordinate Camera", lambda nt: as_colour(nt, _coords(nt, "Camera"), 1.5)),
        ("Texture Coordinate Window", lambda nt: as_colour(nt, _coords(nt, "Window"), 8.0)),
        ("Tangent radial X", lambda nt: as_colour(
            nt, _node(nt, "ShaderNodeTangent", direction_type="RADIAL", axis="X").outputs[0], 3.0)),
        ("Tangent UV map", lambda nt: as_colour(
            nt, _node(nt, "ShaderNodeTangent", direction_type="UV_MAP").outputs[0], 3.0)),
        ("Bump", lambda nt: as_colour(nt, _bump(nt), 3.0)),
        ("Normal Map object", lambda nt: as_colour(nt, _normal_map(nt, "OBJECT", (0.7, 0.4, 0.8)), 3.0)),
        ("Normal Map tangent", lambda nt: as_colour(nt, _normal_map(nt, "TANGENT", (0.65, 0.4, 0.9)), 3.0)),
        ("Vector Math on Normal", lambda nt: as_colour(
            nt, _vmath(nt, "CROSS_PRODUCT", _geometry(nt, "Normal"), (0.3, 0.8, 0.5)), 3.0)),
        ("Fresnel, Normal linked", _fresnel),
        ("Layer Weight Facing, Normal linked", _facing),
    ]


def build_scene(cases):
    scene = ru.reset_scene()
    rows = (len(cases) + COLS - 1) // COLS
    for i, (name, make) in enumerate(cases):
        row, col = divmod(i, COLS)
        mat, emission = ru.emission_material(f"case{i}")
        nt = mat.node_tree
        nt.links.new(make(nt), emission.inputs["Color"])
        bpy.ops.mesh.primitive_uv_sphere_add(segments=16, ring_count=8, radius=0.75)
        obj = bpy.context.object
        obj.name = f"sphere{i}"
        obj.location = (2.0 * col - COLS + 1.0, rows - 1.0 - 2.0 * row, 0.0)
        # Turned about an oblique axis, scaled unevenly: object, world and
        # camera space all differ, and normals differ from directions.
        obj.rotation_euler = (0.7 + 0.1 * i, -0.5, 0.9 + 0.2 * i)
        obj.scale = (1.0, 0.65, 1.3)
        obj.modifiers.new("Subdivision", "SUBSURF").render_levels = 2
        obj.data.materials.append(mat)
        ru.shade_smooth(obj)
    ru.add_camera(scene, (0.3, -0.4, 17.0), (0.3, -0.4, 0.0), shift=(0.03, -0.02))
    scene.camera.rotation_euler = (0.0, 0.0, 0.0)  # straight down, +y up, so spheres read left to right
    scene.micropoly.shading_rate = 0.25
    return scene, rows


def world_window_warning(scene):
    """A world reading Texture Coordinate > Window: the world is baked into a
    map, not seen through the camera, so the output warns (once, naming the
    world and the node) and gives zero; the other outputs do not warn."""
    nt = scene.world.node_tree if scene.world.use_nodes else None
    if nt is None:
        scene.world.use_nodes = True
        nt = scene.world.node_tree
    background = next(n for n in nt.nodes if n.type == "BACKGROUND")
    coords = _node(nt, "ShaderNodeTexCoord", name="Screen")
    nt.links.new(as_colour(nt, coords.outputs["Window"], 2.0), background.inputs["Color"])
    nt.links.new(coords.outputs["Generated"], background.inputs["Strength"])
    from micropoly import operators
    path = os.path.join(tempfile.mkdtemp(prefix="mp-node-vectors-"), "world.rib")
    warnings = operators.export_rib(bpy.context.evaluated_depsgraph_get(), path)
    hits = [w for w in warnings if "'Screen'" in w]
    print(f"world warnings: {hits}")
    if len(hits) != 1 or "Window" not in hits[0] or scene.world.name not in hits[0]:
        return [f"world reading Window: {len(hits)} warnings naming node 'Screen' and Window, not 1"]
    return []


def main():
    cases = build_cases()
    scene, rows = build_scene(cases)
    width, height = COLS * TILE, rows * TILE
    ru.setup_cycles(scene, samples=16, adaptive_subdivision=True)
    ref = ru.render_passes(scene, "CYCLES", width, height)["rgba"]
    ours = ru.render_passes(scene, "MICROPOLY", width, height)["rgba"]
    out = os.environ.get("MICROPOLY_TEST_OUTPUT")
    if out:
        ru.save_side_by_side(out, "node_vectors", ref, ours)
    interior = ru.covered_interior(ref, ours)
    # Each sphere's pixels: the nearest sphere centre in the image.
    cam = scene.camera
    from bpy_extras.object_utils import world_to_camera_view
    centres = []
    for i in range(len(cases)):
        c = world_to_camera_view(scene, cam, bpy.data.objects[f"sphere{i}"].location)
        centres.append(((1.0 - c.y) * height, c.x * width))
    yy, xx = np.mgrid[0:height, 0:width] + 0.5
    d = np.stack([(yy - cy) ** 2 + (xx - cx) ** 2 for cy, cx in centres])
    owner = np.argmin(d, axis=0)
    failures = []
    print(f"{'case':36s} {'pixels':>6s} {'PSNR dB':>8s} {'max |diff|':>10s}")
    for i, (name, _) in enumerate(cases):
        mask = interior & (owner == i)
        if mask.sum() < 400:
            failures.append(f"{name}: only {mask.sum()} interior pixels")
            continue
        value, worst = ru.masked_psnr(ours, ref, mask)
        print(f"{name:36s} {int(mask.sum()):6d} {value:8.1f} {worst:10.4f}")
        least = 30.0 if name == "Bump" and bpy.app.version < (4, 0, 0) else MIN_PSNR
        if not value >= least:
            failures.append(f"{name}: {value:.1f} dB < {least} dB")
    failures += world_window_warning(scene)
    return ru.verdict(failures, f"{len(cases)} vector cases within {MIN_PSNR} dB of Cycles")


if __name__ == "__main__":
    ru.run_test(main)
