#!/usr/bin/env bash
# The world-lighting benchmark through the CLI, from a bundle made by
# bench/make_device_bundle.sh (run in its folder, .device/), after
# bench/world_bench.py --rib-only wrote bench/out/world_*.rib: the scene lit
# by an HDRI world (16 shadowed directions), by four lights casting soft
# shadows, and by nothing, 1920x1080 16 spp, in interleaved rounds of REPEAT
# frames (20), each frame rendering its shadow maps afresh (a moving
# camera's cost; --fresh-shadows). Prints the medians of each round's
# per-frame median, the first frame of each (world baking, prefiltering and
# uploads), and the world's and the four lights' cost over the unlit frame.
# DEVICE=cpu runs it on PoCL.
set -u
cd "$(dirname "$0")"
OUT=${OUT:-/tmp/world_bench}
DEVICE=${DEVICE:-gpu}
REPEAT=${REPEAT:-20}
ROUNDS=${ROUNDS:-3}
mkdir -p "$OUT"
. ./device_env.sh
for round in $(seq 1 "$ROUNDS"); do
  for scene in hdri lights4 none; do
    ./micropoly-render "world_$scene.rib" -o "$OUT/$scene.png" --device "$DEVICE" --fresh-shadows --repeat "$REPEAT" \
      --stats "$OUT/${scene}_$round.json" >/dev/null || echo "world_$scene.rib failed"
  done
done
python3 - "$OUT" "$ROUNDS" <<'PY'
import json, statistics, sys
out, rounds = sys.argv[1], int(sys.argv[2])
keys = ("total", "upload", "shadow_mark", "shadow", "shadows_wall", "bound_split", "dice", "shade", "sample", "resolve",
        "readback")
totals = {}
for scene in ("hdri", "lights4", "none"):
    meds = {}
    for r in range(1, rounds + 1):
        frames = json.load(open(f"{out}/{scene}_{r}.json"))
        for k in keys:
            meds.setdefault(k, []).append(statistics.median(f["timings_ms"].get(k, 0.0) for f in frames[1:]))
    first = json.load(open(f"{out}/{scene}_1.json"))[0]
    med = {k: round(statistics.median(v), 3) for k, v in meds.items()}
    totals[scene] = med["total"]
    sh = first.get("shadows", {})
    print(scene, json.dumps(med))
    print("    first frame total", round(first["timings_ms"]["total"], 2), "upload", round(first["timings_ms"]["upload"], 2),
          "shadowed lights", sh.get("lights"), "shadow micropolygons", sh.get("micropolygons"),
          "peak MiB", round(sh.get("peak_bytes", 0) / 2**20, 1))
world, lights = totals["hdri"] - totals["none"], totals["lights4"] - totals["none"]
print(f"world lighting adds {world:.2f} ms; four shadowed lights add {lights:.2f} ms; ratio {world / lights:.2f}")
PY
