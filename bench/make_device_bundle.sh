#!/usr/bin/env bash
# Packs the built CLI, test binary and device_limits with the shared libraries they need
# (everything but glibc) into .device/, for running on a machine that has a
# GPU but no Debian packages. Usage: bench/make_device_bundle.sh [build-dir]
set -euo pipefail
build=${1:-build}
out=.device
rm -rf "$out" && mkdir -p "$out/lib"
cp "$build/micropoly-render" "$build/micropoly_tests" "$build/device_limits" "$out/"
for bin in "$build/micropoly-render" "$build/micropoly_tests" "$build/device_limits"; do
  ldd "$bin" | awk '/=> \//{print $3}' | grep -vE '/(libc|libm|libpthread|libdl|librt)\.so' | xargs -r cp -L -t "$out/lib/"
done
cp -r tests/scenes "$out/scenes"
# The runner and its suites (bench/bench.py), the image comparison and the
# environment the GPU machine needs (device_env.sh).
cp bench/bench.py bench/suites.py bench/scenes.py bench/identical_images.py bench/device_env.sh "$out/"
# An earlier build's CLI for before/after runs (bench.py --before), if given.
[ -n "${BEFORE:-}" ] && cp "$BEFORE" "$out/micropoly-render-before"
# The benchmark scenes bench/blender_bench.py writes as RIB (--rib-only).
[ -d bench/out ] && cp bench/out/*.rib "$out/" 2>/dev/null || true
[ -d bench/out ] && cp -r bench/out/*_textures "$out/" 2>/dev/null || true
du -sh "$out"
