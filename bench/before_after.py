#!/usr/bin/env python3
"""Two builds of micropoly-render side by side on the standard benchmark
scenes (bench/scenes.py) plus any RIB files given, rounds interleaved so the
machine's noise falls on both alike: per scene, the median over rounds of
each round's per-frame median (frames after the first), and the ratio.

  python3 bench/before_after.py --before OLD_CLI --after NEW_CLI [--device gpu] [--repeat 10] [--rounds 3] [extra.rib ...]
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scenes  # noqa: E402


def run_frames(cli, rib, out, device, repeat, extra=()):
    """The stats of each frame of one `micropoly-render --repeat` run
    (`extra`: more of the CLI's options)."""
    stats = os.path.join(out, "stats.json")
    cmd = [cli, rib, "-o", os.path.join(out, "image.png"), "--stats", stats, "--repeat", str(repeat)] + list(extra)
    if device:
        cmd += ["--device", device]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode:
        raise SystemExit(f"{' '.join(cmd)} failed: {proc.stderr.strip()}")
    runs = json.load(open(stats))
    return runs if isinstance(runs, list) else [runs]


def frame_ms(cli, rib, out, device, repeat):
    runs = run_frames(cli, rib, out, device, repeat)
    later = runs[1:] or runs
    return statistics.median(r["timings_ms"]["total"] for r in later)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--before", required=True)
    ap.add_argument("--after", required=True)
    ap.add_argument("--device", default="")
    ap.add_argument("--repeat", type=int, default=10)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--teapot", default=os.path.join(os.path.dirname(__file__), "..", "tests", "scenes", "teapot.rib"))
    ap.add_argument("ribs", nargs="*")
    a = ap.parse_args()
    out = tempfile.mkdtemp(prefix="mp-before-after-")
    paths = scenes.write_all(out, a.teapot)
    paths.pop("wide_subdiv_4k")  # the memory sweep's scene
    for rib in a.ribs:
        paths[os.path.splitext(os.path.basename(rib))[0]] = rib
    times = {name: {"before": [], "after": []} for name in paths}
    for _ in range(a.rounds):
        for name, rib in paths.items():
            for which in ("before", "after"):
                times[name][which].append(frame_ms(getattr(a, which), rib, out, a.device, a.repeat))
    print(f"| scene | before ms | after ms | after / before | rounds (before; after) |")
    print("|---|---|---|---|---|")
    for name, t in times.items():
        b, f = statistics.median(t["before"]), statistics.median(t["after"])
        print(f"| {name} | {b:.2f} | {f:.2f} | {f / b:.3f} | {', '.join(f'{x:.1f}' for x in t['before'])}; "
              f"{', '.join(f'{x:.1f}' for x in t['after'])} |")
    print(json.dumps(times))


if __name__ == "__main__":
    main()
