#!/usr/bin/env python3
"""Hidden layers in every view: the scenes of bench/occlusion_bench.py
(--rib-only) rendered by one or two builds of micropoly-render with shadows
on, rounds interleaved; per scene and build, the median over rounds of each
round's median frame (frames after the first), the camera's and the lights'
micropolygons, and every pool's peak against its budget.

  python3 bench/shadow_culling_bench.py --after build/micropoly-render [--before OLD_CLI] \\
      [--device cpu|gpu] [--repeat 3] [--rounds 3] [--spp 16] [--width 960 --height 540] scene.rib ...

Scenes are rendered at --width x --height (a copy of each RIB with its
Format replaced)."""

import argparse
import json
import os
import re
import statistics
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import before_after  # noqa: E402


def frames(cli, rib, out, device, repeat, spp):
    return before_after.run_frames(cli, rib, out, device, repeat, ["--spp", str(spp), "--fresh-shadows"])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--after", required=True)
    ap.add_argument("--before", default="")
    ap.add_argument("--device", default="")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--width", type=int, default=960)
    ap.add_argument("--height", type=int, default=540)
    ap.add_argument("scenes", nargs="+")
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="shadow-culling-")
    builds = [("after", a.after)] + ([("before", a.before)] if a.before else [])
    ribs = {}
    for path in a.scenes:
        name = os.path.splitext(os.path.basename(path))[0]
        text = open(path).read()
        text = re.sub(r"^Format \d+ \d+", f"Format {a.width} {a.height}", text, count=1, flags=re.M)
        copy = os.path.join(os.path.dirname(os.path.abspath(path)), f".{name}_{a.width}x{a.height}.rib")
        open(copy, "w").write(text)
        ribs[name] = copy
    times = {(n, b): [] for n in ribs for b, _ in builds}
    last = {}
    for _ in range(a.rounds):
        for name, rib in ribs.items():
            for build, cli in builds:
                runs = frames(cli, rib, tmp, a.device, a.repeat, a.spp)
                later = runs[1:] or runs
                times[(name, build)].append(statistics.median(r["timings_ms"]["total"] for r in later))
                last[(name, build)] = runs[-1]
    print(f"| scene | build | frame ms (median) | camera micropolygons | shadow micropolygons | shadow sub-patches "
          f"culled | shadows MiB peak / budget | bound & split MiB peak | marking passes |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name in ribs:
        for build, _ in builds:
            s = last[(name, build)]
            sh = s["shadows"]
            print(f"| {name} | {build} | {statistics.median(times[(name, build)]):.1f} | {s['micropolygons']:,} | "
                  f"{sh['micropolygons']:,} | {sh.get('subpatches_occluded', 0):,} | "
                  f"{sh['peak_bytes'] / 2**20:.1f} / {sh['budget_bytes'] / 2**20:.0f} | "
                  f"{s['bound_split_peak_bytes'] / 2**20:.1f} | {sh.get('marking_passes', 0)} |")
    print(json.dumps({"device": last[next(iter(last))]["device"], "spp": a.spp, "size": [a.width, a.height],
                      "times_ms": {f"{n}/{b}": v for (n, b), v in times.items()},
                      "stats": {f"{n}/{b}": s for (n, b), s in last.items()}}))
    for rib in ribs.values():
        os.remove(rib)


if __name__ == "__main__":
    main()
