#!/usr/bin/python3
"""gssm-process on the real GNSS/INS car drive (datasets/gnss-ins-drive, issue
#37) with its own scenario.ini, noise learnt from the log first: the antenna's
horizontal error at the RTK-fixed fixes withheld inside the five outages and
at the fixes used outside them, per method, against the issue's targets where
they are met and against today's level where they are not (said below); the
lever arm against the hand-measured one; the columns of estimates-<method>.csv.

    process_gnss_ins.py BIN_DIR SOURCE_DIR WORK_DIR
"""
import csv
import json
import math
import os
import subprocess

from app_checks import check, setup

bin_dir, src, work = setup()
data = os.path.join(src, "datasets", "gnss-ins-drive")


out = os.path.join(work, "drive")
r = subprocess.run([os.path.join(bin_dir, "gssm-process"), "--data", data, "--out", out],
                   capture_output=True, text=True)
check(r.returncode == 0, "gssm-process runs on the drive" + ("" if r.returncode == 0 else ": " + r.stderr.strip()[-400:]))
check(os.path.exists(os.path.join(out, "scenario.ini")) and os.path.exists(os.path.join(out, "learn.json")),
      "the noise learnt from the log first (scenario.ini, learn.json)")
# The batch's own noise, learnt from every fix ([learn] batch_likelihood_spacing = 0)
learnt_ini = open(os.path.join(out, "scenario.ini")).read()
check(os.path.exists(os.path.join(out, "learn-batch.json")) and "\n[batch.model]\n" in learnt_ini,
      "the batch's own noise learnt too (learn-batch.json, [batch.model])")
doc = json.load(open(os.path.join(out, "metrics.json")))
methods = doc["methods"]
check(sorted(methods) == ["batch", "ekf", "fixed-lag", "incremental"], "the scenario's four methods ran")
check(sum("is not after the start" in s for s in doc["skipped"]) == 14,
      "the 14 fixes before the first IMU row dropped, each named")
for name, m in methods.items():
    check(m["withheld"]["count"] == 292, "%s scored at the 292 withheld RTK-fixed fixes" % name)
    outside = m["used"]["horizontal_rms_m"]
    check(outside <= 0.02, "%s outside the outages %.4f m RMS <= 0.02 m (target)" % (name, outside))
    # each withheld fix's error, what metrics.json summarizes
    with open(os.path.join(out, "withheld-%s.csv" % name), newline="") as f:
        errors = [float(r["horizontal_error"]) for r in csv.DictReader(f)]
    rms = math.sqrt(sum(e * e for e in errors) / max(len(errors), 1))
    check(len(errors) == 292 and abs(rms - m["withheld"]["horizontal_rms_m"]) <= 1e-9 * rms,
          "withheld-%s.csv: the 292 fixes' errors, RMS %.4f m as metrics.json says" % (name, rms))
batch = methods["batch"]["withheld"]["horizontal_rms_m"]
# The smoothed target (issue #37: 0.13 m): 0.1038 m with the gyro's noise
# per IMU axis (0.1351 m with one sigma for all three; docs/datasets/
# gnss-ins-drive.md).
check(batch <= 0.13, "batch inside the outages %.4f m RMS <= 0.13 m (target)" % batch)
# The online target (issue #37: 1.3 m; the EKF held to it too), and today's
# level (0.79-0.80 m).
for name in ("incremental", "fixed-lag", "ekf"):
    e = methods[name]["withheld"]["horizontal_rms_m"]
    check(e <= 0.85, "%s inside the outages %.3f m RMS <= 1.3 m (target; today's level <= 0.85 m)" % (name, e))

with open(os.path.join(out, "estimates-batch.csv"), newline="") as f:
    rows = list(csv.DictReader(f))
want = ["t", "lat", "lon", "height", "vn", "ve", "vd", "roll", "pitch", "yaw", "bg_x", "bg_y", "bg_z", "ba_x", "ba_y",
        "ba_z", "lever_f", "lever_r", "lever_d", "imu_delay", "mount_roll", "mount_pitch", "mount_yaw"]
check(list(rows[0].keys())[:len(want)] == want and "sd_lat" in rows[0] and "sd_mount_yaw" in rows[0],
      "estimates columns: t, antenna lat/lon/height, velocity, vehicle roll/pitch/yaw, constants, sd_ columns")
# A row at every state: every 10 IMU readings and every measurement (the
# constraints' 10 Hz), so at least every 0.1 s (and the 0.14 ms by which an
# event joins a step at nearly its time in GPS seconds: core/time.h).
times = [float(r["t"]) for r in rows]
gap = max(b - a for a, b in zip(times, times[1:]))
check(len(rows) >= 2710 and gap <= 0.1 + 2e-4, "a row at least every 0.1 s (%d rows, largest gap %.4f s)" % (len(rows), gap))
last = rows[-1]
lever = [float(last[k]) for k in ("lever_f", "lever_r", "lever_d")]
hand = [0.0, -0.05, 0.0]
off = [abs(a - b) for a, b in zip(lever, hand)]
check(max(off) <= 0.10, "lever arm (%.3f, %.3f, %.3f) m within 0.10 m of the hand-measured (0, -0.05, 0) per axis "
      "(%.3f m apart)" % (lever[0], lever[1], lever[2], math.sqrt(sum(d * d for d in off))))
pitch, yaw = float(last["mount_pitch"]), float(last["mount_yaw"]) % 360
check(abs(abs(pitch) - 6.79) < 1.5 and abs(yaw - 185.35) < 1.5,
      "mounting pitch %.2f deg, yaw %.2f deg beside the source's hand values 6.79 and 185.35" % (pitch, yaw))
pos = os.path.join(out, "track-batch.pos")
check(os.path.exists(pos) and sum(1 for line in open(pos) if not line.startswith("%")) == len(rows),
      "the smoothed track as an RTKLIB .pos, an epoch per row")

# A method's own values ([batch.model]) may change numbers, not the model's
# structure, and a misspelt section is refused by its line; either before
# anything is learnt or run.
scenario = open(os.path.join(data, "scenario.ini"), encoding="utf-8-sig").read()
for name, extra, want in (("structure", "\n[batch.prior]\nnhc_point_sd = 0 1 0 0\n",
                           "[batch.*]: a method's own values may change the model's numbers, not its states"),
                          ("misspelt", "\n[batch.modle]\ngyro_sd = 0.002\n", "[batch.modle] overrides the keys of [modle]")):
    bad = os.path.join(work, "own-%s.ini" % name)
    with open(bad, "w") as f:
        f.write(scenario + extra)
    r = subprocess.run([os.path.join(bin_dir, "gssm-process"), "--data", data, "--config", bad, "--out",
                        os.path.join(work, "own-" + name)], capture_output=True, text=True)
    check(r.returncode != 0 and want in r.stderr and "noise learnt" not in r.stdout,
          "a batch's own %s refused before learning: %s" % (name, r.stderr.strip()[-200:]))

# OUT/scenario.ini reproduces the run: both learnt noise sets, to the bit
# (a model built from a σ the file does not hold would not be the one the
# file rebuilds).
again = os.path.join(work, "again")
r = subprocess.run([os.path.join(bin_dir, "gssm-process"), "--data", data, "--config", os.path.join(out, "scenario.ini"),
                    "--out", again], capture_output=True, text=True)
same = [m for m in sorted(methods)
        if r.returncode == 0 and open(os.path.join(out, "estimates-%s.csv" % m)).read() ==
        open(os.path.join(again, "estimates-%s.csv" % m)).read()]
check(same == sorted(methods), "OUT/scenario.ini run again gives every method's estimates to the bit (%s)" % ", ".join(same))
