"""EstimatorOptions from keyword arguments (make_estimator, run)."""
from . import _gssm


def method_of(method):
    """A gssm.Method from itself or its name ("fixed-lag")."""
    if isinstance(method, _gssm.Method):
        return method
    return _gssm.Method.named(str(method))


def make_options(method="fixed-lag", *, options=None, window=None, ordering=None, t0=None,
                 compute_nis=None, ekf=None, smoother=None, batch=None):
    """An EstimatorOptions for `method`.

    options: a starting point (copied; default: the C++ defaults).
    window: the states kept by the window methods (fixed-lag, paper-window).
    ordering: the incremental smoother's elimination ordering, "colamd" or "time".
    t0: time of x_c(0). compute_nis: the NIS of every measurement.
    ekf, smoother, batch: dicts of fields of EkfOptions, SmootherOptions,
    BatchOptions (e.g. smoother={"relinearize_threshold": 1e-3}).
    Unknown names raise gssm.InvalidArgument.
    """
    m = method_of(method)
    if options is None:
        o = _gssm.EstimatorOptions(m.text)
    else:
        import copy
        o = copy.deepcopy(options)
        o.method = m.text
    if window is not None:
        if m == _gssm.Method.PAPER_WINDOW:
            o.paper_window_window = int(window)
        elif m == _gssm.Method.FIXED_LAG:
            o.fixed_lag_window = int(window)
        else:
            raise _gssm.InvalidArgument("window= is a setting of fixed-lag and paper-window, not of '%s'" % m.text)
    if ordering is not None:
        o.ordering = ordering
    if t0 is not None:
        o.t0 = float(t0)
    if compute_nis is not None:
        o.compute_nis = bool(compute_nis)
    for name, fields in (("ekf", ekf), ("smoother", smoother), ("batch", batch)):
        if fields is None:
            continue
        group = getattr(o, name)
        for key, value in dict(fields).items():
            if key.startswith("_") or not hasattr(group, key):
                public = sorted(k for k in dir(group) if not k.startswith("_"))
                raise _gssm.InvalidArgument("%s option '%s' does not exist; expected one of %s"
                                            % (name, key, ", ".join(public)))
            setattr(group, key, value)
        setattr(o, name, group)
    return o
