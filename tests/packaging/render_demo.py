"""Renders the demo scene (scripts/demo_scene.py) in a Python that has the bpy
module, with Micropoly either from a folder (the developer build's
addons/, as a legacy add-on) or installed from the extension zip the way
Preferences > Get Extensions > Install from Disk does.

  python render_demo.py --out OUT.png --report R.json (--addon-dir DIR | --install-zip ZIP)

The report says which add-on module rendered, where its native module and
OpenCL libraries were loaded from, and which devices it saw."""

import argparse
import json
import os
import runpy
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
DEMO = os.path.join(HERE, "..", "..", "scripts", "demo_scene.py")


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


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--out", required=True)
    parser.add_argument("--report", required=True)
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--addon-dir")
    source.add_argument("--install-zip")
    args = parser.parse_args()

    import bpy

    report = {"blender": bpy.app.version_string}
    if args.install_zip:
        result = bpy.ops.extensions.package_install_files(filepath=os.path.abspath(args.install_zip),
                                                          repo="user_default", enable_on_install=True)
        report["install"] = sorted(result)
        module = "bl_ext.user_default.micropoly"
    else:
        module = "micropoly"
        os.environ["BLENDER_USER_SCRIPTS"] = os.path.abspath(os.path.join(args.addon_dir, ".."))
        if args.addon_dir not in sys.path:
            sys.path.insert(0, os.path.abspath(args.addon_dir))
    os.environ["MICROPOLY_ADDON_MODULE"] = module
    sys.argv = [DEMO, "--", os.path.abspath(args.out)]
    t0 = time.perf_counter()
    runpy.run_path(DEMO, run_name="__main__")
    # The first render builds the kernels (or reads them from the cache);
    # a second one in the same process times the renderer alone.
    t1 = time.perf_counter()
    bpy.ops.render.render()
    report["first_render_s"] = t1 - t0
    report["second_render_s"] = time.perf_counter() - t1

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
