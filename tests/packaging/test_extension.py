"""The extension zip on a machine with nothing else.

Builds the zip (`cmake --build BUILD --target extension`), then for each bpy
version: makes a fresh virtual environment with only that bpy module, hides
Debian's OpenCL loader, PoCL, OpenSubdiv, libpng and OpenEXR libraries and
its OpenCL driver registry from the loader (bind mounts in a private mount
namespace: the files are there but empty), installs the zip as an extension
the way Preferences does, enables it, renders the demo scene and compares
the image with the developer build's render of the same scene (Debian's
libraries and PoCL, the add-on from BUILD/addons) in the same bpy: >= 40 dB.

Also checks that the rendering process loaded its OpenCL loader and
OpenSubdiv from the wheel, that the CPU device it rendered on is the carried
PoCL, and that no hidden library was mapped.

  MICROPOLY_BUILD_DIR=build python3 tests/packaging/test_extension.py

MICROPOLY_EXTENSION_BPY lists the bpy versions (default: those under BUILD/bpy-*).
Needs root (unshare -m). Exits non-zero on failure."""

import glob
import json
import os
import shutil
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.abspath(os.path.join(HERE, "..", ".."))
BUILD = os.path.abspath(os.environ.get("MICROPOLY_BUILD_DIR", os.path.join(SOURCE, "build")))


def installed_bpy_versions():
    """The bpy versions scripts/setup.sh installed for the tests (BUILD/bpy-VERSION)."""
    venvs = glob.glob(os.path.join(BUILD, "bpy-*", "bin", "python3"))
    return sorted(os.path.basename(os.path.dirname(os.path.dirname(p)))[len("bpy-"):] for p in venvs)


VERSIONS = os.environ.get("MICROPOLY_EXTENSION_BPY", "").split() or installed_bpy_versions()
LIBDIR = "/usr/lib/x86_64-linux-gnu"
# What a machine with nothing else lacks: the libraries the developer build
# links and the OpenCL drivers Debian registers.
HIDDEN_LIBRARIES = ["libOpenCL.so*", "libpocl.so*", "libosd*.so*", "libpng16.so*", "libOpenEXR*.so*", "libIex*.so*",
                    "libIlmThread*.so*", "libImath*.so*"]
HIDDEN_FOLDERS = ["/etc/OpenCL/vendors", f"{LIBDIR}/pocl"]
MIN_PSNR = 40.0


def log(*a):
    print(*a, flush=True)


def hidden_files():
    files = set()
    for pattern in HIDDEN_LIBRARIES:
        for path in glob.glob(os.path.join(LIBDIR, pattern)):
            files.add(os.path.realpath(path))
    return sorted(files)


def hiding_script(command):
    """A shell script that hides the Debian libraries in its own mount
    namespace and then runs `command`."""
    lines = ["set -e"]
    for f in hidden_files():
        lines.append(f"mount --bind /dev/null '{f}'")
    for d in HIDDEN_FOLDERS:
        if os.path.isdir(d):
            lines.append(f"mount -t tmpfs none '{d}'")
    lines.append("exec " + " ".join(f"'{c}'" for c in command))
    return "\n".join(lines)


def read_png(path):
    from PIL import Image

    return np.asarray(Image.open(path).convert("RGB"), dtype=np.float64) / 255.0


def psnr(a, b):
    mse = float(np.mean((a - b) ** 2))
    return float("inf") if mse == 0.0 else 10.0 * np.log10(1.0 / mse)


def fresh_bpy_venv(version, folder):
    """A new venv with only bpy==version (and what it depends on)."""
    shutil.rmtree(folder, ignore_errors=True)
    subprocess.run(["/usr/bin/python3", "-m", "venv", folder], check=True)
    python = os.path.join(folder, "bin", "python3")
    subprocess.run([python, "-m", "pip", "install", "-q", "--disable-pip-version-check", f"bpy=={version}"],
                   check=True)
    return python


def check_version(version, zip_path, work):
    ok = True
    reference_python = os.path.join(BUILD, f"bpy-{version}", "bin", "python3")
    if not os.path.exists(reference_python):
        log(f"bpy {version}: no developer bpy venv at {reference_python}")
        return False
    t0 = time.time()
    python = fresh_bpy_venv(version, os.path.join(work, f"venv-{version}"))
    log(f"bpy {version}: fresh venv in {time.time() - t0:.0f} s")
    render = os.path.join(HERE, "render_demo.py")

    # The developer build: Debian's libraries, the add-on from BUILD/addons.
    ref_png, ref_json = (os.path.join(work, f"reference-{version}.{e}") for e in ("png", "json"))
    subprocess.run([reference_python, render, "--out", ref_png, "--report", ref_json, "--addon-dir",
                    os.path.join(BUILD, "addons")], check=True, stdout=subprocess.DEVNULL)

    # The extension, with Debian's libraries hidden, in a home of its own
    # (Blender's user folders, caches) and an environment with nothing set.
    home = os.path.join(work, f"home-{version}")
    shutil.rmtree(home, ignore_errors=True)
    os.makedirs(home)
    ext_png, ext_json = (os.path.join(work, f"extension-{version}.{e}") for e in ("png", "json"))
    env = {"HOME": home, "PATH": "/usr/bin:/bin", "LANG": "C.UTF-8", "PYTHONNOUSERSITE": "1"}
    script = hiding_script([python, render, "--out", ext_png, "--report", ext_json, "--install-zip", zip_path])
    t0 = time.time()
    done = subprocess.run(["unshare", "-m", "--propagation", "private", "sh", "-c", script], env=env,
                          capture_output=True, text=True)
    log(f"bpy {version}: extension render in {time.time() - t0:.0f} s (exit {done.returncode})")
    if done.returncode != 0:
        log(done.stdout[-3000:], done.stderr[-3000:])
        return False
    with open(ext_json) as f:
        report = json.load(f)
    log(f"bpy {version}: rendered by {report['module']}, native module {report['native']}")
    log(f"bpy {version}: devices {[(d['name'], d['version']) for d in report['devices']]}")
    log(f"bpy {version}: carried CPU device {report['embedded_cpu_device']}")

    if report["module"] != "bl_ext.user_default.micropoly" or "site-packages" not in report["native"]:
        log("FAIL: the render did not come from the installed extension's wheel")
        ok = False
    hidden = set(hidden_files())
    mapped_hidden = [lib for lib in report["libraries"] if os.path.realpath(lib) in hidden]
    if mapped_hidden:
        log(f"FAIL: hidden libraries were mapped: {mapped_hidden}")
        ok = False
    wheel_libs = [lib for lib in report["libraries"] if "micropoly_native.libs" in lib]
    for needed in ("libOpenCL", "libosdCPU", "libpng16"):
        if not any(needed in os.path.basename(lib) for lib in wheel_libs):
            log(f"FAIL: {needed} was not loaded from the wheel (micropoly_native.libs)")
            ok = False
    carried = report["embedded_cpu_device"]
    if not carried or not any(os.path.realpath(lib) == os.path.realpath(carried) for lib in report["libraries"]):
        log("FAIL: the carried PoCL was not the CPU device that rendered")
        ok = False

    with open(ref_json) as f:
        reference = json.load(f)
    log(f"bpy {version}: F12 of the demo scene, first (kernels built) / second: extension "
        f"{report['first_render_s']:.1f} / {report['second_render_s']:.1f} s, developer build "
        f"{reference['first_render_s']:.1f} / {reference['second_render_s']:.1f} s")
    value = psnr(read_png(ref_png), read_png(ext_png))
    log(f"bpy {version}: extension vs developer build PSNR {value:.2f} dB (>= {MIN_PSNR})")
    if not value >= MIN_PSNR:
        ok = False
    return ok


def main():
    if os.geteuid() != 0:
        log("needs root for a private mount namespace (unshare -m)")
        return 1
    work = os.path.join(BUILD, "extension-test")
    os.makedirs(work, exist_ok=True)
    t0 = time.time()
    subprocess.run(["cmake", "--build", BUILD, "--target", "extension"], check=True)
    zips = glob.glob(os.path.join(BUILD, "dist", "micropoly-*-linux-x64.zip"))
    if len(zips) != 1:
        log(f"expected one extension zip, found {zips}")
        return 1
    log(f"built {zips[0]} ({os.path.getsize(zips[0]) / 2**20:.1f} MiB) in {time.time() - t0:.0f} s")
    ok = True
    for version in VERSIONS:
        ok = check_version(version, zips[0], work) and ok
    log("PASS" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
