#!/usr/bin/env python3
"""Renders an animation through the Open Job Description template
farm/openjd/micropoly-render.yaml with `openjd run` and checks the frames.

  python3 tests/farm/test_openjd.py

Environment (all optional):
  MICROPOLY_OPENJD      the openjd executable (default /tmp/openjd-venv/bin/openjd)
  BLENDER_USER_SCRIPTS  folder whose addons/micropoly holds the add-on
                        (default /work/main/build/install)
  MICROPOLY_BLENDER     the Blender executable (default: blender on PATH)
  MICROPOLY_DEVICE      device for both the farm and the reference renders
                        (default: Micropoly's automatic choice)
  MICROPOLY_FARM_KEEP   set to keep the work folder

What it checks:
  1. A task killed while Blender renders the second frame of its chunk leaves
     no frame of that chunk in the output folder.
  2. Two `openjd run` sessions at once, one running the first two chunks of
     Frames=1-8 / ChunkSize=2 as openjd forms them, the other the last two
     (one of them the chunk killed in 1, so it is a re-run), render Blender
     processes that overlap in time, leave exactly the 8 frames and no
     staging folder, and every frame matches a direct `blender -f N` render
     of that frame at >= 40 dB PSNR (and differs from its neighbours, so a
     frame saved under the wrong number would be caught).
  3. A device Micropoly rejects fails the task and publishes nothing.

Exits with status 1 on a failed check, 0 when all pass.
"""

import json
import os
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import threading
import time
import zlib

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TEMPLATE = os.path.join(ROOT, "farm", "openjd", "micropoly-render.yaml")
SCENE_SCRIPT = os.path.join(ROOT, "tests", "farm", "make_animated_scene.py")
OPENJD = os.environ.get("MICROPOLY_OPENJD", "/tmp/openjd-venv/bin/openjd")
USER_SCRIPTS = os.environ.get("BLENDER_USER_SCRIPTS", "/work/main/build/install")
BLENDER = shutil.which(os.environ.get("MICROPOLY_BLENDER", "blender"))
DEVICE = os.environ.get("MICROPOLY_DEVICE", "") or "auto"

FRAMES = 8
CHUNK = 2
PATTERN = "shot_####"
MIN_PSNR = 40.0

failures = []


def check(ok, message):
    print(("ok    " if ok else "FAIL  ") + message, flush=True)
    if not ok:
        failures.append(message)
    return ok


def frame_name(n):
    """The file Blender saves frame n under for PATTERN (a run of '#' is the
    zero-padded frame number) and the PNG format the scene sets."""
    hashes = PATTERN.count("#")
    return PATTERN.replace("#" * hashes, str(n).zfill(hashes)) + ".png"


def blender_env():
    env = dict(os.environ)
    env["BLENDER_USER_SCRIPTS"] = USER_SCRIPTS
    # A Blender that uses the system's Python library takes its Python home
    # from the first python3.x on PATH; a Python that started this test from
    # pyenv or a virtual environment may have put its own folder first.
    env["PATH"] = os.path.dirname(BLENDER) + os.pathsep + env.get("PATH", "")
    if DEVICE == "auto":
        env.pop("MICROPOLY_DEVICE", None)
    else:
        env["MICROPOLY_DEVICE"] = DEVICE
    return env


def run(cmd, log, **kwargs):
    """Runs cmd to completion with its output in log; returns (status, seconds)."""
    started = time.monotonic()
    with open(log, "w") as out:
        status = subprocess.call(cmd, stdout=out, stderr=subprocess.STDOUT, **kwargs)
    return status, time.monotonic() - started


def tail(path, lines=25):
    with open(path, errors="replace") as f:
        return "".join(f.readlines()[-lines:])


# ---- PNG reading (numpy + zlib: the test needs no imaging library) ---------

def read_png(path):
    """Decodes a non-interlaced PNG to an array (height, width, channels) of
    floats in [0, 1]."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path} is not a PNG file")
    pos, idat, header = 8, [], None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
        pos += 12 + length
    width, height, depth, color_type, _, _, interlace = header
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(color_type)
    if channels is None or depth not in (8, 16) or interlace:
        raise ValueError(f"{path}: unsupported PNG (color type {color_type}, depth {depth}, interlace {interlace})")
    bpp = channels * depth // 8
    stride = width * bpp
    raw = np.frombuffer(zlib.decompress(b"".join(idat)), dtype=np.uint8).reshape(height, stride + 1)
    out = np.zeros((height, stride), dtype=np.uint8)
    prior = np.zeros(stride, dtype=np.int32)
    for y in range(height):
        kind, line = raw[y, 0], raw[y, 1:].astype(np.int32)
        if kind == 0:
            row = line
        elif kind == 2:
            row = (line + prior) & 255
        elif kind in (1, 3, 4):
            # Sub, Average and Paeth depend on the bytes already decoded to
            # their left, so they go byte by byte.
            row = np.zeros(stride, dtype=np.int32)
            for x in range(stride):
                left = row[x - bpp] if x >= bpp else 0
                up = prior[x]
                if kind == 1:
                    predicted = left
                elif kind == 3:
                    predicted = (left + up) >> 1
                else:
                    upper_left = prior[x - bpp] if x >= bpp else 0
                    p = left + up - upper_left
                    pa, pb, pc = abs(p - left), abs(p - up), abs(p - upper_left)
                    predicted = left if pa <= pb and pa <= pc else (up if pb <= pc else upper_left)
                row[x] = (line[x] + predicted) & 255
        else:
            raise ValueError(f"{path}: bad PNG filter {kind} in row {y}")
        out[y] = row
        prior = row
    if depth == 16:
        pixels = out.reshape(height, width * channels, 2).astype(np.uint32)
        return ((pixels[..., 0] << 8) | pixels[..., 1]).reshape(height, width, channels) / 65535.0
    return out.reshape(height, width, channels) / 255.0


def psnr(a, b):
    """Peak signal-to-noise ratio in dB of two images in [0, 1] (inf when equal)."""
    if a.shape != b.shape:
        return float("-inf")
    mse = float(np.mean((a - b) ** 2))
    return float("inf") if mse == 0.0 else 10.0 * np.log10(1.0 / mse)


# ---- process handling ---------------------------------------------------------

def processes():
    """{pid: (parent pid, command line)} of the processes on this machine."""
    out = {}
    for name in os.listdir("/proc"):
        if not name.isdigit():
            continue
        try:
            with open(f"/proc/{name}/stat") as f:
                stat = f.read()
            with open(f"/proc/{name}/cmdline", "rb") as f:
                cmdline = [part.decode(errors="replace") for part in f.read().split(b"\0") if part]
        except OSError:
            continue  # exited while we looked
        # The field after the parenthesised command name is the state, then the parent.
        parent = int(stat[stat.rindex(")") + 2:].split()[1])
        out[int(name)] = (parent, cmdline)
    return out


def descendants(root):
    table = processes()
    found, frontier = [], [root]
    while frontier:
        pid = frontier.pop()
        found.append(pid)
        frontier += [child for child, (parent, _) in table.items() if parent == pid]
    return found, table


def is_blender(cmdline):
    return bool(cmdline) and os.path.basename(cmdline[0]).startswith("blender")


def kill_tree(root):
    """Stops, then kills, root and everything below it, at once, as a worker
    that loses power would. openjd starts each action in a session of its own,
    so killing openjd's process group alone would leave Blender running.
    Returns whether a Blender process was among them (still rendering)."""
    pids, table = descendants(root)
    for pid in pids:
        try:
            os.kill(pid, signal.SIGSTOP)  # freeze first: nobody reacts to the others dying
        except ProcessLookupError:
            pass
    # Collected again while frozen: a child forked before the freeze is included.
    pids, table = descendants(root)
    blender_alive = any(is_blender(table.get(pid, (0, []))[1]) for pid in pids)
    for pid in pids:
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    return blender_alive


class BlenderWatch:
    """Samples /proc while running and records, per Blender process whose
    command line names the output folder, when it was first and last seen."""

    def __init__(self, marker):
        self.marker = marker
        self.seen = {}
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def __enter__(self):
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()

    def _run(self):
        while not self._stop.is_set():
            now = time.monotonic()
            table = processes()
            for pid, (parent, cmdline) in table.items():
                # A child that Blender forks (an OpenCL driver running a
                # compiler, say) shows Blender's command line until it execs:
                # it is not another task's Blender.
                if is_blender(table.get(parent, (0, []))[1]):
                    continue
                if is_blender(cmdline) and any(self.marker in part for part in cmdline):
                    first, _ = self.seen.get(pid, (now, now))
                    self.seen[pid] = (first, now)
            time.sleep(0.02)

    def most_at_once(self):
        events = sorted([(t0, 1) for t0, _ in self.seen.values()] + [(t1, -1) for _, t1 in self.seen.values()],
                        key=lambda e: (e[0], -e[1]))
        most = current = 0
        for _, step in events:
            current += step
            most = max(most, current)
        return most


# ---- the test -------------------------------------------------------------------

def openjd_env(work):
    """openjd keeps its sessions' folders under the temporary folder; a
    killed session cannot remove its own, so they go into the work folder."""
    env = dict(os.environ)
    env["TMPDIR"] = os.path.join(work, "tmp")
    os.makedirs(env["TMPDIR"], exist_ok=True)
    return env


def openjd_run(scene, out_dir, extra, device=None):
    cmd = [OPENJD, "run", TEMPLATE,
           "-p", f"SceneFile={scene}", "-p", f"Frames=1-{FRAMES}", "-p", f"ChunkSize={CHUNK}",
           "-p", f"OutputDir={out_dir}", "-p", f"OutputPattern={PATTERN}",
           "-p", f"Device={device or DEVICE}", "-p", f"BlenderExecutable={BLENDER}",
           "-p", f"BlenderUserScripts={USER_SCRIPTS}"]
    return cmd + extra


def staging_dirs(out_dir):
    return sorted(n for n in os.listdir(out_dir) if n.startswith(".partial-"))


def frame_files(out_dir):
    return sorted(n for n in os.listdir(out_dir) if not n.startswith("."))


def kill_mid_chunk(scene, out_dir, work, first, last, attempts=3):
    """Starts the chunk first-last, waits until its first frame is finished in
    the staging folder (Blender is then on the next frame) and kills the
    whole task. Returns the staging folders' contents, or None when every
    attempt came too late (Blender had already exited)."""
    label = f".partial-{first}-{last}."
    for attempt in range(1, attempts + 1):
        cmd = openjd_run(scene, out_dir, ["--task-param", f"Frame={first}-{last}"])
        log = os.path.join(work, f"kill-{attempt}.log")
        with open(log, "w") as out:
            proc = subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT, start_new_session=True,
                                    env=openjd_env(work))
        started = time.monotonic()
        first_frame = None
        while proc.poll() is None and time.monotonic() - started < 120:
            for name in staging_dirs(out_dir):
                if name.startswith(label):
                    path = os.path.join(out_dir, name, frame_name(first))
                    if os.path.isfile(path):
                        first_frame = path
            if first_frame:
                break
            time.sleep(0.005)
        if first_frame is None:
            kill_tree(proc.pid)
            proc.wait()
            print(tail(log))
            check(False, f"kill test: frame {first} never appeared in a staging folder (openjd status {proc.poll()})")
            return None
        blender_alive = kill_tree(proc.pid)
        proc.wait()
        at = time.monotonic() - started
        if blender_alive:
            contents = {n: sorted(os.listdir(os.path.join(out_dir, n))) for n in staging_dirs(out_dir)}
            print(f"killed the task for frames {first}-{last} {at:.2f} s after it started, "
                  f"while Blender was rendering; staging left: {contents}")
            return contents
        # Blender had exited between the poll and the freeze: the task may
        # have been publishing its frames, which proves nothing either way.
        print(f"attempt {attempt}: Blender had already exited when the kill came; trying again")
        for name in os.listdir(out_dir):
            path = os.path.join(out_dir, name)
            shutil.rmtree(path) if os.path.isdir(path) else os.remove(path)
    check(False, f"kill test: {attempts} attempts all came after Blender had exited")
    return None


def main():
    for what, path in (("openjd (MICROPOLY_OPENJD)", OPENJD), ("Blender", BLENDER),
                       ("add-on (BLENDER_USER_SCRIPTS)", os.path.join(USER_SCRIPTS or "", "addons", "micropoly"))):
        if not path or not os.path.exists(path):
            print(f"FAIL  {what} not found: {path}")
            return 1
    work = tempfile.mkdtemp(prefix="micropoly-openjd-")
    print(f"work folder {work}; openjd {OPENJD}; Blender {BLENDER}; device {DEVICE}")
    test_started = time.monotonic()

    scene = os.path.join(work, "anim.blend")
    status, seconds = run([BLENDER, "-b", "--factory-startup", "--python", SCENE_SCRIPT, "--", scene,
                           "--frames", str(FRAMES)], os.path.join(work, "scene.log"), env=blender_env())
    if not check(status == 0 and os.path.isfile(scene), f"built the animated scene ({seconds:.1f} s)"):
        print(tail(os.path.join(work, "scene.log")))
        return 1

    # References: each frame in a Blender process of its own, the way an
    # artist renders one frame, with nothing carried over from other frames.
    ref_dir = os.path.join(work, "reference")
    reference = {}
    ref_seconds = []
    for n in range(1, FRAMES + 1):
        status, seconds = run([BLENDER, "-b", "--factory-startup", "--addons", "micropoly", scene,
                               "-E", "MICROPOLY", "-o", os.path.join(ref_dir, PATTERN), "-f", str(n)],
                              os.path.join(work, f"reference-{n}.log"), env=blender_env())
        ref_seconds.append(seconds)
        path = os.path.join(ref_dir, frame_name(n))
        if not check(status == 0 and os.path.isfile(path), f"reference render of frame {n} ({seconds:.1f} s)"):
            print(tail(os.path.join(work, f"reference-{n}.log")))
            return 1
        reference[n] = read_png(path)
    neighbours = [psnr(reference[n], reference[n + 1]) for n in range(1, FRAMES)]
    print("PSNR between consecutive reference frames: " + ", ".join(f"{p:.1f}" for p in neighbours) + " dB")
    check(max(neighbours) < MIN_PSNR,
          f"every frame differs from the next by more than the match threshold (highest {max(neighbours):.1f} dB "
          f"< {MIN_PSNR} dB), so a frame published under the wrong number would fail the comparison")

    out_dir = os.path.join(work, "frames")
    os.makedirs(out_dir)

    # 1. A task killed mid-chunk publishes nothing.
    killed_first, killed_last = FRAMES - CHUNK + 1, FRAMES
    kill_started = time.monotonic()
    left = kill_mid_chunk(scene, out_dir, work, killed_first, killed_last)
    if left is not None:
        check(frame_files(out_dir) == [],
              f"after the kill the output folder holds no frame (found {frame_files(out_dir)})")
        finished = [f for files in left.values() for f in files if f.endswith(".png")]
        check(frame_name(killed_first) in finished,
              f"the killed task had finished frame {killed_first} in its staging folder, unpublished")
    kill_seconds = time.monotonic() - kill_started

    # 2. Two sessions at once. Session A runs the job's first two tasks as
    # openjd forms them from Frames and ChunkSize; session B picks the last
    # two by their chunk values, one of them the chunk just killed.
    session_a = openjd_run(scene, out_dir, ["--maximum-tasks", "2"])
    tasks_b = [{"Frame": f"{f}-{f + CHUNK - 1}"} for f in range(2 * CHUNK + 1, FRAMES + 1, CHUNK)]
    session_b = openjd_run(scene, out_dir, ["--tasks", json.dumps(tasks_b)])
    logs = [os.path.join(work, "session-a.log"), os.path.join(work, "session-b.log")]
    started = time.monotonic()
    with BlenderWatch(out_dir) as watch:
        handles = [open(log, "w") for log in logs]
        procs = [subprocess.Popen(cmd, stdout=h, stderr=subprocess.STDOUT, env=openjd_env(work))
                 for cmd, h in zip((session_a, session_b), handles)]
        statuses = [p.wait(timeout=600) for p in procs]
        for h in handles:
            h.close()
    farm_seconds = time.monotonic() - started
    for name, status, log in zip("AB", statuses, logs):
        if not check(status == 0, f"openjd session {name} succeeded (status {status})"):
            print(tail(log, 40))
    spans = sorted(watch.seen.values())
    print("Blender processes (start, end) in s from the sessions' start: "
          + ", ".join(f"({t0 - started:.1f}, {t1 - started:.1f})" for t0, t1 in spans))
    check(len(spans) == 4, f"the sessions ran one Blender process per task: {len(spans)} for 4 tasks")
    check(watch.most_at_once() >= 2, f"Blender processes of different tasks overlapped in time "
                                     f"(at most {watch.most_at_once()} at once)")
    with open(logs[0]) as f:
        log_a = f.read()
    chunks_a = [line.split("chunk ", 1)[1].split(":", 1)[0] for line in log_a.splitlines()
                if "chunk " in line and ": frames [" in line]
    expected_a = [f"{f}-{f + CHUNK - 1}" for f in range(1, 2 * CHUNK + 1, CHUNK)]
    check(chunks_a == expected_a, f"openjd formed session A's tasks from ChunkSize={CHUNK}: {chunks_a}")
    if left is not None:
        with open(logs[1]) as f:
            log_b = f.read()
        check(all(f"removing the staging folder of an earlier run of this chunk: {os.path.join(out_dir, name)}"
                  in log_b for name in left),
              "the re-run of the killed chunk removed the staging folder left by the kill")
    check(staging_dirs(out_dir) == [], f"no staging folder is left ({staging_dirs(out_dir)})")
    expected = [frame_name(n) for n in range(1, FRAMES + 1)]
    check(frame_files(out_dir) == sorted(expected), f"the output folder holds exactly the {FRAMES} frames "
                                                    f"({len(frame_files(out_dir))} files)")
    scores = {}
    for n in range(1, FRAMES + 1):
        path = os.path.join(out_dir, frame_name(n))
        if os.path.isfile(path):
            scores[n] = psnr(read_png(path), reference[n])
    print("PSNR of farm frames against their reference: "
          + ", ".join(f"{n}: {p:.1f}" for n, p in sorted(scores.items())) + " dB")
    for n, p in sorted(scores.items()):
        check(p >= MIN_PSNR, f"frame {n} matches its reference ({p:.1f} dB >= {MIN_PSNR} dB)")

    # 3. A failing render fails the task and publishes nothing.
    bad_dir = os.path.join(work, "bad-device")
    status, seconds = run(openjd_run(scene, bad_dir, ["--task-param", f"Frame=1-{CHUNK}"], device="no-such-device"),
                          os.path.join(work, "bad-device.log"), env=openjd_env(work))
    check(status != 0, f"a task on a device Micropoly rejects fails (openjd status {status}, {seconds:.1f} s)")
    leftovers = os.listdir(bad_dir) if os.path.isdir(bad_dir) else []
    check(leftovers == [], f"the failed task left nothing in its output folder ({leftovers})")

    total = time.monotonic() - test_started
    print(f"times: reference frames {sum(ref_seconds):.1f} s ({sum(ref_seconds) / FRAMES:.2f} s per Blender run), "
          f"kill test {kill_seconds:.1f} s, two sessions of {2 * CHUNK} frames each {farm_seconds:.1f} s, "
          f"whole test {total:.1f} s")
    if failures:
        print(f"{len(failures)} check(s) failed; work folder kept: {work}")
        return 1
    if os.environ.get("MICROPOLY_FARM_KEEP"):
        print(f"work folder kept: {work}")
    else:
        shutil.rmtree(work, ignore_errors=True)
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
