#!/usr/bin/env bash
# find_package(gssm) works after cmake --install: a program on gssm::io (and
# gssm::plot when the apps are built) builds and runs against the installed
# libraries, each with its SOVERSION.
set -euo pipefail
build="$1"; src="$2"; work="$3"
rm -rf "$work"
cmake --install "$build" --prefix "$work/prefix" > /dev/null
for lib in gssm gssm_analysis gssm_io; do
  [ -n "$(find "$work/prefix" -name "lib$lib.so.0.1")" ] || { echo "lib$lib.so.0.1 (SOVERSION) not installed"; exit 1; }
done
cmake -S "$src/tests/install_consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/prefix" > /dev/null
cmake --build "$work/consumer" > /dev/null
"$work/consumer/consumer"
if [ -d "$build/gui-offscreen" ]; then
  [ -x "$work/consumer/plot_consumer" ] || { echo "gssm::plot was not exported"; exit 1; }
  "$work/consumer/plot_consumer" "$work/consumer.png"
fi
