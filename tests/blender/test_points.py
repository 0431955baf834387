"""Point clouds in Blender (run by blender -b, or a Python with the bpy
module): Geometry Nodes' Distribute Points on Faces with a random radius per
point and a material, above a floor under a sun that casts shadows,
exported as one shared sphere prototype and one instance per point, and
rendered against Cycles' direct light (PSNR >= 32 dB over pixels both
cover, silhouettes IoU >= 0.98); hidden from the camera, the points still
cast their shadows, as in Cycles (the floor and shadows alone against
Cycles >= 30 dB, test_shadows.py's bar for hard shadows). Then what point
materials read, shown through emission: Point Info's Random, Radius and
Position and an attribute of the points read by name (their radius),
against Cycles >= 35 dB over the pixels both cover; and the points moving
with their emitter against Cycles' motion blur >= 30 dB over every pixel
either covers. Exits non-zero on failure."""

import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

import render_utils as ru  # noqa: E402

RESULTS = []
W, H = 320, 240
CYCLES_SAMPLES = 128


def check(name, condition, detail=""):
    RESULTS.append(bool(condition))
    print(f"{'ok  ' if condition else 'FAIL'} {name}" + (f": {detail}" if detail else ""))


def points_scene():
    """Returns the scene and the emitter, whose modifier outputs only points."""
    scene = ru.reset_scene()
    ru.add_camera(scene, (4.5, -5.5, 4.5), (0.0, 0.0, 0.0))
    ru.add_sun(scene, (math.radians(30), 0.0, math.radians(40)))
    bpy.ops.mesh.primitive_plane_add(size=10.0, location=(0.0, 0.0, -0.5))
    bpy.context.object.name = "Floor"
    bpy.context.object.data.materials.append(ru.diffuse_material("Floor", (0.6, 0.6, 0.6)))
    bpy.ops.mesh.primitive_plane_add(size=4.0, location=(0.0, 0.0, 0.4))
    emitter = bpy.context.object
    emitter.name = "Emitter"
    mod = emitter.modifiers.new("Points", "NODES")
    tree = bpy.data.node_groups.new("Points", "GeometryNodeTree")
    mod.node_group = tree
    nodes, links = tree.nodes, tree.links
    if hasattr(tree, "interface"):  # Blender 4.0 and later
        tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
        tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    else:
        tree.inputs.new("NodeSocketGeometry", "Geometry")
        tree.outputs.new("NodeSocketGeometry", "Geometry")
    group_in, group_out = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    distribute = nodes.new("GeometryNodeDistributePointsOnFaces")
    distribute.inputs["Density"].default_value = 4.0
    distribute.inputs["Seed"].default_value = 7
    radius = nodes.new("GeometryNodeSetPointRadius")
    size = nodes.new("FunctionNodeRandomValue")
    size.data_type = "FLOAT"
    size.inputs[2].default_value, size.inputs[3].default_value = 0.08, 0.22  # Min, Max (float)
    material = nodes.new("GeometryNodeSetMaterial")
    material.inputs["Material"].default_value = ru.diffuse_material("Beads", (0.8, 0.35, 0.1))
    links.new(group_in.outputs[0], distribute.inputs["Mesh"])
    links.new(distribute.outputs["Points"], radius.inputs["Points"])
    links.new(size.outputs[1], radius.inputs["Radius"])
    links.new(radius.outputs[0], material.inputs["Geometry"])
    links.new(material.outputs[0], group_out.inputs[0])
    return scene, emitter


def against_cycles(name, scene, threshold=32.0):
    ru.setup_cycles(scene, samples=CYCLES_SAMPLES, shadows=True)
    ref = ru.render_passes(scene, "CYCLES", W, H)["rgba"]
    got = ru.render_passes(scene, "MICROPOLY", W, H, samples=16)["rgba"]
    both = (ref[..., 3] > 0.999) & (got[..., 3] > 0.999)
    iou = ru.iou(ref[..., 3], got[..., 3])
    a, b = ref[both][:, :3], got[both][:, :3]
    p = ru.psnr(a, b, peak=float(a.max())) if both.sum() else 0.0
    check(f"{name}: against Cycles' direct light", p >= threshold and iou >= 0.98 and both.sum() > 8000,
          f"{p:.1f} dB, IoU {iou:.4f}, {int(both.sum())} pixels")
    return got


def scaled(nodes, links, value, factor):
    math = nodes.new("ShaderNodeMath")
    math.operation = "MULTIPLY"
    links.new(value, math.inputs[0])
    math.inputs[1].default_value = factor
    return math.outputs[0]


def info_material(nodes, links, info):
    """Emission of (Random, 4 x Radius, 2 x the points' "radius" attribute
    read by an Attribute node)."""
    xyz, attribute = nodes.new("ShaderNodeCombineXYZ"), nodes.new("ShaderNodeAttribute")
    attribute.attribute_name = "radius"
    links.new(info.outputs["Random"], xyz.inputs[0])
    links.new(scaled(nodes, links, info.outputs["Radius"], 4.0), xyz.inputs[1])
    links.new(scaled(nodes, links, attribute.outputs["Fac"], 2.0), xyz.inputs[2])
    return xyz.outputs[0]


def position_material(nodes, links, info):
    """Emission of the point's centre, 0.25 x Position + 0.5."""
    shift = nodes.new("ShaderNodeVectorMath")
    shift.operation = "MULTIPLY_ADD"
    links.new(info.outputs["Position"], shift.inputs[0])
    shift.inputs[1].default_value = (0.25, 0.25, 0.25)
    shift.inputs[2].default_value = (0.5, 0.5, 0.5)
    return shift.outputs[0]


def set_points_material(emitter, m):
    """The points' material, set by the tree's Set Material node. The
    emitter's own slot gets it too: the mesh renders nothing (the tree
    outputs only points), but the Cycles references know a scene by its
    objects' material slots, not by what a node tree assigns."""
    next(n for n in emitter.modifiers["Points"].node_group.nodes if n.type == "SET_MATERIAL").inputs[
        "Material"].default_value = m
    emitter.data.materials.clear()
    emitter.data.materials.append(m)


def emission_against_cycles(name, scene, emitter, build):
    m, emission = ru.emission_material(name)
    nodes, links = m.node_tree.nodes, m.node_tree.links
    links.new(build(nodes, links, nodes.new("ShaderNodePointInfo")), emission.inputs["Color"])
    set_points_material(emitter, m)
    ru.setup_cycles(scene, samples=32)
    ref = ru.render_passes(scene, "CYCLES", W, H)["rgba"]
    got = ru.render_passes(scene, "MICROPOLY", W, H, samples=16)["rgba"]
    both = (ref[..., 3] > 0.999) & (got[..., 3] > 0.999)
    a, b = ref[both][:, :3], got[both][:, :3]
    p = ru.psnr(a, b, peak=float(a.max())) if both.sum() else 0.0
    check(f"points: {name} against Cycles", p >= 35.0 and both.sum() > 8000, f"{p:.1f} dB, {int(both.sum())} pixels")


def main():
    scene, emitter = points_scene()
    from micropoly import export

    depsgraph = bpy.context.evaluated_depsgraph_get()
    clouds = [inst.object.data for inst in depsgraph.object_instances if inst.object.type == "POINTCLOUD"]
    count = sum(len(pc.points) for pc in clouds)
    exported = export.export_scene(depsgraph)
    got = (exported.scene.prototype_count, exported.scene.instance_count, exported.scene.mesh_count)
    check("points: one sphere prototype, an instance per point", len(clouds) == 1 and count > 30 and
          got == (1, count, 1), f"{count} points, exported {got}")
    seen = against_cycles("points", scene)
    # Hidden from the camera: gone from the image, their shadows stay.
    emitter.visible_camera = False
    # The floor and the points' shadows alone: test_shadows.py's bar for hard shadows.
    hidden = against_cycles("points hidden from the camera", scene, threshold=30.0)
    floor = (seen[..., 3] > 0.999) & (hidden[..., 3] > 0.999)
    shadowed = hidden[..., :3].sum(axis=-1)[floor] < 0.5 * hidden[..., :3].sum(axis=-1)[floor].max()
    check("points hidden from the camera: their shadows stay", 800 < int(shadowed.sum()),
          f"{int(shadowed.sum())} floor pixels in shadow")
    emitter.visible_camera = True
    bpy.data.objects["Floor"].hide_render = True
    emission_against_cycles("Point Info's Random and Radius, the points' radius attribute", scene, emitter,
                            info_material)
    emission_against_cycles("Point Info's Position", scene, emitter, position_material)

    # Moving during the shutter: the emitter slides along x (keys at frames
    # 1 and 3, frame 2 rendered with a shutter of one frame).
    ru.motion_blur(scene)
    for frame, x in ((1, -0.4), (3, 0.4)):
        emitter.location.x = x
        emitter.keyframe_insert("location", frame=frame)
    scene.frame_set(2)
    m, emission = ru.emission_material("Moving points")
    m.node_tree.links.new(info_material(m.node_tree.nodes, m.node_tree.links, m.node_tree.nodes.new(
        "ShaderNodePointInfo")), emission.inputs["Color"])
    set_points_material(emitter, m)
    ru.setup_cycles(scene, samples=64)
    ref = ru.render_passes(scene, "CYCLES", W, H)["rgba"]
    got = ru.render_passes(scene, "MICROPOLY", W, H, samples=64)["rgba"]  # blur is noise at 16 samples
    p, seen = ru.blurred_psnr(ref, got)
    check("points moving, against Cycles' motion blur", p >= 30.0 and seen > 8000,
          f"{p:.1f} dB over {seen} pixels either covers")
    return 0 if all(RESULTS) else 1


ru.run_test(main)
