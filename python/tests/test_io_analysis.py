"""Datasets round-trip through NumPy and back to the bytes gssm-simulate
writes; the analysis arrays equal what gssm-process reports."""
import filecmp
import math
import pickle
import json
import os

import numpy as np
import pytest

import gssm
from conftest import run_app


def test_simulate_writes_the_bundled_dataset_bit_for_bit(repo, tmp_path):
    gssm.io.write_dataset(str(tmp_path), gssm.simulate("paper", seed=1, steps=400))
    for f in ("measurements.csv", "truth.csv", "scenario.ini"):
        assert filecmp.cmp(tmp_path / f, os.path.join(repo, "datasets", "radar-paper", f), shallow=False), f


def test_read_back_and_from_arrays(repo, tmp_path):
    data = gssm.io.read_dataset(os.path.join(repo, "datasets", "radar-paper"))
    gssm.io.write_dataset(str(tmp_path), data)
    again = gssm.io.read_dataset(str(tmp_path))
    assert np.array_equal(again.t, data.t) and np.array_equal(again.y, data.y)
    assert np.array_equal(again.truth_x, data.truth_x)
    arrays = gssm.io.from_arrays(data.t, data.y[:, 0], truth_t=data.truth_t, truth_x=data.truth_x)
    a = gssm.run(gssm.models.Radar2D(), arrays, method="fixed-lag")
    b = gssm.run(gssm.models.Radar2D(), data, method="fixed-lag")
    assert np.array_equal(a.mean, b.mean)


def test_plaza_layout(repo):
    data = gssm.io.read_dataset(os.path.join(repo, "datasets", "plaza2"))
    model = data.model
    assert data.rows_at_inputs and len(model.channels) > 1
    assert data.u.shape == (len(data.input_t), model.nu)
    assert set(np.unique(data.channel)) <= set(range(len(model.channels)))
    assert data.truth_components == [0, 1]
    assert "range_scale" in model.constant_names or model.nb >= 1


def test_metrics_equal_gssm_process(repo, gssm_process, tmp_path):
    d = os.path.join(repo, "datasets", "radar-paper")
    run_app(gssm_process, "--data", d, "--method", "all", "--out", tmp_path)
    cpp = json.load(open(tmp_path / "metrics.json"))["methods"]
    data = gssm.io.read_dataset(d)
    for method in gssm.methods():
        run = gssm.run(data.model, data, method=method)
        m = gssm.analysis.metrics(data.model, run, data)
        e = gssm.analysis.errors(run, data)
        np.testing.assert_array_equal(e["rmse"], m["rmse"])
        assert e["error"].shape == (400, 3) and e["nees"].shape == (400,)
        assert np.isclose(np.mean(e["nees"]), m["mean_nees"], rtol=1e-12)
        rmse_cpp = np.array([cpp[method]["rmse"][n] for n in m["names"]])
        np.testing.assert_allclose(m["rmse"], rmse_cpp, rtol=1e-9)
        assert np.isclose(m["mean_nees"], cpp[method]["mean_nees"], rtol=1e-9)


def test_bounds_and_identifiability():
    data = gssm.simulate("consistent", seed=2, steps=200)
    model = data.model
    b = gssm.analysis.cramer_rao(model, data)
    assert b["filtering"].shape == (200, 3, 3) and b["smoothing"].shape == (200, 3, 3)
    # smoothing uses more data: never a larger bound
    assert np.all(b["smoothing"][:, 0, 0] <= b["filtering"][:, 0, 0] * (1 + 1e-9))
    run = gssm.run(model, data, method="batch")
    ident = gssm.analysis.identifiability(model, run.covariance[-1][1:, 1:])
    assert ident["rank"] == 2 and ident["determined"]
    lo, hi = gssm.analysis.nees_interval(3, runs=1)
    assert np.isclose(lo, gssm.analysis.chi2_quantile(0.025, 3)) and lo < 3 < hi


def test_nees_interval_of_one_degree_is_exact():
    # χ²₁'s 2.5% and 97.5% quantiles, from the normal's: (Φ⁻¹(0.4875))², (Φ⁻¹(0.0125))².
    from statistics import NormalDist
    lo, hi = gssm.analysis.nees_interval(dof=1)
    assert np.isclose(lo, NormalDist().inv_cdf(0.4875) ** 2, rtol=1e-9)
    assert np.isclose(hi, NormalDist().inv_cdf(0.0125) ** 2, rtol=1e-9)
    assert round(lo, 6) == 0.000982 and round(hi, 3) == 5.024
    lo10, hi10 = gssm.analysis.nees_interval(dof=1, runs=10)  # the mean of ten: χ²₁₀ / 10
    assert np.isclose(lo10, gssm.analysis.chi2_quantile(0.025, 10) / 10, rtol=1e-12) and lo < lo10 < 1 < hi10 < hi


AWKWARD = "plaza\t2\nrun \"a\" \\ b\x01 Zürich 東京"


def test_metrics_json_keeps_any_name(repo, tmp_path, gssm_process):
    import shutil
    data = gssm.io.read_dataset(os.path.join(repo, "datasets", "radar-paper"))
    run = gssm.run(data.model, data, method="ekf")
    text = gssm.analysis.metrics_json(data.model, [run], truth=data, dataset=AWKWARD)
    assert json.loads(text)["dataset"] == AWKWARD
    # The app, on a folder with such a name (legal on Linux): its metrics.json loads back.
    folder = tmp_path / AWKWARD.replace("/", "")
    shutil.copytree(os.path.join(repo, "datasets", "radar-paper"), folder)
    run_app(gssm_process, "--data", folder, "--method", "ekf", "--out", tmp_path / "out")
    with open(tmp_path / "out" / "metrics.json", encoding="utf-8") as f:
        assert json.load(f)["dataset"] == str(folder)


def test_options_objects_have_the_ini_keys_and_the_cpp_defaults():
    keys = dict(gssm.io.ini_option_keys())

    def public(obj):
        return {k for k in dir(obj) if not k.startswith("_")}
    assert set(keys["ekf"]) == public(gssm.EkfOptions())
    # [smoother] ordering is the incremental smoother's: EstimatorOptions.ordering.
    assert set(keys["smoother"]) == public(gssm.SmootherOptions()) | {"ordering"}
    assert set(keys["batch"]) == public(gssm.BatchOptions())
    assert keys["fixed_lag"] == ["window", "constants_check_sigmas"] and keys["paper_window"] == ["window"]
    o = gssm.EstimatorOptions("fixed-lag")
    assert {"ordering", "fixed_lag_window", "fixed_lag_constants_check_sigmas", "paper_window_window"} <= public(o)
    assert math.isnan(o.fixed_lag_constants_check_sigmas)  # the fixed lag follows [smoother]'s
    o.fixed_lag_constants_check_sigmas = 1e9
    assert pickle.loads(pickle.dumps(o)).fixed_lag_constants_check_sigmas == 1e9
    # Defaults are the C++ structs' (the INI a default EstimatorOptions would write).
    assert gssm.BatchOptions().algorithm == "levenberg-marquardt" and gssm.BatchOptions().initial_lambda == 1e-8
    with pytest.raises(gssm.InvalidArgument, match="algorithm.*levenberg-marquardt or gauss-newton"):
        gssm.BatchOptions().algorithm = "newton"
