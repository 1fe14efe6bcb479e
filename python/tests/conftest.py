"""Shared fixtures: the repository, the build tree's programs, a Dask
LocalCluster on loopback (one per test session: starting one costs ~1 s)."""
import os
import subprocess

import numpy as np
import pytest

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
BUILD = os.environ.get("GSSM_BUILD_DIR", os.path.join(REPO, "build"))


def app(name):
    path = os.path.join(BUILD, "apps", name)
    if not os.path.exists(path):
        pytest.skip("%s not built (GSSM_BUILD_APPS=OFF?)" % name)
    return path


@pytest.fixture(scope="session")
def repo():
    return REPO


@pytest.fixture(scope="session")
def gssm_process():
    return app("gssm-process")


@pytest.fixture(scope="session")
def gssm_learn():
    return app("gssm-learn")


def run_app(*args):
    proc = subprocess.run([str(a) for a in args], capture_output=True, text=True)
    assert proc.returncode == 0, "%s failed (%d):\n%s\n%s" % (args[0], proc.returncode, proc.stdout, proc.stderr)
    return proc


def read_estimates(path):
    """estimates-<method>.csv of gssm-process: (header, (N, 1 + 2n) floats, parsed exactly)."""
    with open(path) as f:
        header = f.readline().strip().split(",")
        rows = [[float(v) for v in line.strip().split(",")] for line in f if line.strip()]
    return header, np.array(rows)


@pytest.fixture(scope="session")
def cluster():
    from gssm.campaign import local_cluster
    with local_cluster(workers=2) as c:
        yield c


@pytest.fixture
def client(cluster):
    from distributed import Client
    with Client(cluster) as c:
        yield c
