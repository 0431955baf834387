# SPDX-License-Identifier: GPL-3.0-or-later
"""F12 rendering: export, render in the native module, write the result."""

import numpy as np

from . import _native, export


def render_final(engine, depsgraph):
    try:
        native_scene = export.export_scene(depsgraph)
        renderer = _native.Renderer()
        engine.update_stats("", f"Micropoly: rendering on {renderer.device}")

        def progress(p):
            engine.update_progress(p)
            return not engine.test_break()

        result = renderer.render(native_scene, progress)
    except RuntimeError as e:
        engine.report({"ERROR"}, f"Micropoly: {e}")
        return
    stats = result["stats"]
    if stats["cancelled"]:
        return
    rgba = result["rgba"]
    scene = depsgraph.scene
    if not scene.render.film_transparent and scene.world is not None:
        # An opaque film shows the world color behind the objects, as Cycles does.
        alpha = rgba[..., 3:4]
        background = np.array(list(scene.world.color), dtype=np.float32)
        rgba = np.concatenate([rgba[..., :3] + (1.0 - alpha) * background, np.ones_like(alpha)], axis=-1)
    height, width = rgba.shape[:2]
    settings = native_scene.settings
    x0 = int(settings.crop_x0 * settings.width) if settings.crop_x0 > 0 else 0
    y_top = int(settings.crop_y0 * settings.height) if settings.crop_y0 > 0 else 0
    y0 = settings.height - y_top - height  # Blender's rows run bottom to top
    render_result = engine.begin_result(x0, y0, width, height)
    combined = render_result.layers[0].passes["Combined"]
    combined.rect = np.ascontiguousarray(rgba[::-1]).reshape(-1, 4)
    engine.end_result(render_result)
    engine.update_stats("", f"Micropoly: {stats['micropolygons']} micropolygons on {stats['device']}, "
                            f"{stats['timings_ms']['total']:.0f} ms")
