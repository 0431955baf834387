"""Instances in Blender (run by blender -b, or a Python with the bpy module):
Geometry Nodes' Instance on Points (still, and moving over the shutter
with Render > Motion Blur), a particle system of objects and one of a
collection, a collection instanced by empties whose collection holds another collection
instance (nested), objects sharing one mesh (linked duplicates), and
Instance on Points of a subdivided, displaced rock, and Attribute nodes of
type Instancer and Object on instances, each exported as prototypes and instances (one prototype per instanced
mesh, one instance per copy: the exported scene's own counts), each against
Cycles' direct light (PSNR >= 30 dB over pixels both cover, silhouettes
IoU >= 0.98), and each rendering like the same scene with its instances made
real in Blender (Realize Instances, Make Instances Real, a mesh of its own
for each duplicate): PSNR >= 60 dB,
alpha identical. The Geometry Nodes scene, written as RIB (ObjectBegin,
ObjectInstance) and rendered by the CLI, matches its F12. Exits non-zero on
failure."""

import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import render_utils as ru  # noqa: E402

RESULTS = []
W, H = 160, 120
CYCLES_SAMPLES = 128


def check(name, condition, detail=""):
    RESULTS.append(bool(condition))
    print(f"{'ok  ' if condition else 'FAIL'} {name}" + (f": {detail}" if detail else ""))


def exported_counts(scene):
    from micropoly import export

    exported = export.export_scene(bpy.context.evaluated_depsgraph_get())
    return exported.scene.prototype_count, exported.scene.instance_count, exported.scene.mesh_count


def base_scene():
    scene = ru.reset_scene()
    ru.add_camera(scene, (7.0, -9.0, 7.0), (0.0, 0.0, 0.0))
    ru.add_sun(scene, (math.radians(35), 0.0, math.radians(25)))
    bpy.ops.mesh.primitive_plane_add(size=12.0, location=(0.0, 0.0, -0.6))
    bpy.context.object.name = "Floor"
    bpy.context.object.data.materials.append(ru.diffuse_material("Floor", (0.6, 0.6, 0.6)))
    return scene


def rock(name, color, location=(0.0, 0.0, -20.0)):
    """A flat-shaded ico sphere, away from the camera: only its instances show."""
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=2, radius=0.5, location=location)
    obj = bpy.context.object
    obj.name = name
    obj.data.materials.append(ru.diffuse_material(name, color))
    return obj


def against_cycles(name, scene):
    ru.setup_cycles(scene, samples=CYCLES_SAMPLES)
    ref = ru.render_passes(scene, "CYCLES", W, H)["rgba"]
    got = ru.render_passes(scene, "MICROPOLY", W, H, samples=16)["rgba"]
    both = (ref[..., 3] > 0.999) & (got[..., 3] > 0.999)
    iou = ru.iou(ref[..., 3], got[..., 3])
    a, b = ref[both][:, :3], got[both][:, :3]
    p = ru.psnr(a, b, peak=float(a.max())) if both.sum() else 0.0
    check(f"{name}: against Cycles' direct light", p >= 30.0 and iou >= 0.98 and both.sum() > 2000,
          f"{p:.1f} dB, IoU {iou:.4f}, {int(both.sum())} pixels")


def single_users(scene):
    """Each mesh object its own mesh: objects made real share their mesh,
    which would make them instances again (linked duplicates)."""
    for obj in scene.objects:
        if obj.type == "MESH" and obj.data.users > 1:
            obj.data = obj.data.copy()


def compare(name, scene, make_real, prototypes, instances):
    got = exported_counts(scene)
    check(f"{name}: exported as prototypes and instances", got[0] == prototypes and got[1] == instances,
          f"{got[0]} prototypes, {got[1]} instances (expected {prototypes}, {instances})")
    against_cycles(name, scene)
    a = ru.render_passes(scene, "MICROPOLY", W, H, samples=4)["rgba"]
    make_real()
    real = exported_counts(scene)
    check(f"{name}: made real, no instances are left", real[1] == 0, f"{real[1]} instances")
    b = ru.render_passes(scene, "MICROPOLY", W, H, samples=4)["rgba"]
    p = ru.psnr(a[..., :3], b[..., :3], peak=1.0)
    alpha_same = bool(np.array_equal(a[..., 3], b[..., 3]))
    covered = float((a[..., 3] > 0.5).mean())
    check(f"{name}: renders like its instances made real", p >= 60.0 and alpha_same and covered > 0.2,
          f"{p:.1f} dB, alpha identical {alpha_same}, covered {covered:.2f}")


def displaced_rock(name, color):
    """A cube under a Subdivision Surface modifier (rendered as its limit
    surface), displaced by its material's noise, away from the camera."""
    bpy.ops.mesh.primitive_cube_add(size=0.9, location=(0.0, 0.0, -20.0))
    obj = bpy.context.object
    obj.name = name
    mod = obj.modifiers.new("Subdivision", "SUBSURF")
    mod.levels = mod.render_levels = 3
    mat = ru.diffuse_material(name, color)
    ru.add_noise_displacement(mat, 2.5, 0.15, detail=0.0)
    obj.data.materials.append(mat)
    return obj


def geometry_nodes_scene(displaced=False):
    """Instance on Points: a rock on each vertex of a 4 x 4 grid, rotated and
    scaled per point."""
    scene = base_scene()
    stone = displaced_rock("Stone", (0.8, 0.4, 0.2)) if displaced else rock("Stone", (0.8, 0.4, 0.2))
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=3, y_subdivisions=3, size=8.0)
    grid = bpy.context.object
    grid.name = "Scatter"
    tree, on_points, group_out = ru.scatter_instances(grid, stone, scale_range=(0.6, 1.3))
    nodes, links = tree.nodes, tree.links

    def realize():
        real = nodes.new("GeometryNodeRealizeInstances")
        links.new(on_points.outputs["Instances"], real.inputs["Geometry"])
        links.new(real.outputs["Geometry"], group_out.inputs[0])

    return scene, realize


def instance_attributes_scene():
    """Instance on Points whose rocks take their colour from Attribute
    nodes: "tint" of type Instancer, a random colour per instance stored by
    Geometry Nodes where Python can read it (Blender 4.3 and later), else
    the instancer's custom property of that name (which Cycles reads where
    the instance has no such attribute), times "shade" of type Object, the
    rock's own custom property. Returns the scene and the node storing the
    colours (None before 4.3)."""
    scene, _ = geometry_nodes_scene()
    grid, stone = bpy.data.objects["Scatter"], bpy.data.objects["Stone"]
    grid["tint"] = (0.2, 0.7, 0.4)
    stone["shade"] = 0.9
    tree = grid.modifiers["Scatter"].node_group
    nodes, links = tree.nodes, tree.links
    on_points = next(n for n in nodes if n.type == "INSTANCE_ON_POINTS")
    group_out = next(n for n in nodes if n.type == "GROUP_OUTPUT")
    store = None
    if hasattr(bpy.types, "GeometrySet"):
        store = store_random_colours(nodes, links, on_points, group_out)
    mat = stone.data.materials[0]
    nt = mat.node_tree
    bsdf = next(n for n in nt.nodes if n.type == "BSDF_DIFFUSE")
    tint, shade = nt.nodes.new("ShaderNodeAttribute"), nt.nodes.new("ShaderNodeAttribute")
    tint.attribute_type, tint.attribute_name = "INSTANCER", "tint"
    shade.attribute_type, shade.attribute_name = "OBJECT", "shade"
    times = nt.nodes.new("ShaderNodeVectorMath")
    times.operation = "SCALE"
    nt.links.new(tint.outputs["Color"], times.inputs[0])
    nt.links.new(shade.outputs["Fac"], times.inputs["Scale"])
    nt.links.new(times.outputs[0], bsdf.inputs["Color"])
    return scene, store


def store_random_colours(nodes, links, on_points, group_out):
    """Stores "tint", a random colour per instance, after Instance on Points."""
    store = nodes.new("GeometryNodeStoreNamedAttribute")
    store.data_type, store.domain = "FLOAT_VECTOR", "INSTANCE"
    store.inputs["Name"].default_value = "tint"
    colour = nodes.new("FunctionNodeRandomValue")
    colour.data_type = "FLOAT_VECTOR"
    colour.inputs["Min"].default_value = (0.1, 0.1, 0.1)
    colour.inputs["Max"].default_value = (1.0, 1.0, 1.0)
    links.new(on_points.outputs["Instances"], store.inputs["Geometry"])
    links.new(colour.outputs[0], next(i for i in store.inputs if i.name == "Value" and i.enabled))
    links.new(store.outputs["Geometry"], group_out.inputs[0])
    return store


def particle_scene(collection=False):
    """A particle system on an emitter that renders a rock per particle, or
    (collection) one of a collection's two rocks per particle."""
    scene = base_scene()
    if collection:
        pebbles = bpy.data.collections.new("Pebbles")
        scene.collection.children.link(pebbles)
        for name, color in (("PebbleA", (0.3, 0.5, 0.8)), ("PebbleB", (0.8, 0.7, 0.2))):
            stone = rock(name, color)
            pebbles.objects.link(stone)
            scene.collection.objects.unlink(stone)
        pebbles.instance_offset = (0.0, 0.0, -20.0)  # where the rocks lie, out of view
    else:
        stone = rock("Pebble", (0.3, 0.5, 0.8))
    bpy.ops.mesh.primitive_plane_add(size=8.0, location=(0.0, 0.0, 0.0))
    emitter = bpy.context.object
    emitter.name = "Emitter"
    emitter.show_instancer_for_render = False
    emitter.modifiers.new("Particles", "PARTICLE_SYSTEM")
    settings = emitter.particle_systems[0].settings
    settings.count = 24
    settings.frame_start = settings.frame_end = 1
    settings.physics_type = "NO"
    if collection:
        settings.render_type = "COLLECTION"
        settings.instance_collection = pebbles
    else:
        settings.render_type = "OBJECT"
        settings.instance_object = stone
    settings.particle_size = 0.8
    settings.use_rotations = True
    settings.rotation_factor_random = 1.0

    def make_real():
        bpy.ops.object.select_all(action="DESELECT")
        emitter.select_set(True)
        bpy.context.view_layer.objects.active = emitter
        bpy.ops.object.duplicates_make_real()
        emitter.modifiers.clear()
        emitter.hide_render = True  # as its particle system hid it
        single_users(scene)

    return scene, make_real


def moving_instances_scene():
    """Instance on Points whose instancer slides over the shutter (Render >
    Motion Blur): every instance moves by its own transform at each step."""
    scene, realize = geometry_nodes_scene()
    grid = bpy.data.objects["Scatter"]
    edit = bpy.context.preferences.edit
    interpolation = edit.keyframe_new_interpolation_type
    edit.keyframe_new_interpolation_type = "LINEAR"
    grid.location.x = -0.6
    grid.keyframe_insert("location", frame=1)
    grid.location.x = 0.6
    grid.keyframe_insert("location", frame=3)
    edit.keyframe_new_interpolation_type = interpolation
    r = scene.render
    r.use_motion_blur = True
    r.motion_blur_shutter = 1.0
    owner = r if hasattr(r, "motion_blur_position") else scene.cycles
    owner.motion_blur_position = "CENTER"
    scene.frame_set(2)
    return scene, realize


def nested_collection_scene():
    """Empties instancing a collection whose own objects include an empty
    instancing a second collection: two levels flatten to prototype and
    transform."""
    scene = base_scene()

    def collection_of_rock(name, color):
        collection = bpy.data.collections.new(name)
        scene.collection.children.link(collection)
        obj = rock(f"{name} Rock", color, location=(0.0, 0.0, 0.0))
        for c in obj.users_collection:
            c.objects.unlink(obj)
        collection.objects.link(obj)
        return collection

    inner = collection_of_rock("Inner", (0.2, 0.7, 0.3))
    outer = collection_of_rock("Outer", (0.7, 0.2, 0.5))
    nested = bpy.data.objects.new("Nested", None)
    nested.instance_type = "COLLECTION"
    nested.instance_collection = inner
    nested.location = (0.9, 0.0, 0.3)
    nested.scale = (0.6, 0.6, 0.6)
    outer.objects.link(nested)
    # The collections themselves stay out of the render; only their instances show.
    scene.view_layers[0].layer_collection.children["Inner"].exclude = True
    scene.view_layers[0].layer_collection.children["Outer"].exclude = True
    empties = []
    for k, (x, y, angle) in enumerate(((-3.0, -1.0, 0.3), (0.0, 2.0, 1.2), (3.0, -0.5, 2.0))):
        e = bpy.data.objects.new(f"Place{k}", None)
        e.instance_type = "COLLECTION"
        e.instance_collection = outer
        e.location = (x, y, 0.0)
        e.rotation_euler = (0.0, 0.0, angle)
        scene.collection.objects.link(e)
        empties.append(e)

    def make_real():
        bpy.ops.object.select_all(action="DESELECT")
        for e in empties:
            e.select_set(True)
        bpy.context.view_layer.objects.active = empties[0]
        bpy.ops.object.duplicates_make_real(use_base_parent=False, use_hierarchy=False)
        # Made real, the nested empties instance the inner collection still.
        for obj in list(bpy.context.view_layer.objects):
            if obj.type == "EMPTY" and obj.instance_type == "COLLECTION" and obj.name.startswith("Nested"):
                bpy.ops.object.select_all(action="DESELECT")
                obj.select_set(True)
                bpy.context.view_layer.objects.active = obj
                bpy.ops.object.duplicates_make_real()
        single_users(scene)

    return scene, make_real


def linked_duplicates_scene():
    """Three objects sharing one subdivided, displaced mesh (linked
    duplicates, Alt+D), placed and sized apart."""
    scene = base_scene()
    first = displaced_rock("Shared", (0.4, 0.6, 0.7))
    objects = [first]
    for k in range(1, 3):
        dup = first.copy()  # a new object, the same mesh
        scene.collection.objects.link(dup)
        objects.append(dup)
    for k, obj in enumerate(objects):
        obj.location = (-2.5 + 2.5 * k, 0.5 * k, 0.0)
        obj.scale = (1.0 + 0.3 * k,) * 3
        obj.rotation_euler = (0.2 * k, 0.0, 0.7 * k)

    def make_single():
        for obj in objects[1:]:
            obj.data = obj.data.copy()

    return scene, make_single


def main():
    scene, realize = geometry_nodes_scene()
    # Exported as RIB (ObjectBegin, ObjectInstance), rendered by the CLI:
    # the image F12 makes.
    diff = ru.rib_against_f12(scene, W, H, 4, ["ObjectBegin", "ObjectInstance"], transparent=True)
    if diff is not None:
        check("Geometry Nodes Instance on Points: the RIB renders like F12", diff <= 1.0 / 255.0 + 1e-6,
              f"largest difference {diff * 255:.1f} / 255")
    compare("Geometry Nodes Instance on Points", scene, realize, prototypes=1, instances=16)
    scene, make_real = particle_scene()
    compare("particle system of objects", scene, make_real, prototypes=1, instances=24)
    scene, make_real = particle_scene(collection=True)
    compare("particle system of a collection", scene, make_real, prototypes=2, instances=24)
    scene, realize = moving_instances_scene()
    blurred = ru.render_passes(scene, "MICROPOLY", W, H, samples=4)["rgba"]
    scene.render.use_motion_blur = False
    still = ru.render_passes(scene, "MICROPOLY", W, H, samples=4)["rgba"]
    scene.render.use_motion_blur = True
    p = ru.psnr(blurred[..., :3], still[..., :3], peak=1.0)
    check("moving instances: the shutter blurs them", p < 35.0, f"{p:.1f} dB against the still frame")
    compare("moving instances (motion blur)", scene, realize, prototypes=1, instances=16)
    scene, make_real = nested_collection_scene()
    compare("nested collection instances", scene, make_real, prototypes=2, instances=6)
    scene, make_single = linked_duplicates_scene()
    compare("linked duplicates", scene, make_single, prototypes=1, instances=3)
    # Attribute nodes of type Instancer and Object: against Cycles; and
    # where Geometry Nodes store a colour per instance, the rocks' colours
    # spread far wider than with the instancer's one colour.
    scene, store = instance_attributes_scene()
    against_cycles("instance attributes", scene)
    if store is not None:
        spreads = []
        for mute in (False, True):
            store.mute = mute
            got = ru.render_passes(scene, "MICROPOLY", W, H, samples=4)["rgba"]
            rocks = got[(got[..., 3] > 0.999) & (np.abs(got[..., 0] - got[..., 2]) > 0.02)][:, :3]
            share = rocks[:, 0] / np.maximum(rocks.sum(axis=1), 1e-6)
            spreads.append(float(np.std(share)) if len(rocks) > 500 else 0.0)
        check("instance attributes: each instance its own colour", spreads[0] > 2.0 * spreads[1] > 0.0,
              f"spread of red's share {spreads[0]:.3f}, with the instancer's one colour {spreads[1]:.3f}")
    # Made real by Realize Instances, the rocks would be the modifier's
    # polygons: compared with Cycles only.
    scene, _ = geometry_nodes_scene(displaced=True)
    got = exported_counts(scene)
    check("subdivided, displaced rocks: exported as prototypes and instances", got[:2] == (1, 16), f"{got}")
    against_cycles("subdivided, displaced rocks", scene)
    return 0 if all(RESULTS) else 1


ru.run_test(main)
