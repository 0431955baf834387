# SPDX-License-Identifier: GPL-3.0-or-later
"""Rendered viewport shading: a session that renders the current view on a
worker thread, progressively, and is restarted whenever the view or the
scene changes.

Blender's UI thread only exports (view_update) and draws the newest image
(view_draw, viewport_draw.py); the native renderer runs with the GIL released
on the session's thread, which owns one native Renderer for the session's
lifetime, so kernels are built once. A newer request cancels the render in
flight at its next progress check (between bound & split launches and sample
chunks). Refinement follows `refinement_passes`: a quarter-resolution image
with one sample first, then the full view at the viewport sample count."""

import atexit
import math
import threading
import time
import weakref
from dataclasses import dataclass, field, replace

import numpy as np

from . import camera_view, export


def refinement_passes(samples, shading_rate):
    """(resolution divisor, samples per pixel, shading rate) per pass: a
    quarter-resolution image at one sample, then the full view at the
    viewport's samples. Shading rates are in the pass's own pixels; the first
    pass's micropolygons are 4x larger still (8x8 final pixels at rate 1):
    it is a preview, replaced within about a second. There is no
    full-resolution 1-sample pass in between: dicing and shading cost the
    same at any sample count (Reyes shades grid vertices, not samples), so it
    would nearly double the time to the final image (bench/viewport_bench.py:
    3.4 s instead of 2.0 s on PoCL at 1.5M micropolygons)."""
    return [(4, 1, 4.0 * shading_rate), (1, samples, shading_rate)]


# ---------------------------------------------------------------------------
# The view


def _window_from_projection(p, orthographic):
    """Screen window (left, right, bottom, top) and clip range of an OpenGL
    projection matrix (numpy, row-major as Blender's Matrix reads)."""
    if orthographic:
        window = ((-1 - p[0, 3]) / p[0, 0], (1 - p[0, 3]) / p[0, 0],
                  (-1 - p[1, 3]) / p[1, 1], (1 - p[1, 3]) / p[1, 1])
        near, far = (p[2, 3] + 1) / p[2, 2], (p[2, 3] - 1) / p[2, 2]
    else:
        window = ((-1 + p[0, 2]) / p[0, 0], (1 + p[0, 2]) / p[0, 0],
                  (-1 + p[1, 2]) / p[1, 1], (1 + p[1, 2]) / p[1, 1])
        near, far = p[2, 3] / (p[2, 2] - 1), p[2, 3] / (p[2, 2] + 1)
    return tuple(float(x) for x in window), float(near), float(far)


def view_from_matrices(view_matrix, window_matrix, orthographic, width, height, crop=None, lens_camera=None):
    view = np.array(view_matrix, dtype=np.float32).reshape(4, 4)
    proj = np.array(window_matrix, dtype=np.float64).reshape(4, 4)
    window, near, far = _window_from_projection(proj, orthographic)
    if orthographic and near < 1e-3:
        # An orthographic viewport clips symmetrically around its view point,
        # and Micropoly renders only in front of the camera: the camera steps
        # back along its axis until the near plane is in front of it.
        shift = 1e-3 - near
        view = view.copy()
        view[2, 3] -= shift
        near, far = near + shift, far + shift
    return export.ViewCamera(width=width, height=height, world_to_camera=view, orthographic=orthographic,
                             screen_window=window, clip_near=max(near, 1e-6), clip_far=max(far, near + 1e-3),
                             crop=crop, lens_camera=lens_camera)


def _camera_frame_in_region(context, scene):
    """The scene camera's frame in region pixels (xmin, xmax, ymin, ymax,
    y up), from the corners Blender draws as the camera border."""
    from bpy_extras.view3d_utils import location_3d_to_region_2d

    cam = scene.camera
    corners = [cam.matrix_world @ v for v in cam.data.view_frame(scene=scene)]
    pts = [location_3d_to_region_2d(context.region, context.region_data, c) for c in corners]
    if any(p is None for p in pts):
        return None
    xs, ys = [p.x for p in pts], [p.y for p in pts]
    return min(xs), max(xs), min(ys), max(ys)


def _crop(x0, x1, y0, y1, width, height):
    """Region pixels (y up) -> crop fractions with y0 at the top, or None."""
    c = (min(max(x0 / width, 0.0), 1.0), min(max(x1 / width, 0.0), 1.0),
         min(max(1.0 - y1 / height, 0.0), 1.0), min(max(1.0 - y0 / height, 0.0), 1.0))
    return c if c[1] > c[0] and c[3] > c[2] else None


def view_from_context(context):
    """The ViewCamera of the 3D viewport being drawn: its own view and
    projection (scene camera view included, with its zoom and offset), and
    the render border (the scene's in camera view, the viewport's otherwise)."""
    region, rv3d, space = context.region, context.region_data, context.space_data
    scene = context.scene
    width, height = region.width, region.height
    crop, lens_camera = None, None
    if rv3d.view_perspective == "CAMERA" and scene.camera is not None:
        lens_camera = scene.camera  # through the camera, its depth of field shows, as in Cycles
        if scene.render.use_border:
            frame = _camera_frame_in_region(context, scene)
            if frame is not None:
                fx0, fx1, fy0, fy1 = frame
                r = scene.render
                crop = _crop(fx0 + r.border_min_x * (fx1 - fx0), fx0 + r.border_max_x * (fx1 - fx0),
                             fy0 + r.border_min_y * (fy1 - fy0), fy0 + r.border_max_y * (fy1 - fy0), width, height)
    elif getattr(space, "use_render_border", False):
        crop = _crop(space.render_border_min_x * width, space.render_border_max_x * width,
                     space.render_border_min_y * height, space.render_border_max_y * height, width, height)
    return view_from_matrices(rv3d.view_matrix, rv3d.window_matrix, not rv3d.is_perspective, width, height, crop,
                              lens_camera)


def view_from_camera(scene, depsgraph, width, height):
    """The scene camera as a ViewCamera (what the viewport shows in camera
    view with the frame filling the region): for benchmarks and tests."""
    cam = scene.camera.evaluated_get(depsgraph)
    view = camera_view.view_matrix(cam)
    proj = cam.calc_matrix_camera(depsgraph, x=width, y=height)
    return view_from_matrices(view, proj, cam.data.type == "ORTHO", width, height, lens_camera=cam)


def scene_signature(scene):
    """What of the Scene data-block itself a viewport render depends on:
    frame, camera, world, film and border settings and Micropoly's settings."""
    r, mp = scene.render, scene.micropoly
    settings = tuple(getattr(mp, name) for name in mp.bl_rna.properties.keys() if name != "rna_type")
    world = scene.world
    return (scene.frame_current, scene.frame_subframe, scene.camera.name if scene.camera else None,
            world.name if world else None, tuple(world.color) if world else None, r.film_transparent,
            r.use_border, r.border_min_x, r.border_max_x, r.border_min_y, r.border_max_y, settings)


def same_view(a, b):
    if a is None or b is None:
        return a is b
    return (a.width == b.width and a.height == b.height and a.orthographic == b.orthographic
            and a.crop == b.crop and np.array_equal(a.world_to_camera, b.world_to_camera)
            and np.allclose(a.screen_window, b.screen_window, rtol=0, atol=1e-7)
            and a.clip_near == b.clip_near and a.clip_far == b.clip_far)


# ---------------------------------------------------------------------------
# The session


@dataclass
class ViewportImage:
    """One finished pass: premultiplied scene-linear RGBA, rows bottom first
    (as textures want them), covering `crop` of a width x height view."""
    pixels: np.ndarray
    width: int
    height: int
    crop: tuple
    samples: int
    final: bool
    generation: int
    seconds: float  # since the request that started this refinement
    stats: dict = field(default_factory=dict)


# Live sessions, weakly held: lets scripts and tests wait for a viewport to
# finish refining (live_sessions()); owning them is the engines' business.
_LIVE = weakref.WeakSet()


def live_sessions():
    return list(_LIVE)


# How long quitting waits for a render in flight to reach its next progress
# check. A kernel or program build checks none until it ends: on a CPU
# device with empty caches that is several seconds, more on a loaded
# machine (a test suite's quit mid-render, with two tests per core, outwaited
# 2 s and crashed). Quitting waits for it rather than crash.
CLOSE_AT_EXIT_S = 120.0


def _close_live_sessions():
    # When Python shuts down (Blender quits, or a background script fails)
    # with a render in flight, a worker thread inside the native renderer
    # would be torn down as it next takes the GIL, which aborts the process.
    # Stop every session first: each returns at its next progress check.
    for session in list(_LIVE):
        session.close(timeout=CLOSE_AT_EXIT_S)


atexit.register(_close_live_sessions)


class ViewportSession:
    """Renders the newest (scene, view) request on a worker thread."""

    def __init__(self, device_selector):
        self._selector = device_selector
        self._cond = threading.Condition()
        self._generation = 0
        self._job = None          # (generation, native scene, view, background, samples, rate, requested at)
        self._image = None
        self._error = None
        self._fatal = None        # the renderer could not be made: every request gets this error
        self._busy = False
        self._stop = False
        self.device = ""
        self._thread = threading.Thread(target=self._run, name="micropoly-viewport", daemon=True)
        self._thread.start()
        _LIVE.add(self)

    # ---- UI thread -------------------------------------------------------
    def request(self, exported, view, samples, shading_rate):
        """Renders `exported` (an ExportedScene nobody else will touch) from
        `view`, cancelling whatever is in flight."""
        with self._cond:
            self._generation += 1
            self._job = (self._generation, exported, view, samples, shading_rate, time.perf_counter())
            self._busy = self._fatal is None
            self._error = self._fatal
            self._cond.notify()
        return self._generation

    def restart_view(self, view):
        """Same scene, new view."""
        with self._cond:
            if self._job is None:
                return None
            _, exported, _, samples, rate, _ = self._job
        return self.request(exported, view, samples, rate)

    def cancel(self):
        """Stops the render in flight (the scene can no longer be exported)."""
        with self._cond:
            self._generation += 1
            self._job = None
            self._image = None
            self._busy = False
            self._cond.notify_all()

    def view(self):
        with self._cond:
            return self._job[2] if self._job else None

    def image(self):
        with self._cond:
            return self._image

    def error(self):
        with self._cond:
            return self._error

    def busy(self):
        with self._cond:
            return self._busy

    def wait_idle(self, timeout):
        """For scripts and benchmarks: waits until the newest request is done."""
        deadline = time.perf_counter() + timeout
        with self._cond:
            while self._busy and not self._stop:
                left = deadline - time.perf_counter()
                if left <= 0:
                    return False
                self._cond.wait(left)
        return True

    def close(self, timeout=2.0):
        """Cancels the render in flight and ends the worker thread."""
        with self._cond:
            self._stop = True
            self._cond.notify_all()
        if threading.current_thread() is not self._thread:
            self._thread.join(timeout)

    # ---- worker thread ---------------------------------------------------
    def _current(self, generation):
        return not self._stop and self._generation == generation

    def _run(self):
        try:
            from . import _native, warm_up

            warm_up.yield_to_render()  # it is building what this renderer would build
            renderer = _native.Renderer(self._selector)
            self.device = renderer.device
        except Exception as e:  # no device, kernels that do not build
            from . import native_module

            with self._cond:
                self._fatal = self._error = native_module.device_error(e)
                self._busy = False
                self._cond.notify_all()
            return
        while True:
            with self._cond:
                while not self._stop and (self._job is None or not self._busy):
                    self._cond.wait()
                if self._stop:
                    return
                job = self._job
            try:
                self._refine(renderer, *job)
            except Exception as e:  # reported in the viewport, the session goes on
                with self._cond:
                    if self._generation == job[0]:
                        self._error = str(e)
            with self._cond:
                if self._generation == job[0]:
                    self._busy = False
                self._cond.notify_all()

    def _refine(self, renderer, generation, exported, view, samples, shading_rate, requested):
        from . import _native

        native = exported.scene
        passes = refinement_passes(samples, shading_rate)
        try:
            for k, (divisor, spp, rate) in enumerate(passes):
                if not self._current(generation):
                    return
                w, h = max(1, math.ceil(view.width / divisor)), max(1, math.ceil(view.height / divisor))
                replace(view, width=w, height=h).apply(native)
                native.settings.samples = spp
                native.settings.shading_rate = rate
                native.settings.depth_and_normal_passes = False  # the viewport draws colour only
                # It draws half floats (viewport_draw.py), so half the bytes come back.
                native.settings.read_back = _native.ReadBack.HALF
                # The preview's penumbrae read the pages the first marking makes
                # (coarser near contact); the final pass adds the finer ones. Its
                # shadow maps keep the final pass's dicing, so that the pages of
                # both stay in the renderer for the next request.
                native.settings.soft_shadow_pages = k == len(passes) - 1
                result = renderer.render(native, lambda p: self._current(generation))
                if result["stats"]["cancelled"] or not self._current(generation):
                    return
                rgba = result["rgba"]
                if not exported.transparent:  # a world program lies behind already (alpha 1)
                    alpha = rgba[..., 3:4]
                    rgba = np.concatenate([rgba[..., :3] + (1.0 - alpha) * exported.background,
                                           np.ones_like(alpha)], axis=-1)
                image = ViewportImage(np.ascontiguousarray(rgba[::-1], dtype=np.float32), w, h, view.crop, spp,
                                      k == len(passes) - 1, generation, time.perf_counter() - requested,
                                      result["stats"])
                with self._cond:
                    if self._generation == generation:
                        self._image = image
        finally:
            native.settings.soft_shadow_pages = True  # a view change renders this scene again
