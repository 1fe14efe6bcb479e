"""The GNSS/INS drive from Python (issue #37, point 8): gssm.process writes
what gssm-process writes (the errors at the withheld fixes in metrics.json,
the navigator's columns), and gssm.run on the same dataset ends where the
processor's run ends (the final constants, the row count)."""
import json
import os

import numpy as np

import gssm
from conftest import read_estimates


def test_process_and_run_on_the_drive(repo, tmp_path):
    data_dir = os.path.join(repo, "datasets", "gnss-ins-drive")
    r = gssm.process(data_dir, str(tmp_path), method="ekf", learn=False, figures=False)
    m = json.loads(r.metrics_json)["methods"]["ekf"]
    assert m["withheld"]["count"] == 292 and m["used"]["count"] == 784
    assert m["used"]["horizontal_rms_m"] < 0.02
    assert m["withheld"]["horizontal_rms_m"] < 5.0
    header, rows = read_estimates(os.path.join(tmp_path, "estimates-ekf.csv"))
    assert header[:10] == ["t", "lat", "lon", "height", "vn", "ve", "vd", "roll", "pitch", "yaw"]
    data = gssm.io.read_dataset(data_dir)
    run = gssm.run(data.model, data, method="ekf")
    assert len(run.t) == rows.shape[0] and np.array_equal(run.t, rows[:, 0])
    names = data.model.constant_names
    final = run.mean[-1, -len(names):]
    assert np.allclose(final, [m["constants"][n] for n in names], rtol=1e-12, atol=1e-15)
