"""gssm.process runs the dataset processor in this process: the same files
gssm-process writes (byte for byte but for the timings), errors as gssm.Error
subclasses naming file and line, a bad row stopping it partway with what came
before written, and methods named by gssm.Method."""
import filecmp
import json
import os
import shutil
import subprocess

import pytest

import gssm
from conftest import run_app

TIMINGS = ("latency_median_s", "latency_p99_s", "total_s")


def without_timings(path):
    with open(path) as f:
        m = json.load(f)
    for run in m["methods"].values():
        for k in TIMINGS:
            run.pop(k, None)
    return m


@pytest.mark.parametrize("dataset", ["radar-paper", "plaza2"])
def test_process_writes_what_gssm_process_writes(repo, gssm_process, tmp_path, dataset):
    data = os.path.join(repo, "datasets", dataset)
    run_app(gssm_process, "--data", data, "--method", "all", "--out", tmp_path / "app")
    r = gssm.process(data, str(tmp_path / "py"), method="all")
    app_files = sorted(os.listdir(tmp_path / "app"))
    assert app_files == sorted(os.listdir(tmp_path / "py"))
    assert sorted(os.path.basename(f) for f in r.files) == app_files
    for name in app_files:
        if name.endswith(".csv") or (name.endswith(".png") and name != "fig-latency.png"):
            assert filecmp.cmp(tmp_path / "app" / name, tmp_path / "py" / name, shallow=False), name
    assert without_timings(tmp_path / "app" / "metrics.json") == without_timings(tmp_path / "py" / "metrics.json")
    assert json.loads(r.metrics_json) == json.load(open(tmp_path / "py" / "metrics.json"))
    assert [m.text for m in r.methods] == gssm.methods() and not r.partial
    assert len(r.runs) == 5 and r.runs[0].method == "ekf"


def test_process_takes_methods_by_value(repo, tmp_path):
    data = os.path.join(repo, "datasets", "radar-paper")
    r = gssm.process(data, str(tmp_path / "a"), method=[gssm.Method.FIXED_LAG, "ekf"], window=7, figures=False)
    assert r.methods == [gssm.Method.FIXED_LAG, gssm.Method.EKF]
    assert sorted(os.listdir(tmp_path / "a")) == ["estimates-ekf.csv", "estimates-fixed-lag.csv", "metrics.json"]
    assert gssm.Method.named("batch") == gssm.Method.BATCH and not gssm.Method.BATCH.streaming
    with pytest.raises(gssm.InvalidArgument, match="method 'kalman'"):
        gssm.process(data, str(tmp_path / "b"), method="kalman")


def test_process_errors_name_the_file_and_line(repo, tmp_path):
    broken = tmp_path / "broken"
    shutil.copytree(os.path.join(repo, "datasets", "radar-paper"), broken)
    ini = (broken / "scenario.ini").read_text().replace("R = [9]", "R = [nine]")
    (broken / "scenario.ini").write_text(ini)
    with pytest.raises(gssm.InputError, match=r"scenario\.ini:\d+: \[model\] R = '\[nine\]'"):
        gssm.process(str(broken), str(tmp_path / "out"), figures=False)


def test_a_bad_row_stops_it_partway_with_what_came_before_written(repo, gssm_process, tmp_path):
    data = tmp_path / "data"
    shutil.copytree(os.path.join(repo, "datasets", "radar-paper"), data)
    lines = (data / "measurements.csv").read_text().splitlines()
    lines[101] = lines[101].split(",")[0] + ",not-a-number"
    (data / "measurements.csv").write_text("\n".join(lines) + "\n")
    r = gssm.process(str(data), str(tmp_path / "py"), method="ekf", figures=False)
    assert r.partial and "measurements.csv:102" in r.stopped_at, r.stopped_at
    rows = open(tmp_path / "py" / "estimates-ekf.csv").read().splitlines()
    assert len(rows) == 1 + 100  # the header and the 100 good rows before it
    proc = subprocess.run([str(gssm_process), "--data", str(data), "--method", "ekf", "--out", str(tmp_path / "app")],
                          capture_output=True, text=True)
    assert proc.returncode == 3 and "measurements.csv:102" in proc.stderr
    assert filecmp.cmp(tmp_path / "app" / "estimates-ekf.csv", tmp_path / "py" / "estimates-ekf.csv", shallow=False)
    skipped = gssm.process(str(data), str(tmp_path / "skip"), method="ekf", skip_bad_rows=True, figures=False)
    assert not skipped.partial and len(skipped.skipped) == 1 and len(skipped.runs[0]) == 399


def test_process_on_threads_writes_the_same_and_reports_progress(repo, tmp_path):
    data = os.path.join(repo, "datasets", "radar-paper")
    seen = []
    r2 = gssm.process(data, str(tmp_path / "t2"), threads=2, figures=False,
                      progress=lambda m, done, total: seen.append((m.text, done, total)))
    gssm.process(data, str(tmp_path / "t1"), threads=1, figures=False)
    for name in os.listdir(tmp_path / "t1"):
        if name.endswith(".csv"):
            assert filecmp.cmp(tmp_path / "t1" / name, tmp_path / "t2" / name, shallow=False), name
    assert without_timings(tmp_path / "t1" / "metrics.json") == without_timings(tmp_path / "t2" / "metrics.json")
    assert {m for m, _, _ in seen} >= {"ekf", "batch", "incremental", "fixed-lag", "paper-window"} - {"batch"}
    assert [m.text for m in r2.methods] == gssm.methods()
    with pytest.raises(gssm.InvalidArgument, match="threads"):
        gssm.process(data, str(tmp_path / "t0"), threads=0, figures=False)
