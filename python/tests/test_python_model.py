"""A model written in Python drives every estimator, and equals the same
model in C++ (Radar2D) to 1e-9; errors raised inside it reach the caller
as themselves and leave the estimator unchanged."""
import os
import pickle

import numpy as np
import pytest

import gssm


def radar_f(xc, xb, u, dt):
    return np.array([xc[0] + xb[0] * dt])


def radar_h(xc, xb):
    return np.array([np.hypot(xc[0], xb[1])])


def radar_jf(xc, xb, u, dt):
    return np.array([[1.0]]), np.array([[dt, 0.0]])


def radar_jh(xc, xb):
    rho = np.hypot(xc[0], xb[1])
    return np.array([[xc[0] / rho]]), np.array([[0.0, xb[1] / rho]])


def python_radar(jacobians=True):
    ref = gssm.models.Radar2D()
    return gssm.models.PythonModel(
        radar_f, radar_h, nc=1, nb=2, ny=1, Q=ref.Q, R=ref.R, T=ref.T, prior_state=ref.prior_state,
        prior_constants=ref.prior_constants, jacobian_f=radar_jf if jacobians else None,
        jacobian_h=radar_jh if jacobians else None, name="radar-in-python",
        state_names=["x"], constant_names=["xdot", "h"], measurement_names=["range"])


@pytest.fixture(scope="module")
def data(repo):
    return gssm.io.read_dataset(os.path.join(repo, "datasets", "radar-paper"))


@pytest.mark.parametrize("method", gssm.methods())
def test_python_model_equals_cpp_model(method, data):
    cpp = gssm.run(gssm.models.Radar2D(), data, method=method)
    py = gssm.run(python_radar(), data, method=method)
    scale = np.maximum(1.0, np.abs(cpp.mean))
    assert np.max(np.abs(py.mean - cpp.mean) / scale) <= 1e-9, method
    assert np.max(np.abs(py.sd - cpp.sd) / np.maximum(1.0, cpp.sd)) <= 1e-9, method


@pytest.mark.parametrize("method", ["ekf", "fixed-lag", "batch"])
def test_central_differences_stand_in_for_missing_jacobians(method, data):
    cpp = gssm.run(gssm.models.Radar2D(), data, method=method)
    py = gssm.run(python_radar(jacobians=False), data, method=method)
    assert python_radar(jacobians=False).jacobian_source == "central differences"
    # differences of step ~1e-6 relative: agreement to ~1e-6 of the state scale
    assert np.max(np.abs(py.mean - cpp.mean) / np.maximum(1.0, np.abs(cpp.mean))) <= 1e-5, method


def test_model_functions_match_cpp():
    py, cpp = python_radar(), gssm.models.Radar2D()
    xc, xb = np.array([-80.0]), np.array([190.0, 2100.0])
    for a, b in zip(py.f(xc, xb, dt=0.05, jacobians=True), cpp.f(xc, xb, dt=0.05, jacobians=True)):
        np.testing.assert_allclose(a, b, rtol=1e-15)
    for a, b in zip(py.h(xc, xb, jacobians=True), cpp.h(xc, xb, jacobians=True)):
        np.testing.assert_allclose(a, b, rtol=1e-15)
    assert py.check_jacobians(xc, xb)["max_rel_error"] < 1e-6
    assert py.stacked_state_names == ["x", "xdot", "h"]


def test_error_in_user_code_reaches_the_caller_and_leaves_the_estimator(data):
    calls = {"n": 0}

    def h(xc, xb):
        calls["n"] += 1
        if calls["n"] == 40:
            raise ZeroDivisionError("user bug")
        return radar_h(xc, xb)

    ref = gssm.models.Radar2D()
    model = gssm.models.PythonModel(radar_f, h, nc=1, nb=2, ny=1, Q=ref.Q, R=ref.R, T=ref.T,
                                    prior_state=ref.prior_state, prior_constants=ref.prior_constants,
                                    jacobian_f=radar_jf, jacobian_h=radar_jh)
    est = gssm.make_estimator(model, "ekf")
    failed_at = None
    for k, (t, y) in enumerate(zip(data.t[:50], data.y[:50])):
        before = est.current()
        try:
            est.add_measurement(t, y)
        except ZeroDivisionError:
            failed_at = k
            after = est.current()
            assert after.step == before.step and np.array_equal(after.mean, before.mean)
            est.add_measurement(t, y)  # the same measurement again: goes through
    assert failed_at is not None
    ok = gssm.make_estimator(gssm.models.Radar2D(), "ekf")
    for t, y in zip(data.t[:50], data.y[:50]):
        ok.add_measurement(t, y)
    np.testing.assert_allclose(est.current().mean, ok.current().mean, rtol=1e-12)


def test_wrong_sizes_from_user_code_are_named():
    ref = gssm.models.Radar2D()
    model = gssm.models.PythonModel(lambda xc, xb, u, dt: np.array([1.0, 2.0]), radar_h, nc=1, nb=2, ny=1,
                                    Q=ref.Q, R=ref.R, T=ref.T, prior_state=ref.prior_state,
                                    prior_constants=ref.prior_constants, name="broken")
    est = gssm.make_estimator(model, "ekf")
    with pytest.raises(gssm.InvalidArgument, match="model 'broken': f returned 2 values, expected 1"):
        est.add_measurement(0.05, [2000.0])
    assert est.step == 0


def test_python_model_pickles(data):
    model = pickle.loads(pickle.dumps(python_radar()))
    a = gssm.run(model, data, method="ekf")
    b = gssm.run(python_radar(), data, method="ekf")
    assert np.array_equal(a.mean, b.mean)
