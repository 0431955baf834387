#!/usr/bin/env python3
"""Per-stage times of two builds of micropoly-render on RIB scenes, side by
side in one run (rounds interleaved): the median of the frames after the
first of each, per stage, and the sample stage's nanoseconds per
micropolygon (its kernel time over the micropolygons diced).

  python3 bench/before_after_stages.py --before OLD_CLI --after NEW_CLI [--device gpu] [--repeat 3] [--rounds 2] scene.rib ...

A scene given as OLD.rib:NEW.rib is read by the old build from OLD.rib and
by the new one from NEW.rib: the same scene exported by each build's add-on,
where the new one writes material programs the old build cannot compile.
"""

import argparse
import json
import os
import statistics
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from before_after import run_frames  # noqa: E402

STAGES = ("total", "shadows_wall", "bound_split", "dice", "shade", "sample", "resolve", "readback", "occlusion")


def run(cli, rib, out, device, repeat):
    runs = run_frames(cli, rib, out, device, repeat)
    return runs[1:] if len(runs) > 1 else runs


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--before", required=True)
    ap.add_argument("--after", required=True)
    ap.add_argument("--device", default="")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("ribs", nargs="+")
    a = ap.parse_args()
    out = tempfile.mkdtemp(prefix="mp-stages-")
    frames = {(rib, w): [] for rib in a.ribs for w in ("before", "after")}
    for _ in range(a.rounds):
        for rib in a.ribs:
            pair = dict(zip(("before", "after"), rib.split(":", 1) if ":" in rib else (rib, rib)))
            for which in ("before", "after"):
                frames[(rib, which)] += run(getattr(a, which), pair[which], out, a.device, a.repeat)
    print("| scene | build | micropolygons | " + " | ".join(STAGES) + " | sample ns / micropolygon |")
    print("|---|---|---|" + "---|" * len(STAGES) + "---|")
    summary = {}
    for (rib, which), runs in frames.items():
        med = {k: statistics.median(r["timings_ms"].get(k, 0.0) for r in runs) for k in STAGES}
        mps = statistics.median(r["micropolygons"] for r in runs)  # diced: the same count for both builds
        ns = med["sample"] * 1e6 / mps if mps else 0.0
        name = os.path.splitext(os.path.basename(rib.split(":")[-1]))[0]
        summary[f"{name}/{which}"] = {"stages_ms": med, "micropolygons_sampled": mps, "sample_ns_per_micropolygon": ns}
        print(f"| {name} | {which} | {int(mps):,} | " + " | ".join(f"{med[k]:.0f}" for k in STAGES) + f" | {ns:.0f} |")
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
