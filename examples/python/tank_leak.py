"""A user model written in Python: a water tank whose level h drains through
a leak, dh/dt = u − c·sqrt(h), fed by a measured inflow u; an ultrasonic
sensor with a constant offset b and a pressure sensor read the level. The
leak c and the offset b are the constants x_b. No Jacobians are written:
gssm uses central differences (the same model as examples/tank_leak.cpp).
Exit code 0 when both estimators land within 4 sd of the truth.
"""
import sys

import numpy as np

import gssm


def f(xc, xb, u, dt):
    return np.array([xc[0] + (u[0] - xb[0] * np.sqrt(max(xc[0], 0.0))) * dt])


def h(xc, xb):
    return np.array([xc[0] + xb[1], xc[0]])


tank = gssm.models.PythonModel(
    f, h, nc=1, nb=2, nu=1, ny=2, T=0.5, Q=[[1e-6]], R=np.diag([4e-4, 1e-4]),
    prior_state=([1.0], [[0.04]]), prior_constants=([0.01, 0.0], np.diag([1e-4, 0.01])),
    name="tank-leak", state_names=["level"], constant_names=["leak", "offset"], input_names=["inflow"],
    measurement_names=["ultrasonic", "pressure"])

rng = np.random.default_rng(42)
leak, offset, level = 0.012, 0.05, 1.1
estimators = [gssm.make_estimator(tank, "fixed-lag", window=20), gssm.make_estimator(tank, "ekf")]
for k in range(1, 2001):
    t, inflow = k * tank.T, 0.02 if (k // 200) % 2 else 0.0
    for e in estimators:
        e.add_input(t - tank.T, [inflow])
    level += (inflow - leak * np.sqrt(level)) * tank.T + 1e-3 * rng.standard_normal()
    y = [level + offset + 0.02 * rng.standard_normal(), level + 0.01 * rng.standard_normal()]
    for e in estimators:
        e.add_measurement(t, y)

status = 0
for e in estimators:
    s = e.current()
    z = (s.mean[1:] - [leak, offset]) / s.sd[1:]
    print("%-9s leak %.5f (%+.1f sd), offset %.4f (%+.1f sd), level %.3f (truth %.3f); %s"
          % (e.method, s.mean[1], z[0], s.mean[2], z[1], s.mean[0], level, tank.jacobian_source))
    status |= int(np.any(np.abs(z) > 4))
sys.exit(status)
