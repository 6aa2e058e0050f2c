#!/usr/bin/env python3
"""Benchmarks of the Python package (a script, not a test).

(a) Python call overhead. On a 1e6-sample float64 series, ``gmwm.fit(x, freq=100,
    model="AR1()+WN()+RW()", G=...)`` (the whole wrapper: column checks, the native call, the
    JSON document parsed into a ``FitResult``) against the bare native call
    ``gmwm._native.fit([x], ["x"], 100.0, model, draws=G)`` (argument conversion, the engine with
    the GIL released, the engine's JSON document as a string), run in turns, medians of several
    runs; the wrapper alone, timed with the native call stubbed by its ready document (the
    difference of two noisy ~ms timings would drown it); the same on a tiny series, where the
    fixed cost of a call shows; and ``_native.version()``, the floor of any call into the
    extension.
    The engine alone, through the Rust API: ``cargo run --release -p gmwm --example fit_timing``
    fits the same model with the same G (2000), seeds and 1e6-sample series (same truth, same
    simulator and seed as ``gmwm.simulate`` here), so the three rows time the same numbers
    (``--no-rust`` skips it; it needs cargo). With ``--criterion``, also the criterion cell
    ``fit/3gm/classical/G=1000/1000000`` of ``cargo bench -p gmwm --bench fit`` against the
    native call and the wrapper on its very series and model. Nothing is added to Rust.
(a') CPU time per fit: the same fit in a Python process (``_native.fit``) and in a Rust process
    (the example), each process run with few and with many fits so that start-up cancels; the
    CPU time (user + system over every thread, from the child's rusage) does not count the time
    a loaded machine gives to other work, which wall times do.
(b) Fleet scaling. 8 recordings calibrated by ``gmwm.calibrate_many`` on a
    ``dask.distributed.LocalCluster`` of 1 worker and of 2 workers (processes, 1 thread each),
    and with ``--pool`` in the process pool of ``max_workers`` 1 and 2; wall times (medians) and
    the speed-up. The workers are started and warmed up (gmwm imported, one calibration done)
    before the clock starts; reading the CSV files is part of each calibration. The engine runs
    its own threads within a calibration (rayon, every core), so this is done twice: as it comes,
    and with ``RAYON_NUM_THREADS=1`` in every process. Baselines: the 8 calibrations one after the
    other in one process, in this environment and in the environment a dask nanny gives its
    workers (``MALLOC_TRIM_THRESHOLD_=65536`` etc., which costs the engine time).

Run from ``crates/gmwm-py`` with the package installed (``pip install 'gmwm[test]'``)::

    python benches/bench_python.py                 # about 3 minutes on 2 cores
    python benches/bench_python.py --quick         # a smoke run
    python benches/bench_python.py --pool          # (b) also with the process pool
    python benches/bench_python.py --criterion     # also the criterion cell (builds the bench)

Timings on a shared machine are skewed by other load: the load average is printed at the start
and end, and the configurations compared are run in turns so that load falls on them alike.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import json
import logging
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Callable, Dict, List, Optional, Tuple

import numpy as np

import gmwm
from gmwm import _native

MODEL = "AR1()+WN()+RW()"
FREQ = 100.0
# the truth, seed and G of crates/gmwm/examples/fit_timing.rs (the engine-alone timing)
TRUTH = "AR1(phi=0.999, sigma2=1e-8)+WN(sigma2=1e-4)+RW(gamma2=1e-10)"
SERIES_SEED = 1
EXAMPLE_G = 2000
# the criterion cell of crates/gmwm/benches/fit.rs: its truth, its series seed (4000 + n) at 1 Hz
CRITERION_TRUTH = "AR1(phi=0.9, sigma2=1)+AR1(phi=0.99, sigma2=0.1)+AR1(phi=0.999, sigma2=0.01)"
CRITERION_CELL = "fit/3gm/classical/G=1000/1000000"


def _per_call(fn: Callable[[], object], calls: int, repeats: int) -> List[float]:
    """Seconds per call, each sample the mean over `calls` back-to-back calls."""
    fn()
    out = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(calls):
            fn()
        out.append((time.perf_counter() - t0) / calls)
    return out


def _fmt_s(s: float) -> str:
    if s >= 1:
        return f"{s:.3f} s"
    if s >= 1e-3:
        return f"{s * 1e3:.2f} ms"
    if s >= 1e-6:
        return f"{s * 1e6:.1f} us"
    return f"{s * 1e9:.0f} ns"


def _table(title: str, header: List[str], rows: List[List[str]]) -> None:
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(header)]
    print(f"\n{title}")
    print("  " + "  ".join(h.ljust(w) for h, w in zip(header, widths)))
    print("  " + "  ".join("-" * w for w in widths))
    for r in rows:
        print("  " + "  ".join(c.ljust(w) for c, w in zip(r, widths)))


# ------------------------------------------------------------------------------------------
# (a) call overhead


def _interleaved(fns: Dict[str, Callable[[], object]], repeats: int) -> Dict[str, List[float]]:
    """Wall times of each callable, run in turns (the order rotating each round) so that drifts
    of the machine (other load, clock speed) fall on all of them alike."""
    names = list(fns)
    for k in names:
        fns[k]()
    out: Dict[str, List[float]] = {k: [] for k in names}
    for r in range(repeats):
        for k in names[r % len(names):] + names[: r % len(names)]:
            t0 = time.perf_counter()
            fns[k]()
            out[k].append(time.perf_counter() - t0)
    return out


class _StubbedNative:
    """`gmwm._native.fit` replaced by a function returning a ready document: what is left of
    `gmwm.fit` is the Python wrapper alone (argument handling, json.loads, FitResult)."""

    def __init__(self, doc: str):
        self.doc = doc

    def __enter__(self):
        self.orig = _native.fit
        _native.fit = lambda *a, **k: self.doc
        return self

    def __exit__(self, *exc):
        _native.fit = self.orig


def _overhead_rows(label: str, x: np.ndarray, G: int, rounds: int) -> Tuple[List[List[str]], Dict[str, float]]:
    doc = _native.fit([x], ["x"], FREQ, MODEL, draws=G)
    assert gmwm.fit(x, freq=FREQ, model=MODEL, G=G).to_dict() == json.loads(doc), "wrapper != native"
    t = _interleaved(
        {
            "wrapper": lambda: gmwm.fit(x, freq=FREQ, model=MODEL, G=G),
            "native": lambda: _native.fit([x], ["x"], FREQ, MODEL, draws=G),
        },
        rounds,
    )
    calls, repeats = 200, 7
    with _StubbedNative(doc):
        python_only = _per_call(lambda: gmwm.fit(x, freq=FREQ, model=MODEL, G=G), calls, repeats)
    parse = _per_call(lambda: json.loads(doc), calls, repeats)
    v = {"wrapper": t["wrapper"], "native": t["native"], "python": python_only, "parse": parse}
    m = {k: statistics.median(s) for k, s in v.items()}
    spread = lambda s: f"{_fmt_s(min(s))} .. {_fmt_s(max(s))}"  # noqa: E731
    rows = [
        [f"{label}: gmwm.fit (whole wrapper)", _fmt_s(m["wrapper"]), spread(v["wrapper"]), "100 %"],
        [f"{label}: _native.fit (native call)", _fmt_s(m["native"]), spread(v["native"]),
         f"{100 * m['native'] / m['wrapper']:.1f} %"],
        [f"{label}:   wrapper alone (native call stubbed)", _fmt_s(m["python"]), spread(v["python"]),
         f"{100 * m['python'] / m['wrapper']:.2f} %"],
        [f"{label}:   of which json.loads ({len(doc)} chars)", _fmt_s(m["parse"]), spread(v["parse"]),
         f"{100 * m['parse'] / m['wrapper']:.2f} %"],
    ]
    return rows, m


def bench_overhead(repeats: int, G: int, n: int, tiny_n: int, tiny_rounds: int, rust: bool) -> Dict[str, float]:
    x = gmwm.simulate(TRUTH, n=n, freq=FREQ, seed=SERIES_SEED)
    assert x.dtype == np.float64 and x.flags.c_contiguous
    copies = gmwm._copies()
    big_rows, big = _overhead_rows(f"n={n:.0e}", x, G, repeats)
    assert gmwm._copies() == copies, "the float64 series was copied"
    y = gmwm.simulate(TRUTH, n=tiny_n, freq=FREQ, seed=2)
    tiny_rows, tiny = _overhead_rows(f"n={tiny_n}", y, G, tiny_rounds)
    floor = _per_call(_native.version, 100_000, repeats)
    engine = None
    if rust:
        if G == EXAMPLE_G:
            engine = _rust_example(n, repeats)
        else:
            print(f"(the Rust example fits with G={EXAMPLE_G}: not compared at G={G})")
    for i, (what, (median, low)) in enumerate((engine or {}).items()):
        big_rows.insert(i, [f"n={n:.0e}: Rust API, examples/fit_timing: {what}", _fmt_s(median),
                            f"min {_fmt_s(low)}", f"{100 * median / big['wrapper']:.1f} %"])
    rows = big_rows + tiny_rows + [
        ["_native.version() (floor of any call)", _fmt_s(statistics.median(floor)),
         f"{_fmt_s(min(floor))} .. {_fmt_s(max(floor))}", ""]
    ]
    _table(
        f"(a) call overhead: model {MODEL}, G={G}; medians (min .. max) of {repeats} (n={n:.0e}) and "
        f"{tiny_rounds} (n={tiny_n}) calls taken in turns; the stubbed wrapper and json.loads: "
        "each of 7 runs the mean of 200 calls",
        ["call", "median", "range", "share of gmwm.fit"],
        rows,
    )
    return {"big": big, "tiny": tiny, "floor": statistics.median(floor), "rust": engine}


def _rust_example(n: int, runs: int) -> Optional[Dict[str, Tuple[float, float]]]:
    """Median and minimum seconds of each timing `examples/fit_timing.rs` prints (the fit, and
    the fit with its canonical reading and JSON document; same series, model, G and seeds as
    (a), timed in its own process; the example prints 0.1 ms steps); None when it cannot be
    built or run."""
    root = Path(__file__).resolve().parents[3]
    cmd = ["cargo", "run", "--release", "--quiet", "-p", "gmwm", "--example", "fit_timing", "--", str(n), str(runs)]
    print(f"running: {' '.join(cmd)}  (in {root})", flush=True)
    try:
        p = subprocess.run(cmd, cwd=root, capture_output=True, text=True, timeout=1800)
    except (OSError, subprocess.TimeoutExpired) as e:
        print(f"the Rust example did not run: {e}")
        return None
    hits = re.findall(r"^rust (.+?): .*median ([\d.]+) s, min ([\d.]+) s", p.stdout, re.M)
    if p.returncode != 0 or not hits:
        print(f"the Rust example failed (exit {p.returncode}):\n" + "\n".join((p.stdout + p.stderr).splitlines()[-10:]))
        return None
    return {what: (float(median), float(low)) for what, median, low in hits}


_PY_FITS = """
import sys
import numpy as np
import gmwm
from gmwm import _native
calls = int(sys.argv[1])
x = np.ascontiguousarray(gmwm.simulate(%r, n=%d, freq=%r, seed=%d), dtype=np.float64)
for _ in range(calls):
    _native.fit([x], ["x"], %r, %r, draws=%d)
"""


def _child_cpu(cmd: List[str], cwd: Optional[Path] = None) -> float:
    """CPU seconds (user + system, every thread) of one child process, from its rusage."""
    import resource

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run(cmd, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed: {p.stderr.strip()[-500:]}")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def bench_cpu(repeats: int, n: int, fits: int) -> Optional[Dict[str, float]]:
    """(a') CPU time per fit, Python native call against the Rust API, each in its own process.

    Wall times on a loaded machine mix in other work; the CPU time a process spends does not
    (only its cache and frequency conditions). Each side runs twice, with few and with many
    fits, and the difference over the extra fits is the CPU time of one fit: process start,
    imports, simulating the series and building the example cancel. The Rust example fits
    twice per run (the second time with the canonical reading and JSON document); the Python
    call always returns the document."""
    root = Path(__file__).resolve().parents[3]
    example = root / "target" / "release" / "examples" / "fit_timing"
    build = subprocess.run(["cargo", "build", "--release", "--quiet", "-p", "gmwm", "--example", "fit_timing"],
                           cwd=root, capture_output=True, text=True)
    if build.returncode != 0 or not example.exists():
        print(f"(a') skipped: the Rust example did not build: {build.stderr.strip()[-300:]}")
        return None
    script = _PY_FITS % (TRUTH, n, FREQ, SERIES_SEED, FREQ, MODEL, EXAMPLE_G)
    runs = fits // 2
    rust, py = [], []
    for _ in range(repeats):
        r0 = _child_cpu([str(example), str(n), "1"])
        r1 = _child_cpu([str(example), str(n), str(runs + 1)])
        p0 = _child_cpu([sys.executable, "-c", script, "0"])
        p1 = _child_cpu([sys.executable, "-c", script, str(2 * runs)])
        rust.append((r1 - r0) / (2 * runs))
        py.append((p1 - p0) / (2 * runs))
    ratios = [p / r for p, r in zip(py, rust)]
    rows = [
        ["Rust API (examples/fit_timing)", _fmt_s(statistics.median(rust)), f"{_fmt_s(min(rust))} .. {_fmt_s(max(rust))}", ""],
        ["Python _native.fit", _fmt_s(statistics.median(py)), f"{_fmt_s(min(py))} .. {_fmt_s(max(py))}",
         f"{100 * (statistics.median(ratios) - 1):+.1f} % (runs {', '.join(f'{100 * (r - 1):+.1f}' for r in ratios)})"],
    ]
    _table(
        f"(a') CPU time per fit (user + system, all threads), n={n:.0e}, model {MODEL}, G={EXAMPLE_G}: "
        f"{2 * runs} extra fits per process, {repeats} pairs of processes in turns",
        ["call", "median", "range", "Python against Rust"],
        rows,
    )
    return {"rust": statistics.median(rust), "python": statistics.median(py), "ratio": statistics.median(ratios)}


def bench_criterion(repeats: int, target_dir: Optional[str]) -> Optional[Dict[str, float]]:
    """The criterion cell against the native call and the wrapper on the same series."""
    root = Path(__file__).resolve().parents[3]
    cmd = ["cargo", "bench", "-p", "gmwm", "--bench", "fit", "--", "--exact", CRITERION_CELL]
    env = dict(os.environ)
    if target_dir:
        env["CARGO_TARGET_DIR"] = target_dir
    print(f"\nrunning: {' '.join(cmd)}  (in {root}; builds the bench first)", flush=True)
    p = subprocess.run(cmd, cwd=root, env=env, capture_output=True, text=True)
    out = p.stdout + p.stderr
    hit = re.search(r"time:\s+\[([\d.]+) (\w+) ([\d.]+) (\w+) ([\d.]+) (\w+)\]", out)
    if p.returncode != 0 or not hit:
        print(f"cargo bench failed (exit {p.returncode}); its last lines:\n" + "\n".join(out.splitlines()[-15:]))
        return None
    scale = {"ns": 1e-9, "us": 1e-6, "µs": 1e-6, "ms": 1e-3, "s": 1.0}
    low, mid, high = (float(hit.group(i)) * scale[hit.group(i + 1)] for i in (1, 3, 5))

    n = 1_000_000
    x = gmwm.simulate(CRITERION_TRUTH, n=n, freq=1.0, seed=4000 + n)
    t = _interleaved(
        {
            "native": lambda: _native.fit([x], ["x"], 1.0, "3*AR1()", draws=1000),
            "wrapper": lambda: gmwm.fit(x, freq=1.0, model="3*AR1()", G=1000),
        },
        repeats,
    )
    m = {"rust": mid, "native": statistics.median(t["native"]), "wrapper": statistics.median(t["wrapper"])}
    _table(
        f"(a') engine alone vs Python on the criterion cell {CRITERION_CELL} (3*AR1(), G=1000, n=1e6)",
        ["what", "time", "vs engine"],
        [
            ["Rust engine, Gmwm::fit (criterion estimate)", f"{_fmt_s(mid)} [{_fmt_s(low)} .. {_fmt_s(high)}]", "1.00x"],
            ["_native.fit (adds canonical form + JSON document)", _fmt_s(m["native"]), f"{m['native'] / mid:.3f}x"],
            ["gmwm.fit (adds json.loads + FitResult)", _fmt_s(m["wrapper"]), f"{m['wrapper'] / mid:.3f}x"],
        ],
    )
    return m


# ------------------------------------------------------------------------------------------
# (b) fleet scaling


def _write_fleet(root: Path, units: int, n: int) -> List[str]:
    paths = []
    for i in range(units):
        s2, g2 = 1e-4 * (1 + i % 4), 1e-9 * (1 + i % 3)
        x = gmwm.simulate(f"WN(sigma2={s2})+RW(gamma2={g2})", n=n, freq=FREQ, seed=500 + i)
        path = root / f"unit{i}.csv"
        np.savetxt(path, np.column_stack([np.arange(n) / FREQ, x]), delimiter=",",
                   header="time,gyro_x [rad/s]", comments="", fmt="%.17g")
        paths.append(str(path))
    return paths


def _run_fleet(paths, options, ref, client=None, max_workers=None) -> float:
    """Wall time of one `calibrate_many`, checked against the single calls `ref`."""
    t0 = time.perf_counter()
    fleet = gmwm.calibrate_many(paths, client, max_workers=max_workers, **options)
    wall = time.perf_counter() - t0
    assert not fleet.errors and len(fleet.results) == len(paths), fleet.errors
    assert {u: r.to_dict() for u, r in fleet.results.items()} == ref, "fleet != single calls"
    return wall


def _interleaved_values(fns: Dict[str, Callable[[], float]], repeats: int) -> Dict[str, List[float]]:
    """The values (times) the callables return, called in turns, the order rotating."""
    names = list(fns)
    out: Dict[str, List[float]] = {k: [] for k in names}
    for r in range(repeats):
        for k in names[r % len(names):] + names[: r % len(names)]:
            out[k].append(fns[k]())
    return out


_SERIAL = """
import json, sys, time, gmwm
paths, options = json.loads(sys.argv[1]), json.loads(sys.argv[2])
c0, t0 = time.process_time(), time.perf_counter()
gmwm.calibrate(paths[0], **options)
one_wall, one_cpu = time.perf_counter() - t0, time.process_time() - c0
t0 = time.perf_counter()
docs = {p: gmwm.calibrate(p, **options).to_dict() for p in paths}
print(json.dumps({"one_wall": one_wall, "one_cpu": one_cpu, "serial": time.perf_counter() - t0, "docs": docs}))
"""


def _serial(paths, options, env: Dict[str, str]) -> dict:
    """In a fresh process with exactly `env`: one calibration's wall and CPU time (the first,
    which is also the warm-up), then the calibrations one after the other."""
    out = subprocess.run(
        [sys.executable, "-c", _SERIAL, json.dumps(paths), json.dumps(options)],
        env=env, capture_output=True, text=True, check=True,
    )
    return json.loads(out.stdout)


def _rayon_threads():
    return os.environ.get("RAYON_NUM_THREADS")


def _dask_worker_env() -> Dict[str, str]:
    """What a dask nanny sets in its worker's environment (``distributed.nanny.pre-spawn-environ``,
    e.g. MALLOC_TRIM_THRESHOLD_=65536)."""
    import dask

    cfg = dask.config.get("distributed.nanny.pre-spawn-environ")
    return {k: str(v) for k, v in cfg.items() if v is not None}


@contextlib.contextmanager
def _exact_environ(env: Dict[str, str]):
    """os.environ is exactly `env` inside, and what it was before afterwards (a nanny writes its
    worker variables into the environment of the process that starts it and leaves them there,
    where spawned pool processes and subprocesses would inherit them)."""
    saved = dict(os.environ)
    os.environ.clear()
    os.environ.update(env)
    try:
        yield
    finally:
        os.environ.clear()
        os.environ.update(saved)


def bench_fleet(repeats: int, units: int, n: int, bootstrap: int, pool: bool, malloc_trim: bool) -> Dict[str, dict]:
    """Per engine-thread setting: the serial baselines and the runners with 1 and 2 workers."""
    import dask
    from dask.distributed import Client, LocalCluster

    options = dict(model=MODEL, bootstrap=bootstrap, G=1000)
    clean = dict(os.environ)
    cfg = {} if malloc_trim else {"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}
    with dask.config.set(cfg):
        worker_env = _dask_worker_env()
    report: Dict[str, dict] = {}
    with tempfile.TemporaryDirectory(prefix="gmwm-bench-") as tmp:
        paths = _write_fleet(Path(tmp), units, n)
        warm = paths[:2]
        # the engine parallelizes within a calibration (rayon, on every core unless
        # RAYON_NUM_THREADS says otherwise): measured as it comes, and with one thread a worker
        for threads, env in (("all cores", {}), ("1", {"RAYON_NUM_THREADS": "1"})):
            base = _serial(paths, options, {**clean, **env})
            base_dask_env = _serial(paths, options, {**clean, **worker_env, **env})
            ref = {Path(p).stem: d for p, d in base["docs"].items()}
            assert {Path(p).stem: d for p, d in base_dask_env["docs"].items()} == ref
            runners: Dict[str, Callable[[], float]] = {}
            with _exact_environ(clean), dask.config.set(cfg), contextlib.ExitStack() as stack:
                # both clusters up at once, their runs taken in turns with the pool's, so that
                # other load on the machine falls on every configuration alike
                for workers in (1, 2):
                    cluster = stack.enter_context(LocalCluster(
                        n_workers=workers, threads_per_worker=1, processes=True, env=env,
                        dashboard_address=":0", silence_logs=logging.ERROR))
                    client = stack.enter_context(Client(cluster))
                    client.wait_for_workers(workers, timeout=120)
                    got = client.run(_rayon_threads)
                    assert set(got.values()) == {env.get("RAYON_NUM_THREADS")}, got
                    gmwm.calibrate_many(warm * workers, client, **{**options, "bootstrap": 10})
                    runners[f"dask {workers}"] = functools.partial(_run_fleet, paths, options, ref, client=client)
                if pool:
                    # the pool's spawned processes inherit this process' environment: the clean
                    # one, not the nanny's leftovers
                    stack.enter_context(_exact_environ({**clean, **env}))
                    for workers in (1, 2):
                        runners[f"pool {workers}"] = functools.partial(
                            _run_fleet, paths, options, ref, max_workers=workers)
                results = _interleaved_values(runners, repeats)
            report[threads] = {"base": base, "base_dask_env": base_dask_env, "times": results}

    trim = worker_env.get("MALLOC_TRIM_THRESHOLD_")
    rows = []
    for threads, r in report.items():
        base, results = r["base"], r["times"]
        med = {k: statistics.median(v) for k, v in results.items()}
        order = sorted(results, key=lambda k: (k.split()[0] != "dask", k))
        rows.append([threads, f"{base['one_wall']:.3f} s / {base['one_cpu']:.3f} s",
                     "serial, one process", "-", _fmt_s(base["serial"]), "", ""])
        rows.append(["", f"{r['base_dask_env']['one_wall']:.3f} s / {r['base_dask_env']['one_cpu']:.3f} s",
                     "serial, dask worker env", "-", _fmt_s(r["base_dask_env"]["serial"]), "", ""])
        for k in order:
            v = results[k]
            kind, w = k.split()
            rows.append([
                "", "", "dask LocalCluster" if kind == "dask" else "process pool (spawn)", w,
                _fmt_s(med[k]), " ".join(f"{t:.2f}" for t in v), f"{med[f'{kind} 1'] / med[k]:.2f}x",
            ])
        r["medians"] = med
    _table(
        f"(b) fleet scaling: {units} recordings x {n} samples at {FREQ:g} Hz, calibrate(model={MODEL}, "
        f"bootstrap={bootstrap}, G=1000); workers are processes of 1 thread; {repeats} runs each, "
        "the configurations taken in turns",
        ["engine threads", "one calib. wall / CPU", "runner", "workers", "median wall", "runs (s)",
         "speed-up 1 -> 2"],
        rows,
    )
    print("  serial, one process: this environment; serial, dask worker env: with what a dask nanny "
          f"sets for its workers ({', '.join(f'{k}={v}' for k, v in worker_env.items())})")
    if trim is not None:
        print(f"  (MALLOC_TRIM_THRESHOLD_={trim} makes glibc map and unmap the engine's large buffers on "
              "every allocation; --no-malloc-trim starts the workers without it)")
    return report


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer runs, smaller work (a smoke run)")
    ap.add_argument("--repeats", type=int, default=None, help="runs per measurement (default 7, fleet 3)")
    ap.add_argument("--G", type=int, default=EXAMPLE_G,
                    help=f"starting-value draws of the fit (default {EXAMPLE_G}, that of the Rust example)")
    ap.add_argument("--fleet-bootstrap", type=int, default=2000,
                    help="bootstrap of each fleet calibration (default 2000: ~1 s a recording)")
    ap.add_argument("--pool", action="store_true", help="also the process pool (no client) in (b)")
    ap.add_argument("--no-malloc-trim", action="store_true",
                    help="(b): start the dask workers without dask's MALLOC_TRIM_THRESHOLD_")
    ap.add_argument("--no-overhead", action="store_true", help="skip (a)")
    ap.add_argument("--no-fleet", action="store_true", help="skip (b)")
    ap.add_argument("--no-rust", action="store_true", help="skip the Rust example (cargo run) in (a)")
    ap.add_argument("--criterion", action="store_true", help="also run the criterion cell (cargo bench)")
    ap.add_argument("--cargo-target-dir", default=None, help="CARGO_TARGET_DIR for --criterion")
    args = ap.parse_args(argv)

    repeats = args.repeats or (3 if args.quick else 7)
    fleet_repeats = args.repeats or (1 if args.quick else 3)
    print(f"gmwm {gmwm.__version__}, Python {platform.python_version()}, numpy {np.__version__}, "
          f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f} at start", flush=True)

    if not args.no_overhead:
        bench_overhead(repeats, args.G, n=1_000_000, tiny_n=512, tiny_rounds=50 if args.quick else 400,
                       rust=not args.no_rust)
        if not args.no_rust:
            bench_cpu(max(3, repeats // 2), n=1_000_000, fits=10 if args.quick else 40)
    if args.criterion:
        bench_criterion(repeats, args.cargo_target_dir)
    if not args.no_fleet:
        bench_fleet(fleet_repeats, units=8, n=2**15,
                    bootstrap=200 if args.quick else args.fleet_bootstrap, pool=args.pool, malloc_trim=not args.no_malloc_trim)
    print(f"\nload average {os.getloadavg()[0]:.2f} at the end (other work on the machine skews the times)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
