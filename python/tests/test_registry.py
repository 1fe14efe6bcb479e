"""Registered model types in Python (docs/DESIGN.md §3, "Adding a model"):
every class comes from its C++ registration (keywords = its INI keys, the
C++ defaults); a model defined in the test tree (tests/models/drift_1d)
appears in gssm.models once its extension is loaded."""
import importlib
import os
import pickle
import sys

import numpy as np
import pytest

import gssm
from conftest import BUILD


def load_test_models():
    path = os.path.join(BUILD, "tests", "python")
    if not os.path.isdir(path):
        pytest.skip("tests/models extension not built")
    sys.path.insert(0, path)
    try:
        return importlib.import_module("gssm_test_models")
    finally:
        sys.path.remove(path)


def test_test_tree_model_appears_in_python():
    load_test_models()
    names = [t["class_name"] for t in gssm.models.registered_types()]
    assert "Drift1D" in names
    model = gssm.models.Drift1D(q=0.04, prior_start=3.0)
    assert isinstance(model, gssm.models.Drift1D) and not isinstance(model, gssm.models.Radar2D)
    assert model.name == "drift_1d" and model.nb == 2
    assert model.params["q"] == 0.04 and model.params["prior_start"] == 3.0
    assert model.params["r"] == 0.25  # the C++ default
    # Through its INI form and pickling, the same model.
    again = gssm.models.from_ini(model.to_ini())
    assert again.params == model.params
    assert pickle.loads(pickle.dumps(model)).params == model.params
    with pytest.raises(gssm.InvalidArgument, match="unknown parameter 'qq'.*known: T, q, r"):
        gssm.models.Drift1D(qq=1.0)


def test_test_tree_model_estimates_as_the_equivalent_linear_model():
    load_test_models()
    drift = gssm.models.Drift1D(T=0.5, q=0.02, r=0.3)
    Q = drift.Q
    linear = gssm.models.Linear(A_c=[[0.0]], A_b=[[1.0, 0.0]], C_c=[[1.0]], C_b=[[0.0, 1.0]], Q=Q, R=drift.R,
                                T=0.5, prior_state_mean=drift.prior_state[0], prior_state_cov=drift.prior_state[1],
                                prior_constants_mean=drift.prior_constants[0],
                                prior_constants_cov=drift.prior_constants[1])
    data = gssm.simulate(linear, seed=4, steps=50)
    a = gssm.run(drift, data, method="incremental")
    b = gssm.run(linear, data, method="incremental")
    np.testing.assert_allclose(a.mean, b.mean, rtol=1e-9, atol=1e-9)


def test_keywords_are_the_ini_keys_and_defaults_are_the_cpp_ones(repo):
    # Radar2D() is the paper's model, as the INI of the radar-paper dataset says.
    ini = gssm.models.from_ini(open(os.path.join(repo, "datasets", "radar-paper", "scenario.ini")).read())
    paper = gssm.models.Radar2D()
    for name in ("T", "Q", "R", "prior_state_mean", "prior_state_cov", "prior_constants_mean", "prior_constants_cov"):
        np.testing.assert_array_equal(np.asarray(paper.params[name]), np.asarray(ini.params[name]))
    assert gssm.models.Radar2D(R=36.0).params["R"][0, 0] == 36.0
    for info in gssm.models.registered_types():
        cls = getattr(gssm.models, info["class_name"])
        assert info["summary"] in cls.__doc__
        for p in info["params"]:
            assert p["name"] in cls.__doc__


def test_bad_keyword_values_name_the_keyword():
    with pytest.raises(gssm.InvalidArgument, match=r"Radar2D\(R=...\).*shape \(2, 2\)"):
        gssm.models.Radar2D(R=np.eye(2))
    with pytest.raises(gssm.InvalidArgument, match=r"RangeBeacon2D\(beacons=...\).*no default"):
        gssm.models.RangeBeacon2D()
    with pytest.raises(gssm.Error, match=r"RangeBeacon2D\(loss=...\).*huber"):
        gssm.models.RangeBeacon2D(beacons=[[0, 0.0, 0.0]], loss="hubber")


def test_planar_rigid_body_from_keywords_and_from_the_uwb_log(repo):
    anchors = [[0, -3.0, 3.0, 1.0], [1, 3.0, 3.0, 1.0], [2, 0.0, -3.0, 1.0]]
    tags = [[0, -0.1, 0.0, 0.0], [1, 0.1, 0.0, 0.0]]
    m = gssm.models.PlanarRigidBody(anchors=anchors, tags=tags, height=1.0, range_sd=0.05)
    assert isinstance(m, gssm.models.PlanarRigidBody) and m.nc == 6 and m.nb == 6
    assert [c.name for c in m.channels][:2] == ["range_0_0", "range_0_1"]
    assert m.constant_names[-1] == "bias_1_2" and m.angle_states == [2]
    np.testing.assert_array_equal(m.landmarks, [[-3.0, 3.0], [3.0, 3.0], [0.0, -3.0]])
    data = gssm.simulate(m, seed=3, steps=120, channels=[c.name for c in m.channels])
    run = gssm.run(m, data, method="batch")
    assert np.all(np.abs(run.mean[-1, 6:] - data.truth_x[-1, 6:]) < 4 * run.sd[-1, 6:])
    # A part every link shares in the bias prior; a Gauss-Markov error state per link.
    shared = gssm.models.PlanarRigidBody(anchors=anchors, tags=tags, height=1.0, prior_bias_sd=0.05, prior_bias_common_sd=0.4,
                                         colored_noise_channels=["all"], colored_noise_tau=0.2)
    assert shared.nc == 12 and shared.state_names[6] == "err_range_0_0"
    assert isinstance(shared, gssm.models.PlanarRigidBody) and shared.name == "planar_rigid_body"
    P = 0.05 ** 2 * np.eye(6) + 0.4 ** 2
    np.testing.assert_allclose(shared.prior_constants[1], P, atol=1e-15)
    spread = gssm.learn(m, data, parameters=["bias_sd"], start=0.3)
    assert spread.parameters[0].method == "em" and spread.prior_converged and spread.prior_iterations >= 1
    assert spread.evaluations == 0 and 0 < spread.parameters[0].value < 0.3
    uwb = gssm.io.read_dataset(os.path.join(repo, "datasets", "uwb-fast"))
    assert isinstance(uwb.model, gssm.models.PlanarRigidBody) and len(uwb.model.channels) == 24
    assert len(uwb) == 323514 and uwb.truth_x.shape[1] == 3


def test_strapdown_ins_from_its_registration():
    """The GNSS/INS model (issue #37): keywords from its INI keys, a rotation
    block, its constants and channels, its INI form and Jacobians' shapes."""
    m = gssm.models.StrapdownIns(anchor=[40.0, -105.0, 1600.0], prior_start_rpy=[0.0, 0.0, 30.0], prior_delay_sd=0.2)
    assert isinstance(m, gssm.models.StrapdownIns) and m.name == "strapdown_ins"
    assert (m.nc, m.nb) == (10, 20) and m.rotation_blocks == [0] and m.angle_states == []
    assert m.constant_names[12] == "imu_delay" and m.constant_names[-1] == "clock_rate"
    assert [c.name for c in m.channels] == ["gnss", "nhc", "zupt", "zaru", "gnss_vel"]
    assert [c.regressors for c in m.channels] == [0, 0, 0, 0, 6]
    assert m.params["prior_delay_sd"] == 0.2
    assert m.channels[0].own_R_scale == 1.0  # the fixes' own sds as reported
    scaled = gssm.models.StrapdownIns(anchor=[40.0, -105.0, 1600.0], gnss_sd_scale=2.0)
    assert scaled.channels[0].own_R_scale == 4.0 and scaled.channels[1].own_R_scale == 1.0
    assert gssm.models.from_ini(m.to_ini()).to_ini() == m.to_ini()
    # the gyro's σ: one for every axis, or one per IMU axis (θ's noise in its axes)
    per_axis = gssm.models.StrapdownIns(anchor=[40.0, -105.0, 1600.0], gyro_sd=[0.001, 0.003, 0.0002])
    np.testing.assert_allclose(per_axis.Q.diagonal()[:3], np.array([0.001, 0.003, 0.0002]) ** 2 * 0.01, rtol=1e-15)
    np.testing.assert_array_equal(gssm.models.from_ini(per_axis.to_ini()).params["gyro_sd"], [0.001, 0.003, 0.0002])
    with pytest.raises(Exception, match="gyro_sd.*one σ .every axis. or three"):
        gssm.models.StrapdownIns(anchor=[40.0, -105.0, 1600.0], gyro_sd=[0.001, 0.003])
    x, b = m.prior_state[0], m.prior_constants[0]
    np.testing.assert_allclose(np.linalg.norm(x[:3]), np.radians(30.0), atol=1e-12)  # yaw 30° as a rotation vector
    nxt, J_x, J_b = m.f(x, b, u=[0, 0, 0, 0, 0, -9.797], dt=0.01, jacobians=True)
    assert J_x.shape == (10, 10) and J_b.shape == (10, 20)
    assert abs(nxt[5]) < 1e-3  # at rest on the ground: no vertical acceleration to speak of
    # The GNSS velocity reads the IMU's reading at the fix: without a lever
    # arm or a delay it is the velocity itself; with a lever arm it turns.
    reading = np.array([0.0, 0.0, 0.5, 0.0, 0.0, -9.8])
    x = np.array(x, dtype=float)
    x[3:6] = [3.0, -1.0, 0.2]
    still = np.zeros(20)
    np.testing.assert_allclose(m.h(x, still, "gnss_vel", regressors=reading), x[3:6], atol=1e-12)
    with pytest.raises(gssm.InvalidArgument, match="carries 0 known values"):
        m.h(x, still, "gnss_vel")
    lever = still.copy()
    lever[6:9] = [1.0, 0.0, 0.0]  # 1 m ahead along the IMU's x, turning at 0.5 rad/s about its z
    y, J_x, J_b = m.h(x, lever, "gnss_vel", jacobians=True, regressors=reading)
    assert J_x.shape == (3, 10) and J_b.shape == (3, 20)
    np.testing.assert_allclose(np.linalg.norm(y - x[3:6]), 0.5, rtol=1e-12)


def test_strapdown_ins_constraints_at_a_point_below_the_imu():
    """The vehicle constraints at points off the IMU ([prior] nhc_point_sd):
    each offset with a sigma is one more constant, and `nhc` then reads the
    gyro's reading: rolling at 0.5 rad/s about a centre 1 m below the IMU,
    the IMU moves sideways at 0.5 m/s, which the constraint's point does not."""
    m = gssm.models.StrapdownIns(anchor=[40.0, -105.0, 1600.0], prior_nhc_point_sd=[0.0, 1.0, 0.0, 0.0])
    assert m.nb == 21 and m.constant_names[-1] == "nhc_side_d"
    assert [c.regressors for c in m.channels] == [0, 3, 0, 0, 6]
    x, b = np.array(m.prior_state[0], dtype=float), np.zeros(21)
    x[:3] = 0.0  # IMU axes = NED = vehicle axes (mount_rpy 0)
    x[3:6] = [0.0, 0.5, 0.0]  # the IMU moving right at 0.5 m/s
    rolling = np.array([0.5, 0.0, 0.0])
    np.testing.assert_allclose(m.h(x, b, "nhc", regressors=rolling), [0.5, 0.0], atol=1e-12)  # at the IMU
    b[20] = 1.0  # the point 1 m below: there the roll cancels it
    np.testing.assert_allclose(m.h(x, b, "nhc", regressors=rolling), [0.0, 0.0], atol=1e-12)
    with pytest.raises(gssm.InvalidArgument, match="carries 0 known values"):
        m.h(x, b, "nhc")
    assert gssm.models.from_ini(m.to_ini()).to_ini() == m.to_ini()


def test_strapdown_ins_constraints_with_the_bodys_give():
    """The body's give ([prior] nhc_compliance): the constraints hold in axes
    turned by k_v times the forward specific force about right, so a car at
    10 m/s braking or climbing with 2 m/s^2 forward at k_v = 0.005 shows
    0.1 m/s down in the body's axes and none in the turned ones; `nhc` then
    reads the gyro's and the accelerometer's readings."""
    m = gssm.models.StrapdownIns(anchor=[40.0, -105.0, 1600.0], prior_nhc_compliance=[0.0, 0.005])
    assert m.nb == 20 and [c.regressors for c in m.channels][1] == 6
    x, b = np.array(m.prior_state[0], dtype=float), np.zeros(20)
    x[:3] = 0.0  # IMU axes = NED = vehicle axes (mount_rpy 0)
    x[3:6] = [10.0, 0.0, 0.0]
    reading = np.array([0.0, 0.0, 0.0, 2.0, 0.0, -9.8])
    np.testing.assert_allclose(m.h(x, b, "nhc", regressors=reading), [0.0, 0.1], atol=1e-12)
    x[5] = -0.1  # rising against the body's axes as it pitches: level in the turned ones
    np.testing.assert_allclose(m.h(x, b, "nhc", regressors=reading), [0.0, 0.0], atol=1e-12)
    learnt = gssm.models.StrapdownIns(anchor=[40.0, -105.0, 1600.0], prior_nhc_compliance_sd=[0.01, 0.01])
    assert learnt.constant_names[-2:] == ["nhc_side_k", "nhc_vert_k"]
    assert gssm.models.from_ini(learnt.to_ini()).to_ini() == learnt.to_ini()
