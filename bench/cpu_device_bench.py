#!/usr/bin/env python3
"""F12 on the CPU OpenCL devices side by side: Debian's PoCL (the developer
build's device), the PoCL the extension carries (scripts/build/cpu_device_wheel.py),
that same PoCL held to the target a processor with AVX2 but not AVX-512
gets, and optionally another PoCL library (e.g. PyPI's pocl-binary-
distribution 3.0, the extension's device before). Each configuration is one
Blender process rendering bench/blender_bench.py's scene (six subdivided
Suzannes, 1920x1080, 16 samples) or its displaced variant; rounds are
interleaved so that the machine's noise falls on all alike. Per process the
first F12 (kernels loaded) is dropped, the median of the rest kept; the
table gives the median over rounds and the ratio to Debian's PoCL.

  python3 bench/cpu_device_bench.py --wheel build/dist/wheels/micropoly_pocl-*.whl [--other NAME=LIBPOCL.so]
                                    [--rounds 3] [--repeat 4] [--blender blender]
"""

import argparse
import glob
import json
import os
import statistics
import subprocess
import sys
import tempfile
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(HERE)


def vendors_folder(root, name, library):
    folder = os.path.join(root, f"vendors-{name}")
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, f"{name}.icd"), "w") as f:
        f.write(library + "\n")
    return folder


def f12_times(blender, configuration, displaced, repeat, work):
    env = dict(os.environ, MICROPOLY_ADDON_DIR=os.path.join(SOURCE, "build", "addons"), **configuration["env"])
    cmd = [blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python",
           os.path.join(HERE, "blender_bench.py"), "--", "--engines", "MICROPOLY", "--f12-only", "--repeat", str(repeat)]
    if displaced:
        cmd.append("--displaced")
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=work)
    results = [line for line in done.stdout.splitlines() if line.startswith("{")]
    if done.returncode or not results:
        raise SystemExit(f"{configuration['name']}: {' '.join(cmd)} failed:\n{done.stdout[-2000:]}{done.stderr[-2000:]}")
    times = json.loads(results[-1])["renders"]["MICROPOLY"]
    return statistics.median(times[1:])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--wheel", required=True, help="the micropoly_pocl wheel")
    ap.add_argument("--other", action="append", default=[], help="NAME=path of another libpocl to compare")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--repeat", type=int, default=4)
    ap.add_argument("--blender", default="blender")
    a = ap.parse_args()
    work = tempfile.mkdtemp(prefix="mp-cpu-device-bench-")
    wheel = os.path.join(work, "wheel")
    with zipfile.ZipFile(glob.glob(a.wheel)[0]) as z:
        z.extractall(wheel)
    carried = os.path.join(wheel, "micropoly_pocl", "lib", "x86_64-linux-gnu", "libpocl.so.2")
    configurations = [
        {"name": "Debian's PoCL 3.1 (system)", "env": {"OCL_ICD_VENDORS": "/etc/OpenCL/vendors"}},
        {"name": "carried PoCL 3.1 (extension)", "env": {"OCL_ICD_VENDORS": vendors_folder(work, "carried", carried)}},
        {"name": "carried PoCL 3.1, avx2 target (haswell)",
         "env": {"OCL_ICD_VENDORS": vendors_folder(work, "carried", carried), "POCL_KERNELLIB_NAME": "avx2"}},
    ]
    for other in a.other:
        name, library = other.split("=", 1)
        configurations.append({"name": name, "env": {"OCL_ICD_VENDORS": vendors_folder(work, "other", library)}})
    for c in configurations:  # a cache of its own per device, made before the timed rounds
        c["env"]["POCL_CACHE_DIR"] = os.path.join(work, "pocl-cache-" + str(configurations.index(c)))
        c["env"]["MICROPOLY_CACHE_DIR"] = os.path.join(work, "mp-cache-" + str(configurations.index(c)))
    scenes = {"six Suzannes": False, "displaced Suzannes": True}
    for c in configurations:
        f12_times(a.blender, c, False, 2, work)
    times = {(c["name"], s): [] for c in configurations for s in scenes}
    for round_ in range(a.rounds):
        for scene, displaced in scenes.items():
            for c in configurations:
                t = f12_times(a.blender, c, displaced, a.repeat, work)
                times[(c["name"], scene)].append(t)
                print(f"round {round_ + 1}: {scene}, {c['name']}: {t:.2f} s", flush=True)
    print(f"\nF12, 1920x1080, 16 samples; per process the median of F12s 2-{a.repeat}; median over {a.rounds} rounds")
    print("| device | " + " | ".join(f"{s} F12 s | vs Debian's" for s in scenes) + " |")
    print("|---|" + "---|---|" * len(scenes))
    for c in configurations:
        cells = []
        for scene in scenes:
            med = statistics.median(times[(c["name"], scene)])
            base = statistics.median(times[(configurations[0]["name"], scene)])
            cells.append(f"{med:.2f} ({', '.join(f'{t:.2f}' for t in times[(c['name'], scene)])}) | {med / base:.3f}x")
        print(f"| {c['name']} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    sys.exit(main())
