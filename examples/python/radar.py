"""The paper's radar example in twenty lines: stream the bundled dataset
through the fixed-lag smoother, then run the EKF and the batch solver over
the whole run with the loop in C++.  Run from the repository root:
    PYTHONPATH=build/python /usr/bin/python3 examples/python/radar.py
"""
import numpy as np

# [quickstart]
import gssm
model = gssm.models.Radar2D()                           # the paper's settings
data = gssm.io.read_dataset("datasets/radar-paper")     # data.t (N,), data.y (N, 1)
est = gssm.make_estimator(model, method="fixed-lag", window=10)
for t, y in zip(data.t, data.y):
    est.add_measurement(t, y)
e = est.current()                                       # e.mean (n,), e.covariance (n, n): NumPy
run = gssm.run(model, data, method="ekf")               # the loop in C++: run.t (N,), run.mean (N, n), run.sd (N, n)
# [/quickstart]
print("fixed-lag at t = %.2f s: %s ± %s" % (e.t, np.round(e.mean, 2), np.round(e.sd, 2)))
truth = data.truth_x[-1]
for method in ("ekf", "batch"):
    run = gssm.run(model, data, method=method)          # every method gssm-process knows
    err = gssm.analysis.errors(run, data)
    print("%-5s final %s, RMSE %s, %.2f ms" % (method, np.round(run.mean[-1], 2), np.round(err["rmse"], 2),
                                              1e3 * run.total_seconds))
print("truth %s" % np.round(truth, 2))
