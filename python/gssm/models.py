"""Models: the built-in ones (the C++ defaults as keyword defaults), the
linear model from matrices, and PythonModel for models written in Python."""
import numpy as _np

from . import _gssm

Model = _gssm.models.Model
Channel = _gssm.models.Channel
Radar2D = _gssm.models.Radar2D
Nav2D = _gssm.models.Nav2D
RangeBeacon2D = _gssm.models.RangeBeacon2D
Linear = _gssm.models.Linear
from_ini = _gssm.models.from_ini

__all__ = ["Model", "Channel", "Radar2D", "Nav2D", "RangeBeacon2D", "Linear", "PythonModel", "from_ini"]


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
    """Unpickles a built-in model (pickled through its INI form)."""
    return from_ini(text)
