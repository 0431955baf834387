"""Writes a RIB groom for micropoly-render: N strands of S Catmull-Rom
segments rooted on the upper half of a sphere (a head of radius 0.5),
rising along the normal and falling under gravity, 0.0015 wide at the root
tapering to 0.0005, at 1920x1080 with 16 spp under a distant light with
shadows (the issue's 1 M strands x 16 segments at N = 1000000). Only the
standard library: it runs where the GPU is, beside the bundled CLI.

  python3 bench/hair_rib.py OUT.rib [--strands N] [--segments S]"""

import math
import random
import sys

args = sys.argv[1:]


def arg(name, default):
    return args[args.index(name) + 1] if name in args else default


def main():
    out, n, segs = args[0], int(arg("--strands", "100000")), int(arg("--segments", "16"))
    rng = random.Random(3)
    keys = segs + 3  # Catmull-Rom: a phantom key at each end
    with open(out, "w") as f:
        f.write('Format 1920 1080 1\nPixelSamples 4 4\nProjection "perspective" "fov" [30]\n'
                'Translate 0 -0.3 2.4\nRotate -15 1 0 0\nWorldBegin\n'
                'LightSource "distantlight" 1 "from" [1 1 -1] "to" [0 0 0] "intensity" [2] '
                '"string shadowname" ["raytrace"]\n'
                'AttributeBegin\nSurface "matte"\nColor [0.8 0.6 0.5]\nSphere 0.5 -0.5 0.5 360\nAttributeEnd\n'
                'Surface "matte"\nColor [0.35 0.2 0.1]\nBasis "catmull-rom" 1 "catmull-rom" 1\n')
        batch = 2000
        for first in range(0, n, batch):
            count = min(batch, n - first)
            pts, widths = [], []
            for _ in range(count):
                z = rng.uniform(0.0, 0.95)
                phi = rng.uniform(0.0, 2.0 * math.pi)
                s = math.sqrt(1.0 - z * z)
                nx, ny, nz = s * math.cos(phi), s * math.sin(phi), z
                for k in range(keys):
                    t = min(max((k - 1) / segs, 0.0), 1.0)
                    pts.append(f"{0.5 * nx + 0.3 * t * nx:.5f} {0.5 * ny + 0.3 * t * ny:.5f} "
                               f"{0.5 * nz + 0.3 * t * nz - 0.35 * t * t:.5f}")
                widths.extend(f"{0.0015 - 0.001 * j / segs:.6f}" for j in range(segs + 1))
            f.write(f'Curves "cubic" [{" ".join([str(keys)] * count)}] "nonperiodic" "P" [{" ".join(pts)}] '
                    f'"width" [{" ".join(widths)}]\n')
        f.write("WorldEnd\n")


main()
