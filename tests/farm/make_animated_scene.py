"""Builds a small animated Micropoly scene for the farm tests and saves it.

  BLENDER_USER_SCRIPTS=build/install blender -b --factory-startup \
      --python tests/farm/make_animated_scene.py -- OUT.blend [--frames N]

A subdivided Suzanne turns and moves across a floor over frames 1..N (8 by
default) under a sun, so every frame differs from the others: a frame written
under the wrong number, or rendered at the wrong time, does not match the
reference render of its number.
"""

import math
import os
import sys

import bpy

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if not args:
    print("usage: blender -b --python make_animated_scene.py -- OUT.blend [--frames N]", file=sys.stderr)
    sys.exit(2)
out = os.path.abspath(args[0])
frames = int(args[args.index("--frames") + 1]) if "--frames" in args else 8

bpy.ops.wm.read_factory_settings(use_empty=True)
import addon_utils  # noqa: E402

# The scene stores the engine by name and the Micropoly settings as
# scene.micropoly; both need the add-on registered while the scene is built.
addon_utils.enable("micropoly", default_set=True)
if not hasattr(bpy.types.Scene, "micropoly"):
    print("the micropoly add-on did not register (is BLENDER_USER_SCRIPTS set?)", file=sys.stderr)
    sys.exit(1)

scene = bpy.context.scene


def material(name, color):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    m.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*color, 1.0)
    return m


bpy.ops.mesh.primitive_monkey_add(size=1.4, location=(0.0, 0.0, 0.9))
monkey = bpy.context.object
monkey.modifiers.new("Subdivision", "SUBSURF").render_levels = 1
monkey.data.materials.append(material("Clay", (0.8, 0.35, 0.2)))

# Keyframes at the first and last frame; Blender's default Bezier easing
# still gives each frame in between its own pose.
scene.frame_start, scene.frame_end = 1, frames
monkey.location = (-1.2, 0.0, 0.9)
monkey.rotation_euler = (0.0, 0.0, math.radians(-50))
monkey.keyframe_insert("location", frame=1)
monkey.keyframe_insert("rotation_euler", frame=1)
monkey.location = (1.2, 0.4, 1.1)
monkey.rotation_euler = (math.radians(15), 0.0, math.radians(60))
monkey.keyframe_insert("location", frame=frames)
monkey.keyframe_insert("rotation_euler", frame=frames)

bpy.ops.mesh.primitive_plane_add(size=10.0)
bpy.context.object.data.materials.append(material("Floor", (0.6, 0.6, 0.6)))

bpy.ops.object.light_add(type="SUN", rotation=(math.radians(40), math.radians(15), math.radians(30)))
bpy.context.object.data.energy = 3.0

bpy.ops.object.camera_add(location=(0.0, -6.5, 3.2))
cam = bpy.context.object
target = __import__("mathutils").Vector((0.0, 0.0, 0.8))
cam.rotation_euler = (cam.location - target).to_track_quat("Z", "Y").to_euler()
scene.camera = cam

world = bpy.data.worlds.new("World")
world.color = (0.05, 0.06, 0.08)
scene.world = world

scene.render.engine = "MICROPOLY"
scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 160, 120, 100
scene.render.film_transparent = False
scene.render.image_settings.file_format = "PNG"
scene.render.image_settings.color_mode = "RGB"
scene.render.image_settings.color_depth = "8"
# Few samples keep each frame to a few seconds on a CPU device; the farm
# test compares renders of the same frame, not against a converged image.
scene.micropoly.samples = 4

bpy.ops.wm.save_as_mainfile(filepath=out)
print(f"wrote {out} (frames {scene.frame_start}-{scene.frame_end})")
