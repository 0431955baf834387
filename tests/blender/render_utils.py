"""Helpers for blender -b tests: build scenes, render with an engine, read
float passes back (through the compositor's File Output node, which works the
same in Blender 3.4 and 4.x)."""

import math
import os
import tempfile
from collections import deque

import bpy
import numpy as np
from mathutils import Vector

import cycles_references


def enable_addon():
    """Registers the add-on from MICROPOLY_ADDON_DIR (the build tree's addons/)."""
    import sys

    folder = os.environ.get("MICROPOLY_ADDON_DIR")
    if folder and folder not in sys.path:
        sys.path.insert(0, folder)
    import micropoly

    if hasattr(bpy.types.Scene, "micropoly"):
        return  # still registered (opening a file keeps registered classes)
    micropoly.register()


def run_test(main):
    """Runs main() (returning an exit status) and exits with it. An exception
    is a failure. In background mode the process leaves at once, without
    exit handlers: the bpy module can hang in them after renders."""
    import sys
    import traceback

    try:
        code = main()
    except Exception:
        traceback.print_exc()
        code = 1
    sys.stdout.flush()
    if bpy.app.background:
        os._exit(code)
    sys.exit(code)


def verdict(failures, ok):
    """A test's exit status: 1 after printing its failures, else 0 after
    printing `ok`."""
    if failures:
        print("FAIL: " + "; ".join(failures))
        return 1
    print("OK: " + ok)
    return 0


def reset_scene():
    """A fresh, empty scene with the add-on registered and a black world.
    The add-on stays registered from one scene to the next, as in an
    artist's session: its final renderer keeps its device, programs and the
    shadow pages of geometry that did not change."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    enable_addon()
    scene = bpy.context.scene
    world = bpy.data.worlds.new("World")
    world.color = (0.0, 0.0, 0.0)
    # Blender 5.0 gives a new world a node tree with a grey Background.
    if world.use_nodes and world.node_tree is not None:
        for node in world.node_tree.nodes:
            if node.type == "BACKGROUND":
                node.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    scene.world = world
    return scene


def add_camera(scene, location, target, lens=50.0, ortho_scale=None, shift=(0.0, 0.0)):
    cam_data = bpy.data.cameras.new("Camera")
    cam_data.lens = lens
    cam_data.shift_x, cam_data.shift_y = shift
    if ortho_scale is not None:
        cam_data.type = "ORTHO"
        cam_data.ortho_scale = ortho_scale
    cam = bpy.data.objects.new("Camera", cam_data)
    scene.collection.objects.link(cam)
    cam.location = location
    cam.rotation_euler = (Vector(location) - Vector(target)).to_track_quat("Z", "Y").to_euler()
    scene.camera = cam
    return cam


def add_tile(scene, name, mesh, row, col, rows, cols, tile=2.0):
    """Links an object of `mesh` into the scene at tile (row, col) of a
    rows x cols grid of `tile`-wide cells centred on the origin in the xy
    plane (row 0 at the top, +y), scaled to leave a gap between tiles."""
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    obj.location = ((col + 0.5) * tile - cols * tile / 2.0, rows * tile / 2.0 - (row + 0.5) * tile, 0.0)
    obj.scale = (0.45 * tile, 0.45 * tile, 1.0)
    return obj


def add_sun(scene, rotation, energy=3.0):
    """A sun light of strength `energy` turned by Euler angles `rotation`."""
    data = bpy.data.lights.new("Sun", "SUN")
    data.energy = energy
    obj = bpy.data.objects.new("Sun", data)
    obj.rotation_euler = rotation
    scene.collection.objects.link(obj)
    return obj


def empty_material(name):
    """A node material holding only its Material Output; returns (material, output node)."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes = m.node_tree.nodes
    for n in list(nodes):
        if n.type != "OUTPUT_MATERIAL":
            nodes.remove(n)
    return m, next(n for n in nodes if n.type == "OUTPUT_MATERIAL")


def emission_material(name):
    """A node material whose surface is an Emission shader of strength 1;
    returns (material, emission node) for the test to link its colour."""
    m, out = empty_material(name)
    emission = m.node_tree.nodes.new("ShaderNodeEmission")
    emission.inputs["Strength"].default_value = 1.0
    m.node_tree.links.new(emission.outputs["Emission"], out.inputs["Surface"])
    return m, emission


def diffuse_material(name, color):
    m, _ = empty_material(name)
    nodes = m.node_tree.nodes
    bsdf = nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (*color, 1.0)
    out = next(n for n in nodes if n.type == "OUTPUT_MATERIAL")
    m.node_tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return m


def principled_material(name, color, roughness):
    m, _ = empty_material(name)
    nodes = m.node_tree.nodes
    bsdf = nodes.new("ShaderNodeBsdfPrincipled")
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    out = next(n for n in nodes if n.type == "OUTPUT_MATERIAL")
    m.node_tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return m


def shade_smooth(obj):
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.shade_smooth()


def add_suzanne_torus_floor(material):
    """The world-lighting scene (tests/blender/test_world.py, bench/world_bench.py):
    a floor, Suzanne and a torus with Subdivision Surface, smooth shaded;
    material(name, color) makes each one's material."""
    bpy.ops.mesh.primitive_plane_add(size=8.0)
    bpy.context.object.data.materials.append(material("Floor", (0.6, 0.6, 0.6)))
    bpy.ops.mesh.primitive_monkey_add(location=(-0.8, 0.0, 0.75), rotation=(0.5, 0.0, 0.3))
    monkey = bpy.context.object
    bpy.ops.mesh.primitive_torus_add(location=(1.1, 0.3, 0.35), major_radius=0.6, minor_radius=0.25)
    torus = bpy.context.object
    for obj, color in ((monkey, (0.8, 0.5, 0.3)), (torus, (0.3, 0.5, 0.8))):
        obj.modifiers.new("Subdivision", "SUBSURF").render_levels = 2
        obj.data.materials.append(material(obj.name, color))
        shade_smooth(obj)


def add_displacement(mat, height, strength, midlevel=0.5):
    """Displaces the node material `mat` along its normal by the output
    socket `height` through a Displacement node of `strength` (Displacement
    Only, in every version)."""
    nt = mat.node_tree
    disp = nt.nodes.new("ShaderNodeDisplacement")
    disp.inputs["Scale"].default_value = strength
    disp.inputs["Midlevel"].default_value = midlevel
    nt.links.new(height, disp.inputs["Height"])
    out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
    nt.links.new(disp.outputs["Displacement"], out.inputs["Displacement"])
    if hasattr(mat, "displacement_method"):
        mat.displacement_method = "DISPLACEMENT"
    else:
        mat.cycles.displacement_method = "DISPLACEMENT"
    return mat


def add_noise_displacement(mat, scale, strength, detail=None):
    """Displaces `mat` by a Noise texture of `scale` (add_displacement)."""
    noise = mat.node_tree.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = scale
    if detail is not None:
        noise.inputs["Detail"].default_value = detail
    return add_displacement(mat, noise.outputs["Fac"], strength)


def add_aimed_light(scene, kind, location, target, energy, **props):
    """A light of `kind` at `location` aimed at `target`, of radius 0 unless
    `props` (light data attributes) say otherwise."""
    from mathutils import Vector

    data = bpy.data.lights.new(kind.lower(), kind)
    data.energy = energy
    if hasattr(data, "shadow_soft_size"):
        data.shadow_soft_size = 0.0
    for k, v in props.items():
        setattr(data, k, v)
    obj = bpy.data.objects.new(kind.lower(), data)
    scene.collection.objects.link(obj)
    obj.location = location
    obj.rotation_euler = (Vector(location) - Vector(target)).to_track_quat("Z", "Y").to_euler()
    return obj


def png_image(name, rgba, colorspace):
    """Writes rgba ((h, w, 4) in [0, 1], rows bottom to top) as an 8-bit PNG
    in a temporary folder and loads it back, as an artist's image file would
    be."""
    folder = tempfile.mkdtemp(prefix="micropoly_images_")
    h, w = rgba.shape[:2]
    img = bpy.data.images.new(name + "_src", w, h, alpha=True)
    img.pixels.foreach_set(np.ascontiguousarray(rgba, dtype=np.float32).reshape(-1))
    path = os.path.join(folder, name + ".png")
    img.filepath_raw = path
    img.file_format = "PNG"
    img.save()
    bpy.data.images.remove(img)
    loaded = bpy.data.images.load(path)
    loaded.colorspace_settings.name = colorspace
    return loaded


def set_cast_shadow(light, on):
    """A light's Cast Shadow toggle, as each Blender version names it for
    Cycles (light.cycles.cast_shadow in 3.x, light.use_shadow from 4.0; in
    3.x use_shadow is EEVEE's, so both are set)."""
    if hasattr(light, "cycles") and hasattr(light.cycles, "cast_shadow"):
        light.cycles.cast_shadow = on
    if hasattr(light, "use_shadow"):
        light.use_shadow = on


def save_png(path, rows):
    """Writes an (h, w, 3 or 4) float image, rows top first, values in
    [0, 1] (display-ready), as an 8-bit PNG: for looking at test renders."""
    h, w = rows.shape[:2]
    rgba = np.ones((h, w, 4), dtype=np.float32)
    rgba[..., :rows.shape[2]] = np.clip(rows[..., :4], 0.0, 1.0)
    img = bpy.data.images.new("save_png", w, h, alpha=True)
    img.pixels.foreach_set(np.ascontiguousarray(rgba[::-1]).reshape(-1))
    img.filepath_raw = path
    img.file_format = "PNG"
    img.save()
    bpy.data.images.remove(img)


def setup_cycles(scene, samples=64, adaptive_subdivision=True, shadows=False):
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = samples
    if hasattr(c, "use_adaptive_sampling"):
        c.use_adaptive_sampling = False
    if hasattr(c, "use_denoising"):
        c.use_denoising = False
    c.max_bounces = 0
    c.diffuse_bounces = 0
    c.glossy_bounces = 0
    c.transmission_bounces = 0
    if adaptive_subdivision:
        # Blender 3.x/4.x: experimental feature set and a per-object switch;
        # 5.0: a setting of the Subdivision Surface modifier itself.
        if hasattr(c, "feature_set"):
            c.feature_set = "EXPERIMENTAL"
        c.dicing_rate = 1.0
        for obj in scene.objects:
            if obj.type == "MESH" and obj.modifiers and obj.modifiers[-1].type == "SUBSURF":
                mod = obj.modifiers[-1]
                if hasattr(mod, "use_adaptive_subdivision"):
                    mod.use_adaptive_subdivision = True
                    mod.adaptive_space = "PIXEL"
                    mod.adaptive_pixel_size = 1.0
                elif hasattr(obj, "cycles") and hasattr(obj.cycles, "use_adaptive_subdivision"):
                    obj.cycles.use_adaptive_subdivision = True
    # Lights cast shadows only where a test asks for them; Micropoly reads
    # the same toggle, so both renderers agree on it.
    for obj in scene.objects:
        if obj.type == "LIGHT":
            set_cast_shadow(obj.data, shadows)


def _load_exr(path, height, width):
    image = bpy.data.images.load(path)
    px = np.array(image.pixels[:], dtype=np.float32).reshape(height, width, 4)[::-1]
    bpy.data.images.remove(image)
    return px


def render_passes(scene, engine, width, height, samples=16, transparent=True, cycles_data=False, stored=True):
    """Renders and returns dict(rgba=(H,W,4), depth=(H,W), normal=(H,W,3)),
    rows top first, as float arrays. Blender 5.0 replaced the compositor's
    scene node tree; there only rgba is read back (depth and normal are None).
    Cycles' depth and normal are kept (with its stored reference) only where
    a test asks for them with cycles_data; otherwise they are None.
    stored=False renders Cycles now, neither reading nor storing a reference:
    for scenes whose geometry Blender makes anew in each session (particle
    hair's children, which its threads place in a different order each
    time)."""
    scene.render.engine = engine
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = transparent
    if engine == "MICROPOLY":
        scene.micropoly.samples = samples
    view_layer = scene.view_layers[0]
    view_layer.use_pass_z = True
    view_layer.use_pass_normal = True
    scene.display_settings.display_device = "sRGB"
    scene.view_settings.view_transform = "Standard"
    reference = None
    if engine == "CYCLES" and stored:
        # Cycles' passes are rendered once per scene and Blender version
        # and kept with the tests (cycles_references.py).
        reference = cycles_references.Reference(scene, width, height, transparent)
        stored = reference.load()
        if stored is not None:
            return stored
    result = _render_passes(scene, engine, width, height)
    if engine == "CYCLES" and not stored and not cycles_data:
        result["depth"] = result["normal"] = None
    if reference is not None:
        if not cycles_data:
            result["depth"] = result["normal"] = None
        result = cycles_references.as_stored(result)
        reference.store(result)
    return result


def _render_passes(scene, engine, width, height):
    folder = tempfile.mkdtemp(prefix=f"mp-{engine.lower()}-")
    if not hasattr(scene, "node_tree"):
        scene.render.image_settings.file_format = "OPEN_EXR"
        scene.render.image_settings.color_depth = "32"
        scene.render.filepath = os.path.join(folder, "combined.exr")
        bpy.ops.render.render(write_still=True)
        return {"rgba": _load_exr(scene.render.filepath, height, width), "depth": None, "normal": None}
    scene.use_nodes = True
    tree = scene.node_tree
    for n in list(tree.nodes):
        tree.nodes.remove(n)
    layers = tree.nodes.new("CompositorNodeRLayers")
    composite = tree.nodes.new("CompositorNodeComposite")
    tree.links.new(layers.outputs["Image"], composite.inputs["Image"])
    out = tree.nodes.new("CompositorNodeOutputFile")
    out.base_path = folder
    out.format.file_format = "OPEN_EXR"
    out.format.color_depth = "32"
    out.file_slots.clear()
    for name in ("Image", "Depth", "Normal"):
        out.file_slots.new(name)
        tree.links.new(layers.outputs[name], out.inputs[name])
    bpy.ops.render.render(write_still=False)
    frame = scene.frame_current
    result = {}
    for name, key, channels in (("Image", "rgba", 4), ("Depth", "depth", 1), ("Normal", "normal", 3)):
        px = _load_exr(os.path.join(folder, f"{name}{frame:04d}.exr"), height, width)
        result[key] = px[..., :channels] if channels > 1 else px[..., 0]
    return result


def motion_blur(scene, shutter=1.0):
    """Render > Motion Blur on, a shutter of `shutter` frames centred on the
    frame, and keyframes inserted from now on linear (both renderers read
    the same settings)."""
    r = scene.render
    r.use_motion_blur = True
    r.motion_blur_shutter = shutter
    (r if hasattr(r, "motion_blur_position") else scene.cycles).motion_blur_position = "CENTER"
    bpy.context.preferences.edit.keyframe_new_interpolation_type = "LINEAR"


def blurred_psnr(ref, got):
    """(PSNR, pixels) of two motion-blurred RGBA images: few pixels are
    wholly covered, so colour (premultiplied) and alpha are compared
    wherever either image has any."""
    seen = (ref[..., 3] > 0.01) | (got[..., 3] > 0.01)
    return psnr(ref[seen], got[seen], peak=float(ref[seen].max())), int(seen.sum())


def iou(a, b, threshold=0.5):
    ma, mb = a > threshold, b > threshold
    union = np.logical_or(ma, mb).sum()
    return 1.0 if union == 0 else np.logical_and(ma, mb).sum() / union


def psnr(a, b, peak=None):
    mse = float(np.mean((a - b) ** 2))
    peak = float(max(a.max(), b.max())) if peak is None else peak
    return math.inf if mse == 0 else 10.0 * math.log10(peak * peak / mse)


def masked_psnr(ours, ref, mask):
    """PSNR of ours against ref (RGBA images) on the mask's pixels, RGB,
    with the reference's largest value there as peak; and the largest
    absolute difference."""
    a, b = ours[mask][:, :3], ref[mask][:, :3]
    peak = max(float(np.abs(b).max()), 1e-3)
    return psnr(a, b, peak=peak), float(np.abs(a - b).max())


def covered_interior(a, b, margin=2):
    """Pixels fully covered in both RGBA images and at least `margin` pixels
    from any pixel that is not (where the two renderers' edges differ)."""
    inside = (a[..., 3] > 0.999) & (b[..., 3] > 0.999)
    interior = inside.copy()
    for axis in (0, 1):
        for shift in range(1, margin + 1):
            interior &= np.roll(inside, shift, axis=axis) & np.roll(inside, -shift, axis=axis)
    return interior


def pinholes(rgba, depth):
    """Pixels of crack regions: connected not-fully-covered regions that stay
    2 pixels off the frame's edge, hold fewer than 12 uncovered pixels and are
    not seen past a silhouette (covered pixels around them within 10% in
    depth). Same rule as tests/native/test_watertight.cpp."""
    alpha = rgba[..., 3]
    h, w = alpha.shape
    full = alpha >= 1.0 - 1e-3
    seen = np.zeros_like(full)
    count = 0
    for y0, x0 in zip(*np.nonzero(~full)):
        if seen[y0, x0]:
            continue
        seen[y0, x0] = True
        q = deque([(y0, x0)])
        size = uncovered = 0
        edge = False
        dmin, dmax = math.inf, 0.0
        while q:
            y, x = q.popleft()
            size += 1
            edge |= x < 2 or y < 2 or x >= w - 2 or y >= h - 2
            uncovered += alpha[y, x] < 1e-3
            for yy in range(max(y - 1, 0), min(y + 2, h)):
                for xx in range(max(x - 1, 0), min(x + 2, w)):
                    if full[yy, xx]:
                        dmin, dmax = min(dmin, depth[yy, xx]), max(dmax, depth[yy, xx])
                    elif not seen[yy, xx]:
                        seen[yy, xx] = True
                        q.append((yy, xx))
        if not (edge or uncovered >= 12 or dmax > 1.1 * dmin):
            count += size
    return count, int(full.sum())


def ramp_width(alpha):
    """Median over the middle rows of the distance from 5% to 95% alpha along
    the row (the first crossing of each from the left, interpolated)."""
    h = alpha.shape[0]
    widths = []
    for row in alpha[h // 4: 3 * h // 4]:
        row = np.convolve(row, np.ones(3) / 3.0, mode="same")  # tame sample noise

        def crossing(level):
            i = int(np.argmax(row >= level))
            if i == 0:
                return None
            return i - 1 + (level - row[i - 1]) / max(row[i] - row[i - 1], 1e-6)

        lo, hi = crossing(0.05), crossing(0.95)
        if lo is not None and hi is not None:
            widths.append(hi - lo)
    return float(np.median(widths)) if widths else float("nan")


def save_side_by_side(folder, name, cycles, micro):
    """Cycles, Micropoly and their difference x4 side by side in
    folder/name.png (nothing without a folder)."""
    if not folder:
        return
    os.makedirs(folder, exist_ok=True)
    diff = np.abs(cycles[..., :3] - micro[..., :3]) * 4.0
    row = np.concatenate([cycles[..., :3], micro[..., :3], diff], axis=1)
    save_png(os.path.join(folder, name + ".png"), np.power(np.clip(row, 0, 1), 1 / 2.2))


def rib_against_f12(scene, width, height, samples, must_contain, transparent=False):
    """Renders `scene` with F12 (8-bit PNG), exports it as RIB (checking
    that the file holds `must_contain`), renders that with micropoly-render
    and returns the largest difference of the two images (0..1), or None
    when MICROPOLY_CLI is not set."""
    import subprocess

    cli = os.environ.get("MICROPOLY_CLI")
    if not cli:
        print("skip RIB: MICROPOLY_CLI is not set")
        return None
    from micropoly import operators
    folder = tempfile.mkdtemp(prefix="mp-rib-")
    r = scene.render
    r.engine = "MICROPOLY"
    r.resolution_x, r.resolution_y, r.resolution_percentage = width, height, 100
    r.film_transparent = transparent
    r.dither_intensity = 0.0
    r.image_settings.file_format = "PNG"
    r.image_settings.color_mode = "RGBA"
    r.image_settings.color_depth = "8"
    scene.view_settings.view_transform = "Standard"
    scene.micropoly.samples = samples
    r.filepath = os.path.join(folder, "f12.png")
    bpy.ops.render.render(write_still=True)
    rib, png = os.path.join(folder, "scene.rib"), os.path.join(folder, "cli.png")
    operators.export_rib(bpy.context.evaluated_depsgraph_get(), rib)
    text = open(rib).read()
    for needle in must_contain:
        assert needle in text, f"the RIB should hold {needle!r}"
    proc = subprocess.run([cli, rib, "-o", png], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    a, b = bpy.data.images.load(r.filepath), bpy.data.images.load(png)
    assert tuple(a.size) == tuple(b.size) == (width, height), (tuple(a.size), tuple(b.size))
    pa = np.array(a.pixels[:], dtype=np.float32).reshape(-1, 4)
    pb = np.array(b.pixels[:], dtype=np.float32).reshape(-1, 4)
    return float(np.abs(pa - pb).max())


def f12_seconds(scene):
    """Wall time of one F12 render of `scene` (its engine as set)."""
    import time

    started = time.perf_counter()
    bpy.ops.render.render()
    return time.perf_counter() - started


def write_bench_rib(scene, name):
    """`scene` rendered by Micropoly, as RIB in bench/out/<name>.rib (for the
    CLI's benchmarks on PoCL and on a GPU)."""
    enable_addon()
    from micropoly import operators

    folder = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bench", "out")
    os.makedirs(folder, exist_ok=True)
    scene.render.engine = "MICROPOLY"
    path = os.path.abspath(os.path.join(folder, name + ".rib"))
    operators.export_rib(bpy.context.evaluated_depsgraph_get(), path)
    print(f"wrote {path}")


def scatter_instances(grid, obj, scale_range=None):
    """A Geometry Nodes modifier on `grid` placing `obj` (as an instance) on
    each of its vertices, turned about Z by a random angle and, with
    scale_range (min, max), scaled at random. Returns the node tree, its
    Instance on Points node and its group output."""
    mod = grid.modifiers.new("Scatter", "NODES")
    tree = bpy.data.node_groups.new("Scatter", "GeometryNodeTree")
    mod.node_group = tree
    nodes, links = tree.nodes, tree.links
    if hasattr(tree, "interface"):  # Blender 4.0 and later
        tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
        tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    else:
        tree.inputs.new("NodeSocketGeometry", "Geometry")
        tree.outputs.new("NodeSocketGeometry", "Geometry")
    group_in, group_out = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    info = nodes.new("GeometryNodeObjectInfo")
    info.inputs["Object"].default_value = obj
    info.transform_space = "ORIGINAL"
    if "As Instance" in info.inputs:
        info.inputs["As Instance"].default_value = True
    on_points = nodes.new("GeometryNodeInstanceOnPoints")
    rotation = nodes.new("FunctionNodeRandomValue")
    rotation.data_type = "FLOAT_VECTOR"
    rotation.inputs["Max"].default_value = (0.0, 0.0, 6.0)
    links.new(group_in.outputs[0], on_points.inputs["Points"])
    links.new(info.outputs["Geometry"], on_points.inputs["Instance"])
    links.new(rotation.outputs[0], on_points.inputs["Rotation"])
    if scale_range is not None:
        scale = nodes.new("FunctionNodeRandomValue")
        scale.data_type = "FLOAT"
        scale.inputs[2].default_value, scale.inputs[3].default_value = scale_range  # Min, Max (float)
        links.new(scale.outputs[1], on_points.inputs["Scale"])
    links.new(on_points.outputs["Instances"], group_out.inputs[0])
    return tree, on_points, group_out
