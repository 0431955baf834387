# SPDX-License-Identifier: GPL-3.0-or-later
"""The native renderer that final renders keep between F12s, shared by the
render engine (engine.py) and the kernel warm-up that preferences.py starts
(warm_up.py), so neither imports the other."""

import threading


class FinalRenderers:
    """The native renderer of final renders, kept from one F12 to the next
    while the device stays the same: its OpenCL context, compiled programs,
    uploaded scene and patch cache carry over, so a second F12 (or the next
    frame of an animation) skips building them. One at a time: Blender runs
    one final render at a time, and the lock makes sure of it. The kernel
    warm-up (warm_up.py) renders on it first, so the first F12 finds it
    built; an F12 that starts meanwhile waits for the lock."""

    def __init__(self):
        self._lock = threading.Lock()
        self._selector = None
        self._renderer = None
        self._dropped = False
        # Seconds the last final render spent exporting, in the native
        # renderer and writing the render result, and the buckets it was
        # rendered in (the benchmarks and tests read them).
        self.last_timings = {}

    def acquire(self, selector):
        """The renderer for `selector`, locked until release(); a new one if
        the device changed (the old one is freed first)."""
        from . import _native, warm_up

        warm_up.yield_to_render()  # the job it is on ends first; the jobs after it are dropped
        self._lock.acquire()
        self._dropped = False
        try:
            if self._renderer is None or self._selector != selector:
                self._renderer = None
                self._renderer = _native.Renderer(selector)
                self._selector = selector
            return self._renderer
        except BaseException:
            self._lock.release()
            raise

    def release(self):
        if self._dropped:
            self.forget()
        self._lock.release()

    def forget(self):
        """Called while acquired, after a render failed: the next render
        starts from a new renderer."""
        self._renderer = None
        self._selector = None

    def drop(self):
        """Frees the device (at unregister). A render or warm-up still
        running frees it when it ends: unregistering does not wait for it."""
        self._dropped = True
        if self._lock.acquire(blocking=False):
            self.forget()
            self._lock.release()

    def reopen(self):
        """At register: a renderer still held by a render or warm-up that
        began before the add-on was last disabled is kept after all."""
        self._dropped = False


_shared = FinalRenderers()


def shared():
    """The renderer final renders keep (the kernel warm-up builds it)."""
    return _shared
