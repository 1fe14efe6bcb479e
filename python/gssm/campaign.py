"""Campaigns on Dask: Monte Carlo over seeds × scenarios × methods, and
gssm.process over a folder of logs, on any dask.distributed cluster.

    import gssm.campaign as gc
    res = gc.monte_carlo("paper", seeds=100)        # a LocalCluster on this machine
    res = gc.monte_carlo("paper", seeds=10000, client="tcp://scheduler:8786")
    print(res.markdown()); gc.save_monte_carlo(res, "out/mc")

Each seed is one Dask task (retried if its worker dies); finished results
are pulled to the client as they complete, so a dead worker loses none.
The table is computed from the seeds in seed order by the same C++ code as
gssm-montecarlo: equal bit for bit to a single-process run, whatever the
number of workers.
"""
import contextlib
import json
import os
import sys
import time
import uuid

from . import _gssm

Scenario = _gssm.campaign.Scenario
SeedResult = _gssm.campaign.SeedResult
MonteCarloResult = _gssm.campaign.MonteCarloResult
MethodSummary = _gssm.campaign.MethodSummary

__all__ = ["Scenario", "SeedResult", "MonteCarloResult", "MethodSummary", "monte_carlo", "save_monte_carlo",
           "process_folder", "local_cluster"]


def local_cluster(workers=None, threads_per_worker=1):
    """A LocalCluster on the loopback interface (no dashboard), with gssm
    importable in its worker processes. `workers` defaults to the CPU count."""
    from distributed import LocalCluster
    package_parent = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    paths = os.environ.get("PYTHONPATH", "").split(os.pathsep)
    if package_parent not in paths:
        os.environ["PYTHONPATH"] = os.pathsep.join([package_parent] + [p for p in paths if p])
    return LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=threads_per_worker,
                        processes=True, host="127.0.0.1", dashboard_address=None)


@contextlib.contextmanager
def _client(client, workers):
    """The Dask client to use: an existing Client, a scheduler address, or a
    new LocalCluster (closed afterwards)."""
    from distributed import Client
    if client is None:
        with local_cluster(workers) as cluster, Client(cluster) as c:
            yield c
    elif isinstance(client, str):
        with Client(client) as c:
            yield c
    else:
        yield client


class _Progress:
    """A one-line progress bar on stderr."""

    def __init__(self, total, label, enabled):
        self.total, self.label, self.enabled, self.done = total, label, enabled, 0

    def step(self):
        self.done += 1
        if self.enabled:
            width = 40
            filled = width * self.done // max(self.total, 1)
            sys.stderr.write("\r%s [%s%s] %d/%d" % (self.label, "#" * filled, " " * (width - filled), self.done,
                                                    self.total))
            if self.done == self.total:
                sys.stderr.write("\n")
            sys.stderr.flush()


def _run_seed(scenario, seed):
    return scenario.run_seed(seed)


def monte_carlo(scenarios="paper", seeds=100, *, first_seed=1, steps=400, methods=None, window=None,
                estimator_config=None, client=None, workers=None, retries=3, progress=True, on_result=None):
    """A Monte Carlo campaign: every seed of every scenario with every method.

    scenarios: a built-in scenario name (gssm.io.scenarios()), a Scenario, or
    a list of them; the result is one MonteCarloResult, or a dict name ->
    result for a list. seeds: how many, from first_seed; steps: per run.
    methods: names (default: all; "ekf" is required, the baseline).
    window: fixed-lag and paper-window length (default: the scenario's).
    estimator_config: INI text for the estimators' own model (mis-tuned runs).
    client: None (a LocalCluster of `workers` processes), a scheduler
    address ("tcp://host:8786"), a distributed.Client, or False (this
    process, no Dask: gssm-montecarlo's thread pool, on `workers` threads).
    retries: times Dask retries a seed whose worker died.
    progress: a progress bar on stderr; on_result: a callable(scenario name,
    SeedResult) called in the client as each seed arrives (Dask runs only).
    """
    single = not isinstance(scenarios, (list, tuple))
    wanted = [scenarios] if single else list(scenarios)
    built = []
    for s in wanted:
        if isinstance(s, Scenario):
            built.append(s)
        else:
            ini = _gssm.io.scenario_ini(s, first_seed, steps)
            built.append(Scenario(ini, estimator_config or "", list(methods or []), int(window or 0)))
    results = {}
    start = time.perf_counter()
    if client is False:
        for s in built:
            results[s.name] = s.run_local(seeds, first_seed, workers or os.cpu_count() or 1)
    else:
        results = _dask_monte_carlo(built, seeds, first_seed, client, workers, retries, progress, on_result)
    for r in results.values():
        r.seconds = time.perf_counter() - start
    return results[built[0].name] if single else results


def _dask_monte_carlo(built, seeds, first_seed, client, workers, retries, progress, on_result):
    from distributed import as_completed
    token = uuid.uuid4().hex[:8]
    with _client(client, workers) as c:
        futures, owner = [], {}
        for s in built:
            for seed in range(first_seed, first_seed + seeds):
                f = c.submit(_run_seed, s, seed, key="gssm-mc-%s-%s-%d" % (token, s.name, seed), retries=retries,
                             pure=False)
                futures.append(f)
                owner[f.key] = s.name
        bar = _Progress(len(futures), "gssm.campaign.monte_carlo", progress)
        got = {s.name: {} for s in built}
        for future, result in as_completed(futures, with_results=True):
            name = owner[future.key]
            if result.seed in got[name]:
                raise _gssm.Error("campaign: seed %d of %s arrived twice" % (result.seed, name))
            got[name][result.seed] = result
            future.release()
            bar.step()
            if on_result:
                on_result(name, result)
    out = {}
    for s in built:
        ordered = [got[s.name][seed] for seed in range(first_seed, first_seed + seeds)]
        out[s.name] = s.summarize(ordered)
    return out


def save_monte_carlo(result, out, command=None):
    """Writes montecarlo.md and fig-mc-rmse-<state>.png to `out`, as
    gssm-montecarlo does (figures drawn with matplotlib). Returns the paths."""
    os.makedirs(out, exist_ok=True)
    md = os.path.join(out, "montecarlo.md")
    with open(md, "w") as f:
        f.write("# Monte Carlo: %s\n\n" % result.scenario)
        if command:
            f.write("Command: `%s`\n\n" % command)
        f.write(result.markdown())
    paths = [md]
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    for i, state in enumerate(result.state_names):
        fig, ax = plt.subplots(figsize=(8, 4.5), dpi=100)
        for m in result.methods:
            style = "-" if _gssm.Method.named(m.method).streaming else "--"  # the batch uses all the data
            ax.plot(m.times, m.rmse_over_time[:, i], style, lw=1.5, label=m.method)
        ax.set_title("RMSE of %s over %d seeds (%s)" % (state, result.seeds, result.scenario))
        ax.set_xlabel("time t (s)")
        ax.set_ylabel("RMSE " + state)
        ax.grid(True, alpha=0.3)
        ax.legend()
        path = os.path.join(out, "fig-mc-rmse-%s.png" % state)
        fig.tight_layout()
        fig.savefig(path)
        plt.close(fig)
        paths.append(path)
    return paths


def _process_one(data, out, settings):
    """One log through gssm.process in this (worker) process; its exit code
    as gssm-process would give it: 0, 3 when a bad row stopped it partway,
    1 when it failed (the error's message in "error")."""
    from . import process
    try:
        r = process(data, out, **settings)
    except _gssm.Error as e:
        return {"data": data, "out": out, "returncode": 1, "error": str(e), "metrics": None, "files": []}
    return {"data": data, "out": out, "returncode": 3 if r.partial else 0, "error": r.stopped_at,
            "metrics": json.loads(r.metrics_json), "files": list(r.files)}


def process_folder(folder, out, *, method="all", window=None, config=None, skip_bad_rows=False, figures=True,
                   client=None, workers=None, retries=3, progress=True):
    """gssm.process over every dataset folder (a folder with a scenario.ini)
    under `folder`, one Dask task per log, in the workers' own processes,
    outputs in out/<log name>/.

    method, window, config, skip_bad_rows, figures: as gssm.process. client:
    as in monte_carlo (False: one after the other in this process). Returns
    {log name: {"returncode" (gssm-process's exit code), "error", "metrics",
    "files", "data", "out"}}; raises gssm.Error naming every log that failed,
    after all have run.
    """
    logs = sorted(d for d in os.listdir(folder) if os.path.isfile(os.path.join(folder, d, "scenario.ini")))
    if not logs:
        raise _gssm.InvalidArgument("process_folder: no dataset folders (with a scenario.ini) in " + folder)
    settings = dict(method=method, window=window, config=config, skip_bad_rows=skip_bad_rows, figures=figures,
                    progress=None)
    jobs = {name: (os.path.abspath(os.path.join(folder, name)), os.path.abspath(os.path.join(out, name)), settings)
            for name in logs}
    bar = _Progress(len(jobs), "gssm.campaign.process_folder", progress)
    results = {}
    if client is False:
        for name, job in jobs.items():
            results[name] = _process_one(*job)
            bar.step()
    else:
        from distributed import as_completed
        token = uuid.uuid4().hex[:8]
        with _client(client, workers) as c:
            futures = {c.submit(_process_one, *job, key="gssm-process-%s-%s" % (token, name), retries=retries,
                                pure=False): name for name, job in jobs.items()}
            for future, result in as_completed(list(futures), with_results=True):
                results[futures[future]] = result
                bar.step()
    failed = {n: r for n, r in results.items() if r["returncode"] != 0}
    if failed:
        raise _gssm.Error("process_folder: %d of %d logs failed: %s" % (
            len(failed), len(results),
            "; ".join("%s (exit %d): %s" % (n, r["returncode"], r["error"]) for n, r in sorted(failed.items()))))
    return dict(sorted(results.items()))
