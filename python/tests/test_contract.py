"""The README's Python lines run as written (from the repository root)."""
import os
import re

import numpy as np


def readme_snippet(repo):
    text = open(os.path.join(repo, "README.md")).read()
    return re.search(r"```python\n(.*?)```", text, re.S).group(1)  # the README's one Python block


def test_readme_lines_run_as_written(repo, monkeypatch):
    monkeypatch.chdir(repo)
    ns = {}
    exec(compile(readme_snippet(repo), "README.md", "exec"), ns)
    data, e, run = ns["data"], ns["e"], ns["run"]
    assert data.t.shape == (400,) and data.y.shape == (400, 1)
    assert isinstance(e.mean, np.ndarray) and e.mean.shape == (3,) and e.covariance.shape == (3, 3)
    assert run.t.shape == (400,) and run.mean.shape == (400, 3) and run.sd.shape == (400, 3)
    assert np.array_equal(run.t, data.t)
    # the fixed lag ends near the batch answer on this dataset (xdot, h)
    assert abs(e.mean[1] - run.mean[-1, 1]) < 10 * run.sd[-1, 1] + 10
