#!/usr/bin/env bash
# A long fuzzing run of the three host targets at once, each with WORKERS
# libFuzzer workers (-fork), for SECONDS; findings are kept and counted, not
# fatal (docs/reliability.md, Fuzzing). For a many-core machine.
#
#   tests/fuzz/long_run.sh FUZZ_BIN_DIR OUT_DIR [SECONDS=3600] [WORKERS=5]
#
# FUZZ_BIN_DIR holds fuzz_rib_reader, fuzz_rib_round_trip and
# fuzz_scene_validation (BUILD/tests/fuzz). OUT_DIR receives each target's
# log, its grown corpus and its findings (artifacts/).
set -u -o pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 FUZZ_BIN_DIR OUT_DIR [SECONDS] [WORKERS]" >&2
  exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
bin=$(cd "$1" && pwd)
out=$(mkdir -p "$2" && cd "$2" && pwd)
seconds=${3:-3600}
workers=${4:-5}
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 ASAN_OPTIONS=detect_leaks=1
export LSAN_OPTIONS=suppressions=$here/lsan.supp
for t in rib_reader rib_round_trip scene_validation; do
  mkdir -p "$out/$t/corpus" "$out/$t/artifacts"
  cp "$here/corpus/$t"/* "$out/$t/corpus/"
  extra=(-max_len=8192 "-dict=$here/rib.dict")
  [ $t = scene_validation ] && extra=(-max_len=4096 -close_fd_mask=1)
  "$bin/fuzz_$t" -fork="$workers" -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 "${extra[@]}" \
    -artifact_prefix="$out/$t/artifacts/" "$out/$t/corpus" > "$out/$t.log" 2>&1 &
done
wait
for t in rib_reader rib_round_trip scene_validation; do
  echo "== $t"
  grep -E "^#[0-9]+: cov" "$out/$t.log" | tail -n 1
  echo "corpus: $(ls "$here/corpus/$t" | wc -l) -> $(ls "$out/$t/corpus" | wc -l) inputs;" \
       "findings: $(ls "$out/$t/artifacts" | sed 's/-.*//' | sort | uniq -c | tr '\n' ' ')"
done
