#!/usr/bin/env python3
"""End-to-end speed bench of the `gmwm` command line (issue 14; the goals of issue 32).

Whole-command wall times, as a user sees them (process start, reading the file, the
computation, writing the output), measured side by side in one run against peers:
allantools in a whole Python process, the R package gmwm 3.0.0 (live if it is installed,
else the reference timings of ``shared/ref``), and gmwm's own in-memory path. Each command
runs ``--repeat`` times (default 3), taken in turns with its peer so that load on the machine
falls on both alike; the table shows the median (and the minimum), the ratio peer / gmwm
(so ``30x`` means gmwm is 30 times faster), the goal of issue 14 and whether the medians
meet it. A command that exits non-zero is reported as failed, not timed. This is a
measurement script: it never asserts, and its exit code is 0 whenever it ran.

Rows (ids for ``--only``):

  wv1e7          gmwm wv FILE --format f64 --freq 1 --json on 1e7 raw f64 (white noise)
                 vs allantools oadev(y, rate=1, data_type='freq', taus='octave') on the same
                 values, whole Python process (numpy.fromfile + oadev).   goal: ratio >= 40x
  stream1e6      gmwm wv on 1e6 raw f64 (the streaming path: raw binary, classical Haar
                 MODWT, no time column) vs gmwm wv on the same values in a 2-column raw file
                 whose first column is a time column (--time-column 1): a time column turns
                 streaming off (crates/gmwm-cli/src/cmd/wv.rs, `streamable`), so that command
                 loads the series and runs the in-memory kernel. Both are whole commands; the
                 in-memory one reads twice the bytes (the time column) and checks the stamps.
                 The two WVs are compared.                                 goal: within 1.5x
  stream1e6_kernel  (only with --kernel-bench) the same streaming command vs the in-memory
                 kernel alone: the criterion cell wv/haar-modwt/1000000 of
                 `cargo bench -p gmwm --bench variance` (builds the bench; seeded white noise
                 of the same length, no process start, no reading).        goal: within 1.5x
  fit_exact      gmwm fit FILE --format f64 --freq 1 --model "<3*AR1 truth with values>" on
                 N = 1e6 simulated by `gmwm simulate --seed 4005` (the truth of
                 timings_gmwm_3gm.json), vs R gmwm_imu(truth, x).          goal: ratio >= 100x
  fit_g          the same with --model "3*AR1()" --G 20000, vs R gmwm_imu(3*GM(), x,
                 G = 20000).                                               goal: ratio >= 100x
  robust_exact   fit_exact with --robust --eff 0.6, vs R robust = TRUE.     goal: ratio >= 100x
  robust_g       fit_g with --robust --eff 0.6, vs R robust = TRUE.         goal: ratio >= 100x
  inference      asymptotic inference at N = 1e6: (gmwm fit ... --inference) - (gmwm fit ...)
                 with the exact start (--inference is the sandwich with the exact V of the
                 fitted model, --covariance bootstrap the package's 100-replicate V;
                 --bootstrap B would be bootstrap inference), vs R summary(m, inference =
                 TRUE).                                                     goal: <= 1 s
  fit_adis       gmwm fit adis_16405_imu1.csv.gz --columns gyro_x --model "2*GM()+WN()+RW()"
                 --inference, whole command, vs R gmwm_imu + summary(inference = TRUE) on
                 the same column.                                           goal: <= 1 s
  select6        gmwm select adis_16405_imu1.csv.gz --model "3*AR1()+WN()+RW()+QN()+DR()"
                 (six axes, 63 candidates each) vs R auto_imu(x[, 1], 3*AR1()+WN()+RW()+QN())
                 (ONE axis, 31 candidates).                                 goal: <= 1 s
  select_boot    the same on --columns gyro_x with --optimism bootstrap; no R peer (no
                 reference timing of auto_imu(bootstrap = TRUE)).          goal: <= 10 s
  calib1e8       (only when asked: --only calib1e8) writes a 10^8-sample raw f64 file (800
                 MB: white noise sd 1e-3 plus a random walk of step sd 1e-6, numpy
                 default_rng(8), sidecar gyro_x at 100 Hz) and times `gmwm calibrate FILE
                 --format f64`; also its peak RSS (GNU time). goal: <= 2 s and <= 128 MB
  calib1e9       (only when asked: --only calib1e9) the same with 10^9 samples (8 GB of disk
                 in the work directory), and the WN density beside that of the file's first
                 10^8 samples (copied to a prefix file, calibrated untimed).
                                                            goal: <= 25 s and <= 200 MB

Peers. allantools runs in ``--peer-python`` (default: this interpreter); when it cannot import
allantools the row is skipped with the install command (``--install-peers`` pip-installs it).
R runs live when ``Rscript -e 'library(gmwm)'`` succeeds (``--r auto``, the default), with the
calls of shared/ref/README.md timed inside R by system.time (data already in memory, R start
not counted, as in the reference files); otherwise, or if a live R call fails, the peer is the
reference file's median, labelled "R (ref file, same machine kind)": a 2-core AMD EPYC VM, R
4.2.2, gmwm 3.0.0, reference BLAS. fit_adis, select6 live need the R package imudata.

Work files (1e7 and 1e6 white noise from numpy's default_rng, seeded; the 3*AR1 series from
`gmwm simulate`; every command's stdout and stderr) go to a temporary directory, removed at the
end unless ``--workdir DIR`` is given.

Examples:
  python3 bench/e2e.py                              # every row, 3 runs each
  python3 bench/e2e.py --only wv1e7,fit_adis --repeat 1 --verbose
  python3 bench/e2e.py --json e2e.json --workdir /tmp/e2e
  /path/to/venv/bin/python bench/e2e.py --only wv1e7   # allantools from a venv
  python3 bench/e2e.py --list                       # the rows and their commands, nothing run

Needs Python >= 3.9 and numpy; allantools (optional) for wv1e7; the release binary
(``cargo build --release -p gmwm-cli``).
"""

from __future__ import annotations

import argparse
import datetime as _dt
import importlib.util
import json
import os
import platform
import re
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

REPO = Path(__file__).resolve().parent.parent

ROW_IDS = [
    "wv1e7",
    "stream1e6",
    "fit_exact",
    "fit_g",
    "robust_exact",
    "robust_g",
    "inference",
    "fit_adis",
    "select6",
    "select_boot",
]
OPTIONAL_ROW_IDS = ["stream1e6_kernel", "calib1e8", "calib1e9"]
# GNU time, for the peak RSS of a command (see `measure`); wait4 alone when it is missing
GNU_TIME = shutil.which("time", path="/usr/bin:/bin")
RSS_MARK = "gmwm-bench-peak-rss-kb "
BIG_N = 100_000_000
HUGE_N = 1_000_000_000
BIG_SEED = 8

# the truth of shared/ref/timings_gmwm_3gm.json (paper Tab. II/III) in AR1 form at 1 Hz
TRUTH_3AR1 = "AR1(phi=0.9, sigma2=1)+AR1(phi=0.99, sigma2=0.1)+AR1(phi=0.999, sigma2=0.01)"
SIM_SEED = 4005  # timings_gmwm_3gm.json: seed 4000 + k, k = 5 for N = 1e6
SELECT_MODEL = "3*AR1()+WN()+RW()+QN()+DR()"
ADIS = "adis_16405_imu1.csv.gz"
WHITE_SEED = 14  # issue 14
CRITERION_CELL = "wv/haar-modwt/1000000"

ALLANTOOLS_CODE = (
    "import sys, numpy as np, allantools; "
    "y = np.fromfile(sys.argv[1], dtype='<f8'); "
    "allantools.oadev(y, rate=1.0, data_type='freq', taus='octave')"
)

R_TRUTH_GM = (
    "GM(beta = -log(0.9), sigma2_gm = 1/(1-0.9^2)) + "
    "GM(beta = -log(0.99), sigma2_gm = 0.1/(1-0.99^2)) + "
    "GM(beta = -log(0.999), sigma2_gm = 0.01/(1-0.999^2))"
)


def log(msg: str = "") -> None:
    print(msg, file=sys.stderr, flush=True)


# ------------------------------------------------------------------------------------------
# formatting


def fmt_s(t: Optional[float]) -> str:
    if t is None:
        return "—"
    if t < 0:
        return f"{t * 1e3:.1f} ms"
    if t < 1e-3:
        return f"{t * 1e6:.0f} µs"
    if t < 1.0:
        return f"{t * 1e3:.1f} ms" if t < 0.1 else f"{t * 1e3:.0f} ms"
    if t < 100:
        return f"{t:.2f} s"
    return f"{t:.0f} s"


def fmt_ratio(r: Optional[float]) -> str:
    if r is None:
        return "—"
    if r >= 100:
        return f"{r:.0f}×"
    if r >= 10:
        return f"{r:.1f}×"
    return f"{r:.2f}×"


# ------------------------------------------------------------------------------------------
# running and timing commands


class Timed:
    """One command timed `repeat` times: wall seconds per run, or the seconds an R script
    printed (`ELAPSED x`) when `metric` is "r_elapsed"."""

    def __init__(self, label: str, argv: List[str], metric: str = "wall", cwd: Optional[Path] = None):
        self.label = label
        self.argv = argv
        self.metric = metric
        self.cwd = cwd
        self.runs: List[float] = []
        self.wall: List[float] = []
        self.max_rss_mb: List[float] = []
        self.measure_rss = False             # peak RSS of the command itself (GNU time)
        self.status = "pending"
        self.rc: Optional[int] = None
        self.error = ""
        self.out_path: Optional[Path] = None

    @property
    def cmd(self) -> str:
        return shlex.join(self.argv)

    @property
    def median(self) -> Optional[float]:
        return statistics.median(self.runs) if self.status == "ok" and self.runs else None

    @property
    def minimum(self) -> Optional[float]:
        return min(self.runs) if self.status == "ok" and self.runs else None

    def to_json(self) -> Dict[str, Any]:
        return {
            "label": self.label,
            "command": self.cmd,
            "metric": self.metric,
            "status": self.status,
            "exit_code": self.rc,
            "runs_s": self.runs,
            "wall_s": self.wall,
            "median_s": self.median,
            "min_s": self.minimum,
            "max_rss_mb": self.max_rss_mb,
            "error": self.error or None,
        }


def run_once(t: Timed, outdir: Path, timeout: float, verbose: bool) -> Optional[float]:
    """Runs the command once; returns its time, or None (and marks `t` failed)."""
    stem = re.sub(r"[^A-Za-z0-9_.-]+", "_", t.label)
    out_path, err_path = outdir / f"{stem}.out", outdir / f"{stem}.err"
    t.out_path = out_path
    with open(out_path, "wb") as out, open(err_path, "wb") as err:
        # No `timeout=` on the wait: with one, CPython polls the child with sleeps of up to
        # 50 ms, which rounds every time up to its polling grid. A timer kills a runaway
        # command instead, and the wait itself blocks until the child exits.
        start = time.perf_counter()
        # Linux keeps a process's peak RSS across execve, and a child forked from this Python
        # process starts with Python's pages (hundreds of MB once the work files are written):
        # wait4 on it would report those. GNU time, itself small, forks the command and
        # reports the command's own peak.
        argv = t.argv
        if t.measure_rss and GNU_TIME:
            argv = [GNU_TIME, "-f", RSS_MARK + "%M"] + argv
        try:
            p = subprocess.Popen(argv, stdout=out, stderr=err, stdin=subprocess.DEVNULL, cwd=t.cwd)
        except OSError as e:
            t.status, t.error = "failed", f"could not start: {e}"
            return None
        killer = threading.Timer(timeout, p.kill)
        killer.start()
        try:
            # wait4: the child's peak resident set size comes with its exit status
            _, status, usage = os.wait4(p.pid, 0)
            p.returncode = os.waitstatus_to_exitcode(status)
        finally:
            killer.cancel()
        wall = time.perf_counter() - start
        if wall >= timeout:
            t.status, t.error = "failed", f"timed out after {timeout:g} s"
            return None
    t.rc = p.returncode
    if p.returncode != 0:
        tail = err_path.read_text(errors="replace").strip().splitlines()[-5:]
        t.status, t.error = "failed", f"exit code {p.returncode}: " + " | ".join(tail)
        return None
    value = wall
    if t.metric == "r_elapsed":
        hit = re.search(r"^ELAPSED ([0-9.eE+-]+)", out_path.read_text(errors="replace"), re.M)
        if not hit:
            t.status, t.error = "failed", "the R script printed no ELAPSED line"
            return None
        value = float(hit.group(1))
    t.wall.append(wall)
    rss_kb = usage.ru_maxrss  # Linux: kilobytes
    if t.measure_rss and GNU_TIME:
        marks = re.findall(RSS_MARK + r"(\d+)", err_path.read_text(errors="replace"))
        rss_kb = int(marks[-1]) if marks else None
    if rss_kb is not None:
        t.max_rss_mb.append(rss_kb / 1024.0)
    if verbose:
        extra = f" (Rscript process {fmt_s(wall)})" if t.metric == "r_elapsed" else ""
        log(f"    {t.label}: {fmt_s(value)}{extra}")
    return value


def measure(cmds: Sequence[Timed], repeat: int, warmup: int, outdir: Path, timeout: float,
            verbose: bool) -> None:
    """Warm-up runs (untimed), then `repeat` rounds in which every command runs once in turn."""
    for t in cmds:
        if verbose:
            log(f"  $ {t.cmd}" + (f"   (in {t.cwd})" if t.cwd else ""))
    for t in cmds:
        for _ in range(warmup if t.metric == "wall" else 0):
            if run_once(t, outdir, timeout, False) is None:
                t.error = "warm-up run: " + t.error
                break
        t.wall.clear()
    for _ in range(repeat):
        for t in cmds:
            if t.status == "failed":
                continue
            v = run_once(t, outdir, timeout, verbose)
            if v is not None:
                t.runs.append(v)
    for t in cmds:
        if t.status != "failed":
            t.status = "ok"
        else:
            log(f"  FAILED: {t.cmd}\n          {t.error}")


# ------------------------------------------------------------------------------------------
# peers


def python_has(py: str, module: str) -> Tuple[bool, str]:
    try:
        p = subprocess.run([py, "-c", f"import {module}; print(getattr({module}, '__version__', '?'))"],
                           capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired) as e:
        return False, str(e)
    if p.returncode == 0:
        return True, p.stdout.strip()
    return False, (p.stderr.strip().splitlines() or ["?"])[-1]


def ensure_allantools(py: str, install: bool) -> Tuple[bool, str]:
    ok, version = python_has(py, "allantools")
    if ok or not install:
        return ok, version
    log(f"installing allantools: {py} -m pip install allantools")
    p = subprocess.run([py, "-m", "pip", "install", "allantools"], capture_output=True, text=True)
    if p.returncode != 0:
        log("pip install failed (an externally managed Python?); its last lines:\n  "
            + "\n  ".join((p.stdout + p.stderr).strip().splitlines()[-4:]))
    return python_has(py, "allantools")


def allantools_hint(py: str) -> str:
    return (f"allantools is not importable by {py}: `{py} -m pip install allantools` (or "
            "`python3 -m venv /tmp/bench-venv && /tmp/bench-venv/bin/pip install allantools numpy` "
            "and run this script with /tmp/bench-venv/bin/python, or pass --peer-python), "
            "or rerun with --install-peers")


def r_available(rscript: str) -> Tuple[bool, str]:
    if shutil.which(rscript) is None:
        return False, f"{rscript} not found"
    try:
        p = subprocess.run([rscript, "-e", "suppressPackageStartupMessages(library(gmwm)); "
                            "cat(as.character(packageVersion('gmwm')))"],
                           capture_output=True, text=True, timeout=300)
    except (OSError, subprocess.TimeoutExpired) as e:
        return False, str(e)
    if p.returncode != 0:
        return False, "library(gmwm) failed: " + " ".join(p.stderr.strip().splitlines()[-2:])
    return True, p.stdout.strip()


def r_script(body: str) -> str:
    """One line of R (statements joined by '; ') that prints `ELAPSED <seconds>`."""
    lines = ["suppressPackageStartupMessages(library(gmwm))"] + body.splitlines() \
        + ['cat(sprintf("ELAPSED %.6f\\n", e))']
    return "; ".join(line.strip() for line in lines if line.strip())


def r_imudata(body: str) -> str:
    return r_script(
        "suppressPackageStartupMessages(library(imudata))\n"
        "data(adis_16405_imu1, package = \"imudata\")\n"
        "x <- adis_16405_imu1\n" + body)


def r_sim(path: Path, n: int, body: str) -> str:
    return r_script(
        f'x <- readBin({json.dumps(str(path))}, what = "double", n = {n}, size = 8, endian = "little")\n'
        f"truth <- {R_TRUTH_GM}\n" + body)


class RefFiles:
    """The R reference timings of shared/ref (medians, and the runs when recorded)."""

    def __init__(self, ref_dir: Path):
        self.dir = ref_dir
        self.cache: Dict[str, Any] = {}

    def load(self, name: str) -> Optional[Any]:
        if name not in self.cache:
            try:
                self.cache[name] = json.loads((self.dir / name).read_text())
            except (OSError, ValueError):
                self.cache[name] = None
        return self.cache[name]

    def gmwm_3gm(self, kind: str, start: str) -> Optional[Tuple[float, float, str]]:
        d = self.load("timings_gmwm_3gm.json")
        try:
            cell = d["measured"][kind][start]["N1000000"]
            return cell["median_s"], min(cell["runs_s"]), f"timings_gmwm_3gm.json measured.{kind}.{start}.N1000000"
        except (TypeError, KeyError, ValueError):
            return None

    def adis_summary(self) -> Optional[Tuple[float, float, str]]:
        """summary(m, inference = TRUE) at N = 1e6, classical, of the three gyro_x GM fits."""
        d = self.load("gmwm_adis_16405_imu1_gyro_x.json")
        try:
            vals = {k: v["gm"]["summary"]["elapsed_s"] for k, v in d["fits"].items() if "classical" in k}
        except (TypeError, KeyError):
            return None
        if not vals:
            return None
        lo = min(vals.values())
        return lo, lo, ("gmwm_adis_16405_imu1_gyro_x.json fits[* | classical].gm.summary.elapsed_s: "
                        + ", ".join(f"{k.split(' |')[0]} {v:.1f} s" for k, v in vals.items())
                        + f"; the smallest ({lo:.1f} s) is used")

    def adis_fit_inference(self) -> Optional[Tuple[float, float, str]]:
        d = self.load("gmwm_adis_16405_imu1_gyro_x.json")
        try:
            gm = d["fits"]["2*GM()+WN()+RW() | classical"]["gm"]
            fit, summ = gm["fit_elapsed_s"], gm["summary"]["elapsed_s"]
        except (TypeError, KeyError):
            return None
        t = fit + summ
        return t, t, (f"gmwm_adis_16405_imu1_gyro_x.json fits['2*GM()+WN()+RW() | classical'].gm: "
                      f"fit_elapsed_s {fit:.2f} + summary.elapsed_s {summ:.2f} (one run each)")

    def auto_imu(self) -> Optional[Tuple[float, float, str]]:
        d = self.load("auto_imu_adis_16405_imu1_gyro_x.json")
        try:
            t = d["auto_imu"]["elapsed_s"]
        except (TypeError, KeyError):
            return None
        return t, t, "auto_imu_adis_16405_imu1_gyro_x.json auto_imu.elapsed_s (one run)"


# ------------------------------------------------------------------------------------------
# work files


def write_white(path: Path, n: int, seed: int) -> None:
    import numpy as np
    if path.exists() and path.stat().st_size == 8 * n and path.with_suffix(".seed").exists() \
            and path.with_suffix(".seed").read_text() == str(seed):
        return
    rng = np.random.default_rng(seed)
    chunk = 1 << 22
    with open(path, "wb") as f:
        left = n
        while left:
            k = min(chunk, left)
            rng.standard_normal(k).astype("<f8").tofile(f)
            left -= k
    path.with_suffix(".seed").write_text(str(seed))


def write_time_and_value(src: Path, dst: Path) -> None:
    """A 2-column raw f64 file: time stamps 0, 1, 2, ... s and the values of `src`."""
    import numpy as np
    x = np.fromfile(src, dtype="<f8")
    two = np.empty((x.size, 2), dtype="<f8")
    two[:, 0] = np.arange(x.size, dtype="<f8")
    two[:, 1] = x
    two.tofile(dst)


def simulate_3ar1(gmwm: str, path: Path, n: int) -> Optional[str]:
    cmd = [gmwm, "simulate", "--model", TRUTH_3AR1, "--n", str(n), "--seed", str(SIM_SEED), "-o", str(path)]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0 or not path.exists():
        return f"`{shlex.join(cmd)}` failed (exit {p.returncode}): {p.stderr.strip()[-300:]}"
    return None


# ------------------------------------------------------------------------------------------
# rows


class Goal:
    def __init__(self, kind: str, value: float):
        self.kind, self.value = kind, value  # ratio_min | within | max_s

    def text(self) -> str:
        if self.kind == "ratio_min":
            return f"≥ {self.value:g}×"
        if self.kind == "within":
            return f"within {self.value:g}×"
        return f"≤ {self.value:g} s"

    def met(self, gmwm_s: Optional[float], peer_s: Optional[float]) -> Optional[bool]:
        if gmwm_s is None:
            return None
        if self.kind == "max_s":
            return gmwm_s <= self.value
        if peer_s is None:
            return None
        if self.kind == "ratio_min":
            return peer_s / gmwm_s >= self.value
        return gmwm_s <= self.value * peer_s


class Row:
    def __init__(self, rid: str, work: str, goal: Goal):
        self.id, self.work, self.goal = rid, work, goal
        self.gmwm: List[Timed] = []          # timed gmwm commands
        self.peer: List[Timed] = []          # timed peer commands (live)
        self.gmwm_value: Optional[Tuple[Optional[float], Optional[float]]] = None  # median, min
        self.peer_value: Optional[Tuple[Optional[float], Optional[float]]] = None
        self.peer_label = "—"
        self.peer_source = ""                # live | ref | none | skipped | failed
        self.status = "ok"                   # ok | skipped | failed
        self.notes: List[str] = []
        # combine gmwm timings (default: the only command) and live peer timings
        self.combine: Callable[[List[Timed]], Tuple[Optional[float], Optional[float]]] = single
        self.combine_peer: Callable[[List[Timed]], Tuple[Optional[float], Optional[float]]] = single
        self.after: Optional[Callable[["Row"], None]] = None
        self.ref_fallback: Optional[Tuple[float, float, str]] = None  # for a live R peer that fails
        self.criterion = False
        self.heavy = False                   # no warm-up runs (they would take as long as a timed run)
        self.rss_max_mb: Optional[float] = None  # a peak-RSS goal beside the time goal

    def finish(self) -> None:
        if self.status == "skipped":
            return
        if any(t.status == "failed" for t in self.gmwm):
            self.status = "failed"
            self.gmwm_value = (None, None)
        else:
            self.gmwm_value = self.combine(self.gmwm)
        if self.peer:
            if any(t.status == "failed" for t in self.peer):
                errors = "; ".join(t.error for t in self.peer if t.error)
                if self.ref_fallback is not None:
                    ref = self.ref_fallback
                    self.peer_value = (ref[0], ref[1])
                    self.peer_label = "R (ref file, same machine kind)"
                    self.peer_source = "ref"
                    self.notes.append(f"R live failed ({errors}): peer from {ref[2]}")
                else:
                    self.peer_source = "failed"
                    self.peer_value = None
                    self.notes.append("peer failed: " + errors)
            else:
                self.peer_value = self.combine_peer(self.peer)
                self.peer_source = "live"
        if self.after and self.status == "ok":
            try:
                self.after(self)
            except Exception as e:  # a check must never stop the measurement
                self.notes.append(f"check failed: {e}")

    @property
    def ratio(self) -> Optional[float]:
        g = self.gmwm_value[0] if self.gmwm_value else None
        p = self.peer_value[0] if self.peer_value else None
        if g is None or p is None or g <= 0:
            return None
        return p / g

    @property
    def met(self) -> Optional[bool]:
        if self.status != "ok":
            return None
        g = self.gmwm_value[0] if self.gmwm_value else None
        p = self.peer_value[0] if self.peer_value else None
        met = self.goal.met(g, p)
        rss = self.peak_rss_mb
        if met is not None and self.rss_max_mb is not None:
            met = met and rss is not None and rss <= self.rss_max_mb
        return met

    @property
    def peak_rss_mb(self) -> Optional[float]:
        """The largest peak RSS over the gmwm runs."""
        values = [v for t in self.gmwm for v in t.max_rss_mb]
        return max(values) if values else None

    def cells(self) -> List[str]:
        if self.status == "skipped":
            gm = "skipped"
        elif self.status == "failed":
            gm = "failed"
        else:
            med, lo = self.gmwm_value or (None, None)
            gm = f"{fmt_s(med)} (min {fmt_s(lo)})"
            if self.rss_max_mb is not None and self.peak_rss_mb is not None:
                gm += f", peak RSS {self.peak_rss_mb:.0f} MB"
        if self.peer_value and self.peer_value[0] is not None:
            med, lo = self.peer_value
            pc = f"{fmt_s(med)} {self.peer_label}"
        elif self.peer_source == "failed":
            pc = f"failed ({self.peer_label})"
        elif self.peer_source == "skipped":
            pc = f"skipped ({self.peer_label})"
        else:
            pc = self.peer_label
        met = self.met
        return [self.work, gm, pc, fmt_ratio(self.ratio), self.goal.text(),
                "—" if met is None else ("yes" if met else "no")]

    def to_json(self) -> Dict[str, Any]:
        g = self.gmwm_value or (None, None)
        p = self.peer_value or (None, None)
        return {
            "id": self.id,
            "work": self.work,
            "status": self.status,
            "gmwm": {"median_s": g[0], "min_s": g[1], "commands": [t.to_json() for t in self.gmwm]},
            "peer": {"label": self.peer_label, "source": self.peer_source, "median_s": p[0], "min_s": p[1],
                     "commands": [t.to_json() for t in self.peer]},
            "ratio_peer_over_gmwm": self.ratio,
            "goal": {"kind": self.goal.kind, "value": self.goal.value, "text": self.goal.text(),
                     "max_rss_mb": self.rss_max_mb},
            "peak_rss_mb": self.peak_rss_mb,
            "met": self.met,
            "notes": self.notes,
        }


def single(ts: List[Timed]) -> Tuple[Optional[float], Optional[float]]:
    return ts[0].median, ts[0].minimum


def difference(ts: List[Timed]) -> Tuple[Optional[float], Optional[float]]:
    """ts[0] - ts[1] (fit --inference minus the plain fit): of the medians and of the minima."""
    a, b = ts
    if a.median is None or b.median is None:
        return None, None
    return a.median - b.median, a.minimum - b.minimum


def compare_wv_outputs(row: Row) -> None:
    a = json.loads(row.gmwm[0].out_path.read_text())["series"][0]["wv"]
    b = json.loads(row.peer[0].out_path.read_text())["series"][0]["wv"]
    if len(a) != len(b):
        row.notes.append(f"the two WVs have {len(a)} and {len(b)} scales")
        return
    rel = max(abs(x - y) / max(abs(y), 1e-300) for x, y in zip(a, b))
    row.notes.append(f"streaming and in-memory WV agree on all {len(a)} scales to a relative {rel:.1e}")


# ------------------------------------------------------------------------------------------


def build_rows(args: argparse.Namespace, wanted: List[str], work: Path, gmwm: str,
               refs: RefFiles, r_live: bool, prepare: bool = True) -> List[Row]:
    """The rows asked for, with their commands; with `prepare`, also writes their work files
    and checks the peers (without it, for --list, nothing is written or run)."""
    rows: List[Row] = []
    data = Path(args.data_dir)
    adis = data / ADIS
    py = args.peer_python
    ref_label = "R (ref file, same machine kind)"

    need_sim = any(r in wanted for r in ("fit_exact", "fit_g", "robust_exact", "robust_g", "inference"))
    sim_path = work / "sim3ar1_1e6.f64"
    sim_error = None
    if need_sim and prepare:
        log(f"simulating {TRUTH_3AR1}, N = 1e6, seed {SIM_SEED} -> {sim_path}")
        sim_error = simulate_3ar1(gmwm, sim_path, 1_000_000)
        if sim_error:
            log("  " + sim_error)

    def r_peer(row: Row, script: str, ref: Optional[Tuple[float, float, str]], live_label: str) -> None:
        """Live R (if available; on failure the reference value) or the reference file."""
        if r_live:
            row.peer.append(Timed(f"{row.id}.R", [args.rscript, "-e", script], metric="r_elapsed"))
            row.peer_label = f"R live ({live_label}; in-R system.time)"
            row.peer_source = "live"
            row.ref_fallback = ref
        elif ref is not None:
            row.peer_value = (ref[0], ref[1])
            row.peer_label = ref_label
            row.peer_source = "ref"
            row.notes.append("peer: " + ref[2] + f"; call: {live_label}")
        else:
            row.peer_label = "— (no R and no reference value)"
            row.peer_source = "none"

    for rid in wanted:
        if rid == "wv1e7":
            row = Row(rid, "Haar WV, 1e7 raw f64 (`gmwm wv --format f64`) vs allantools `oadev` (octave taus), whole process",
                      Goal("ratio_min", 40))
            path = work / "white_1e7.f64"
            row.gmwm.append(Timed("wv1e7.gmwm", [gmwm, "wv", str(path), "--format", "f64", "--freq", "1", "--json"]))
            ok, version = ensure_allantools(py, args.install_peers) if prepare else (True, "?")
            if prepare and ok:
                log(f"writing 1e7 white noise (numpy default_rng({WHITE_SEED})) -> {path}")
                write_white(path, 10_000_000, WHITE_SEED)
            row.peer_label = "allantools oadev, whole Python process"
            if ok:
                row.peer.append(Timed("wv1e7.allantools", [py, "-c", ALLANTOOLS_CODE, str(path)]))
                row.notes.append(f"peer: allantools {version} in {py}")
            else:
                row.status = "skipped"
                row.peer_source = "skipped"
                row.peer_label = "allantools not installed"
                row.notes.append(allantools_hint(py))
                ref = refs.load("allantools_compare.json")
                try:
                    t = ref["timings"]["oadev_N10000000"]["median_s"]
                    row.notes.append(f"for context, allantools_compare.json has oadev N = 1e7 in-process: {t:.2f} s")
                except (TypeError, KeyError):
                    pass
            rows.append(row)

        elif rid in ("stream1e6", "stream1e6_kernel"):
            path = work / "white_1e6.f64"
            if prepare:
                write_white(path, 1_000_000, WHITE_SEED + 1)
            stream = [gmwm, "wv", str(path), "--format", "f64", "--freq", "1", "--json"]
            if rid == "stream1e6":
                row = Row(rid, "`gmwm wv` streaming, 1e6 raw f64, vs the in-memory path on the same values (whole commands)",
                          Goal("within", 1.5))
                two = work / "white_1e6_time.f64"
                if prepare:
                    write_time_and_value(path, two)
                row.gmwm.append(Timed("stream1e6.streaming", stream))
                row.peer.append(Timed("stream1e6.in_memory", [
                    gmwm, "wv", str(two), "--format", "f64", "--ncols", "2", "--time-column", "1",
                    "--time-unit", "s", "--freq", "1", "--columns", "2", "--json"]))
                row.peer_label = "gmwm wv in-memory (time column turns streaming off)"
                row.notes.append("peer: the same values as column 2 of a 2-column raw f64 file with time stamps "
                                 "0, 1, 2, ... s in column 1; --time-column disables the streaming path "
                                 "(cmd/wv.rs `streamable`), so the series is loaded and wavelet_variance runs "
                                 "in memory; it reads 16 MB instead of 8 MB and checks the stamps")
                row.after = compare_wv_outputs
            else:
                row = Row(rid, "`gmwm wv` streaming, 1e6 raw f64, vs the in-memory kernel alone (criterion)",
                          Goal("within", 1.5))
                row.gmwm.append(Timed("stream1e6_kernel.streaming", stream))
                row.peer_label = f"criterion {CRITERION_CELL} (kernel only)"
                row.criterion = True
            rows.append(row)

        elif rid in ("fit_exact", "fit_g", "robust_exact", "robust_g"):
            robust = rid.startswith("robust")
            exact = rid.endswith("exact")
            start = "exact start" if exact else "guessed start, G = 20000"
            row = Row(rid, f"`gmwm fit` 3*AR1(), N = 1e6 raw f64, {start}, "
                           f"{'robust eff 0.6' if robust else 'classical'}", Goal("ratio_min", 100))
            if sim_error:
                row.status = "skipped"
                row.notes.append(sim_error)
            cmd = [gmwm, "fit", str(sim_path), "--format", "f64", "--freq", "1"]
            cmd += ["--model", TRUTH_3AR1] if exact else ["--model", "3*AR1()", "--G", "20000"]
            if robust:
                cmd += ["--robust", "--eff", "0.6"]
            row.gmwm.append(Timed(f"{rid}.gmwm", cmd))
            rflag = "TRUE" if robust else "FALSE"
            call = (f"gmwm_imu(truth, x, robust = {rflag}, eff = 0.6)" if exact
                    else f"gmwm_imu(3*GM(), x, robust = {rflag}, eff = 0.6, G = 20000)")
            r_peer(row, r_sim(sim_path, 1_000_000, f'e <- system.time(m <- {call})[["elapsed"]]'),
                   refs.gmwm_3gm("robust" if robust else "standard", "exact" if exact else "guess_20000"),
                   call)
            rows.append(row)

        elif rid == "inference":
            row = Row(rid, "asymptotic inference, 3*AR1(), N = 1e6 (`fit --inference` − `fit`, exact start)",
                      Goal("max_s", 1.0))
            if sim_error:
                row.status = "skipped"
                row.notes.append(sim_error)
            cmd = [gmwm, "fit", str(sim_path), "--format", "f64", "--freq", "1", "--model", TRUTH_3AR1]
            row.gmwm.append(Timed("inference.fit_inference", cmd + ["--inference"]))
            row.gmwm.append(Timed("inference.fit", cmd))
            row.combine = difference
            row.notes.append("gmwm: median of (fit --inference) minus median of (fit); min likewise")
            r_peer(row, r_sim(sim_path, 1_000_000,
                              "m <- gmwm_imu(truth, x)\n"
                              'e <- system.time(s <- summary(m, inference = TRUE))[["elapsed"]]'),
                   refs.adis_summary(), "summary(m, inference = TRUE)")
            if row.peer_source == "ref":
                row.peer_label = "R summary(inference = TRUE), N = 1e6, adis gyro_x fits (ref file)"
            rows.append(row)

        elif rid == "fit_adis":
            row = Row(rid, "`gmwm fit` adis_16405_imu1 gyro_x, 2*GM()+WN()+RW(), `--inference`, whole command",
                      Goal("max_s", 1.0))
            if not adis.exists():
                row.status = "skipped"
                row.notes.append(f"{adis} not found (--data-dir)")
            row.gmwm.append(Timed("fit_adis.gmwm", [gmwm, "fit", str(adis), "--columns", "gyro_x",
                                                     "--model", "2*GM()+WN()+RW()", "--inference"]))
            call = "gmwm_imu(2*GM()+WN()+RW(), x[, 1]) + summary(m, inference = TRUE)"
            r_peer(row, r_imudata("e <- system.time({m <- gmwm_imu(2*GM()+WN()+RW(), x[, 1]); "
                                  's <- summary(m, inference = TRUE)})[["elapsed"]]'),
                   refs.adis_fit_inference(), call)
            rows.append(row)

        elif rid in ("select6", "select_boot"):
            boot = rid == "select_boot"
            row = Row(rid, f"`gmwm select` adis_16405_imu1, {SELECT_MODEL}, "
                           + ("gyro_x, `--optimism bootstrap`" if boot else "six axes"),
                      Goal("max_s", 10.0 if boot else 1.0))
            if not adis.exists():
                row.status = "skipped"
                row.notes.append(f"{adis} not found (--data-dir)")
            cmd = [gmwm, "select", str(adis), "--model", SELECT_MODEL]
            if boot:
                cmd += ["--columns", "gyro_x", "--optimism", "bootstrap"]
            row.gmwm.append(Timed(f"{rid}.gmwm", cmd))
            row.heavy = True
            if boot:
                row.peer_label = "— (no R reference for auto_imu(bootstrap = TRUE))"
                row.peer_source = "none"
            else:
                call = "auto_imu(x[, 1], model = 3*AR1()+WN()+RW()+QN()), ONE axis, 31 candidates"
                r_peer(row, r_imudata("e <- system.time(a <- auto_imu(x[, 1], model = 3*AR1()+WN()+RW()+QN()))"
                                      '[["elapsed"]]'),
                       refs.auto_imu(), call)
                row.peer_label += " — one axis, 31 candidates"
            rows.append(row)
        elif rid in ("calib1e8", "calib1e9"):
            big = BIG_N if rid == "calib1e8" else HUGE_N
            power = 8 if rid == "calib1e8" else 9
            size = "800 MB" if rid == "calib1e8" else "8 GB"
            goal_s, goal_mb = (2.0, 128.0) if rid == "calib1e8" else (25.0, 200.0)
            row = Row(rid, f"`gmwm calibrate` of a 10^{power}-sample raw f64 file ({size}; WN + RW, 100 Hz)",
                      Goal("max_s", goal_s))
            row.rss_max_mb = goal_mb
            path = work / f"imu_1e{power}.f64"
            if prepare:
                log(f"writing 10^{power} samples of WN(sd 1e-3) + RW(step 1e-6), numpy default_rng({BIG_SEED}) -> {path}")
                write_big(path, big, BIG_SEED)
            doc = work / f"calib1e{power}.json"
            timed = Timed(f"{rid}.gmwm", [gmwm, "calibrate", str(path), "--format", "f64", "--json", str(doc)])
            timed.measure_rss = True
            row.gmwm.append(timed)
            row.heavy = True
            row.peer_label = f"— (target: <= {goal_s:g} s and peak RSS <= {goal_mb:g} MB)"
            row.peer_source = "none"
            row.notes.append("peak RSS of the gmwm process as GNU time reports it (wait4 on a child forked from "
                             "this Python process would include Python's own pages)" if GNU_TIME else
                             "peak RSS from wait4 (ru_maxrss): GNU time is missing, so it includes the pages of "
                             "this Python process the child was forked from (an upper bound)")
            if rid == "calib1e9":
                row.after = lambda r, path=path, doc=doc: compare_prefix(r, gmwm, path, doc, work)
            rows.append(row)
    return rows


def compare_prefix(row: "Row", gmwm: str, path: Path, doc: Path, work: Path) -> None:
    """The WN density of the 10^9-sample calibration beside that of its first 10^8 samples (a
    prefix copied from the same file, calibrated untimed): the long run must agree with it."""
    prefix = work / "imu_1e9_prefix_1e8.f64"
    with open(path, "rb") as src, open(prefix, "wb") as dst:
        left = BIG_N * 8
        while left:
            block = src.read(min(left, 1 << 24))
            if not block:
                break
            dst.write(block)
            left -= len(block)
    Path(str(prefix) + ".json").write_text(Path(str(path) + ".json").read_text())
    prefix_doc = work / "calib1e9_prefix.json"
    p = subprocess.run([gmwm, "calibrate", str(prefix), "--format", "f64", "--json", str(prefix_doc)],
                       capture_output=True, text=True)
    if p.returncode != 0:
        row.notes.append(f"the 10^8 prefix did not calibrate (exit {p.returncode}): {p.stderr.strip()[-300:]}")
        return

    def density(d: Path):
        axis = json.loads(d.read_text())["axes"][0]
        n = axis["noise_density"]
        return n["value"], n.get("ci_low"), n.get("ci_high")

    try:
        (a, alo, ahi), (b, blo, bhi) = density(doc), density(prefix_doc)
    except (OSError, KeyError, IndexError, TypeError, ValueError) as e:
        row.notes.append(f"WN density not compared: {e!r}")
        return
    row.notes.append(f"WN density (rad/s/sqrt(Hz)): 10^9 samples {a:.6e} [{alo:.6e}, {ahi:.6e}]; its first 10^8 "
                     f"samples {b:.6e} [{blo:.6e}, {bhi:.6e}]; relative difference {abs(a - b) / b:.2e}")
    prefix.unlink()


def write_big(path: Path, n: int, seed: int) -> None:
    """n samples of white noise (sd 1e-3) plus a random walk (step sd 1e-6), little-endian f64,
    written in pieces (memory stays small), with a sidecar naming the column gyro_x at 100 Hz."""
    import numpy as np
    rng = np.random.default_rng(seed)
    piece = 1 << 22
    level = 0.0
    with open(path, "wb") as f:
        for start in range(0, n, piece):
            m = min(piece, n - start)
            steps = rng.standard_normal(m) * 1e-6
            walk = level + np.cumsum(steps)
            level = float(walk[-1])
            (rng.standard_normal(m) * 1e-3 + walk).astype("<f8").tofile(f)
    Path(str(path) + ".json").write_text(json.dumps(
        {"sampling_frequency_hz": 100, "units": {"gyro": "rad/s"}, "columns": [{"name": "gyro_x"}]}))


def run_criterion(row: Row, timeout: float) -> None:
    cmd = ["cargo", "bench", "-p", "gmwm", "--bench", "variance", "--", "--exact", CRITERION_CELL]
    log(f"  $ {shlex.join(cmd)}   (in {REPO}; builds the bench first)")
    try:
        p = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, timeout=timeout)
    except (OSError, subprocess.TimeoutExpired) as e:
        row.peer_source, row.notes = "failed", row.notes + [f"cargo bench did not run: {e}"]
        return
    out = p.stdout + p.stderr
    hit = re.search(r"time:\s+\[([\d.]+) (\S+) ([\d.]+) (\S+) ([\d.]+) (\S+)\]", out)
    if p.returncode != 0 or not hit:
        row.peer_source = "failed"
        row.notes.append(f"cargo bench failed (exit {p.returncode}): " + " | ".join(out.strip().splitlines()[-5:]))
        return
    scale = {"ns": 1e-9, "us": 1e-6, "µs": 1e-6, "ms": 1e-3, "s": 1.0}
    low, mid, _high = (float(hit.group(i)) * scale[hit.group(i + 1)] for i in (1, 3, 5))
    row.peer_value = (mid, low)
    row.peer_source = "criterion"
    row.notes.append(f"peer: `{shlex.join(cmd)}`: criterion estimate {fmt_s(mid)} (lower bound {fmt_s(low)}), "
                     "in-memory wavelet_variance on seeded white noise, no process start or reading")


# ------------------------------------------------------------------------------------------


def markdown(rows: List[Row]) -> str:
    lines = ["| work | gmwm | peer | ratio | goal | met |", "|---|---|---|---|---|---|"]
    for r in rows:
        lines.append("| " + " | ".join(c.replace("|", "\\|") for c in r.cells()) + " |")
    return "\n".join(lines)


def git_commit() -> Optional[str]:
    try:
        p = subprocess.run(["git", "-C", str(REPO), "rev-parse", "HEAD"], capture_output=True, text=True)
        return p.stdout.strip() or None
    except OSError:
        return None


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(
        prog="e2e.py",
        description=__doc__.split("\n\n")[0],
        epilog=__doc__.split("\n", 1)[1],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    ap.add_argument("--gmwm", default=str(REPO / "target" / "release" / "gmwm"),
                    help="the gmwm binary [default: %(default)s]")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs of every command [default: 3]")
    ap.add_argument("--warmup", type=int, default=1,
                    help="untimed runs of every command before the timed ones (not for the select rows, "
                         "nor R) [default: 1]")
    ap.add_argument("--only", default=None,
                    help="comma-separated row ids: " + ", ".join(ROW_IDS + OPTIONAL_ROW_IDS) + " [default: all but "
                         + ", ".join(OPTIONAL_ROW_IDS) + "]")
    ap.add_argument("--kernel-bench", action="store_true",
                    help="also the row stream1e6_kernel (runs `cargo bench -p gmwm --bench variance`)")
    ap.add_argument("--workdir", default=None, help="keep work files (data, outputs) in this directory")
    ap.add_argument("--json", metavar="FILE", default=None, help="also write the results as JSON to FILE")
    ap.add_argument("--verbose", action="store_true", help="print every command line and every run's time")
    ap.add_argument("--list", action="store_true", help="list the rows and their goals, run nothing")
    ap.add_argument("--peer-python", default=sys.executable,
                    help="Python interpreter that runs allantools [default: this one, %(default)s]")
    ap.add_argument("--install-peers", action="store_true",
                    help="pip-install allantools into --peer-python if it is missing")
    ap.add_argument("--r", dest="r_mode", choices=["auto", "live", "ref"], default="auto",
                    help="R peer: live if `Rscript -e 'library(gmwm)'` works (auto), always live, or "
                         "the reference files only [default: auto]")
    ap.add_argument("--rscript", default="Rscript", help="the Rscript program [default: Rscript]")
    ap.add_argument("--data-dir", default=os.environ.get("GMWM_DATA_DIR", str(REPO.parent / "shared" / "data")),
                    help="directory of adis_16405_imu1.csv.gz [default: $GMWM_DATA_DIR or %(default)s]")
    ap.add_argument("--ref-dir", default=str(REPO.parent / "shared" / "ref"),
                    help="directory of the R reference JSON files [default: %(default)s]")
    ap.add_argument("--timeout", type=float, default=1800.0,
                    help="seconds after which one run counts as failed [default: 1800]")
    return ap.parse_args(argv)


def main(argv: Optional[Sequence[str]] = None) -> int:
    args = parse_args(argv)
    if args.only:
        wanted = [w.strip() for w in args.only.split(",") if w.strip()]
        unknown = [w for w in wanted if w not in ROW_IDS + OPTIONAL_ROW_IDS]
        if unknown:
            print(f"unknown row id(s): {', '.join(unknown)}; the rows are {', '.join(ROW_IDS + OPTIONAL_ROW_IDS)}",
                  file=sys.stderr)
            return 2
    else:
        wanted = list(ROW_IDS)
    if args.kernel_bench and "stream1e6_kernel" not in wanted:
        wanted.insert(wanted.index("stream1e6") + 1 if "stream1e6" in wanted else len(wanted), "stream1e6_kernel")
    if args.repeat < 1:
        print("--repeat must be at least 1", file=sys.stderr)
        return 2

    gmwm = args.gmwm
    if not args.list and not (Path(gmwm).is_file() and os.access(gmwm, os.X_OK)):
        print(f"the gmwm binary {gmwm} is missing: build it with `cargo build --release -p gmwm-cli` "
              f"(in {REPO}) or pass --gmwm PATH", file=sys.stderr)
        return 2
    if importlib.util.find_spec("numpy") is None:
        print("numpy is needed to write the work files: pip install numpy", file=sys.stderr)
        return 2

    refs = RefFiles(Path(args.ref_dir))
    r_live, r_info = False, "not checked"
    if args.r_mode != "ref" and not args.list:
        r_live, r_info = r_available(args.rscript)
        if args.r_mode == "live" and not r_live:
            log(f"--r live: R gmwm is not available ({r_info}); using the reference files")
    if not args.list:
        log(f"R peer: {'live, gmwm ' + r_info if r_live else 'reference files (' + r_info + ')'}")

    if args.list:
        work, cleanup = Path(args.workdir or "WORKDIR"), False
    elif args.workdir:
        work = Path(args.workdir).resolve()
        work.mkdir(parents=True, exist_ok=True)
        cleanup = False
    else:
        work = Path(tempfile.mkdtemp(prefix="gmwm-e2e-"))
        cleanup = True
    outdir = work / "out"
    if not args.list:
        outdir.mkdir(exist_ok=True)

    load_start = os.getloadavg()[0] if hasattr(os, "getloadavg") else None
    started = _dt.datetime.now(_dt.timezone.utc)
    try:
        rows = build_rows(args, wanted, work, gmwm, refs, r_live, prepare=not args.list)
        if args.list:
            for r in rows:
                print(f"{r.id}: {r.work}  [goal {r.goal.text()}]")
                for t in r.gmwm + r.peer:
                    print(f"    {t.cmd}")
                print(f"    peer: {r.peer_label}")
            return 0
        log(f"{os.cpu_count()} CPUs, load average {load_start:.2f} at start; {args.repeat} run(s) per command, "
            f"{args.warmup} warm-up; work files in {work}")
        if load_start is not None and os.cpu_count() and load_start > 0.5 * os.cpu_count():
            log("warning: the machine is busy; these times are noisy")
        for row in rows:
            log(f"[{row.id}] {row.work}")
            if row.status == "skipped":
                for t in row.gmwm + row.peer:
                    t.status = "skipped"
                log("  skipped: " + "\n  ".join(row.notes))
            else:
                # gmwm and its live peer run in turns; R is not warmed up (each run is a new R)
                measure(row.gmwm + row.peer, args.repeat, 0 if row.heavy else args.warmup, outdir,
                        args.timeout, args.verbose)
                if row.criterion:
                    run_criterion(row, args.timeout)
            row.finish()
            if row.status == "ok":
                med, lo = row.gmwm_value or (None, None)
                log(f"  gmwm {fmt_s(med)} (min {fmt_s(lo)}); peer "
                    f"{fmt_s(row.peer_value[0]) if row.peer_value else '—'}; ratio {fmt_ratio(row.ratio)}")
        load_end = os.getloadavg()[0] if hasattr(os, "getloadavg") else None

        gm_version = subprocess.run([gmwm, "--version"], capture_output=True, text=True).stdout.strip()
        print(f"# gmwm end-to-end bench (issue 14): {gm_version}, commit {git_commit() or '?'}")
        print(f"# {started:%Y-%m-%d %H:%M UTC}, {platform.platform()}, {os.cpu_count()} CPUs, load average "
              f"{load_start:.2f} at start and {load_end:.2f} at the end; {args.repeat} run(s) per command")
        print("# gmwm: median (min) of whole-command wall times; ratio = peer / gmwm on medians; "
              "met compares medians with the goal\n")
        print(markdown(rows))
        print()
        for r in rows:
            print(f"- **{r.id}**")
            for t in r.gmwm:
                print(f"  - gmwm: `{t.cmd}`" + (f" — FAILED: {t.error}" if t.status == "failed" else ""))
            for t in r.peer:
                if r.peer_source != "ref":
                    print(f"  - peer: `{t.cmd}`" + (f" — FAILED: {t.error}" if t.status == "failed" else ""))
            for n in r.notes:
                print(f"  - {n}")

        if args.json:
            doc = {
                "bench": "gmwm end-to-end (issue 14)",
                "date_utc": started.isoformat(timespec="seconds"),
                "gmwm_binary": str(Path(gmwm).resolve()),
                "gmwm_version": gm_version,
                "commit": git_commit(),
                "machine": {"platform": platform.platform(), "cpus": os.cpu_count(),
                            "load_average_start": load_start, "load_average_end": load_end},
                "python": sys.version.split()[0],
                "peer_python": args.peer_python,
                "r": {"mode": args.r_mode, "live": r_live, "info": r_info},
                "repeat": args.repeat,
                "warmup": args.warmup,
                "workdir": str(work) if not cleanup else None,
                "rows": [r.to_json() for r in rows],
                "markdown": markdown(rows),
            }
            Path(args.json).write_text(json.dumps(doc, indent=2, ensure_ascii=False) + "\n")
            log(f"wrote {args.json}")
        return 0
    finally:
        if cleanup:
            shutil.rmtree(work, ignore_errors=True)
        elif not args.list:
            log(f"work files kept in {work}")


if __name__ == "__main__":
    sys.exit(main())
