"""Scene -> RIB from Python (write_rib), read back and rendered: the same image."""

import os
import struct
import subprocess

import numpy as np
import pytest

from micropoly import _native
from scene_helpers import look_at

HERE = os.path.dirname(os.path.abspath(__file__))
CLI = os.environ.get("MICROPOLY_CLI", os.path.join(HERE, "..", "..", "build", "micropoly-render"))


CUBE_POINTS = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                        [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=np.float32)
CUBE_FACES = np.array([0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 2, 3, 7, 6, 1, 2, 6, 5, 0, 4, 7, 3], dtype=np.int32)


def transform(translate=(0, 0, 0), scale=(1, 1, 1)):
    m = np.diag([*scale, 1.0]).astype(np.float32)
    m[:3, 3] = translate
    return m


def build_scene():
    scene = _native.Scene()
    st = scene.settings
    st.width, st.height, st.samples = 64, 48, 4
    st.filter = _native.PixelFilter.BLACKMAN_HARRIS
    st.filter_width = 2.5
    st.crop_x0, st.crop_x1, st.crop_y0, st.crop_y1 = 0.1, 0.95, 0.05, 0.9
    st.shading_rate = 0.8
    st.bound_split = _native.BoundSplitMethod.BREADTH
    st.shadow_memory_mib, st.shadow_shading_rate = 96.0, 2.5
    scene.set_camera(look_at((1.5, 2.0, 7.0), (0.0, 0.3, 0.0)), fov_degrees=42.0, clip_near=0.1, clip_far=100.0,
                     screen_window=[-1.4, 1.3, -1.0, 1.05])
    scene.add_material(name="floor", model="matte", color=[0.6, 0.6, 0.55], ka=0.5, kd=0.9)
    scene.add_material(name="gold", model="principled", color=[1.0, 0.77, 0.34], metallic=0.9, roughness=0.3,
                       specular=0.4)
    scene.add_material(name="red", model="plastic", color=[0.9, 0.1, 0.1], ks=0.7, roughness=0.05,
                       specular_color=[1.0, 0.9, 0.8], opacity=[0.8, 0.8, 0.8])
    scene.add_material(name='lamp "shade"', model="constant", color=[0.2, 0.3, 0.4], emission=[0.5, 0.4, 0.1])
    scene.add_light("ambient", intensity=0.1)
    # Shadows: soft from the sun's angle and the point light's radius (a
    # sphere), none from the spot light.
    scene.add_light("distant", intensity=0.7, direction=[-0.3, -0.6, -1.0], angle=0.05)
    scene.add_light("point", intensity=6.0, position=[-2.0, 3.0, 2.0], color=[1.0, 0.9, 0.7], radius=0.3,
                    soft_falloff=False)
    scene.add_light("spot", intensity=300.0, position=[0.5, 6.0, 20.0], direction=[-0.5, -6.0, -20.0],
                    cone_angle=0.25, cone_delta_angle=0.05, beam_distribution=1.5, cast_shadows=False)
    # Small, distant and normalised in double precision, as the add-on exports
    # them: the direction must come back bit for bit.
    direction = np.array([-0.35, 0.62, -0.7])
    scene.add_light("area", shape="ellipse", intensity=300.0, position=[2.0, -3.0, 3.0],
                    direction=(direction / np.linalg.norm(direction)).tolist(), axis_u=[0.88, 0.48, 0.0],
                    size_u=0.25, size_v=0.2)
    scene.add_light("area", shape="rectangle", intensity=2.0, position=[-1.5, 0.5, 3.0],
                    direction=[0.3, 0.0, -1.0], axis_u=[0.0, 1.0, 0.0], size_u=0.8, size_v=1.2)
    # Catmull-Clark cube with creases, a corner, a hole and per-face materials.
    scene.add_mesh("cube", CUBE_POINTS, np.full(6, 4, dtype=np.int32), CUBE_FACES, subdivision=True,
                   object_to_world=transform((0.0, 0.4, 0.0), (0.7, 0.7, 0.7)), material=1,
                   face_materials=np.array([1, 1, 2, 1, 2, 1], dtype=np.int32),
                   crease_vertices=np.array([0, 1, 1, 2], dtype=np.int32),
                   crease_sharpness=np.array([3.0, 10.0], dtype=np.float32),
                   corner_vertices=np.array([6], dtype=np.int32), corner_sharpness=np.array([2.0], dtype=np.float32),
                   hole_faces=np.array([3], dtype=np.int32), boundary="edge_only")
    # A single-sided floor of two materials, and a mirrored single-sided box
    # that the camera does not see (it still casts shadows).
    floor = np.array([[-3, -0.5, -3], [0, -0.5, -3], [3, -0.5, -3], [-3, -0.5, 3], [0, -0.5, 3], [3, -0.5, 3]],
                     dtype=np.float32)
    scene.add_mesh("floor", floor, np.array([4, 4], dtype=np.int32),
                   np.array([0, 3, 4, 1, 1, 4, 5, 2], dtype=np.int32), material=0,
                   face_materials=np.array([0, 2], dtype=np.int32), double_sided=False)
    scene.add_mesh("mirrored", CUBE_POINTS, np.full(6, 4, dtype=np.int32), CUBE_FACES,
                   object_to_world=transform((-1.8, 0.0, 0.5), (-0.3, 0.4, 0.35)), material=3, double_sided=False,
                   visible_camera=False)
    scene.validate()
    return scene


@pytest.fixture(scope="module")
def renderer():
    return _native.Renderer()


def test_written_rib_reads_back_and_renders_the_same(renderer, tmp_path):
    scene = build_scene()
    path = tmp_path / "scene.rib"
    scene.write_rib(str(path))
    back = _native.read_rib(str(path))
    assert (back.mesh_count, back.material_count, back.light_count) == (3, 4, 6)
    settings = back.settings
    assert (settings.shadows, settings.shadow_memory_mib, settings.shadow_shading_rate) == (True, 96.0, 2.5)
    a = renderer.render(scene)["rgba"]
    b = renderer.render(back)["rgba"]
    assert a.shape == b.shape == (42, 55, 4)  # the crop window of 64 x 48
    assert a[..., 3].sum() > 100.0  # the scene is in view
    assert np.abs(a - b).max() <= 1.0 / 255.0


def test_cli_renders_the_written_file(tmp_path):
    out = tmp_path / "out.png"
    path = tmp_path / "scene with spaces.rib"
    _native.write_rib(build_scene(), str(path), display=str(out))  # Display: no -o needed
    r = subprocess.run([CLI, str(path)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert "warning" not in r.stderr
    with open(out, "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    assert struct.unpack(">II", head[16:24]) == (55, 42)  # the crop window of 64 x 48


def test_write_errors_raise(tmp_path):
    scene = build_scene()
    with pytest.raises(_native.Error):
        scene.write_rib(str(tmp_path / "missing" / "scene.rib"))
    scene.add_mesh("bad", CUBE_POINTS, np.array([4], dtype=np.int32), np.array([0, 1, 2, 9], dtype=np.int32))
    with pytest.raises(_native.Error, match="bad"):
        _native.write_rib(scene, str(tmp_path / "bad.rib"))
    assert not (tmp_path / "bad.rib").exists()  # refused before the file is created
