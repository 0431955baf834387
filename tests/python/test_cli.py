"""micropoly-render: exit codes, messages, outputs and stats."""

import json
import os
import struct
import subprocess

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = os.path.join(HERE, "..", "scenes")
CLI = os.environ.get("MICROPOLY_CLI", os.path.join(HERE, "..", "..", "build", "micropoly-render"))

STATS_KEYS = {"device", "width", "height", "spp", "patches", "subpatches_diced", "micropolygons",
              "micropolygons_sampled", "sampled_area_px", "bound_split_peak_bytes", "timings_ms"}
TIMING_KEYS = {"upload", "bound_split", "dice", "shade", "sample", "resolve", "total"}


def run(*args, env=None):
    return subprocess.run([CLI, *args], capture_output=True, text=True, timeout=600, env=env)


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", head[16:24])


def test_renders_the_teapot_to_png_with_stats(tmp_path):
    out, stats = tmp_path / "teapot.png", tmp_path / "stats.json"
    r = run(os.path.join(SCENES, "teapot.rib"), "-o", str(out), "--spp", "4", "--stats", str(stats))
    assert r.returncode == 0, r.stderr
    assert png_size(out) == (640, 480)
    s = json.loads(stats.read_text())
    assert STATS_KEYS <= set(s) and TIMING_KEYS <= set(s["timings_ms"])
    assert s["patches"] == 32 and s["spp"] == 4 and s["micropolygons"] > 10000


def test_exr_output_and_breadth_first(tmp_path):
    out = tmp_path / "teapot.exr"
    r = run(os.path.join(SCENES, "teapot.rib"), "-o", str(out), "--spp", "1", "--bound-split", "breadth")
    assert r.returncode == 0, r.stderr
    with open(out, "rb") as f:
        assert f.read(4) == b"\x76\x2f\x31\x01"  # OpenEXR magic number


def test_repeated_frames_overlap_their_read_back_and_none_writes_no_image(tmp_path):
    teapot = os.path.join(SCENES, "teapot.rib")
    once, again = tmp_path / "once.png", tmp_path / "again.png"
    assert run(teapot, "-o", str(once), "--spp", "1").returncode == 0
    stats = tmp_path / "stats.json"
    r = run(teapot, "-o", str(again), "--spp", "1", "--repeat", "3", "--stats", str(stats))
    assert r.returncode == 0, r.stderr
    assert again.read_bytes() == once.read_bytes()  # the last overlapped frame, whole
    frames = json.loads(stats.read_text())
    assert len(frames) == 3
    for f in frames:  # each frame's interval covers its own render call
        assert f["timings_ms"]["interval"] >= f["timings_ms"]["total"] > 0
        assert f["timings_ms"]["readback"] > 0
    none = tmp_path / "none.png"
    r = run(teapot, "-o", str(none), "--spp", "1", "--readback", "none", "--stats", str(stats))
    assert r.returncode == 0, r.stderr
    assert not none.exists() and json.loads(stats.read_text())["timings_ms"]["readback"] == 0
    r = run(teapot, "-o", str(none), "--readback", "halves")
    assert r.returncode == 2 and "--readback is float, half or none" in r.stderr


def test_malformed_rib_names_file_and_line(tmp_path):
    bad = tmp_path / "bad.rib"
    bad.write_text('Format 64 64 1\nWorldBegin\nPolygon "P" [0 0 0 1 0\n')
    r = run(str(bad), "-o", str(tmp_path / "x.png"))
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "bad.rib:3" in lines[0], r.stderr
    assert not (tmp_path / "x.png").exists()


def test_binary_junk_is_an_error_not_a_crash(tmp_path):
    junk = tmp_path / "junk.rib"
    junk.write_bytes(bytes(range(256)) * 8)
    r = run(str(junk), "-o", str(tmp_path / "x.png"))
    assert r.returncode == 2 and "junk.rib" in r.stderr


def test_unsupported_request_warns_once(tmp_path):
    rib = tmp_path / "warn.rib"
    rib.write_text('Format 32 32 1\nWorldBegin\nMakeShadow "a" "b"\nMakeShadow "c" "d"\n'
                   'Polygon "P" [-1 -1 5 1 -1 5 1 1 5]\nWorldEnd\n')
    r = run(str(rib), "-o", str(tmp_path / "w.png"))
    assert r.returncode == 0, r.stderr
    assert r.stderr.count("MakeShadow") == 1


def test_usage_errors_and_device_listing(tmp_path):
    assert run().returncode == 2
    assert run(os.path.join(SCENES, "teapot.rib"), "--spp", "zero").returncode == 2
    assert run(os.path.join(SCENES, "teapot.rib"), "--bound-split", "sideways").returncode == 2
    r = run(os.path.join(SCENES, "teapot.rib"), "-o", str(tmp_path / "t.png"), "--occlusion-culling", "maybe")
    assert r.returncode == 2 and "--occlusion-culling is on or off" in r.stderr
    r = run(os.path.join(SCENES, "teapot.rib"), "-o", str(tmp_path / "t.png"), "--sampler", "fast")
    assert r.returncode == 2 and "--sampler is auto, tiles, micropolygons or bins" in r.stderr
    r = run(os.path.join(SCENES, "teapot.rib"), "-o", str(tmp_path / "t.png"), "--visibility-first", "later")
    assert r.returncode == 2 and "--visibility-first is auto, on or off" in r.stderr
    assert run(os.path.join(SCENES, "teapot.rib"), "-o", str(tmp_path / "t.png"), "--sample-memory", "0").returncode == 2
    r = run("--list-devices")
    assert r.returncode == 0 and "[cpu]" in r.stdout


def test_unknown_device_fails_cleanly(tmp_path):
    r = run(os.path.join(SCENES, "teapot.rib"), "-o", str(tmp_path / "t.png"), "--device", "7")
    assert r.returncode == 1 and "out of range" in r.stderr


def test_missing_opencl_driver_is_a_clear_message(tmp_path):
    env = dict(os.environ, OCL_ICD_VENDORS=str(tmp_path), OCL_ICD_FILENAMES="")
    r = run(os.path.join(SCENES, "teapot.rib"), "-o", str(tmp_path / "t.png"), env=env)
    assert r.returncode == 1
    assert "no OpenCL device" in r.stderr


def test_budget_too_small_is_reported(tmp_path):
    r = run(os.path.join(SCENES, "teapot.rib"), "-o", str(tmp_path / "t.png"), "--bound-split-memory", "0.01")
    assert r.returncode == 1 and "too small" in r.stderr


@pytest.mark.parametrize("scene", ["all_requests.rib", "subdiv_creases.rib"])
def test_test_scenes_render(tmp_path, scene):
    r = run(os.path.join(SCENES, scene), "-o", str(tmp_path / "s.png"), "--spp", "1")
    assert r.returncode == 0, r.stderr
