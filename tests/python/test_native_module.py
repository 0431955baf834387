"""micropoly._native from Python: numpy in, numpy images and stats out."""

import math

import numpy as np
import pytest

from micropoly import _native
from scene_helpers import look_at


def make_scene(width=160, height=120, samples=16):
    scene = _native.Scene()
    scene.settings.width = width
    scene.settings.height = height
    scene.settings.samples = samples
    scene.settings.filter = _native.PixelFilter.BOX
    scene.settings.filter_width = 1.0
    scene.add_material(name="grey", model="matte", color=[0.5, 0.5, 0.5], ka=1.0, kd=1.0)
    scene.add_light("distant", intensity=1.0, direction=[0.0, 0.0, -1.0])
    return scene


def square(scene, half=1.0, z=0.0, **kwargs):
    points = np.array([[-half, -half, z], [half, -half, z], [half, half, z], [-half, half, z]], dtype=np.float32)
    scene.add_mesh("square", points, np.array([4], dtype=np.int32), np.arange(4, dtype=np.int32), **kwargs)


@pytest.fixture(scope="module")
def renderer():
    return _native.Renderer()


def test_square_round_trips_to_an_image(renderer):
    scene = make_scene()
    scene.set_camera(look_at((0, 0, 4), (0, 0, 0)), fov_degrees=45.0)
    square(scene)
    result = renderer.render(scene)
    rgba = result["rgba"]
    assert rgba.shape == (120, 160, 4) and rgba.dtype == np.float32
    assert result["depth"].shape == (120, 160)
    assert result["normal"].shape == (120, 160, 3)
    # Coverage equals the square's projected area: side 2 at distance 4.
    t = math.tan(math.radians(45.0) / 2)
    side_px = 2.0 / (4.0 * t) * (120 / 2.0)
    assert rgba[..., 3].sum() == pytest.approx(side_px * side_px, rel=0.01)
    # A matte surface lit head-on by a unit distant light: Cs * Kd * 1.
    centre = rgba[60, 80]
    assert centre[3] == pytest.approx(1.0)
    np.testing.assert_allclose(centre[:3], [0.5, 0.5, 0.5], rtol=1e-4)
    assert result["depth"][60, 80] == pytest.approx(4.0, rel=1e-4)
    assert result["depth"][0, 0] > 1e9  # nothing there
    stats = result["stats"]
    assert stats["micropolygons"] > 0 and stats["patches"] == 1
    for key in ("upload", "bound_split", "dice", "shade", "sample", "resolve", "total"):
        assert stats["timings_ms"][key] >= 0.0


def test_world_transform_is_row_major_like_blender(renderer):
    scene = make_scene(64, 64, 4)
    scene.set_camera(look_at((0, 0, 10), (0, 0, 0)), fov_degrees=30.0)
    m = np.identity(4, dtype=np.float32)
    m[0, 3] = 100.0  # moved far to the right: out of view
    square(scene, object_to_world=m)
    assert renderer.render(scene)["rgba"][..., 3].sum() == 0.0


def test_bad_input_raises_a_clear_error(renderer):
    scene = make_scene(32, 32, 1)
    points = np.array([[0, 0, 0], [1, 0, 0], [np.nan, 1, 0]], dtype=np.float32)
    scene.add_mesh("broken", points, np.array([3], dtype=np.int32), np.arange(3, dtype=np.int32))
    with pytest.raises(_native.Error, match="broken"):
        renderer.render(scene)
    scene = make_scene(32, 32, 1)
    points = np.zeros((3, 3), dtype=np.float32)
    scene.add_mesh("bad_index", points, np.array([3], dtype=np.int32), np.array([0, 1, 7], dtype=np.int32))
    with pytest.raises(RuntimeError, match="out of range"):
        renderer.render(scene)
    with pytest.raises(_native.Error, match="object_color"):
        scene.add_mesh("odd_colour", points, np.array([3], dtype=np.int32), np.arange(3, dtype=np.int32),
                       object_color=[1.0, 0.5, 0.2])
    with pytest.raises(_native.Error):
        scene.add_light("laser")
    with pytest.raises(_native.Error):
        _native.Renderer("no-such-device")
    for width in (float("nan"), -1.0, 17.0):
        scene = make_scene(32, 32, 1)
        square(scene)
        scene.settings.texture_filter_width = width
        with pytest.raises(_native.Error, match="texture filter width"):
            renderer.render(scene)


def test_progress_callback_can_cancel(renderer):
    scene = make_scene(128, 128, 4)
    scene.set_camera(look_at((0, 0, 4), (0, 0, 0)), fov_degrees=45.0)
    square(scene)
    calls = []

    def progress(p):
        calls.append(p)
        return False

    result = renderer.render(scene, progress)
    assert calls and result["stats"]["cancelled"]


def test_lists_devices():
    devices = _native.list_devices()
    assert devices and {"index", "name", "platform", "type"} <= set(devices[0])
