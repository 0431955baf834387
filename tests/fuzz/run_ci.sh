#!/usr/bin/env bash
# Runs every fuzz target built in BUILD_DIR (configured with -DMICROPOLY_FUZZ=ON)
# for a short fixed time on a copy of its committed seed corpus, after
# replaying the saved crash reproducers, and proves first that a planted bug
# is caught. Exits non-zero on any crash, sanitizer report, leak, timeout or
# out-of-memory, or when the planted bug goes unnoticed.
#
#   tests/fuzz/run_ci.sh BUILD_DIR
#
# Environment: MICROPOLY_FUZZ_SECONDS (default 30) per host target,
# MICROPOLY_FUZZ_PROGRAM_SECONDS (default 60) for the material program target
# (one OpenCL build per input); MICROPOLY_FUZZ_KEEP=1 keeps the work folder.
set -u -o pipefail

if [ $# -ne 1 ] || [ ! -d "$1" ]; then
  echo "usage: $0 BUILD_DIR (a build configured with -DMICROPOLY_FUZZ=ON)" >&2
  exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
build_dir=$(cd "$1" && pwd)
bin=$build_dir/tests/fuzz
seconds=${MICROPOLY_FUZZ_SECONDS:-30}
program_seconds=${MICROPOLY_FUZZ_PROGRAM_SECONDS:-60}
work=$(mktemp -d "${TMPDIR:-/tmp}/micropoly-fuzz.XXXXXX")
if [ "${MICROPOLY_FUZZ_KEEP:-0}" != 1 ]; then trap 'rm -rf "$work"' EXIT; fi

# Sanitizer reports are fatal (UBSan only warns by default); leaks of the
# OpenCL driver itself are not the renderer's.
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export LSAN_OPTIONS="suppressions=$here/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
# Material programs: PoCL's kernel cache would grow by one entry per input,
# and the renderer's binary cache is kept out of the user's home.
export POCL_KERNEL_CACHE=0
export MICROPOLY_CACHE_DIR="$work/cache"

# name  binary  seconds  libFuzzer options  extra LeakSanitizer options
#
# material_program: LeakSanitizer does not scan thread-local storage there.
# The target loads PoCL, whose LLVM and per-program kernel libraries are
# dlopen'ed with thread-local data; on some kernels and CPUs compiler-rt 14's
# walk over glibc's dynamic TLS vector meets an entry that is not a block and
# its tracer thread dies (SIGSEGV "Tracer caught signal 11", then "LeakSanitizer
# has encountered a fatal error") before any leak is judged. Without TLS as a
# root the check only grows stricter: an allocation that only a thread-local
# holds is then reported as a leak, none is hidden.
targets=(
  "rib_reader|fuzz_rib_reader|$seconds|-max_len=8192 -timeout=10 -rss_limit_mb=2048 -dict=$here/rib.dict|"
  "rib_round_trip|fuzz_rib_round_trip|$seconds|-max_len=8192 -timeout=10 -rss_limit_mb=2048 -dict=$here/rib.dict|"
  "scene_validation|fuzz_scene_validation|$seconds|-max_len=4096 -timeout=10 -rss_limit_mb=2048 -close_fd_mask=1|"
  "material_program|fuzz_material_program|$program_seconds|-max_len=1024 -timeout=60 -rss_limit_mb=4096 -dict=$here/opencl.dict|use_tls=0"
)

failed=0
fail() { echo "FAIL: $*" >&2; failed=1; }

# 1. The planted bug (fuzz_support.h): with MICROPOLY_FUZZ_PLANTED_BUG set, an
# input starting with the marker overflows a heap array. Each host target
# must stop on it with AddressSanitizer's report and save the crash input;
# a harness that lost its sanitizers or its crash reporting fails here.
for t in rib_reader rib_round_trip scene_validation; do
  exe="$bin/fuzz_$t"
  [ -x "$exe" ] || continue
  mkdir -p "$work/planted/$t/corpus" "$work/planted/$t/artifacts"
  printf 'MICROPOLY-PLANTED-BUG WorldBegin WorldEnd\n' > "$work/planted/$t/corpus/planted"
  MICROPOLY_FUZZ_PLANTED_BUG=1 "$exe" -max_total_time=10 -close_fd_mask=1 \
    -artifact_prefix="$work/planted/$t/artifacts/" "$work/planted/$t/corpus" > "$work/planted/$t/log" 2>&1
  rc=$?
  if [ $rc -eq 0 ] || ! grep -q "AddressSanitizer: heap-buffer-overflow" "$work/planted/$t/log" ||
     ! ls "$work/planted/$t/artifacts"/crash-* > /dev/null 2>&1; then
    fail "$t: the planted bug was not caught (exit $rc); see below"
    tail -n 20 "$work/planted/$t/log" >&2
  else
    echo "planted bug caught by fuzz_$t (exit $rc, crash input saved)"
  fi
done

# 2. Saved reproducers (regressions/<target>_*) must no longer fail, then
# 3. each target fuzzes for its time from a copy of its seed corpus. A target
# is one process on one core, and its time is fixed, so targets run side by
# side, one per core (MICROPOLY_FUZZ_JOBS, default: the cores), the longest
# first; each writes its row and its failures into the work folder.
fuzz_target() {
  local name=$1 exe_name=$2 secs=$3 opts=$4 lsan_extra=$5
  local lsan="$LSAN_OPTIONS${lsan_extra:+:$lsan_extra}" exe="$bin/$exe_name" failures="$work/$name.failures"
  if [ ! -x "$exe" ]; then
    echo "FAIL: $exe_name is not built in $build_dir" > "$failures"
    return
  fi
  local regressions=("$here"/regressions/"$name"_*)
  if [ -e "${regressions[0]}" ]; then
    # shellcheck disable=SC2086
    if ! LSAN_OPTIONS="$lsan" "$exe" $opts -runs=1 "${regressions[@]}" > "$work/$name.regressions.log" 2>&1; then
      { echo "FAIL: $name: a saved reproducer still fails"
        grep -E "ERROR|SUMMARY|Running:|differs|round trip" "$work/$name.regressions.log" | head -n 20; } >> "$failures"
    fi
  fi
  mkdir -p "$work/$name/corpus" "$work/$name/artifacts"
  cp "$here/corpus/$name"/* "$work/$name/corpus/" 2>/dev/null
  local before start rc elapsed runs rate after
  before=$(ls "$work/$name/corpus" | wc -l)
  start=$(date +%s)
  # shellcheck disable=SC2086
  LSAN_OPTIONS="$lsan" "$exe" $opts -max_total_time="$secs" -print_final_stats=1 \
    -artifact_prefix="$work/$name/artifacts/" "$work/$name/corpus" > "$work/$name.log" 2>&1
  rc=$?
  elapsed=$(( $(date +%s) - start ))
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/$name.log" | tail -n 1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$work/$name.log" | tail -n 1)
  after=$(ls "$work/$name/corpus" | wc -l)
  printf '%-18s %8s %10s %8s %14s\n' "$name" "$elapsed" "${runs:-?}" "${rate:-?}" "$before>$after" > "$work/$name.row"
  if [ $rc -ne 0 ]; then
    { echo "FAIL: $name: exit $rc; the input is saved in $work/$name/artifacts (set MICROPOLY_FUZZ_KEEP=1 to keep it)"
      grep -v '^#\|^INFO\|^"' "$work/$name.log" | tail -n 60; } >> "$failures"
  fi
}

jobs=${MICROPOLY_FUZZ_JOBS:-$(nproc)}
mapfile -t ordered < <(printf '%s\n' "${targets[@]}" | sort -t '|' -k3,3nr)
for entry in "${ordered[@]}"; do
  IFS='|' read -r name exe_name secs opts lsan_extra <<< "$entry"
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n; done
  fuzz_target "$name" "$exe_name" "$secs" "$opts" "$lsan_extra" &
done
wait
printf '%-18s %8s %10s %8s %14s\n' target seconds executions exec/s "corpus in>out"
for entry in "${targets[@]}"; do
  IFS='|' read -r name _ <<< "$entry"
  cat "$work/$name.row" 2>/dev/null
done
for entry in "${targets[@]}"; do
  IFS='|' read -r name _ <<< "$entry"
  if [ -s "$work/$name.failures" ]; then
    cat "$work/$name.failures" >&2
    failed=1
  fi
done

[ $failed -eq 0 ] && echo "fuzzing: all targets clean" || echo "fuzzing: FAILED" >&2
exit $failed
