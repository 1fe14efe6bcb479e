#!/usr/bin/python3
"""Fixed outputs: every method's estimates on every bundled real or paper
dataset (radar-paper, Plaza 2, uwb-fast, the GNSS/INS drive) against the committed reference outputs (tests/fixed_outputs/), so
that no speed-up changes what a method computes unnoticed.

    fixed_outputs.py BIN_DIR SOURCE_DIR WORK_DIR            compare
    fixed_outputs.py BIN_DIR SOURCE_DIR WORK_DIR --update   rewrite the references

Each dataset runs as `gssm-process --data datasets/NAME --method all` (its
scenario.ini, learning included where it says so). Every column of every
estimates-<method>.csv is compared at the reference's rows: all rows of the
small logs, every STRIDE-th row (and the last) of a long one — an online
method's row depends on every row before it, and the batch's rows share its
constants. Tolerance: |a − b| ≤ 1e-9·(|b| + 1e-3). Not bit for bit, because a
change of summation order (a vectorized loop, a reordered dot) is rounding,
not a change of method: those move an estimate by ~1e-12 relative. A change
of what a method computes moves it by ~1e-3 of its sd or more. Values are
stored with 17 significant digits.

A change meant to change results re-runs this with --update and says in its
commit which estimates moved, by how much and why.
"""
import csv
import gzip
import io
import json
import math
import os
import shutil
import subprocess
import sys

# name: stride (the drive: ~5,600 rows a method, every 20th; its noise
# learnt by scoring first, on every core: the same bits on one thread)
DATASETS = {"radar-paper": 1, "plaza2": 1, "uwb-fast": 20, "gnss-ins-drive": 20}
RTOL, ATOL_SCALE = 1e-9, 1e-3

bin_dir, src, work = sys.argv[1:4]
update = "--update" in sys.argv[4:]
ref_root = os.path.join(src, "tests", "fixed_outputs")


def run(name):
    out = os.path.join(work, name)
    shutil.rmtree(out, ignore_errors=True)
    subprocess.run([os.path.join(bin_dir, "gssm-process"), "--data", os.path.join(src, "datasets", name),
                    "--out", out, "--method", "all"], check=True, stdout=subprocess.DEVNULL)
    return out


def rows_of(path):
    with open(path, newline="") as f:
        r = csv.reader(f)
        header = next(r)
        return header, [row for row in r]


def sampled(rows, stride):
    keep = list(range(0, len(rows), stride))
    if keep and keep[-1] != len(rows) - 1:
        keep.append(len(rows) - 1)
    return keep


def write_reference(name, out, stride):
    dest = os.path.join(ref_root, name)
    shutil.rmtree(dest, ignore_errors=True)
    os.makedirs(dest)
    manifest = {"stride": stride, "files": {}}
    for f in sorted(os.listdir(out)):
        if not (f.startswith("estimates-") and f.endswith(".csv")):
            continue
        header, rows = rows_of(os.path.join(out, f))
        keep = sampled(rows, stride)
        manifest["files"][f] = len(rows)
        # no time stamp in the gzip header: an unchanged reference re-written is the same file
        with io.TextIOWrapper(gzip.GzipFile(os.path.join(dest, f + ".gz"), "wb", mtime=0), newline="") as g:
            w = csv.writer(g, lineterminator="\n")
            w.writerow(["row"] + header)
            for i in keep:
                w.writerow([i] + ["%.17g" % float(v) for v in rows[i]])
    with open(os.path.join(dest, "manifest.json"), "w") as m:
        json.dump(manifest, m, indent=1, sort_keys=True)
        m.write("\n")
    print("wrote", dest, "(%d files)" % len(manifest["files"]))


def compare(name, out):
    dest = os.path.join(ref_root, name)
    manifest = json.load(open(os.path.join(dest, "manifest.json")))
    problems = []
    produced = sorted(f for f in os.listdir(out) if f.startswith("estimates-") and f.endswith(".csv"))
    if produced != sorted(manifest["files"]):
        problems.append("files %s, the reference has %s" % (produced, sorted(manifest["files"])))
    for f, count in sorted(manifest["files"].items()):
        if f not in produced:
            continue
        header, rows = rows_of(os.path.join(out, f))
        if len(rows) != count:
            problems.append("%s: %d rows, the reference has %d" % (f, len(rows), count))
            continue
        with gzip.open(os.path.join(dest, f + ".gz"), "rt", newline="") as g:
            r = csv.reader(g)
            ref_header = next(r)[1:]
            if header != ref_header:
                problems.append("%s: columns %s, the reference has %s" % (f, header, ref_header))
                continue
            worst = (0.0, None)
            for ref in r:
                i = int(ref[0])
                for c, (a, b) in enumerate(zip(rows[i], ref[1:])):
                    a, b = float(a), float(b)
                    excess = abs(a - b) / (RTOL * (abs(b) + ATOL_SCALE)) if not (math.isnan(a) and math.isnan(b)) else 0
                    if excess > worst[0]:
                        worst = (excess, "row %d column %s: %.17g, reference %.17g" % (i, header[c], a, b))
            status = "FAIL" if worst[0] > 1 else "ok"
            print("%s: %s/%s: worst %.3g of the tolerance%s" %
                  (status, name, f, worst[0], (" (" + worst[1] + ")") if worst[1] else ""))
            if worst[0] > 1:
                problems.append("%s: %s" % (f, worst[1]))
    return problems


shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
failed = []
for name, stride in DATASETS.items():
    out = run(name)
    if update:
        write_reference(name, out, stride)
    else:
        failed += ["%s/%s" % (name, p) for p in compare(name, out)]
if failed:
    sys.exit("FAIL: estimates moved from tests/fixed_outputs (re-run with --update only if the change is meant "
             "to change them, and say why in the commit):\n  " + "\n  ".join(failed))
print("ok: every method's estimates on %s equal the fixed outputs" % ", ".join(DATASETS))
