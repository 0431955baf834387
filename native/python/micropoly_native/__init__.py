# SPDX-License-Identifier: GPL-3.0-or-later
"""Micropoly's native renderer as the micropoly_native wheel.

The wheel carries every shared library the module needs (auditwheel), the
OpenCL ICD loader among them; drivers are not in it. Before the module
loads, opencl_vendors.register() points that loader at the system's
drivers plus, where the system has no PoCL of its own, the CPU device of
the micropoly_pocl wheel installed beside this one (Debian's PoCL,
scripts/build/cpu_device_wheel.py), so a machine without any OpenCL driver still
renders on its CPU (docs/install.md).
"""

from . import opencl_vendors

embedded_cpu_device = opencl_vendors.register()
# Why the carried CPU device was left out, if it was for want of a linker.
embedded_cpu_device_problem = opencl_vendors.linker_problem() if embedded_cpu_device is None else None

from . import _native  # noqa: E402  (after the loader knows its drivers)


def devices():
    """The OpenCL devices the module sees, as (name, type) pairs."""
    return [(d["name"], d["type"]) for d in _native.list_devices()]
