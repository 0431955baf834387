"""What each benchmark suite renders (bench/bench.py runs them): its cases,
each a name, a scene and the CLI options it renders with; how many frames
a run renders by default; which stage timings its table shows; and which
ratios between its cases it prints.

The scenes are RIB files that the scene generators write with --rib-only
into bench/out (blender_bench.py --shadows: shadow_suzannes;
occlusion_bench.py: shells_N, shells_out_N, layers_point, layers_sun,
field_2000; world_bench.py: world_*; blur_bench.py: blur_*; texture_bench.py:
texture_*); the standard suite writes its own (scenes.py) from
tests/scenes/teapot.rib."""

import os
from collections import namedtuple

import scenes

Case = namedtuple("Case", "name scene options")

CORE_STAGES = ("bound_split", "dice", "shade", "sample", "resolve", "readback", "readback_wait")
SHADOW_STAGES = ("shadow_mark", "shadow", "shadow_bound_split", "shadow_dice", "shadow_sample", "shadows_wall")


class Suite:
    def __init__(self, about, cases, repeat, stages=CORE_STAGES, ratios=()):
        self.about = about
        self._cases = cases  # a list of Cases, or a function of (scene folder, temporary folder) giving one
        self.repeat = repeat
        self.stages = stages
        self.ratios = ratios  # (case, over case) pairs

    def cases(self, scene_dir, tmp):
        return self._cases(scene_dir, tmp) if callable(self._cases) else list(self._cases)


def _teapot(scene_dir):
    teapot = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "scenes", "teapot.rib")
    if not os.path.exists(teapot):  # the device bundle keeps tests/scenes beside the runner
        teapot = os.path.join(scene_dir, "scenes", "teapot.rib")
    return teapot


def _standard(scene_dir, tmp):
    paths = scenes.write_all(tmp, _teapot(scene_dir))
    paths.pop("wide_subdiv_4k")  # the memory sweep's scene, not a frame to time
    return [Case(name, rib, []) for name, rib in paths.items()]


def _memory(scene_dir, tmp):
    """Bound & split within budgets of 4 to 256 MiB, and breadth-first, on
    the two scenes that split the most."""
    teapot = _teapot(scene_dir)
    paths = scenes.write_all(tmp, teapot)
    cases = []
    for scene in ("wide_subdiv_4k", "eye_split_plane"):
        for budget in (4, 16, 64, 256):
            cases.append(Case(f"{scene}/bounded_{budget}", paths[scene],
                              ["--bound-split", "bounded", "--bound-split-memory", str(budget)]))
        cases.append(Case(f"{scene}/breadth", paths[scene], ["--bound-split", "breadth"]))
    return cases


def _occlusion_cases():
    cases = []
    for scene in ("shells_1", "shells_4", "shells_16", "shells_64", "field_2000", "shadow_suzannes"):
        for mode in ("on", "off"):
            cases.append(Case(f"{scene}/culling_{mode}", scene + ".rib", ["--spp", "4", "--occlusion-culling", mode]))
    return cases


def _culling_cases():
    names = ["shells_1", "shells_16", "shells_64", "shells_out_1", "shells_out_16", "shells_out_64", "layers_point",
             "layers_sun", "field_2000"]
    return [Case(n, n + ".rib", ["--spp", "16", "--fresh-shadows"]) for n in names]


SUITES = {
    "standard": Suite("the standard scenes (scenes.py) at their own sizes and samples", _standard, repeat=10),
    "memory": Suite("bound & split within 4, 16, 64 and 256 MiB and breadth-first, on the scenes that split most",
                    _memory, repeat=5, stages=("bound_split",) + CORE_STAGES[1:]),
    "occlusion": Suite("occlusion culling on and off: nested shells, the rock field and the six Suzannes, 4 spp",
                       _occlusion_cases(), repeat=10, stages=CORE_STAGES + ("occlusion", "shadows_wall"),
                       ratios=[(f"{s}/culling_off", f"{s}/culling_on") for s in
                               ("shells_1", "shells_4", "shells_16", "shells_64", "field_2000", "shadow_suzannes")]),
    "shadows": Suite("three soft-shadowed lights on the six Suzannes: fresh maps every frame, maps kept "
                     "(a still view), no shadows; and the breadth-first bound & split",
                     [Case("fresh", "shadow_suzannes.rib", ["--fresh-shadows"]),
                      Case("kept", "shadow_suzannes.rib", []),
                      Case("off", "shadow_suzannes.rib", ["--shadows", "off"]),
                      Case("breadth_fresh", "shadow_suzannes.rib", ["--fresh-shadows", "--bound-split", "breadth"]),
                      Case("breadth_off", "shadow_suzannes.rib", ["--shadows", "off", "--bound-split", "breadth"])],
                     repeat=30, stages=SHADOW_STAGES + CORE_STAGES,
                     ratios=[("fresh", "off"), ("kept", "off"), ("breadth_fresh", "fresh")]),
    "world": Suite("world light (an HDRI, 16 shadowed directions) against four soft-shadowed lights and none",
                   [Case(s, f"world_{s}.rib", ["--fresh-shadows"]) for s in ("hdri", "lights4", "none")],
                   repeat=20, stages=("upload",) + SHADOW_STAGES + CORE_STAGES,
                   ratios=[("hdri", "none"), ("lights4", "none")]),
    "blur": Suite("the six Suzannes still, with motion blur and with depth of field",
                  [Case(s, f"blur_{s}.rib", []) for s in ("static", "motion", "dof")],
                  repeat=20, ratios=[("motion", "static"), ("dof", "static")]),
    "textures": Suite("image textures filtered (MIP-mapped, anisotropic) and unfiltered: a checkerboard floor to "
                      "the horizon and a busy image on a small distant card, 1920x1080, 16 spp",
                      [Case(f"{scene}/{mode}", f"texture_{scene}.rib", ["--texture-filter-width", width])
                       for scene in ("floor", "card") for mode, width in (("filtered", "1"), ("unfiltered", "0"))],
                      repeat=10, stages=("upload",) + CORE_STAGES,
                      ratios=[("floor/filtered", "floor/unfiltered"), ("card/filtered", "card/unfiltered")]),
    "materials": Suite("node trees recorded by their programs and lit by the light program: the soak scene's "
                       "trees at 1920x1080 (bench/program_build_bench.py --make-rib), and the image textures' "
                       "emission trees",
                       [Case("trees", "material_trees_1080.rib", []),
                        Case("floor", "texture_floor.rib", []), Case("card", "texture_card.rib", [])],
                       repeat=10, stages=("upload",) + SHADOW_STAGES + CORE_STAGES),
    "gpu_frame": Suite("the GPU frame's scenes (bench/gpu_frame_scenes.py): a tree outdoors and a colonnade, each under "
                       "a soft sun, 1080p, 16 spp; shadow pages kept (a still view) and rendered every frame",
                       [Case(f"{s}/{v}", f"{s}.rib", ["--spp", "16"] + o) for s in ("outdoor", "colonnade")
                        for v, o in (("kept", []), ("fresh", ["--fresh-shadows"]))],
                       repeat=20, stages=SHADOW_STAGES + CORE_STAGES),
    "viewport_loop": Suite("a Rendered viewport's loop in the CLI: 4 spp, half-float read-back, shadow pages kept, "
                           "frames overlapped (time them with --frame interval)",
                           [Case(n, n + ".rib", ["--spp", "4", "--readback", "half"])
                            for n in ("outdoor", "colonnade", "shells_1", "shells_64", "layers_point")],
                           repeat=10, stages=SHADOW_STAGES + CORE_STAGES),
    "culling": Suite("hidden layers in every view, shadows on: nested shells (lamp inside, lamp outside), "
                     "1,000 stacked layers (point lamp, sun), the rock field",
                     _culling_cases(), repeat=3, stages=SHADOW_STAGES + CORE_STAGES,
                     ratios=[("shells_16", "shells_1"), ("shells_64", "shells_1"),
                             ("shells_out_16", "shells_out_1"), ("shells_out_64", "shells_out_1")]),
}
