#!/usr/bin/env python3
"""gssm-process --checkpoint-every / --resume: a run that stops (here at a
bad row) and is resumed from its last checkpoint on the repaired dataset
writes the same estimates, bit for bit, as an uninterrupted run, for every
streaming method; a truncated checkpoint, another method or another dataset
is refused with an error naming the file and the reason."""
import json, os, shutil, subprocess, sys

bin_dir, work = sys.argv[1], sys.argv[2]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
data = os.path.join(work, "data")
subprocess.run([f"{bin_dir}/gssm-simulate", "--scenario", "paper", "--seed", "5",
                "--steps", "90", "--out", data], check=True, capture_output=True)
# The same dataset with a bad row at data row 61: processing stops after 60 rows.
broken = os.path.join(work, "broken")
shutil.copytree(data, broken)
mpath = os.path.join(broken, "measurements.csv")
lines = open(mpath).read().splitlines()
lines[61] = lines[61].split(",")[0] + ",nan?"
open(mpath, "w").write("\n".join(lines) + "\n")

def process(*args):
    return subprocess.run([f"{bin_dir}/gssm-process", *args], capture_output=True, text=True)

for method in ["ekf", "incremental", "fixed-lag", "paper-window"]:
    full, crashed, resumed = (os.path.join(work, f"{n}-{method}") for n in ["full", "crashed", "resumed"])
    r = process("--data", data, "--method", method, "--out", full)
    assert r.returncode == 0, r.stderr
    r = process("--data", broken, "--method", method, "--checkpoint-every", "25", "--out", crashed)
    assert r.returncode == 3, (method, r.returncode, r.stderr)
    ckpt = os.path.join(crashed, f"checkpoint-{method}.ckpt")
    assert os.path.exists(ckpt) and not os.path.exists(ckpt + ".tmp"), method
    # Resume on the repaired dataset; the method comes from the checkpoint.
    r = process("--data", data, "--resume", ckpt, "--out", resumed)
    assert r.returncode == 0, (method, r.stderr)
    a = open(os.path.join(full, f"estimates-{method}.csv")).read()
    b = open(os.path.join(resumed, f"estimates-{method}.csv")).read()
    assert a == b, f"{method}: resumed estimates differ from the uninterrupted run"
    ma = json.load(open(os.path.join(full, "metrics.json")))["methods"][method]
    mb = json.load(open(os.path.join(resumed, "metrics.json")))["methods"][method]
    for key in ["rows", "rmse", "final_error", "mean_nees"]:
        assert ma.get(key) == mb.get(key), (method, key, ma.get(key), mb.get(key))
    print(f"{method}: stopped after 60 rows, resumed from row 50: estimates identical")

ckpt = os.path.join(work, "crashed-fixed-lag", "checkpoint-fixed-lag.ckpt")
cut = os.path.join(work, "cut.ckpt")
open(cut, "wb").write(open(ckpt, "rb").read()[:-100])
r = process("--data", data, "--resume", cut, "--out", os.path.join(work, "x"))
assert r.returncode != 0 and "cut.ckpt" in r.stderr and "truncated" in r.stderr, r.stderr
r = process("--data", data, "--method", "ekf", "--resume", ckpt, "--out", os.path.join(work, "x"))
assert r.returncode != 0 and "method 'fixed-lag'" in r.stderr, r.stderr
other = os.path.join(work, "other")
subprocess.run([f"{bin_dir}/gssm-simulate", "--scenario", "paper", "--seed", "6",
                "--steps", "90", "--out", other], check=True, capture_output=True)
r = process("--data", other, "--resume", ckpt, "--out", os.path.join(work, "x"))
assert r.returncode != 0 and "differ from this dataset" in r.stderr, r.stderr
print("refused: truncated checkpoint, other method, other dataset: ok")

# A long run killed with SIGKILL while it writes checkpoints resumes to the
# same bytes as an uninterrupted run; its checkpoints do not grow with the
# run (they hold the estimator and how far the flushed output files got,
# not the rows: the old layout reached 8 MB after 30,000 radar rows).
import signal, time
long_data = os.path.join(work, "long")
subprocess.run([f"{bin_dir}/gssm-simulate", "--scenario", "paper", "--seed", "7",
                "--steps", "100000", "--out", long_data], check=True, capture_output=True)
for method in ["fixed-lag", "ekf"]:
    full, killed = os.path.join(work, f"long-full-{method}"), os.path.join(work, f"long-killed-{method}")
    r = process("--data", long_data, "--method", method, "--out", full)
    assert r.returncode == 0, r.stderr
    ckpt = os.path.join(killed, f"checkpoint-{method}.ckpt")
    proc = subprocess.Popen([f"{bin_dir}/gssm-process", "--data", long_data, "--method", method,
                             "--checkpoint-every", "1000", "--out", killed],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    seen = {}  # (inode, mtime) -> size: each checkpoint is a new file renamed into place
    deadline = time.time() + 120
    while len(seen) < 8 and proc.poll() is None and time.time() < deadline:
        try:
            st = os.stat(ckpt)
            seen[(st.st_ino, st.st_mtime_ns)] = st.st_size
        except FileNotFoundError:
            pass
        time.sleep(0.0005)
    running = proc.poll() is None
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert running, f"{method}: the run ended before it could be killed (seen {len(seen)} checkpoints)"
    sizes = sorted(set(seen.values()))
    assert len(seen) >= 3, (method, seen)
    assert sizes[-1] - sizes[0] <= 64 and sizes[-1] < 16384, (method, sizes)
    r = process("--data", long_data, "--resume", ckpt, "--out", killed)
    assert r.returncode == 0, (method, r.stderr)
    a = open(os.path.join(full, f"estimates-{method}.csv"), "rb").read()
    b = open(os.path.join(killed, f"estimates-{method}.csv"), "rb").read()
    assert a == b, f"{method}: estimates after SIGKILL and resume differ from the uninterrupted run"
    ma = json.load(open(os.path.join(full, "metrics.json")))["methods"][method]
    mb = json.load(open(os.path.join(killed, "metrics.json")))["methods"][method]
    for key in ["rows", "rmse", "final_error", "mean_nees", "max_abs_error", "constants", "constants_sd"]:
        assert ma.get(key) == mb.get(key), (method, key, ma.get(key), mb.get(key))
    print(f"{method}: killed after {len(seen)} checkpoints of {sizes[0]}..{sizes[-1]} bytes; "
          f"resumed: {len(a)} bytes of estimates identical")
