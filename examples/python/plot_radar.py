"""Estimates with ±3σ bands against the truth, drawn with matplotlib.
    PYTHONPATH=build/python /usr/bin/python3 examples/python/plot_radar.py [out.png]
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import gssm  # noqa: E402

data = gssm.io.read_dataset("datasets/radar-paper")
model = data.model
runs = {m: gssm.run(model, data, method=m) for m in ("ekf", "fixed-lag", "batch")}
fig, axes = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
errors = {m: gssm.analysis.errors(run, data)["error"] for m, run in runs.items()}  # truth matched by time
for i, (ax, name) in enumerate(zip(axes, model.stacked_state_names)):
    for method, run in runs.items():
        err = errors[method][:, i]
        line, = ax.plot(run.t, err, lw=1.2, label=method)
        ax.fill_between(run.t, -3 * run.sd[:, i], 3 * run.sd[:, i], color=line.get_color(), alpha=0.12)
    ax.set_ylabel("error in %s" % name)
    ax.set_ylim(-60, 60)
    ax.grid(True, alpha=0.3)
axes[0].legend(loc="upper right")
axes[0].set_title("radar-paper: estimate − truth with ±3σ bands")
axes[-1].set_xlabel("time t (s)")
out = sys.argv[1] if len(sys.argv) > 1 else "out/python-radar.png"
fig.tight_layout()
fig.savefig(out, dpi=100)
print("wrote", out)
