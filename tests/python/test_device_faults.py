"""Device faults mid-frame through the Python module and the CLI, as shipped.

MICROPOLY_CL_FAULT plants one OpenCL failure when a renderer opens its
device (native/src/cl/device_faults.h). The render it hits raises
micropoly._native.Error naming the phase and the OpenCL error; the same
Renderer object (as Blender's Rendered viewport keeps one) then renders the
next frame exactly as a clean renderer does.
"""

import os
import subprocess

import numpy as np
import pytest

from micropoly import _native
from scene_helpers import look_at

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = os.path.join(HERE, "..", "scenes")
CLI = os.environ.get("MICROPOLY_CLI", os.path.join(HERE, "..", "..", "build", "micropoly-render"))


def make_scene(offset=0.0):
    scene = _native.Scene()
    scene.settings.width = 96
    scene.settings.height = 72
    scene.settings.samples = 4
    scene.settings.filter = _native.PixelFilter.BOX
    scene.settings.filter_width = 1.0
    scene.add_material(name="grey", model="matte", color=[0.6, 0.5, 0.4], ka=1.0, kd=1.0)
    scene.add_light("distant", intensity=1.0, direction=[-0.3, -0.5, -1.0])
    scene.set_camera(look_at((2.5, 2.0, 4.0), (0, 0, 0)), fov_degrees=45.0)
    cube = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                     [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=np.float32)
    cube[:, 0] += offset
    faces = np.array([0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 2, 3, 7, 6, 1, 2, 6, 5, 0, 4, 7, 3], dtype=np.int32)
    scene.add_mesh("cube", cube, np.full(6, 4, dtype=np.int32), faces)
    return scene


@pytest.fixture(scope="module")
def reference():
    return _native.Renderer().render(make_scene())


def faulty_renderer(monkeypatch, plan):
    """A renderer whose session was opened with `plan` planted."""
    monkeypatch.setenv("MICROPOLY_CL_FAULT", plan)
    renderer = _native.Renderer()
    monkeypatch.delenv("MICROPOLY_CL_FAULT")
    return renderer


def assert_same_image(result, reference):
    for key in ("rgba", "depth", "normal"):
        np.testing.assert_array_equal(result[key], reference[key], err_msg=key)


@pytest.mark.parametrize("plan, phase, code", [
    ("alloc:1:CL_MEM_OBJECT_ALLOCATION_FAILURE@upload", "(upload)", "CL_MEM_OBJECT_ALLOCATION_FAILURE"),
    ("launch:1:CL_OUT_OF_RESOURCES@shade", "(bound_split/shade)", "CL_OUT_OF_RESOURCES"),
    ("launch:2:CL_OUT_OF_HOST_MEMORY@bound_split", "bound_split)", "CL_OUT_OF_HOST_MEMORY"),
    ("read:1:CL_INVALID_COMMAND_QUEUE@readback", "(readback)", "CL_INVALID_COMMAND_QUEUE"),
    ("launch:1:CL_OUT_OF_RESOURCES:lost@resolve", "(resolve)", "CL_OUT_OF_RESOURCES"),
    ("finish:1:CL_DEVICE_NOT_AVAILABLE", "", "CL_DEVICE_NOT_AVAILABLE"),
])
def test_a_fault_ends_that_render_and_the_same_renderer_renders_the_next(monkeypatch, reference, plan, phase, code):
    renderer = faulty_renderer(monkeypatch, plan)
    with pytest.raises(_native.Error) as failed:
        renderer.render(make_scene())
    message = str(failed.value)
    assert isinstance(failed.value, RuntimeError)
    assert phase in message and code in message, message
    again = renderer.render(make_scene())
    assert not again["stats"]["cancelled"]
    assert_same_image(again, reference)
    # A different scene, then the first one again from the cache.
    renderer.render(make_scene(0.3))
    assert_same_image(renderer.render(make_scene()), reference)


def test_progressive_renders_like_the_viewport_recover(monkeypatch, reference):
    renderer = faulty_renderer(monkeypatch, "finish:2:CL_OUT_OF_RESOURCES")
    seen = []

    def progress(p):
        seen.append(p)
        return True

    with pytest.raises(_native.Error, match="CL_OUT_OF_RESOURCES"):
        renderer.render(make_scene(), progress)
    assert_same_image(renderer.render(make_scene(), progress), reference)
    assert seen and seen[-1] == 1.0


def test_a_progress_callback_that_raises_leaves_the_renderer_usable(reference):
    renderer = _native.Renderer()

    def progress(p):
        if p > 0.0:
            raise KeyError("stop")
        return True

    with pytest.raises(KeyError):
        renderer.render(make_scene(), progress)
    assert_same_image(renderer.render(make_scene()), reference)


def test_a_malformed_plan_is_a_clear_error(monkeypatch):
    monkeypatch.setenv("MICROPOLY_CL_FAULT", "launch:one:CL_OUT_OF_RESOURCES")
    with pytest.raises(_native.Error, match="N must be a positive count"):
        _native.Renderer()


def test_the_cli_exits_with_the_message_and_renders_without_the_fault(tmp_path):
    out = tmp_path / "teapot.png"
    args = [CLI, os.path.join(SCENES, "teapot.rib"), "-o", str(out), "--spp", "1"]
    env = dict(os.environ, MICROPOLY_CL_FAULT="launch:3:CL_INVALID_COMMAND_QUEUE@dice")
    failed = subprocess.run(args, capture_output=True, text=True, timeout=600, env=env)
    assert failed.returncode == 1, failed.stderr
    assert "failed (bound_split/dice)" in failed.stderr and "CL_INVALID_COMMAND_QUEUE" in failed.stderr, failed.stderr
    assert not out.exists()
    env.pop("MICROPOLY_CL_FAULT")
    clean = subprocess.run(args, capture_output=True, text=True, timeout=600, env=env)
    assert clean.returncode == 0, clean.stderr
    assert out.exists()
