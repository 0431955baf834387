"""An 8K frame at 64 samples per pixel: its samples alone would take 51 GB
(24 bytes each), more than any device holds, so it renders in buckets within
the default sample memory (RenderSettings.sample_memory_mib, 2 GiB), on
whichever device MICROPOLY_DEVICE picks. Checked against a 1080p render of
the same scene: 4 x 4 blocks of the 8K image average to the same picture."""
import os

import numpy as np

from micropoly import _native

TEAPOT = os.path.join(os.path.dirname(__file__), "..", "scenes", "teapot.rib")


def render(width, height, spp):
    scene = _native.read_rib(TEAPOT)
    s = scene.settings
    s.width, s.height = width, height
    s.samples = spp
    s.filter = _native.PixelFilter.BOX
    s.filter_width = 1.0
    s.shading_rate = 4.0
    s.depth_and_normal_passes = False
    renderer = _native.Renderer(os.environ.get("MICROPOLY_DEVICE", ""))
    return renderer.render(scene)


def test_8k_at_64_spp_renders_in_buckets_within_the_budget():
    big = render(7680, 4320, 64)
    stats = big["stats"]
    samples = 7680 * 4320 * 64
    budget = 2048 * 2**20
    assert samples * 24 > 20 * budget  # the whole frame's samples are far beyond the budget
    assert stats["buckets"] >= samples * 24 // budget
    rgba = np.asarray(big["rgba"])
    assert rgba.shape == (4320, 7680, 4)
    assert np.isfinite(rgba).all()
    small = np.asarray(render(1920, 1080, 64)["rgba"])
    blocks = rgba.reshape(1080, 4, 1920, 4, 4).mean(axis=(1, 3))
    covered = small[..., 3] > 0
    assert covered.mean() > 0.2  # the teapot fills a good part of the frame
    mse = float(((blocks - small) ** 2).mean())
    psnr = 10 * np.log10(1.0 / mse)
    print(f"8K in {stats['buckets']} buckets: {stats['timings_ms']['total'] / 1000:.1f} s, "
          f"{stats['micropolygons']:,} micropolygons; 4x4 blocks vs 1080p: {psnr:.1f} dB")
    assert psnr >= 35.0
