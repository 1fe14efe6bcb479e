"""Errors arrive as gssm.Error subclasses with the C++ message and leave
the estimator as it was; checkpoints (bytes, files, pickle) continue a run
bit for bit."""
import os
import pickle

import numpy as np
import pytest

import gssm


@pytest.fixture(scope="module")
def data(repo):
    return gssm.io.read_dataset(os.path.join(repo, "datasets", "radar-paper"))


def test_exception_classes():
    for cls in (gssm.InvalidArgument, gssm.InputError, gssm.NumericalError, gssm.CheckpointError):
        assert issubclass(cls, gssm.Error)
    assert issubclass(gssm.Error, RuntimeError)


@pytest.mark.parametrize("method", gssm.methods(streaming_only=True))
def test_bad_input_is_named_and_changes_nothing(method, data):
    est = gssm.make_estimator(gssm.models.Radar2D(), method, options=data.options(method))
    for t, y in zip(data.t[:20], data.y[:20]):
        est.add_measurement(t, y)
    before = est.current()
    bad = [
        (lambda: est.add_measurement(data.t[20], [1.0, 2.0]), "dimension|size|2"),
        (lambda: est.add_measurement(data.t[20], [float("nan")]), "NaN|finite"),
        # before the start (late measurements between states: the incremental inserts a state)
        (lambda: est.add_measurement(data.t[0] - 1.0, data.y[20]), "time|before|increas|start"),
        (lambda: est.add_measurement(data.t[20], data.y[20], channel="gps"), "gps"),
    ]
    for call, pattern in bad:
        with pytest.raises(gssm.InvalidArgument, match=pattern):
            call()
        after = est.current()
        assert after.step == before.step and np.array_equal(after.mean, before.mean), method
    for t, y in zip(data.t[20:], data.y[20:]):
        est.add_measurement(t, y)
    run = gssm.run(gssm.models.Radar2D(), data, method=method)
    assert np.array_equal(est.current().mean, run.mean[-1])


def test_bad_options_and_files():
    with pytest.raises(gssm.InvalidArgument, match="method 'kalman'"):
        gssm.make_estimator(gssm.models.Radar2D(), "kalman")
    with pytest.raises(gssm.InvalidArgument, match="window"):
        gssm.make_estimator(gssm.models.Radar2D(), "fixed-lag", window=0)
    with pytest.raises(gssm.InvalidArgument, match="smoother option 'nonsense'"):
        gssm.make_estimator(gssm.models.Radar2D(), "incremental", smoother={"nonsense": 1})
    with pytest.raises(gssm.InvalidArgument, match="batch"):
        gssm.make_estimator(gssm.models.Radar2D(), "batch")
    with pytest.raises(gssm.Error, match="no-such-folder"):
        gssm.io.read_dataset("no-such-folder")
    with pytest.raises(gssm.CheckpointError):
        gssm.restore(gssm.models.Radar2D(), b"not a checkpoint")


def test_bad_row_is_named_by_file_line_column(tmp_path, repo):
    src = os.path.join(repo, "datasets", "radar-paper")
    for f in ("scenario.ini", "truth.csv"):
        open(tmp_path / f, "w").write(open(os.path.join(src, f)).read())
    lines = open(os.path.join(src, "measurements.csv")).read().splitlines()
    lines[11] = lines[11].split(",")[0] + ",abc"
    open(tmp_path / "measurements.csv", "w").write("\n".join(lines) + "\n")
    with pytest.raises(gssm.InputError, match=r"measurements.csv:12"):
        gssm.io.read_dataset(str(tmp_path))
    stopped = gssm.io.read_dataset(str(tmp_path), bad_rows="stop")
    assert len(stopped) == 10 and len(stopped.row_errors) == 1


@pytest.mark.parametrize("method", gssm.methods(streaming_only=True))
def test_checkpoint_continues_bit_for_bit(method, data, tmp_path):
    model = gssm.models.Radar2D()
    whole = gssm.make_estimator(model, method)
    half = gssm.make_estimator(model, method)
    for t, y in zip(data.t[:150], data.y[:150]):
        whole.add_measurement(t, y)
        half.add_measurement(t, y)
    copies = [
        gssm.restore(model, half.to_bytes()),
        pickle.loads(pickle.dumps(half)),
    ]
    half.save(str(tmp_path / "ckpt"))
    copies.append(gssm.restore(model, str(tmp_path / "ckpt")))
    for t, y in zip(data.t[150:], data.y[150:]):
        whole.add_measurement(t, y)
        for c in copies:
            c.add_measurement(t, y)
    for c in copies:
        assert c.method == method and c.step == whole.step
        assert np.array_equal(c.current().mean, whole.current().mean)
        assert np.array_equal(c.current().covariance, whole.current().covariance)
    info = gssm.checkpoint_info(model, half.to_bytes(user_data=b"log.csv:151"))
    assert info["method"] == method and info["step"] == 150 and info["user_data"] == b"log.csv:151"


def test_builtin_models_pickle_through_their_ini_form(repo):
    plaza = gssm.io.read_dataset(os.path.join(repo, "datasets", "plaza2"))
    for model in (gssm.models.Radar2D(R=4.0), gssm.models.Nav2D(), plaza.model,
                  gssm.models.Linear(A_c=[[0.0]], C_c=[[1.0]], Q=[[0.1]], R=[[1.0]], T=0.5)):
        copy = pickle.loads(pickle.dumps(model))
        assert type(copy) is type(model) and copy.to_ini() == model.to_ini()
        assert np.array_equal(copy.Q, model.Q) and np.array_equal(copy.R, model.R)


def test_report_and_marginals(data):
    est = gssm.make_estimator(gssm.models.Radar2D(), "incremental", compute_nis=True)
    for t, y in zip(data.t[:100], data.y[:100]):
        est.add_measurement(t, y)
    r = est.report()
    assert r.method == "incremental" and r.measurements == 100 and r.ordering == "colamd" and np.isfinite(r.nis)
    assert r.to_dict()["measurements"] == 100 and "variables" in r.detail
    joint = est.marginal_covariance(states=[50, 100], constants=True)
    assert joint.shape == (4, 4)
    s50 = est.smoothed(50)
    assert s50.step == 50 and np.isclose(joint[0, 0], s50.covariance[0, 0], rtol=1e-9)
    cur = est.current()
    np.testing.assert_allclose(joint[1:, 1:], cur.covariance, rtol=1e-9)
    ekf = gssm.make_estimator(gssm.models.Radar2D(), "ekf")
    ekf.add_measurement(data.t[0], data.y[0])
    assert ekf.smoothed(0) is None
