"""gssm: real-time optimal estimation with the Graphical State Space Model.

The C++ library at C++ speed: constants kept as one node for the whole run,
an incremental (Bayes tree) smoother, an exact fixed-lag smoother, the EKF
baseline and the batch MAP, on the same model object.

Run from the repository root (the tests run this example as a doctest)::

    >>> import gssm
    >>> model = gssm.models.Radar2D()
    >>> data = gssm.io.read_dataset("datasets/radar-paper")
    >>> est = gssm.make_estimator(model, method="fixed-lag", window=10)
    >>> for t, y in zip(data.t, data.y):
    ...     _ = est.add_measurement(t, y)
    >>> e = est.current()                          # e.mean, e.covariance: NumPy
    >>> run = gssm.run(model, data, method="ekf")  # run.t, run.mean, run.sd
    >>> run.mean.shape == (len(data.t), 3)
    True

Methods are named as gssm-process names them: see gssm.methods().
"""
import os

from . import _gssm
from ._gssm import (
    Error,
    InvalidArgument,
    InputError,
    NumericalError,
    CheckpointError,
    Estimator,
    EstimatorOptions,
    EkfOptions,
    SmootherOptions,
    BatchOptions,
    EstimatorReport,
    UpdateReport,
    StateEstimate,
    Run,
    Method,
    ProcessResult,
    LearnReport,
    LearntParameter,
    methods,
    checkpoint_info,
)
from . import models, io, analysis  # noqa: E402  (after _gssm: they wrap it)
from ._options import make_options, method_of  # noqa: E402

__all__ = [
    "Error", "InvalidArgument", "InputError", "NumericalError", "CheckpointError",
    "Estimator", "EstimatorOptions", "EkfOptions", "SmootherOptions", "BatchOptions",
    "EstimatorReport", "UpdateReport", "StateEstimate", "Run", "Method", "ProcessResult",
    "LearnReport", "LearntParameter",
    "methods", "make_options", "make_estimator", "run", "process", "learn", "restore", "checkpoint_info",
    "simulate", "models", "io", "analysis",
]


def make_estimator(model, method="fixed-lag", *, options=None, **settings):
    """A streaming estimator for `model`.

    method: "ekf", "incremental", "fixed-lag" or "paper-window" (the batch
    solver needs the whole run: gssm.run(..., method="batch")).
    options: an EstimatorOptions to start from (default: the C++ defaults).
    settings: window=, ordering=, t0=, compute_nis=, and ekf=, smoother=,
    batch= as dicts of those option groups' fields; see make_options.
    Raises gssm.InvalidArgument naming the option at fault.
    """
    o = make_options(method, options=options, **settings)
    o.validate(model)
    return _gssm.make_estimator_from_options(model, o)


def run(model, data, method="fixed-lag", *, options=None, rows_at_inputs=None, progress=None, **settings):
    """Runs `method` over a whole dataset with the loop in C++; returns a gssm.Run.

    data: a gssm.io.Dataset (read_dataset, simulate, io.from_arrays).
    Settings come, as in gssm-process, from the dataset's scenario.ini
    sections ([ekf], [smoother], [fixed_lag], [paper_window], [batch]) and
    its start time when it has them, else from the C++ defaults; options=
    replaces them and keyword settings (window=, ...) override either.
    Every name gssm-process takes is a method here, "batch" included.
    progress: a callable(done, total), called from the loop (holds the GIL).
    The result equals gssm-process's estimates bit for bit.
    """
    if options is None:
        options = _dataset_options(data, model, method_of(method).text)
    o = make_options(method, options=options, **settings)
    o.validate(model)
    return _gssm.run_dataset(model, data, o, rows_at_inputs, progress)


def _dataset_options(data, model, method):
    if data.scenario.strip():
        try:
            return data.options(method, model)
        except InputError as e:
            raise InputError("%s (the dataset's settings for this model; pass options= to use others)" % e) from e
    o = EstimatorOptions(method)
    o.t0 = data.t0
    return o


def restore(model, source):
    """The estimator a checkpoint holds, on `model`: source is bytes
    (Estimator.to_bytes) or a file path (Estimator.save)."""
    if isinstance(source, (bytes, bytearray, memoryview)):
        return _gssm.restore_bytes(model, bytes(source))
    return _gssm.restore_file(model, str(source))


def simulate(scenario="paper", seed=1, steps=400, **kwargs):
    """A simulated run as a gssm.io.Dataset (with .model and the whole truth).

    scenario: a built-in scenario name (gssm.io.scenarios(); the same bytes
    gssm-simulate writes for the same seed and steps) or a gssm.models.Model
    (x0=, xb=, measure_every= as keywords; x0 and xb drawn from the priors
    unless given).
    """
    if isinstance(scenario, str):
        if kwargs:
            raise InvalidArgument("simulate: keyword arguments %s are for a model, not scenario '%s'"
                                  % (sorted(kwargs), scenario))
        return _gssm.io.simulate_scenario(scenario, seed, steps)
    return _gssm.io.simulate_model(scenario, seed, steps, **kwargs)


def learn(model_or_folder, data=None, *, out=None, config=None, parameters=None, sigmas=None, start=0.0,
          search_range=1e4, max_evaluations=4000, tolerance=1e-7, max_restarts=6, standard_errors=True,
          optimizer="nelder-mead", threads=1):
    """Noise learnt from a log, no truth (docs/DESIGN.md §10): the σs the
    model declares learnable fitted by maximum likelihood (an ungated EKF's
    prediction errors, maximized over log σ by Nelder-Mead or, with
    optimizer="scoring", a quasi-Newton method that takes several times
    fewer filter passes but climbs to the nearest maximum; threads: passes
    at once, for a registered model). Returns a gssm.LearnReport:
    .model (the learnt model), .parameters (start, value, standard_error,
    identifiable, note), .log_likelihood per iteration.

        report = gssm.learn(model, data, start=1.0)      # a model and a gssm.io dataset
        report = gssm.learn("datasets/plaza2", out="out/learnt")   # what gssm-learn does

    A folder: its scenario.ini (or config=) with its [learn] options; writes
    out/scenario.ini (the input with the learnt values) and out/learn.json.
    parameters: names to learn ("range_sd", "Q", "Q[1]"; default every
    learnable one); start: every σ starts here (0: the model's values).
    A σ of the constants' prior ("bias_sd" of PlanarRigidBody) is learnt by
    EM on the factor graph (each E-step a batch solve): method "em".

    A model written in Python declares no parameters: pass a factory and
    the σs it takes, sigmas={"q": 0.1, "r": 0.5} (the given values); it is
    called as factory(q=..., r=...) for every likelihood evaluated:

        report = gssm.learn(lambda q, r: MyModel(q, r), data, sigmas={"q": 0.1, "r": 0.5}, start=1.0)
    """
    options = (float(start), float(search_range), int(max_evaluations), float(tolerance), int(max_restarts),
               bool(standard_errors), str(optimizer), int(threads))
    if callable(model_or_folder) and not isinstance(model_or_folder, models.Model):
        if not sigmas:
            raise InvalidArgument("gssm.learn(factory, data, sigmas={name: given σ, ...}): name the σs it takes")
        names = list(sigmas)
        factory = model_or_folder
        # one pass at a time (options without threads): the factory and its model's f and h are Python
        return _gssm._learn_family(lambda s: factory(**dict(zip(names, (float(v) for v in s)))), names,
                                   [float(sigmas[n]) for n in names], data, *options[:-1])
    if isinstance(model_or_folder, (str, os.PathLike)):
        if data is not None or out is None:
            raise InvalidArgument("gssm.learn(folder, out=DIR): a dataset folder takes out=, not data")
        return _gssm._learn_folder(str(model_or_folder), str(out), str(config or ""))
    if data is None:
        raise InvalidArgument("gssm.learn(model, data): the data to learn from (gssm.io.read_dataset, gssm.simulate)")
    return _gssm._learn_model(model_or_folder, data, list(parameters or []), *options)


def process(data, out, *, method="all", config=None, window=None, checkpoint_every=None, resume=None,
            skip_bad_rows=False, figures=True, progress=None, learn=None, threads=1):
    """gssm-process in this process: runs estimators over a dataset folder and
    writes estimates-<method>.csv, metrics.json and (figures=True) the ``fig-*.png``
    into `out`, the same files gssm-process writes. Returns a gssm.ProcessResult
    (its runs, metrics.json's text, the files written; partial and stopped_at
    when a bad row stopped it, after what came before was processed).

    method: "all" (with resume=: the checkpoint's), a gssm.Method or its
    name, or a list of them. config: an INI file instead of the folder's
    scenario.ini. window: fixed-lag and paper-window states. checkpoint_every,
    resume: as gssm-process's --checkpoint-every, --resume. learn: True to
    learn the noise first (gssm-process --learn), False not to, None as the
    INI's [learn] enabled says. threads: methods run at the same time, and
    figures drawn (gssm-process --threads; the same output). progress: a
    callable(method, done, total), called from the loop (from the method's
    thread, one call at a time). Errors are gssm.Error
    subclasses naming file, line and column, as gssm-process prints them.
    """
    if isinstance(method, str) and method == "all":
        methods = []
    elif isinstance(method, (list, tuple)):
        methods = [method_of(m) for m in method]
    else:
        methods = [method_of(method)]
    result = _gssm.process_dataset(str(data), str(out), methods, str(config or ""), window,
                                   int(checkpoint_every or 0), str(resume or ""), bool(skip_bad_rows), progress,
                                   learn, int(threads))
    if figures:
        try:
            from . import _plot
        except ImportError as e:
            raise Error("gssm.process: figures need the gssm._plot extension (built with the apps, "
                        "GSSM_BUILD_APPS=ON); pass figures=False (%s)" % e) from e
        result._add_files(_plot.write_process_figures(result, str(out), int(threads)))
    return result


def _restore_pickled(model, data):
    """Unpickles an Estimator (pickled as its model and a checkpoint)."""
    return _gssm.restore_bytes(model, data)
