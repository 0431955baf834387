#!/usr/bin/env bash
# The shadow benchmark through the CLI, from a bundle made by
# bench/make_device_bundle.sh (run in its folder, .device/): on a GPU machine
# the GPU tests first, then the six-Suzanne scene
# (bench/out/shadow_suzannes.rib, written by bench/blender_bench.py --shadows
# --rib-only) at 1920x1080, 16 spp, its three lights casting soft shadows, in
# interleaved rounds of REPEAT frames (30): shadows on with fresh maps every
# frame, on with pages kept between frames (a still scene, as the viewport
# redraws it), and off; then once each with the breadth-first bound & split.
# Prints the medians of each round's per-frame median and writes everything
# under $OUT. DEVICE=cpu runs it on PoCL (no tests: SKIP_TESTS=1).
set -u
cd "$(dirname "$0")"
OUT=${OUT:-/tmp/shadow_bench}
DEVICE=${DEVICE:-gpu}
REPEAT=${REPEAT:-30}
mkdir -p "$OUT"
. ./device_env.sh
if [ -z "${SKIP_TESTS:-}" ]; then
  MICROPOLY_DEVICE=gpu ./micropoly_tests --gtest_filter="${TESTS:-*Shadow*:RenderTest.*:Watertight*:MaterialProgram*}" \
    > "$OUT/gpu_tests.txt" 2>&1
  tail -3 "$OUT/gpu_tests.txt"
  grep -E "FAILED|Failure" "$OUT/gpu_tests.txt" | head
fi
scene=${SCENE:-shadow_suzannes.rib}
for round in 1 2 3; do
  ./micropoly-render "$scene" -o "$OUT/on.png" --device "$DEVICE" --fresh-shadows --repeat "$REPEAT" --stats "$OUT/on_$round.json" >/dev/null
  ./micropoly-render "$scene" -o "$OUT/kept.png" --device "$DEVICE" --repeat "$REPEAT" --stats "$OUT/kept_$round.json" >/dev/null
  ./micropoly-render "$scene" -o "$OUT/off.png" --device "$DEVICE" --shadows off --repeat "$REPEAT" --stats "$OUT/off_$round.json" >/dev/null
done
# The breadth-first bound & split, once each.
./micropoly-render "$scene" -o "$OUT/on_breadth.png" --device "$DEVICE" --fresh-shadows --bound-split breadth --repeat "$REPEAT" \
  --stats "$OUT/breadth_on_1.json" >/dev/null
./micropoly-render "$scene" -o "$OUT/off_breadth.png" --device "$DEVICE" --shadows off --bound-split breadth --repeat "$REPEAT" \
  --stats "$OUT/breadth_off_1.json" >/dev/null
python3 - "$OUT" <<'PY'
import json, os, statistics, sys
out = sys.argv[1]
keys = ("total", "shadow_mark", "shadow", "shadow_bound_split", "shadow_dice", "shadow_sample", "shadows_wall",
        "bound_split", "dice", "shade", "sample", "resolve", "readback")
for mode in ("on", "kept", "off", "breadth_on", "breadth_off"):
    rounds = (1,) if mode.startswith("breadth") else (1, 2, 3)
    meds = {}
    for r in rounds:
        frames = json.load(open(f"{out}/{mode}_{r}.json"))[1:]  # the first frame builds programs and buffers
        for k in keys:
            meds.setdefault(k, []).append(statistics.median(f["timings_ms"].get(k, 0.0) for f in frames))
    last = json.load(open(f"{out}/{mode}_1.json"))[-1]
    sh = last["shadows"]
    print(mode, json.dumps({k: round(statistics.median(v), 3) for k, v in meds.items()}))
    print("   ", "launches", last["bound_split_launches"], "pages", sh["pages_requested"], "rendered", sh["pages_rendered"], "shadow micropolygons",
          sh["micropolygons"], "batches", sh["batches"], "mark wall ms", round(sh["mark_wall_ms"], 2),
          "render wall ms", round(sh["render_wall_ms"], 2), "peak MiB", round(sh["peak_bytes"] / 2**20, 1), "per light MiB",
          [round(l["bytes"] / 2**20, 1) for l in sh["per_light"]])
    for r in rounds[1:]:
        os.remove(f"{out}/{mode}_{r}.json")  # the medians above keep them
PY
