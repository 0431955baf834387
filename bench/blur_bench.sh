#!/usr/bin/env bash
# The blur benchmark through the CLI, from a bundle made by
# bench/make_device_bundle.sh (run in its folder, .device/), after
# bench/blur_bench.py --rib-only wrote bench/out/blur_*.rib: the six
# Suzannes static, with motion blur and with depth of field, 1920x1080
# 16 spp, in interleaved rounds of REPEAT frames (20). Prints the medians of
# each round's per-frame median stage times, micropolygons and sample tests
# per sample, and each blur's cost over the static frame. DEVICE=cpu runs it
# on PoCL.
set -u
cd "$(dirname "$0")"
OUT=${OUT:-/tmp/blur_bench}
DEVICE=${DEVICE:-gpu}
REPEAT=${REPEAT:-20}
ROUNDS=${ROUNDS:-3}
mkdir -p "$OUT"
. ./device_env.sh
for round in $(seq 1 "$ROUNDS"); do
  for scene in static motion dof; do
    ./micropoly-render "blur_$scene.rib" -o "$OUT/$scene.png" --device "$DEVICE" --repeat "$REPEAT" \
      --stats "$OUT/${scene}_$round.json" >/dev/null || echo "blur_$scene.rib failed"
  done
done
python3 - "$OUT" "$ROUNDS" <<'PY'
import json, statistics, sys
out, rounds = sys.argv[1], int(sys.argv[2])
keys = ("total", "upload", "shadows_wall", "bound_split", "dice", "shade", "sample", "resolve", "readback")
totals = {}
for scene in ("static", "motion", "dof"):
    meds = {}
    for r in range(1, rounds + 1):
        frames = json.load(open(f"{out}/{scene}_{r}.json"))
        for k in keys:
            meds.setdefault(k, []).append(statistics.median(f["timings_ms"].get(k, 0.0) for f in frames[1:]))
    last = json.load(open(f"{out}/{scene}_1.json"))[-1]
    med = {k: round(statistics.median(v), 3) for k, v in meds.items()}
    totals[scene] = med["total"]
    print(scene, json.dumps(med))
    print("    micropolygons", last["micropolygons"], "sample tests", last.get("sample_tests"),
          "per sample", round(last.get("sample_tests_per_sample", 0.0), 2))
for scene in ("motion", "dof"):
    print(f"{scene}: {totals[scene] / totals['static']:.2f}x the static frame")
PY
