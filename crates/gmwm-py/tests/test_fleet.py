"""Fleet calibration (`gmwm.calibrate_many`): a process pool and a `dask.distributed` cluster
give, unit for unit, the documents of single `gmwm.calibrate` calls; a worker killed mid-run
loses and duplicates nothing; a bad recording is reported with the engine's message while the
others calibrate.

The recordings are simulated with a known truth, WN(sigma2) + RW(gamma2) at 100 Hz, so that
N = sqrt(sigma2 / f) and K = sqrt(gamma2 * f), and written as CSV with a time column (the rate)
and `gyro_* [rad/s]` headers (the unit). Every cluster is local (2 worker processes of 1
thread), bounded by timeouts and closed by the test that made it; every `calibrate_many` call
runs under a timeout too, so that a hang fails the test instead of stalling CI.
"""

from __future__ import annotations

import logging
import math
import multiprocessing
import os
import sys
import threading
import time
from pathlib import Path
from typing import Dict, List, Tuple

import numpy as np
import pytest

import gmwm
from gmwm import CalibrationResult

FREQ = 100.0
MODEL = "AR1()+WN()+RW()"
# ~0.03 s a recording of 2^15 samples
FAST = dict(model=MODEL, bootstrap=10, G=1000, seed=11)
# ~1 s a recording: long enough that a worker can be killed while it computes
SLOW = dict(model=MODEL, bootstrap=2000, G=1000, seed=11)
N_SAMPLES = 2**15
TIMEOUT = 180.0  # seconds, for anything that waits on the cluster

TABLE_COLUMNS = {
    "unit",
    "axis",
    "model",
    "noise_density",
    "noise_density_low",
    "noise_density_high",
    "bias_instability",
    "bias_instability_low",
    "bias_instability_high",
    "random_walk",
    "random_walk_low",
    "random_walk_high",
    "explains_wv",
}

# Unit i: its axes' truths (sigma2 of WN, gamma2 of RW); odd units have two axes.
TRUTHS: List[List[Tuple[float, float]]] = [
    [(1e-4, 1e-9)],
    [(4e-4, 4e-9), (2.5e-5, 1e-10)],
    [(1e-3, 1e-8)],
    [(2.5e-5, 4e-10), (1e-4, 2e-9)],
    [(2e-4, 1e-9)],
    [(6.4e-5, 5e-10), (9e-4, 9e-9)],
    [(1.6e-4, 3e-9)],
    [(3.6e-4, 2e-10), (4.9e-5, 1e-9)],
]
AXES = ["gyro_x", "gyro_y", "gyro_z"]


def _column(axis: str) -> str:
    """The column name as the reader keeps it (with the unit of the header)."""
    return f"{axis} [rad/s]"


def _write_unit(path: Path, truths: List[Tuple[float, float]], seed: int, n: int = N_SAMPLES) -> None:
    cols = [np.arange(n) / FREQ]
    for k, (s2, g2) in enumerate(truths):
        cols.append(gmwm.simulate(f"WN(sigma2={s2})+RW(gamma2={g2})", n=n, freq=FREQ, seed=seed * 10 + k))
    header = ",".join(["time"] + [_column(AXES[k]) for k in range(len(truths))])
    np.savetxt(path, np.column_stack(cols), delimiter=",", header=header, comments="", fmt="%.17g")


def _recordings(root: Path, prefix: str, n: int = N_SAMPLES) -> Dict[str, str]:
    """unit -> path of 8 recordings with the truths of TRUTHS."""
    root.mkdir(parents=True, exist_ok=True)
    out = {}
    for i, truths in enumerate(TRUTHS):
        unit = f"{prefix}{i}"
        path = root / f"{unit}.csv"
        _write_unit(path, truths, seed=1000 + i, n=n)
        out[unit] = str(path)
    return out


@pytest.fixture(scope="module")
def fast(tmp_path_factory) -> Dict[str, str]:
    return _recordings(tmp_path_factory.mktemp("fast"), "imu")


@pytest.fixture(scope="module")
def fast_refs(fast) -> Dict[str, dict]:
    """The single calls: unit -> `gmwm.calibrate(path, **FAST).to_dict()`."""
    return {u: gmwm.calibrate(p, **FAST).to_dict() for u, p in fast.items()}


@pytest.fixture(scope="module")
def bad(tmp_path_factory) -> Dict[str, str]:
    """Recordings the engine refuses: unit -> path."""
    root = tmp_path_factory.mktemp("bad")
    garbled = root / "garbled.csv"
    garbled.write_text("time,gyro_x [rad/s]\n0,0.1\n0.01,0.2\n0.02,abc\n0.03,0.4\n")
    return {"garbled": str(garbled), "missing": str(root / "missing.csv")}


def _bounded(fn, timeout: float = TIMEOUT):
    """`fn()` in a thread, failing after `timeout` s; on a timeout the child processes of this
    process (pool workers, or the cluster's nannies) are killed so that the thread ends."""
    box: dict = {}

    def run():
        try:
            box["value"] = fn()
        except BaseException as e:  # noqa: BLE001 - re-raised below
            box["error"] = e

    t = threading.Thread(target=run, daemon=True)
    t.start()
    t.join(timeout)
    if t.is_alive():
        for child in multiprocessing.active_children():
            child.kill()
        t.join(30)
        raise AssertionError(f"calibrate_many did not return within {timeout:.0f} s")
    if "error" in box:
        raise box["error"]
    return box["value"]


def _same(a, b) -> bool:
    """Exact equality, with None and NaN (pandas' missing value) equal."""
    missing_a = a is None or (isinstance(a, float) and math.isnan(a))
    missing_b = b is None or (isinstance(b, float) and math.isnan(b))
    if missing_a or missing_b:
        return missing_a and missing_b
    return a == b


def _check_fleet(fleet, paths: Dict[str, str], refs: Dict[str, dict]) -> None:
    """Every unit once, each document equal to its single call, the table one row per unit and
    axis with the single call's numbers, and N (and K, loosely) near the truth."""
    assert fleet.errors == {}
    assert list(fleet.results) == list(paths), "results keyed by unit, in the order of paths"
    for unit, ref in refs.items():
        assert fleet.results[unit].to_dict() == ref, f"{unit}: fleet document differs from the single call"

    table = fleet.table
    assert TABLE_COLUMNS <= set(table.columns), sorted(TABLE_COLUMNS - set(table.columns))
    expected_rows = sum(len(ref["axes"]) for ref in refs.values())
    assert len(table) == expected_rows
    pairs = list(zip(table["unit"], table["axis"]))
    assert len(set(pairs)) == len(pairs), "a (unit, axis) row appears twice"
    assert sorted(pairs) == sorted((u, a["column"]) for u, ref in refs.items() for a in ref["axes"])

    for unit, ref in refs.items():
        i = int(unit.lstrip("abcdefghijklmnopqrstuvwxyz"))
        for k, (s2, g2) in enumerate(TRUTHS[i]):
            column = _column(AXES[k])
            row = table[(table["unit"] == unit) & (table["axis"] == column)].iloc[0].to_dict()
            expected = CalibrationResult(ref).axis(column)
            assert row["model"] == expected["canonical_model"]
            for term in ("noise_density", "bias_instability", "random_walk"):
                e = expected.get(term)
                assert _same(row[term], e["value"] if e else None), (unit, column, term)
                assert _same(row[f"{term}_low"], e["ci_low"] if e else None), (unit, column, term)
                assert _same(row[f"{term}_high"], e["ci_high"] if e else None), (unit, column, term)
            assert bool(row["explains_wv"]) == expected["verdict"]["explains_wv"]

            n_true, k_true = math.sqrt(s2 / FREQ), math.sqrt(g2 * FREQ)
            n_hat = fleet.results[unit].axis(column)["noise_density"]["value"]
            assert abs(n_hat / n_true - 1) < 0.10, f"{unit} {column}: N {n_hat:.4g} vs truth {n_true:.4g}"
            rw = fleet.results[unit].axis(column)["random_walk"]
            assert rw is not None, f"{unit} {column}: no random walk found"
            # K comes from the last octaves of 327 s of data, a few degrees of freedom: near the
            # truth means within a factor 2, or inside its interval where the data leave it wide
            # (one unit in the twelve axes has K at 0.49x with an interval of 0.1x..2.3x)
            inside = rw["ci_low"] is not None and rw["ci_low"] <= k_true <= rw["ci_high"]
            assert 0.5 < rw["value"] / k_true < 2.0 or inside, (
                f"{unit} {column}: K {rw['value']:.4g} vs truth {k_true:.4g}, "
                f"interval {rw['ci_low']}..{rw['ci_high']}"
            )


# --------------------------------------------------------------------------------------------
# process pool (no client)


def test_process_pool_equals_single_calls(fast, fast_refs):
    # `fast_refs` ran the engine in this process first: a pool forked from here deadlocked in
    # its workers (the engine's rayon thread pool does not survive a fork); the pool spawns now
    fleet = _bounded(lambda: gmwm.calibrate_many(list(fast.values()), max_workers=2, **FAST))
    _check_fleet(fleet, fast, fast_refs)
    assert len(fleet) == 8
    assert repr(fleet) == "<FleetResult: 8 calibrated, 0 failed>"


def _engine_message(path: str) -> str:
    with pytest.raises(gmwm.GmwmError) as e:
        gmwm.calibrate(path, **FAST)
    return str(e.value)


def _check_bad(fleet, fast, fast_refs, bad) -> None:
    good = list(fast)[:3]
    assert set(fleet.errors) == set(bad)
    for unit, path in bad.items():
        message = _engine_message(path)
        assert os.path.basename(path) in message, message
        assert fleet.errors[unit] == message
    assert list(fleet.results) == good
    for unit in good:
        assert fleet.results[unit].to_dict() == fast_refs[unit]
    assert set(fleet.table["unit"]) == set(good)
    assert len(fleet.table) == sum(len(fast_refs[u]["axes"]) for u in good)


def _mixed_paths(fast, bad) -> List[str]:
    good = list(fast.values())[:3]
    return [good[0], bad["garbled"], good[1], bad["missing"], good[2]]


def test_process_pool_bad_recording_reports_engine_message(fast, fast_refs, bad):
    # regression: the native GmwmError (module "_native") cannot be pickled back from a pool
    # process, so the error used to read "Can't pickle <class '_native.GmwmError'>..."
    fleet = _bounded(lambda: gmwm.calibrate_many(_mixed_paths(fast, bad), max_workers=2, **FAST))
    _check_bad(fleet, fast, fast_refs, bad)
    assert "pickle" not in " ".join(fleet.errors.values())


# --------------------------------------------------------------------------------------------
# dask.distributed


def _local_cluster():
    from dask.distributed import LocalCluster

    return LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        dashboard_address=":0",  # a free port: clusters may overlap
        silence_logs=logging.CRITICAL,
    )


@pytest.fixture(scope="module")
def client():
    from dask.distributed import Client

    with _local_cluster() as cluster, Client(cluster, timeout="60s") as c:
        c.wait_for_workers(2, timeout=60)
        yield c


def test_dask_equals_single_calls(client, fast, fast_refs):
    fleet = _bounded(lambda: gmwm.calibrate_many(list(fast.values()), client, **FAST))
    _check_fleet(fleet, fast, fast_refs)
    # both worker processes took part (each holds a pid other than ours)
    pids = client.run(os.getpid)
    assert len(pids) == 2 and os.getpid() not in pids.values()


def test_dask_bad_recording_reports_engine_message(client, fast, fast_refs, bad):
    fleet = _bounded(lambda: gmwm.calibrate_many(_mixed_paths(fast, bad), client, **FAST))
    _check_bad(fleet, fast, fast_refs, bad)


def test_dask_calls_on_one_client_are_independent(client, fast):
    # regression: the task keys were the same for every call, so a second call with other
    # options got the first call's results back while the scheduler still knew the keys
    path = [next(iter(fast.values()))]
    first = _bounded(lambda: gmwm.calibrate_many(path, client, **FAST))
    second = _bounded(lambda: gmwm.calibrate_many(path, client, **{**FAST, "model": "WN()+RW()", "alpha": 0.1}))
    (a,) = first.results.values()
    (b,) = second.results.values()
    assert a.to_dict()["full_model"] == MODEL and a.to_dict()["alpha"] == 0.05
    assert b.to_dict()["full_model"] == "WN()+RW()" and b.to_dict()["alpha"] == 0.1


def _exit_if_computing(marker: str, dask_worker=None):
    """Run in a worker's event loop: when a calibration is executing there, write its key to
    `marker` and end the process at once (no cleanup, as a crash would); else return None."""
    keys = [str(ts.key) for ts in dask_worker.state.executing if str(ts.key).startswith("gmwm-calibrate")]
    if keys:
        Path(marker).write_text(keys[0])
        os._exit(17)
    return None


def _done_count(dask_scheduler=None) -> int:
    return sum(1 for k, ts in dask_scheduler.tasks.items() if str(k).startswith("gmwm-calibrate") and ts.state == "memory")


def _wait(predicate, what: str, timeout: float = TIMEOUT, every: float = 0.02):
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout:.0f} s waiting for {what}")
        time.sleep(every)


@pytest.fixture
def by_value():
    """The helpers of this module sent to workers by value, whatever pytest's import mode (a
    worker need not be able to import this file)."""
    import cloudpickle

    module = sys.modules[__name__]
    cloudpickle.register_pickle_by_value(module)
    yield
    cloudpickle.unregister_pickle_by_value(module)


def test_dask_worker_killed_mid_run(tmp_path, by_value):
    from dask.distributed import Client

    slow = _recordings(tmp_path / "slow", "slow")
    marker = str(tmp_path / "killed-task.txt")
    box: dict = {}

    def run(c):
        try:
            box["fleet"] = gmwm.calibrate_many(list(slow.values()), c, **SLOW)
        except BaseException as e:  # noqa: BLE001 - reported by the test below
            box["error"] = e

    with _local_cluster() as cluster, Client(cluster, timeout="60s") as c:
        c.wait_for_workers(2, timeout=60)
        before = set(c.scheduler_info()["workers"])
        victim = sorted(before)[0]
        worker = threading.Thread(target=run, args=(c,), daemon=True)
        worker.start()
        # (on a failure below, leaving the block closes the cluster under the thread, which ends)
        # mid-run: some calibrations done, and the victim computing one right now
        _wait(lambda: c.run_on_scheduler(_done_count) >= 1 or not worker.is_alive(), "a first result")
        assert worker.is_alive(), f"the run ended before the kill: {box}"

        def kill():
            try:
                out = c.run(_exit_if_computing, marker, workers=[victim], on_error="return")
            except Exception:  # noqa: BLE001 - the connection dies with the worker
                return True
            return isinstance(out.get(victim), BaseException) or os.path.exists(marker)

        _wait(kill, "the victim to be computing")
        killed_key = _wait(lambda: os.path.exists(marker) and Path(marker).read_text(), "the marker")
        done_at_kill = c.run_on_scheduler(_done_count)
        assert done_at_kill < 8, "the kill came after the run"

        # the worker process is gone and the nanny started a new one in its place
        after = _wait(
            lambda: (lambda w: w if victim not in w and len(w) == 2 else None)(
                set(c.scheduler_info()["workers"])
            ),
            "the victim to leave and a replacement to join",
        )
        assert victim not in after and len(after - before) == 1

        worker.join(TIMEOUT)
        assert not worker.is_alive(), f"calibrate_many did not finish within {TIMEOUT:.0f} s"
    assert "error" not in box, box.get("error")
    fleet = box["fleet"]

    # the killed task was rescheduled and its unit arrived, once, like every other unit
    killed_unit = killed_key.split("-")[3]
    assert killed_unit in slow
    assert len(fleet.results) == 8 and fleet.errors == {}
    assert fleet.table["unit"].value_counts().to_dict() == {
        f"slow{i}": len(t) for i, t in enumerate(TRUTHS)
    }
    refs = {u: gmwm.calibrate(p, **SLOW).to_dict() for u, p in slow.items()}
    _check_fleet(fleet, slow, refs)
