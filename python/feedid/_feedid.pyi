"""Stubs of the native module (the public API is in feedid/__init__.py)."""

from typing import Any, Dict, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

_Row = Tuple[float, float, float, float]

class Recording:
    """A checked recording: time [s], command [m], position [m]."""

    def __init__(
        self,
        time: npt.NDArray[np.float64],
        command: npt.NDArray[np.float64],
        position: npt.NDArray[np.float64],
        *,
        jitter_tol: float = 0.01,
        allow_gaps: bool = False,
    ) -> None: ...
    @property
    def gaps(self) -> List[Tuple[int, int]]:
        """Gaps of dropped samples as (index of the first sample after it, samples missing)."""
    @property
    def time(self) -> npt.NDArray[np.float64]:
        """Sample times [s] (read-only view)."""
    @property
    def command(self) -> npt.NDArray[np.float64]:
        """Position command [m] (read-only view)."""
    @property
    def position(self) -> npt.NDArray[np.float64]:
        """Measured position [m] (read-only view)."""
    @property
    def channels(self) -> Dict[str, npt.NDArray[np.float64]]:
        """Further channels (a simulation's true_position [m], current [A], velocity [m/s])."""
    @property
    def dt(self) -> float:
        """Mean sampling interval [s]."""
    @property
    def rate_hz(self) -> float:
        """Mean sampling rate [Hz]."""
    @property
    def duration(self) -> float:
        """Duration [s]."""
    @property
    def notes(self) -> List[str]: ...
    def __getattr__(self, name: str) -> npt.NDArray[np.float64]: ...
    def __len__(self) -> int: ...

class OnlineCompensator:
    def __init__(
        self,
        *,
        rate: float,
        command_lead: int,
        replay: bool = False,
        max_velocity: float = 1.0,
        max_acceleration: float = 30.0,
        model_json: Optional[str] = None,
        model_path: Optional[str] = None,
    ) -> None: ...
    def push(self, t: float, u: float, y: float) -> Optional[Tuple[float, float, float]]: ...
    def push_many(
        self,
        t: npt.NDArray[np.float64],
        u: npt.NDArray[np.float64],
        y: npt.NDArray[np.float64],
    ) -> List[Tuple[float, float, float]]: ...
    @property
    def stats(self) -> Dict[str, Any]: ...

class Streamer:
    def __init__(
        self,
        *,
        rate: Optional[float] = None,
        method: str = "auto",
        window: Optional[int] = None,
        horizon: int = 10,
        hop: Optional[int] = None,
        command_lead: int = 0,
        extrapolate: Optional[str] = None,
        jitter_tol: float = 0.01,
        interval: float = 95.0,
        runaway: Optional[float] = 1.5,
        # method options: generated from the library's option descriptions (FEEDID_UPDATE_STUBS=1 cargo test -p feedid-cli --test options)
        solver: Optional[str] = None,
        time_origin: Optional[str] = None,
        prediction: Optional[str] = None,
        simplex_start: Optional[str] = None,
        order: Optional[str] = None,
        ridge: Optional[float] = None,
        lambda_: Optional[float] = None,
        hidden: Optional[int] = None,
        train_samples: Optional[int] = None,
        epochs: Optional[int] = None,
        learning_rate: Optional[float] = None,
        online_steps: Optional[int] = None,
        nn_seed: Optional[int] = None,
        # end of method options
    ) -> None: ...
    def push(self, t: float, u: float, y: float) -> List[_Row]: ...
    def push_many(
        self,
        t: npt.NDArray[np.float64],
        u: npt.NDArray[np.float64],
        y: npt.NDArray[np.float64],
    ) -> List[_Row]: ...
    def finish(self) -> List[_Row]: ...
    @property
    def stats(self) -> Dict[str, Any]: ...
    @property
    def dt(self) -> Optional[float]: ...

def method_options() -> List[Dict[str, Any]]: ...
def methods() -> List[Dict[str, Any]]: ...

def read(
    path: str,
    *,
    time: Optional[str] = None,
    command: Optional[str] = None,
    position: Optional[str] = None,
    rate: Optional[float] = None,
    delimiter: Optional[str] = None,
    header: Optional[bool] = None,
    unit: str = "m",
    scale: Optional[float] = None,
    time_unit: str = "s",
    jitter_tol: float = 0.01,
    allow_gaps: bool = False,
) -> Recording: ...
def identify(
    recording: Optional[Recording] = None,
    *,
    time: Optional[npt.NDArray[np.float64]] = None,
    command: Optional[npt.NDArray[np.float64]] = None,
    position: Optional[npt.NDArray[np.float64]] = None,
    jitter_tol: float = 0.01,
    method: str = "auto",
    window: Optional[int] = None,
    horizon: int = 10,
    hop: Optional[int] = None,
    interval: float = 95.0,
    runaway: Optional[float] = 1.5,
    params_path: Optional[str] = None,
    params_json: Optional[str] = None,
    allow_unstable: bool = False,
    nominal: bool = True,
    global_model: bool = True,
    residuals: bool = True,
    # method options: generated from the library's option descriptions (FEEDID_UPDATE_STUBS=1 cargo test -p feedid-cli --test options)
    solver: Optional[str] = None,
    time_origin: Optional[str] = None,
    prediction: Optional[str] = None,
    simplex_start: Optional[str] = None,
    order: Optional[str] = None,
    ridge: Optional[float] = None,
    lambda_: Optional[float] = None,
    hidden: Optional[int] = None,
    train_samples: Optional[int] = None,
    epochs: Optional[int] = None,
    learning_rate: Optional[float] = None,
    online_steps: Optional[int] = None,
    nn_seed: Optional[int] = None,
    # end of method options
) -> Dict[str, Any]: ...
def simulate(
    scenario: str,
    *,
    seed: int = 0,
    duration: Optional[float] = None,
    rate: float = 5000.0,
    params_path: Optional[str] = None,
    params_json: Optional[str] = None,
    linear: bool = False,
    effects: Optional[str] = None,
    allow_unstable: bool = False,
) -> Recording: ...
def model(
    *, params_path: Optional[str] = None, params_json: Optional[str] = None, d1: str = "corrected"
) -> str: ...
def compensate(
    time: npt.NDArray[np.float64],
    desired: npt.NDArray[np.float64],
    *,
    model_json: Optional[str] = None,
    model_path: Optional[str] = None,
    params_path: Optional[str] = None,
    params_json: Optional[str] = None,
    position_loop: str = "sampled",
    smooth: Optional[float] = None,
    max_smoothing: float = 0.02,
    max_velocity: float = 1.0,
    max_acceleration: float = 30.0,
    keep_dc_gain: bool = False,
    allow_unstable: bool = False,
    start: str = "rest",
    min_benefit: float = 1.25,
    min_fit: float = 90.0,
    fallback: bool = True,
    check: Optional[Recording] = None,
    check2: Optional[Recording] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], str]: ...

def learn(
    time: npt.NDArray[np.float64],
    desired: npt.NDArray[np.float64],
    sent: npt.NDArray[np.float64],
    measured: npt.NDArray[np.float64],
    *,
    model_json: Optional[str] = None,
    model_path: Optional[str] = None,
    history_json: Optional[str] = None,
    gain: float = 1.0,
    noise_filter: Optional[float] = None,
    smooth: Optional[float] = None,
    max_smoothing: float = 0.02,
    max_velocity: float = 1.0,
    max_acceleration: float = 30.0,
    keep_dc_gain: bool = False,
    start: str = "rest",
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], str, str]: ...
def structure_model(path: str) -> str: ...
def structure_simulate(
    path: str,
    command: npt.NDArray[np.float64],
    rate: float,
    *,
    initial_position: Optional[float] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def structure_fit(
    path: str,
    command: npt.NDArray[np.float64],
    position: npt.NDArray[np.float64],
    rate: float,
    estimate: List[str],
    *,
    restarts: int = 2,
) -> Tuple[str, str]: ...
def structure_tune(path: str, bandwidth: float, damping: float) -> Tuple[str, str]: ...
