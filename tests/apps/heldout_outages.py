#!/usr/bin/python3
"""scripts/heldout_outages on the GNSS/INS drive: a window as long as each
withheld outage, 7.5 s after it ends, withheld beside them (and a second
set 11 s after, pooled with the first in the summary); its fixes
counted from the .pos itself (RTK-fixed ones inside the windows) and found
again in each method's withheld CSV and in metrics.json's withheld count;
every method there guarded at today's level (docs/datasets/
gnss-ins-drive.md: 1.66 / 1.54 / 1.36 m, EKF / incremental / fixed lag;
the batch, with its own noise, 0.075 m). The EKF's guard rose from 1.55 m
with the gyro's noise per axis: these windows lose (1.45 -> 1.66 m) where
the withheld outages and the windows 3 and 11 s after them gain (pooled
over all three offsets on the log and on it cut at 53 s, every method
gains).

    heldout_outages.py BIN_DIR SOURCE_DIR WORK_DIR
"""
import datetime
import json
import math
import os
import subprocess

from app_checks import check, setup

bin_dir, src, work = setup()
data = os.path.join(src, "datasets", "gnss-ins-drive")
r = subprocess.run(["/usr/bin/python3", os.path.join(src, "scripts", "heldout_outages"), "--data", data,
                    "--out", work, "--offset", "7.5", "11", "--bin", bin_dir], capture_output=True, text=True)
check(r.returncode == 0, "scripts/heldout_outages runs on the drive" + ("" if r.returncode == 0 else ": " + r.stderr[-400:]))
pooled = json.load(open(os.path.join(work, "heldout.json")))
check([o["offset_s"] for o in pooled["offsets"]] == [7.5, 11], "one set of windows per offset")
result = pooled["offsets"][0]
outages = [tuple(map(float, l.split(","))) for l in open(os.path.join(data, "outages.csv")).read().split()[1:]]
want = [(b + 7.5, b + 7.5 + (b - a)) for a, b in outages]
check(len(result["windows"]) == 5 and all(abs(w[0] - v[0]) < 1e-9 and abs(w[1] - v[1]) < 1e-9
                                           for w, v in zip(result["windows"], want)),
      "five windows, each as long as a withheld outage and 7.5 s after it")
gps0 = datetime.datetime(1980, 1, 6)
fixed = 0
for line in open(os.path.join(data, "gnss.pos")):
    if line.startswith("%") or not line.strip():
        continue
    f = line.split()
    t = (datetime.datetime.strptime(f[0] + " " + f[1], "%Y/%m/%d %H:%M:%S.%f") - gps0).total_seconds()
    fixed += float(f[5]) == 1 and any(a <= t < b for a, b in want)
metrics = json.load(open(os.path.join(work, "offset-7.5", "run", "metrics.json")))["methods"]
for name, m in result["methods"].items():
    check(m["count"] == fixed and metrics[name]["withheld"]["count"] == 292 + fixed,
          "%s scored at the windows' %d RTK-fixed fixes (of %d withheld)" % (name, fixed, 292 + fixed))
for name, m in pooled["methods"].items():
    sets = [o["methods"][name] for o in pooled["offsets"]]
    n = sum(x["count"] for x in sets)
    rms = math.sqrt(sum(x["count"] * x["horizontal_rms_m"] ** 2 for x in sets) / n)
    check(m["count"] == n and abs(m["horizontal_rms_m"] - rms) < 1e-12,
          "%s pooled over both sets: %.3f m RMS at %d fixes" % (name, m["horizontal_rms_m"], n))
for name, level in (("ekf", 1.75), ("incremental", 1.6), ("fixed-lag", 1.4), ("batch", 0.08)):
    e = result["methods"][name]["horizontal_rms_m"]
    check(e <= level, "%s in the held-out windows %.3f m RMS (today's level <= %.2f m)" % (name, e, level))
