#!/usr/bin/env bash
# gssm-simulate is deterministic: the same seed gives byte-identical files,
# and a different seed gives different measurements.
set -euo pipefail
bin="$1"; work="$2"
rm -rf "$work"; mkdir -p "$work"
for s in consistent paper; do
  "$bin/gssm-simulate" --scenario $s --seed 7 --steps 50 --out "$work/a-$s" > /dev/null
  "$bin/gssm-simulate" --scenario $s --seed 7 --steps 50 --out "$work/b-$s" > /dev/null
  "$bin/gssm-simulate" --scenario $s --seed 8 --steps 50 --out "$work/c-$s" > /dev/null
  for f in measurements.csv truth.csv scenario.ini; do
    cmp "$work/a-$s/$f" "$work/b-$s/$f"
  done
  if cmp -s "$work/a-$s/measurements.csv" "$work/c-$s/measurements.csv"; then
    echo "seeds 7 and 8 gave the same measurements"; exit 1
  fi
  [ "$(wc -l < "$work/a-$s/measurements.csv")" -eq 51 ]
  [ "$(wc -l < "$work/a-$s/truth.csv")" -eq 52 ]
done
for s in nav-paper-like nav-consistent; do
  "$bin/gssm-simulate" --scenario $s --seed 7 --steps 50 --out "$work/a-$s" > /dev/null
  "$bin/gssm-simulate" --scenario $s --seed 7 --steps 50 --out "$work/b-$s" > /dev/null
  for f in measurements.csv truth.csv inputs.csv scenario.ini; do
    cmp "$work/a-$s/$f" "$work/b-$s/$f"
  done
  [ "$(wc -l < "$work/a-$s/measurements.csv")" -eq 11 ]  # ranges every 5th step
  [ "$(wc -l < "$work/a-$s/inputs.csv")" -eq 51 ]
done
echo "simulate deterministic: ok"
