"""Renders the demo scene (scripts/build/demo_scene.py) in a Python that has the bpy
module, with Micropoly either from a folder (the developer build's
addons/, as a legacy add-on) or installed from the extension zip the way
Preferences > Get Extensions > Install from Disk does.

  python render_demo.py --out OUT.png --report R.json (--addon-dir DIR | --install-zip ZIP | --installed)
                        [--viewport] [--once] [--percentage P]

The demo scene is built (scripts/build/demo_scene.py --no-render, which enables
the add-on and so starts its kernel warm-up, addon/micropoly/warm_up.py);
the warm-up is waited for, as an artist would see it finish in the status
bar before the first F12; then the scene is rendered twice, each F12 timed
from Blender's render_init to its render_complete (--once: one F12).
--installed uses the extension an earlier run installed in the same home.
--viewport renders no F12 but the scene's first Rendered viewport frame, in
two sessions one after the other (each makes its renderer anew).

The report says which add-on module rendered, where its native module and
OpenCL libraries were loaded from, which devices it saw, and the times."""

import argparse
import json
import os
import runpy
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
DEMO = os.path.join(HERE, "..", "..", "scripts", "build", "demo_scene.py")


def loaded_libraries():
    """Paths of the shared objects this process has mapped."""
    paths = set()
    with open("/proc/self/maps") as f:
        for line in f:
            fields = line.split(maxsplit=5)
            # A file replaced since it was mapped (Blender re-extracts an
            # extension's wheels when preferences are reset) ends " (deleted)".
            path = fields[5].strip().removesuffix(" (deleted)") if len(fields) == 6 else ""
            if ".so" in os.path.basename(path):
                paths.add(path)
    return sorted(paths)


def viewport_first_frame(module):
    """Seconds from asking a new Rendered viewport session for the scene to
    its first image."""
    import bpy

    export = sys.modules[f"{module}.export"]
    viewport = sys.modules[f"{module}.viewport"]
    scene = bpy.context.scene
    depsgraph = bpy.context.evaluated_depsgraph_get()
    view = viewport.view_from_camera(scene, depsgraph, scene.render.resolution_x, scene.render.resolution_y)
    session = viewport.ViewportSession("")
    try:
        t0 = time.perf_counter()
        session.request(export.export_scene(depsgraph, view=view), view, scene.micropoly.viewport_samples,
                        scene.micropoly.viewport_shading_rate)
        while session.image() is None and session.error() is None and time.perf_counter() - t0 < 600.0:
            time.sleep(0.005)
        if session.error():
            raise RuntimeError(session.error())
        return time.perf_counter() - t0
    finally:
        session.close()


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--out", required=True)
    parser.add_argument("--report", required=True)
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--addon-dir")
    source.add_argument("--install-zip")
    source.add_argument("--installed", action="store_true")
    parser.add_argument("--viewport", action="store_true")
    parser.add_argument("--once", action="store_true", help="one F12 (under emulation, where each takes a minute)")
    parser.add_argument("--percentage", type=int, default=100,
                        help="the render's resolution percentage (the emulated F12 renders a small frame)")
    args = parser.parse_args()

    import bpy

    report = {"blender": bpy.app.version_string}
    if args.install_zip:
        result = bpy.ops.extensions.package_install_files(filepath=os.path.abspath(args.install_zip),
                                                          repo="user_default", enable_on_install=True)
        report["install"] = sorted(result)
        module = "bl_ext.user_default.micropoly"
    elif args.installed:
        module = "bl_ext.user_default.micropoly"
    else:
        module = "micropoly"
        os.environ["BLENDER_USER_SCRIPTS"] = os.path.abspath(os.path.join(args.addon_dir, ".."))
        if args.addon_dir not in sys.path:
            sys.path.insert(0, os.path.abspath(args.addon_dir))
    os.environ["MICROPOLY_ADDON_MODULE"] = module
    # The demo scene (it enables the add-on, whose kernel warm-up starts),
    # then the warm-up's end, as the status bar shows it, then the renders.
    t0 = time.perf_counter()
    sys.argv = [DEMO, "--", os.path.abspath(args.out), "--no-render"]
    runpy.run_path(DEMO, run_name="__main__")
    bpy.context.scene.render.resolution_percentage = args.percentage
    warm_up = sys.modules[f"{module}.warm_up"]
    warm_up.wait(600.0)
    report["warm_up"] = dict(warm_up.state(), waited_s=time.perf_counter() - t0)

    renders = []
    bpy.app.handlers.render_init.append(bpy.app.handlers.persistent(lambda *a: renders.append(time.perf_counter())))
    bpy.app.handlers.render_complete.append(
        bpy.app.handlers.persistent(lambda *a: renders.append(time.perf_counter())))
    if args.viewport:
        report["viewport_first_frames_s"] = [viewport_first_frame(module) for _ in range(2)]
    else:
        bpy.ops.render.render(write_still=True)
        report["first_render_s"] = renders[1] - renders[0]
        report["first_render_timings"] = dict(sys.modules[f"{module}.engine"]._final_renderers.last_timings)
        if not args.once:
            bpy.ops.render.render()
            report["second_render_s"] = renders[3] - renders[2]

    addon = sys.modules[module]
    native = sys.modules[f"{module}._native"]
    report["module"] = module
    report["native"] = native.__file__
    report["devices"] = native.list_devices()
    wheel = sys.modules.get("micropoly_native")
    report["embedded_cpu_device"] = getattr(wheel, "embedded_cpu_device", None)
    report["addon"] = addon.__file__
    report["libraries"] = loaded_libraries()
    report["ocl_icd_vendors"] = os.environ.get("OCL_ICD_VENDORS")
    with open(args.report, "w") as f:
        json.dump(report, f, indent=1)


if __name__ == "__main__":
    try:
        main()
        code = 0
    except BaseException:
        import traceback

        traceback.print_exc()
        code = 1
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)  # the bpy module can hang in its exit handlers after a render
