#!/usr/bin/env python3
"""Dicing density before and after a dicing change, side by side in one run:
micropolygons per pixel of surface (per covered pixel per depth layer) at
shading rate 1 and the frame time, for two builds of micropoly-render on the
density scenes. Each scene is rendered by both builds in turn, `--rounds`
times (median of the rounds' median frame times), so machine noise hits both.
  python3 bench/dicing_density.py --before OLD/micropoly-render --after build/micropoly-render \
      [--device gpu] [--repeat 5] [--rounds 3] [--json out.json]
"""
import argparse
import json
import os
import statistics
import sys
import tempfile

sys.path.insert(0, os.path.dirname(__file__))
import scenes  # noqa: E402
from run_bench import render, summarise  # noqa: E402

SCENES = {
    "dense_subdiv": "dense_subdiv (sheet at 25°)",
    "grazing_sheet": "grazing_sheet (same sheet at 78°)",
    "eye_split_plane": "eye_split_plane (ground plane to the horizon)",
    "teapot": "teapot",
}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--before", required=True)
    ap.add_argument("--after", required=True)
    ap.add_argument("--device", default="")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--teapot", default=os.path.join(os.path.dirname(__file__), "..", "tests", "scenes", "teapot.rib"))
    ap.add_argument("--json", default="")
    args = ap.parse_args()
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        paths = scenes.write_all(tmp, args.teapot)
        for key, name in SCENES.items():
            frames = {"before": [], "after": []}
            first = {}
            for _ in range(args.rounds):
                for which in ("before", "after"):
                    s = summarise(render(getattr(args, which), paths[key], tmp, which, args.repeat, args.device))
                    frames[which].append(s["frame_ms"])
                    first.setdefault(which, s)
            results[name] = {w: dict(first[w], frame_ms=statistics.median(frames[w]), frame_ms_rounds=frames[w])
                             for w in ("before", "after")}
    print(f"device: {results[next(iter(results))]['after']['device']}")
    print("| scene | micropolygons before → after | per pixel of surface before → after | frame ms before → after |")
    print("|---|---|---|---|")
    for name, r in results.items():
        b, a = r["before"], r["after"]
        print(f"| {name} | {b['micropolygons']:,} → {a['micropolygons']:,} | "
              f"{b['micropolygons_per_pixel']:.2f} → **{a['micropolygons_per_pixel']:.2f}** | "
              f"{b['frame_ms']:.1f} → {a['frame_ms']:.1f} |")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
