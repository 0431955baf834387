"""The wheel's choice of OpenCL drivers (native/python/micropoly_native/
opencl_vendors.py), against a fake system registry and a fake
pocl-binary-distribution install in temporary folders."""

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
    return module, system, tmp_path


def install_fake_pocl(tmp_path, monkeypatch):
    """A site-packages folder laid out as pocl-binary-distribution's wheel."""
    site = tmp_path / "site"
    (site / "pocl_binary_distribution").mkdir(parents=True)
    (site / "pocl_binary_distribution" / "__init__.py").write_text("")
    (site / "pyopencl" / ".libs").mkdir(parents=True)
    library = site / "pyopencl" / ".libs" / "libpocl-0123abcd.so"
    library.write_bytes(b"")
    monkeypatch.syspath_prepend(str(site))
    sys.modules.pop("pocl_binary_distribution", None)
    return str(library)


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
