#!/usr/bin/python3
"""gssm-process on the real CMU Plaza 2 log (datasets/plaza2): the noise
learnt from the log (from 1.0 each), the numbers of the run against the
targets, the range scale against an offline fit to the truth computed here,
the learnt scenario.ini reproducing the run, the estimates lined up with the
truth, the run with the range scale switched off, and bad input named by
file, line and column.

    process_plaza.py BIN_DIR SOURCE_DIR WORK_DIR
"""
import csv
import json
import math
import os
import shutil
import subprocess
import sys

bin_dir, src, work = sys.argv[1:4]
data = os.path.join(src, "datasets", "plaza2")
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)


def process(*args):
    return subprocess.run([os.path.join(bin_dir, "gssm-process"), *args], capture_output=True, text=True)


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def check(cond, what):
    if not cond:
        sys.exit("FAIL: " + what)
    print("ok:", what)


out = os.path.join(work, "plaza2")
r = process("--data", data, "--method", "all", "--out", out)
check(r.returncode == 0, "gssm-process runs on plaza2: " + r.stderr.strip()[-300:])
metrics = json.load(open(os.path.join(out, "metrics.json")))["methods"]
pos = {m: v["position_error_m"]["rmse"] for m, v in metrics.items()}
print("position RMSE (m):", {m: round(v, 3) for m, v in pos.items()})

# The offline fit the issue describes: range = a * true distance + b, every
# beacon together, the true position interpolated to each range's time.
truth = rows(os.path.join(data, "truth.csv"))
tt = [float(t["t"]) for t in truth]
beacons = {int(float(b["beacon"])): (float(b["x"]), float(b["y"])) for b in rows(os.path.join(data, "beacons.csv"))}
xs, ys = [], []
j = 0
for rg in rows(os.path.join(data, "ranges.csv")):
    t = float(rg["t"])
    while j + 1 < len(tt) and tt[j + 1] < t:
        j += 1
    if t < tt[0] or j + 1 >= len(tt):
        continue
    w = (t - tt[j]) / (tt[j + 1] - tt[j])
    px = (1 - w) * float(truth[j]["px"]) + w * float(truth[j + 1]["px"])
    py = (1 - w) * float(truth[j]["py"]) + w * float(truth[j + 1]["py"])
    bx, by = beacons[int(float(rg["beacon"]))]
    xs.append(math.hypot(px - bx, py - by))
    ys.append(float(rg["range"]))
n = len(xs)
mx, my = sum(xs) / n, sum(ys) / n
a = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
print("offline fit against the truth: range = %.4f * distance + %.3f over %d ranges" % (a, my - a * mx, n))
scale = metrics["batch"]["constants"]["range_scale"]
check(abs(scale - a) <= 0.002, "batch range scale %.4f within 0.002 of the offline fit %.4f" % (scale, a))

check(pos["batch"] <= 0.27, "batch (smoothed) position RMSE %.3f m <= 0.27" % pos["batch"])
for m in ("incremental", "fixed-lag"):
    check(pos[m] <= 0.39, "%s position RMSE %.3f m <= 0.39" % (m, pos[m]))
    check(pos[m] <= pos["ekf"], "%s (%.3f m) no worse than the EKF of the same model (%.3f m)" % (m, pos[m], pos["ekf"]))

# The noise was learnt from the log: learn.json and the learnt scenario.ini.
learn = json.load(open(os.path.join(out, "learn.json")))
trace = learn["log_likelihood_trace"]
check(learn["converged"] and all(b >= a for a, b in zip(trace, trace[1:])),
      "learning converged; its log-likelihood never decreased (%d iterations, %.1f -> %.1f)"
      % (len(trace), trace[0], trace[-1]))
learnt = {p["name"]: p for p in learn["parameters"]}
check(sorted(learnt) == sorted(["range_sd", "distance_sd", "turn_sd", "heading_drift_sd", "position_sd_per_s",
                                "heading_sd_per_s"]) and all(p["start"] == 1.0 for p in learnt.values()),
      "the six noise σs learnt, each from 1.0")
rs = learnt["range_sd"]
check(rs["identifiable"] and 0.4 < rs["learnt"] < 0.7 and 0 < rs["standard_error"] < 0.05,
      "range_sd learnt %.3f ± %.3f m" % (rs["learnt"], rs["standard_error"]))
check(learn["log_likelihood"]["final"] > learn["log_likelihood"]["given"],
      "the learnt noise explains the log better than the hand-tuned values (%.1f vs %.1f)"
      % (learn["log_likelihood"]["final"], learn["log_likelihood"]["given"]))
again = os.path.join(work, "plaza2-learnt")
r = process("--data", data, "--config", os.path.join(out, "scenario.ini"), "--method", "batch", "--out", again)
check(r.returncode == 0 and not os.path.exists(os.path.join(again, "learn.json")) and
      open(os.path.join(again, "estimates-batch.csv")).read() == open(os.path.join(out, "estimates-batch.csv")).read(),
      "the learnt scenario.ini reproduces the batch estimates without learning again")
r = process("--data", data, "--method", "batch", "--out", data)
check(r.returncode != 0 and "would replace its own" in r.stderr, "refuses to write the learnt INI over the dataset's")

# One row per odometry step, at the truth's times.
odo = rows(os.path.join(data, "odometry.csv"))
for m in metrics:
    est = rows(os.path.join(out, "estimates-%s.csv" % m))
    check(len(est) == len(odo) and all(e["t"] == o["t"] or abs(float(e["t"]) - float(o["t"])) < 1e-9
                                       for e, o in zip(est, odo)),
          "%s: %d estimate rows at the odometry (= truth) times" % (m, len(est)))
check(list(rows(os.path.join(out, "estimates-batch.csv"))[0].keys())[:5] == ["t", "px", "py", "heading", "range_scale"],
      "estimates columns t, px, py, heading, then the constants by name")
for name in ("fig-trajectory.png", "fig-position-error.png", "fig-range_scale.png"):
    check(os.path.getsize(os.path.join(out, name)) > 10000, name + " drawn")

# The constant switched off: the same log, the same command, another config.
ini = open(os.path.join(data, "scenario.ini")).read().replace("range_scale = true", "range_scale = false")
cfg = os.path.join(work, "no-scale.ini")
open(cfg, "w").write(ini)
out2 = os.path.join(work, "plaza2-no-scale")
r = process("--data", data, "--config", cfg, "--method", "batch", "--out", out2)
check(r.returncode == 0, "runs with the range scale switched off: " + r.stderr.strip()[-300:])
off = json.load(open(os.path.join(out2, "metrics.json")))["methods"]["batch"]["position_error_m"]["rmse"]
check(off > 5 * pos["batch"], "without the range-scale node the batch RMSE is %.2f m (with it %.3f m)" % (off, pos["batch"]))

# Bad input: named by file, line and column; the rows before it processed.
def corrupt(name, edit):
    d = os.path.join(work, "bad-" + name.replace(".", "-") + "-" + str(len(os.listdir(work))))
    shutil.copytree(data, d)
    lines = open(os.path.join(d, name)).read().split("\n")
    edit(lines)
    open(os.path.join(d, name), "w").write("\n".join(lines))
    return d

bad = corrupt("ranges.csv", lambda l: l.__setitem__(101, l[101].rsplit(",", 2)[0] + ",7," + l[101].rsplit(",", 1)[1]))
r = process("--data", bad, "--method", "fixed-lag", "--out", os.path.join(work, "o1"))
check(r.returncode == 3 and "ranges.csv:102: column 'beacon': '7' names channel 'range_7'" in r.stderr,
      "a beacon id not in beacons.csv is named (exit %d): %s" % (r.returncode, r.stderr.strip()[-200:]))
m1 = json.load(open(os.path.join(work, "o1", "metrics.json")))
check(m1["partial"] and len(rows(os.path.join(work, "o1", "estimates-fixed-lag.csv"))) > 100,
      "the rows before it were processed and written, metrics marked partial")
r = process("--data", bad, "--method", "ekf", "--skip-bad-rows", "--out", os.path.join(work, "o2"))
check(r.returncode == 0 and "skipped" in r.stderr, "--skip-bad-rows goes on past it")

bad = corrupt("ranges.csv", lambda l: l.__setitem__(50, l[50].rsplit(",", 1)[0] + ",nan"))
r = process("--data", bad, "--method", "ekf", "--out", os.path.join(work, "o3"))
check(r.returncode == 3 and "ranges.csv:51: column 'range'" in r.stderr,
      "a non-finite range is named: " + r.stderr.strip()[-200:])

bad = corrupt("odometry.csv", lambda l: l.__setitem__(0, "t,delta_distance,dheading"))
r = process("--data", bad, "--method", "ekf", "--out", os.path.join(work, "o4"))
check(r.returncode != 0 and "odometry.csv:1: no column 'delta_heading'" in r.stderr,
      "a missing column is named: " + r.stderr.strip()[-200:])

# A log whose truth starts later than its ranges and odometry (start_time =
# truth): the rows before the start are dropped and listed, not an error.
late = corrupt("truth.csv", lambda l: l.__delitem__(slice(1, 3)))
r = process("--data", late, "--method", "ekf", "--out", os.path.join(work, "o6"))
m6 = json.load(open(os.path.join(work, "o6", "metrics.json")))
dropped = [s for s in m6["skipped"] if "before the run" in s]
check(r.returncode == 0 and not m6["partial"] and any("ranges.csv:2:" in s for s in dropped)
      and any("odometry.csv:2:" in s for s in dropped),
      "rows before the truth's start are dropped and listed (%d), the rest processed" % len(dropped))

ini = open(os.path.join(data, "scenario.ini")).read().replace("channel_prefix = range_", "channel_prefix = rnge_")
cfg = os.path.join(work, "bad-prefix.ini")
open(cfg, "w").write(ini)
r = process("--data", data, "--config", cfg, "--method", "ekf", "--out", os.path.join(work, "o5"))
check(r.returncode != 0 and "ranges.csv:2: column 'beacon': '1' names channel 'rnge_1', which model 'range_beacon_2d' does not have" in r.stderr,
      "an unknown channel name is named: " + r.stderr.strip()[-200:])
# Checkpoint and resume on the real log (rows at the odometry times): stop
# at a bad range, repair it, resume from the last checkpoint: the same
# estimates as an uninterrupted run. A resumed run must use the model the
# checkpoint was made with: here the learnt scenario.ini (learning on the
# first, partial run would have learnt from part of the log).
learnt_cfg = os.path.join(out, "scenario.ini")
bad = corrupt("ranges.csv", lambda l: l.__setitem__(901, l[901].rsplit(",", 1)[0] + ",nan"))
r = process("--data", bad, "--config", learnt_cfg, "--method", "fixed-lag", "--checkpoint-every", "500",
            "--out", os.path.join(work, "c1"))
check(r.returncode == 3, "stops at the bad range with a checkpoint written")
shutil.copy(os.path.join(data, "ranges.csv"), os.path.join(bad, "ranges.csv"))
r = process("--data", bad, "--config", learnt_cfg, "--method", "fixed-lag", "--resume",
            os.path.join(work, "c1", "checkpoint-fixed-lag.ckpt"), "--out", os.path.join(work, "c2"))
check(r.returncode == 0, "resumes on the repaired log: " + r.stderr.strip()[-200:])
check(open(os.path.join(work, "c2", "estimates-fixed-lag.csv")).read() ==
      open(os.path.join(out, "estimates-fixed-lag.csv")).read(),
      "the resumed run's estimates equal the uninterrupted run's, byte for byte")
print("plaza2 end to end: all checks passed")
