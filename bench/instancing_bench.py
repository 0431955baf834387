"""Instancing benchmark: the rock field (bench/occlusion_bench.py: 2,000
subdivided, displaced rocks that share one mesh, scattered over a ground
plane under a sun, 1920x1080, 16 spp) rendered as instances of one
prototype and as copies (each rock a mesh of its own), side by side.

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup --python bench/instancing_bench.py -- --rib-only [--rocks N]
      writes bench/out/field_<N>.rib (instances: the add-on exports objects
      that share a mesh as instances) and bench/out/field_<N>_copies.rib
      (every rock given a mesh of its own first).
  python3 bench/instancing_bench.py --cli build/micropoly-render [--before OLD_CLI] [--rocks N] [--rounds 3] [--device cpu|gpu]
      renders both (and, with --before, the copies with OLD_CLI) in
      interleaved rounds, one process per frame: the first frame's upload
      (scene preparation and upload), its total, the second frame's total,
      the process's peak resident memory, and the device memory the scene's
      buffers take (patches, instances, objects); medians over rounds.
Only the standard library is used outside Blender."""

import json
import os
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "out")
args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]


def arg(name, default):
    return args[args.index(name) + 1] if name in args else default


ROCKS = int(arg("--rocks", "2000"))


def write_ribs():
    sys.argv = [sys.argv[0]]  # occlusion_bench reads its own options
    sys.path.insert(0, HERE)
    import bpy
    import occlusion_bench

    os.makedirs(OUT, exist_ok=True)
    occlusion_bench.field_scene(ROCKS)
    from micropoly import operators

    for name in (f"field_{ROCKS}", f"field_{ROCKS}_copies"):
        if name.endswith("_copies"):
            for obj in bpy.context.scene.objects:
                if obj.type == "MESH" and obj.data.users > 1:
                    obj.data = obj.data.copy()
        path = os.path.join(OUT, name + ".rib")
        operators.export_rib(bpy.context.evaluated_depsgraph_get(), path)
        print(f"wrote {path} ({os.path.getsize(path) / 2**20:.1f} MiB)")


def one_run(cli, rib, device):
    """One process rendering two frames: (stats of each frame, peak RSS MiB)."""
    with tempfile.TemporaryDirectory() as tmp:
        stats = os.path.join(tmp, "stats.json")
        cmd = [cli, rib, "-o", os.path.join(tmp, "image.png"), "--stats", stats, "--repeat", "2"]
        if device:
            cmd += ["--device", device]
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        _, rusage = os.wait4(proc.pid, 0)[1:]
        err = proc.stderr.read().decode()
        proc.returncode = 0
        with open(stats) as f:
            runs = json.load(f)
        if not isinstance(runs, list) or len(runs) < 2:
            raise SystemExit(f"{' '.join(cmd)}: {err}")
        return runs, rusage.ru_maxrss / 1024.0


def measure():
    cli = arg("--cli", os.path.join(HERE, "..", "build", "micropoly-render"))
    before = arg("--before", None)
    device = arg("--device", None)
    rounds = int(arg("--rounds", "3"))
    cases = [("instances", cli, f"field_{ROCKS}.rib"), ("copies", cli, f"field_{ROCKS}_copies.rib")]
    if before:
        cases.append(("copies, before", before, f"field_{ROCKS}_copies.rib"))
    scenes = arg("--scenes", OUT)
    results = {name: [] for name, _, _ in cases}
    for _ in range(rounds):
        for name, binary, rib in cases:
            runs, rss = one_run(binary, os.path.join(scenes, rib), device)
            first, second = runs[0], runs[1]
            results[name].append({
                "upload_ms": first["timings_ms"].get("upload", 0.0),
                "first_ms": first["timings_ms"]["total"],
                "frame_ms": second["timings_ms"]["total"],
                "rss_mib": rss,
                "patches": second.get("patches", 0),
                "micropolygons": second.get("micropolygons", 0),
                "scene_mib": second.get("scene_bytes", 0) / 2**20,
            })
    keys = ("upload_ms", "first_ms", "frame_ms", "rss_mib", "scene_mib")
    print(f"{'case':16s}" + "".join(f"{k:>14s}" for k in keys) + f"{'patches':>14s}{'micropolygons':>16s}")
    medians = {}
    for name, rows in results.items():
        medians[name] = {k: statistics.median(r[k] for r in rows) for k in keys}
        print(f"{name:16s}" + "".join(f"{medians[name][k]:14.1f}" for k in keys) +
              f"{rows[-1]['patches']:14,d}{rows[-1]['micropolygons']:16,d}")
    for other in [n for n in medians if n != "instances"]:
        print(f"instances / {other}: " + ", ".join(
            f"{k} {medians['instances'][k] / medians[other][k]:.3f}" for k in keys if medians[other][k] > 0))


if __name__ == "__main__":
    if "--rib-only" in args:
        write_ribs()
    else:
        measure()
