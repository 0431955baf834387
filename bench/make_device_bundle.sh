#!/usr/bin/env bash
# Packs the built CLI and test binary with the shared libraries they need
# (everything but glibc) into .device/, for running on a machine that has a
# GPU but no Debian packages. Usage: bench/make_device_bundle.sh [build-dir]
set -euo pipefail
build=${1:-build}
out=.device
rm -rf "$out" && mkdir -p "$out/lib"
cp "$build/micropoly-render" "$build/micropoly_tests" "$out/"
for bin in "$build/micropoly-render" "$build/micropoly_tests"; do
  ldd "$bin" | awk '/=> \//{print $3}' | grep -vE '/(libc|libm|libpthread|libdl|librt)\.so' | xargs -r cp -L -t "$out/lib/"
done
cp -r tests/scenes "$out/scenes"
cp bench/shadow_culling_bench.py bench/identical_images.py bench/shadow_bench.sh bench/occlusion_bench.sh bench/world_bench.sh bench/blur_bench.sh bench/device_env.sh bench/before_after.py bench/before_after_stages.py bench/scenes.py "$out/"
# An earlier build's CLI for before/after runs (bench/before_after.py), if given.
[ -n "${BEFORE:-}" ] && cp "$BEFORE" "$out/micropoly-render-before"
# The benchmark scenes bench/blender_bench.py writes as RIB (--rib-only).
[ -d bench/out ] && cp bench/out/*.rib "$out/" 2>/dev/null || true
[ -d bench/out ] && cp -r bench/out/*_textures "$out/" 2>/dev/null || true
du -sh "$out"
