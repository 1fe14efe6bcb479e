#!/usr/bin/env bash
# The whole `gssm-process --method all` on the UWB log (datasets/uwb-fast:
# 323,514 ranges, the shipped scenario.ini with its EM learning): wall time,
# the learning's and each method's own seconds (learn.json, metrics.json
# total_s) and peak RSS; with a second (baseline) gssm-process binary, the
# two run in turn, three times each, so their ratio shares the machine's
# state. THREADS (default: one per core) is passed as --threads.
#   bench/uwb_all.sh build/apps/gssm-process [baseline/gssm-process]
set -euo pipefail
new="$1"; base="${2:-}"
threads="${THREADS:-$(nproc)}"
src="$(cd "$(dirname "$0")/.." && pwd)/datasets/uwb-fast"
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
seconds() { grep -o "\"$2\": [0-9.e-]*" "$1" | head -1 | awk '{print $2}'; }
echo "machine: $("$(dirname "$0")/../scripts/machine")"
echo
echo "| binary | run | wall (s) | learning (s) | ekf | batch | incremental | fixed-lag | paper-window | peak RSS (MB) |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
for run in 1 2 3; do
  for label in new base; do
    bin="$new"; [ "$label" = base ] && bin="$base"
    [ -n "$bin" ] || continue
    out="$dir/out-$label"
    /usr/bin/time -f "%e %M" -o "$dir/time" "$bin" --data "$src" --method all --threads "$threads" --out "$out" > /dev/null
    read -r wall rss < "$dir/time"
    learn=$(printf "%.2f" "$(seconds "$out/learn.json" seconds)")
    row="| $label | $run | $wall | $learn"
    for m in ekf batch incremental fixed-lag paper-window; do
      t=$(/usr/bin/python3 -c "import json,sys; print('%.2f' % json.load(open(sys.argv[1]))['methods'][sys.argv[2]]['total_s'])" "$out/metrics.json" "$m")
      row="$row | $t"
    done
    echo "$row | $((rss / 1024)) |"
  done
done
