"""The kernel warm-up's job queue (addon/micropoly/warm_up.py), against a
fake native module and a fake FinalRenderers: every job queued renders the
built-in frames on the kept renderer and gives it back, a job queued while
another runs is not lost, a failed job is tried once more, and a device that
keeps failing leaves its error for the render to report."""

import importlib.util
import os
import sys
import threading
import time
import types

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
MODULE = os.path.join(HERE, "..", "..", "addon", "micropoly", "warm_up.py")


class FakeScene:
    def __init__(self):
        self.settings = types.SimpleNamespace()
        self.meshes, self.lights, self.materials = [], [], []

    def add_material(self, **kw):
        self.materials.append(kw)

    def add_mesh(self, name, *args, **kw):
        self.meshes.append((name, kw.get("material", 0)))

    def add_light(self, kind, **kw):
        self.lights.append(kind)

    def set_camera(self, matrix, **kw):
        assert matrix.shape == (4, 4)

    def set_world(self, radiance=None, **kw):
        assert radiance.ndim == 3 and radiance.shape[2] == 4  # (height, width, RGBA), as the native Scene takes
        self.world = radiance

    @property
    def material_count(self):
        return len(self.materials)

    @property
    def mesh_count(self):
        return len(self.meshes)


class FakeRenderer:
    device = "fake CPU"

    def __init__(self, failures):
        self.failures = failures
        self.frames = []

    def render(self, scene, progress):
        if self.failures:
            self.failures -= 1
            raise RuntimeError("the OpenCL kernels failed to build")
        assert progress(0.5)
        self.frames.append((scene.settings.width, scene.settings.height, scene.mesh_count))


class FakeRenderers:
    def __init__(self, failures=0, gate=None):
        self.renderer = FakeRenderer(failures)
        self.lock = threading.Lock()
        self.acquired = self.forgotten = 0
        self.gate = gate

    def acquire(self, selector):
        if self.gate is not None:
            self.gate.wait(10.0)
        self.lock.acquire()
        self.acquired += 1
        return self.renderer

    def release(self):
        self.lock.release()

    def forget(self):
        self.forgotten += 1


@pytest.fixture
def warm_up(monkeypatch):
    package = types.ModuleType("warm_up_test_pkg")
    package.__path__ = []
    native = types.ModuleType("warm_up_test_pkg._native")
    native.Scene = FakeScene
    native.list_devices = lambda: []
    monkeypatch.setitem(sys.modules, "warm_up_test_pkg", package)
    monkeypatch.setitem(sys.modules, "warm_up_test_pkg._native", native)
    spec = importlib.util.spec_from_file_location("warm_up_test_pkg.warm_up", MODULE)
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "warm_up_test_pkg.warm_up", module)
    spec.loader.exec_module(module)
    monkeypatch.setattr(module, "RETRY_AFTER_S", 0.0)
    return module


def test_the_built_in_frames_render_on_the_kept_renderer(warm_up):
    renderers = FakeRenderers()
    warm_up.start("", renderers)
    warm_up.start("", renderers)  # once per process
    warm_up.wait(10.0)
    assert [(w, h) for w, h, _ in renderers.renderer.frames] == [f[:2] for f in warm_up.FRAMES]
    assert all(meshes == 2 for _, _, meshes in renderers.renderer.frames)  # the cube and the floor
    assert renderers.acquired == 1 and not renderers.lock.locked() and renderers.forgotten == 0
    state = warm_up.state()
    assert not state["running"] and state["error"] is None and state["device"] == "fake CPU"


def test_a_job_queued_while_one_runs_is_rendered(warm_up):
    gate = threading.Event()
    renderers = FakeRenderers(gate=gate)
    warm_up.start("", renderers)
    materials = FakeScene()
    materials.add_material(name="default")
    materials.add_material(name="file material")
    warm_up._queue((materials, 1), "", renderers)
    gate.set()
    warm_up.wait(10.0)
    assert renderers.acquired == 2 and len(renderers.renderer.frames) == 2 * len(warm_up.FRAMES)
    assert ("cube", 1) in materials.meshes  # the file's material wears the cube
    # and once the thread has ended, a new job starts another
    warm_up._queue((), "", renderers)
    warm_up.wait(10.0)
    assert renderers.acquired == 3


def test_a_failed_job_is_tried_once_more(warm_up):
    renderers = FakeRenderers(failures=1)
    warm_up.start("", renderers)
    warm_up.wait(10.0)
    assert renderers.forgotten == 1 and renderers.acquired == 2
    assert warm_up.state()["error"] is None and len(renderers.renderer.frames) == len(warm_up.FRAMES)


def test_a_device_that_keeps_failing_leaves_its_error(warm_up):
    renderers = FakeRenderers(failures=5)
    warm_up.start("", renderers)
    warm_up.wait(10.0)
    assert "failed to build" in warm_up.state()["error"]
    assert not renderers.lock.locked() and renderers.forgotten == 2


def test_a_render_drops_the_queue_and_waits_for_the_job_running(warm_up):
    gate = threading.Event()
    renderers = FakeRenderers(gate=gate)
    warm_up.start("", renderers)
    # The first job has begun (its thread waits at the gate) before the
    # others are queued: a thread slow to start would otherwise still have
    # it queued, and the render drops the jobs not yet begun.
    deadline = time.monotonic() + 10.0
    while warm_up._state["step"] != "building the kernels" and time.monotonic() < deadline:
        time.sleep(0.005)
    for _ in range(3):
        warm_up._queue((), "", renderers)
    threading.Timer(0.2, gate.set).start()
    warm_up.yield_to_render()  # what FinalRenderers.acquire and the viewport call first
    assert not warm_up.running() and renderers.acquired == 1
    assert len(renderers.renderer.frames) == len(warm_up.FRAMES)


def test_drivers_only_builds_nothing(warm_up):
    loaded = []
    sys.modules["warm_up_test_pkg._native"].list_devices = lambda: loaded.append(True) or []
    renderers = FakeRenderers()
    warm_up.start("", renderers, build=False)
    warm_up.wait(10.0)
    assert loaded == [True] and renderers.acquired == 0 and warm_up.state()["error"] is None
