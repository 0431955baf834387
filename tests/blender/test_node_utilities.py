"""Colour and vector utility nodes and node groups, Micropoly against Cycles
(run by blender -b, or by a Python with the bpy module).

Each case is one tile of a single render: a flat quad seen from above by an
orthographic camera, with an Emission shader fed by the node set-up under
test. Its inputs are two smooth colours built from Object coordinates by Math
nodes, A = (x, y, 1 - xy) and B = (1 - y, 0.2 + 0.6x, 0.5 + 0.3y) with x, y in
[0, 1] across the quad, so every case covers a range of inputs. Cases: the
Mix node with every blend mode Blender offers, the Hue/Saturation/Value node,
vector Map Range in each interpolation mode, Vector Rotate of each type
(with and without Invert), RGB Curves, Vector Curves and Float Curve
(their tables among the material's node values), Vector Transform between world, object and
camera space (points, vectors, normals; on tiles turned and scaled
unevenly), node groups (nested, with
linked and unlinked group inputs, and node names repeated inside and outside
the groups), and Texture Coordinate > Object of another object (an Empty
moved, turned and scaled: 65-68 dB; this object's own coordinates instead
give 8.7 dB).

Micropoly shades at grid vertices (shading rate 1/4) and Cycles per sample,
both at 16 samples per pixel. Compared on each tile's interior (two pixels in
from the quad's edge): PSNR >= 40 dB per case, with the case's largest value
as peak. Prints a table. Exits non-zero on failure.

Observed: 44-72 dB; the lowest is stepped Map Range, whose steps Micropoly
ramps over one micropolygon. Switching one blend mode off (it falls back to
Mix) drops its case to 18 dB."""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import render_utils as ru  # noqa: E402

TILE = 48
COLS = 8
MIN_PSNR = 40.0


def _math(nt, op, a, b=None):
    n = nt.nodes.new("ShaderNodeMath")
    n.operation = op
    for i, v in enumerate((a, b)):
        if v is None:
            continue
        if isinstance(v, (int, float)):
            n.inputs[i].default_value = v
        else:
            nt.links.new(v, n.inputs[i])
    return n.outputs[0]


def _combine(nt, x, y, z):
    n = nt.nodes.new("ShaderNodeCombineXYZ")
    for i, v in enumerate((x, y, z)):
        if isinstance(v, (int, float)):
            n.inputs[i].default_value = v
        else:
            nt.links.new(v, n.inputs[i])
    return n.outputs[0]


def _sine(nt, vector):
    """0.5 + 0.4 sin(v) per component: any vector as a colour in range, with
    no edges."""
    wave = nt.nodes.new("ShaderNodeVectorMath")
    wave.operation = "SINE"
    nt.links.new(vector, wave.inputs[0])
    shift = nt.nodes.new("ShaderNodeVectorMath")
    shift.operation = "MULTIPLY_ADD"
    shift.inputs[1].default_value = (0.4, 0.4, 0.4)
    shift.inputs[2].default_value = (0.5, 0.5, 0.5)
    nt.links.new(wave.outputs["Vector"], shift.inputs[0])
    return shift.outputs["Vector"]


def inputs_ab(nt):
    """A and B (see the module docstring) from Object coordinates."""
    coords = nt.nodes.new("ShaderNodeTexCoord")
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(coords.outputs["Object"], sep.inputs[0])
    x = _math(nt, "MULTIPLY_ADD", sep.outputs[0], 0.5)
    x.node.inputs[2].default_value = 0.5
    y = _math(nt, "MULTIPLY_ADD", sep.outputs[1], 0.5)
    y.node.inputs[2].default_value = 0.5
    a = _combine(nt, x, y, _math(nt, "SUBTRACT", 1.0, _math(nt, "MULTIPLY", x, y)))
    b = _combine(nt, _math(nt, "SUBTRACT", 1.0, y), _math(nt, "ADD", _math(nt, "MULTIPLY", x, 0.6), 0.2),
                 _math(nt, "ADD", _math(nt, "MULTIPLY", y, 0.3), 0.5))
    return a, b


def _group_socket(tree, name, in_out, socket_type):
    if hasattr(tree, "interface"):
        return tree.interface.new_socket(name, in_out=in_out, socket_type=socket_type)
    return (tree.inputs if in_out == "INPUT" else tree.outputs).new(socket_type, name)


def make_groups():
    """Inner(Color, Amount) = Amount * Color + (1 - Amount) * (1 - Color), with
    a Math node named like one outside; Outer(A, B, Gain) runs Inner on
    A and on B (Amount unlinked: its default, 0.25) and mixes the two by Gain."""
    inner = bpy.data.node_groups.new("Inner", "ShaderNodeTree")
    _group_socket(inner, "Color", "INPUT", "NodeSocketColor")
    amount = _group_socket(inner, "Amount", "INPUT", "NodeSocketFloat")
    _group_socket(inner, "Result", "OUTPUT", "NodeSocketColor")
    gi, go = inner.nodes.new("NodeGroupInput"), inner.nodes.new("NodeGroupOutput")
    inv = inner.nodes.new("ShaderNodeInvert")
    inv.inputs["Fac"].default_value = 1.0
    inner.links.new(gi.outputs["Color"], inv.inputs["Color"])
    mix = inner.nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    mix.name = "Shared Name"
    inner.links.new(gi.outputs["Amount"], mix.inputs["Factor"])
    inner.links.new(inv.outputs["Color"], mix.inputs[6])
    inner.links.new(gi.outputs["Color"], mix.inputs[7])
    inner.links.new(mix.outputs[2], go.inputs["Result"])

    outer = bpy.data.node_groups.new("Outer", "ShaderNodeTree")
    for name in ("A", "B"):
        _group_socket(outer, name, "INPUT", "NodeSocketColor")
    _group_socket(outer, "Gain", "INPUT", "NodeSocketFloat")
    _group_socket(outer, "Result", "OUTPUT", "NodeSocketColor")
    gi, go = outer.nodes.new("NodeGroupInput"), outer.nodes.new("NodeGroupOutput")
    calls = []
    for name in ("A", "B"):
        call = outer.nodes.new("ShaderNodeGroup")
        call.node_tree = inner
        outer.links.new(gi.outputs[name], call.inputs["Color"])
        calls.append(call)
    outer.links.new(gi.outputs["Gain"], calls[0].inputs["Amount"])
    calls[1].inputs["Amount"].default_value = 0.25
    mix = outer.nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    mix.name = "Shared Name"
    mix.blend_type = "MULTIPLY"
    mix.inputs["Factor"].default_value = 0.8
    outer.links.new(calls[0].outputs["Result"], mix.inputs[6])
    outer.links.new(calls[1].outputs["Result"], mix.inputs[7])
    outer.links.new(mix.outputs[2], go.inputs["Result"])
    return outer


def build_cases():
    cases = []
    modes = [e.identifier for e in bpy.types.ShaderNodeMix.bl_rna.properties["blend_type"].enum_items]
    for mode in modes:
        def mix_case(nt, a, b, mode=mode):
            n = nt.nodes.new("ShaderNodeMix")
            n.data_type = "RGBA"
            n.blend_type = mode
            n.inputs["Factor"].default_value = 0.7
            nt.links.new(a, n.inputs[6])
            nt.links.new(b, n.inputs[7])
            return n.outputs[2]
        cases.append((f"Mix {mode}", mix_case))

    def hsv_case(nt, a, b):
        n = nt.nodes.new("ShaderNodeHueSaturation")
        n.inputs["Hue"].default_value = 0.3
        n.inputs["Saturation"].default_value = 1.6
        n.inputs["Value"].default_value = 0.8
        n.inputs["Fac"].default_value = 0.9
        nt.links.new(a, n.inputs["Color"])
        return n.outputs["Color"]
    cases.append(("Hue/Saturation/Value", hsv_case))

    for mode in ("LINEAR", "STEPPED", "SMOOTHSTEP", "SMOOTHERSTEP"):
        def range_case(nt, a, b, mode=mode):
            n = nt.nodes.new("ShaderNodeMapRange")
            n.data_type = "FLOAT_VECTOR"
            n.interpolation_type = mode
            n.clamp = True
            ids = {s.identifier: s for s in n.inputs}
            nt.links.new(a, ids["Vector"])
            ids["From_Min_FLOAT3"].default_value = (0.2, 0.1, 0.9)
            ids["From_Max_FLOAT3"].default_value = (0.8, 0.9, 0.1)
            nt.links.new(b, ids["To_Min_FLOAT3"])
            ids["To_Max_FLOAT3"].default_value = (1.2, 0.0, 0.7)
            ids["Steps_FLOAT3"].default_value = (3.0, 5.0, 2.0)
            return n.outputs["Vector"]
        cases.append((f"Map Range vector {mode}", range_case))

    def group_case(nt, a, b):
        outer = make_groups()
        # A node outside the group named like nodes inside it.
        gain = nt.nodes.new("ShaderNodeMix")
        gain.name = "Shared Name"
        gain.data_type = "FLOAT"
        gain.inputs["Factor"].default_value = 0.6
        gain.inputs[2].default_value = 0.1
        gain.inputs[3].default_value = 0.9
        n = nt.nodes.new("ShaderNodeGroup")
        n.node_tree = outer
        nt.links.new(a, n.inputs["A"])
        nt.links.new(b, n.inputs["B"])
        nt.links.new(gain.outputs[0], n.inputs["Gain"])
        return n.outputs["Result"]
    cases.append(("Node groups, nested", group_case))

    for rtype, invert in (("AXIS_ANGLE", False), ("AXIS_ANGLE", True), ("X_AXIS", False), ("Y_AXIS", True),
                          ("Z_AXIS", False), ("EULER_XYZ", False), ("EULER_XYZ", True)):
        def rotate_case(nt, a, b, rtype=rtype, invert=invert):
            # A turned about (0.5, 0.5, 0.5) by an angle from B's x (or fixed
            # Euler angles), lifted by 0.5 to stay positive.
            n = nt.nodes.new("ShaderNodeVectorRotate")
            n.rotation_type, n.invert = rtype, invert
            ids = {s.identifier: s for s in n.inputs}  # 4.5 hides unavailable sockets from lookups by name
            nt.links.new(a, ids["Vector"])
            ids["Center"].default_value = (0.5, 0.5, 0.5)
            ids["Axis"].default_value = (1.0, 2.0, 0.5)
            ids["Rotation"].default_value = (0.3, -1.2, 2.0)
            sep = nt.nodes.new("ShaderNodeSeparateXYZ")
            nt.links.new(b, sep.inputs[0])
            nt.links.new(_math(nt, "MULTIPLY", sep.outputs[0], 2.5), ids["Angle"])
            lift = nt.nodes.new("ShaderNodeVectorMath")
            lift.operation = "ADD"
            lift.inputs[1].default_value = (0.5, 0.5, 0.5)
            nt.links.new(n.outputs["Vector"], lift.inputs[0])
            return lift.outputs["Vector"]
        cases.append((f"Vector Rotate {rtype}{' inverted' if invert else ''}", rotate_case))

    for vtype, src, dst in (("POINT", "WORLD", "OBJECT"), ("POINT", "OBJECT", "WORLD"), ("VECTOR", "OBJECT", "WORLD"),
                            ("NORMAL", "OBJECT", "WORLD"), ("NORMAL", "WORLD", "OBJECT"), ("POINT", "WORLD", "CAMERA"),
                            ("POINT", "CAMERA", "OBJECT"), ("VECTOR", "OBJECT", "CAMERA"),
                            ("NORMAL", "CAMERA", "WORLD")):
        def transform_case(nt, a, b, vtype=vtype, src=src, dst=dst):
            # A taken as a point, vector or normal in one space to another
            # (the tile turned and scaled unevenly, build_scene), through
            # sines so far-away values stay in range.
            n = nt.nodes.new("ShaderNodeVectorTransform")
            n.vector_type, n.convert_from, n.convert_to = vtype, src, dst
            nt.links.new(a, n.inputs["Vector"])
            return _sine(nt, n.outputs["Vector"])
        cases.append((f"Vector Transform {vtype} {src}>{dst}", transform_case))

    def set_points(curve, points):
        while len(curve.points) < len(points):
            curve.points.new(0.5, 0.5)
        for point, xy in zip(curve.points, points):
            point.location = xy

    def rgb_curves_case(nt, a, b):
        # Red and the combined curve bent, the combined extrapolated: the
        # table travels as node values (MP_PARAM_TABLE).
        n = nt.nodes.new("ShaderNodeRGBCurve")
        set_points(n.mapping.curves[0], [(0.0, 0.1), (0.45, 0.8), (1.0, 0.6)])
        set_points(n.mapping.curves[3], [(0.1, 0.0), (0.6, 0.45), (0.9, 1.0)])
        n.mapping.extend = "EXTRAPOLATED"
        n.mapping.update()
        n.inputs["Fac"].default_value = 0.9
        nt.links.new(a, n.inputs["Color"])
        return n.outputs["Color"]
    cases.append(("RGB Curves", rgb_curves_case))

    def vector_curves_case(nt, a, b):
        n = nt.nodes.new("ShaderNodeVectorCurve")
        set_points(n.mapping.curves[1], [(-1.0, 0.2), (0.3, 0.9), (1.0, -0.4)])
        n.mapping.update()
        nt.links.new(b, n.inputs["Vector"])
        lift = nt.nodes.new("ShaderNodeVectorMath")
        lift.operation = "ADD"
        lift.inputs[1].default_value = (0.0, 0.5, 0.0)
        nt.links.new(n.outputs["Vector"], lift.inputs[0])
        return lift.outputs["Vector"]
    cases.append(("Vector Curves", vector_curves_case))

    if hasattr(bpy.types, "ShaderNodeFloatCurve"):
        def float_curve_case(nt, a, b):
            sep = nt.nodes.new("ShaderNodeSeparateXYZ")
            nt.links.new(a, sep.inputs[0])
            n = nt.nodes.new("ShaderNodeFloatCurve")
            set_points(n.mapping.curves[0], [(0.0, 0.9), (0.35, 0.2), (1.0, 0.7)])
            n.mapping.update()
            nt.links.new(sep.outputs[0], n.inputs["Value"])
            return _combine(nt, n.outputs["Value"], sep.outputs[1], sep.outputs[2])
        cases.append(("Float Curve", float_curve_case))

    def other_object_case(nt, a, b):
        # Texture Coordinate > Object of another object (an Empty moved,
        # turned and scaled), through smooth sines so the case has no edges.
        ref = bpy.data.objects.new("Reference", None)
        bpy.context.scene.collection.objects.link(ref)
        ref.location = (3.0, -1.0, 0.5)
        ref.rotation_euler = (0.3, 0.2, 0.9)
        ref.scale = (0.7, 1.6, 1.0)
        coords = nt.nodes.new("ShaderNodeTexCoord")
        coords.object = ref
        return _sine(nt, coords.outputs["Object"])
    cases.append(("Texture Coordinate, other object", other_object_case))
    return cases


def build_scene(cases):
    scene = ru.reset_scene()
    rows = (len(cases) + COLS - 1) // COLS
    tile_world = 2.0
    for i, (name, make) in enumerate(cases):
        row, col = divmod(i, COLS)
        mat, emission = ru.emission_material(f"case{i}")
        nt = mat.node_tree
        a, b = inputs_ab(nt)
        nt.links.new(make(nt, a, b), emission.inputs["Color"])
        mesh = bpy.data.meshes.new(f"quad{i}")
        mesh.from_pydata([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)])
        mesh.materials.append(mat)
        obj = ru.add_tile(scene, f"quad{i}", mesh, row, col, rows, COLS, tile_world)
        if name.startswith("Vector Transform"):
            obj.rotation_euler = (0.0, 0.0, 0.25)
            obj.scale = (0.8, 0.75, 1.3)
    cam = ru.add_camera(scene, (0.0, 0.0, 10.0), (0.0, 0.0, 0.0), ortho_scale=COLS * tile_world)
    cam.rotation_euler = (0.0, 0.0, 0.0)  # straight down, +y up, so tiles read left to right
    scene.micropoly.shading_rate = 0.25
    return scene, rows


def main():
    ru.reset_scene()  # before the cases: they look up node types of this Blender
    cases = build_cases()
    scene, rows = build_scene(cases)
    width, height = COLS * TILE, rows * TILE
    ru.setup_cycles(scene, samples=16, adaptive_subdivision=False)
    ref = ru.render_passes(scene, "CYCLES", width, height)["rgba"]
    ours = ru.render_passes(scene, "MICROPOLY", width, height)["rgba"]
    interior = ru.covered_interior(ref, ours)
    failures = []
    print(f"{'case':34s} {'PSNR dB':>8s} {'max |diff|':>10s}")
    for i, (name, _) in enumerate(cases):
        row, col = divmod(i, COLS)
        sl = (slice(row * TILE, (row + 1) * TILE), slice(col * TILE, (col + 1) * TILE))
        mask = interior[sl]
        if mask.sum() < 0.5 * (0.9 * TILE) ** 2:
            failures.append(f"{name}: only {mask.sum()} interior pixels")
            continue
        value, worst = ru.masked_psnr(ours[sl], ref[sl], mask)
        print(f"{name:34s} {value:8.1f} {worst:10.4f}")
        if not value >= MIN_PSNR:
            failures.append(f"{name}: {value:.1f} dB < {MIN_PSNR} dB")
    return ru.verdict(failures, f"{len(cases)} node cases within {MIN_PSNR} dB of Cycles")


if __name__ == "__main__":
    ru.run_test(main)
