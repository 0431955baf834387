#!/usr/bin/env bash
# Builds Micropoly with AddressSanitizer and UndefinedBehaviorSanitizer and runs
# the parts that read untrusted input or drive the device under them: the
# sanitized GoogleTest subset below, one CLI render, and the fuzz targets' CI
# run when tests/fuzz provides them (docs/reliability.md).
#
#   scripts/check_sanitized.sh [BUILD_DIR]     (default: build-sanitize)
#
# One clang build serves both the sanitized tests and the libFuzzer targets
# (libFuzzer is clang's; Debian 12: clang, libclang-rt-14-dev). Any sanitizer
# report, leak, test failure or failed render makes the script exit non-zero.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=$(realpath -m "${1:-build-sanitize}")
jobs=${MICROPOLY_JOBS:-2}
start=$SECONDS

# -O1 keeps the instrumented renders quick while leaving every call in the
# reports' stacks; line tables alone give file:line there and build faster
# than full debug information. Assertions stay on (no -DNDEBUG).
opt_flags="-O1 -gline-tables-only"
fuzz=OFF
if [[ -f $root/tests/fuzz/CMakeLists.txt ]]; then fuzz=ON; fi

echo "== configure $build (clang, address+undefined, fuzz $fuzz)"
mkdir -p "$build"
CC=clang CXX=clang++ cmake -S "$root" -B "$build" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_C_FLAGS_RELWITHDEBINFO=$opt_flags" \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$opt_flags" \
  -DMICROPOLY_SANITIZE=address,undefined \
  -DMICROPOLY_FUZZ=$fuzz \
  -DMICROPOLY_BUILD_PYTHON=OFF >"$build/configure-output.log" 2>&1 \
  || { cat "$build/configure-output.log"; exit 1; }

echo "== build (-j$jobs)"
# The default target: micropoly_tests, micropoly-render, the small
# texture_probe tool and, with MICROPOLY_FUZZ, the fuzz targets.
cmake --build "$build" -j "$jobs"
echo "   configure + build: $((SECONDS - start)) s"

# Sanitizer settings for the tests and the render below (tests/fuzz/run_ci.sh
# sets its own for the fuzz targets).
#   ASAN_OPTIONS
#     detect_leaks=1                 LeakSanitizer checks at exit (already the
#                                    default on x86_64 Linux; stated so that a
#                                    changed default cannot drop it silently)
#     check_initialization_order=1   with strict_init_order=1: a static
#     strict_init_order=1            initialiser that reads another file's
#                                    global before it is built is an error
#   LSAN_OPTIONS  tests/sanitize/lsan.supp: the OpenCL driver's allocations
#                 that live until exit (that file says which and why)
#   UBSAN_OPTIONS print_stacktrace=1: reports come with the call stack;
#                 halt_on_error=1: the first report ends the process (the
#                 code is also built with -fno-sanitize-recover=undefined)
# use_tls=0: LeakSanitizer's tracer can die walking glibc's dynamic
# thread-local vector once PoCL has loaded kernel libraries (seen here when
# the shards finish side by side); leaving thread-local storage out of the
# roots only makes the check stricter (docs/reliability.md).
sanitized=(env
  ASAN_OPTIONS="detect_leaks=1:check_initialization_order=1:strict_init_order=1"
  LSAN_OPTIONS="suppressions=$root/tests/sanitize/lsan.supp:use_tls=0"
  UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1")

# The sanitized subset, by test suite:
#   scene validation      RenderTest.InvalidSceneIsRejected*, SmoothShadingInput,
#                         MaterialProgramTest.*Rejected*, WorldLighting.Bad*
#   RIB reader            Rib* (test_rib.cpp, test_rib_errors.cpp incl. RibJunk,
#                         test_rib_patches.cpp)
#   untrusted files       Untrusted* (paths, searchpath, program checks),
#                         ImageBounds (crafted PNG and OpenEXR headers)
#   RIB writer            RibWriter* (test_rib_writer.cpp, with its renders)
#   patch building        SubdivPatchEval, SubdivRobustness, PatchEvalMath,
#                         PolygonPatches, BezierPatches, PatchCache, Watertight,
#                         WatertightRender
#   material programs     MaterialProgramTest (textured and displaced), ProgramCache
#   full renders on the default device (PoCL on CPU machines):
#     bounded and breadth-first bound-and-split   RenderTest
#     tile and per-micropolygon samplers          SampleTilesTest, TileSamplerGate
#     the bins and their lists                    SampleBinsTest.BinsChoose*, SampleBins
#     shadows                                     ShadowRenderTest, ShadowPagePool
#   device faults mid-frame and the recovery      DeviceFault
#   the read-back's worker thread, frames overlapped
#   and half floats widened                       ReadBackTest, HalfFloats
#   after them (freed and rebuilt device state)
#   the planted-bug self-test                     SanitizerSelfTest
filter="RenderTest.*:SmoothShadingInput.*:Rib*:SubdivPatchEval.*:SubdivRobustness.*"
filter+=":PatchEvalMath.*:PolygonPatches.*:BezierPatches.*:PatchCache.*:Watertight.*:WatertightRender.*"
filter+=":MaterialProgramTest.*:ProgramCache.*:SampleTilesTest.*:TileSamplerGate.*"
filter+=":ShadowRenderTest.*:ShadowPagePool.*:WorldLighting.BadWorldsAreRefusedCleanly"
filter+=":Untrusted*:ImageBounds.*:DeviceFault*:SanitizerSelfTest.*:RefractionTrace.*:RefractionRenderTest.*"
filter+=":ReadBackTest.*:HalfFloats.*:SampleBinsTest.BinsChoose*:SampleBins.*"
# Left out to keep the step near ten minutes on two cores: the slowest
# repeats of paths already covered above (bucketed tiles, and the watertight
# renders under motion blur and depth of field).
exclude="SampleTilesTest.BucketsEqualTheWholeFrame:WatertightRender.NoPinholesInMotion"
exclude+=":WatertightRender.NoPinholesOutOfFocus"

echo "== sanitized tests"
# A renamed or removed suite must not shrink the subset silently: every
# pattern has to match at least one test.
IFS=: read -ra patterns <<<"$filter"
for pattern in "${patterns[@]}"; do
  listed=$("${sanitized[@]}" "$build/micropoly_tests" --gtest_list_tests --gtest_filter="$pattern")
  if ! grep -q '^  ' <<<"$listed"; then
    echo "check_sanitized.sh: the sanitized subset's pattern '$pattern' matches no test" >&2
    exit 1
  fi
done
t=$SECONDS
# One shard per job (GoogleTest's sharding), side by side: the instrumented
# host code is one thread per process, so two shards on two cores take 52 s
# where one process took 85. Per-test times land in
# sanitized-tests-<shard>.json for finding what slows the step.
pids=()
for ((shard = 0; shard < jobs; shard++)); do
  GTEST_TOTAL_SHARDS=$jobs GTEST_SHARD_INDEX=$shard "${sanitized[@]}" "$build/micropoly_tests" \
    --gtest_filter="$filter-$exclude" --gtest_brief=1 \
    --gtest_output="json:$build/sanitized-tests-$shard.json" >"$build/sanitized-tests-$shard.log" 2>&1 &
  pids+=($!)
done
failed=0
for ((shard = 0; shard < jobs; shard++)); do
  if ! wait "${pids[$shard]}"; then
    echo "check_sanitized.sh: sanitized test shard $shard of $jobs failed:" >&2
    cat "$build/sanitized-tests-$shard.log" >&2
    failed=1
  fi
done
grep -h '^\[  PASSED  \]' "$build"/sanitized-tests-*.log
[[ $failed -eq 0 ]] || exit 1
echo "   tests: $((SECONDS - t)) s"

echo "== CLI render of tests/scenes/teapot.rib"
t=$SECONDS
"${sanitized[@]}" "$build/micropoly-render" "$root/tests/scenes/teapot.rib" -o "$build/sanitized-teapot.png"
echo "   CLI: $((SECONDS - t)) s"

if [[ -f $root/tests/fuzz/run_ci.sh ]]; then
  echo "== fuzz targets (tests/fuzz/run_ci.sh)"
  t=$SECONDS
  bash "$root/tests/fuzz/run_ci.sh" "$build"
  echo "   fuzz: $((SECONDS - t)) s"
fi

echo "== sanitized checks passed in $((SECONDS - start)) s"
