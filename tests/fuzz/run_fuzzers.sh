#!/usr/bin/env bash
# Runs the libFuzzer targets built by a -DGSSM_FUZZ=ON build (clang,
# ASan + UBSan) for SECONDS each on a copy of the seed corpus; fails on the
# first crash, leak or sanitizer report, showing the log's tail.
#   tests/fuzz/run_fuzzers.sh SECONDS BUILD_DIR      (longer by hand: 600)
set -euo pipefail
secs="${1:-30}"
src="$(cd "$(dirname "$0")/../.." && pwd)"
bin="${2:?build directory of a -DGSSM_FUZZ=ON build}/tests"
for t in csv ini checkpoint pos; do
  work="$bin/fuzz-$t"
  rm -rf "$work"; mkdir -p "$work"; cp -r "$src/tests/fuzz/corpus/$t" "$work/corpus"
  echo "fuzz_$t: ${secs}s"
  "$bin/fuzz_$t" -max_total_time="$secs" -max_len=16384 -timeout=10 -rss_limit_mb=4096 \
      -artifact_prefix="$work/" "$work/corpus" 2> "$work/log" \
    || { tail -60 "$work/log"; echo "fuzz_$t FAILED: crash input in $work/"; exit 1; }
  grep -E "Done [0-9]+ runs" "$work/log" | tail -1
done
echo "fuzzers: ok"
