#!/usr/bin/env bash
# The bundled datasets regenerate bit for bit with the command in their README.
set -euo pipefail
bin="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
for s in paper consistent; do
  cmd=$(grep -o "gssm-simulate --scenario $s [^\`]*" "$src/datasets/radar-$s/README.md" | head -1)
  [ -n "$cmd" ] || { echo "no regenerate command in datasets/radar-$s/README.md"; exit 1; }
  args=$(echo "$cmd" | sed -e 's/^gssm-simulate //' -e "s|--out [^ ]*|--out $work/$s|")
  "$bin/gssm-simulate" $args > /dev/null
  for f in measurements.csv truth.csv scenario.ini; do
    cmp "$work/$s/$f" "$src/datasets/radar-$s/$f"
  done
done
echo "datasets regenerate bit for bit: ok"
