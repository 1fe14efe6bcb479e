#!/usr/bin/python3
"""gssm-process on the real UWB planar-pose log (datasets/uwb-fast): the
batch smoother's body-origin and yaw RMSE against the issue's targets, its 24
learnt link biases against the source repository's calibration runs
(bias + slope x the link's mean true distance, computed here from the truth),
and the estimates' columns; the noise σs learnt by likelihood and the links'
spread by EM before the run (learn.json, the learnt scenario.ini); with that
learnt file, the fixed lag's and the incremental smoother's online estimates
(each when its epoch arrives) against the online target; the EKF runs over
the whole log.

    process_uwb.py BIN_DIR SOURCE_DIR WORK_DIR
"""
import csv
import json
import math
import os
import subprocess

from app_checks import check, setup

bin_dir, src, work = setup()
data = os.path.join(src, "datasets", "uwb-fast")


def quat_rotate(q, v):
    w, x, y, z = q
    return (v[0] * (1 - 2 * (y * y + z * z)) + v[1] * 2 * (x * y - w * z) + v[2] * 2 * (x * z + w * y),
            v[0] * 2 * (x * y + w * z) + v[1] * (1 - 2 * (x * x + z * z)) + v[2] * 2 * (y * z - w * x),
            v[0] * 2 * (x * z - w * y) + v[1] * 2 * (y * z + w * x) + v[2] * (1 - 2 * (x * x + y * y)))


def reference_biases():
    """bias + slope x mean true distance of each link (the repository's
    calibration, judged as a bias-only constant), and each link's mean true
    distance."""
    rd = lambda name: list(csv.DictReader(open(os.path.join(data, name))))
    anchors = {int(r["anchor"]): [float(r[k]) for k in "xyz"] for r in rd("anchors.csv")}
    tags = {int(r["tag"]): [float(r[k]) for k in "xyz"] for r in rd("tags.csv")}
    truth = rd("truth.csv")[::10]
    total = {(t, a): 0.0 for t in tags for a in anchors}
    for row in truth:
        p = [float(row[k]) for k in "xyz"]
        q = [float(row[k]) for k in ("qw", "qx", "qy", "qz")]
        for t, lever in tags.items():
            r = quat_rotate(q, lever)
            tag = [p[i] + r[i] for i in range(3)]
            for a, pos in anchors.items():
                total[(t, a)] += math.dist(tag, pos)
    mean = {k: v / len(truth) for k, v in total.items()}
    return {(int(r["tag"]), int(r["anchor"])): float(r["bias"]) + float(r["slope"]) * mean[(int(r["tag"]), int(r["anchor"]))]
            for r in rd("calibration_reference.csv")}, mean


out = os.path.join(work, "uwb")
r = subprocess.run([os.path.join(bin_dir, "gssm-process"), "--data", data, "--method", "batch", "--out", out],
                   capture_output=True, text=True)
check(r.returncode == 0, "gssm-process --method batch runs on uwb-fast: " + r.stderr.strip()[-300:])
m = json.load(open(os.path.join(out, "metrics.json")))["methods"]["batch"]
check(m["rows"] == 13481, "one estimate row per epoch (%d)" % m["rows"])
origin, yaw = m["position_error_m"]["rmse"], math.degrees(m["rmse"]["yaw"])
check(origin <= 0.030, "batch body-origin RMSE %.2f cm <= 3.0 cm" % (100 * origin))
check(yaw <= 4.7, "batch yaw RMSE %.2f deg <= 4.7 deg" % yaw)
ref, distance = reference_biases()
# With a common range scale s the model's bias is the offset at distance 0:
# each link's range error at its mean true distance is b + (s - 1) d.
scale = m["constants"].get("range_scale", 1.0)
diff = [m["constants"]["bias_%d_%d" % k] + (scale - 1) * distance[k] - v for k, v in ref.items()]
rms = math.sqrt(sum(d * d for d in diff) / len(diff))
check(len(diff) == 24 and rms <= 0.020,
      "24 learnt link biases (range scale %.4f) %.2f cm RMS from the calibration runs (<= 2.0 cm)" % (scale, 100 * rms))
check(abs(rms - m["constants_reference_rms"]) < 0.001,
      "metrics.json's constants_reference_rms %.2f cm agrees" % (100 * m["constants_reference_rms"]))
header = open(os.path.join(out, "estimates-batch.csv")).readline().strip().split(",")
check(header[:4] == ["t", "px", "py", "yaw"] and "bias_2_7" in header and "sd_bias_2_7" in header,
      "estimates columns t, px, py, yaw, bias_<tag>_<anchor> and their sd_")
learnt = json.load(open(os.path.join(out, "learn.json")))
by_key = {p["key"]: p for p in learnt["parameters"]}
spread = by_key.get("bias_sd", {})
check(spread.get("method") == "em" and learnt["constants_prior"]["converged"]
      and 0 < spread["learnt"] < spread["start"],
      "the links' spread learnt by EM after the noise: bias_sd %.4f m" % spread.get("learnt", float("nan")))
noise = [by_key.get(k, {}) for k in ("accel_sd", "yaw_accel_sd", "range_sd")]
check(learnt["converged"] and all(p.get("method") == "likelihood" and 0 < p["learnt"] != p["start"] for p in noise),
      "the noise learnt by likelihood: accel_sd %.3f, yaw_accel_sd %.3f, range_sd %.4f"
      % tuple(p.get("learnt", float("nan")) for p in noise))
learnt_ini = open(os.path.join(out, "scenario.ini")).read()
check("bias_sd = " in learnt_ini, "the learnt scenario.ini written beside the estimates")
# The other methods on the learnt file, which turns learning off (learning
# once, not per method); copied, as their runs write into the same folder.
config = os.path.join(work, "uwb-learnt.ini")
open(config, "w").write(learnt_ini)
for method in ("fixed-lag", "incremental"):
    r = subprocess.run([os.path.join(bin_dir, "gssm-process"), "--data", data, "--config", config, "--method", method,
                        "--out", out], capture_output=True, text=True)
    f = json.load(open(os.path.join(out, "metrics.json")))["methods"][method]
    check(r.returncode == 0 and f["position_error_m"]["rmse"] <= 0.044,
          "%s online (each estimate when its epoch arrives): origin RMSE %.2f cm <= 4.4 cm"
          % (method, 100 * f["position_error_m"]["rmse"]))
r = subprocess.run([os.path.join(bin_dir, "gssm-process"), "--data", data, "--config", config, "--method", "ekf",
                    "--out", out], capture_output=True, text=True)
e = json.load(open(os.path.join(out, "metrics.json")))["methods"]["ekf"]
check(r.returncode == 0 and e["position_error_m"]["rmse"] < 0.1,
      "the EKF (30 states) over the whole log: origin RMSE %.2f cm" % (100 * e["position_error_m"]["rmse"]))
