#!/usr/bin/env python3
"""gssm-process end to end: files written, CSV columns and row counts right,
metrics.json parses and its RMSE equals one recomputed here from the CSVs;
a bad option gives a one-line error and a non-zero exit."""
import csv, json, math, os, shutil, subprocess, sys

bin_dir, work = sys.argv[1], sys.argv[2]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
data, out = os.path.join(work, "data"), os.path.join(work, "out")
subprocess.run([f"{bin_dir}/gssm-simulate", "--scenario", "consistent", "--seed", "3",
                "--steps", "60", "--out", data], check=True, capture_output=True)
subprocess.run([f"{bin_dir}/gssm-process", "--data", data, "--method", "all", "--out", out],
               check=True, capture_output=True)

def read(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return rows[0], [[float(v) for v in r] for r in rows[1:]]

_, truth = read(os.path.join(data, "truth.csv"))
truth_by_t = {r[0]: r[1:] for r in truth}
metrics = json.load(open(os.path.join(out, "metrics.json")))
names = ["x", "xdot", "h"]
for method, m in metrics["methods"].items():
    header, rows = read(os.path.join(out, f"estimates-{method}.csv"))
    assert header == ["t"] + names + ["sd_" + n for n in names], header
    assert len(rows) == 60, (method, len(rows))
    assert m["rows"] == 60
    for i, n in enumerate(names):
        sq = [(r[1 + i] - truth_by_t[r[0]][i]) ** 2 for r in rows]
        rmse = math.sqrt(sum(sq) / len(sq))
        assert abs(rmse - m["rmse"][n]) <= 1e-9 * max(1.0, rmse), (method, n, rmse, m["rmse"][n])
        assert all(r[4 + i] > 0 for r in rows)
assert set(metrics["methods"]) == {"ekf", "batch", "incremental", "fixed-lag", "paper-window"}, metrics["methods"].keys()
for fig in ["fig-xdot.png", "fig-h.png", "fig-x-error.png", "fig-latency.png"]:
    assert os.path.getsize(os.path.join(out, fig)) > 10000, fig

# Methods run concurrently (--threads) write the same estimates and metrics
# as one after another (timings aside).
def timeless(path):
    return {k: {kk: vv for kk, vv in v.items() if not kk.endswith("_s")} if isinstance(v, dict) else v
            for k, v in json.load(open(path))["methods"].items()}
outs = {}
for threads in ("1", "3"):
    outs[threads] = os.path.join(work, "out-threads-" + threads)
    subprocess.run([f"{bin_dir}/gssm-process", "--data", data, "--method", "all", "--threads", threads,
                    "--out", outs[threads]], check=True, capture_output=True)
for method in metrics["methods"]:
    name = f"estimates-{method}.csv"
    assert open(os.path.join(outs["1"], name)).read() == open(os.path.join(outs["3"], name)).read(), name
assert timeless(os.path.join(outs["1"], "metrics.json")) == timeless(os.path.join(outs["3"], "metrics.json"))
zero = subprocess.run([f"{bin_dir}/gssm-process", "--data", data, "--threads", "0", "--out", out],
                      capture_output=True, text=True)
assert zero.returncode != 0 and "--threads" in zero.stderr, zero.stderr

bad = subprocess.run([f"{bin_dir}/gssm-process", "--data", data, "--method", "kalman",
                      "--out", out], capture_output=True, text=True)
assert bad.returncode != 0
assert "kalman" in bad.stderr and bad.stderr.count("\n") == 1, bad.stderr
missing = subprocess.run([f"{bin_dir}/gssm-process", "--data", os.path.join(work, "nope"),
                          "--out", out], capture_output=True, text=True)
assert missing.returncode != 0 and "nope" in missing.stderr, missing.stderr
print("process end to end: ok")

# A linear GSSM described entirely in an INI config (no C++): x_c = [p, v],
# x_b = [b] an input bias, y = p + noise; processed with --config.
lin = os.path.join(work, "linear")
os.makedirs(lin)
with open(os.path.join(lin, "run.ini"), "w") as f:
    f.write("""[model]
type = linear
T = 0.1
A_c = [0 1; 0 0]
A_b = [0; -1]
B = [0; 1]
C_c = [1 0]
C_b = [0]
Q = [1e-4 0; 0 1e-4]
R = [0.01]
discretization = exact
[prior]
state_mean = [0 0]
state_cov = [1 0; 0 1]
constants_mean = [0]
constants_cov = [1]
[fixed_lag]
window = 5
""")
import random
random.seed(1)
p, v, b = 0.0, 0.0, 0.2
with open(os.path.join(lin, "measurements.csv"), "w") as fm, open(os.path.join(lin, "inputs.csv"), "w") as fi:
    fm.write("t,y1\n")
    fi.write("t,u1\n")
    for k in range(200):
        u = 0.5 if (k // 50) % 2 == 0 else -0.5
        fi.write(f"{k * 0.1!r},{u!r}\n")
        a = u - b
        p, v = p + v * 0.1 + 0.5 * a * 0.01, v + a * 0.1
        fm.write(f"{(k + 1) * 0.1!r},{p + random.gauss(0, 0.1)!r}\n")
lout = os.path.join(work, "linear-out")
r = subprocess.run([f"{bin_dir}/gssm-process", "--data", lin, "--config", os.path.join(lin, "run.ini"),
                    "--out", lout], capture_output=True, text=True)
assert r.returncode == 0, r.stderr
header, rows = read(os.path.join(lout, "estimates-fixed-lag.csv"))
assert header == ["t", "x1", "x2", "b1", "sd_x1", "sd_x2", "sd_b1"], header
assert len(rows) == 200
b_est, b_sd = rows[-1][3], rows[-1][6]
assert abs(b_est - 0.2) < 4 * b_sd, (b_est, b_sd)
print("linear GSSM from an INI config: ok, bias", b_est, "+-", b_sd)

# Bad input: a malformed row stops processing there; everything before it is
# written, metrics.json is marked partial, exit code non-zero. With
# --skip-bad-rows the row is reported and skipped.
bad = os.path.join(work, "bad")
shutil.copytree(data, bad)
mpath = os.path.join(bad, "measurements.csv")
lines = open(mpath).read().splitlines()
lines[30] = lines[30].split(",")[0] + ",12x4"      # data row 30 (file line 31)
open(mpath, "w").write("\n".join(lines) + "\n")
bout = os.path.join(work, "bad-out")
r = subprocess.run([f"{bin_dir}/gssm-process", "--data", bad, "--method", "fixed-lag", "--out", bout],
                   capture_output=True, text=True)
assert r.returncode == 3, (r.returncode, r.stderr)
assert "measurements.csv:31" in r.stderr and "'range'" in r.stderr and "12x4" in r.stderr, r.stderr
_, rows = read(os.path.join(bout, "estimates-fixed-lag.csv"))
assert len(rows) == 29, len(rows)                 # the rows before the bad one
mj = json.load(open(os.path.join(bout, "metrics.json")))
assert mj["partial"] is True and "measurements.csv:31" in mj["stopped_at"], mj
sout = os.path.join(work, "skip-out")
r = subprocess.run([f"{bin_dir}/gssm-process", "--data", bad, "--method", "fixed-lag", "--skip-bad-rows",
                    "--out", sout], capture_output=True, text=True)
assert r.returncode == 0, r.stderr
_, rows = read(os.path.join(sout, "estimates-fixed-lag.csv"))
assert len(rows) == 59, len(rows)
mj = json.load(open(os.path.join(sout, "metrics.json")))
assert mj["partial"] is False and mj["skipped_rows"] == 1, mj
# a duplicated timestamp is reported as such
lines = open(os.path.join(data, "measurements.csv")).read().splitlines()
lines[11] = lines[10]
open(mpath, "w").write("\n".join(lines) + "\n")
r = subprocess.run([f"{bin_dir}/gssm-process", "--data", bad, "--method", "ekf", "--out", bout],
                   capture_output=True, text=True)
assert r.returncode == 3 and "duplicated timestamp" in r.stderr and "measurements.csv:12" in r.stderr, r.stderr
print("bad rows: stop with partial output / skip: ok")

# gssm-analyze: report sections and figures on a small dataset.
aout = os.path.join(work, "analyze-out")
r = subprocess.run([f"{bin_dir}/gssm-analyze", "--data", data, "--runs", "4", "--out", aout],
                   capture_output=True, text=True)
assert r.returncode == 0, r.stderr
report = open(os.path.join(aout, "analysis.md")).read()
for section in ["## 1. How close", "## 2. Consistency", "## 3. Identifiability", "## 4. Does the GSSM improve"]:
    assert section in report, section
for n in names:
    assert os.path.getsize(os.path.join(aout, f"fig-bound-{n}.png")) > 10000, n
print("gssm-analyze: ok")
