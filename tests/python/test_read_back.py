"""The image's read-back formats through the Python module, as the viewport
uses them (RenderSettings.read_back): half floats are the nearest halves to
the float image, rounded as NumPy rounds (IEEE 754 round-to-nearest-even),
and NONE brings back no pixels but the frame's statistics."""

import numpy as np

from micropoly import _native
from test_device_faults import make_scene


def test_half_floats_are_numpys_nearest_halves_of_the_float_image():
    renderer = _native.Renderer()
    full = renderer.render(make_scene())
    scene = make_scene()
    scene.settings.read_back = _native.ReadBack.HALF
    half = renderer.render(scene)
    assert half["rgba"].dtype == np.float32 and half["rgba"].shape == full["rgba"].shape
    assert full["rgba"][..., 3].sum() > 1000.0  # the cube covers much of the frame
    expected = full["rgba"].astype(np.float16).astype(np.float32)
    np.testing.assert_array_equal(half["rgba"], expected)
    assert not np.array_equal(half["rgba"], full["rgba"])  # rounded, not the floats themselves
    np.testing.assert_array_equal(half["depth"], full["depth"])  # the passes stay floats
    np.testing.assert_array_equal(half["normal"], full["normal"])
    timings = half["stats"]["timings_ms"]
    # A frame rendered at once waits for its own read-back.
    assert timings["readback"] > 0.0 and timings["readback_wait"] > 0.0


def test_none_brings_back_no_pixels_and_the_next_frame_all_of_them():
    renderer = _native.Renderer()
    scene = make_scene()
    scene.settings.read_back = _native.ReadBack.NONE
    nothing = renderer.render(scene)
    assert nothing["rgba"].shape == (0, 0, 4)
    assert nothing["stats"]["width"] == 96 and nothing["stats"]["micropolygons"] > 0
    scene.settings.read_back = _native.ReadBack.FLOAT
    np.testing.assert_array_equal(renderer.render(scene)["rgba"], _native.Renderer().render(make_scene())["rgba"])
