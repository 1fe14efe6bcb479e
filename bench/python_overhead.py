#!/usr/bin/env python3
"""Overhead of the Python module (not a test; scripts/bench runs it).

Per-update cost on the paper's radar scenario (2000 steps), all in one run:
  * C++ loop: the estimator's own total inside gssm.run (runOffline, the loop
    a C++ program runs);
  * gssm.run from Python: the same call timed from Python (conversions included);
  * Python loop: est.add_measurement(t, y) per measurement from Python;
  * Python loop reading est.current() after every measurement;
  * a model written in Python (PythonModel): analytic Jacobians, and central
    differences, through gssm.run.
Each figure is the fastest of R repetitions (this machine is shared).

    PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py [steps] [repetitions]
"""
import sys
import time

import numpy as np

import gssm


def fastest(fn, reps):
    best = float("inf")
    for _ in range(reps):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def radar_in_python(jacobians):
    ref = gssm.models.Radar2D()

    def f(xc, xb, u, dt):
        return np.array([xc[0] + xb[0] * dt])

    def h(xc, xb):
        return np.array([np.hypot(xc[0], xb[1])])

    def jf(xc, xb, u, dt):
        return np.array([[1.0]]), np.array([[dt, 0.0]])

    def jh(xc, xb):
        rho = np.hypot(xc[0], xb[1])
        return np.array([[xc[0] / rho]]), np.array([[0.0, xb[1] / rho]])

    return gssm.models.PythonModel(f, h, nc=1, nb=2, ny=1, Q=ref.Q, R=ref.R, T=ref.T,
                                   prior_state=ref.prior_state, prior_constants=ref.prior_constants,
                                   jacobian_f=jf if jacobians else None, jacobian_h=jh if jacobians else None)


def main():
    steps = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
    reps = int(sys.argv[2]) if len(sys.argv) > 2 else 7
    data = gssm.simulate("paper", seed=1, steps=steps)
    model = gssm.models.Radar2D()
    t_list, y_arr = list(data.t), data.y
    rows = []
    for method in ("ekf", "fixed-lag", "incremental"):
        opts = data.options(method)
        cpp = float("inf")

        def vectorized():
            nonlocal cpp
            r = gssm.run(model, data, method=method, options=opts)
            cpp = min(cpp, r.total_seconds)

        helper = fastest(vectorized, reps)

        def python_loop(read_current):
            def go():
                est = gssm.make_estimator(model, method, options=opts)
                add = est.add_measurement
                for t, y in zip(t_list, y_arr):
                    add(t, y)
                    if read_current:
                        est.current()
            return go

        loop = fastest(python_loop(False), reps)
        loop_current = fastest(python_loop(True), reps)
        pm = fastest(lambda: gssm.run(radar_in_python(True), data, method=method, options=opts), max(2, reps // 3))
        pm_fd = fastest(lambda: gssm.run(radar_in_python(False), data, method=method, options=opts),
                        max(2, reps // 3))
        rows.append((method, cpp, helper, loop, loop_current, pm, pm_fd))

    us = lambda s: 1e6 * s / steps  # noqa: E731
    print("Python overhead, radar `paper` scenario, %d steps, fastest of %d runs; µs per update "
          "(ratio to the C++ loop)\n" % (steps, reps))
    print("| method | C++ loop | gssm.run from Python | Python loop, add_measurement | + current() each step "
          "| PythonModel, analytic Jacobians | PythonModel, central differences |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for method, cpp, helper, loop, loop_current, pm, pm_fd in rows:
        cell = lambda s: "%.2f (%.2f×)" % (us(s), s / cpp)  # noqa: E731
        print("| %s | %.2f | %s | %s | %s | %s | %s |" % (method, us(cpp), cell(helper), cell(loop), cell(loop_current),
                                                        cell(pm), cell(pm_fd)))


if __name__ == "__main__":
    main()
