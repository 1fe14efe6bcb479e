"""gssm.learn: noise learnt from a log, the same as gssm-learn's and as the
C++ library's, from a model and data or from a dataset folder."""
import json
import math
import os

import numpy as np
import pytest

import gssm
from conftest import run_app


def test_learn_from_a_model_and_data_recovers_the_noise_it_was_drawn_with():
    truth = gssm.models.Linear(A_c=[[0, 1], [0, 0]], C_c=[[1, 0]], Q=np.diag([0.25, 0.01]), R=[[0.25]], T=1.0,
                               prior_state_mean=[0, 1], prior_state_cov=np.diag([4.0, 1.0]))
    data = gssm.simulate(truth, seed=4, steps=800)
    start = gssm.models.Linear(A_c=[[0, 1], [0, 0]], C_c=[[1, 0]], Q=np.eye(2), R=[[1.0]], T=1.0,
                               prior_state_mean=[0, 1], prior_state_cov=np.diag([4.0, 1.0]))
    r = gssm.learn(start, data, start=1.0)
    assert r.converged
    assert [p.name for p in r.parameters] == ["Q[0]", "Q[1]", "R[0]"]
    for p, sigma in zip(r.parameters, [0.5, 0.1, 0.5]):
        assert p.start == 1.0 and p.identifiable, p.note
        assert abs(p.value - sigma) < 3 * p.standard_error, (p.name, p.value, p.standard_error)
    assert np.all(np.diff(r.log_likelihood) >= 0)
    assert r.final_log_likelihood == r.log_likelihood[-1] > r.start_log_likelihood
    # The learnt model is a model like any other: its Q holds the learnt σs.
    q = np.asarray(r.params["Q"])
    assert q[0, 0] == pytest.approx(r.parameters[0].value ** 2, rel=1e-12)
    run = gssm.run(r.model, data, method="ekf")
    assert run.mean.shape[0] == len(data.t)


def test_scoring_reaches_nelder_meads_maximum_in_fewer_passes_on_any_number_of_threads():
    def linear(q, r):
        return gssm.models.Linear(A_c=[[0, 1], [0, 0]], C_c=[[1, 0]], Q=np.diag(q), R=[[r]], T=1.0,
                                  prior_state_mean=[0, 1], prior_state_cov=np.diag([4.0, 1.0]))
    data = gssm.simulate(linear([0.25, 0.01], 0.25), seed=6, steps=600)
    nm = gssm.learn(linear([1, 1], 1), data, start=1.0, tolerance=1e-10, standard_errors=False)
    one = gssm.learn(linear([1, 1], 1), data, start=1.0, tolerance=1e-10, standard_errors=False, optimizer="scoring")
    two = gssm.learn(linear([1, 1], 1), data, start=1.0, tolerance=1e-10, standard_errors=False, optimizer="scoring",
                     threads=2)
    assert one.converged and one.evaluations * 3 < nm.evaluations, (one.evaluations, nm.evaluations)
    assert one.final_log_likelihood == pytest.approx(nm.final_log_likelihood, abs=1e-6)
    for a, b in zip(one.parameters, nm.parameters):
        assert a.value == pytest.approx(b.value, rel=1e-3), a.name
    assert [p.value for p in two.parameters] == [p.value for p in one.parameters]
    with pytest.raises(gssm.InvalidArgument, match="optimizer 'bfgs'"):
        gssm.learn(linear([1, 1], 1), data, optimizer="bfgs")


def test_learn_names_what_it_cannot_learn():
    model = gssm.models.Radar2D()
    data = gssm.simulate("paper", seed=1, steps=20)
    with pytest.raises(gssm.InvalidArgument, match="'range_sd' is not a learnable parameter of model 'radar_2d'"):
        gssm.learn(model, data, parameters=["range_sd"])
    with pytest.raises(gssm.InvalidArgument, match="out="):
        gssm.learn("some/folder")


def test_learn_a_folder_equals_gssm_learn(repo, tmp_path, gssm_learn):
    data = os.path.join(repo, "datasets", "plaza2")
    r = gssm.learn(data, out=str(tmp_path / "py"))
    run_app(gssm_learn, "--data", data, "--out", str(tmp_path / "app"))
    py = json.load(open(tmp_path / "py" / "learn.json"))
    app = json.load(open(tmp_path / "app" / "learn.json"))
    assert [p["learnt"] for p in py["parameters"]] == [p["learnt"] for p in app["parameters"]]
    assert [p.value for p in r.parameters] == [p["learnt"] for p in py["parameters"]]
    def without_timing(path):  # the summary line says how long it took
        return [line for line in open(path) if "EKF passes" not in line]
    assert without_timing(tmp_path / "py" / "scenario.ini") == without_timing(tmp_path / "app" / "scenario.ini")
    rs = {p.name: p for p in r.parameters}["range_sd"]
    assert 0.4 < rs.value < 0.7 and rs.identifiable and math.isfinite(rs.standard_error)


def test_process_learns_when_asked_and_not_when_told_not_to(repo, tmp_path):
    data = os.path.join(repo, "datasets", "plaza2")
    on = gssm.process(data, str(tmp_path / "on"), method="ekf", figures=False)
    assert on.learnt is not None and os.path.exists(tmp_path / "on" / "learn.json")
    off = gssm.process(data, str(tmp_path / "off"), method="ekf", figures=False, learn=False)
    assert off.learnt is None and not os.path.exists(tmp_path / "off" / "learn.json")
    assert on.runs[0].mean[-1, 0] != off.runs[0].mean[-1, 0]



def test_learn_a_model_written_in_python_through_its_factory():
    def walk(q, r):
        return gssm.models.PythonModel(lambda xc, xb, u, dt: xc, lambda xc, xb: xc[0], nc=1, ny=1,
                                       Q=[[q * q]], R=[[r * r]], prior_state=([0.0], [[4.0]]),
                                       jacobian_f=lambda xc, xb, u, dt: (np.eye(1), np.zeros((1, 0))),
                                       jacobian_h=lambda xc, xb: (np.eye(1), np.zeros((1, 0))))
    data = gssm.simulate(walk(0.3, 1.0), seed=9, steps=600)
    r = gssm.learn(walk, data, sigmas={"q": 0.5, "r": 0.5}, start=1.0)
    assert r.converged and [p.name for p in r.parameters] == ["q", "r"]
    for p, truth in zip(r.parameters, [0.3, 1.0]):
        assert p.given == 0.5 and p.start == 1.0
        assert abs(p.value - truth) < 3 * p.standard_error, (p.name, p.value, p.standard_error)
    with pytest.raises(gssm.InvalidArgument, match="sigmas="):
        gssm.learn(walk, data)


def test_the_batchs_own_noise_is_what_the_batch_runs_with(repo, tmp_path):
    """[learn] batch_likelihood_spacing: the batch's noise learnt again, into
    [batch.model]; the batch then runs as it would with those values in
    [model] (checked by a run that has them there and learns nothing)."""
    data = os.path.join(repo, "datasets", "plaza2")
    text = open(os.path.join(data, "scenario.ini"), encoding="utf-8-sig").read()
    config = tmp_path / "own.ini"
    config.write_text(text.replace("[learn]\n", "[learn]\nbatch_likelihood_spacing = 5\n", 1))
    own = gssm.process(data, str(tmp_path / "own"), method="batch", config=str(config), figures=False)
    assert own.learnt is not None and own.learnt_batch is not None
    assert os.path.exists(tmp_path / "own" / "learn-batch.json")
    learnt = open(tmp_path / "own" / "scenario.ini").read()
    head, batch_section = learnt.split("\n[batch.model]\n")
    values = dict(line.split(" = ") for line in batch_section.strip().splitlines() if " = " in line)
    online = {p.name: p.value for p in own.learnt.parameters}
    assert set(values) == set(online) and any(abs(float(values[k]) - online[k]) > 1e-3 * online[k] for k in online)
    lines = [l for l in head.splitlines() if not any(l.startswith(k + " = ") for k in values)]
    at = lines.index("[model]") + 1
    moved = tmp_path / "moved.ini"
    moved.write_text("\n".join(lines[:at] + [k + " = " + v for k, v in values.items()] + lines[at:]) + "\n")
    plain = gssm.process(data, str(tmp_path / "plain"), method="batch", config=str(moved), figures=False, learn=False)
    a, b = own.runs[0], plain.runs[0]
    assert a.mean.shape == b.mean.shape
    ratio = np.max(np.abs(a.mean - b.mean) / np.maximum(b.sd, 1e-15))  # 1184 sd apart if [batch.model] were ignored
    assert ratio < 1e-3
