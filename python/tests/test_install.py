"""After `cmake --install`, the README's lines run against the installed
package (not the build tree's), and gssm.process runs there with its
figures (the installed libraries found through the modules' RPATH)."""
import glob
import os
import subprocess
import sys

from conftest import BUILD
from test_contract import readme_snippet


def test_installed_package_runs_the_readme_lines(repo, tmp_path):
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", BUILD, "--prefix", str(prefix)], check=True, capture_output=True)
    packages = glob.glob(str(prefix / "lib" / "python3*" / "dist-packages"))
    assert len(packages) == 1, packages
    out = tmp_path / "processed"
    code = ("import gssm, os\n" + readme_snippet(repo) +
            "\nr = gssm.process('datasets/radar-paper', %r, method='ekf')" % str(out) +
            "\nprint(gssm.__file__)\nprint(len(r.files))\n")
    env = dict(os.environ, PYTHONPATH=packages[0])
    proc = subprocess.run([sys.executable, "-c", code], cwd=repo, env=env, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    module, files = proc.stdout.split()[-2:]
    assert module.startswith(str(prefix)), module
    assert int(files) >= 4 and (out / "estimates-ekf.csv").exists() and (out / "fig-latency.png").exists()
    for stub in ("__init__.pyi", "models.pyi", "io.pyi", "analysis.pyi", "campaign.pyi", "py.typed"):
        assert os.path.exists(os.path.join(packages[0], "gssm", stub)), stub
    # The installed gssm-process finds its plotting library (loaded with
    # dlopen beside its reading) through its own RUNPATH, $ORIGIN/../lib.
    app = prefix / "bin" / "gssm-process"
    if app.exists():
        figures = tmp_path / "app-figures"
        proc = subprocess.run([str(app), "--data", "datasets/radar-paper", "--method", "ekf", "--out", str(figures)],
                              cwd=repo, capture_output=True, text=True, env=dict(os.environ, LD_LIBRARY_PATH=""))
        assert proc.returncode == 0, proc.stderr
        assert (figures / "fig-h.png").exists() and (figures / "metrics.json").exists(), proc.stdout
