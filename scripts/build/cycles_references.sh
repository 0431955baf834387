#!/usr/bin/env bash
# Renders again the Cycles references that the Blender tests compare against
# (tests/references/cycles; tests/blender/cycles_references.py says how they
# are keyed): after a test's scene or script changes, or for a new Blender.
# Runs the tests that render Cycles, with every Blender the build tree tests
# with (Debian's and build/bpy-*), storing Cycles' passes as they go.
#   scripts/build/cycles_references.sh            all of them
#   scripts/build/cycles_references.sh closures   only test_closures.py
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${MICROPOLY_BUILD_DIR:-build}
if [ $# -eq 0 ]; then
  set -- $(grep -l '"CYCLES"' tests/blender/test_*.py | sed 's|.*/test_||; s|\.py$||')
fi
pattern=$(IFS='|'; echo "$*")
cd "$build"
MICROPOLY_CYCLES_REFERENCES=update ctest --output-on-failure -j "$(nproc)" -R "^(blender|bpy-[0-9.]+)_(${pattern})\$"
