"""Type stubs of the compiled extension (python/src/*.rs)."""

from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

__version__: str
SIMULATE_COLUMNS: str
STRIBECK_COLUMNS: str
LOOP_METRIC_COLUMNS: str

class Estimate:
    """One step's estimate (the fields of friction_msgs/FrictionEstimate), SI units."""

    time_s: float
    velocity_m_s: float
    load_n: float
    friction_force_n: float
    contact_friction_force_n: float
    cof: float  # contact friction per unit load: rigid (|F_visc| + (mu_bl + mu_r asinh(|v|/v_a)) F_asp) / F_ext; with pre-sliding |F_c| / F_ext; drivetrain terms excluded
    h0_m: float
    h_min_m: float
    hydrodynamic_force_n: float
    asperity_force_n: float
    asperity_load_share: float
    viscous_force_n: float
    max_pressure_pa: float
    residual: float
    iterations: int
    substeps: int
    status: str
    regime: str
    calibrated_range: str

class Model:
    def __init__(
        self, yaml: Optional[str] = None, path: Optional[str] = None, overrides: Sequence[str] = ...
    ) -> None: ...
    @property
    def dt(self) -> float: ...
    @property
    def load_n(self) -> float: ...
    def config_yaml(self) -> str: ...
    def step(self, velocity: float, load: Optional[float] = None, dt: Optional[float] = None) -> Estimate: ...
    def reset(self, velocity: float = 0.0, load: Optional[float] = None) -> Estimate: ...
    def set_parameter(self, key: str, value: Any) -> None: ...
    def set_temperature(self, temperature_c: float) -> None: ...
    def run(
        self,
        t: npt.NDArray[np.float64],
        velocity: npt.NDArray[np.float64],
        load: Optional[npt.NDArray[np.float64]] = None,
        temperature: Optional[npt.NDArray[np.float64]] = None,
    ) -> Dict[str, Any]: ...

def default_config_yaml() -> str: ...
def stribeck(
    velocities: npt.NDArray[np.float64],
    load: Optional[float] = None,
    yaml: Optional[str] = None,
    path: Optional[str] = None,
    overrides: Sequence[str] = ...,
) -> Dict[str, Any]: ...
def replay(
    bag: str,
    config_path: Optional[str] = None,
    overrides: Sequence[str] = ...,
    topic: Optional[str] = None,
    joint: Optional[str] = None,
    load_topic: Optional[str] = None,
    temperature_topic: Optional[str] = None,
    velocity_map: Optional[str] = None,
    load_map: Optional[str] = None,
    out: Optional[str] = None,
    report_dir: Optional[str] = None,
) -> Dict[str, Any]: ...
def fit(
    data: Sequence[str],
    keys: Sequence[str],
    config_path: Optional[str] = None,
    overrides: Sequence[str] = ...,
    bounds: Sequence[Tuple[str, float, float]] = ...,
    starts_at: Sequence[Tuple[str, float]] = ...,
    holdout: float = 0.0,
    validate: Sequence[str] = ...,
    baselines: bool = False,
    starts: int = 3,
    global_points: int = 16,
    seed: int = 1,
    max_evaluations: int = 200,
    columns: Optional[List[str]] = None,
    skip: int = 0,
    delimiter: str = "auto",
    time: Optional[str] = None,
    velocity: str = "velocity_m_s",
    friction: str = "friction_n",
    load: Optional[str] = None,
    temperature: Optional[str] = None,
    smooth: float = 0.05,
    map: Sequence[Tuple[str, float]] = ...,
    velocity_topic: Optional[str] = None,
    friction_topic: Optional[str] = None,
    joint: Optional[str] = None,
    load_topic: Optional[str] = None,
    temperature_topic: Optional[str] = None,
    out: Optional[str] = None,
    report_dir: Optional[str] = None,
    progress: bool = False,
    rotary: bool = False,
    jacobian: str = "secant",
    later_runs: str = "full",
    linear_keys: str = "solved",
    cheap_keys: str = "profiled",
) -> Dict[str, Any]: ...
