# SPDX-License-Identifier: GPL-3.0-or-later
"""Draws the viewport session's newest image into the 3D view with Blender's
gpu module (bgl is gone from newer Blender): a float texture, premultiplied
alpha blending, and the engine's display-space shader bound, so the view
transform, look and exposure are applied as for F12."""

import gpu
from gpu_extras.presets import draw_texture_2d


class ViewportTexture:
    """The GPU texture of one ViewportImage, remade only when a new image arrives."""

    def __init__(self):
        self._image = None
        self._texture = None

    def texture(self, image):
        if image is not self._image:
            flat = image.pixels.reshape(-1)
            buffer = gpu.types.Buffer("FLOAT", flat.size, flat)
            self._texture = gpu.types.GPUTexture((image.width, image.height), format="RGBA16F", data=buffer)
            self._image = image
        return self._texture


def draw(engine, scene, texture_cache, image, region_width, region_height):
    """Draws `image` over its part (crop) of a region_width x region_height view.
    An image of an older view size is stretched until the new one arrives."""
    x0, x1, y0, y1 = image.crop or (0.0, 1.0, 0.0, 1.0)
    left, right = x0 * region_width, x1 * region_width
    bottom, top = (1.0 - y1) * region_height, (1.0 - y0) * region_height
    texture = texture_cache.texture(image)
    gpu.state.blend_set("ALPHA_PREMULT")
    engine.bind_display_space_shader(scene)
    try:
        draw_texture_2d(texture, (left, bottom), right - left, top - bottom)
    finally:
        engine.unbind_display_space_shader()
        gpu.state.blend_set("NONE")

