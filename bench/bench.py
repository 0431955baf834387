#!/usr/bin/env python3
"""The benchmark runner. Renders a suite's cases (bench/suites.py) with one
build of micropoly-render, or two side by side (--before), in interleaved
rounds so that the machine's noise falls on every case and build alike.
Per case and build it reports the median over rounds of each round's
per-frame median (frames after the first, which builds programs and
uploads the scene; with --first, that first frame instead), the stages' medians, the last frame's counts and every
pool's peak against its budget; with two builds, after / before; and the
suite's ratios between cases.

  python3 bench/bench.py SUITE --cli build/micropoly-render [--before OLD_CLI]
      [--device cpu|gpu] [--rounds 3] [--repeat N] [--only CASE,CASE]
      [--size WxH] [--scenes DIR] [--json FILE] [--first]
      [--args "OPTIONS"] [--before-args "OPTIONS"] [--frame total|interval]

  python3 bench/bench.py --list

Scenes are read from DIR (default: bench/out, where the generators write
them with --rib-only; on the GPU machine the bundle's folder, .device/).
--size renders every scene at that size (a copy of each RIB beside it with
its Format replaced). --args and --before-args add CLI options to each
build's runs: one binary twice with two settings is a before/after too
(--cli X --before X --before-args "--occlusion-waves off"). Only Python's
standard library is used: the GPU machine has no packages. Results go to bench/results/<device>/ by hand,
with the command that made them."""

import argparse
import json
import os
import re
import shlex
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import suites  # noqa: E402


def run_frames(cli, rib, out, device, repeat, options=()):
    """The stats of each frame of one `micropoly-render --repeat` run."""
    stats = os.path.join(out, "stats.json")
    cmd = [cli, rib, "-o", os.path.join(out, "image.png"), "--stats", stats, "--repeat", str(repeat)] + list(options)
    if device:
        cmd += ["--device", device]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode:
        raise SystemExit(f"{' '.join(cmd)} failed: {proc.stderr.strip()}")
    with open(stats) as f:
        runs = json.load(f)
    return runs if isinstance(runs, list) else [runs]


def resized(rib, size):
    """A copy of `rib` beside it (its archives and textures stay reachable)
    rendering at `size` (w, h)."""
    with open(rib) as f:
        text = f.read()
    text = re.sub(r"^Format \d+ \d+", f"Format {size[0]} {size[1]}", text, count=1, flags=re.M)
    name = os.path.splitext(os.path.basename(rib))[0]
    copy = os.path.join(os.path.dirname(os.path.abspath(rib)), f".{name}_{size[0]}x{size[1]}.rib")
    with open(copy, "w") as f:
        f.write(text)
    return copy


def median_frames(runs, key, first=False):
    later = runs[:1] if first else runs[1:] or runs
    return statistics.median(r["timings_ms"].get(key, 0.0) for r in later)


def mib(x):
    return x / 2**20


def report(suite, cases, builds, times, stages, last, frame_key="total"):
    two = len(builds) == 2
    print(f"| case | build | frame ms | {' | '.join(stages)} | micropolygons | shadow micropolygons | "
          f"micropolygons per pixel of surface | bound & split MiB peak | shadows MiB peak / budget | marking passes | buckets | "
          f"camera waves (root overlap) | host waits | kernel launches |" + (" after / before |" if two else ""))
    print("|---|---|---|" + "---|" * len(stages) + "---|---|---|---|---|---|---|---|---|---|" + ("---|" if two else ""))
    frame = {}
    for case in cases:
        for build, _ in builds:
            key = (case.name, build)
            frame[key] = statistics.median(t[frame_key] for t in times[key])
            stage_ms = [statistics.median(t[s] for t in times[key]) for s in stages]
            s = last[key]
            sh = s["shadows"]
            ratio = ""
            if two and build == "after":
                ratio = f" {frame[key] / frame[(case.name, 'before')]:.3f} |"
            elif two:
                ratio = " |"
            print(f"| {case.name} | {build} | {frame[key]:.2f} | " + " | ".join(f"{x:.2f}" for x in stage_ms) +
                  f" | {s['micropolygons']:,} | {sh['micropolygons']:,} | "
                  f"{s['micropolygons_sampled'] / max(s['sampled_area_px'], 1e-9):.2f} | {mib(s['bound_split_peak_bytes']):.1f} | "
                  f"{mib(sh['peak_bytes']):.1f} / {mib(sh['budget_bytes']):.0f} | {sh.get('marking_passes', 0)} | "
                  f"{s['buckets']} | {s.get('waves', '—')} ({s.get('root_overlap', 0):.1f}) | "
                  f"{s.get('host_waits', '—')} | {s.get('kernel_launches', '—')} |" + ratio)
    names = {c.name for c in cases}
    for a, b in suite.ratios:
        if a in names and b in names:
            for build, _ in builds:
                print(f"{build}: {a} / {b} = {frame[(a, build)] / frame[(b, build)]:.2f}")
    return frame


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("suite", nargs="?", choices=sorted(suites.SUITES))
    ap.add_argument("--cli", default=os.path.join(HERE, "..", "build", "micropoly-render"))
    ap.add_argument("--before", default="", help="an earlier build's micropoly-render, run beside --cli")
    ap.add_argument("--args", default="", help="options added to --cli's command (e.g. \"--occlusion-waves on\")")
    ap.add_argument("--before-args", default="", help="options added to --before's command")
    ap.add_argument("--device", default="")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--repeat", type=int, default=0, help="frames per run (default: the suite's)")
    ap.add_argument("--only", default="", help="comma-separated case names (or their scene part before '/')")
    ap.add_argument("--size", default="", help="WxH: every scene at this size")
    ap.add_argument("--scenes", default=os.path.join(HERE, "out"))
    ap.add_argument("--json", default="", help="also write every frame's times and the last stats here")
    ap.add_argument("--first", action="store_true",
                    help="time each run's first frame (a new process: programs from the cache, the scene and its "
                         "world uploaded, baked and prefiltered) instead of the frames after it")
    ap.add_argument("--frame", default="total", choices=("total", "interval"),
                    help="the frame time: each render call's wall time (total), or the wall time from one frame's "
                         "start to the next's (interval: a loop's throughput, each frame's read-back overlapping the "
                         "next frame's work; builds before it report 0)")
    ap.add_argument("--list", action="store_true")
    a = ap.parse_args()
    if a.list or not a.suite:
        for name, suite in suites.SUITES.items():
            print(f"{name}: {suite.about}")
        return
    suite = suites.SUITES[a.suite]
    tmp = tempfile.mkdtemp(prefix=f"mp-bench-{a.suite}-")
    cases = suite.cases(a.scenes, tmp)
    if a.only:
        wanted = set(a.only.split(","))
        cases = [c for c in cases if c.name in wanted or c.name.split("/")[0] in wanted]
    size = tuple(int(x) for x in a.size.lower().split("x")) if a.size else None
    ribs, made = {}, set()
    for case in cases:
        rib = case.scene if os.path.isabs(case.scene) else os.path.join(a.scenes, case.scene)
        if not os.path.exists(rib):
            raise SystemExit(f"{rib} is missing: write it with its generator's --rib-only (bench/suites.py)")
        if size:
            rib = resized(rib, size)
            made.add(rib)
        ribs[case.name] = rib
    # Two builds: the earlier first in each round.
    builds = [("before", a.before), ("after", a.cli)] if a.before else [("build", a.cli)]
    extra = {"before": shlex.split(a.before_args), "after": shlex.split(a.args), "build": shlex.split(a.args)}
    stages = tuple(dict.fromkeys((a.frame,) + tuple(suite.stages)))
    times = {(c.name, b): [] for c in cases for b, _ in builds}
    frames, last = {}, {}
    repeat = a.repeat or suite.repeat
    for _ in range(a.rounds):
        for case in cases:
            for build, cli in builds:
                runs = run_frames(cli, ribs[case.name], tmp, a.device, repeat, list(case.options) + extra[build])
                times[(case.name, build)].append({s: median_frames(runs, s, a.first) for s in stages})
                frames.setdefault(f"{case.name}/{build}", []).append([r["timings_ms"][a.frame] for r in runs])
                last[(case.name, build)] = runs[-1]
    device = next(iter(last.values()))["device"] if last else ""
    print(f"{a.suite}: {suite.about}; {device}, {a.rounds} rounds of {repeat} frames"
          + (f", {size[0]}x{size[1]}" if size else "") + (", the first frame of each" if a.first else "")
          + (", frame ms from one frame's start to the next's" if a.frame == "interval" else ""))
    report(suite, cases, builds, times, suite.stages, last, a.frame)
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"suite": a.suite, "device": device, "rounds": a.rounds, "repeat": repeat,
                       "frames_ms": frames, "stats": {f"{n}/{b}": s for (n, b), s in last.items()}}, f)
    for rib in made:
        os.remove(rib)


if __name__ == "__main__":
    main()
