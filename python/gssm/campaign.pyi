from typing import Callable, Dict, List, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

Vector = npt.NDArray[np.float64]
Matrix = npt.NDArray[np.float64]

class SeedResult:
    @property
    def seed(self) -> int: ...
    @property
    def times(self) -> Vector: ...
    @property
    def methods(self) -> List[str]: ...
    def rmse(self, method: Union[str, object]) -> Optional[Vector]: ...
    def error(self, method: Union[str, object]) -> str: ...

class MethodSummary:
    @property
    def method(self) -> str: ...
    mean_rmse: Vector
    rms_final_error: Vector
    mean_nees: float
    nees_step_in_interval: float
    beats_ekf: Vector
    @property
    def times(self) -> Vector: ...
    @property
    def rmse_over_time(self) -> Matrix: ...
    consistency: str
    mean_nis: float
    nis_consistency: str
    nis_step_in_interval: float
    failures: int
    first_failure: str

class MonteCarloResult:
    scenario: str
    seeds: int
    steps: int
    dof: int
    nees_lo: float
    nees_hi: float
    nis_dof: int
    nis_lo: float
    nis_hi: float
    state_names: List[str]
    methods: List[MethodSummary]
    seconds: float
    def markdown(self) -> str: ...

class Scenario:
    def __init__(self, scenario_ini: str, estimator_ini: str = "", methods: Sequence[str] = ...,
                 window: int = 0) -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def methods(self) -> List[str]: ...
    @property
    def steps(self) -> int: ...
    def run_seed(self, seed: int) -> SeedResult: ...
    def summarize(self, results: Sequence[SeedResult]) -> MonteCarloResult: ...
    def run_local(self, seeds: int, first_seed: int = 1, threads: int = 1) -> MonteCarloResult: ...

def local_cluster(workers: Optional[int] = None, threads_per_worker: int = 1) -> object: ...
def monte_carlo(scenarios: Union[str, Scenario, Sequence[Union[str, Scenario]]] = "paper", seeds: int = 100, *,
                first_seed: int = 1, steps: int = 400, methods: Optional[Sequence[str]] = None,
                window: Optional[int] = None, estimator_config: Optional[str] = None, client: object = None,
                workers: Optional[int] = None, retries: int = 3, progress: bool = True,
                on_result: Optional[Callable[[str, SeedResult], None]] = None
                ) -> Union[MonteCarloResult, Dict[str, MonteCarloResult]]: ...
def save_monte_carlo(result: MonteCarloResult, out: str, command: Optional[str] = None) -> List[str]: ...
def process_folder(folder: str, out: str, *, method: Union[str, object] = "all", window: Optional[int] = None,
                   config: Optional[str] = None, skip_bad_rows: bool = False, figures: bool = True,
                   client: object = None, workers: Optional[int] = None, retries: int = 3,
                   progress: bool = True) -> Dict[str, Dict[str, object]]: ...
