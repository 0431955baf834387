# SPDX-License-Identifier: GPL-3.0-or-later
"""Which OpenCL drivers the wheel's ICD loader (ocl-icd) loads.

The loader reads its drivers from /etc/OpenCL/vendors, or from the folder
that OCL_ICD_VENDORS names. A machine with no OpenCL driver has nothing
there; one with an NVIDIA or AMD driver has that driver's file. So this
module writes a folder of its own holding the system's files plus one for
the CPU device the extension carries (the micropoly_pocl wheel: Debian 12's
PoCL with LLVM 15, relocatable, scripts/build/cpu_device_wheel.py), and names it
in OCL_ICD_VENDORS before the native module first calls the loader.

Left alone: an OCL_ICD_VENDORS the user set, and a system that has a PoCL
of its own (two CPU platforms would only compete for the same cores), unless
MICROPOLY_EMBEDDED_POCL=1 asks for the carried one anyway.

PoCL links every kernel it compiles into a shared object with the system's
linker and C library files, and aborts the whole process when it cannot.
A machine without them (no binutils, no GCC) does not get the carried PoCL,
and linker_problem() says why, for the message that no device was found.
"""

import glob
import hashlib
import importlib.util
import os
import tempfile

SYSTEM_VENDORS = "/etc/OpenCL/vendors"
# What PoCL's link step (clang's driver running ld -shared ... -lgcc -lc)
# needs, looked for under ROOT: the linker, GCC's run-time files and the C
# library's link script.
ROOT = "/"
LINKER_NEEDS = (
    ("a linker ('ld', from binutils)", ("usr/bin/ld", "bin/ld")),
    ("GCC's run-time files (the gcc package)", ("usr/lib/gcc/*/*/crtbegin.o", "usr/lib64/gcc/*/*/crtbegin.o")),
    ("the C library's development files (libc6-dev, glibc-devel)",
     ("usr/lib/x86_64-linux-gnu/libc.so", "usr/lib64/libc.so", "usr/lib/libc.so")),
)


def linker_problem():
    """What the carried PoCL's link step lacks on this machine, or None."""
    missing = [what for what, patterns in LINKER_NEEDS
               if not any(glob.glob(os.path.join(ROOT, pattern)) for pattern in patterns)]
    if not missing:
        return None
    return ("the CPU device Micropoly carries (PoCL) links the kernels it compiles with the system's tools, and "
            "this machine lacks " + " and ".join(missing) + ": install them (e.g. Debian's or Ubuntu's "
            "build-essential) to render on the CPU")


def carried_pocl():
    """The path of the PoCL library the micropoly_pocl wheel installed, or
    None. PoCL finds its device plugins and kernel library relative to it."""
    spec = importlib.util.find_spec("micropoly_pocl")
    if spec is None or not spec.submodule_search_locations:
        return None
    package = os.path.abspath(list(spec.submodule_search_locations)[0])
    library = os.path.join(package, "lib", "x86_64-linux-gnu", "libpocl.so.2")
    return library if os.path.exists(library) else None


def _system_icds():
    return sorted(glob.glob(os.path.join(SYSTEM_VENDORS, "*.icd")))


def _cache_root():
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "micropoly")


def _write_vendors(entries):
    """A folder holding one .icd file per (name, library) entry, named by its
    content so that processes with the same drivers share it and never see
    a half-written one."""
    digest = hashlib.sha256(repr(entries).encode()).hexdigest()[:16]
    for root in (_cache_root(), tempfile.gettempdir()):
        folder = os.path.join(root, f"opencl-vendors-{digest}")
        if os.path.isdir(folder):
            return folder
        try:
            os.makedirs(root, exist_ok=True)
            staging = tempfile.mkdtemp(prefix="opencl-vendors-", dir=root)
            for name, library in entries:
                with open(os.path.join(staging, name), "w") as f:
                    f.write(library + "\n")
            try:
                os.rename(staging, folder)
            except OSError:  # another process got there first
                for name, _ in entries:
                    os.remove(os.path.join(staging, name))
                os.rmdir(staging)
            return folder
        except OSError:
            continue
    return None


def register():
    """Points the ICD loader at the system's drivers plus the carried PoCL.
    Returns the carried PoCL's path when it was added, else None."""
    if "OCL_ICD_VENDORS" in os.environ:
        return None
    pocl = carried_pocl()
    if pocl is None:
        return None
    system = _system_icds()
    if os.environ.get("MICROPOLY_EMBEDDED_POCL") != "1":
        if any("pocl" in os.path.basename(icd).lower() for icd in system):
            return None
    if linker_problem() is not None:
        return None  # it would abort the process at its first kernel build
    entries = []
    for icd in system:
        try:
            with open(icd) as f:
                entries.append((os.path.basename(icd), f.read().strip()))
        except OSError:
            continue
    entries.append(("micropoly-carried-pocl.icd", pocl))
    folder = _write_vendors(entries)
    if folder is None:
        return None
    os.environ["OCL_ICD_VENDORS"] = folder
    return pocl
