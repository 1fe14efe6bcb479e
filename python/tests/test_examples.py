"""examples/python run as documented (from the repository root)."""
import os
import subprocess
import sys

import pytest

EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "python")


def run_example(repo, name, *args):
    env = dict(os.environ)
    proc = subprocess.run([sys.executable, os.path.join(EXAMPLES, name)] + [str(a) for a in args], cwd=repo,
                          env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return proc.stdout


def test_radar(repo):
    out = run_example(repo, "radar.py")
    assert "fixed-lag at t = 20.00 s" in out and "batch final" in out


def test_user_model_in_python(repo):
    out = run_example(repo, "tank_leak.py")
    assert "central differences" in out


def test_plot(repo, tmp_path):
    run_example(repo, "plot_radar.py", tmp_path / "radar.png")
    assert os.path.getsize(tmp_path / "radar.png") > 20000


def test_montecarlo_on_a_local_cluster(repo, tmp_path):
    out = run_example(repo, "montecarlo_dask.py", 4, tmp_path)
    assert "| paper-window |" in out
    assert os.path.exists(tmp_path / "fig-mc-rmse-h.png")
