"""Campaigns on a 2-worker LocalCluster (loopback) equal the single-process
run and gssm-montecarlo bit for bit; a worker killed mid-campaign costs no
seed; gssm-process over a folder of logs on Dask writes what gssm-process
writes."""
import filecmp
import os
import shutil
import signal
import threading
import time

import numpy as np

import gssm
import gssm.campaign as gc
from conftest import app, run_app


def same(a, b):
    assert a.markdown() == b.markdown()
    assert [m.method for m in a.methods] == [m.method for m in b.methods]
    for ma, mb in zip(a.methods, b.methods):
        for field in ("mean_rmse", "rms_final_error", "beats_ekf", "rmse_over_time"):
            assert np.array_equal(getattr(ma, field), getattr(mb, field)), (ma.method, field)
        assert ma.mean_nees == mb.mean_nees and ma.failures == mb.failures
        assert ma.mean_nis == mb.mean_nis or (np.isnan(ma.mean_nis) and np.isnan(mb.mean_nis))


def test_cluster_equals_single_process_and_the_cpp_app(client, tmp_path):
    local = gc.monte_carlo(["paper", "consistent"], seeds=6, steps=80, window=5, client=False, workers=1)
    dask = gc.monte_carlo(["paper", "consistent"], seeds=6, steps=80, window=5, client=client, progress=False)
    for name in ("paper", "consistent"):
        same(local[name], dask[name])
    out = tmp_path / "cpp"
    run_app(app("gssm-montecarlo"), "--scenario", "paper", "--seeds", 6, "--steps", 80, "--window", 5,
            "--threads", 2, "--out", out)
    cpp = open(out / "montecarlo.md").read()
    assert dask["paper"].markdown() in cpp
    paths = gc.save_monte_carlo(dask["paper"], str(tmp_path / "py"))
    assert [os.path.basename(p) for p in paths] == ["montecarlo.md", "fig-mc-rmse-x.png", "fig-mc-rmse-xdot.png",
                                                    "fig-mc-rmse-h.png"]
    assert all(os.path.getsize(p) > 1000 for p in paths[1:])


def test_killed_worker_still_completes_every_seed_once(client):
    pids = client.run(os.getpid)
    seeds = 40
    arrived = []
    two_done = threading.Event()
    killed = {}

    def on_result(name, result):
        arrived.append(result.seed)
        if len(arrived) >= 2:
            two_done.set()

    def kill_one_worker():  # after the first seeds arrived, while the campaign runs
        if not two_done.wait(60):
            return
        addr, pid = sorted(pids.items())[0]
        os.kill(pid, signal.SIGKILL)
        killed["arrived"] = len(arrived)

    killer = threading.Thread(target=kill_one_worker)
    killer.start()
    res = gc.monte_carlo("paper", seeds=seeds, steps=400, window=10, client=client, progress=False,
                         on_result=on_result)
    killer.join()
    assert "arrived" in killed, "the worker was not killed"
    assert killed["arrived"] < seeds, "the campaign had finished before the kill"
    assert sorted(arrived) == list(range(1, seeds + 1))  # every seed once
    ref = gc.monte_carlo("paper", seeds=seeds, steps=400, window=10, client=False, workers=1)
    same(res, ref)
    assert client.run(os.getpid) != pids  # the nanny replaced the killed worker


def test_process_folder_on_dask_writes_what_gssm_process_writes(repo, client, gssm_process, tmp_path):
    logs = tmp_path / "logs"
    shutil.copytree(os.path.join(repo, "datasets", "radar-paper"), logs / "radar-paper")
    gssm.io.write_dataset(str(logs / "nav"), gssm.simulate("nav-paper-like", seed=4, steps=80))
    res = gc.process_folder(str(logs), str(tmp_path / "dask"), method="ekf", client=client, progress=False)
    assert sorted(res) == ["nav", "radar-paper"]
    for name in res:
        assert res[name]["returncode"] == 0 and list(res[name]["metrics"]["methods"]) == ["ekf"]
        direct = tmp_path / "direct" / name
        run_app(gssm_process, "--data", logs / name, "--method", "ekf", "--out", direct)
        assert filecmp.cmp(direct / "estimates-ekf.csv", tmp_path / "dask" / name / "estimates-ekf.csv",
                           shallow=False)
    (logs / "broken").mkdir()
    (logs / "broken" / "scenario.ini").write_text("[model]\ntype = nothing\n")
    try:
        gc.process_folder(str(logs), str(tmp_path / "again"), method="ekf", client=False, progress=False)
        raise AssertionError("a broken log must fail the folder")
    except gssm.Error as e:
        assert "broken" in str(e) and "1 of 3" in str(e)


def test_scheduler_address_scales_out(cluster):
    """client= a scheduler address (how a campaign reaches a cluster of
    machines): here the LocalCluster's own, over TCP on loopback."""
    address = cluster.scheduler_address
    assert address.startswith("tcp://127.0.0.1:")
    remote = gc.monte_carlo("consistent", seeds=3, steps=40, client=address, progress=False)
    local = gc.monte_carlo("consistent", seeds=3, steps=40, client=False, workers=1)
    same(remote, local)
