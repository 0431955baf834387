#!/usr/bin/env python3
"""Soak test of the command-line renderer: one process renders a RIB scene
N times (micropoly-render --repeat N) while this script samples, from
outside, its resident set (/proc/PID/status VmRSS every --interval seconds)
and, where nvidia-smi exists, its GPU memory (nvidia-smi
--query-compute-apps=pid,used_memory), so the same script measures PoCL and
an NVIDIA GPU.

  python3 tests/soak/soak_cli.py build/micropoly-render tests/scenes/teapot.rib \
      [--repeat 200] [--width 160 --height 120] [--interval 0.05] \
      [--json OUT.json] [--result OUT.txt] [-- EXTRA CLI ARGUMENTS, e.g. --device gpu]

--width/--height render a copy of the scene with its Format request
replaced (written to a temporary folder, so scenes that read archives must
be rendered at their own size). The CLI writes one stats record per render
(--stats); their "total" times place every sample on the render it fell in:
the render loop ends when the process's last render ends, just before the
image is written. The series (memory against render index) is judged by
soak_series.judge: 20 renders of warm-up, growth of the last 50 renders'
median over renders 20-70 within GROWTH_BOUND_KIB, least-squares slope within
SLOPE_BOUND_KIB per render, and a leak of one RGBA float image of the frame
per render, added to the series, must fail those bounds. Exit status 0:
within the bounds; 1: not, or the CLI failed; 3: too few samples fell in
the render loop to judge (render a larger image or sample more often).
"""

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import soak_series  # noqa: E402

WARMUP, WINDOW = 20, 50
# Bounds (bench/results/pocl/soak_cli.txt): on PoCL the resident set after the
# warm-up moves by well under a MiB; GPU memory as nvidia-smi reports it is
# counted in whole MiB. A leak of one 160 x 120 RGBA float image per render
# (300 KiB) adds 39 MiB between the windows and 300 KiB per render to the slope.
GROWTH_BOUND_KIB = 8192
SLOPE_BOUND_KIB = 40
GPU_GROWTH_BOUND_KIB = 16384


def gpu_memory_mib(pid):
    """The process's GPU memory in MiB from nvidia-smi, or None."""
    try:
        out = subprocess.run(["nvidia-smi", "--query-compute-apps=pid,used_memory", "--format=csv,noheader,nounits"],
                             capture_output=True, text=True, timeout=10).stdout
    except (OSError, subprocess.TimeoutExpired):
        return None
    total, seen = 0, False
    for line in out.splitlines():
        parts = [p.strip() for p in line.split(",")]
        if len(parts) == 2 and parts[0] == str(pid) and parts[1].isdigit():
            total += int(parts[1])
            seen = True
    return total if seen else None


def scene_at_size(scene, width, height, folder):
    text = open(scene, encoding="utf-8").read()
    text, n = re.subn(r"(?m)^(\s*)Format\s+\S+\s+\S+", rf"\g<1>Format {width} {height}", text, count=1)
    if n == 0:
        text = f"Format {width} {height} 1\n" + text
    path = os.path.join(folder, os.path.basename(scene))
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    return path


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("cli")
    ap.add_argument("scene")
    ap.add_argument("--repeat", type=int, default=200)
    ap.add_argument("--width", type=int)
    ap.add_argument("--height", type=int)
    ap.add_argument("--interval", type=float, default=0.05)
    ap.add_argument("--json")
    ap.add_argument("--result")
    argv = sys.argv[1:]
    extra = argv[argv.index("--") + 1:] if "--" in argv else []
    a = ap.parse_args(argv[:argv.index("--")] if "--" in argv else argv)
    a.extra = extra
    folder = tempfile.mkdtemp(prefix="mp-soak-cli-")
    try:
        return run(a, folder)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def run(a, folder):
    scene = a.scene
    if a.width or a.height:
        scene = scene_at_size(a.scene, a.width or 160, a.height or 120, folder)
    stats_path = os.path.join(folder, "stats.json")
    cmd = [a.cli, scene, "-o", os.path.join(folder, "out.png"), "--repeat", str(a.repeat), "--stats", stats_path,
           *a.extra]
    has_smi = shutil.which("nvidia-smi") is not None
    started = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    rss = []  # (seconds since start, KiB)
    gpu = []  # (seconds since start, MiB)
    done = threading.Event()

    def sample_gpu():
        while not done.is_set():
            t = time.perf_counter() - started
            mib = gpu_memory_mib(proc.pid)
            if mib is not None:
                gpu.append((t, mib))
            done.wait(max(a.interval, 0.1))

    gpu_thread = threading.Thread(target=sample_gpu, daemon=True) if has_smi else None
    if gpu_thread:
        gpu_thread.start()
    while proc.poll() is None:
        kib = soak_series.rss_kib(proc.pid)
        t = time.perf_counter() - started
        if kib is not None and proc.poll() is None:
            rss.append((t, kib))
        time.sleep(a.interval)
    ended = time.perf_counter() - started
    done.set()
    if gpu_thread:
        gpu_thread.join()
    out, err = proc.communicate()
    report = {"command": cmd, "exit_status": proc.returncode, "stderr": err.strip()[-2000:], "wall_s": ended,
              "interval_s": a.interval, "nvidia_smi": has_smi, "failures": []}
    if proc.returncode != 0:
        report["failures"].append(f"micropoly-render exited with status {proc.returncode}: {err.strip()[-500:]}")
        return finish(a, report, 1)
    with open(stats_path) as f:
        stats = json.load(f)
    if len(stats) != a.repeat:
        report["failures"].append(f"{len(stats)} stats records for {a.repeat} renders")
        return finish(a, report, 1)
    totals = [s["timings_ms"]["total"] / 1000.0 for s in stats]
    loop_s = sum(totals)
    # The loop ends when the image writing starts; that is at most the time
    # since the last sample, so the end is placed at the last sample (an error
    # of under one interval, a small fraction of a render at these sizes).
    loop_end = rss[-1][0] if rss else ended
    loop_start = loop_end - loop_s
    ends = []
    acc = loop_start
    for s in totals:
        acc += s
        ends.append(acc)

    def render_index(t):
        """Fractional render index of time t (0 at the loop's start)."""
        if t <= loop_start:
            return None
        prev = loop_start
        for i, e in enumerate(ends):
            if t <= e:
                return i + (t - prev) / max(e - prev, 1e-9)
            prev = e
        return float(len(ends))

    width, height = stats[-1]["width"], stats[-1]["height"]
    leak_kib = width * height * 16 / 1024
    report.update(device=stats[-1]["device"], width=width, height=height, spp=stats[-1]["spp"], renders=a.repeat,
                  render_loop_s=loop_s, render_ms_median=sorted(totals)[len(totals) // 2] * 1000.0,
                  bound_split_peak_bytes=[min(s["bound_split_peak_bytes"] for s in stats),
                                          max(s["bound_split_peak_bytes"] for s in stats)],
                  shadow_peak_bytes=[min(s["shadows"]["peak_bytes"] for s in stats),
                                     max(s["shadows"]["peak_bytes"] for s in stats)],
                  leak_kib_per_step=leak_kib)
    code = 0
    for name, samples, scale, growth_bound in (("rss", rss, 1, GROWTH_BOUND_KIB),
                                               ("gpu", gpu, 1024, GPU_GROWTH_BOUND_KIB)):
        placed = [(render_index(t), v * scale) for t, v in samples]
        placed = [(x, v) for x, v in placed if x is not None]
        report[f"{name}_samples_in_loop"] = len(placed)
        if name == "gpu" and not has_smi:
            continue
        if not placed:
            report["failures"].append(f"no {name} samples fell in the render loop")
            code = code or 3
            continue
        xs, vs = [x for x, _ in placed], [v for _, v in placed]
        try:
            judged = soak_series.judge(vs, WARMUP, WINDOW, growth_bound, SLOPE_BOUND_KIB, xs)
        except ValueError as e:
            report["failures"].append(f"{name}: {e} (render a larger image or sample more often)")
            code = code or 3
            continue
        judged["leak_detected_on_this_series"] = soak_series.leak_detected(
            vs, leak_kib, WARMUP, WINDOW, growth_bound, SLOPE_BOUND_KIB, xs)
        if not judged["leak_detected_on_this_series"]:
            judged["failures"].append(f"a leak of {leak_kib:.0f} KiB per render would pass these bounds")
        report[name] = judged
        report["failures"] += [f"{name}: {f}" for f in judged["failures"]]
        report[f"{name}_series"] = [[round(x, 2), v] for x, v in placed]
    if report["failures"] and code == 0:
        code = 1
    return finish(a, report, code)


def finish(a, report, code):
    lines = [f"soak_cli: {report['command'][0]} {os.path.basename(report['command'][1])} --repeat "
             f"{report.get('renders', '?')} at {report.get('width', '?')}x{report.get('height', '?')}, "
             f"{report.get('spp', '?')} spp on {report.get('device', '?')}",
             f"  exit_status: {report['exit_status']}",
             f"  wall_s: {report['wall_s']:.1f}"]
    for key in ("render_loop_s", "render_ms_median", "bound_split_peak_bytes", "shadow_peak_bytes",
                "leak_kib_per_step", "rss_samples_in_loop", "gpu_samples_in_loop", "nvidia_smi"):
        if key in report:
            v = report[key]
            lines.append(f"  {key}: {v:.1f}" if isinstance(v, float) else f"  {key}: {v}")
    for name, title in (("rss", "resident set (KiB)"), ("gpu", "GPU memory from nvidia-smi (KiB)")):
        if name in report:
            lines.append(f"  {title}:")
            lines += ["  " + line for line in soak_series.summary_text("", report[name]).splitlines()[1:-1]]
    verdict = "pass" if code == 0 else ("TOO SHORT TO JUDGE: " if code == 3 else "FAIL: ") + "; ".join(
        report["failures"])
    lines.append("  verdict: " + verdict)
    text = "\n".join(lines) + "\n"
    print(text, end="")
    if a.result:
        with open(a.result, "w") as f:
            f.write(text)
    if a.json:
        soak_series.write_json(a.json, report)
    return code


if __name__ == "__main__":
    sys.exit(main())
