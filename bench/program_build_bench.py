"""Time to build node trees the device has not seen: what an artist waits
for after a node tree's structure changes (a link, a node, a mode), and what
a test run pays for every tree after the kernels change.

The scene is the soak tests' (tests/soak/soak_scene.py, 160 x 120, 16 spp,
a sun with shadow maps): Suzanne's Principled BSDF over a Noise texture, the
torus' noise displacement, the floor's image texture and the ball's plain
Principled, exported as RIB by the add-on. Each round gives every tree in it
a constant no earlier round used (an addition of zero that the compilers
cannot see through before they build), so neither Micropoly's binary cache
nor PoCL's holds them, while the stages' program stays cached. Each CLI
renders the new trees, then the same scene again (every tree cached); the
difference is the trees' cost. Before and after builds take turns.

  # once, to write bench/out/material_trees.rib (and _1080.rib):
  MICROPOLY_ADDON_DIR=build/addons blender -b --factory-startup \\
      --python bench/program_build_bench.py -- --make-rib
  python3 bench/program_build_bench.py --cli build/micropoly-render \\
      --before OLD/micropoly-render [--rounds 5] [--json FILE] [--cold]

--cold also times the first render from empty caches (Micropoly's and
PoCL's both new each round): the stages' program, the light program and
every tree built, what a fresh install's first F12 pays.
"""

import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
RIB = os.path.join(HERE, "out", "material_trees.rib")


def make_rib():
    sys.path.insert(0, os.path.join(HERE, "..", "tests", "blender"))
    sys.path.insert(0, os.path.join(HERE, "..", "tests", "soak"))
    import render_utils as ru
    import soak_scene

    ru.enable_addon()
    from micropoly import operators

    import bpy

    soak_scene.build_scene(160, 120, samples=16)
    os.makedirs(os.path.dirname(RIB), exist_ok=True)
    operators.export_rib(bpy.context.evaluated_depsgraph_get(), RIB)
    print("wrote", RIB)
    # The same trees at 1920 x 1080 for the speed of shading them (bench.py's
    # "materials" suite).
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = 1920, 1080
    large = RIB.replace(".rib", "_1080.rib")
    operators.export_rib(bpy.context.evaluated_depsgraph_get(), large)
    print("wrote", large)


# A material program's source inside the RIB: "string program" ["..."].
PROGRAM = re.compile(r'("string program" \[")((?:[^"\\]|\\.)*)(")')


def variant(text, k):
    """The scene with every tree's code changed by round k: its surface
    function first stores k where a footprint of -k.5 (which never occurs)
    is seen, so each round's code differs and renders the same."""
    head = "MpSurface* s) {\\n"
    def change(m):
        body = m.group(2)
        if head not in body:
            raise SystemExit("a tree without mp_node_surface: " + body[:80])
        body = body.replace(head, head + f"  if (g->footprint == -{k}.5f) s->dropped = {k};\\n", 1)
        return m.group(1) + body + m.group(3)
    return PROGRAM.sub(change, text)


def render(cli, rib, out, env, stats):
    t0 = time.perf_counter()
    subprocess.run([cli, rib, "-o", out, "--stats", stats, "--allow-any-path"], env=env, check=True,
                   stdout=subprocess.DEVNULL)
    seconds = time.perf_counter() - t0
    with open(stats) as f:
        return seconds, json.load(f).get("program_build_ms", 0.0) / 1000.0


def run(clis, rounds, cold=False):
    with open(RIB) as f:
        text = f.read()
    trees = len(PROGRAM.findall(text))
    work = tempfile.mkdtemp(prefix="mp-program-build-")
    results = {name: {"new": [], "cached": [], "build": []} for name in clis}
    try:
        envs = {}
        for name in clis:
            env = dict(os.environ)
            env["MICROPOLY_CACHE_DIR"] = os.path.join(work, name + "-cache")
            env["POCL_CACHE_DIR"] = os.path.join(work, name + "-pocl")
            envs[name] = env
        # Warm-up: the stages' program built and cached for each build.
        base = RIB
        for name, cli in clis.items():
            render(cli, base, os.path.join(work, "warm.png"), envs[name], os.path.join(work, "s.json"))
        for k in range(1, rounds + 1):
            # Beside the scene: its textures are named relative to it.
            rib = os.path.join(os.path.dirname(RIB), f".material_trees_round{k}.rib")
            with open(rib, "w") as f:
                f.write(variant(text, k))
            for name, cli in clis.items():
                new, build = render(cli, rib, os.path.join(work, f"{name}{k}.png"), envs[name],
                                    os.path.join(work, "s.json"))
                cached, _ = render(cli, rib, os.path.join(work, f"{name}{k}.png"), envs[name],
                                   os.path.join(work, "s.json"))
                results[name]["new"].append(round(new, 3))
                results[name]["cached"].append(round(cached, 3))
                results[name]["build"].append(round(build, 3))
            os.remove(rib)
        if cold:
            for k in range(rounds):
                for name, cli in clis.items():
                    env = dict(os.environ)
                    env["MICROPOLY_CACHE_DIR"] = os.path.join(work, f"{name}-cold{k}")
                    env["POCL_CACHE_DIR"] = os.path.join(work, f"{name}-cold-pocl{k}")
                    seconds, build = render(cli, RIB, os.path.join(work, "cold.png"), env,
                                            os.path.join(work, "s.json"))
                    results[name].setdefault("cold", []).append(round(seconds, 3))
                    results[name].setdefault("cold_build", []).append(round(build, 3))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    summary = {"scene": os.path.basename(RIB), "trees": trees, "rounds": rounds}
    for name, r in results.items():
        per_tree = [(n - c) / trees for n, c in zip(r["new"], r["cached"])]
        summary[name] = dict(r, median_new_s=statistics.median(r["new"]),
                             median_cached_s=statistics.median(r["cached"]),
                             median_per_tree_s=round(statistics.median(per_tree), 3))
        if cold:
            summary[name]["median_cold_s"] = statistics.median(r["cold"])
    return summary


def main(argv):
    if "--make-rib" in argv:
        make_rib()
        return 0
    clis = {"after": argv[argv.index("--cli") + 1]}
    if "--before" in argv:
        clis = {"before": argv[argv.index("--before") + 1], **clis}
    rounds = int(argv[argv.index("--rounds") + 1]) if "--rounds" in argv else 5
    summary = run(clis, rounds, cold="--cold" in argv)
    print(json.dumps(summary, indent=1))
    if "--json" in argv:
        with open(argv[argv.index("--json") + 1], "w") as f:
            json.dump(summary, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]))
