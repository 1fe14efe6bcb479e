#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (+ASan/UBSan) from the io sources
# only, and runs each for SECONDS (default 30) on a copy of the seed corpus.
# Longer by hand: tests/fuzz/run_fuzzers.sh 600
set -euo pipefail
secs="${1:-30}"
src="$(cd "$(dirname "$0")/../.." && pwd)"
out="${2:-$src/build-fuzz}"
mkdir -p "$out"
flags=(-std=c++17 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
       -I"$src/include" -isystem /usr/include/eigen3)
for t in csv ini; do
  clang++ "${flags[@]}" "$src/tests/fuzz/fuzz_$t.cpp" "$src/src/io/csv.cpp" "$src/src/io/ini.cpp" \
    -o "$out/fuzz_$t"
  rm -rf "$out/corpus-$t"; cp -r "$src/tests/fuzz/corpus/$t" "$out/corpus-$t"
  echo "fuzz_$t: ${secs}s"
  "$out/fuzz_$t" -max_total_time="$secs" -max_len=4096 -timeout=5 "$out/corpus-$t" 2> "$out/fuzz_$t.log" \
    || { tail -40 "$out/fuzz_$t.log"; exit 1; }
  grep -E "^#[0-9]+.*DONE|Done [0-9]+ runs" "$out/fuzz_$t.log" | tail -1
done
echo "fuzzers: ok"
