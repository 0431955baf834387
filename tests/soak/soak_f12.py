"""Soak test of final renders: 200 F12 renders in one Blender process.

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup \
      --python tests/soak/soak_f12.py -- [--renders N] [--result FILE.txt] [--leak-image] [--vary-material]

The scene holds what a production frame holds on a small image (160 x 120):
Subdivision Surface on Suzanne and a torus, noise displacement on the torus,
an image texture on the floor, a procedural texture on Suzanne and a sun
whose shadow maps are on. After every render the process's resident set
(/proc/self/status VmRSS) is read, with the renderer's own peaks of its
budgeted device buffers (bound & split, shadow maps). On a CPU OpenCL device
(PoCL) device buffers are host memory and so part of the resident set.

The series is judged by soak_series.judge: after 20 renders of warm-up, the
median RSS of the last 50 renders may exceed that of renders 20-70 by at
most GROWTH_BOUND_KIB and the least-squares slope may be at most
SLOPE_BOUND_KIB per render. A leak of one 160 x 120 RGBA float image per
render (300 KiB) is added to the measured series and must fail the same
bounds, so the bounds are shown to catch it on this run's noise.
--leak-image keeps such an image alive after every render (a deliberate
leak, for showing that the test fails). --vary-material gives Suzanne's
material a new Roughness before every render, as an animated material value
does. Fewer than 120 renders are too few to judge: the series is printed and
the exit status is 1.
"""

import os
import statistics
import sys
import time

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "blender"))
import render_utils as ru  # noqa: E402
import soak_scene  # noqa: E402
import soak_series  # noqa: E402

WIDTH, HEIGHT = 160, 120
WARMUP, WINDOW = 20, 50
# Bounds: on PoCL (bench/results/pocl/soak_f12.txt) the series' noise about its
# fitted line is 1-1.6 MiB, which puts the slope's standard error near
# 2.3 KiB per render over 180 renders; the bounds sit well above that and
# well below the 300 KiB per render of the smallest leak they must catch
# (one 160 x 120 RGBA float image).
GROWTH_BOUND_KIB = 8192
SLOPE_BOUND_KIB = 40
LEAK_KIB = WIDTH * HEIGHT * 4 * 4 / 1024


class StatsRecorder:
    """Wraps the final renderer so that each render's stats are kept (the
    add-on shows them only in the status bar)."""

    def __init__(self):
        from micropoly import engine

        self.original = engine._final_renderers.acquire
        self.stats = []
        recorder = self

        class Proxy:
            def __init__(self, renderer):
                self._renderer = renderer

            def __getattr__(self, name):
                return getattr(self._renderer, name)

            def render(self, *args, **kwargs):
                result = self._renderer.render(*args, **kwargs)
                recorder.stats.append(result["stats"])
                return result

        def acquire(selector):
            return Proxy(recorder.original(selector))

        engine._final_renderers.acquire = acquire


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    renders = int(argv[argv.index("--renders") + 1]) if "--renders" in argv else 200
    result_path = argv[argv.index("--result") + 1] if "--result" in argv else None
    leak = "--leak-image" in argv
    vary = "--vary-material" in argv
    scene = soak_scene.build_scene(WIDTH, HEIGHT, samples=16)
    recorder = StatsRecorder()
    kept = []
    series, seconds = [], []
    started = time.perf_counter()
    bsdf = next(n for n in bpy.data.materials["Suzanne"].node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    for i in range(renders):
        if vary:
            bsdf.inputs["Roughness"].default_value = 0.3 + 0.4 * i / renders
        t0 = time.perf_counter()
        bpy.ops.render.render()
        seconds.append(time.perf_counter() - t0)
        if len(recorder.stats) != i + 1:
            raise RuntimeError(f"render {i} did not reach the native renderer (a reported error?)")
        if leak:
            kept.append(np.ones((HEIGHT, WIDTH, 4), dtype=np.float32))
        series.append(soak_series.rss_kib())
    wall = time.perf_counter() - started
    if renders < WARMUP + 2 * WINDOW:
        print("series_kib:", series)
        print("render_s:", [round(t, 2) for t in seconds])
        return 1
    result = soak_series.judge(series, WARMUP, WINDOW, GROWTH_BOUND_KIB, SLOPE_BOUND_KIB)
    split_peaks = [s["bound_split_peak_bytes"] for s in recorder.stats]
    shadow_peaks = [s["shadows"]["peak_bytes"] for s in recorder.stats]
    result["device"] = recorder.stats[-1]["device"]
    result["bound_split_peak_bytes"] = [min(split_peaks), max(split_peaks)]
    result["shadow_peak_bytes"] = [min(shadow_peaks), max(shadow_peaks)]
    result["shadow_budget_bytes"] = recorder.stats[-1]["shadows"]["budget_bytes"]
    result["shadow_pages_rendered_last"] = recorder.stats[-1]["shadows"]["pages_rendered"]
    result["micropolygons"] = recorder.stats[-1]["micropolygons"]
    result["render_s_median"] = statistics.median(seconds)
    result["wall_s"] = wall
    result["leak_image_switch"] = leak
    result["leak_kib_per_step"] = LEAK_KIB
    result["leak_detected_on_this_series"] = soak_series.leak_detected(
        series, LEAK_KIB, WARMUP, WINDOW, GROWTH_BOUND_KIB, SLOPE_BOUND_KIB)
    # The budgeted device buffers must not grow from render to render: the
    # same frame needs the same peaks once the warm-up is over.
    if max(split_peaks[WARMUP:]) > max(split_peaks[:WARMUP]):
        result["failures"].append("bound & split peak grew after the warm-up")
    if max(shadow_peaks[WARMUP:]) > max(shadow_peaks[:WARMUP]):
        result["failures"].append("shadow map peak grew after the warm-up")
    if result["shadow_pages_rendered_last"] == 0 and result["shadow_peak_bytes"][1] == 0:
        result["failures"].append("no shadow maps were rendered: the scene does not exercise them")
    if not result["leak_detected_on_this_series"]:
        result["failures"].append(f"a leak of {LEAK_KIB:.0f} KiB per render would pass these bounds")
    text = soak_series.summary_text(f"soak_f12: {renders} F12 renders at {WIDTH}x{HEIGHT}, 16 spp, "
                                    "subdivision + displacement + textures + shadows, Blender "
                                    f"{bpy.app.version_string}", result)
    print(text)
    print("series_kib:", series)
    if result_path:
        with open(result_path, "w") as f:
            f.write(text)
            f.write("  series_kib: " + " ".join(str(v) for v in series) + "\n")
    return 1 if result["failures"] else 0


if __name__ == "__main__":
    ru.run_test(main)
