"""gmwm: stochastic error calibration of inertial sensors with the Generalized Method of
Wavelet Moments, on a Rust engine.

The verbs are the CLI's, with keyword options named as its flags::

    import gmwm
    wv = gmwm.wv("imu.csv.gz")                       # docs/methods.md §1: every sensor column
    fit = gmwm.fit(x, freq=100, model="2*AR1()+WN()+RW()")
    cal = gmwm.calibrate("run.bag", gyro_unit=None)  # the pipeline of `gmwm calibrate`
    cal.to_dataframe()                               # N, B, K per axis with intervals

Data are a path (every format the CLI reads: CSV/TSV, .gz, raw binary, binary IMU records,
ROS1 bags, MCAP, rosbag2), a numpy array (1-D, or 2-D with samples along the longer axis), a
pandas ``DataFrame`` or a ``{name: array}`` mapping. Contiguous float64 columns are used
without a copy; the GIL is released while the engine works; ``progress=callable(done, total)``
reports long work. Every result's ``to_dict()`` is the CLI's ``--json`` for the same call.
Errors the engine refuses raise :class:`GmwmError` (a ``ValueError``) with its message.
"""

from __future__ import annotations

import json
import os
import warnings
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native
from ._native import GmwmError
from ._results import (
    CalibrationResult,
    FitResult,
    Implied,
    Recording,
    SelectionResult,
    Series,
    SeriesResult,
)

__all__ = [
    "GmwmError",
    "wv",
    "avar",
    "implied",
    "simulate",
    "fit",
    "select",
    "calibrate",
    "calibrate_pooled",
    "calibrate_many",
    "read",
    "Recording",
    "Series",
    "SeriesResult",
    "Implied",
    "FitResult",
    "SelectionResult",
    "CalibrationResult",
]

__version__ = _native.version()

Data = Union[str, "os.PathLike[str]", np.ndarray, Mapping[str, Any], Sequence[float]]
Progress = Optional[Callable[[int, int], Any]]

_READ_KEYS = (
    "columns",
    "format",
    "ncols",
    "header",
    "time_column",
    "time_unit",
    "time_policy",
    "topic",
)


def _column(values: Any, name: str) -> np.ndarray:
    """A 1-D float64 array: float64 as it is (no copy), other real dtypes converted."""
    a = np.asarray(values)
    if a.ndim != 1:
        raise GmwmError(f"column {name}: expected a 1-D array, got shape {a.shape}")
    if a.dtype == np.float64:
        return a
    if a.dtype.kind in "fiu":
        return a.astype(np.float64)
    raise GmwmError(f"column {name}: expected real numbers, got dtype {a.dtype}")


def _is_path(data: Any) -> bool:
    return isinstance(data, (str, os.PathLike))


def read(path: Union[str, "os.PathLike[str]"], *, freq: Optional[float] = None, **options) -> Recording:
    """Reads a recording as the CLI does: ``columns``, ``freq``, ``format`` (auto, csv, tsv,
    f64, f32, imar, ln200, ln200ig, ixsea, navchip-int, navchip-flt), ``ncols``, ``header``
    (auto, yes, no), ``time_column``, ``time_unit`` (s, ms, us, ns), ``time_policy`` (strict, sort,
    drop-duplicates: what a repeated or reordered stamp does), ``topic`` (ROS)."""
    unknown = set(options) - set(_READ_KEYS)
    if unknown:
        raise TypeError(f"read() got unexpected keyword(s): {', '.join(sorted(unknown))}")
    if isinstance(options.get("columns"), str):
        options["columns"] = [c.strip() for c in options["columns"].split(",")]
    if options.get("columns") is not None:
        options["columns"] = [str(c) for c in options["columns"]]
    names, arrays, file_freq, units, notes = _native.read(os.fspath(path), freq=freq, **options)
    return Recording(os.fspath(path), names, arrays, file_freq, units, notes)


def _columns(
    data: Data, freq: Optional[float], names: Optional[Sequence[str]], read_options: Dict[str, Any]
) -> Tuple[List[np.ndarray], List[str], float]:
    """The columns, their names and the rate of any accepted input."""
    if _is_path(data):
        rec = read(data, freq=freq, **read_options)
        rate = freq if freq is not None else rec.freq_hz
        if rate is None:
            warnings.warn(
                f"{os.fspath(data)}: no sampling rate (no freq, time column or JSON sidecar); "
                "using 1 Hz, so tau_s is in samples",
                stacklevel=3,
            )
            rate = 1.0
        return [rec.data[n] for n in rec.names], rec.names, float(rate)
    if read_options:
        raise TypeError(f"{', '.join(sorted(read_options))} apply to a file path, not to arrays")
    if freq is None:
        raise GmwmError("freq (Hz) is required for arrays")
    if hasattr(data, "columns") and hasattr(data, "to_numpy"):  # a pandas DataFrame
        cols = [str(c) for c in data.columns]
        arrays = [_column(data[c].to_numpy(), c) for c in data.columns]
        return arrays, list(names) if names is not None else cols, float(freq)
    if isinstance(data, Mapping):
        cols = [str(k) for k in data]
        return [_column(v, k) for k, v in zip(cols, data.values())], cols, float(freq)
    a = np.asarray(data)
    if a.ndim == 1:
        arrays = [_column(a, "x")]
    elif a.ndim == 2:
        # samples along the longer axis; a column is a view (contiguous in C order when the
        # array is columns x samples, in Fortran order when it is samples x columns)
        arrays = [_column(a[k], f"col{k + 1}") for k in range(a.shape[0])] if a.shape[0] < a.shape[1] else [
            _column(a[:, k], f"col{k + 1}") for k in range(a.shape[1])
        ]
    else:
        raise GmwmError(f"expected a 1-D or 2-D array, got shape {a.shape}")
    if names is None:
        names = ["x"] if a.ndim == 1 else [f"col{k + 1}" for k in range(len(arrays))]
    names = [str(n) for n in names]
    if len(names) != len(arrays):
        raise GmwmError(f"{len(arrays)} column(s) but {len(names)} name(s)")
    return arrays, names, float(freq)


def _split(options: Dict[str, Any]) -> Tuple[Dict[str, Any], Dict[str, Any]]:
    read_options = {k: options.pop(k) for k in list(options) if k in _READ_KEYS}
    return read_options, options


def wv(data: Data, *, freq: Optional[float] = None, names: Optional[Sequence[str]] = None, **options) -> SeriesResult:
    """Wavelet variance of each column with confidence intervals (docs/methods.md §1, §2):
    ``robust``, ``eff``, ``robust_convention``, ``filter``, ``transform``, ``levels``,
    ``alpha``."""
    read_options, options = _split(options)
    arrays, cols, rate = _columns(data, freq, names, read_options)
    return SeriesResult(json.loads(_native.wv(arrays, cols, rate, **options)))


def avar(data: Data, *, freq: Optional[float] = None, names: Optional[Sequence[str]] = None, **options) -> SeriesResult:
    """Allan, modified Allan or Hadamard variance of each column (docs/methods.md §3): ``kind``
    (overlapping, non-overlapping, modified, hadamard, hadamard-non-overlapping),
    ``convention`` (textbook, package), ``alpha``."""
    read_options, options = _split(options)
    arrays, cols, rate = _columns(data, freq, names, read_options)
    return SeriesResult(json.loads(_native.avar(arrays, cols, rate, **options)))


def implied(model: str, *, levels: int, freq: float = 1.0) -> Implied:
    """Implied (theoretical) wavelet variance of a fully specified model and of each process
    (docs/methods.md §4)."""
    return Implied(json.loads(_native.implied(model, levels, freq)))


def simulate(model: str, *, n: int, freq: float = 1.0, seed: int = 0, components: bool = False):
    """A seeded simulation of a fully specified model (docs/methods.md §10): the series, or with
    ``components=True`` a pair ``(series, {process: series})``."""
    x, parts = _native.simulate(model, n, freq, seed, components)
    return (x, dict(parts)) if components else x


def fit(
    data: Data,
    *,
    model: str,
    freq: Optional[float] = None,
    names: Optional[Sequence[str]] = None,
    G: Optional[int] = None,
    progress: Progress = None,
    **options,
) -> FitResult:
    """GMWM estimate of ``model`` on each column (docs/methods.md §5): ``weights`` (fast, diag,
    bootstrap), ``G`` (starting-value draws), ``seed``, ``inference``, ``bootstrap`` and
    ``covariance`` (docs/methods.md §7; "auto", "exact" or "bootstrap": how V is obtained),
    ``robust``, ``eff``, ``robust_convention``, ``levels``, ``alpha``, and ``augment``
    ("mean", "acf:K" or "mean,acf:K": GMWM+ beside each fit, docs/methods.md §5.15, in
    ``to_dict()["fits"][k]["augmented"]``)."""
    read_options, options = _split(options)
    arrays, cols, rate = _columns(data, freq, names, read_options)
    doc = _native.fit(arrays, cols, rate, model, draws=G, progress=progress, **options)
    return FitResult(json.loads(doc))


def select(
    data: Data,
    *,
    model: Optional[str] = None,
    candidates: Optional[Union[str, Sequence[str]]] = None,
    freq: Optional[float] = None,
    names: Optional[Sequence[str]] = None,
    G: Optional[int] = None,
    progress: Progress = None,
    **options,
) -> SelectionResult:
    """Model selection by the Wavelet Information Criterion on each column (docs/methods.md §8):
    ``model`` (every sub-model is a candidate) or ``candidates`` (a list, or text separated by
    ``;``), ``bootstrap``, ``covariance``, ``optimism``, ``convention``, ``rule``, ``G``, ``seed``, and the WV
    settings."""
    read_options, options = _split(options)
    arrays, cols, rate = _columns(data, freq, names, read_options)
    if isinstance(candidates, str):
        candidates = [c.strip() for c in candidates.split(";") if c.strip()]
    doc = _native.select(
        arrays, cols, rate, model=model, candidates=candidates, draws=G, progress=progress, **options
    )
    return SelectionResult(json.loads(doc))


def calibrate(
    data: Data,
    *,
    freq: Optional[float] = None,
    names: Optional[Sequence[str]] = None,
    units: Optional[Sequence[Optional[str]]] = None,
    G: Optional[int] = None,
    progress: Progress = None,
    **options,
) -> CalibrationResult:
    """The calibration pipeline of ``gmwm calibrate`` (per axis: WV, WIC selection, the
    identified fit with intervals, N/B/K in SI and datasheet units, the IEEE 952 read-off, the
    verdict, the contamination check, the navigation sets): ``gyro_unit``, ``accel_unit``,
    ``model``, ``rule``, ``bootstrap``, ``covariance``, ``G``, ``seed``, ``eff``, ``robust``, ``alpha``,
    ``axis_policy``, ``inflate``, ``conservative``, ``horizon`` (a mission length in seconds:
    per axis the white noise + random walk bounding the model up to it, in ``axes[].horizon``
    and the navigation sets), ``rostopic``, ``tolerance`` (the verdict's,
    0.1), ``force_units`` (unit flags on a ROS recording), ``datasheet`` (as ``gmwm calibrate
    --datasheet``: "N=2 deg/sqrt(h), B=25.2 deg/h, N=0.2 m/s/sqrt(h)", compared per axis in
    ``axes[].datasheet``); for a path also the read options
    (``columns``, ``format``, ``topic``, ...)."""
    if _is_path(data):
        doc = _native.calibrate(path=os.fspath(data), freq=freq, draws=G, progress=progress, **options)
    else:
        read_options, options = _split(options)
        arrays, cols, rate = _columns(data, freq, names, read_options)
        doc = _native.calibrate(
            arrays=arrays, names=cols, units=list(units) if units is not None else None,
            freq=rate, draws=G, progress=progress, **options,
        )
    return CalibrationResult(json.loads(doc))


def calibrate_pooled(
    paths: Sequence[Union[str, "os.PathLike[str]"]],
    *,
    freq: Optional[float] = None,
    G: Optional[int] = None,
    progress: Progress = None,
    **options,
) -> CalibrationResult:
    """One calibration of several recordings of one sensor (``gmwm calibrate FILE... --pool``,
    docs/methods.md §5.12): their wavelet variances pooled level by level, the pipeline of
    :func:`calibrate` on the pooled one. The result's ``recordings`` lists the inputs; each axis'
    notes compare every recording with the others, scale by scale. Options as :func:`calibrate`
    for a path."""
    doc = _native.calibrate(
        paths=[os.fspath(p) for p in paths], freq=freq, draws=G, progress=progress, **options
    )
    return CalibrationResult(json.loads(doc))


def calibrate_many(paths, client=None, **options):
    """Calibrates many recordings, on a ``dask.distributed`` client when given, else in a local
    process pool; see :func:`gmwm.fleet.calibrate_many`."""
    from .fleet import calibrate_many as _many

    return _many(paths, client=client, **options)


def _copies() -> int:
    """Columns copied so far because they were not contiguous float64 (zero-copy check)."""
    return _native.copies()
