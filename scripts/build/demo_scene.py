"""Builds the demo scene in Blender and renders it with Micropoly.

  BLENDER_USER_SCRIPTS=build/install blender -b --factory-startup --addons micropoly \
      --python scripts/build/demo_scene.py -- OUT.png
"""

import math
import os
import sys

import bpy

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
out = args[0] if args else "demo.png"
check = "--check" in args
# --no-render: build the scene and stop (the tests render it themselves).
render = "--no-render" not in args

bpy.ops.wm.read_factory_settings(use_empty=True)
import addon_utils  # noqa: E402

# The add-on's module: "micropoly" as a legacy add-on (the developer build),
# "bl_ext.user_default.micropoly" once installed from the extension zip.
addon_utils.enable(os.environ.get("MICROPOLY_ADDON_MODULE", "micropoly"), default_set=True)
scene = bpy.context.scene


def material(name, color):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    m.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*color, 1.0)
    return m


bpy.ops.mesh.primitive_monkey_add(size=1.6, location=(0.0, 0.0, 1.0), rotation=(0.0, 0.0, math.radians(40)))
monkey = bpy.context.object
monkey.modifiers.new("Subdivision", "SUBSURF").render_levels = 2
monkey.data.materials.append(material("Clay", (0.8, 0.35, 0.2)))

bpy.ops.mesh.primitive_torus_add(location=(2.2, 0.8, 0.35), major_radius=0.7, minor_radius=0.3)
torus = bpy.context.object
torus.modifiers.new("Subdivision", "SUBSURF").render_levels = 2
torus.data.materials.append(material("Teal", (0.1, 0.5, 0.55)))

bpy.ops.mesh.primitive_plane_add(size=12.0)
bpy.context.object.data.materials.append(material("Floor", (0.6, 0.6, 0.6)))

# Both lights cast shadows (Blender's default); their sizes soften them.
bpy.ops.object.light_add(type="SUN", rotation=(math.radians(40), math.radians(15), math.radians(30)))
bpy.context.object.data.energy = 3.0
bpy.context.object.data.angle = math.radians(3.0)
bpy.ops.object.light_add(type="POINT", location=(-3.0, -3.0, 4.0))
bpy.context.object.data.energy = 800.0
bpy.context.object.data.shadow_soft_size = 0.3

bpy.ops.object.camera_add(location=(5.5, -6.5, 4.0))
cam = bpy.context.object
direction = cam.location - __import__("mathutils").Vector((0.6, 0.2, 0.8))
cam.rotation_euler = direction.to_track_quat("Z", "Y").to_euler()
scene.camera = cam

world = bpy.data.worlds.new("World")
world.color = (0.05, 0.06, 0.08)
scene.world = world
scene.render.engine = "MICROPOLY"
scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 960, 540, 100
scene.render.film_transparent = False
scene.render.filepath = out
scene.render.image_settings.file_format = "PNG"
if render:
    bpy.ops.render.render(write_still=True)
    print(f"wrote {out}")

if check and render:
    # Used by the test suite: the render reached the file and shows the objects.
    import numpy as np

    image = bpy.data.images.load(bpy.path.abspath(out))
    px = np.array(image.pixels[:], dtype=np.float32).reshape(image.size[1], image.size[0], 4)
    background = np.all(np.abs(px[..., :3] - px[-1, -1, :3]) < 0.02, axis=-1)  # 8-bit output is dithered
    covered = 1.0 - background.mean()
    print(f"covered fraction {covered:.3f}")
    if image.size[:] != (960, 540) or covered < 0.3:
        sys.exit(1)
