# SPDX-License-Identifier: GPL-3.0-or-later
"""The Micropoly render engine as Blender sees it. The work happens in
export.py (scene -> native arrays) and the native module; this file runs a
render on a worker thread, keeps Blender informed, and writes the passes."""

import threading
import time

import bpy
import numpy as np

from . import export, export_mesh, final_renderers, native_module, preferences, viewport

PASSES = (("Depth", 1, "Z", "VALUE"), ("Normal", 3, "XYZ", "VECTOR"))


# The renderer final renders keep (final_renderers.py); tests read it here.
_final_renderers = final_renderers.shared()


def _shadow_degrades(shadows):
    """What keeping the shadow maps within their memory budget cost this
    frame, for the status line (docs/pipeline.md, "Pools and their budgets")."""
    notes = []
    if shadows.get("level_bias"):
        notes.append(f"{shadows['level_bias']} levels coarser to fit")
    if shadows.get("pages_missing"):
        notes.append(f"{shadows['pages_missing']:,} pages left out")
    if shadows.get("marking_passes"):
        notes.append("marking diced twice to fit")
    return f" ({', '.join(notes)})" if notes else ""


class MicropolyRenderEngine(bpy.types.RenderEngine):
    bl_idname = "MICROPOLY"
    bl_label = "Micropoly"
    bl_use_preview = False
    bl_use_postprocess = True
    bl_use_eevee_viewport = True  # Material Preview shading stays EEVEE's, as with Cycles

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._viewport = None        # viewport.ViewportSession while the view is Rendered
        self._viewport_meshes = None  # export_mesh.MeshCache kept between viewport updates
        self._viewport_texture = None
        self._viewport_signature = None
        self._viewport_export_error = None  # why the scene could not be exported, shown in the view

    def __del__(self):
        session = getattr(self, "_viewport", None)
        if session is not None:
            session.close()

    # ---- viewport (Rendered shading) ---------------------------------------
    def view_update(self, context, depsgraph):
        """The scene changed (or the view opened): forget the meshes whose
        geometry changed, export again and restart the refinement."""
        from . import viewport_draw

        first = self._viewport is None
        if first:
            try:
                from . import _native  # noqa: F401
            except ImportError as e:
                self.update_stats("", f"Micropoly: the native module did not load: {e}")
                return
            self._viewport = viewport.ViewportSession(preferences.device_selector(context))
            self._viewport_meshes = export_mesh.MeshCache()
            self._viewport_texture = viewport_draw.ViewportTexture()
        # Updates of the Scene alone also come from edits that change nothing
        # rendered (a new image data-block, selection): those are told apart
        # by the scene settings Micropoly reads.
        signature = viewport.scene_signature(depsgraph.scene)
        relevant = first or signature != self._viewport_signature
        for update in depsgraph.updates:
            if not isinstance(update.id, bpy.types.Scene):
                relevant = True
            if update.is_updated_geometry:
                self._viewport_meshes.forget(update.id.original)
        self._viewport_signature = signature
        if relevant:
            self._viewport_export(context, depsgraph)

    def _viewport_export(self, context, depsgraph):
        scene = depsgraph.scene
        view = viewport.view_from_context(context)
        try:
            exported = export.export_scene(depsgraph, view=view, meshes=self._viewport_meshes)
        except export.ExportError as e:
            self._viewport_export_error = f"Micropoly: {e}"
            self._viewport.cancel()
            return
        mp = scene.micropoly
        self._viewport_export_error = None
        self._viewport.request(exported, view, mp.viewport_samples, mp.viewport_shading_rate)

    def view_draw(self, context, depsgraph):
        """Draws the newest image; a changed view restarts the refinement."""
        from . import viewport_draw

        session = self._viewport
        if session is None:
            return
        view = viewport.view_from_context(context)
        if not viewport.same_view(view, session.view()):
            session.restart_view(view)
        image = session.image()
        if image is not None:
            viewport_draw.draw(self, depsgraph.scene, self._viewport_texture, image, view.width, view.height)
        error = session.error()
        if error:
            self.update_stats("", f"Micropoly: {error}")
        elif self._viewport_export_error:
            self.update_stats("", self._viewport_export_error)
        elif image is not None:
            state = "Done" if image.final and not session.busy() else "Refining"
            self.update_stats("", f"Micropoly | {session.device} | {state} | {image.samples} spp | "
                                  f"{image.stats.get('micropolygons', 0):,} micropolygons | {image.seconds:.2f} s")
        if session.busy():
            self.tag_redraw()  # draw again soon: the next pass is on its way

    # ---- final render ---------------------------------------------------------
    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        if renderlayer.use_pass_z:
            self.register_pass(scene, renderlayer, "Depth", 1, "Z", "VALUE")
        if renderlayer.use_pass_normal:
            self.register_pass(scene, renderlayer, "Normal", 3, "XYZ", "VECTOR")

    def render(self, depsgraph):
        try:
            from . import _native
        except ImportError as e:
            self.report({"ERROR"}, f"Micropoly: the native module did not load: {e}")
            return
        scene = depsgraph.scene
        view_layer = depsgraph.view_layer
        export_started = time.perf_counter()
        try:
            exported = export.export_final(depsgraph, self.frame_set)
        except export.ExportError as e:
            self.report({"ERROR"}, f"Micropoly: {e}")
            return
        for warning in exported.warnings:
            self.report({"WARNING"}, f"Micropoly: {warning}")
        native_scene = exported.scene
        native_scene.settings.depth_and_normal_passes = view_layer.use_pass_z or view_layer.use_pass_normal
        native_scene.settings.normal_pass = view_layer.use_pass_normal  # Depth needs no normals
        try:
            renderer = _final_renderers.acquire(preferences.device_selector(bpy.context))
        except RuntimeError as e:
            self.report({"ERROR"}, f"Micropoly: {native_module.device_error(e)}")
            return
        try:
            _final_renderers.last_timings = {"export_s": time.perf_counter() - export_started}
            self._render_with(renderer, scene, view_layer, exported, native_scene)
        finally:
            _final_renderers.release()

    def _render_with(self, renderer, scene, view_layer, exported, native_scene):
        self.update_stats("", f"Micropoly | {renderer.device} | {exported.summary}")

        outcome = {}
        progress = {"value": 0.0}
        cancel = threading.Event()

        def on_progress(value):
            progress["value"] = value
            return not cancel.is_set()

        def work():
            try:
                outcome["result"] = renderer.render(native_scene, on_progress)
            except Exception as e:  # reported on the render thread below
                outcome["error"] = e

        worker = threading.Thread(target=work, name="micropoly-render", daemon=True)
        started = time.perf_counter()
        worker.start()
        while worker.is_alive():
            worker.join(0.05)
            if self.should_cancel():
                cancel.set()
            self.update_progress(progress["value"])
        if "error" in outcome:
            error = outcome["error"]
            if isinstance(error, MemoryError):  # a host allocation outside the renderer's own phases
                error = "the computer ran out of memory while rendering: close other programs, or lower the " \
                        "resolution or the samples"
            self.report({"ERROR"}, f"Micropoly: {error}")
            _final_renderers.forget()
            return
        result = outcome["result"]
        stats = result["stats"]
        if stats["cancelled"] or cancel.is_set():
            return
        native_s = time.perf_counter() - started
        write_started = time.perf_counter()
        self._write_result(scene, view_layer, exported, result)
        _final_renderers.last_timings.update(native_s=native_s, native_total_s=stats["timings_ms"]["total"] / 1000.0,
                                             write_s=time.perf_counter() - write_started, buckets=stats["buckets"],
                                             program_build_s=stats["program_build_ms"] / 1000.0)
        mib = stats["bound_split_peak_bytes"] / 2**20
        shadows = stats["shadows"]
        shadow_note = (f"shadow maps {shadows['pages_requested']:,} pages, {shadows['peak_bytes'] / 2**20:.0f} of "
                       f"{shadows['budget_bytes'] / 2**20:.0f} MiB{_shadow_degrades(shadows)} | "
                       if shadows["lights"] else "")
        hidden = (f"{stats['subpatches_occluded']:,} hidden sub-patches culled | "
                  if stats["subpatches_occluded"] else "")
        buckets = f"{stats['buckets']} buckets | " if stats["buckets"] > 1 else ""
        self.update_stats("", f"Micropoly | {stats['device']} | {stats['micropolygons']:,} micropolygons | "
                              f"{hidden}{buckets}bound & split {mib:.1f} MiB | {shadow_note}"
                              f"{time.perf_counter() - started:.2f} s")

    def should_cancel(self):
        """Esc in Blender; a seam the tests use to cancel in background mode."""
        return self.test_break()

    def _write_result(self, scene, view_layer, exported, result):
        rgba = result["rgba"]
        height, width = rgba.shape[:2]
        if not scene.render.film_transparent:
            # An opaque film shows the world color behind objects, as Cycles does
            # (a world program the renderer has laid behind them already: its
            # alpha is 1 and its exported background colour black).
            alpha = rgba[..., 3:4]
            rgba = np.concatenate([rgba[..., :3] + (1.0 - alpha) * exported.background,
                                   np.ones_like(alpha)], axis=-1)
        x0, y0 = exported.crop_origin_bottom_left(width, height)
        render_result = self.begin_result(x0, y0, width, height, layer=view_layer.name)
        layer = render_result.layers[0]
        _set_pass(layer, "Combined", rgba)
        if view_layer.use_pass_z and "depth" in result:
            _set_pass(layer, "Depth", result["depth"][..., None])
        if view_layer.use_pass_normal and "normal" in result:
            _set_pass(layer, "Normal", result["normal"])
        self.end_result(render_result)


def _set_pass(layer, name, pixels):
    """Writes top-row-first pixels into a pass (Blender's rows run bottom up).
    foreach_set copies the buffer at once; Blender 4 and later take it as
    flat floats, 3.x as one row of channels per pixel (assigning the array
    instead goes through every element: 0.8 s for a 1080p image)."""
    render_pass = layer.passes.find_by_name(name, "")
    if render_pass is None:
        return
    rows = np.ascontiguousarray(pixels[::-1], dtype=np.float32).reshape(-1, pixels.shape[-1])
    for data in (rows.reshape(-1), rows):
        try:
            render_pass.rect.foreach_set(data)
            return
        except (AttributeError, TypeError, ValueError):
            continue
    render_pass.rect = rows


def register():
    _final_renderers.reopen()
    bpy.utils.register_class(MicropolyRenderEngine)


def unregister():
    bpy.utils.unregister_class(MicropolyRenderEngine)
    _final_renderers.drop()
