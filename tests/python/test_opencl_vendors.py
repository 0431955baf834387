"""The wheel's choice of OpenCL drivers (native/python/micropoly_native/
opencl_vendors.py), against a fake system registry and a fake
micropoly_pocl install in temporary folders."""

import importlib.util
import os
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
MODULE = os.path.join(HERE, "..", "..", "native", "python", "micropoly_native", "opencl_vendors.py")


@pytest.fixture
def vendors(tmp_path, monkeypatch):
    spec = importlib.util.spec_from_file_location("opencl_vendors_under_test", MODULE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    system = tmp_path / "etc-vendors"
    system.mkdir()
    monkeypatch.setattr(module, "SYSTEM_VENDORS", str(system))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    # register() sets OCL_ICD_VENDORS itself: setting it through monkeypatch
    # first makes the teardown restore whatever the process had.
    monkeypatch.setenv("OCL_ICD_VENDORS", "")
    monkeypatch.delenv("OCL_ICD_VENDORS")
    monkeypatch.delenv("MICROPOLY_EMBEDDED_POCL", raising=False)
    # A machine with the linker and C library files PoCL links with.
    root = tmp_path / "root"
    for path in ("usr/bin/ld", "usr/lib/gcc/x86_64-linux-gnu/12/crtbegin.o", "usr/lib/x86_64-linux-gnu/libc.so"):
        (root / path).parent.mkdir(parents=True, exist_ok=True)
        (root / path).write_text("")
    monkeypatch.setattr(module, "ROOT", str(root))
    return module, system, tmp_path


def install_fake_pocl(tmp_path, monkeypatch):
    """A site-packages folder laid out as the micropoly_pocl wheel
    (scripts/build/cpu_device_wheel.py)."""
    site = tmp_path / "site"
    lib = site / "micropoly_pocl" / "lib" / "x86_64-linux-gnu"
    lib.mkdir(parents=True)
    (site / "micropoly_pocl" / "__init__.py").write_text("")
    library = lib / "libpocl.so.2"
    library.write_bytes(b"")
    monkeypatch.syspath_prepend(str(site))
    sys.modules.pop("micropoly_pocl", None)
    return str(library)


def test_a_package_without_its_library_is_not_a_device(vendors, monkeypatch):
    module, _, tmp_path = vendors
    library = install_fake_pocl(tmp_path, monkeypatch)
    os.remove(library)
    assert module.register() is None
    assert "OCL_ICD_VENDORS" not in os.environ


def test_no_carried_pocl_leaves_the_loader_alone(vendors, monkeypatch):
    module, _, _ = vendors
    monkeypatch.setattr(module.importlib.util, "find_spec", lambda name: None)
    assert module.register() is None
    assert "OCL_ICD_VENDORS" not in os.environ


def test_carried_pocl_joins_the_system_drivers(vendors, monkeypatch):
    module, system, tmp_path = vendors
    (system / "nvidia.icd").write_text("libnvidia-opencl.so.1\n")
    library = install_fake_pocl(tmp_path, monkeypatch)
    assert module.register() == library
    folder = os.environ["OCL_ICD_VENDORS"]
    files = {name: open(os.path.join(folder, name)).read().strip() for name in os.listdir(folder)}
    assert files == {"nvidia.icd": "libnvidia-opencl.so.1", "micropoly-carried-pocl.icd": library}


def test_same_drivers_share_one_folder(vendors, monkeypatch):
    module, _, tmp_path = vendors
    install_fake_pocl(tmp_path, monkeypatch)
    module.register()
    first = os.environ.pop("OCL_ICD_VENDORS")
    module.register()
    assert os.environ["OCL_ICD_VENDORS"] == first
    assert len(os.listdir(os.path.dirname(first))) == 1  # no staging folders left behind


def test_a_system_pocl_wins_unless_asked(vendors, monkeypatch):
    module, system, tmp_path = vendors
    (system / "pocl.icd").write_text("libpocl.so.2\n")
    install_fake_pocl(tmp_path, monkeypatch)
    assert module.register() is None
    assert "OCL_ICD_VENDORS" not in os.environ
    monkeypatch.setenv("MICROPOLY_EMBEDDED_POCL", "1")
    assert module.register() is not None
    assert len(os.listdir(os.environ["OCL_ICD_VENDORS"])) == 2


def test_a_user_setting_is_kept(vendors, monkeypatch):
    module, _, tmp_path = vendors
    install_fake_pocl(tmp_path, monkeypatch)
    monkeypatch.setenv("OCL_ICD_VENDORS", "/somewhere/else")
    assert module.register() is None
    assert os.environ["OCL_ICD_VENDORS"] == "/somewhere/else"


def test_no_linker_no_carried_pocl(vendors, monkeypatch):
    """PoCL aborts the process when it cannot link a kernel: without the
    tools it links with, the carried PoCL is not offered, and the problem
    names what is missing."""
    module, _, tmp_path = vendors
    install_fake_pocl(tmp_path, monkeypatch)
    assert module.linker_problem() is None
    os.remove(tmp_path / "root" / "usr" / "bin" / "ld")
    os.remove(tmp_path / "root" / "usr" / "lib" / "x86_64-linux-gnu" / "libc.so")
    problem = module.linker_problem()
    assert "'ld'" in problem and "libc6-dev" in problem and "GCC" not in problem
    assert module.register() is None
    assert "OCL_ICD_VENDORS" not in os.environ


def test_the_missing_device_message_says_why(monkeypatch):
    """The add-on's message for "no OpenCL device" carries the reason the
    wheel left its CPU device out (addon/micropoly/native_module.py)."""
    import types

    spec = importlib.util.spec_from_file_location(
        "native_module_under_test", os.path.join(HERE, "..", "..", "addon", "micropoly", "native_module.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    wheel = types.SimpleNamespace(embedded_cpu_device_problem="this machine lacks a linker ('ld', from binutils)")
    monkeypatch.setitem(sys.modules, "micropoly_native", wheel)
    message = module.device_error(RuntimeError("no OpenCL device found: install an OpenCL driver"))
    assert message.startswith("no OpenCL device found") and "lacks a linker ('ld'" in message
    assert module.device_error(RuntimeError("the OpenCL kernels failed to build")) == "the OpenCL kernels failed to build"
    wheel.embedded_cpu_device_problem = None
    assert module.device_error(RuntimeError("no OpenCL device found")) == "no OpenCL device found"
