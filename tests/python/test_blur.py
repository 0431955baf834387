"""Motion blur and depth of field through micropoly._native, against what
geometry says: coverage is conserved, a blurred square spreads exactly as
far as it travels (or as its circle of confusion reaches), what is in focus
stays sharp, and bad motion data is refused with a reason."""

import math

import numpy as np
import pytest

from micropoly import _native
from scene_helpers import look_at

W, H = 160, 120
FOV = 45.0
FOCAL_PX = (H / 2.0) / math.tan(math.radians(FOV) / 2.0)  # the shorter side spans [-1, 1]


def square_scene(half=0.3, z=0.0, samples=64):
    scene = _native.Scene()
    scene.settings.width, scene.settings.height, scene.settings.samples = W, H, samples
    scene.settings.filter = _native.PixelFilter.BOX
    scene.settings.filter_width = 1.0
    scene.add_material(name="white", model="constant", color=[1.0, 1.0, 1.0])
    points = np.array([[-half, -half, z], [half, -half, z], [half, half, z], [-half, half, z]], dtype=np.float32)
    scene.add_mesh("square", points, np.array([4], dtype=np.int32), np.arange(4, dtype=np.int32))
    scene.set_camera(look_at((0, 0, 4), (0, 0, 0)), fov_degrees=FOV)
    return scene


def translate(x, y=0.0):
    m = np.identity(4, dtype=np.float32)
    m[0, 3], m[1, 3] = x, y
    return m


def columns_covered(alpha):
    """Columns whose middle row has any coverage."""
    return np.nonzero(alpha[H // 2] > 0.0)[0]


@pytest.fixture(scope="module")
def renderer():
    return _native.Renderer()


def test_moving_square_conserves_coverage_and_spreads_by_its_travel(renderer):
    still = renderer.render(square_scene())["rgba"][..., 3]
    scene = square_scene()
    travel = 0.8  # scene units over the shutter, at distance 4
    scene.set_motion(3)
    scene.set_mesh_motion(0, object_to_world=np.stack([translate(-travel / 2), translate(0), translate(travel / 2)]))
    moving = renderer.render(scene)["rgba"][..., 3]
    # Coverage is the square's area whatever it does during the shutter.
    assert moving.sum() == pytest.approx(still.sum(), rel=0.01)
    # It spreads along x by its travel on screen, and not along y.
    cols_still, cols_moving = columns_covered(still), columns_covered(moving)
    spread = (cols_moving[-1] - cols_moving[0]) - (cols_still[-1] - cols_still[0])
    assert spread == pytest.approx(travel / 4.0 * FOCAL_PX, abs=2.0)
    rows = lambda a: np.nonzero(a[:, W // 2] > 0.0)[0]  # noqa: E731
    assert len(rows(moving)) == len(rows(still))
    # The middle of the path is covered while the square passes over it:
    # its width over its travel of the shutter; the path's ends far less.
    assert moving[H // 2, W // 2] == pytest.approx(0.6 / travel, abs=0.06)
    assert moving[H // 2, cols_moving[0]] < 0.2 and moving[H // 2, cols_moving[-1]] < 0.2


def test_shutter_curve_weights_time(renderer):
    """A shutter closing linearly (openness 1 -> 0) sees the start of the
    path more: the coverage's centroid lies a third of the travel along."""
    travel = 0.8

    def centroid(curve):
        scene = square_scene()
        scene.set_motion(2, shutter_curve=np.array(curve, dtype=np.float32))
        scene.set_mesh_motion(0, object_to_world=np.stack([translate(-travel / 2), translate(travel / 2)]))
        alpha = renderer.render(scene)["rgba"][..., 3]
        cols = np.arange(W) + 0.5
        return (alpha.sum(axis=0) * cols).sum() / alpha.sum()

    px = travel / 4.0 * FOCAL_PX  # the travel on screen
    start = W / 2 - px / 2
    assert centroid([]) == pytest.approx(start + px / 2, abs=0.3)
    assert centroid([1.0, 0.0]) == pytest.approx(start + px / 3, abs=0.4)
    assert centroid([0.0, 1.0]) == pytest.approx(start + 2 * px / 3, abs=0.4)


def test_moving_camera_is_motion_too(renderer):
    """The camera sliding right is the square sliding left."""
    scene = square_scene()
    scene.set_motion(2)
    eye = [look_at((x, 0, 4), (x, 0, 0)) for x in (-0.4, 0.4)]
    scene.set_motion(2, camera_world_to_camera=np.stack(eye))
    by_camera = renderer.render(scene)["rgba"][..., 3]
    scene = square_scene()
    scene.set_motion(2)
    scene.set_mesh_motion(0, object_to_world=np.stack([translate(0.4), translate(-0.4)]))
    by_object = renderer.render(scene)["rgba"][..., 3]
    assert np.abs(by_camera - by_object).max() < 0.2  # the same but for sample noise
    assert np.abs(by_camera - by_object).mean() < 0.01


def test_deformation_moves_points(renderer):
    scene = square_scene()
    pts = np.array([[-0.3, -0.3, 0], [0.3, -0.3, 0], [0.3, 0.3, 0], [-0.3, 0.3, 0]], dtype=np.float32)
    grown = pts * np.array([2.0, 1.0, 1.0], dtype=np.float32)
    scene.set_motion(2)
    scene.set_mesh_motion(0, points=np.stack([pts, grown]))
    alpha = renderer.render(scene)["rgba"][..., 3]
    # The right edge sweeps from 0.3 to 0.6: covered a fraction of the shutter.
    cols = columns_covered(alpha)
    assert (cols[-1] - W / 2) == pytest.approx(0.6 / 4.0 * FOCAL_PX, abs=2.5)
    assert alpha.sum() == pytest.approx(1.5 * (0.6 / 4.0 * FOCAL_PX) ** 2, rel=0.02)


def test_defocus_conserves_coverage_and_spreads_by_the_circle_of_confusion(renderer):
    still = renderer.render(square_scene(z=1.0))["rgba"][..., 3]
    scene = square_scene(z=1.0)
    radius, focus = 0.2, 6.0  # the square is 3 units away
    scene.set_depth_of_field(radius, focus)
    blurred = renderer.render(scene)["rgba"][..., 3]
    assert blurred.sum() == pytest.approx(still.sum(), rel=0.01)
    coc = FOCAL_PX * radius * abs(1.0 / focus - 1.0 / 3.0)  # raster radius
    cols_still, cols_blurred = columns_covered(still), columns_covered(blurred)
    spread = (cols_blurred[-1] - cols_blurred[0]) - (cols_still[-1] - cols_still[0])
    assert spread == pytest.approx(2.0 * coc, abs=2.0)


def test_in_focus_stays_sharp(renderer):
    """In its focal plane the square covers the same pixels (a lens
    shuffles the samples' positions, so edge pixels differ by a few
    samples)."""
    still = renderer.render(square_scene())["rgba"][..., 3]
    scene = square_scene()
    scene.set_depth_of_field(0.3, 4.0)  # the square's own plane
    focused = renderer.render(scene)["rgba"][..., 3]
    assert np.array_equal(focused > 0.0, still > 0.0)
    assert np.abs(focused - still).max() <= 4.0 / 64.0
    assert focused.sum() == pytest.approx(still.sum(), rel=0.005)


@pytest.mark.parametrize("setup, message", [
    (lambda s: s.set_motion(1), "2 to"),
    (lambda s: (s.set_motion(3), s.set_mesh_motion(0, object_to_world=np.stack([translate(0)] * 2))),
     "2 motion transforms for 3"),
    (lambda s: (s.set_motion(2), s.set_mesh_motion(0, points=np.zeros((2, 3, 3), dtype=np.float32))),
     "changes its topology"),
    (lambda s: (s.set_motion(2), s.set_mesh_motion(0, points=np.full((2, 4, 3), np.nan, dtype=np.float32))),
     "NaN"),
    (lambda s: s.set_motion(2, shutter_curve=np.array([1.0, -0.5], dtype=np.float32)), "shutter curve"),
    (lambda s: s.set_motion(2, shutter_curve=np.zeros(4, dtype=np.float32)), "not all zero"),
    (lambda s: s.set_depth_of_field(0.1, -1.0), "focus distance"),
    (lambda s: s.set_depth_of_field(0.1, 2.0, ratio=0.0), "aperture ratio"),
])
def test_bad_motion_and_lens_are_refused(renderer, setup, message):
    scene = square_scene()
    setup(scene)
    with pytest.raises(RuntimeError, match=message):
        renderer.render(scene)
