# Type stubs of the gssm package (checked against the module by
# python/tests/test_stubs.py).
from typing import Callable, Dict, List, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

from . import analysis as analysis
from . import io as io
from . import models as models
from .io import Dataset
from .models import Model

ArrayLike = npt.ArrayLike
Vector = npt.NDArray[np.float64]
Matrix = npt.NDArray[np.float64]

class Error(RuntimeError): ...
class InvalidArgument(Error): ...
class InputError(Error): ...
class NumericalError(Error): ...
class CheckpointError(Error): ...

class EkfOptions:
    constant_process_noise: Vector
    joseph_form: bool
    def __init__(self) -> None: ...

class SmootherOptions:
    relinearize: bool
    relinearize_threshold: float
    constants_check_sigmas: float
    full_pass_growth: float
    full_pass_rounds: int
    max_local_iterations: int
    wildfire_threshold: float
    iterate_to_convergence: bool
    convergence_tolerance: float
    max_iterations: int
    newton_polish_steps: int
    def __init__(self) -> None: ...

class BatchOptions:
    algorithm: str
    max_iterations: int
    relative_cost_tolerance: float
    step_tolerance: float
    gradient_tolerance: float
    decrease_tolerance: float
    initial_lambda: float
    max_lambda: float
    newton_polish_steps: int
    covariance_by_qr: bool
    anderson_memory: int
    def __init__(self) -> None: ...

class EstimatorOptions:
    method: str
    t0: float
    compute_nis: bool
    drop_late: bool
    ekf: EkfOptions
    smoother: SmootherOptions
    batch: BatchOptions
    ordering: str
    fixed_lag_window: int
    fixed_lag_constants_check_sigmas: float
    paper_window_window: int
    @property
    def window(self) -> int: ...
    def __init__(self, method: str = "fixed-lag") -> None: ...
    def validate(self, model: Model) -> None: ...

class StateEstimate:
    @property
    def t(self) -> float: ...
    @property
    def step(self) -> int: ...
    @property
    def mean(self) -> Vector: ...
    @property
    def covariance(self) -> Matrix: ...
    @property
    def sd(self) -> Vector: ...

class UpdateReport:
    new_factors: int
    new_variables: int
    cliques_reeliminated: int
    orphans: int
    factors_checked: int
    factors_relinearized: int
    relinearization_pass: bool
    iterations: int
    variables_backsubstituted: int
    variables_marginalized: int
    num_variables: int
    num_factors: int
    num_cliques: int
    seconds: float
    note: str

class EstimatorReport:
    method: str
    window: int
    ordering: Optional[str]
    measurements: int
    late: int
    late_dropped: int
    seconds: float
    iterations: int
    rejected: int
    smoother: UpdateReport
    detail: str
    nis: float
    def to_dict(self) -> Dict[str, object]: ...

class Estimator:
    @property
    def method(self) -> str: ...
    @property
    def model(self) -> Model: ...
    @property
    def options(self) -> EstimatorOptions: ...
    @property
    def time(self) -> float: ...
    @property
    def step(self) -> int: ...
    def add_input(self, t: float, u: ArrayLike) -> None: ...
    def add_measurement(self, t: float, y: ArrayLike, channel: Union[str, int, None] = None,
                        R: Optional[ArrayLike] = None, regressors: Optional[ArrayLike] = None) -> None: ...
    def current(self) -> StateEstimate: ...
    def smoothed(self, k: int) -> Optional[StateEstimate]: ...
    def marginal_covariance(self, states: Sequence[int] = ..., constants: bool = True) -> Optional[Matrix]: ...
    def report(self) -> EstimatorReport: ...
    def to_bytes(self, user_data: bytes = b"") -> bytes: ...
    def save(self, path: str, user_data: bytes = b"") -> None: ...

class Run:
    @property
    def method(self) -> str: ...
    @property
    def names(self) -> List[str]: ...
    @property
    def t(self) -> Vector: ...
    @property
    def mean(self) -> Matrix: ...
    @property
    def sd(self) -> Matrix: ...
    @property
    def covariance(self) -> npt.NDArray[np.float64]: ...
    @property
    def nis(self) -> Vector: ...
    @property
    def update_seconds(self) -> Vector: ...
    @property
    def total_seconds(self) -> float: ...
    @property
    def iterations(self) -> int: ...
    @property
    def summary(self) -> str: ...
    @property
    def downweighted(self) -> int: ...
    @property
    def rejected(self) -> int: ...
    def __len__(self) -> int: ...

def methods(streaming_only: bool = False) -> List[str]: ...
class Method:
    EKF: Method
    BATCH: Method
    INCREMENTAL: Method
    FIXED_LAG: Method
    PAPER_WINDOW: Method
    name: str
    value: int
    @property
    def text(self) -> str: ...
    @property
    def label(self) -> str: ...
    @property
    def streaming(self) -> bool: ...
    @staticmethod
    def named(text: str) -> Method: ...

class ProcessResult:
    @property
    def runs(self) -> List[Run]: ...
    @property
    def methods(self) -> List[Method]: ...
    @property
    def model(self) -> Model: ...
    @property
    def metrics_json(self) -> str: ...
    @property
    def files(self) -> List[str]: ...
    @property
    def label(self) -> str: ...
    @property
    def partial(self) -> bool: ...
    @property
    def stopped_at(self) -> str: ...
    @property
    def skipped(self) -> List[str]: ...
    @property
    def learnt(self) -> Optional[LearnReport]: ...
    @property
    def learnt_batch(self) -> Optional[LearnReport]: ...

class LearntParameter:
    name: str
    section: str
    key: str
    index: int
    given: float
    start: float
    value: float
    standard_error: float
    identifiable: bool
    note: str
    method: str

class LearnReport:
    parameters: List[LearntParameter]
    log_likelihood: Vector
    given_log_likelihood: float
    start_log_likelihood: float
    final_log_likelihood: float
    evaluations: int
    optimizer: str
    iterations: int
    restarts: int
    converged: bool
    prior_iterations: int
    prior_converged: bool
    seconds: float
    model: Model
    params: Dict[str, object]

MethodLike = Union[str, Method]

def make_options(method: MethodLike = "fixed-lag", *, options: Optional[EstimatorOptions] = None,
                 window: Optional[int] = None, ordering: Optional[str] = None, t0: Optional[float] = None,
                 compute_nis: Optional[bool] = None, ekf: Optional[Dict[str, object]] = None,
                 smoother: Optional[Dict[str, object]] = None,
                 batch: Optional[Dict[str, object]] = None) -> EstimatorOptions: ...
def make_estimator(model: Model, method: MethodLike = "fixed-lag", *, options: Optional[EstimatorOptions] = None,
                   window: Optional[int] = None, ordering: Optional[str] = None, t0: Optional[float] = None,
                   compute_nis: Optional[bool] = None, ekf: Optional[Dict[str, object]] = None,
                   smoother: Optional[Dict[str, object]] = None,
                   batch: Optional[Dict[str, object]] = None) -> Estimator: ...
def run(model: Model, data: Dataset, method: MethodLike = "fixed-lag", *, options: Optional[EstimatorOptions] = None,
        rows_at_inputs: Optional[bool] = None, progress: Optional[Callable[[int, int], None]] = None,
        window: Optional[int] = None, ordering: Optional[str] = None, t0: Optional[float] = None,
        compute_nis: Optional[bool] = None, ekf: Optional[Dict[str, object]] = None,
        smoother: Optional[Dict[str, object]] = None, batch: Optional[Dict[str, object]] = None) -> Run: ...
def process(data: str, out: str, *, method: Union[MethodLike, Sequence[MethodLike]] = "all",
            config: Optional[str] = None, window: Optional[int] = None, checkpoint_every: Optional[int] = None,
            resume: Optional[str] = None, skip_bad_rows: bool = False, figures: bool = True,
            progress: Optional[Callable[[Method, int, int], None]] = None,
            learn: Optional[bool] = None, threads: int = 1) -> ProcessResult: ...
@overload
def learn(model_or_folder: Model, data: Dataset, *, parameters: Optional[Sequence[str]] = None,
          start: float = 0.0, search_range: float = 1e4, max_evaluations: int = 4000, tolerance: float = 1e-7,
          max_restarts: int = 6, standard_errors: bool = True, optimizer: str = "nelder-mead",
          threads: int = 1) -> LearnReport: ...
@overload
def learn(model_or_folder: str, *, out: str, config: Optional[str] = None) -> LearnReport: ...
@overload
def learn(model_or_folder: Callable[..., Model], data: Dataset, *, sigmas: Dict[str, float], start: float = 0.0,
          search_range: float = 1e4, max_evaluations: int = 4000, tolerance: float = 1e-7, max_restarts: int = 6,
          standard_errors: bool = True, optimizer: str = "nelder-mead") -> LearnReport: ...
def restore(model: Model, source: Union[bytes, bytearray, memoryview, str]) -> Estimator: ...
def checkpoint_info(model: Model, data: bytes) -> Dict[str, object]: ...
def simulate(scenario: Union[str, Model] = "paper", seed: int = 1, steps: int = 400, *,
             x0: Optional[ArrayLike] = None, xb: Optional[ArrayLike] = None, measure_every: int = 1,
             channels: Sequence[Union[str, int]] = ...) -> Dataset: ...
