"""Rendered viewport shading in a real Blender window (Xvfb, software OpenGL).

Run as `blender -b --factory-startup --python tests/blender/test_viewport.py`:
this background part builds the scene (a subdivided Suzanne with a diffuse
material over a floor, a sun casting her shadow on it, a camera, Micropoly
as the engine), saves it, and starts
Blender with a window under xvfb-run on that file and this script with
`-- --gui RESULTS.json`. The window part:

1. switches the 3D viewport to the scene camera's view, overlays off, and its
   shading to Rendered; waits for the refinement to finish and screenshots
   the window. The camera frame's part of the screenshot is compared with an
   F12 render of the scene at the frame's size (both colour-managed the same
   way, 8-bit sRGB): mean |difference| <= 2/255 and at most 1% of the pixels
   more than 24/255 apart (silhouette pixels land a fraction of a pixel
   differently in the two images); and an F12 render without shadows must
   not match it (the viewport shows the shadows);
2. renders F12 references of an edited scene (Suzanne moved, its material
   changed from orange to blue), then applies that edit from Python and
   screenshots the viewport until it matches the edited reference by the
   same rule; asserts this happens (within 30 s; the time it took is in the
   results, and its speed is measured by bench/viewport_bench.py);
3. applies another edit and quits Blender while that render is in flight.

The background part then asserts that Blender exited with status 0 (no
crash) and that the window part recorded passing results. The screenshot of
step 1 is kept as MICROPOLY_VIEWPORT_SHOT when that is set (docs/ uses one).
"""

import json
import os
import subprocess
import sys
import tempfile
import time
import traceback

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import render_utils as ru  # noqa: E402

MAX_MEAN = 2.0 / 255.0
OUTLIER = 24.0 / 255.0
MAX_OUTLIERS = 0.01
ORANGE, BLUE = (0.8, 0.3, 0.05), (0.1, 0.25, 0.8)


def build_scene(path):
    scene = ru.reset_scene()
    scene.world.color = (0.05, 0.05, 0.05)
    bpy.ops.mesh.primitive_monkey_add(size=2.0, location=(0.0, 0.0, 0.0), rotation=(0.0, 0.0, 0.4))
    suzanne = bpy.context.object
    suzanne.name = "Suzanne"
    suzanne.modifiers.new("Subdivision", "SUBSURF").render_levels = 2
    bpy.ops.object.shade_smooth()
    suzanne.data.materials.append(ru.diffuse_material("Paint", ORANGE))
    bpy.ops.mesh.primitive_plane_add(size=8.0, location=(0.0, 0.0, -1.0))
    bpy.context.object.data.materials.append(ru.diffuse_material("Floor", (0.6, 0.6, 0.6)))
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (0.6, 0.2, 0.3)
    scene.collection.objects.link(sun)
    ru.add_camera(scene, (0.0, -6.0, 1.5), (0.0, 0.0, 0.0), lens=50.0)
    scene.render.engine = "MICROPOLY"
    scene.micropoly.samples = scene.micropoly.viewport_samples = 16
    scene.micropoly.shading_rate = scene.micropoly.viewport_shading_rate = 1.0
    scene.display_settings.display_device = "sRGB"
    scene.view_settings.view_transform = "Standard"
    scene.render.resolution_percentage = 100
    bpy.ops.wm.save_as_mainfile(filepath=path)


def run_window(blend, results):
    blender = bpy.app.binary_path
    cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", blender, "--factory-startup", blend,
           "--python", os.path.abspath(__file__), "--", "--gui", results]
    started = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    print(proc.stdout[-6000:])
    print(proc.stderr[-3000:])
    return proc.returncode, time.perf_counter() - started


def background_main():
    folder = tempfile.mkdtemp(prefix="mp-viewport-")
    blend, results = os.path.join(folder, "scene.blend"), os.path.join(folder, "results.json")
    build_scene(blend)
    code, seconds = run_window(blend, results)
    failures = []
    if code != 0:
        failures.append(f"Blender with a window exited with status {code}")
    if not os.path.exists(results):
        failures.append("the window part recorded no results")
    else:
        with open(results) as f:
            r = json.load(f)
        print(json.dumps(r, indent=1))
        failures += r.get("failures", [])
        if not r.get("quit_requested"):
            failures.append("the window part did not reach the quit step")
    return ru.verdict(failures, f"viewport matched F12, followed an edit and quit cleanly ({seconds:.1f} s)")


# ---------------------------------------------------------------------------
# Inside the window


def load_png(path):
    """RGBA floats, rows bottom first (foreach_get: no Python list of pixels,
    which would hold the GIL long enough to slow the viewport's thread)."""
    image = bpy.data.images.load(path)
    w, h = image.size
    px = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(px)
    bpy.data.images.remove(image)
    return px.reshape(h, w, 4)


class WindowTest:
    def __init__(self, results_path):
        ru.enable_addon()
        from micropoly import viewport

        self.viewport = viewport
        self.results_path = results_path
        self.results = {"failures": []}
        self.window = bpy.context.window_manager.windows[0]
        self.area = max((a for a in self.window.screen.areas if a.type == "VIEW_3D"),
                        key=lambda a: a.width * a.height)
        self.region = next(r for r in self.area.regions if r.type == "WINDOW")
        self.space = self.area.spaces[0]
        self.scene = bpy.context.scene
        self.folder = os.path.dirname(results_path)
        self.steps = self.run()

    # -- helpers --
    def save(self):
        with open(self.results_path, "w") as f:
            json.dump(self.results, f, indent=1)

    def fail(self, what):
        self.results["failures"].append(what)
        print("FAIL:", what, flush=True)

    def session_idle(self):
        sessions = self.viewport.live_sessions()
        return bool(sessions) and all(not s.busy() and s.image() is not None and s.image().final
                                      for s in sessions)

    def screenshot(self, name):
        path = os.path.join(self.folder, name)
        with bpy.context.temp_override(window=self.window, area=self.area, region=self.region):
            bpy.ops.screen.screenshot(filepath=path)
        return load_png(path), path  # rows bottom first, window coordinates

    def frame_rect(self):
        """The camera frame in window pixels (x0, x1, y0, y1), integers inside it."""
        from bpy_extras.view3d_utils import location_3d_to_region_2d

        cam = self.scene.camera
        corners = [cam.matrix_world @ v for v in cam.data.view_frame(scene=self.scene)]
        pts = [location_3d_to_region_2d(self.region, self.space.region_3d, c) for c in corners]
        xs, ys = [p.x for p in pts], [p.y for p in pts]
        x0, x1 = int(np.ceil(min(xs))), int(np.floor(max(xs)))
        y0, y1 = int(np.ceil(min(ys))), int(np.floor(max(ys)))
        return x0 + self.region.x, x1 + self.region.x, y0 + self.region.y, y1 + self.region.y

    def f12(self, name, width, height):
        r = self.scene.render
        r.resolution_x, r.resolution_y = width, height
        r.image_settings.file_format = "PNG"
        r.image_settings.color_mode = "RGB"
        r.filepath = os.path.join(self.folder, name)
        bpy.ops.render.render(write_still=True)
        return load_png(r.filepath)

    def compare(self, shot, reference):
        x0, x1, y0, y1 = self.rect
        crop = shot[y0:y1, x0:x1, :3]
        h, w = crop.shape[:2]
        ref = reference[:h, :w, :3]
        diff = np.abs(crop - ref).max(axis=-1)
        return float(diff.mean()), float((diff > OUTLIER).mean())

    def matches(self, stats):
        return stats[0] <= MAX_MEAN and stats[1] <= MAX_OUTLIERS

    def edit(self, location_x, color):
        suzanne = bpy.data.objects["Suzanne"]
        suzanne.location.x = location_x
        bsdf = next(n for n in bpy.data.materials["Paint"].node_tree.nodes if n.type == "BSDF_DIFFUSE")
        bsdf.inputs["Color"].default_value = (*color, 1.0)

    # -- the steps (a generator: each yield is the delay before the next) --
    def run(self):
        self.space.overlay.show_overlays = False
        self.space.region_3d.view_perspective = "CAMERA"
        self.space.shading.type = "RENDERED"
        started = time.perf_counter()
        while not self.session_idle():
            if time.perf_counter() - started > 120:
                self.fail("the viewport did not finish its first refinement in 120 s")
                return
            yield 0.1
        self.results["first_refinement_s"] = time.perf_counter() - started
        yield 0.3  # let the final image be drawn
        shot, path = self.screenshot("viewport.png")
        keep = os.environ.get("MICROPOLY_VIEWPORT_SHOT")
        if keep:
            import shutil
            shutil.copy(path, keep)
        self.rect = self.frame_rect()
        x0, x1, y0, y1 = self.rect
        self.results["frame"] = [x0, x1, y0, y1]
        before = self.f12("before.png", x1 - x0, y1 - y0)
        stats = self.compare(shot, before)
        self.results["viewport_vs_f12"] = stats
        if not self.matches(stats):
            self.fail(f"viewport differs from F12: mean {stats[0] * 255:.2f}/255, {stats[1]:.1%} outliers")
        self.scene.micropoly.use_shadows = False
        unshadowed = self.f12("no_shadows.png", x1 - x0, y1 - y0)
        self.scene.micropoly.use_shadows = True
        stats = self.compare(shot, unshadowed)
        self.results["viewport_vs_f12_without_shadows"] = stats
        if self.matches(stats):
            self.fail("the viewport matches F12 without shadows: it shows none")
        # Orange Suzanne in the viewport must not already look like the
        # edited one, or the next step proves nothing.
        self.edit(0.7, BLUE)
        after = self.f12("after.png", x1 - x0, y1 - y0)
        self.edit(0.0, ORANGE)
        stats = self.compare(shot, after)
        self.results["before_vs_after_reference"] = stats
        if self.matches(stats):
            self.fail("the edit does not change the image enough to be detected")
        started = time.perf_counter()
        while not self.session_idle():  # the F12 renders and the revert restarted it
            if time.perf_counter() - started > 120:
                self.fail("the viewport did not settle after the F12 renders")
                return
            yield 0.1
        yield 0.3

        # The edit, live.
        self.edit(0.7, BLUE)
        edited = time.perf_counter()
        matched = None
        while time.perf_counter() - edited < 30:
            yield 0.05
            shot, _ = self.screenshot("edited.png")
            stats = self.compare(shot, after)
            if self.matches(stats):
                matched = time.perf_counter() - edited
                break
        self.results["edit_to_match_s"] = matched
        self.results["edited_vs_f12"] = stats
        if matched is None:
            self.fail(f"the viewport did not come to match the edited scene (last: mean {stats[0] * 255:.2f}/255, "
                      f"{stats[1]:.1%} outliers)")

        # Quit while a render is in flight.
        self.edit(-0.5, ORANGE)
        yield 0.05
        self.results["busy_at_quit"] = any(s.busy() for s in self.viewport.live_sessions())
        self.results["quit_requested"] = True
        self.save()
        bpy.ops.wm.quit_blender()

    def step(self):
        try:
            return next(self.steps)
        except StopIteration:
            self.save()
            bpy.ops.wm.quit_blender()
        except Exception:
            self.fail("exception: " + traceback.format_exc())
            self.save()
            bpy.ops.wm.quit_blender()
        return None


def window_main(results_path):
    test = WindowTest(results_path)
    bpy.app.timers.register(test.step, first_interval=1.0)


if __name__ == "__main__":
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if "--gui" in argv:
        window_main(argv[argv.index("--gui") + 1])
    else:
        ru.run_test(background_main)
