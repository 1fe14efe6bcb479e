"""The paper's Monte Carlo on a Dask LocalCluster: seeds spread over worker
processes, the table equal bit for bit to gssm-montecarlo's.
    PYTHONPATH=build/python /usr/bin/python3 examples/python/montecarlo_dask.py [seeds] [outdir]
Pass a scheduler address as client= to run on a cluster of machines.
"""
import sys

import gssm.campaign as gc

if __name__ == "__main__":  # Dask starts worker processes that import this file
    seeds = int(sys.argv[1]) if len(sys.argv) > 1 else 100
    out = sys.argv[2] if len(sys.argv) > 2 else "out/python-montecarlo"
    result = gc.monte_carlo("paper", seeds=seeds, steps=400, window=10, workers=2)
    print(result.markdown())
    print("%.1f s on 2 workers" % result.seconds)
    for path in gc.save_monte_carlo(result, out, command="examples/python/montecarlo_dask.py %d" % seeds):
        print("wrote", path)
