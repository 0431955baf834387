"""The soak tests' scene (tests/soak/soak_f12.py, soak_viewport.py): what a
production frame holds, on a small image. Subdivision Surface on Suzanne and
a torus (render levels 2), noise displacement on the torus, an image texture
(a 64 x 64 checker PNG) on the floor, a Noise texture on Suzanne, a ball with
a plain Principled material, a sun with shadow maps on, and Suzanne's
rotation keyed over frames 1-50."""

import math

import bpy
import numpy as np

import render_utils as ru


def build_scene(width, height, samples):
    scene = ru.reset_scene()
    scene.world.color = (0.05, 0.06, 0.08)
    # The plain world lights through probe suns, each a shadow view that an
    # edit renders again; four keep that path in the soak at a quarter of
    # the default sixteen's views (the soaks measure memory, not light).
    scene.micropoly.world_shadow_directions = 4
    checker = np.zeros((64, 64, 4), dtype=np.float32)
    checker[..., 3] = 1.0
    cells = ((np.arange(64)[:, None] // 8 + np.arange(64)[None, :] // 8) % 2).astype(np.float32)
    checker[..., 0] = 0.2 + 0.6 * cells
    checker[..., 1] = 0.3 + 0.4 * cells
    checker[..., 2] = 0.6 - 0.3 * cells
    image = ru.png_image("soak_checker", checker, "sRGB")

    def material(name, color):
        m = ru.principled_material(name, color, 0.5)
        nt = m.node_tree
        bsdf = next(n for n in nt.nodes if n.type == "BSDF_PRINCIPLED")
        if name == "Floor":
            tex = nt.nodes.new("ShaderNodeTexImage")
            tex.image = image
            nt.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
        elif name.startswith("Suzanne"):
            noise = nt.nodes.new("ShaderNodeTexNoise")
            noise.inputs["Scale"].default_value = 6.0
            nt.links.new(noise.outputs["Color"], bsdf.inputs["Base Color"])
        elif name.startswith("Torus"):
            ru.add_noise_displacement(m, scale=4.0, strength=0.08)
        return m

    ru.add_suzanne_torus_floor(material)
    # A plain Principled material is sent as parameters, not as a program:
    # editing its values rebuilds nothing.
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.35, location=(0.4, -1.2, 0.35))
    bpy.context.object.name = "Ball"
    bpy.context.object.data.materials.append(ru.principled_material("Plain", (0.7, 0.7, 0.2), 0.4))
    sun = ru.add_sun(scene, (math.radians(40), math.radians(15), math.radians(30)))
    ru.set_cast_shadow(sun.data, True)
    ru.add_camera(scene, (4.5, -5.5, 3.5), (0.1, 0.1, 0.5), lens=50.0)
    scene.render.engine = "MICROPOLY"
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = width, height, 100
    r.film_transparent = False
    scene.micropoly.samples = scene.micropoly.viewport_samples = samples
    scene.micropoly.use_shadows = True
    # Suzanne turns between frames 1 and 50, so that a frame change is an edit.
    suzanne = bpy.data.objects["Suzanne"]
    suzanne.keyframe_insert("rotation_euler", frame=1)
    suzanne.rotation_euler.z += 1.0
    suzanne.keyframe_insert("rotation_euler", frame=50)
    scene.frame_set(1)
    scene.display_settings.display_device = "sRGB"
    scene.view_settings.view_transform = "Standard"
    return scene
