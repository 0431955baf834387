#!/usr/bin/env bash
# Hair on the GPU: writes the bench/hair_rib.py groom of N strands x 16
# segments and renders it with micropoly-render --device gpu --repeat 5,
# printing one line per frame from the statistics. Run in the device bundle
# (bench/make_device_bundle.sh, with hair_rib.py copied beside it) after
# `source device_env.sh`; with BEFORE=1 the bundle's earlier CLI
# (micropoly-render-before) renders the same file first.
#   bash hair_gpu.sh N [N ...]
set -uo pipefail
OUT=${OUT:-/tmp/bench}
mkdir -p "$OUT"
for n in "$@"; do
  rib=hair_$n.rib
  python3 hair_rib.py "$rib" --strands "$n"
  echo "# $rib: $(du -m "$rib" | cut -f1) MB"
  clis=(./micropoly-render)
  [ -n "${BEFORE:-}" ] && [ -x ./micropoly-render-before ] && clis=(./micropoly-render-before ./micropoly-render)
  for cli in "${clis[@]}"; do
    json=$OUT/hair_${n}_$(basename "$cli").json
    start=$SECONDS
    /usr/bin/time -f "peak resident %M KB" "$cli" "$rib" -o "$OUT/hair_${n}_$(basename "$cli").png" --device gpu \
      --repeat 5 --stats "$json" 2>&1 | tail -2
    echo "# $cli: CLI wall $((SECONDS - start)) s (parse, build, 5 frames)"
    python3 - "$json" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1]))
frames = d if isinstance(d, list) else [d]
for k, f in enumerate(frames):
    t = f.get("timings_ms", {})
    keys = ["total", "interval", "upload", "bound_split", "dice", "shade", "sample", "resolve", "readback", "shadows_wall"]
    print(f"frame {k}: patches {f.get('patches')}, micropolygons {f.get('micropolygons')}, "
          f"scene {f.get('scene_bytes', 0) / 2**30:.2f} GiB, " + ", ".join(f"{x} {t[x]:.1f} ms" for x in keys if x in t))
EOF
  done
  rm -f "$rib"
done
