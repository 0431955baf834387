"""Scene.add_curves from Python: curves become round tubes of 4 patches per
segment, or ribbons of one, that render where the curve runs, bad curves
are skipped and counted, and malformed arrays are refused with a message,
never a crash."""

import numpy as np
import pytest

from micropoly import _native
from scene_helpers import look_at


def base():
    s = _native.Scene()
    s.settings.width, s.settings.height = 96, 64
    s.set_camera(look_at((0.0, -6.0, 0.0), (0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0)), fov_degrees=40.0)
    s.add_light("distant", direction=[-0.3, 0.5, -1.0])
    return s


def strands(n, keys=4):
    points = np.zeros((n, keys, 3), dtype=np.float32)
    points[..., 0] = np.linspace(-1.5, 1.5, n)[:, None]
    points[..., 2] = np.linspace(-1.0, 1.0, keys)[None, :]
    offsets = np.arange(0, n * keys + 1, keys, dtype=np.int32)
    return points.reshape(-1, 3), np.full(n * keys, 0.05, np.float32), offsets


@pytest.mark.parametrize("ribbons", [False, True])
def test_curves_render_as_tubes_or_ribbons(ribbons):
    s = base()
    points, radii, offsets = strands(4)
    assert s.add_curves("hair", points, radii, offsets, ribbons=ribbons) == 0
    assert s.patch_set_count == 1
    r = _native.Renderer().render(s)
    alpha = np.asarray(r["rgba"])[..., 3]
    # Four strands 0.1 wide and 2 long, 6 away; fov 40 degrees over the 64 rows.
    px = 32.0 / (6.0 * np.tan(np.radians(20.0)))
    assert alpha.sum() == pytest.approx(4 * 0.1 * 2.0 * px * px, rel=0.03)


def test_bad_curves_are_skipped_and_counted():
    s = base()
    points, radii, offsets = strands(4)
    radii[5] = np.nan  # curve 1
    points[9, 0] = np.inf  # curve 2
    assert s.add_curves("hair", points, radii, offsets) == 2
    lone = np.array([[0.0, 0.0, 0.0]], np.float32)
    assert s.add_curves("dot", lone, np.ones(1, np.float32), np.array([0, 1], np.int32)) == 1


@pytest.mark.parametrize("offsets, message", [
    (np.array([0, 4, 8], np.int32), "the offsets must run from 0 to the number of points"),
    (np.array([0, 10, 6, 16], np.int32), "the offsets must not decrease"),
])
def test_malformed_offsets_are_refused(offsets, message):
    s = base()
    points, radii, _ = strands(4)
    with pytest.raises(RuntimeError, match=message):
        s.add_curves("bad", points, radii, offsets)


@pytest.mark.parametrize("ribbons", [False, True])
def test_moving_curves_blur_along_their_motion(ribbons):
    # Strands moving 1 unit along x during the shutter cover a wider band,
    # as much alpha in all, centred where they are at the shutter's centre.
    still, moving = base(), base()
    points, radii, offsets = strands(1)
    still.add_curves("hair", points, radii, offsets, ribbons=ribbons)
    steps = np.stack([points + np.array([dx, 0.0, 0.0], np.float32) for dx in (-0.5, 0.0, 0.5)])
    moving.set_motion(3)
    moving.add_curves("hair", points, radii, offsets, motion_points=steps, ribbons=ribbons)
    a = np.asarray(_native.Renderer().render(still)["rgba"])[..., 3]
    b = np.asarray(_native.Renderer().render(moving)["rgba"])[..., 3]
    assert b.sum() == pytest.approx(a.sum(), rel=0.05)
    cols = np.arange(a.shape[1])
    assert (b.sum(0) > 0.01).sum() > 3 * (a.sum(0) > 0.01).sum()
    assert (b.sum(0) * cols).sum() / b.sum() == pytest.approx((a.sum(0) * cols).sum() / a.sum(), abs=1.0)


def test_motion_of_another_shape_is_refused():
    s = base()
    points, radii, offsets = strands(2)
    with pytest.raises(RuntimeError, match="motion step 0 has 4 points, not 8"):
        s.add_curves("hair", points, radii, offsets, motion_points=np.zeros((3, 4, 3), np.float32))
    with pytest.raises(RuntimeError, match="a motion point is not finite"):
        s.add_curves("hair", points, radii, offsets, motion_points=np.full((3, 8, 3), np.nan, np.float32))
