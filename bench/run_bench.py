#!/usr/bin/env python3
"""Micropoly benchmark: renders the standard scenes with micropoly-render and
prints the stats JSON of every scene, then a summary table (medians over
repeated renders in one process, so the kernel build and scene upload are
reported separately from the frame time).

  python3 bench/run_bench.py --cli build/micropoly-render [--device cpu|gpu] [--repeat 5]
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(__file__))
import scenes  # noqa: E402

STAGES = ("bound_split", "dice", "shade", "sample", "resolve")
SWEEP_ONLY = ("wide_subdiv_4k",)


def render(cli, rib, out_dir, name, repeat, device, extra=(), env=None):
    stats_path = os.path.join(out_dir, name + ".json")
    image = os.path.join(out_dir, name + ".png")
    cmd = [cli, rib, "-o", image, "--stats", stats_path, "--repeat", str(repeat)] + list(extra)
    if device:
        cmd += ["--device", device]
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed ({proc.returncode}): {proc.stderr.strip()}")
    with open(stats_path) as f:
        runs = json.load(f)
    return runs if isinstance(runs, list) else [runs]


def summarise(runs):
    """Medians over the runs; 'frame' is the render time without the scene upload."""
    frame = statistics.median(r["timings_ms"]["total"] - r["timings_ms"]["upload"] for r in runs)
    out = {
        "device": runs[0]["device"],
        "micropolygons": runs[0]["micropolygons"],
        "subpatches_diced": runs[0]["subpatches_diced"],
        # Dicing density: micropolygons per pixel of surface (per covered pixel per layer).
        "micropolygons_per_pixel": runs[0]["micropolygons_sampled"] / max(runs[0]["sampled_area_px"], 1e-9),
        "patches": runs[0]["patches"],
        "bound_split_peak_mib": runs[0]["bound_split_peak_bytes"] / 2**20,
        "upload_ms": statistics.median(r["timings_ms"]["upload"] for r in runs),
        "first_build_ms": runs[0]["program_build_ms"],
        "cache_hit": runs[0].get("program_cache_hit", False),
        "readback_ms": statistics.median(r["timings_ms"].get("readback", 0.0) for r in runs),
        "device_ms": statistics.median(sum(r["timings_ms"][s] for s in STAGES) for r in runs),
        "frame_ms": frame,
        "runs": len(runs),
    }
    for s in STAGES:
        out[s + "_ms"] = statistics.median(r["timings_ms"][s] for r in runs)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", default="build/micropoly-render")
    ap.add_argument("--out", default="bench/out")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--device", default="")
    ap.add_argument("--teapot", default=os.path.join(os.path.dirname(__file__), "..", "tests", "scenes", "teapot.rib"))
    ap.add_argument("--skip-sweep", action="store_true")
    args = ap.parse_args()

    paths = scenes.write_all(args.out, args.teapot)
    # A fresh program cache, so the first scene's first render shows the cold
    # kernel build; every later render in this run finds the binary cached.
    env = dict(os.environ, MICROPOLY_CACHE_DIR=tempfile.mkdtemp(prefix="micropoly-bench-cache-"))
    results = {}
    for name, rib in paths.items():
        if name in SWEEP_ONLY:
            continue
        runs = render(args.cli, rib, args.out, name, args.repeat, args.device, env=env)
        print(f"== {name}\n{json.dumps(runs[-1], indent=2)}")
        results[name] = summarise(runs)

    sweep = {}
    if not args.skip_sweep:
        for scene in ("wide_subdiv_4k", "eye_split_plane"):
            for label, tag, extra in [(f"bounded {m} MiB", f"bounded{m}",
                                       ["--bound-split", "bounded", "--bound-split-memory", str(m)])
                                      for m in (4, 16, 64, 256)] + [("breadth-first", "breadth",
                                                                     ["--bound-split", "breadth"])]:
                runs = render(args.cli, paths[scene], args.out, f"{scene}_{tag}", args.repeat, args.device, extra, env)
                sweep[f"{scene} / {label}"] = summarise(runs)

    print("\n| scene | micropolygons | micropolygons per pixel of surface | frame ms | device ms | " + " | ".join(s + " ms" for s in STAGES) +
          " | readback ms | upload ms | bound&split peak MiB |")
    print("|---|---|---|---|---|" + "---|" * len(STAGES) + "---|---|---|")
    for name, r in results.items():
        print(f"| {name} | {r['micropolygons']} | {r['micropolygons_per_pixel']:.2f} | {r['frame_ms']:.1f} | {r['device_ms']:.1f} | " +
              " | ".join(f"{r[s + '_ms']:.2f}" for s in STAGES) +
              f" | {r['readback_ms']:.1f} | {r['upload_ms']:.1f} | {r['bound_split_peak_mib']:.2f} |")
    if sweep:
        print("\n| scene / bound & split | peak MiB | bound&split ms | device ms | frame ms |")
        print("|---|---|---|---|---|")
        for name, r in sweep.items():
            print(f"| {name} | {r['bound_split_peak_mib']:.2f} | {r['bound_split_ms']:.2f} | {r['device_ms']:.1f} | "
                  f"{r['frame_ms']:.1f} |")
    first = next(iter(results.values()))
    print(f"\ndevice: {first['device']}; first kernel build {first['first_build_ms']:.0f} ms "
          f"({'from the disk cache' if first['cache_hit'] else 'cold, from source'}); "
          f"medians of {first['runs']} renders per scene in one process")
    with open(os.path.join(args.out, "summary.json"), "w") as f:
        json.dump({"scenes": results, "sweep": sweep}, f, indent=2)


if __name__ == "__main__":
    main()
