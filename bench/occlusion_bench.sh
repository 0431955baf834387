#!/usr/bin/env bash
# The occlusion culling benchmark through the CLI, from a bundle made by
# bench/make_device_bundle.sh (run in its folder, .device/, after
# bench/occlusion_bench.py --rib-only and bench/blender_bench.py --shadows
# --rib-only wrote the scenes): nested shells N = 1, 4, 16, 64, the field of
# 2,000 displaced rocks and the six Suzannes, 1920x1080, 4 spp, with
# occlusion culling on and off, in interleaved rounds (ROUNDS, 3) of REPEAT
# frames (10) each; SHADOWS=off renders them without shadow maps. Prints,
# per scene and mode, the median over rounds of each round's per-frame
# median and the frame's statistics; writes everything under $OUT.
# DEVICE=cpu runs it on PoCL. SKIP_OFF="shells_64" leaves culling-off runs
# of the named scenes out (hours on two cores).
set -u
cd "$(dirname "$0")"
OUT=${OUT:-/tmp/occlusion_bench}
DEVICE=${DEVICE:-gpu}
REPEAT=${REPEAT:-10}
ROUNDS=${ROUNDS:-3}
SCENES=${SCENES:-"shells_1 shells_4 shells_16 shells_64 field_2000 shadow_suzannes"}
mkdir -p "$OUT"
. ./device_env.sh
if [ -n "${TESTS:-}" ]; then
  MICROPOLY_DEVICE=$DEVICE ./micropoly_tests --gtest_filter="$TESTS" > "$OUT/tests.txt" 2>&1
  tail -3 "$OUT/tests.txt"
  grep -E "FAILED|Failure" "$OUT/tests.txt" | head
fi
extra=()
[ "${SHADOWS:-}" = off ] && extra=(--shadows off)
for round in $(seq 1 "$ROUNDS"); do
  for scene in $SCENES; do
    for mode in on off; do
      [ "$mode" = off ] && [[ " ${SKIP_OFF:-} " == *" $scene "* ]] && continue
      ./micropoly-render "$scene.rib" -o "$OUT/${scene}_$mode.png" --device "$DEVICE" --spp 4 \
        --occlusion-culling $mode "${extra[@]}" --repeat "$REPEAT" --stats "$OUT/${scene}_${mode}_$round.json" >/dev/null
    done
  done
done
python3 - "$OUT" "$ROUNDS" $SCENES <<'PY'
import json, os, statistics, sys
out, rounds, scenes = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
keys = ("total", "shadows_wall", "bound_split", "dice", "shade", "sample", "occlusion", "readback")
for scene in scenes:
    for mode in ("on", "off"):
        meds, frame = {}, None
        for r in range(1, rounds + 1):
            path = os.path.join(out, f"{scene}_{mode}_{r}.json")
            if not os.path.exists(path):
                continue
            frames = json.load(open(path))
            frames = frames if isinstance(frames, list) else [frames]
            frame = frames[-1]
            later = frames[1:] or frames
            for k in keys:
                meds.setdefault(k, []).append(statistics.median(f["timings_ms"][k] for f in later))
        if frame is None:
            continue
        t = {k: round(statistics.median(v), 3) for k, v in meds.items()}
        print(f"{scene} {mode} {json.dumps(t)}")
        print(f"    micropolygons {frame['micropolygons']} subpatches_diced {frame['subpatches_diced']} "
              f"occluded {frame['subpatches_occluded']} depth_complexity {frame['depth_complexity']:.3f} "
              f"shadow_micropolygons {frame['shadows']['micropolygons']} batches {frame['batches']}")
PY
