# SPDX-License-Identifier: GPL-3.0-or-later
"""Where the native renderer comes from.

A developer build or install puts the module next to this file
(micropoly/_native*.so). The extension zip instead brings it as the
micropoly_native wheel, which Blender installs into its own site-packages;
that package also registers the CPU OpenCL device it carries before the
module loads. Either way the rest of the add-on imports it as
`from . import _native`: the wheel's module is entered under that name.
"""

import importlib
import importlib.util
import sys


def alias_wheel_module(package):
    """Makes `package._native` the wheel's module when no module of that name
    lies in the package itself. Does nothing when neither exists: the
    add-on's own import of _native then reports the missing module."""
    name = f"{package}._native"
    if name in sys.modules or importlib.util.find_spec(name) is not None:
        return
    try:
        wheel = importlib.import_module("micropoly_native")
    except ModuleNotFoundError as error:
        if error.name != "micropoly_native":
            raise
        return
    sys.modules[name] = wheel._native
    setattr(sys.modules[package], "_native", wheel._native)


def device_error(error):
    """The message of an error opening a device, with the reason the
    extension's own CPU device is missing when that is why there is none."""
    message = str(error)
    wheel = sys.modules.get("micropoly_native")
    problem = getattr(wheel, "embedded_cpu_device_problem", None)
    if problem and "no OpenCL" in message:
        message += f"; {problem}"
    return message
