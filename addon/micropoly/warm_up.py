# SPDX-License-Identifier: GPL-3.0-or-later
"""Kernels built ahead of the first render.

A device compiles Micropoly's kernels the first time they run: on the CPU
(PoCL) about ten seconds for the program, then each kernel's code on its
first launch, and a material's node tree is a program of its own (Blender's
default material is one). When the add-on is enabled, a background thread
loads the OpenCL drivers, builds the program and renders a small built-in
scene that launches the kernels a render of an ordinary scene launches (a
subdivision surface and a polygon floor under a sun, point, spot and area
light and a uniform world, all with soft shadows), with the material programs of the
open file's materials (those that read no image; at most MAX_PROGRAMS), and
again when a file is opened. It renders on the renderer final renders keep
(final_renderers.FinalRenderers), so the first F12 finds its programs built and its
kernels loaded; what it builds also lands in the caches every later renderer
reads (the driver's compiled programs and kernels: PoCL's own cache; other
drivers' program binaries in Micropoly's), so the
first Rendered viewport finds them too. A render that starts while it runs
waits for it rather than building the same things beside it. Blender's
status bar shows it while it runs (docs/install.md).

It runs where Blender has a user interface. In background mode (command-line
and farm renders) the render follows at once and builds what it needs
itself, so the warm-up would only add its own frames: it runs there only
with MICROPOLY_WARM_UP=1; MICROPOLY_WARM_UP=0 turns it off everywhere.
"""

import os
import threading
import time

import numpy as np

# The frames it renders: (width, height, samples per side, Depth and Normal
# passes, camera distance). The driver compiles a kernel once per variant of
# its launch: PoCL one for grids under 65536 work-items and one for larger
# grids, so a tiny frame and one of an F12's size both render; passes on and
# off, and fewer or at least 16 samples per pixel, take different resolve
# kernels.
FRAMES = ((96, 64, 2, True, 6.0), (960, 540, 4, False, 2.6))
# Material programs built ahead, at most (each takes a second or more).
MAX_PROGRAMS = 8
# A job that failed is tried once more after this pause.
RETRY_AFTER_S = 2.0
# Node types whose programs read images: left to the render, which loads them.
IMAGE_NODES = {"TEX_IMAGE", "TEX_ENVIRONMENT"}

# The add-on registers again whenever the tests (or a factory reset) re-enable
# it: one thread at a time works through the jobs queued for the process.
_state = {"thread": None, "working": False, "started": 0.0, "finished": 0.0, "step": "", "error": None,
          "device": "", "jobs": [], "programs_done": set()}
_lock = threading.Lock()
_cancel = threading.Event()


def _look_at(eye, target):
    """World-to-camera (row-major) of a camera at eye looking at target, +Z up."""
    eye = np.asarray(eye, dtype=np.float64)
    forward = np.asarray(target, dtype=np.float64) - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, (0.0, 0.0, 1.0))
    right /= np.linalg.norm(right)
    rotation = np.array([right, np.cross(right, forward), -forward])
    matrix = np.eye(4)
    matrix[:3, :3] = rotation
    matrix[:3, 3] = -rotation @ eye
    return matrix.astype(np.float32)


CUBE = np.array([[x, y, z] for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)], dtype=np.float32)
CUBE_FACES = np.array([0, 2, 3, 1, 4, 5, 7, 6, 0, 1, 5, 4, 2, 6, 7, 3, 0, 4, 6, 2, 1, 3, 7, 5], dtype=np.int32)


def scene(native, materials=None, uv_layers=0):
    """The built-in scene: what an ordinary scene makes every stage launch.
    `materials`: a native Scene holding a file's material (export_materials.
    MaterialTable) whose program `uv_layers` UV maps feed; it then wears the
    cube, and the floor the default material."""
    s = materials if materials is not None else native.Scene()
    if materials is None:
        s.add_material(name="warm-up", model="principled", color=[0.8, 0.8, 0.8], roughness=0.5)
    elif s.mesh_count:
        return s  # a job tried once more
    place = np.diag([1.5, 1.5, 1.5, 1.0]).astype(np.float32)
    place[2, 3] = 0.75
    # UV maps of zeros where a program reads them (none: an empty array).
    s.add_mesh("cube", CUBE, np.full(6, 4, dtype=np.int32), CUBE_FACES, subdivision=True, object_to_world=place,
               material=s.material_count - 1, uv_layers=np.zeros((uv_layers, len(CUBE_FACES), 2), np.float32))
    floor = np.array([[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]], dtype=np.float32)
    s.add_mesh("floor", floor, np.array([4], dtype=np.int32), np.arange(4, dtype=np.int32),
               uv_layers=np.zeros((uv_layers, 4, 2), np.float32))
    s.add_light("distant", intensity=3.0, direction=[-0.4, 0.3, -0.87], angle=0.05)
    s.add_light("point", intensity=40.0, position=[-2.0, -2.0, 3.0], radius=0.3)
    s.add_light("spot", intensity=40.0, position=[2.0, -2.0, 3.0], direction=[-0.5, 0.5, -0.7], radius=0.2)
    s.add_light("area", intensity=5.0, position=[0.0, 2.0, 3.0], direction=[0.0, -0.5, -0.87], size_u=1.0,
                size_v=1.0)
    # Blender's default world: a uniform grey, lit through the world's probe suns.
    s.set_world(radiance=np.full((16, 32, 4), 0.05, dtype=np.float32), camera=False)
    return s


def frame(s, width, height, samples, passes, distance):
    """Sets the scene up for one of FRAMES."""
    s.settings.width, s.settings.height = width, height
    s.settings.samples_x = s.settings.samples_y = samples
    s.settings.depth_and_normal_passes = s.settings.normal_pass = passes
    eye = np.array([0.6, -0.8, 0.5]) * distance
    s.set_camera(_look_at(eye=eye, target=(0.0, 0.0, 0.4)), fov_degrees=40.0)
    return s


def file_materials(native, materials):
    """For each distinct material program of `materials` (Blender materials;
    on the main thread) not built ahead already, a native Scene holding it
    (and the default material) with the number of UV maps it reads. Trees
    that read images are left to the render, which loads them."""
    from . import export_materials

    jobs = []
    for material in materials:
        tree = getattr(material, "node_tree", None)
        if not getattr(material, "use_nodes", False) or tree is None or material.users == 0:
            continue
        if any(node.type in IMAGE_NODES for node in tree.nodes):
            continue
        s = native.Scene()
        table = export_materials.MaterialTable(s)
        try:
            table.get(material)  # compiles its tree, as the export does
        except Exception:  # a tree the compiler refuses: the render reports it
            continue
        sources = set(table.programs) - _state["programs_done"]
        if not sources:
            continue  # no program, or one built ahead already
        _state["programs_done"] |= sources
        jobs.append((s, len(table.uv_names)))
        if len(jobs) == MAX_PROGRAMS:
            break
    return jobs


def _render(native, job, selector, renderers):
    """Renders FRAMES of the scene for one job on the final renders' renderer."""
    _state["step"] = "building the kernels"
    renderer = renderers.acquire(selector)
    try:
        _state["device"] = renderer.device
        _state["step"] = f"building the kernels for {renderer.device}"
        s = scene(native, *job)
        for f in FRAMES:
            renderer.render(frame(s, *f), lambda progress: not _cancel.is_set())
    except BaseException:
        renderers.forget()
        raise
    finally:
        renderers.release()


def _run(selector, renderers):
    from . import _native

    try:
        _state["step"] = "loading the OpenCL drivers"
        _native.list_devices()
        while not _cancel.is_set():
            with _lock:
                if not _state["jobs"]:
                    _state["working"] = False  # a job queued from now on starts a thread
                    break
                job = _state["jobs"].pop(0)
            try:
                _render(_native, job, selector, renderers)
            except Exception:
                # Once more after a pause: Blender re-extracts an extension's
                # wheels when it is disabled and enabled again (a factory
                # reset does it), and a build reading the driver's files
                # meanwhile finds them missing.
                time.sleep(RETRY_AFTER_S)
                _render(_native, job, selector, renderers)
    except Exception as e:  # no device, a build that failed: the render reports it
        _state["error"] = str(e)
        with _lock:
            _state["jobs"].clear()
            _state["working"] = False
    finally:
        _state["finished"] = time.perf_counter()


def _queue(job, selector, renderers):
    """Queues `job` (None: none, the thread only loads the drivers) and
    starts the thread unless it is at work."""
    with _lock:
        if job is not None:
            _state["jobs"].append(job)
        if _state["working"]:
            return  # the thread takes the job before it ends
        _state["working"] = True
        _state["started"] = time.perf_counter()
        _state["error"] = None
        thread = threading.Thread(target=_run, args=(selector, renderers), name="micropoly-warm-up", daemon=True)
        _state["thread"] = thread
        thread.start()


def wanted():
    """Whether this Blender builds its kernels ahead (see above)."""
    import bpy

    setting = os.environ.get("MICROPOLY_WARM_UP", "")
    return setting == "1" or (setting != "0" and not bpy.app.background)


def start(selector, renderers, build=True):
    """Starts the warm-up for `selector` on `renderers` (the final renders'
    final_renderers.FinalRenderers, which keeps the renderer it built for the first
    F12) unless one was started already in this process. build=False only
    loads the OpenCL drivers in the background (about 80 ms with PoCL that
    the first render then does not wait for), where Blender does not warm up."""
    if _state["thread"] is None:
        _queue(() if build else None, selector, renderers)


def add_file_materials(materials, selector, renderers):
    """Builds ahead the programs of these Blender materials (main thread)."""
    from . import _native

    try:
        jobs = file_materials(_native, materials)
    except Exception:  # an odd file: its render reports what is wrong
        return
    for job in jobs:
        _queue(job, selector, renderers)


def running():
    thread = _state["thread"]
    return thread is not None and thread.is_alive()


def wait(timeout=None):
    """Waits for a warm-up still running (a render about to build the same
    kernels); returns at once when none runs."""
    thread = _state["thread"]
    if thread is not None and thread is not threading.current_thread():
        thread.join(timeout)


def yield_to_render():
    """A render is about to open a renderer: the jobs not yet begun are
    dropped (the render builds what it needs itself) and the one running is
    waited for, so that the render neither waits for a queue of material
    programs nor builds beside it. Nothing when called by the warm-up."""
    if threading.current_thread() is _state["thread"]:
        return
    with _lock:
        _state["jobs"].clear()
    wait()


def state():
    """What the warm-up did: running, seconds it took (or has taken so far),
    the device, and the error that stopped it, if any."""
    end = _state["finished"] if not running() else time.perf_counter()
    return {"running": running(), "started": _state["thread"] is not None,
            "seconds": max(end - _state["started"], 0.0) if _state["thread"] is not None else 0.0,
            "device": _state["device"], "error": _state["error"], "step": _state["step"],
            "programs": len(_state["programs_done"])}


def stop():
    """At exit: the scene render stops at its next batch; a program build in
    the driver cannot be interrupted, so this waits for it (only the first
    start on a machine builds for long)."""
    _cancel.set()
    wait(120.0)


# ---- Blender's status bar ------------------------------------------------------
# The workspace's status text: what Blender's own long tasks and modal tools
# use there. It is set when the step changes (not every second, so that a
# tool's hints are covered once at most) and cleared at the end.
_shown = {"text": None}


def _status_text():
    return f"Micropoly: {_state['step']}..." if running() else None


def _update_status():
    """A timer on the main thread: shows the warm-up's step while it runs."""
    import bpy

    text = _status_text()
    if text != _shown["text"]:
        for window in getattr(bpy.context.window_manager, "windows", []):
            window.workspace.status_text_set(text)
        _shown["text"] = text
    return 0.5 if text is not None else None


def show_in_status_bar():
    import bpy

    if bpy.app.background or not running():
        return
    if not bpy.app.timers.is_registered(_update_status):
        bpy.app.timers.register(_update_status, first_interval=0.0, persistent=True)


def hide_from_status_bar():
    import bpy

    if bpy.app.timers.is_registered(_update_status):
        bpy.app.timers.unregister(_update_status)
    if _shown["text"] is not None:
        for window in getattr(bpy.context.window_manager, "windows", []):
            window.workspace.status_text_set(None)
        _shown["text"] = None
