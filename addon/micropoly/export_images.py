# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender images -> native texture images (RGBA float).

Pixels come through foreach_get into numpy. 8-bit images in the sRGB colour
space stay sRGB-encoded and are decoded on the device after filtering, as
Cycles does with them; float images already hold linear values; data images
(Non-Color) are passed through."""

import numpy as np

# Colour spaces whose 8-bit values are taken as they are.
LINEAR_SPACES = {"Linear", "Linear Rec.709", "Linear CIE-XYZ E", "Raw", "Non-Color", "Scene Linear"}


def image_pixels(image, warn):
    """((height, width, 4) float32 RGBA, whether it is sRGB-encoded), or
    (None, False) when the image has no pixels (a missing file)."""
    width, height = (int(x) for x in image.size)
    if width == 0 or height == 0:
        warn(f"image '{image.name}' has no pixels (is its file missing?); it renders magenta")
        return None, False
    if image.source in ("SEQUENCE", "MOVIE", "TILED"):
        warn(f"image '{image.name}' is a {image.source.lower()} image; only its current frame or first tile is used")
    channels = int(image.channels)
    flat = np.empty(width * height * channels, dtype=np.float32)
    image.pixels.foreach_get(flat)
    px = flat.reshape(height, width, channels)
    rgba = np.ones((height, width, 4), dtype=np.float32)
    if channels >= 3:
        rgba[..., :3] = px[..., :3]
        if channels == 4:
            rgba[..., 3] = px[..., 3]
    else:
        rgba[..., :3] = px[..., :1]
        if channels == 2:
            rgba[..., 3] = px[..., 1]
    space = image.colorspace_settings.name
    srgb = False
    if not image.is_float and not image.colorspace_settings.is_data:
        if space == "sRGB":
            srgb = True
        elif space not in LINEAR_SPACES:
            warn(f"image '{image.name}': colour space {space} is not supported; its values are used as linear")
    if image.alpha_mode == "NONE":
        rgba[..., 3] = 1.0
    return np.nan_to_num(rgba, nan=0.0, posinf=0.0, neginf=0.0), srgb


class ImageTable:
    """One native image per Blender image, exported on first use; images
    computed in memory (a Sky Texture's) under keys of their own."""

    def __init__(self, native_scene):
        self.native = native_scene
        self.index = {}

    def get(self, image, warn):
        """(native index or -1, the (lowest, highest) value its colour
        channels hold, or None): 8-bit images hold [0, 1], a float image
        what its pixels hold (so a displacement it drives has a bound)."""
        if image is None:
            warn("has no image; it renders magenta")
            return -1, None
        key = image.name_full if hasattr(image, "name_full") else image.name
        if key not in self.index:
            pixels, srgb = image_pixels(image, warn)
            if pixels is None:
                self.index[key] = -1, None
            else:
                rgb = pixels[..., :3]
                value_range = (0.0, 1.0) if not image.is_float else (float(rgb.min()), float(rgb.max()))
                self.index[key] = self.native.add_image(key, pixels, srgb=srgb), value_range
        return self.index[key]

    def array(self, key, pixels):
        """Native index of a (height, width, 4) float RGBA image held in
        memory (scene-linear, rows bottom to top), one per `key` (a hashable
        naming its content). `pixels` is the array or a function making it,
        called on the key's first use only."""
        table_key = ("array", key)
        if table_key not in self.index:
            rgba = np.asarray(pixels() if callable(pixels) else pixels, dtype=np.float32)
            if rgba.ndim != 3 or rgba.shape[2] != 4:
                raise ValueError(f"an in-memory image must be (height, width, 4), not {rgba.shape}")
            rgba = np.ascontiguousarray(np.nan_to_num(rgba, nan=0.0, posinf=0.0, neginf=0.0))
            name = key[0] if isinstance(key, tuple) and key else str(key)
            self.index[table_key] = self.native.add_image(str(name), rgba, srgb=False)
        return self.index[table_key]
