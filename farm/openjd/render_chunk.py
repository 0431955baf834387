#!/usr/bin/env python3
"""Renders one chunk of frames with Blender and Micropoly, then publishes the
finished frames into the output folder with atomic renames.

Run by the Render step of micropoly-render.yaml, one process per task:

  python3 render_chunk.py --frames 1-4 --scene shot.blend --output-dir out \
      --output-pattern frame_#### [--blender blender] [--user-scripts DIR] \
      [--addon micropoly] [--device auto|cpu|gpu|N]

Output policy. Blender writes into a staging folder private to this task,
OUTPUT_DIR/.partial-<chunk>.<random>, on the same filesystem as the output
folder. Only when Blender has exited with status 0 and every frame of the
chunk is on disk is each frame moved into OUTPUT_DIR with os.replace, which
is atomic there: a reader of OUTPUT_DIR sees either no file or a whole frame,
never one being written. A task that is killed (the worker lost, the job
cancelled) leaves its staging folder behind and nothing in OUTPUT_DIR; the
next run of the same chunk deletes the staging folders of that chunk before
it renders the frames again. A task that fails while it is still alive
deletes its own staging folder.

Two runs of the same chunk must not overlap in time (a scheduler runs a task
once at a time): the second would delete the first's staging folder.

Needs only the Python standard library (3.8 or later), so any python3 on a
render node will do.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

# Runs inside Blender (--python-expr) after the scene is loaded and -E / -o
# have been applied, before any frame renders. It fails the process (through
# --python-exit-code) when Micropoly is not the engine that will render: if
# the add-on did not load, Blender's -E only prints an error and would render
# the frames with another engine. It also writes where Blender will save each
# frame, as scene.render.frame_path gives it (the output pattern, the scene's
# file format and its extension), so that the frames can be checked and
# moved without guessing Blender's naming rules.
_IN_BLENDER = r"""
import json, bpy
def _engines(cls):
    for sub in cls.__subclasses__():
        yield sub.bl_idname
        yield from _engines(sub)
_scene = bpy.context.scene
if "MICROPOLY" not in set(_engines(bpy.types.RenderEngine)):
    raise RuntimeError("the Micropoly render engine is not registered: add-on %r not enabled "
                       "(check BlenderUserScripts / AddonModule)" % ADDON)
if _scene.render.engine != "MICROPOLY":
    raise RuntimeError("the scene's render engine is %r, not MICROPOLY" % _scene.render.engine)
with open(MANIFEST, "w") as _f:
    json.dump({str(n): bpy.path.abspath(_scene.render.frame_path(frame=n)) for n in FRAMES}, _f)
"""

# Exit status of Blender when the check above raises.
_PYTHON_EXIT_CODE = 3


def parse_frames(expr):
    """The frames of an Open Job Description integer range expression
    ("1-8", "1-9:2", "3", "1-4,10"), in ascending order without repeats."""
    frames = set()
    for item in expr.replace(" ", "").split(","):
        if not item:
            raise ValueError(f"empty item in frame range {expr!r}")
        step = 1
        if ":" in item:
            item, step_text = item.split(":", 1)
            step = int(step_text)
            if step == 0:
                raise ValueError(f"zero step in frame range {expr!r}")
        # A leading '-' is a negative number, not a range separator.
        cut = item.find("-", 1)
        if cut < 0:
            start = end = int(item)
        else:
            start, end = int(item[:cut]), int(item[cut + 1:])
        if (end - start) * step < 0:
            raise ValueError(f"step {step} does not lead from {start} to {end} in {expr!r}")
        frames.update(range(start, end + (1 if step > 0 else -1), step))
    return sorted(frames)


def runs(frames):
    """Splits ascending frames into (first, last, step) runs, each one
    Blender -s/-e/-j/-a invocation: a contiguous chunk is a single run."""
    out = []
    i = 0
    while i < len(frames):
        if i + 1 == len(frames):
            out.append((frames[i], frames[i], 1))
            break
        step = frames[i + 1] - frames[i]
        j = i + 1
        while j + 1 < len(frames) and frames[j + 1] - frames[j] == step:
            j += 1
        out.append((frames[i], frames[j], step))
        i = j + 1
    return out


def chunk_label(frame_runs):
    """A name for the chunk that is safe in a file name, and that no other
    chunk's label starts with followed by '.', so that '.partial-<label>.*'
    matches the staging folders of this chunk only."""
    return "_".join(f"{a}-{b}" if s == 1 else f"{a}-{b}x{s}" for a, b, s in frame_runs)


def check_pattern(pattern):
    """The output pattern is a path relative to the output folder; it must
    stay inside it (its frames are moved there from the staging folder)."""
    if not pattern or os.path.isabs(pattern) or pattern.startswith("//"):
        raise ValueError(f"OutputPattern {pattern!r} must be a relative path such as frame_####")
    parts = pattern.replace("\\", "/").split("/")
    if ".." in parts or parts[-1] in ("", "."):
        raise ValueError(f"OutputPattern {pattern!r} must name files inside the output folder")


def clear_stale_staging(output_dir, label):
    prefix = f".partial-{label}."
    for name in os.listdir(output_dir):
        path = os.path.join(output_dir, name)
        if name.startswith(prefix) and os.path.isdir(path):
            print(f"removing the staging folder of an earlier run of this chunk: {path}", flush=True)
            shutil.rmtree(path, ignore_errors=True)


def blender_command(args, blender, scene, staging, frame_runs, frames, manifest):
    pattern = os.path.join(staging, args.output_pattern)
    check = (f"ADDON = {args.addon!r}\nMANIFEST = {manifest!r}\nFRAMES = {frames!r}\n" + _IN_BLENDER)
    # Order matters: Blender handles its arguments left to right, so the file
    # is loaded, the engine and output set and the check run before -a renders.
    cmd = [blender, "-b", "--factory-startup", "--addons", args.addon, scene,
           "--python-exit-code", str(_PYTHON_EXIT_CODE),
           "-E", "MICROPOLY", "-o", pattern, "--python-expr", check]
    for first, last, step in frame_runs:
        cmd += ["-s", str(first), "-e", str(last), "-j", str(step), "-a"]
    return cmd


def blender_environment(args, blender):
    env = dict(os.environ)
    # A Blender built against the system's Python library (as Linux
    # distributions package it) takes its Python home from the first
    # python3.x on PATH. When this helper was started through a Python that
    # put its own folder first (pyenv, a virtual environment), Blender would
    # load that Python's library path and miss the modules the add-on needs
    # (numpy). Blender's own folder first restores the Python that Blender was
    # installed with; Blender builds that bundle Python are unaffected.
    folder = os.path.dirname(blender)
    if folder:
        env["PATH"] = folder + os.pathsep + env.get("PATH", "")
    if args.user_scripts:
        env["BLENDER_USER_SCRIPTS"] = args.user_scripts
    # "auto" (or nothing) leaves the choice to Micropoly: the first GPU, else
    # the CPU. An inherited MICROPOLY_DEVICE is dropped so "auto" means that.
    device = (args.device or "").strip()
    if device.lower() in ("", "auto"):
        env.pop("MICROPOLY_DEVICE", None)
    else:
        env["MICROPOLY_DEVICE"] = device
    return env


def publish(path, destination):
    """Moves a finished frame into place: flushed to disk first, so that a
    crash after the rename cannot leave a truncated file under the final name."""
    with open(path, "rb") as f:
        os.fsync(f.fileno())
    os.makedirs(os.path.dirname(destination), exist_ok=True)
    os.replace(path, destination)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--frames", required=True, help="range expression of this chunk, e.g. 1-4")
    parser.add_argument("--scene", required=True)
    parser.add_argument("--output-dir", required=True)
    parser.add_argument("--output-pattern", default="frame_####")
    parser.add_argument("--blender", default="blender")
    parser.add_argument("--user-scripts", default="", help="BLENDER_USER_SCRIPTS for Blender; empty keeps the inherited value")
    parser.add_argument("--addon", default="micropoly", help="module name of the add-on for --addons")
    parser.add_argument("--device", default="auto", help="MICROPOLY_DEVICE: auto, cpu, gpu or an index")
    args = parser.parse_args(argv)

    try:
        frames = parse_frames(args.frames)
        check_pattern(args.output_pattern)
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if not os.path.isfile(args.scene):
        print(f"error: scene file {args.scene} not found", file=sys.stderr)
        return 2
    scene = os.path.abspath(args.scene)
    output_dir = os.path.abspath(args.output_dir)
    os.makedirs(output_dir, exist_ok=True)

    blender = shutil.which(args.blender)
    if blender is None:
        print(f"error: Blender executable {args.blender!r} not found", file=sys.stderr)
        return 2
    blender = os.path.abspath(blender)
    frame_runs = runs(frames)
    label = chunk_label(frame_runs)
    clear_stale_staging(output_dir, label)
    staging = tempfile.mkdtemp(prefix=f".partial-{label}.", dir=output_dir)
    try:
        # The manifest sits beside the frames' subtree, not in it, so only
        # the files it names are ever moved.
        manifest = os.path.join(staging, "frames.json")
        cmd = blender_command(args, blender, scene, staging, frame_runs, frames, manifest)
        print(f"chunk {args.frames}: frames {frames}, staging {staging}", flush=True)
        print("running: " + " ".join(cmd[:cmd.index("--python-expr") + 1]) + " <check> "
              + " ".join(cmd[cmd.index("--python-expr") + 2:]), flush=True)
        started = time.monotonic()
        status = subprocess.call(cmd, env=blender_environment(args, blender))
        elapsed = time.monotonic() - started
        if status != 0:
            print(f"error: Blender exited with status {status} after {elapsed:.1f} s", file=sys.stderr)
            return 1
        if not os.path.isfile(manifest):
            print("error: Blender exited without running the engine check", file=sys.stderr)
            return 1
        with open(manifest) as f:
            paths = {int(k): v for k, v in json.load(f).items()}
        # Micropoly reports a failed render as an error and Blender saves no
        # frame, yet exits with status 0: a missing frame is the failure sign.
        missing = [n for n in frames if not os.path.isfile(paths.get(n, "")) or os.path.getsize(paths[n]) == 0]
        if missing:
            print(f"error: Blender exited without writing frame(s) {missing}; see the log above", file=sys.stderr)
            return 1
        for n in frames:
            relative = os.path.relpath(paths[n], staging)
            if relative.startswith(os.pardir):
                print(f"error: frame {n} was written outside the staging folder: {paths[n]}", file=sys.stderr)
                return 1
            destination = os.path.join(output_dir, relative)
            publish(paths[n], destination)
            print(f"frame {n} -> {destination}", flush=True)
        print(f"chunk {args.frames}: {len(frames)} frame(s) in {elapsed:.1f} s", flush=True)
        return 0
    finally:
        shutil.rmtree(staging, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
