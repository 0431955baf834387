"""Soak test of Rendered viewport shading: 200 redraw cycles with an edit
before each, in a Blender window under Xvfb.

  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup \
      --python tests/soak/soak_viewport.py -- [--count N] [--result FILE.txt]

This background part builds the soak scene (soak_scene.py), saves it and
starts Blender with a 512 x 320 window (xvfb-run, a 1280 x 800 screen; the
3D viewport's drawing region is then 468 x 345) on it,
running this script with `-- --gui RESULTS.json`. The window
part turns the 3D viewport to the camera's view in Rendered shading and then,
200 times: applies an edit, in turn
  1. moves the torus,
  2. changes the ball's material (its Roughness, a new value each time),
  3. changes the frame (Suzanne's rotation is keyed),
  4. resizes the viewport's drawing region (shows or hides the sidebar),
waits until the viewport's session has finished the refinement that edit
started (its final image carries a newer generation), lets it be drawn and
reads the process's resident set (/proc/self/status VmRSS). The viewport's
device buffers are host memory on a CPU OpenCL device (PoCL), so inside it.

The series is judged as the F12 soak's (soak_series.judge): 20 cycles of
warm-up, growth of the last 50 cycles' median over cycles 20-70 within
GROWTH_BOUND_KIB, least-squares slope within SLOPE_BOUND_KIB per cycle; a
leak of one viewport-sized RGBA float image per cycle, added to the series,
must fail those bounds. The background part asserts that Blender exited with
status 0 and that the window part recorded a passing result.
"""

import json
import os
import subprocess
import sys
import tempfile
import time
import traceback

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "blender"))
import render_utils as ru  # noqa: E402
import soak_scene  # noqa: E402
import soak_series  # noqa: E402

WARMUP, WINDOW = 20, 50
# Bounds: the series' noise on PoCL (bench/results/pocl/soak_viewport.txt) is
# 4-5 MiB about its fitted line, which puts the slope's standard error near
# 6-7 KiB per cycle over 180 cycles; the smallest
# leak they must catch is one RGBA float image of the drawing region per
# cycle (2.5 MiB for the 468 x 345 region).
GROWTH_BOUND_KIB = 16384
SLOPE_BOUND_KIB = 100
SAMPLES, SHADING_RATE = 4, 2.0
CYCLE_TIMEOUT_S = 60


def argument(argv, name, default):
    return argv[argv.index(name) + 1] if name in argv else default


def background_main(argv):
    cycles = int(argument(argv, "--count", "200"))
    result_path = argument(argv, "--result", None)
    folder = tempfile.mkdtemp(prefix="mp-soak-viewport-")
    blend, results = os.path.join(folder, "scene.blend"), os.path.join(folder, "results.json")
    scene = soak_scene.build_scene(160, 120, samples=SAMPLES)
    scene.micropoly.viewport_shading_rate = SHADING_RATE
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    # A small window keeps each redraw cheap (the drawing region comes out
    # at 468 x 345; a full-screen window's is about 1000 x 640).
    cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", bpy.app.binary_path, "--factory-startup",
           "--window-geometry", "0", "0", "512", "320", blend,
           "--python", os.path.abspath(__file__), "--", "--gui", results, "--count", str(cycles)]
    started = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=1800)
    wall = time.perf_counter() - started
    print(proc.stdout[-4000:])
    print(proc.stderr[-3000:])
    failures = []
    if proc.returncode != 0:
        failures.append(f"Blender with a window exited with status {proc.returncode}")
    if not os.path.exists(results):
        failures.append("the window part recorded no results")
        r = {}
    else:
        with open(results) as f:
            r = json.load(f)
        failures += r.get("failures", [])
    if len(r.get("series_kib", [])) < WARMUP + 2 * WINDOW:
        print("series_kib:", r.get("series_kib"), "cycle_s:", r.get("cycle_s_median"))
        failures.append(f"{len(r.get('series_kib', []))} cycles are too few to judge")
    else:
        series = r["series_kib"]
        judged = soak_series.judge(series, WARMUP, WINDOW, GROWTH_BOUND_KIB, SLOPE_BOUND_KIB)
        leak_kib = r["region_pixels"] * 16 / 1024
        judged["region"] = r["region"]
        judged["leak_kib_per_step"] = leak_kib
        judged["leak_detected_on_this_series"] = soak_series.leak_detected(
            series, leak_kib, WARMUP, WINDOW, GROWTH_BOUND_KIB, SLOPE_BOUND_KIB)
        judged["cycle_s_median"] = r["cycle_s_median"]
        judged["cycle_s_max"] = r["cycle_s_max"]
        judged["wall_s"] = wall
        if not judged["leak_detected_on_this_series"]:
            judged["failures"].append(f"a leak of {leak_kib:.0f} KiB per cycle would pass these bounds")
        failures += judged["failures"]
        text = soak_series.summary_text(
            f"soak_viewport: {len(series)} Rendered viewport cycles (move, material value, frame, resize), "
            f"{SAMPLES} spp, shading rate {SHADING_RATE}, Blender {bpy.app.version_string} under Xvfb", judged)
        print(text)
        if result_path:
            with open(result_path, "w") as f:
                f.write(text)
                f.write("  series_kib: " + " ".join(str(v) for v in series) + "\n")
        if len(series) != cycles:
            failures.append(f"{len(series)} of {cycles} cycles completed")
    if failures:
        print("FAIL: " + "; ".join(failures))
        return 1
    print(f"OK: {cycles} viewport cycles within the memory bounds ({wall:.1f} s)")
    return 0


# ---------------------------------------------------------------------------
# Inside the window


class WindowSoak:
    def __init__(self, results_path, cycles):
        ru.enable_addon()
        from micropoly import viewport

        self.viewport = viewport
        self.results_path = results_path
        self.cycles = cycles
        self.results = {"failures": [], "series_kib": []}
        self.window = bpy.context.window_manager.windows[0]
        self.area = max((a for a in self.window.screen.areas if a.type == "VIEW_3D"),
                        key=lambda a: a.width * a.height)
        self.space = self.area.spaces[0]
        self.scene = bpy.context.scene
        self.steps = self.run()

    def region(self):
        return next(r for r in self.area.regions if r.type == "WINDOW")

    def save(self):
        with open(self.results_path, "w") as f:
            json.dump(self.results, f)

    def fail(self, what):
        self.results["failures"].append(what)
        print("FAIL:", what, flush=True)

    def final_generation(self):
        """The generation of the newest final image when the session is idle, else None."""
        sessions = self.viewport.live_sessions()
        if len(sessions) != 1:
            return None
        s = sessions[0]
        image = s.image()
        if s.busy() or image is None or not image.final:
            return None
        if s.error():
            self.fail(f"the viewport reported an error: {s.error()}")
        return image.generation

    def edit(self, i):
        kind = i % 4
        if kind == 0:
            torus = bpy.data.objects["Torus"]
            torus.location.x = 1.1 + 0.3 * ((i // 4) % 3)
        elif kind == 1:
            # A new value every time. The ball's plain Principled material is
            # sent as parameters; values inside a node program are compiled
            # into its source instead (see --vary-material in soak_f12.py).
            bsdf = next(n for n in bpy.data.materials["Plain"].node_tree.nodes if n.type == "BSDF_PRINCIPLED")
            bsdf.inputs["Roughness"].default_value = 0.2 + 0.6 * i / self.cycles
        elif kind == 2:
            self.scene.frame_set(1 + (i // 4) % 40)
        else:
            self.space.show_region_ui = not self.space.show_region_ui
        self.area.tag_redraw()

    def run(self):
        # Without region overlap the sidebar takes its width from the drawing
        # region, so showing or hiding it resizes the rendered view.
        bpy.context.preferences.system.use_region_overlap = False
        self.space.overlay.show_overlays = False
        self.space.region_3d.view_perspective = "CAMERA"
        self.space.shading.type = "RENDERED"
        started = time.perf_counter()
        generation = None
        while generation is None:
            if time.perf_counter() - started > 120:
                self.fail("the viewport did not finish its first refinement in 120 s")
                return
            yield 0.1
            generation = self.final_generation()
        region = self.region()
        self.results["region"] = [region.width, region.height]
        self.results["region_pixels"] = region.width * region.height
        durations = []
        for i in range(self.cycles):
            t0 = time.perf_counter()
            self.edit(i)
            while True:
                yield 0.02
                now = self.final_generation()
                if now is not None and now > generation:
                    generation = now
                    break
                if time.perf_counter() - t0 > CYCLE_TIMEOUT_S:
                    self.fail(f"cycle {i} (edit {i % 4}) did not finish a refinement in {CYCLE_TIMEOUT_S} s")
                    return
            yield 0.05  # the final image is drawn
            durations.append(time.perf_counter() - t0)
            self.results["series_kib"].append(soak_series.rss_kib())
            self.results["cycle_s_median"] = sorted(durations)[len(durations) // 2]
        durations.sort()
        self.results["cycle_s_median"] = durations[len(durations) // 2]
        self.results["cycle_s_max"] = durations[-1]

    def step(self):
        try:
            return next(self.steps)
        except StopIteration:
            pass
        except Exception:
            self.fail("exception: " + traceback.format_exc())
        self.save()
        bpy.ops.wm.quit_blender()
        return None


def window_main(argv):
    soak = WindowSoak(argument(argv, "--gui", None), int(argument(argv, "--count", "200")))
    bpy.app.timers.register(soak.step, first_interval=1.0)


if __name__ == "__main__":
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if "--gui" in argv:
        window_main(argv)
    else:
        ru.run_test(lambda: background_main(argv))
