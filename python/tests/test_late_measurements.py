"""Measurements out of sequence from Python: the smoothers attach a late
reading to the state at its time (the same result as in order); the EKF
refuses it, or drops and counts it with drop_late."""
import numpy as np
import pytest

import gssm


def test_a_late_measurement_joins_its_state_in_the_smoothers_and_the_ekf_refuses_or_drops_it():
    model = gssm.models.Linear(A_c=[[0, 1], [0, 0]], C_c=[[1, 0]], Q=np.diag([0.01, 0.04]), R=[[0.25]], T=0.5,
                               prior_state_mean=[0, 1], prior_state_cov=np.diag([4.0, 1.0]))
    data = gssm.simulate(model, seed=3, steps=30)
    for method in ("incremental", "fixed-lag"):
        window = {"window": 10} if method == "fixed-lag" else {}
        late = gssm.make_estimator(model, method, **window)
        ordered = gssm.make_estimator(model, method, **window)
        for k, (t, y) in enumerate(zip(data.t, data.y)):
            ordered.add_measurement(t, y)
            ordered.add_measurement(t, y + 1.0)  # a second reading of each instant
            late.add_measurement(t, y)
            if k >= 3:  # ... arriving three instants late
                late.add_measurement(data.t[k - 3], data.y[k - 3] + 1.0)
        for k in range(len(data.t) - 3, len(data.t)):
            late.add_measurement(data.t[k], data.y[k] + 1.0)
        assert late.report().late == 29 and late.report().measurements == 60
        assert np.allclose(late.current().mean, ordered.current().mean, rtol=1e-9, atol=1e-9), method
    data = gssm.simulate("paper", seed=3, steps=30)
    ekf = gssm.make_estimator(gssm.models.Radar2D(), "ekf")
    ekf.add_measurement(data.t[0], data.y[0])
    ekf.add_measurement(data.t[1], data.y[1])
    with pytest.raises(gssm.InvalidArgument, match="before the newest state"):
        ekf.add_measurement(data.t[0], data.y[0])
    options = gssm.make_options("ekf")
    options.drop_late = True
    ekf = gssm.make_estimator(gssm.models.Radar2D(), "ekf", options=options)
    ekf.add_measurement(data.t[1], data.y[1])
    ekf.add_measurement(data.t[0], data.y[0])
    assert ekf.report().late_dropped == 1 and ekf.report().measurements == 1
