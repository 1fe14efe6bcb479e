#!/usr/bin/env bash
# Whole-process wall time of gssm-process against the estimator's own total
# (metrics.json total_s) on 200,000 radar steps with the EKF: what text I/O,
# metrics and figures add. Three runs each; optionally a second (baseline)
# gssm-process binary, run in turn with the first.
#   bench/process_io.sh build/apps/gssm-process [baseline/gssm-process]
set -euo pipefail
new="$1"; base="${2:-}"
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$(dirname "$new")/gssm-simulate" --scenario paper --seed 1 --steps 200000 --out "$dir/data" > /dev/null
echo "machine: $("$(dirname "$0")/../scripts/machine")"
echo
echo "| binary | run | whole process (s) | estimator total_s (s) | ratio | peak RSS (MB) |"
echo "| --- | --- | --- | --- | --- | --- |"
for run in 1 2 3; do
  for label in new base; do
    bin="$new"; [ "$label" = base ] && bin="$base"
    [ -n "$bin" ] || continue
    /usr/bin/time -f "%e %M" -o "$dir/time" "$bin" --data "$dir/data" --method ekf --out "$dir/out-$label" > /dev/null
    read -r wall rss < "$dir/time"
    est=$(grep -o '"total_s": [0-9.e-]*' "$dir/out-$label/metrics.json" | head -1 | awk '{print $2}')
    awk -v l="$label" -v r="$run" -v w="$wall" -v e="$est" -v m="$rss" \
      'BEGIN { printf "| %s | %d | %.2f | %.3f | %.1f× | %.0f |\n", l, r, w, e, w / e, m / 1024 }'
  done
done
