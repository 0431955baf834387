#!/usr/bin/env python3
"""Two builds of micropoly-render on the same scenes, every variant: the
images (colour, alpha, Depth and Normal, as OpenEXR files written by the
same library) must be the same byte for byte, or (where culling a light's views may let another of two
micropolygons at one depth win a texel) within --min-db with identical
alpha. Prints one line per scene and variant and exits non-zero on a
difference.

  python3 bench/identical_images.py --before OLD_CLI --after NEW_CLI [--device gpu] [--spp 4] scene.rib ...

One build with two settings that must give the same image:

  python3 bench/identical_images.py --before CLI --after CLI --before-args="--visibility-first off" \
      --after-args="--visibility-first on" scene.rib ...
"""

import argparse
import os
import subprocess
import sys
import tempfile

VARIANTS = {
    "tiles": ["--sampler", "tiles"],
    "micropolygons": ["--sampler", "micropolygons"],
    "breadth": ["--bound-split", "breadth"],
    "no-culling": ["--occlusion-culling", "off"],
}


def read_png(path):
    import numpy as np  # noqa: PLC0415  (only where images differ)
    from PIL import Image  # noqa: PLC0415

    return np.asarray(Image.open(path).convert("RGBA"), dtype=np.float32) / 255.0


def render(cli, rib, out, device, spp, extra):
    cmd = [cli, rib, "-o", out, "--spp", str(spp)] + extra + (["--device", device] if device else [])
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode:
        raise SystemExit(f"{' '.join(cmd)}: {p.stderr.strip()}")


def psnr(a, b):
    import numpy as np  # noqa: PLC0415

    peak = max(float(np.percentile(np.abs(b), 99)), 1e-6)
    mse = float(np.mean((a - b) ** 2))
    return float("inf") if mse == 0 else 10 * np.log10(peak * peak / mse)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--before", required=True)
    ap.add_argument("--after", required=True)
    ap.add_argument("--device", default="")
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--min-db", type=float, default=60.0)
    ap.add_argument("--variants", default=",".join(VARIANTS))
    ap.add_argument("--before-args", default="", help="more options for the first build's renders")
    ap.add_argument("--after-args", default="", help="more options for the second build's renders")
    ap.add_argument("scenes", nargs="+")
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="identical-")
    failed = 0
    builds = (("before", a.before, a.before_args.split()), ("after", a.after, a.after_args.split()))
    for rib in a.scenes:
        for v in a.variants.split(","):
            files = []
            for tag, cli, more in builds:
                out = os.path.join(tmp, f"{tag}.exr")
                render(cli, rib, out, a.device, a.spp, VARIANTS[v] + more)
                files.append(open(out, "rb").read())
            if files[0] == files[1]:
                verdict = "identical"
            else:
                # Measured on 8-bit images: enough to tell 60 dB from less.
                b, n = [render(cli, rib, os.path.join(tmp, f"{t}.png"), a.device, a.spp, VARIANTS[v] + more) or
                        read_png(os.path.join(tmp, f"{t}.png"))
                        for t, cli, more in builds]
                db = psnr(n[..., :3], b[..., :3])
                alpha_same = bool((b[..., 3] == n[..., 3]).all())
                verdict = f"differs: {db:.1f} dB, alpha {'identical' if alpha_same else 'DIFFERS'}"
                if db < a.min_db or not alpha_same:
                    verdict += "  FAIL"
                    failed += 1
            print(f"{os.path.basename(rib)} [{v}]: {verdict}", flush=True)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
