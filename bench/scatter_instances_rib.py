#!/usr/bin/env python3
"""Writes a rock field of any number of instances from the 2,000-rock field
the add-on exported (bench/instancing_bench.py --rib-only): the same camera,
lights, world and prototype, its first ObjectInstance block repeated with a
transform and Object Info random of its own per rock, scattered as the
2,000 rocks are (bench/occlusion_bench.py: sizes 0.4 to 1.3, turned about Z)
over a ground that grows with the count, so the rocks stay as dense.

  python3 bench/scatter_instances_rib.py bench/out/field_2000.rib 100000 OUT.rib [--sun-only]

--sun-only leaves the world's light out (the sun alone lights the field).

Standard library only (the GPU machine has no packages)."""

import math
import random
import re
import sys


def main():
    source, count, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    text = open(source).read()
    if "--sun-only" in sys.argv[4:]:
        text = re.sub(r'LightSource "micropoly_environmentlight"[^\n]*\n', "", text)
    first = text.index("AttributeBegin\n  Transform", text.index("ObjectEnd"))
    end = text.index("AttributeEnd\n", first) + len("AttributeEnd\n")
    block = text[first:end]
    head = text[:first]
    spread = math.sqrt(count / 2000.0)
    rng = random.Random(7)
    with open(out, "w") as f:
        f.write(head)
        for _ in range(count):
            x, y = rng.uniform(-60.0, 60.0) * spread, rng.uniform(2.0, 2.0 + 88.0 * spread)
            size = rng.uniform(0.4, 1.3)
            sx, sy, sz = size, size * rng.uniform(0.7, 1.3), size * rng.uniform(0.6, 1.0)
            a = rng.uniform(0.0, 2.0 * math.pi)
            c, s = math.cos(a), math.sin(a)
            # Column-major, as the writer puts a matrix: R_z(a) * S, then the translation.
            m = [c * sx, s * sx, 0, 0, -s * sy, c * sy, 0, 0, 0, 0, sz, 0, x, y, 0.3 * size, 1]
            b = re.sub(r"Transform \[[^\]]*\]", "Transform [" + " ".join(f"{v:.7g}" for v in m) + "]", block)
            b = re.sub(r'"float objectrandom" \[[^\]]*\]', f'"float objectrandom" [{rng.random():.7g}]', b)
            f.write(b)
        f.write("WorldEnd\nFrameEnd\n")


if __name__ == "__main__":
    main()
