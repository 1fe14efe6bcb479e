#!/usr/bin/env bash
# The layer checker must fail on an upward include, an internal header in a
# public one, a header outside the layer folders, and a cycle.
set -euo pipefail
checker="$1"; work="$2"
rm -rf "$work"; mkdir -p "$work"/{src/core,src/solvers,include/gssm/core,include/gssm/estimator}
printf '#include "gssm/estimator/estimator.h"\n' > "$work/src/core/bad.cpp"              # upward
printf '#include "solvers/a.h"\n' > "$work/include/gssm/core/leak.h"                    # internal in public
printf '#include "solvers/b.h"\n' > "$work/src/solvers/a.h"                              # a -> b -> a
printf '#include "solvers/a.h"\n' > "$work/src/solvers/b.h"
printf '\n' > "$work/include/gssm/estimator/estimator.h"
printf '\n' > "$work/include/gssm/flat.h"                                                # no layer
if out=$("$checker" "$work"); then echo "checker passed a broken tree:"; echo "$out"; exit 1; fi
for want in "an upward include" "public header includes internal" "outside the layer folders" "circular include"; do
  grep -q "$want" <<<"$out" || { echo "missing: $want"; echo "$out"; exit 1; }
done
echo "check_layers self-test: all four problems reported"
