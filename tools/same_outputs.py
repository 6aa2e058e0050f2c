#!/usr/bin/env python3
"""Do two `gmwm` binaries print and write the same outputs? (a harness for refactors)

    python3 tools/same_outputs.py OLD_GMWM NEW_GMWM [--data DIR] [--keep DIR] [--only NAME...]

Runs a fixed list of cases (every subcommand, its output styles and files, the help texts and
a handful of error cases) with both binaries, each case of each binary in its own fresh
temporary working directory, and compares per step the exit code, stdout and stderr, and then
every file the case left in its working directory (JSON, YAML/SDF exports, CSV, gzip, SVG/PNG
figures, HTML reports). Prints one line per case (`same` or `DIFFERENT: what`) with a unified
diff excerpt for text, then `N cases, K different`; exits 1 if any case differs (or could not
be run), 0 otherwise.

Inputs: the recordings of `--data` (default ../shared/data beside the repository), reached from
each working directory through a symlink `data/`, so outputs that name an input say
`data/adis_16405_imu1.csv.gz` whatever the machine; and fixtures this script makes once per
run under its temporary root, shared by both binaries through a symlink `fx/`: a folder of two
recordings (symlinks) for batch mode, a folder with a broken recording, a CSV with a nanosecond
time column and a gap, and ROS recordings written by crates/gmwm/tests/fixtures/write_imu_bag.py
when the Python `rosbags` package is importable (`python3 -m pip install rosbags`; without it
the cases that need a bag are reported as skipped; `topics` on a non-ROS file always runs).
Nothing is written into the repository or the data folder.

Both binaries run with stdin from /dev/null (unless a case feeds a file), stdout and stderr to
pipes (not a terminal, so no progress bars and no colours), RUST_BACKTRACE, COLUMNS, LINES and
CLICOLOR_FORCE removed from the environment, and TMPDIR pointing at an empty folder of their
own (temporary files left behind are counted and compared).

Options: --keep DIR keeps the working directories (DIR/old/CASE, DIR/new/CASE, DIR/fx) for a
closer look; --only NAME... runs the cases named (shell-style patterns such as 'calibrate-*'
allowed); --list prints the cases and exits; --no-normalise turns off the normalisations listed
below (to see what they hide: two runs of one binary then differ now and then).

Standard library only; runs the cases one after the other (about 80 s with the baseline as
both binaries on an idle 2-core machine, about 2 minutes while it compiles).
"""

import argparse
import difflib
import fnmatch
import gzip
import json
import os
import random
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
DEFAULT_DATA = REPO.parent / "shared" / "data"
BAG_WRITER = REPO / "crates" / "gmwm" / "tests" / "fixtures" / "write_imu_bag.py"
STEP_TIMEOUT_S = 300
DIFF_LINES = 40
CLIP = 200  # characters of one diff line shown

# ---------------------------------------------------------------------------------------------
# Normalisations: only what legitimately depends on the run. Each one says why.
# ---------------------------------------------------------------------------------------------

# Wall-clock timing: `gmwm demo` (table style) ends with "(fit: 7 ms on this machine; ...)",
# the elapsed time of its fit measured with Instant::now (crates/gmwm-cli/src/cmd/demo.rs).
# Eight runs of the same baseline printed 11, 11, 13, 15, 16, 16, 17 and 17 ms. The number is
# replaced, the sentence around it is kept (so a change of the wording is still caught). No
# other output holds a time: JSON, HTML reports, YAML/SDF exports and figures of two runs are
# byte-identical.
TIMING_PATTERNS = [
    (re.compile(r"\(fit: \d+ ms on this machine"), "(fit: <ms> ms on this machine"),
]

# Temporary paths: every case of every binary runs in its own temporary working directory,
# with its own TMPDIR and the shared fixtures and data reached by absolute symlinks. An
# output that spells one of these absolute paths (an error naming a canonicalised path, a
# batch table, ...) would differ between the two runs by the folder name alone, so each is
# replaced by a placeholder (<WORK>, <TMP>, <FX>, <DATA>). Relative paths are untouched. (The
# baseline prints no such absolute path in any case here: inputs and outputs are named
# relative to the working directory; this is a guard for a refactor that canonicalises.)


def path_replacements(work, tmpdir, fx, data):
    pairs = []
    for path, token in ((work, "<WORK>"), (tmpdir, "<TMP>"), (fx, "<FX>"), (data, "<DATA>")):
        for variant in {str(path), os.path.realpath(path)}:
            pairs.append((variant, token))
    # longest first, so a path inside another is replaced by its own token
    pairs.sort(key=lambda p: -len(p[0]))
    return pairs


RAW = False  # --no-normalise: compare everything as it is (to see what the rules above hide)


def normalise(text, repl):
    if RAW:
        return text
    for old, token in repl:
        text = text.replace(old, token)
    for rx, sub in TIMING_PATTERNS:
        text = rx.sub(sub, text)
    return text


# Order of stderr lines of batch mode: `gmwm wv FOLDER` (and any batch) reads its recordings in
# parallel threads, each printing its own "gmwm: note: FILE: ... rows read" line when it is read,
# so the order of those lines between recordings depends on thread scheduling (12 runs of
# `gmwm wv fx/runs --out-dir o` gave imu1-then-imu2 8 times and imu2-then-imu1 4 times). Cases
# marked unordered_stderr compare their stderr as a sorted list of lines: the same lines, in
# any order. stdout (the summary table, in input order) is compared as it is.


# ---------------------------------------------------------------------------------------------
# Cases
# ---------------------------------------------------------------------------------------------

class Step:
    def __init__(self, argv, stdin=None, stdout_to=None):
        self.argv = list(argv)
        self.stdin = stdin          # file (relative to the working directory) fed on stdin
        self.stdout_to = stdout_to  # file (relative) that receives stdout, compared as a file


class Case:
    def __init__(self, name, steps, files=(), needs=(), unordered_stderr=False):
        self.name = name
        self.steps = steps
        self.files = list(files)    # files the case must write (checked to exist in both runs)
        self.needs = set(needs)     # fixtures it needs: {"bags"}
        self.unordered_stderr = unordered_stderr


def C(name, *argv, files=(), needs=(), stdin=None, unordered_stderr=False):
    """A one-step case."""
    return Case(name, [Step(argv, stdin=stdin)], files=files, needs=needs,
                unordered_stderr=unordered_stderr)


def S(*argv, stdin=None, stdout_to=None):
    return Step(argv, stdin=stdin, stdout_to=stdout_to)


IMU = [f"data/adis_16405_imu{i}.csv.gz" for i in range(1, 7)]
IMU1, IMU2, IMU3, IMU4, IMU5, IMU6 = IMU
CONT = "data/cont_imu1.csv.gz"
AR1_1E4 = "data/sim/ar1_wn_rw_N10000.csv.gz"
AR1_1E5 = "data/sim/ar1_wn_rw_N100000.csv.gz"
GM3_1E3 = "data/sim/gm3_N1000.csv.gz"
GM3_1E4 = "data/sim/gm3_N10000.csv.gz"
GM3_1E5 = "data/sim/gm3_N100000.csv.gz"
AR1_F64 = "data/sim/ar1_wn_rw_N1000000.f64le.bin"
NAVCHIP_WV = "data/precomputed/navchip_wv.json"
ADIS_WV = "data/precomputed/adis_wv.json"

SUBCOMMANDS = ["demo", "wv", "avar", "simulate", "implied", "fit", "select", "calibrate", "plot",
               "report", "topics", "same-model", "shared", "monitor"]
PLOT_KINDS = ["wv", "avar", "compare", "fit", "select", "ieee"]


def cases():
    out = []
    add = out.append

    # --- help texts (help is output too) ---
    add(C("help", "--help"))
    add(C("help-short", "-h"))
    add(C("help-version", "--version"))
    add(C("help-help-fit", "help", "fit"))
    for sub in SUBCOMMANDS:
        add(C(f"help-{sub}", sub, "--help"))
        add(C(f"help-{sub}-short", sub, "-h"))
    for kind in PLOT_KINDS:
        add(C(f"help-plot-{kind}", "plot", kind, "--help"))

    # --- demo ---
    add(C("demo", "demo"))
    add(C("demo-json", "demo", "--n", "100000", "--seed", "7", "--json"))
    add(C("demo-robust-csv", "demo", "--n", "65536", "--robust", "--eff", "0.8", "--csv"))

    # --- wv ---
    add(C("wv-table", "wv", IMU1))
    add(C("wv-json", "wv", IMU1, "--columns", "gyro_x,accel_z", "--json"))
    add(C("wv-csv-dwt-la8", "wv", IMU1, "--columns", "gyro_y", "--transform", "dwt",
          "--filter", "la8", "--levels", "6", "--csv"))
    add(C("wv-robust", "wv", CONT, "--robust", "--eff", "0.6"))
    add(C("wv-robust-package-json", "wv", CONT, "--robust", "--robust-convention", "package",
          "--levels", "12", "--json"))
    add(C("wv-stdin", "wv", "-", "--freq", "250", stdin=GM3_1E4))
    add(C("wv-f64-streamed", "wv", AR1_F64, "--format", "f64", "--freq", "200",
          "--stream-from", "100000", "--json"))
    add(C("wv-csv-streamed", "wv", IMU6, "--columns", "gyro_x,accel_y", "--stream-from",
          "100000", "--json"))
    add(C("wv-time-column", "wv", "fx/euroc.csv"))
    add(Case("wv-batch", [
        S("wv", "fx/runs", "--out-dir", "wvout", "--columns", "gyro_x,accel_y"),
        S("wv", "fx/runs", "--out-dir", "wvout", "--columns", "gyro_x,accel_y", "--json"),
        S("wv", "fx/runs/*.csv.gz", "--out-dir", "wvout", "--columns", "gyro_z", "--robust",
          "--force"),
    ], files=["wvout/adis_16405_imu1.wv.json", "wvout/adis_16405_imu2.wv.json"],
        unordered_stderr=True))
    add(C("wv-batch-failed", "wv", "fx/runs_bad", "--out-dir", "wvout", unordered_stderr=True))
    add(C("wv-bag", "wv", "fx/bags/imu.bag", "--topic", "/imu1", "--json", needs={"bags"}))

    # --- avar ---
    add(C("avar-table", "avar", IMU1, "--columns", "gyro_x,accel_x"))
    add(C("avar-non-overlapping", "avar", IMU1, "--kind", "non-overlapping",
          "--columns", "accel_z"))
    add(C("avar-modified-csv", "avar", IMU1, "--kind", "modified", "--columns", "gyro_z",
          "--csv"))
    add(C("avar-hadamard-json", "avar", IMU1, "--kind", "hadamard", "--columns", "gyro_x",
          "--json"))
    add(C("avar-hadamard-no-package", "avar", GM3_1E5, "--kind", "hadamard-non-overlapping",
          "--convention", "package", "--freq", "100"))

    # --- simulate ---
    add(C("simulate-file", "simulate", "--model",
          "3*GM(beta=0.25, sigma2_gm=7e-9)+WN(sigma2=7e-7)+RW(gamma2=4e-14)",
          "--freq", "250", "--n", "20000", "--seed", "1", "-o", "sim.csv.gz",
          files=["sim.csv.gz", "sim.csv.gz.json"]))
    add(C("simulate-components", "simulate", "--model",
          "GM(beta=0.25, sigma2_gm=7e-9)+WN(sigma2=7e-7)", "--freq", "250", "--n", "1000",
          "--components"))
    add(Case("simulate-f64-roundtrip", [
        S("simulate", "--model",
          "ARMA11(phi=0.8, theta=-0.3, sigma2=0.5)+QN(q2=0.1)+DR(omega=0.001)+RW(gamma2=1e-4)",
          "--n", "50000", "--seed", "3", "--freq", "10", "-o", "sim.f64"),
        S("wv", "sim.f64", "--json"),
    ], files=["sim.f64", "sim.f64.json"]))

    # --- implied ---
    add(C("implied-table", "implied", "--model", "3*AR1(phi=0.9, sigma2=1)+WN(sigma2=2)",
          "--levels", "10"))
    add(C("implied-json", "implied", "--model",
          "GM(beta=0.25, sigma2_gm=7.08e-9)+RW(gamma2=3.9e-14)", "--levels", "20",
          "--freq", "250", "--json"))
    add(C("implied-all-terms", "implied", "--model",
          "MA1(theta=0.5, sigma2=1)+QN(q2=0.1)+DR(omega=0.001)+RW(gamma2=1e-4)+WN(sigma2=2)",
          "--levels", "8", "--freq", "10"))

    # --- fit ---
    add(C("fit-recording", "fit", IMU1, "--columns", "gyro_x", "--model",
          "3*GM()+WN()+QN()+RW()"))
    add(C("fit-inference-json", "fit", IMU1, "--columns", "gyro_x", "--model",
          "2*GM()+WN()+RW()", "--inference", "--json"))
    add(C("fit-start-values-csv", "fit", AR1_1E5, "--model",
          "AR1(phi=0.99, sigma2=0.01)+WN(sigma2=1)+RW(gamma2=1e-6)", "--csv"))
    add(C("fit-robust", "fit", GM3_1E5, "--model", "2*AR1()+WN()", "--robust", "--eff", "0.6",
          "--G", "20000", "--seed", "7", "--levels", "13"))
    # the baseline refuses this one (exit 1): the robust WV of level 15 of this recording is
    # NaN, "CI width = NaN gives no usable weight"; its message is behaviour too
    add(C("fit-robust-nan-level", "fit", GM3_1E5, "--model", "2*AR1()+WN()", "--robust",
          "--G", "20000", "--seed", "7"))
    add(C("fit-bootstrap-inference", "fit", AR1_1E4, "--model", "AR1()+WN()+RW()",
          "--inference", "--bootstrap", "40"))
    add(C("fit-weights-bootstrap", "fit", AR1_1E4, "--model", "AR1()+WN()+RW()",
          "--weights", "bootstrap"))
    add(C("fit-covariance-bootstrap-json", "fit", GM3_1E4, "--model", "2*AR1()+WN()",
          "--inference", "--covariance", "bootstrap", "--json"))
    add(C("fit-precomputed-wv", "fit", NAVCHIP_WV, "--columns", "1", "--model",
          "3*GM()+WN()+QN()+RW()", "--inference"))
    add(Case("fit-saved-wv", [
        S("wv", IMU2, "--columns", "gyro_y", "--json", stdout_to="wv.json"),
        S("fit", "wv.json", "--model", "2*GM()+WN()+RW()", "--inference"),
    ], files=["wv.json"]))
    add(C("fit-pool", "fit", IMU1, IMU2, "--pool", "--columns", "gyro_x", "--model",
          "2*AR1()+WN()+RW()", "--inference"))

    # --- select ---
    add(C("select-table", "select", AR1_1E5, "--model", "3*AR1()+WN()+RW()+QN()+DR()"))
    add(C("select-json", "select", IMU1, "--columns", "gyro_x", "--model",
          "3*AR1()+WN()+RW()+QN()", "--json"))
    add(C("select-csv", "select", GM3_1E4, "--model", "2*AR1()+WN()+RW()+QN()+DR()",
          "--top", "0", "--csv"))
    add(C("select-candidates", "select", AR1_1E4, "--candidates",
          "AR1()+WN()+RW();2*AR1()+WN()+RW();3*AR1()+WN()+QN()+RW()", "--rule",
          "parsimonious"))
    add(C("select-robust", "select", CONT, "--model", "2*GM()+WN()+RW()", "--robust",
          "--eff", "0.6", "--G", "20000", "--seed", "7"))
    add(C("select-pool", "select", IMU1, IMU2, "--pool", "--columns", "gyro_x", "--model",
          "2*AR1()+WN()+RW()"))

    # --- calibrate ---
    add(C("calibrate-full", "calibrate", IMU1, "--json", "cal.json", "--kalibr", "imu.yaml",
          "--report", "report.html", files=["cal.json", "imu.yaml", "report.html"]))
    # px4 is refused on this recording since its gyro model has no Gauss-Markov bias (the
    # flicker term explains it): the refusal and the other four files are compared
    add(C("calibrate-exports", "calibrate", IMU2, "--columns", "gyro_x,accel_x",
          "--kalibr", "kalibr.yaml", "--export", "openvins", "openvins.yaml",
          "--export", "vins", "vins.yaml", "--export", "orbslam3", "orbslam3.yaml",
          "--export", "px4", "px4.sdf", "--export", "kalibr", "kalibr2.yaml",
          files=["kalibr.yaml", "openvins.yaml", "vins.yaml", "orbslam3.yaml", "kalibr2.yaml"]))
    add(C("calibrate-json-stdout", "calibrate", IMU3, "--columns", "gyro_y,accel_z",
          "--json", "-"))
    add(C("calibrate-per-axis", "calibrate", IMU4, "--columns", "gyro_x,gyro_y,accel_x,accel_y",
          "--axis-policy", "per-axis", "--kalibr", "imu.yaml", "--export", "px4", "imu.sdf",
          files=["imu.x.yaml", "imu.y.yaml"]))
    add(C("calibrate-mean-inflate", "calibrate", IMU4, "--columns", "gyro_z,accel_y",
          "--axis-policy", "mean", "--inflate", "2", "--rostopic", "/imu/data",
          "--export", "openvins", "openvins.yaml", "--export", "vins", "vins.yaml",
          files=["openvins.yaml", "vins.yaml"]))
    add(C("calibrate-conservative", "calibrate", IMU4, "--columns", "gyro_z,accel_y",
          "--conservative", "--kalibr", "imu.yaml", "--export", "orbslam3", "orbslam3.yaml",
          files=["imu.yaml", "orbslam3.yaml"]))
    add(C("calibrate-model-rule", "calibrate", IMU5, "--columns", "gyro_y", "--model",
          "2*AR1()+WN()+RW()", "--rule", "wic-minimum", "--json", "cal.json",
          files=["cal.json"]))
    add(C("calibrate-robust-cont", "calibrate", CONT, "--robust"))
    add(C("calibrate-pool", "calibrate", IMU1, IMU2, "--pool", "--columns", "gyro_x,accel_x",
          "--kalibr", "pool.yaml", "--json", "pool.json", "--report", "pool.html",
          files=["pool.yaml", "pool.json", "pool.html"]))
    add(Case("calibrate-batch", [
        S("calibrate", "fx/runs", "--out-dir", "cal", "--columns", "gyro_x,accel_x",
          "--kalibr", "imu.yaml", "--report", "report.html"),
        S("calibrate", "fx/runs", "--out-dir", "cal", "--columns", "gyro_x,accel_x",
          "--kalibr", "imu.yaml", "--report", "report.html", "--json", "-"),
    ], files=[f"cal/adis_16405_imu{i}.{x}" for i in (1, 2)
              for x in ("calibration.json", "imu.yaml", "report.html")],
        unordered_stderr=True))
    add(Case("calibrate-units", [
        S("calibrate", IMU3, "--columns", "gyro_z,accel_y", "--gyro-unit", "deg/s",
          "--accel-unit", "g"),
        S("calibrate", IMU3, "--columns", "gyro_z,accel_y", "--gyro-unit", "rad/s",
          "--accel-unit", "mg", "--kalibr", "imu.yaml"),
    ], files=["imu.yaml"]))
    # streamed (one pass through a spool file in TMPDIR) instead of loaded
    add(C("calibrate-streamed", "calibrate", IMU6, "--columns", "gyro_x,accel_x",
          "--stream-from", "100000", "--json", "cal.json", "--kalibr", "imu.yaml",
          files=["cal.json", "imu.yaml"]))
    add(C("calibrate-time-column", "calibrate", "fx/euroc.csv", "--gyro-unit", "rad/s",
          "--accel-unit", "m/s^2", "--kalibr", "imu.yaml", files=["imu.yaml"]))
    add(C("calibrate-bag", "calibrate", "fx/bags/imu.bag", "--topic", "/imu0", "--kalibr",
          "imu.yaml", "--json", "cal.json", files=["imu.yaml", "cal.json"], needs={"bags"}))
    add(C("calibrate-mcap", "calibrate", "fx/bags/mc", "--export", "openvins",
          "kalibr_imu_chain.yaml", files=["kalibr_imu_chain.yaml"], needs={"bags"}))

    # --- plot ---
    add(C("plot-wv-svg", "plot", "wv", IMU1, "-o", "wv.svg", files=["wv.svg"]))
    add(C("plot-wv-overlay-png", "plot", "wv", IMU1, "--overlay", "-o", "wv.png",
          files=["wv.png"]))
    add(C("plot-avar-svg", "plot", "avar", IMU1, "--columns", "gyro_x", "--kind", "modified",
          "-o", "adev.svg", files=["adev.svg"]))
    add(C("plot-compare-svg", "plot", "compare", CONT, "--eff", "0.6", "-o", "robust.svg",
          files=["robust.svg"]))
    add(C("plot-fit-svg", "plot", "fit", IMU1, "--columns", "gyro_x", "--model",
          "2*AR1()+WN()+RW()", "-o", "fit.svg", files=["fit.svg"]))
    add(C("plot-select-png", "plot", "select", IMU1, "--columns", "gyro_x", "--model",
          "2*AR1()+WN()+RW()+QN()", "-o", "select.png", files=["select.png"]))
    add(C("plot-ieee-svg", "plot", "ieee", IMU1, "--columns", "gyro_x,accel_x", "--width",
          "900", "--height", "500", "-o", "ieee.svg", files=["ieee.svg"]))

    # --- report ---
    add(C("report-default-name", "report", IMU2, "--columns", "gyro_x,accel_x",
          files=["adis_16405_imu2.report.html"]))
    add(C("report-output-kalibr", "report", IMU6, "--columns", "gyro_x,accel_x", "--kalibr",
          "imu.yaml", "-o", "acceptance.html", files=["acceptance.html", "imu.yaml"]))
    # a gyroscope alone: the report is written, the Kalibr file cannot be (exit 1)
    add(C("report-robust-kalibr-gyro-only", "report", CONT, "--robust", "--gyro-unit",
          "rad/s", "--kalibr", "imu.yaml", "-o", "cont.html", files=["cont.html"]))

    # --- topics ---
    add(C("topics-ros1", "topics", "fx/bags/imu.bag", needs={"bags"}))
    add(C("topics-ros1-json", "topics", "fx/bags/imu.bag", "--json", needs={"bags"}))
    add(C("topics-mcap", "topics", "fx/bags/mc", needs={"bags"}))
    add(C("topics-sqlite3-json", "topics", "fx/bags/db", "--json", needs={"bags"}))
    add(C("topics-not-ros", "topics", "data/adis_16405_imu1.json"))

    # --- same-model ---
    add(C("same-model", "same-model", IMU1, IMU2, "--model", "2*GM()+WN()+RW()",
          "--columns", "gyro_x"))
    add(C("same-model-bootstrap-json-plot", "same-model", IMU3, IMU4, "--model",
          "AR1()+WN()+RW()", "--columns", "gyro_x,accel_x", "--bootstrap", "20", "--json",
          "--plot", "same.svg", files=["same.svg"]))

    # --- shared ---
    add(C("shared", "shared", IMU1, "--shared", "GM()", "--model", "WN()+RW()", "--columns",
          "gyro_x,gyro_y,gyro_z"))
    add(C("shared-json-plot", "shared", IMU1, "--shared", "AR1()", "--model",
          "WN()+QN()+RW()", "--columns", "accel_x,accel_y", "--levels", "14", "--json",
          "--plot", "shared.svg", files=["shared.svg"]))
    add(C("shared-csv-png", "shared", IMU2, "--shared", "GM()", "--model", "WN()+RW()",
          "--columns", "gyro_x,gyro_y", "--csv", "--plot", "shared.png", files=["shared.png"]))

    # --- monitor (on a calibration made in the same case) ---
    add(Case("monitor", [
        S("calibrate", IMU5, "--columns", "gyro_x,gyro_z", "--json", "cal.json"),
        S("monitor", IMU5, "--model-from", "cal.json", "--columns", "gyro_x,gyro_z"),
        S("monitor", IMU5, "--model-from", "cal.json", "--columns", "gyro_x", "--window",
          "600s", "--step", "60s", "--json"),
        # (the baseline accepts --csv here and prints the table)
        S("monitor", IMU5, "--model-from", "cal.json", "--columns", "gyro_z", "--against",
          "model", "--window", "65536", "--csv"),
    ], files=["cal.json"]))
    # the baseline's calibrate writes null for the NaN robust WV of accel_z's last two levels
    # (contamination.robust.wv) and monitor then refuses that calibration (exit 1)
    add(Case("monitor-null-robust-wv", [
        S("calibrate", IMU5, "--columns", "gyro_x,accel_z", "--json", "cal.json"),
        S("monitor", IMU5, "--model-from", "cal.json", "--columns", "gyro_x"),
    ], files=["cal.json"]))
    add(Case("monitor-cont-out-dir", [
        S("calibrate", CONT, "--robust", "--out-dir", "cal"),
        S("monitor", CONT, "--model-from", "cal/cont_imu1.calibration.json", "--against",
          "wv", "--window", "10min"),
    ], files=["cal/cont_imu1.calibration.json"]))

    # --- errors: exit code and message must stay ---
    add(C("err-no-subcommand"))
    add(C("err-unknown-flag", "wv", "--bogus"))
    add(C("err-missing-required", "fit", GM3_1E3))
    add(C("err-freq-negative", "wv", GM3_1E3, "--freq", "-5"))
    add(C("err-eff-out-of-range", "fit", GM3_1E3, "--model", "WN()", "--eff", "1.5"))
    add(C("err-alpha-confidence", "wv", GM3_1E3, "--alpha", "0.95"))
    add(C("err-kind-value", "avar", GM3_1E3, "--kind", "bogus"))
    add(C("err-gyro-unit", "calibrate", IMU1, "--gyro-unit", "furlong/s"))
    add(C("err-inflate-conservative", "calibrate", IMU1, "--inflate", "2", "--conservative"))
    add(C("err-export-unknown-unit", "calibrate", CONT, "--kalibr", "imu.yaml"))
    add(C("err-export-stack", "calibrate", IMU1, "--export", "bogus", "x.yaml"))
    add(C("err-missing-file", "wv", "nope.csv"))
    add(C("err-bad-model", "fit", GM3_1E3, "--model", "AR1(+WN("))
    add(C("err-two-arma-terms", "implied", "--model",
          "MA1(theta=0.5, sigma2=1)+ARMA11(phi=0.8, theta=-0.3, sigma2=0.5)", "--levels", "5"))
    add(C("err-model-without-values", "implied", "--model", "AR1()+WN()", "--levels", "5"))
    add(C("err-levels-too-large", "wv", GM3_1E3, "--levels", "30"))
    add(C("err-fit-levels-too-large", "fit", GM3_1E3, "--model", "AR1()+WN()", "--levels",
          "12"))
    add(C("err-calibrate-wv-json", "calibrate", ADIS_WV))
    add(C("err-same-model-one-file", "same-model", GM3_1E3, "--model", "WN()"))
    add(C("err-monitor-missing-calibration", "monitor", GM3_1E3, "--model-from", "nope.json"))
    add(C("err-plot-json", "plot", "wv", GM3_1E3, "-o", "p.svg", "--json"))
    add(Case("err-output-is-input", [
        S("simulate", "--model", "WN(sigma2=1)", "--n", "5000", "--freq", "100", "-o",
          "s.csv"),
        S("calibrate", "s.csv", "--json", "s.csv"),
        S("calibrate", "s.csv", "--kalibr", "s.csv.json"),
    ], files=["s.csv", "s.csv.json"]))
    return out


# ---------------------------------------------------------------------------------------------
# Fixtures (made once per run, shared read-only by both binaries through the symlink fx/)
# ---------------------------------------------------------------------------------------------

def make_fixtures(fx, data):
    """Returns the set of optional fixtures available ({"bags"} when rosbags works) and notes."""
    notes = []
    runs = fx / "runs"
    runs.mkdir(parents=True)
    for i in (1, 2):
        for ext in (".csv.gz", ".json"):
            name = f"adis_16405_imu{i}{ext}"
            (runs / name).symlink_to(data / name)
    bad = fx / "runs_bad"
    bad.mkdir()
    (bad / "gm3_N10000.csv.gz").symlink_to(data / "sim" / "gm3_N10000.csv.gz")
    (bad / "broken.csv").write_text("x\n0.1\n0.2\nabc\n0.3\n")

    # A EuRoC-style CSV: a nanosecond time column at 200 Hz with one gap (rate from the stamps,
    # the gap reported), gyro and accel columns of white noise plus a random walk. Seeded
    # Python `random` (its sequence for a given seed is stable across Python versions).
    rng = random.Random(2024)
    rows = ["#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
            "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]"]
    bias = [0.0] * 6
    t0 = 1_403_636_579_758_555_392
    k = 0
    for i in range(20000):
        if i == 12000:
            k += 5  # a gap of five samples
        vals = []
        for a in range(6):
            bias[a] += rng.gauss(0.0, 1e-5 if a < 3 else 1e-4)
            wn = rng.gauss(0.0, 2e-3 if a < 3 else 2e-2)
            vals.append((9.81 if a == 5 else 0.0) + bias[a] + wn)
        rows.append(f"{t0 + k * 5_000_000}," + ",".join(repr(v) for v in vals))
        k += 1
    (fx / "euroc.csv").write_text("\n".join(rows) + "\n")

    available = set()
    bags = fx / "bags"
    bags.mkdir()
    common = ["--rate", "200", "--seed", "1", "--gyro-wn-density", "1e-4",
              "--gyro-rw-density", "1e-6", "--accel-wn-density", "1e-3",
              "--accel-rw-density", "1e-5"]
    jobs = [
        ["--container", "ros1", "--out", str(bags / "imu.bag"), "--n", "6000",
         "--topic", "/imu0", "--topic", "/imu1", "--extra-topic",
         "/chatter:std_msgs/msg/String", "--compression", "lz4"],
        ["--container", "mcap", "--out", str(bags / "mc"), "--n", "6000", "--compression",
         "zstd"],
        ["--container", "sqlite3", "--out", str(bags / "db"), "--n", "500",
         "--extra-topic", "/tf:tf2_msgs/msg/TFMessage"],
    ]
    if not BAG_WRITER.exists():
        notes.append(f"no {BAG_WRITER}: the cases that need a ROS bag are skipped")
        return available, notes
    for job in jobs:
        r = subprocess.run([sys.executable, str(BAG_WRITER)] + job + common,
                           capture_output=True, text=True)
        if r.returncode != 0:
            msg = (r.stderr.strip().splitlines() or ["(no message)"])[-1]
            notes.append(f"ROS bags not written ({msg}): the cases that need one are skipped")
            return available, notes
    available.add("bags")
    return available, notes


# ---------------------------------------------------------------------------------------------
# Running
# ---------------------------------------------------------------------------------------------

def child_env(tmpdir):
    env = dict(os.environ)
    # a backtrace would add lines to a panic message; terminal width and forced colours would
    # change help text and errors: none of them is the binary's behaviour under comparison
    for var in ("RUST_BACKTRACE", "RUST_LIB_BACKTRACE", "COLUMNS", "LINES", "CLICOLOR_FORCE",
                "FORCE_COLOR"):
        env.pop(var, None)
    env["TMPDIR"] = str(tmpdir)
    return env


class Run:
    """One binary's run of one case: per step (rc, stdout, stderr), then the files."""

    def __init__(self):
        self.steps = []
        self.files = {}      # relative path -> bytes (symlinks: "-> target")
        self.tmp_left = []   # entries left in TMPDIR
        self.repl = []
        self.seconds = 0.0


def run_case(binary, case, side_root, fx, data):
    work = side_root / case.name / "work"
    tmpdir = side_root / case.name / "tmp"
    work.mkdir(parents=True)
    tmpdir.mkdir(parents=True)
    (work / "data").symlink_to(data)
    (work / "fx").symlink_to(fx)
    env = child_env(tmpdir)
    run = Run()
    run.repl = path_replacements(work, tmpdir, fx, data)
    start = time.monotonic()
    for step in case.steps:
        stdin = open(work / step.stdin, "rb") if step.stdin else subprocess.DEVNULL
        try:
            r = subprocess.run([binary] + step.argv, cwd=work, env=env, stdin=stdin,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               timeout=STEP_TIMEOUT_S)
            rc, out, err = r.returncode, r.stdout, r.stderr
        except subprocess.TimeoutExpired as e:
            rc, out, err = f"timeout after {STEP_TIMEOUT_S} s", e.stdout or b"", e.stderr or b""
        finally:
            if step.stdin:
                stdin.close()
        if step.stdout_to:
            (work / step.stdout_to).write_bytes(out)
            out = b""
        n = len(run.steps) + 1
        # beside the working directory (not compared), for a look with --keep
        (side_root / case.name / f"step{n}.stdout").write_bytes(out)
        (side_root / case.name / f"step{n}.stderr").write_bytes(err)
        (side_root / case.name / f"step{n}.rc").write_text(f"{rc}\n")
        run.steps.append((rc, out, err))
    run.seconds = time.monotonic() - start
    for dirpath, dirnames, filenames in os.walk(work):
        rel_dir = Path(dirpath).relative_to(work)
        for name in sorted(dirnames + filenames):
            rel = rel_dir / name
            if rel_dir == Path(".") and name in ("data", "fx"):
                continue  # our symlinks to the inputs
            p = work / rel
            if p.is_symlink():
                run.files[str(rel)] = ("-> " + os.readlink(p)).encode()
            elif p.is_file():
                run.files[str(rel)] = p.read_bytes()
    run.tmp_left = sorted(os.listdir(tmpdir))
    return run


# ---------------------------------------------------------------------------------------------
# Comparing
# ---------------------------------------------------------------------------------------------

def as_text(data):
    """The text of bytes that look like text, else None."""
    if b"\0" in data[:65536]:
        return None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return None


def clip(line, start=0):
    line = line.rstrip("\n")
    if start > 0:
        line = "…" + line[start:]
    return line if len(line) <= CLIP else line[:CLIP] + f"… ({len(line)} chars)"


def first_difference(a, b):
    """(line number, column) of the first difference of two texts, 1-based."""
    la, lb = a.splitlines(), b.splitlines()
    for i, (x, y) in enumerate(zip(la, lb)):
        if x != y:
            col = next((j for j, (p, q) in enumerate(zip(x, y)) if p != q), min(len(x), len(y)))
            return i + 1, col + 1, x, y
    i = min(len(la), len(lb))
    return i + 1, 1, (la[i] if i < len(la) else "<end>"), (lb[i] if i < len(lb) else "<end>")


def json_first_difference(a, b, path="$"):
    """The JSON path of the first difference of two parsed documents, with both values."""
    if type(a) is not type(b):
        return path, a, b
    if isinstance(a, dict):
        for k in list(a.keys()) + [k for k in b.keys() if k not in a]:
            if k not in a or k not in b:
                return f"{path}.{k}", a.get(k, "<absent>"), b.get(k, "<absent>")
            d = json_first_difference(a[k], b[k], f"{path}.{k}")
            if d:
                return d
        if list(a.keys()) != list(b.keys()):
            return f"{path} (key order)", list(a.keys()), list(b.keys())
        return None
    if isinstance(a, list):
        for i, (x, y) in enumerate(zip(a, b)):
            d = json_first_difference(x, y, f"{path}[{i}]")
            if d:
                return d
        if len(a) != len(b):
            return f"{path} (length)", len(a), len(b)
        return None
    return None if a == b else (path, a, b)


def text_diff_report(label, a, b):
    """Lines describing how two (normalised) texts differ."""
    lines = []
    ln, col, x, y = first_difference(a, b)
    lines.append(f"    first difference: {label} line {ln}, column {col}")
    start = max(0, col - 60)
    lines.append(f"      old: {clip(x, start)}")
    lines.append(f"      new: {clip(y, start)}")
    if label.endswith(".json") or a.lstrip().startswith(("{", "[")):
        try:
            # numbers are compared as written (parse_float=str), never as rounded floats
            ja = json.loads(a, parse_float=str, parse_constant=str)
            jb = json.loads(b, parse_float=str, parse_constant=str)
            d = json_first_difference(ja, jb)
            if d:
                lines.append(f"    first JSON difference at {d[0]}: "
                             f"{clip(json.dumps(d[1]))}  ->  {clip(json.dumps(d[2]))}")
        except ValueError:
            pass
    diff = list(difflib.unified_diff(a.splitlines(), b.splitlines(), f"old/{label}",
                                     f"new/{label}", n=2, lineterm=""))
    for d in diff[:DIFF_LINES]:
        lines.append("    " + clip(d))
    if len(diff) > DIFF_LINES:
        lines.append(f"    ... ({len(diff) - DIFF_LINES} more diff lines)")
    return lines


def png_size(data):
    if data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) >= 24:
        w, h = struct.unpack(">II", data[16:24])
        return f"{w}x{h}"
    return None


def compare_bytes(label, a, b, repl_old, repl_new):
    """None when the same, else (short reason, detail lines)."""
    if a is None or b is None:
        return (f"{label} written by {'new only' if a is None else 'old only'}", [])
    if label.endswith(".gz") or a[:2] == b"\x1f\x8b":
        if a == b:
            return None
        try:
            ua, ub = gzip.decompress(a), gzip.decompress(b)
        except (OSError, EOFError) as e:
            return (f"{label} differs (and does not decompress: {e})", [])
        if ua == ub:
            return (f"{label}: gzip bytes differ, decompressed content identical", [])
        r = compare_bytes(label.removesuffix(".gz") + " (decompressed)", ua, ub, repl_old,
                          repl_new)
        return r
    # text (JSON, YAML, SDF, CSV, SVG, HTML, stdout, ...: whatever is UTF-8 without NUL) is
    # normalised and diffed; anything else (PNG, raw floats) is compared byte for byte
    ta, tb = as_text(a), as_text(b)
    if ta is not None and tb is not None:
        na, nb = normalise(ta, repl_old), normalise(tb, repl_new)
        if na == nb:
            return None
        return (f"{label} differs", text_diff_report(label, na, nb))
    if a == b:
        return None
    detail = [f"    binary: {len(a)} vs {len(b)} bytes"]
    sa, sb = png_size(a), png_size(b)
    if sa or sb:
        detail.append(f"    PNG: {sa} vs {sb}")
    first = next((i for i, (p, q) in enumerate(zip(a, b)) if p != q), min(len(a), len(b)))
    detail.append(f"    first differing byte at offset {first}")
    return (f"{label} differs (binary)", detail)


def compare_case(case, old, new):
    """A list of (reason, detail lines); empty when the case is the same."""
    problems = []
    for i, ((rc_a, out_a, err_a), (rc_b, out_b, err_b)) in enumerate(zip(old.steps, new.steps)):
        tag = f"step {i + 1} " if len(case.steps) > 1 else ""
        if rc_a != rc_b:
            problems.append((f"{tag}exit code {rc_a} -> {rc_b}", []))
        r = compare_bytes(f"{tag}stdout", out_a, out_b, old.repl, new.repl)
        if r:
            problems.append(r)
        ea = normalise(err_a.decode("utf-8", "replace"), old.repl)
        eb = normalise(err_b.decode("utf-8", "replace"), new.repl)
        unordered = case.unordered_stderr and not RAW
        if unordered:
            ea = "".join(sorted(ea.splitlines(keepends=True)))
            eb = "".join(sorted(eb.splitlines(keepends=True)))
        if ea != eb:
            label = f"{tag}stderr" + (" (lines sorted)" if unordered else "")
            problems.append((f"{label} differs", text_diff_report(label, ea, eb)))
    for rel in sorted(set(old.files) | set(new.files)):
        r = compare_bytes(rel, old.files.get(rel), new.files.get(rel), old.repl, new.repl)
        if r:
            problems.append(r)
    for rel in case.files:
        if rel not in old.files and rel not in new.files:
            problems.append((f"{rel} written by neither (the case expects it: fix the case)",
                             []))
    if len(old.tmp_left) != len(new.tmp_left):
        problems.append((f"temporary files left in TMPDIR: {len(old.tmp_left)} -> "
                         f"{len(new.tmp_left)}", [f"    old: {old.tmp_left}",
                                                  f"    new: {new.tmp_left}"]))
    return problems


# ---------------------------------------------------------------------------------------------
# Main
# ---------------------------------------------------------------------------------------------

def coverage_notes(binary, all_cases):
    """Subcommands of the binary's --help that no case runs (a new one needs cases)."""
    try:
        text = subprocess.run([binary, "--help"], capture_output=True, text=True,
                              stdin=subprocess.DEVNULL, timeout=60).stdout
    except (OSError, subprocess.SubprocessError):
        return []
    m = re.search(r"^Commands:\n(.*?)\n\n", text, re.S | re.M)
    if not m:
        return []
    listed = {ln.split()[0] for ln in m.group(1).splitlines() if ln.strip()} - {"help"}
    covered = {c.steps[0].argv[0] for c in all_cases if c.steps and c.steps[0].argv}
    covered |= {s.argv[0] for c in all_cases for s in c.steps if s.argv}
    return [f"note: subcommand {s!r} of {binary} --help has no case here: add some"
            for s in sorted(listed - covered)]


def main(argv=None):
    p = argparse.ArgumentParser(
        description="Run every gmwm command with two binaries and compare all outputs.")
    p.add_argument("old", nargs="?", help="the gmwm binary before the change")
    p.add_argument("new", nargs="?", help="the gmwm binary after the change")
    p.add_argument("--data", type=Path, default=DEFAULT_DATA,
                   help=f"the recordings folder [default: {DEFAULT_DATA}]")
    p.add_argument("--keep", type=Path, default=None,
                   help="keep the working directories in DIR (created; must be empty)")
    p.add_argument("--only", nargs="+", default=None, metavar="NAME",
                   help="run only these cases (shell-style patterns allowed)")
    p.add_argument("--list", action="store_true", help="list the cases and exit")
    p.add_argument("--no-normalise", action="store_true",
                   help="apply none of the normalisations (shows what they hide)")
    args = p.parse_args(argv)
    global RAW
    RAW = args.no_normalise

    all_cases = cases()
    names = [c.name for c in all_cases]
    assert len(names) == len(set(names)), "duplicate case names"
    if args.list:
        print("\n".join(names))
        return 0
    selected = all_cases
    if args.only:
        unknown = [o for o in args.only if not any(fnmatch.fnmatchcase(n, o) for n in names)]
        if unknown:
            p.error(f"no case matches {', '.join(unknown)} (see --list)")
        selected = [c for c in all_cases if any(fnmatch.fnmatchcase(c.name, o)
                                                 for o in args.only)]
    if not (args.old and args.new):
        p.error("give the two binaries: OLD_GMWM NEW_GMWM")

    binaries = []
    for b in (args.old, args.new):
        path = Path(b).resolve() if os.sep in b or Path(b).exists() else shutil.which(b)
        if not path or not os.access(path, os.X_OK) or not Path(path).is_file():
            p.error(f"{b}: not an executable file")
        binaries.append(str(path))
    data = args.data.resolve()
    if not (data / "adis_16405_imu1.csv.gz").exists():
        p.error(f"{data}: no adis_16405_imu1.csv.gz there (give --data DIR)")

    if args.keep:
        args.keep.mkdir(parents=True, exist_ok=True)
        if any(args.keep.iterdir()):
            p.error(f"--keep {args.keep}: not empty")
        root = args.keep.resolve()
    else:
        root = Path(tempfile.mkdtemp(prefix="gmwm-same-outputs-"))
    started = time.monotonic()
    try:
        fx = root / "fx"
        available, notes = make_fixtures(fx, data)
        print(f"old: {binaries[0]}\nnew: {binaries[1]}\ndata: {data}")
        for n in notes + coverage_notes(binaries[0], all_cases):
            print(n)
        print(flush=True)
        different, skipped, ran = [], [], 0
        width = max(len(c.name) for c in selected)
        for case in selected:
            missing = case.needs - available
            if missing:
                skipped.append(case.name)
                print(f"{case.name:<{width}}  skipped (needs {', '.join(sorted(missing))})",
                      flush=True)
                continue
            old = run_case(binaries[0], case, root / "old", fx, data)
            new = run_case(binaries[1], case, root / "new", fx, data)
            ran += 1
            problems = compare_case(case, old, new)
            if not problems:
                print(f"{case.name:<{width}}  same", flush=True)
                continue
            different.append(case.name)
            print(f"{case.name:<{width}}  DIFFERENT: "
                  + "; ".join(reason for reason, _ in problems), flush=True)
            for step in case.steps:
                print("    $ gmwm " + " ".join(_quote(a) for a in step.argv)
                      + (f" < {step.stdin}" if step.stdin else "")
                      + (f" > {step.stdout_to}" if step.stdout_to else ""))
            for _, detail in problems:
                for line in detail:
                    print(line)
            print(flush=True)
        elapsed = time.monotonic() - started
        print()
        if different:
            print("different: " + " ".join(different))
        tail = f" ({len(skipped)} skipped: {' '.join(skipped)})" if skipped else ""
        print(f"{ran} cases, {len(different)} different{tail}; {elapsed:.0f} s")
        if args.keep:
            print(f"working directories kept in {root}")
        return 1 if different else 0
    finally:
        if not args.keep:
            shutil.rmtree(root, ignore_errors=True)


def _quote(a):
    return a if re.fullmatch(r"[\w./:=,+@%^-]+", a) else "'" + a.replace("'", "'\\''") + "'"


if __name__ == "__main__":
    sys.exit(main())
