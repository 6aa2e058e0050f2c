"""Typed results of the gmwm verbs.

Each result keeps the engine's JSON document (the CLI's ``--json`` for the same call) and
exposes it as ``to_dict()``; arrays are numpy views of the document's lists, and tables are
pandas ``DataFrame``s (``to_dataframe()``; pandas is optional).
"""

from __future__ import annotations

import copy
from typing import Any, Dict, Iterator, List, Optional

import numpy as np


def _array(values: Optional[list]) -> np.ndarray:
    """A float64 array from a JSON list (null becomes NaN)."""
    if values is None:
        return np.empty(0)
    return np.array([np.nan if v is None else v for v in values], dtype=np.float64)


def _pandas():
    try:
        import pandas
    except ImportError as e:  # pragma: no cover - exercised only without pandas
        raise ImportError("to_dataframe() needs pandas: pip install 'gmwm[pandas]'") from e
    return pandas


class _Document:
    """A result backed by an engine JSON document."""

    def __init__(self, doc: Dict[str, Any]):
        self._doc = doc

    def to_dict(self) -> Dict[str, Any]:
        """The CLI's JSON document for the same call, field for field (a deep copy)."""
        return copy.deepcopy(self._doc)

    def __repr__(self) -> str:
        return f"<{type(self).__name__}: {self._summary()}>"

    def _summary(self) -> str:
        return ""


class Series(_Document):
    """One column's wavelet or Allan-type variance (docs/methods.md §1–§3).

    Attributes: ``name``, ``n``, ``freq_hz``, ``alpha``, ``tau`` (samples), ``tau_s``
    (seconds), ``value`` (the variance: ``wv`` or ``avar``), ``ci_low``, ``ci_high`` (on the
    variance's scale), and for Allan-type variances ``adev`` with its interval on the deviation
    scale, ``adev_ci_low`` and ``adev_ci_high``.
    """

    def __init__(self, doc: Dict[str, Any]):
        super().__init__(doc)
        self.name: str = doc["name"]
        self.n: int = doc["n"]
        self.freq_hz: float = doc["freq_hz"]
        self.alpha: float = doc["alpha"]
        self.tau = _array(doc["tau"])
        self.tau_s = _array(doc["tau_s"])
        self.kind = "wv" if "wv" in doc else "avar"
        self.value = _array(doc[self.kind])
        self.ci_low = _array(doc["ci_low"])
        self.ci_high = _array(doc["ci_high"])
        self.adev = _array(doc["adev"]) if "adev" in doc else None
        # the interval on the deviation scale, to pair with ``adev`` (``ci_low``/``ci_high`` are
        # on the variance scale)
        self.adev_ci_low = _array(doc["adev_ci_low"]) if "adev_ci_low" in doc else None
        self.adev_ci_high = _array(doc["adev_ci_high"]) if "adev_ci_high" in doc else None

    def _summary(self) -> str:
        return f"{self.name}, {self.kind} at {len(self.tau)} scales"


class SeriesResult(_Document):
    """The variances of several columns: ``result["gyro_x"]``, iteration, ``to_dataframe()``."""

    def __init__(self, doc: Dict[str, Any]):
        super().__init__(doc)
        self.series: List[Series] = [Series(s) for s in doc["series"]]

    def __getitem__(self, key) -> Series:
        if isinstance(key, int):
            return self.series[key]
        for s in self.series:
            if s.name == key:
                return s
        raise KeyError(f"no series {key!r}; the series are {', '.join(s.name for s in self.series)}")

    def __iter__(self) -> Iterator[Series]:
        return iter(self.series)

    def __len__(self) -> int:
        return len(self.series)

    def names(self) -> List[str]:
        """The columns, in order."""
        return [s.name for s in self.series]

    def to_dataframe(self):
        """One row per series and scale: series, level, tau, tau_s, the variance, ci_low, ci_high
        (the CLI's ``--csv``)."""
        pd = _pandas()
        rows = []
        for s in self.series:
            for j in range(len(s.tau)):
                row = {
                    "series": s.name,
                    "level": j + 1,
                    "tau": s.tau[j],
                    "tau_s": s.tau_s[j],
                    s.kind: s.value[j],
                    "ci_low": s.ci_low[j],
                    "ci_high": s.ci_high[j],
                }
                if s.adev is not None:
                    row["adev"] = s.adev[j]
                if s.adev_ci_low is not None:
                    row["adev_ci_low"] = s.adev_ci_low[j]
                    row["adev_ci_high"] = s.adev_ci_high[j]
                rows.append(row)
        return pd.DataFrame(rows)

    def _summary(self) -> str:
        return ", ".join(self.names())


class Implied(_Document):
    """The implied WV of a model and of each process (docs/methods.md §4)."""

    def __init__(self, doc: Dict[str, Any]):
        super().__init__(doc)
        self.model: str = doc["model"]
        self.tau_s = _array(doc["tau_s"])
        self.wv = _array(doc["wv"])
        self.processes = {p["process"]: _array(p["wv"]) for p in doc["processes"]}

    def _summary(self) -> str:
        return self.model


class FitResult(_Document):
    """GMWM fits, one per column (docs/methods.md §5; §7 with ``inference=True``)."""

    def __init__(self, doc: Dict[str, Any]):
        super().__init__(doc)
        self.fits: List[Dict[str, Any]] = doc["fits"]

    def __getitem__(self, column: str) -> Dict[str, Any]:
        for f in self.fits:
            if f["column"] == column:
                return f
        raise KeyError(f"no fit of column {column!r}")

    def to_dataframe(self):
        """One row per column and parameter: column, process, index, name, value, se, ci_low,
        ci_high (the CLI's ``--csv``)."""
        pd = _pandas()
        rows = []
        for f in self.fits:
            for p in f["parameters"]:
                rows.append(
                    {
                        "column": f["column"],
                        "process": p["process"],
                        "index": p["index"],
                        "name": p["name"],
                        "value": p["value"],
                        "se": p.get("se"),
                        "ci_low": p.get("ci_low"),
                        "ci_high": p.get("ci_high"),
                    }
                )
        return pd.DataFrame(rows)

    def _summary(self) -> str:
        return ", ".join(f"{f['column']}: {f['model']}" for f in self.fits)


class SelectionResult(_Document):
    """WIC selections, one per column (docs/methods.md §8)."""

    def __init__(self, doc: Dict[str, Any]):
        super().__init__(doc)
        self.selections: List[Dict[str, Any]] = doc["selections"]

    def selected(self) -> Dict[str, str]:
        """The selected canonical model of each column."""
        return {s["column"]: s["selected_canonical"] for s in self.selections}

    def to_dataframe(self):
        """One row per column and canonical model: rank, model, objective, optimism, WIC,
        delta_wic, delta_wic_se, status."""
        pd = _pandas()
        rows = []
        for s in self.selections:
            for rank, r in enumerate(s["rows"], start=1):
                rows.append(
                    {
                        "column": s["column"],
                        "rank": rank,
                        "canonical_model": r["canonical_model"],
                        "objective": r["objective"],
                        "optimism": r["optimism"],
                        "wic": r["wic"],
                        "delta_wic": r["delta_wic"],
                        "delta_wic_se": r["delta_wic_se"],
                        "status": r["status"],
                    }
                )
        return pd.DataFrame(rows)

    def _summary(self) -> str:
        return ", ".join(f"{k}: {v}" for k, v in self.selected().items())


_SUMMARY_TERMS = ("noise_density", "bias_instability", "random_walk")


def summary_rows(doc: Dict[str, Any], unit: Optional[str] = None) -> List[Dict[str, Any]]:
    """One row per axis of a calibration document: unit, axis, model, N, B, K with their
    intervals (SI) and status, the fit verdict and whether contamination matters."""
    rows = []
    for a in doc["axes"]:
        row: Dict[str, Any] = {"axis": a["column"], "model": a["canonical_model"]}
        if unit is not None:
            row = {"unit": unit, **row}
        for term in _SUMMARY_TERMS:
            e = a.get(term)
            row[term] = e["value"] if e else None
            row[f"{term}_low"] = e["ci_low"] if e else None
            row[f"{term}_high"] = e["ci_high"] if e else None
            row[f"{term}_status"] = e["status"] if e else None
        row["si_unit_noise_density"] = a["noise_density"]["unit"] if a.get("noise_density") else None
        row["explains_wv"] = a["verdict"]["explains_wv"]
        row["j_test_p_value"] = a["verdict"]["j_test_p_value"]
        c = a.get("contamination")
        row["contamination_matters"] = c["matters"] if c else None
        rows.append(row)
    return rows


class CalibrationResult(_Document):
    """The calibration of a recording (the pipeline of ``gmwm calibrate``): per axis the model,
    the noise density N, bias instability B and random walk K with intervals, the IEEE
    read-off, the verdict and the navigation sets as exported."""

    def __init__(self, doc: Dict[str, Any]):
        super().__init__(doc)
        self.file: str = doc["file"]
        self.freq_hz: float = doc["freq_hz"]
        self.axes: List[Dict[str, Any]] = doc["axes"]
        self.exported: List[Dict[str, Any]] = doc["exported"]

    def axis(self, column: str) -> Dict[str, Any]:
        """One axis' calibration."""
        for a in self.axes:
            if a["column"] == column:
                return a
        raise KeyError(f"no axis {column!r}")

    def summary(self) -> List[Dict[str, Any]]:
        """One row per axis (see :func:`summary_rows`)."""
        return summary_rows(self._doc)

    def to_dataframe(self):
        """:meth:`summary` as a ``DataFrame``."""
        return _pandas().DataFrame(self.summary())

    def _summary(self) -> str:
        return ", ".join(f"{a['column']}: {a['canonical_model']}" for a in self.axes)


class Recording:
    """Columns read from a recording: ``names``, ``data`` (name -> float64 array), ``freq_hz``,
    ``units`` (name -> unit text or None) and the reader's ``notes``."""

    def __init__(self, path: str, names, arrays, freq_hz, units, notes):
        self.path = path
        self.names: List[str] = list(names)
        self.data: Dict[str, np.ndarray] = dict(zip(names, arrays))
        self.freq_hz: Optional[float] = freq_hz
        self.units: Dict[str, Optional[str]] = dict(zip(names, units))
        self.notes: List[str] = list(notes)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.data[name]

    def __len__(self) -> int:
        return len(next(iter(self.data.values()))) if self.data else 0

    def to_dataframe(self):
        """The columns as a ``DataFrame``."""
        return _pandas().DataFrame(self.data)

    def __repr__(self) -> str:
        return f"<Recording {self.path}: {len(self)} samples x {', '.join(self.names)} at {self.freq_hz} Hz>"
