"""Scene.add_points from Python: a cloud becomes one shared unit sphere and
an instance per point that renders, bad points are skipped and counted, and
malformed arrays are refused with a message, never a crash."""

import numpy as np
import pytest

from micropoly import _native
from scene_helpers import look_at


def base():
    s = _native.Scene()
    s.settings.width, s.settings.height = 96, 64
    s.set_camera(look_at((0.0, -8.0, 2.0), (0.0, 0.0, 0.0)), fov_degrees=60.0)
    s.add_light("distant", direction=[-0.3, 0.5, -1.0])
    return s


def cloud(n):
    positions = np.zeros((n, 3), dtype=np.float32)
    positions[:, 0] = np.linspace(-2.5, 2.5, n)
    return positions, np.linspace(0.1, 0.4, n, dtype=np.float32)


def test_points_share_one_sphere_and_render():
    s = base()
    positions, radii = cloud(6)
    assert s.add_points("a", positions, radii) == 0
    assert s.add_points("b", positions + 10.0, radii, random=0.5) == 0
    assert (s.prototype_count, s.instance_count, s.mesh_count) == (1, 12, 0)
    r = _native.Renderer().render(s)
    assert r["stats"]["instances"] == 12
    # The six spheres in view (radii 0.1 to 0.4, 8 units away) cover discs.
    alpha = np.asarray(r["rgba"])[..., 3]
    assert 40.0 < alpha.sum() < 600.0


def test_bad_points_are_skipped_and_counted():
    s = base()
    positions, radii = cloud(5)
    radii[1] = 0.0
    radii[2] = np.nan
    positions[3, 1] = np.inf
    assert s.add_points("a", positions, radii) == 3
    assert s.instance_count == 2


@pytest.mark.parametrize("positions, radii, message", [
    (np.zeros((4, 3), np.float32), np.ones(3, np.float32), "4 positions but 3 radii"),
    (np.zeros((4, 2), np.float32), np.ones(4, np.float32), "positions"),
    (np.zeros((4, 3), np.float32), np.ones((4, 1), np.float32), "radii must be a (points,) array"),
])
def test_malformed_clouds_are_refused(positions, radii, message):
    s = base()
    with pytest.raises(RuntimeError, match=message.replace("(", r"\(").replace(")", r"\)")):
        s.add_points("bad", positions, radii)
