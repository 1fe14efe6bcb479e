#!/usr/bin/env bash
# find_package(gssm) works after cmake --install.
set -euo pipefail
build="$1"; src="$2"; work="$3"
rm -rf "$work"
cmake --install "$build" --prefix "$work/prefix" > /dev/null
cmake -S "$src/tests/install_consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/prefix" > /dev/null
cmake --build "$work/consumer" > /dev/null
"$work/consumer/consumer"
