"""Type stubs of the compiled module `gmwm._native` (PyO3). Every function returns the engine's
JSON document as text (the CLI's --json) unless stated; `gmwm/__init__.py` wraps them."""

from typing import Callable, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]
Progress = Optional[Callable[[int, int], object]]

class GmwmError(ValueError):
    """An input or computation the engine refuses; the message names what is wrong."""

def wv(arrays: Sequence[F64], names: Sequence[str], freq: float, robust: bool = ..., eff: float = ...,
       robust_convention: str = ..., filter: str = ..., transform: str = ..., levels: Optional[int] = ...,
       alpha: float = ...) -> str:
    """Wavelet variance of each column (docs/methods.md §1, §2)."""

def avar(arrays: Sequence[F64], names: Sequence[str], freq: float, kind: str = ..., convention: str = ...,
         alpha: float = ...) -> str:
    """Allan, modified Allan or Hadamard variance of each column (docs/methods.md §3)."""

def implied(model: str, levels: int, freq: float = ...) -> str:
    """Implied WV of a fully specified model and of each process (docs/methods.md §4)."""

def simulate(model: str, n: int, freq: float = ..., seed: int = ..., components: bool = ...) -> Tuple[F64, List[Tuple[str, F64]]]:
    """Seeded simulation (docs/methods.md §10): the series and, with components, each process."""

def fit(arrays: Sequence[F64], names: Sequence[str], freq: float, model: str, weights: str = ...,
        draws: Optional[int] = ..., seed: int = ..., inference: bool = ..., bootstrap: Optional[int] = ...,
        covariance: str = ..., robust: bool = ..., eff: float = ..., robust_convention: str = ..., levels: Optional[int] = ...,
        alpha: float = ..., progress: Progress = ..., augment: Optional[str] = ...) -> str:
    """GMWM fit of `model` on each column (docs/methods.md §5, §7; GMWM+ with `augment`, §5.15)."""

def select(arrays: Sequence[F64], names: Sequence[str], freq: float, model: Optional[str] = ...,
           candidates: Optional[Sequence[str]] = ..., bootstrap: int = ..., covariance: str = ...,
           optimism: str = ...,
           convention: str = ..., rule: str = ..., draws: Optional[int] = ..., seed: int = ...,
           robust: bool = ..., eff: float = ..., robust_convention: str = ..., levels: Optional[int] = ...,
           alpha: float = ..., progress: Progress = ...) -> str:
    """WIC model selection on each column (docs/methods.md §8)."""

def read(path: str, columns: Optional[Sequence[str]] = ..., freq: Optional[float] = ..., format: str = ...,
         ncols: Optional[int] = ..., header: str = ..., time_column: Optional[str] = ...,
         time_unit: Optional[str] = ..., time_policy: str = ..., topic: Optional[str] = ...
         ) -> Tuple[List[str], List[F64], Optional[float], List[Optional[str]], List[str]]:
    """A recording's columns as the CLI reads them: names, arrays, rate, units, notes."""

def calibrate(path: Optional[str] = ..., arrays: Optional[Sequence[F64]] = ...,
              paths: Optional[Sequence[str]] = ..., names: Optional[Sequence[str]] = ...,
              units: Optional[Sequence[Optional[str]]] = ..., freq: Optional[float] = ...,
              columns: Optional[Sequence[str]] = ..., format: str = ..., ncols: Optional[int] = ...,
              header: str = ..., time_column: Optional[str] = ..., time_unit: Optional[str] = ..., time_policy: str = ...,
              topic: Optional[str] = ..., gyro_unit: Optional[str] = ..., accel_unit: Optional[str] = ...,
              model: Optional[str] = ..., rule: str = ..., bootstrap: int = ..., covariance: str = ...,
              draws: Optional[int] = ...,
              seed: int = ..., eff: float = ..., robust_convention: str = ..., robust: bool = ...,
              alpha: float = ..., axis_policy: str = ..., inflate: Optional[float] = ...,
              conservative: bool = ..., horizon: Optional[float] = ...,
              rostopic: Optional[str] = ..., progress: Progress = ...) -> str:
    """The calibration pipeline of `gmwm calibrate` on a recording, on arrays, or on several
    recordings of one sensor (`paths`: `gmwm calibrate --pool`)."""

def copies() -> int:
    """Columns copied so far because they were not contiguous float64."""

def version() -> str:
    """The engine's version."""
