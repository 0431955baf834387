"""Micropoly, Cycles and EEVEE rendering one scene side by side, plus the
export time of a 1M-face mesh. Run with Blender (or a Python with bpy):

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup --python bench/blender_bench.py -- [--repeat 3] [--quick] [--displaced] [--shadows]

Scene: six subdivided Suzannes (Subdivision Surface, rendered by Micropoly as
limit surfaces and by Cycles with adaptive subdivision at 1 px) on a floor,
sun + point + area light, 1920x1080, 16 samples for every engine. Cycles uses
its default light paths with denoising off; EEVEE its defaults with 16 samples.
The lights have Blender's default sizes (sun angle 0.526 degrees, point radius
and area size 0.25 m) and cast shadows in every engine.
Prints the wall time of each F12 render (median of --repeat) and the ratios.

--shadows: the shadow benchmark instead, its renders interleaved round by
round so that the machine's noise falls on all alike: Micropoly with shadows,
Micropoly without, Cycles with shadows and direct light only (the light
Micropoly computes) and Cycles with its default light paths; with the shadow
maps' page counts and memory per light. --rib-only with --shadows writes the
scene as RIB for the CLI (bench/out/shadow_suzannes.rib)."""

import json
import math
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "blender"))

import bpy  # noqa: E402

import render_utils as ru  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
REPEAT = int(args[args.index("--repeat") + 1]) if "--repeat" in args else 3
QUICK = "--quick" in args
# --displaced: every Suzanne's material is displaced by a Noise texture
# (Displacement Only), the issue-5 benchmark scene.
DISPLACED = "--displaced" in args
SHADOWS = "--shadows" in args
# --deep: the Suzannes in five rows one behind the other (30 of them, each
# row hiding most of the next): high depth complexity.
DEEP = "--deep" in args
# --material mix|principled|glass|film: every Suzanne wears a Mix Shader of a
# Diffuse and a Glossy BSDF (factor 0.5), or a Principled BSDF of the same
# colour (the closure benchmark: shade time of two closures against one
# Principled), or a Glass BSDF (IOR 1.45) with a world of a Noise texture
# for it to refract (paths traced through each Suzanne's proxy); film: the
# Principled BSDF with a 450 nm Thin Film (Blender 4.2 and later); subsurface:
# the Principled BSDF at Subsurface Weight 1 (4.x: Cycles' random walk's
# albedo looked up per vertex, kernels/closures/mp_subsurface.h); sheen: the
# Principled BSDF at Sheen Weight 1 (4.x: the microfiber LTC lobe).
MATERIAL = args[args.index("--material") + 1] if "--material" in args else None
# --engines A,B: only these engines (default: Micropoly, Cycles and EEVEE).
# --f12-only: print the F12 times alone (no breakdown, no export timing).
ENGINES = args[args.index("--engines") + 1].split(",") if "--engines" in args else None
W, H = (480, 270) if QUICK else (1920, 1080)
SAMPLES = 16


def bench_material(mat, kind):
    """Replaces the diffuse material's shader by a Mix(Diffuse, Glossy) or a Principled BSDF."""
    nt = mat.node_tree
    out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
    old = out.inputs["Surface"].links[0].from_node
    color = tuple(old.inputs["Color"].default_value)
    nt.nodes.remove(old)
    if kind == "glass":
        g = nt.nodes.new("ShaderNodeBsdfGlass")
        g.inputs["Color"].default_value = color
        g.inputs["Roughness"].default_value = 0.0
        g.inputs["IOR"].default_value = 1.45
        nt.links.new(g.outputs[0], out.inputs["Surface"])
        world = bpy.context.scene.world
        world.use_nodes = True
        wt = world.node_tree
        bg = next(n for n in wt.nodes if n.type == "BACKGROUND")
        if not bg.inputs["Color"].is_linked:
            noise = wt.nodes.new("ShaderNodeTexNoise")
            noise.inputs["Scale"].default_value = 2.0
            wt.links.new(noise.outputs["Color"], bg.inputs["Color"])
        return
    film = kind == "film"  # Blender 4.2 and later
    if kind in ("principled", "film", "subsurface", "sheen"):
        p = nt.nodes.new("ShaderNodeBsdfPrincipled")
        p.inputs["Base Color"].default_value = color
        p.inputs["Roughness"].default_value = 0.3
        if film:
            p.inputs["Thin Film Thickness"].default_value = 450.0
        if kind == "subsurface":
            p.inputs["Subsurface Weight"].default_value = 1.0
        if kind == "sheen":
            p.inputs["Sheen Weight"].default_value = 1.0
        nt.links.new(p.outputs[0], out.inputs["Surface"])
        return
    d = nt.nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = color
    g = nt.nodes.new("ShaderNodeBsdfGlossy")
    g.inputs["Roughness"].default_value = 0.3
    mix = nt.nodes.new("ShaderNodeMixShader")
    mix.inputs[0].default_value = 0.5
    nt.links.new(d.outputs[0], mix.inputs[1])
    nt.links.new(g.outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], out.inputs["Surface"])


def build_scene():
    scene = ru.reset_scene()
    scene.world.color = (0.05, 0.05, 0.06)
    for i in range(30 if DEEP else 6):
        x, y = ((i % 6) - 2.5) * 1.5 if DEEP else (i % 3 - 1) * 2.6, (i // 6 if DEEP else i // 3) * 2.6
        bpy.ops.mesh.primitive_monkey_add(size=2.0, location=(x, y, 0.0), rotation=(0.0, 0.0, math.radians(20 * i)))
        obj = bpy.context.object
        obj.modifiers.new("Subdivision", "SUBSURF").render_levels = 2
        bpy.ops.object.shade_smooth()
        mat = ru.diffuse_material(f"m{i}", (0.2 + 0.12 * (i % 6), 0.5, 0.8 - 0.1 * (i % 6)))
        if DISPLACED:
            ru.add_noise_displacement(mat, 4.0, 0.15)
        if MATERIAL:
            bench_material(mat, MATERIAL)
        obj.data.materials.append(mat)
    bpy.ops.mesh.primitive_plane_add(size=30.0, location=(0, 0, -1.0))
    for kind, energy, loc in (("SUN", 3.0, (3, -3, 6)), ("POINT", 1000.0, (-4, -4, 4)), ("AREA", 500.0, (0, -6, 5))):
        data = bpy.data.lights.new(kind, kind)
        data.energy = energy
        obj = bpy.data.objects.new(kind, data)
        scene.collection.objects.link(obj)
        obj.location = loc
        obj.rotation_euler = (math.radians(40), 0.0, math.radians(20))
    ru.add_camera(scene, (0.0, -11.0, 5.0), (0.0, 1.3, 0.0), lens=35.0)
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = W, H, 100
    return scene


def time_engine(scene, engine):
    scene.render.engine = engine
    if engine == "MICROPOLY":
        scene.micropoly.samples = SAMPLES
    elif engine == "CYCLES":
        ru.setup_cycles(scene, samples=SAMPLES, shadows=True)
        c = scene.cycles
        c.max_bounces, c.diffuse_bounces, c.glossy_bounces = 12, 4, 4  # Cycles' defaults
        scene.render.engine = "CYCLES"
    else:
        eevee = scene.eevee
        eevee.taa_render_samples = SAMPLES
    times = []
    for _ in range(REPEAT):
        started = time.perf_counter()
        bpy.ops.render.render()
        times.append(time.perf_counter() - started)
    return times


def f12_breakdown(scene):
    """Where Micropoly's F12 goes (the last of three on one scene): the
    export, the native render (the worker thread's wall time and the
    renderer's own total), writing the render result, and the rest of the
    F12 (Blender's render pipeline around the engine)."""
    from micropoly import engine

    scene.render.engine = "MICROPOLY"
    scene.micropoly.samples = SAMPLES
    for _ in range(3):
        started = time.perf_counter()
        bpy.ops.render.render()
        f12 = time.perf_counter() - started
    t = dict(engine._final_renderers.last_timings)
    t["f12_s"] = f12
    t["outside_s"] = f12 - t["export_s"] - t["native_s"] - t["write_s"]
    return t


def export_time():
    from micropoly import export

    scene = ru.reset_scene()
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=1001, y_subdivisions=1001, size=10.0)
    faces = len(bpy.context.object.data.polygons)
    ru.add_camera(scene, (0, -10, 10), (0, 0, 0))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    times = []
    for _ in range(REPEAT):
        started = time.perf_counter()
        export.export_scene(depsgraph)
        times.append(time.perf_counter() - started)
    return faces, times


def export_rib(name):
    """The scene as RIB (material programs included), for the CLI's
    per-stage timings on PoCL and on a GPU: bench/out/<name>.rib."""
    scene = build_scene()  # enables the add-on
    from micropoly import operators

    scene.render.engine = "MICROPOLY"
    scene.micropoly.samples = SAMPLES
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "out", name + ".rib")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    operators.export_rib(bpy.context.evaluated_depsgraph_get(), path)
    print(f"wrote {path}")


def shadow_variants():
    """(label, set-up) of the shadow benchmark's renders."""
    def micropoly(shadows):
        def setup(scene):
            scene.render.engine = "MICROPOLY"
            scene.micropoly.samples = SAMPLES
            scene.micropoly.use_shadows = shadows
        return setup

    def cycles(direct_only):
        def setup(scene):
            ru.setup_cycles(scene, samples=SAMPLES, shadows=True)
            if not direct_only:
                c = scene.cycles
                c.max_bounces, c.diffuse_bounces, c.glossy_bounces = 12, 4, 4  # Cycles' defaults
        return setup

    return (("Micropoly, shadows", micropoly(True)), ("Micropoly, no shadows", micropoly(False)),
            ("Cycles, shadows, direct light", cycles(True)), ("Cycles, shadows, default light paths", cycles(False)))


def shadow_bench():
    variants = shadow_variants()
    times = {label: [] for label, _ in variants}
    stats = None
    for _ in range(REPEAT):
        for label, setup in variants:
            scene = build_scene()
            setup(scene)
            started = time.perf_counter()
            bpy.ops.render.render()
            times[label].append(time.perf_counter() - started)
            if label == "Micropoly, shadows" and stats is None:
                stats = shadow_stats(scene)
    base = statistics.median(times["Micropoly, no shadows"])
    print(f"\nBlender {bpy.app.version_string}, {W}x{H}, {SAMPLES} samples, F12, rounds interleaved, median of {REPEAT}")
    print("| render | F12 s (median) | runs | time / Micropoly without shadows |")
    print("|---|---|---|---|")
    for label, runs in times.items():
        med = statistics.median(runs)
        print(f"| {label} | {med:.2f} | {', '.join(f'{t:.2f}' for t in runs)} | {med / base:.2f}x |")
    if stats:
        print(f"\nshadow maps: {stats['pages_requested']} pages, {stats['micropolygons']:,} micropolygons, "
              f"peak {stats['peak_bytes'] / 2**20:.1f} MiB of a {stats['budget_bytes'] / 2**20:.0f} MiB budget")
        for light in stats["per_light"]:
            print(f"  light {light['light']}: {light['pages']} pages, {light['bytes'] / 2**20:.1f} MiB")
    print(json.dumps({"version": bpy.app.version_string, "width": W, "height": H, "renders": times,
                      "shadow_stats": stats}))


def shadow_stats(scene):
    """The shadow statistics of one render of the scene through the native
    module (F12 reports them only in its status line)."""
    from micropoly import _native, export, preferences

    exported = export.export_scene(bpy.context.evaluated_depsgraph_get())
    renderer = _native.Renderer(preferences.device_selector(bpy.context))
    return renderer.render(exported.scene)["stats"]["shadows"]


def main():
    if "--rib-only" in args:
        export_rib("shadow_suzannes" if SHADOWS else "displaced_suzannes" if DISPLACED else
                   "deep_suzannes" if DEEP else f"suzannes_{MATERIAL}" if MATERIAL else "suzannes")
        return
    if SHADOWS:
        shadow_bench()
        return
    engines = ENGINES or ("MICROPOLY", "CYCLES", "BLENDER_EEVEE_NEXT" if bpy.app.version >= (4, 2, 0) else "BLENDER_EEVEE")
    results = {}
    for engine in engines:
        scene = build_scene()
        try:
            results[engine] = time_engine(scene, engine)
        except Exception as e:  # EEVEE needs an OpenGL context some machines lack
            print(f"{engine}: could not render ({e})")
    if "--f12-only" in args:  # the F12 times alone (bench/cpu_device_bench.py)
        print(json.dumps({"version": bpy.app.version_string, "width": W, "height": H, "renders": results}))
        return
    breakdown = f12_breakdown(build_scene())
    faces, export_times = export_time()
    print(f"\nBlender {bpy.app.version_string}, {W}x{H}, {SAMPLES} samples, median of {REPEAT} F12 renders")
    micro = statistics.median(results["MICROPOLY"])
    print("| engine | F12 s (median) | runs | time / Micropoly's |")
    print("|---|---|---|---|")
    for engine, times in results.items():
        med = statistics.median(times)
        print(f"| {engine} | {med:.2f} | {', '.join(f'{t:.2f}' for t in times)} | {med / micro:.1f}x |")
    print(f"\nMicropoly F12 {breakdown['f12_s']:.2f} s: export {breakdown['export_s']:.2f} s, native render "
          f"{breakdown['native_s']:.2f} s (renderer's total {breakdown['native_total_s']:.2f} s), writing the "
          f"result {breakdown['write_s']:.2f} s, the rest of the F12 {breakdown['outside_s']:.2f} s")
    print(f"\nexport of a {faces:,}-face mesh: median {statistics.median(export_times):.3f} s "
          f"({', '.join(f'{t:.3f}' for t in export_times)})")
    print(json.dumps({"version": bpy.app.version_string, "width": W, "height": H, "renders": results,
                      "export_faces": faces, "export_s": export_times, "breakdown": breakdown}))


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    os._exit(0)  # the bpy module can hang in its exit handlers
