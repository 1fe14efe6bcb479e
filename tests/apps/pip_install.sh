#!/usr/bin/env bash
# `pip install .` as a user runs it, offline, into a fresh virtual
# environment (NumPy from Debian through --system-site-packages), reusing
# this build's CMake tree; then the package works from the venv alone.
set -euo pipefail
build="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
/usr/bin/python3 -m venv --system-site-packages "$work/venv"
GSSM_CMAKE_BUILD_DIR="$build" "$work/venv/bin/pip" install --no-build-isolation --no-index --no-deps "$src" \
  > "$work/pip.log" 2>&1 || { cat "$work/pip.log"; exit 1; }
cd "$work"
"$work/venv/bin/python" - "$src" "$work" <<'PY'
import os, sys
import gssm
src, work = sys.argv[1], sys.argv[2]
assert gssm.__file__.startswith(os.path.join(work, "venv")), gssm.__file__
data = gssm.io.read_dataset(os.path.join(src, "datasets", "radar-paper"))
run = gssm.run(gssm.models.Radar2D(), data, method="fixed-lag")
assert run.mean.shape == (400, 3) and abs(run.mean[-1, 1] - 100) < 5, run.mean[-1]
r = gssm.process(os.path.join(src, "datasets", "radar-paper"), os.path.join(work, "out"), method="ekf")
assert os.path.exists(os.path.join(work, "out", "fig-xdot.png")) and not r.partial
print("pip install: gssm", gssm.__file__, "runs; xdot =", run.mean[-1, 1])
PY
