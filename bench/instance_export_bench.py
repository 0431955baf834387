"""Export time of Geometry Nodes instances: a grid of points, a subdivided
rock instanced on each (Instance on Points, random rotation and scale),
exported by the add-on (export.export_scene) as F12 does; the time of the
export alone, its prototypes and instances, and per million instances.
With --attribute the rock's material reads "k", an instance attribute
Geometry Nodes store (the instance's index), through an Attribute node of
type Instancer, so the export also reads each instance's value.

  MICROPOLY_ADDON_DIR=build/addons build/bpy-4.5.15/bin/python3 bench/instance_export_bench.py [--instances 100000] [--rounds 3] [--attribute]
"""

import os
import statistics
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "blender"))

import bpy  # noqa: E402

import render_utils as ru  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
COUNT = int(args[args.index("--instances") + 1]) if "--instances" in args else 100000
ROUNDS = int(args[args.index("--rounds") + 1]) if "--rounds" in args else 3
ATTRIBUTE = "--attribute" in args


def scene(count):
    scene = ru.reset_scene()
    ru.add_camera(scene, (0.0, -60.0, 30.0), (0.0, 0.0, 0.0))
    ru.add_sun(scene, (0.8, 0.0, 0.5))
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=2, radius=0.3, location=(0.0, 0.0, -50.0))
    rock = bpy.context.object
    rock.modifiers.new("Subdivision", "SUBSURF").render_levels = 2
    side = max(2, int(round(count ** 0.5)))
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=side - 1, y_subdivisions=side - 1, size=100.0)
    grid = bpy.context.object
    tree, on_points, group_out = ru.scatter_instances(grid, rock)
    if ATTRIBUTE:
        read_instance_index(tree, on_points, group_out, rock)
    return scene, side * side


def read_instance_index(tree, on_points, group_out, rock):
    """Stores each instance's index as "k" and colours the rock by it."""
    store = tree.nodes.new("GeometryNodeStoreNamedAttribute")
    store.data_type, store.domain = "FLOAT", "INSTANCE"
    store.inputs["Name"].default_value = "k"
    tree.links.new(on_points.outputs["Instances"], store.inputs["Geometry"])
    tree.links.new(tree.nodes.new("GeometryNodeInputIndex").outputs[0],
                   next(i for i in store.inputs if i.name == "Value" and i.enabled))
    tree.links.new(store.outputs["Geometry"], group_out.inputs[0])
    mat = ru.diffuse_material("Rock", (0.5, 0.5, 0.5))
    attribute = mat.node_tree.nodes.new("ShaderNodeAttribute")
    attribute.attribute_type, attribute.attribute_name = "INSTANCER", "k"
    bsdf = next(n for n in mat.node_tree.nodes if n.type == "BSDF_DIFFUSE")
    mat.node_tree.links.new(attribute.outputs["Color"], bsdf.inputs["Color"])
    rock.data.materials.append(mat)


def main():
    built, count = scene(COUNT)
    from micropoly import export

    depsgraph = bpy.context.evaluated_depsgraph_get()
    times = []
    for _ in range(ROUNDS):
        start = time.perf_counter()
        exported = export.export_scene(depsgraph)
        times.append(time.perf_counter() - start)
    s = exported.scene
    median = statistics.median(times)
    print(f"Blender {bpy.app.version_string}{', an instance attribute read' if ATTRIBUTE else ''}: "
          f"{count:,} instances, {s.prototype_count} prototypes, "
          f"{s.instance_count:,} placed; export {median:.2f} s (median of {ROUNDS}: "
          f"{', '.join(f'{t:.2f}' for t in times)}), {median * 1e6 / count:.1f} s per million")
    return 0


ru.run_test(main)
