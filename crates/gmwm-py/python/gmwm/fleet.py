"""Fleet calibration: many recordings, one table.

``calibrate_many(paths, client=None, **options)`` runs :func:`gmwm.calibrate` on every
recording, on a ``dask.distributed`` client when one is given (``pip install 'gmwm[fleet]'``),
else in a local process pool. Each recording is one task keyed by its position and path; a
worker lost mid-run has its tasks rescheduled by the scheduler, and the results are gathered
once, in the order of ``paths``: nothing is reported twice or dropped.
"""

from __future__ import annotations

import multiprocessing
import os
import uuid
from concurrent.futures import ProcessPoolExecutor
from typing import Any, Dict, List, Optional, Sequence

from ._results import CalibrationResult, summary_rows


def _unit_name(path: str) -> str:
    """The unit's name: the file name without its data extensions."""
    name = os.path.basename(os.fspath(path).rstrip("/"))
    for ext in (".gz", ".csv", ".tsv", ".txt", ".bag", ".mcap", ".db3", ".bin", ".f64", ".f32"):
        if name.endswith(ext):
            name = name[: -len(ext)]
    return name or os.fspath(path)


def calibrate_one(path: str, options: Dict[str, Any]) -> Dict[str, Any]:
    """One recording's calibration document (what a worker runs; plain data, picklable), or
    ``{"error": message}`` when the engine refuses the recording: that answer is deterministic,
    so it is returned rather than raised, and Dask does not retry it."""
    from . import GmwmError, calibrate

    try:
        return calibrate(path, **options).to_dict()
    except GmwmError as e:
        return {"error": str(e)}


class FleetResult:
    """The calibrations of a fleet: ``results`` (unit -> :class:`CalibrationResult`, in input
    order), ``table`` (one row per unit and axis: unit, axis, model, N, B, K with intervals,
    verdict; a pandas ``DataFrame`` when pandas is installed, else a list of dicts) and
    ``errors`` (unit -> message, for recordings that could not be calibrated)."""

    def __init__(self, units: List[str], docs: List[Optional[Dict[str, Any]]], errors: Dict[str, str]):
        self.results: Dict[str, CalibrationResult] = {
            u: CalibrationResult(d) for u, d in zip(units, docs) if d is not None
        }
        self.errors = errors
        rows = [row for u, d in zip(units, docs) if d is not None for row in summary_rows(d, unit=u)]
        try:
            import pandas

            self.table = pandas.DataFrame(rows)
        except ImportError:  # pragma: no cover - pandas is in the fleet extra
            self.table = rows

    def __len__(self) -> int:
        return len(self.results)

    def __repr__(self) -> str:
        return f"<FleetResult: {len(self.results)} calibrated, {len(self.errors)} failed>"


def calibrate_many(
    paths: Sequence[str],
    client=None,
    *,
    max_workers: Optional[int] = None,
    retries: int = 1,
    **options,
) -> FleetResult:
    """Calibrates every recording of ``paths`` with the same ``options`` (those of
    :func:`gmwm.calibrate`). With a ``dask.distributed.Client`` each recording is a task
    (``retries`` more attempts on an unexpected exception; an error of the engine on the
    recording is deterministic and not retried; a lost worker's tasks are rescheduled by Dask);
    without one, a ``ProcessPoolExecutor`` of ``max_workers`` spawned processes runs them (so a
    script calling this at import time needs the ``if __name__ == "__main__":`` guard). A recording
    that fails is reported in ``errors`` with the engine's message, not raised, so that one bad
    unit does not lose the fleet."""
    paths = [os.fspath(p) for p in paths]
    units = [_unit_name(p) for p in paths]
    if len(set(units)) != len(units):
        units = [f"{i + 1}:{u}" for i, u in enumerate(units)]
    docs: List[Optional[Dict[str, Any]]] = [None] * len(paths)
    errors: Dict[str, str] = {}
    if client is not None:
        # one token per call: a key already known to the scheduler (an earlier call on the same
        # client whose futures are not yet released) would be reused with its old result
        token = uuid.uuid4().hex
        futures = client.map(
            calibrate_one,
            paths,
            [options] * len(paths),
            key=[f"gmwm-calibrate-{i}-{u}-{token}" for i, u in enumerate(units)],
            retries=retries,
            pure=False,
        )
        for i, f in enumerate(futures):
            try:
                docs[i] = f.result()
            except Exception as e:  # noqa: BLE001 - reported per unit, not raised
                errors[units[i]] = str(e)
            if docs[i] is not None and "error" in docs[i]:
                errors[units[i]] = docs[i].pop("error")
                docs[i] = None
    else:
        # spawned, not forked: the engine's thread pool (rayon) does not survive a fork, so a
        # pool forked from a process that has already run the engine once (a single
        # `gmwm.calibrate` before this call) deadlocks in its workers
        context = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(max_workers=max_workers, mp_context=context) as pool:
            futures = [pool.submit(calibrate_one, p, options) for p in paths]
            for i, f in enumerate(futures):
                try:
                    docs[i] = f.result()
                except Exception as e:  # noqa: BLE001
                    errors[units[i]] = str(e)
                if docs[i] is not None and "error" in docs[i]:
                    errors[units[i]] = docs[i].pop("error")
                    docs[i] = None
    return FleetResult(units, docs, errors)
