"""Models: every registered model type (Radar2D, Nav2D, RangeBeacon2D,
Linear, and any a C++ library registers) as a class whose keywords are the
type's parameters, the same keys as its INI form ([model] key, [prior] key as
prior_key); PythonModel for models written in Python.

The parameters, their defaults and their checks live in C++ (one
registration per model type, docs/DESIGN.md §3 "Adding a model"): a keyword
left out keeps the C++ default, and `model.params` gives every value used.
"""
import numpy as _np

from . import _gssm

Model = _gssm.models.Model
Channel = _gssm.models.Channel
from_ini = _gssm.models.from_ini


class _RegisteredType(type):
    """The class of a registered model type: calling it builds the model in
    C++ (an instance of Model); isinstance asks the registry."""

    def __call__(cls, **params):
        return _gssm.models._make(cls._type_name, params)

    def __instancecheck__(cls, obj):
        return isinstance(obj, Model) and _gssm.models._type_of(obj) == cls._type_name


def _type_doc(info):
    lines = [info["summary"], "", "Keywords (absent: the C++ default; see .params):"]
    for p in info["params"]:
        need = ", required" if p["required"] else ""
        lines.append("    %s (%s%s): %s  [INI: [%s] %s]" % (p["name"], p["kind"], need, p["doc"], p["section"], p["key"]))
    return "\n".join(lines)


def _registered_class(info):
    return _RegisteredType(info["class_name"], (), {"_type_name": info["name"], "__doc__": _type_doc(info),
                                                    "__module__": __name__})


def registered_types():
    """Every registered model type, as dicts: name, aliases, class_name,
    summary and params (name, section, key, kind, required, doc)."""
    return _gssm.models._types()


_CLASSES = {}


def _refresh():
    for info in registered_types():
        if info["class_name"] not in _CLASSES:
            _CLASSES[info["class_name"]] = _registered_class(info)
    return _CLASSES


globals().update(_refresh())


def __getattr__(name):
    """A model type registered after this module was imported (a C++
    extension that registers its own)."""
    classes = _refresh()
    if name in classes:
        globals()[name] = classes[name]
        return classes[name]
    raise AttributeError("module 'gssm.models' has no attribute %r" % name)


__all__ = ["Model", "Channel", *sorted(_CLASSES), "PythonModel", "from_ini", "registered_types"]


class PythonModel(_gssm.models._FunctionModel):
    """A model written in Python, driving every estimator.

    f(xc, xb, u, dt) -> x_c at the next step (n_c,)
    h(xc, xb)        -> y (n_y,) (a float for n_y = 1)
    jacobian_f(xc, xb, u, dt) -> (J_f_xc (n_c, n_c), J_f_xb (n_c, n_b)), optional
    jacobian_h(xc, xb)        -> (J_h_xc (n_y, n_c), J_h_xb (n_y, n_b)), optional
    Without a Jacobian, central differences of the function are used.

    nc, nb, nu, ny: sizes of x_c, x_b, u, y. Q: process noise of one nominal
    step T; R: measurement noise. prior_state, prior_constants: (mean,
    covariance) pairs (default zero mean, identity). verify_jacobians checks
    the analytic Jacobians against differences on the first calls.
    Pickles when its functions do (module-level functions; cloudpickle, as
    Dask uses, also takes lambdas).
    """

    def __init__(self, f, h, *, nc, ny, Q, R, nb=0, nu=0, T=1.0, prior_state=None,
                 prior_constants=None, jacobian_f=None, jacobian_h=None, name="user",
                 state_names=(), constant_names=(), input_names=(), measurement_names=(),
                 verify_jacobians=False):
        self._init_args = dict(f=f, h=h, nc=nc, ny=ny, Q=Q, R=R, nb=nb, nu=nu, T=T,
                               prior_state=prior_state, prior_constants=prior_constants,
                               jacobian_f=jacobian_f, jacobian_h=jacobian_h, name=name,
                               state_names=tuple(state_names), constant_names=tuple(constant_names),
                               input_names=tuple(input_names), measurement_names=tuple(measurement_names),
                               verify_jacobians=verify_jacobians)
        ps = prior_state if prior_state is not None else (None, None)
        pb = prior_constants if prior_constants is not None else (None, None)
        _gssm.models._FunctionModel.__init__(
            self, nc, nb, nu, ny, f, h, _np.atleast_2d(_np.asarray(Q, dtype=float)),
            _np.atleast_2d(_np.asarray(R, dtype=float)), float(T), ps[0], ps[1], pb[0], pb[1],
            jacobian_f, jacobian_h, name, list(state_names), list(constant_names), list(input_names),
            list(measurement_names), verify_jacobians)

    def __reduce__(self):
        return (_rebuild_python_model, (self._init_args,))


def _rebuild_python_model(args):
    args = dict(args)
    return PythonModel(args.pop("f"), args.pop("h"), **args)


def _from_ini_pickled(text):
    """Unpickles a registered model (pickled through its INI form)."""
    return from_ini(text)
