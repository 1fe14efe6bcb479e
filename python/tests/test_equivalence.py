"""Python results equal the C++ results bit for bit: gssm.run against
gssm-process's estimates files (written with 17 significant digits, read
back exactly) for every built-in model and every method, and a Python loop
over the streaming estimator against gssm.run."""
import os

import numpy as np
import pytest

import gssm
from conftest import read_estimates, run_app

METHODS = gssm.methods()


def simulated(tmp, scenario, steps, seed=3):
    d = os.path.join(tmp, scenario)
    gssm.io.write_dataset(d, gssm.simulate(scenario, seed=seed, steps=steps))
    return d


def linear_dataset(tmp):
    """A two-sensor linear model from matrices, simulated and written."""
    model = gssm.models.Linear(
        A_c=[[0, 1], [0, 0]], C_c=[[1, 0]], Q=np.diag([1e-4, 1e-3]), R=[[0.25]], A_b=[[0], [1]], C_b=[[1]],
        prior_state_mean=[0, 1], prior_state_cov=np.eye(2), prior_constants_mean=[0.5],
        prior_constants_cov=[[4.0]], T=0.1,
        channels=[dict(name="gps", C_c=[[1, 0]], C_b=[[0]], R=[[1.0]])])
    d = os.path.join(tmp, "linear")
    gssm.io.write_dataset(d, gssm.simulate(model, seed=5, steps=150, channels=["y", "gps"]))
    return d


@pytest.fixture(scope="module")
def datasets(repo, tmp_path_factory):
    tmp = str(tmp_path_factory.mktemp("datasets"))
    return {
        "radar-paper": os.path.join(repo, "datasets", "radar-paper"),
        "plaza2": os.path.join(repo, "datasets", "plaza2"),
        "nav": simulated(tmp, "nav-paper-like", 120),
        "beacons": simulated(tmp, "beacons-consistent", 150),
        "linear": linear_dataset(tmp),
    }


@pytest.mark.parametrize("name", ["radar-paper", "plaza2", "nav", "beacons", "linear"])
def test_run_equals_gssm_process_bit_for_bit(name, datasets, gssm_process, tmp_path):
    data_dir = datasets[name]
    run_app(gssm_process, "--data", data_dir, "--method", "all", "--out", tmp_path)
    # A dataset whose [learn] is on ran on the learnt model: its learnt scenario.ini.
    learnt = os.path.join(tmp_path, "learn.json")
    data = gssm.io.read_dataset(data_dir, config=os.path.join(tmp_path, "scenario.ini") if os.path.exists(learnt) else "")
    for method in METHODS:
        header, cpp = read_estimates(os.path.join(tmp_path, "estimates-%s.csv" % method))
        run = gssm.run(data.model, data, method=method)
        n = len(run.names)
        assert header[1:1 + n] == run.names
        assert np.array_equal(run.t, cpp[:, 0]), (name, method)
        assert np.array_equal(run.mean, cpp[:, 1:1 + n]), (name, method, np.abs(run.mean - cpp[:, 1:1 + n]).max())
        assert np.array_equal(run.sd, cpp[:, 1 + n:]), (name, method)


def test_builtin_model_from_python_equals_the_dataset_model(repo):
    """gssm.models.Radar2D() (the contract's model) is the paper's model."""
    data = gssm.io.read_dataset(os.path.join(repo, "datasets", "radar-paper"))
    for method in METHODS:
        a = gssm.run(gssm.models.Radar2D(), data, method=method)
        b = gssm.run(data.model, data, method=method)
        assert np.array_equal(a.mean, b.mean) and np.array_equal(a.sd, b.sd), method


@pytest.mark.parametrize("method", gssm.methods(streaming_only=True))
def test_python_loop_equals_the_loop_in_cpp(method, repo):
    data = gssm.io.read_dataset(os.path.join(repo, "datasets", "radar-paper"))
    run = gssm.run(data.model, data, method=method)
    est = gssm.make_estimator(data.model, method, options=data.options(method))
    for k, (t, y) in enumerate(zip(data.t, data.y)):
        est.add_measurement(t, y)
        e = est.current()
        assert e.t == run.t[k]
        assert np.array_equal(e.mean, run.mean[k]), (method, k)
        assert np.array_equal(np.sqrt(np.diag(e.covariance)), run.sd[k]), (method, k)


def test_channels_and_inputs_in_a_python_loop(repo):
    """Plaza 2 (odometry inputs, one range channel per beacon) fed by hand
    through add_input / add_measurement(channel=name) ends where gssm.run does."""
    data = gssm.io.read_dataset(os.path.join(repo, "datasets", "plaza2"))
    model = data.model
    names = [c.name for c in model.channels]
    opts = data.options("fixed-lag")
    est = gssm.make_estimator(model, "fixed-lag", options=opts)
    events = [(t, 0, i) for i, t in enumerate(data.input_t)] + [(t, 1, i) for i, t in enumerate(data.t)]
    events.sort(key=lambda e: (e[0], e[1]))  # an input before a measurement at the same time
    for t, kind, i in events:
        if kind == 0:
            est.add_input(t, data.u[i])
        else:
            est.add_measurement(t, data.y[i], channel=names[data.channel[i]])
    run = gssm.run(model, data, method="fixed-lag")  # rows at the odometry times
    assert est.time == run.t[-1]
    np.testing.assert_allclose(est.current().mean, run.mean[-1], rtol=0, atol=1e-9)


def test_measurement_with_its_own_R_and_progress(repo):
    """add_measurement(R=...) equals a model whose channel has that R; the
    progress callback of gssm.run sees every measurement."""
    data = gssm.io.read_dataset(os.path.join(repo, "datasets", "radar-paper"))
    noisy = gssm.models.Radar2D(R=36.0)
    for method in gssm.methods(streaming_only=True):
        a = gssm.make_estimator(gssm.models.Radar2D(), method)
        b = gssm.make_estimator(noisy, method)
        for t, y in zip(data.t[:120], data.y[:120]):
            a.add_measurement(t, y, R=[[36.0]])
            b.add_measurement(t, y)
        np.testing.assert_allclose(a.current().mean, b.current().mean, rtol=1e-12, err_msg=method)
        np.testing.assert_allclose(a.current().covariance, b.current().covariance, rtol=1e-9, err_msg=method)
    seen = []
    gssm.run(data.model, data, method="ekf", progress=lambda done, total: seen.append((done, total)))
    assert seen and seen[-1] == (400, 400)
