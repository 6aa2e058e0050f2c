"""The Python package against the CLI and the engine: to_dict() is the CLI's --json for the
same call (WV, fit, select, calibrate on the ADIS16405 recording), numpy dtypes and layouts
(borrowed without a copy where contiguous float64), every bad input raising a clear exception,
and the notebook example run end to end."""

from __future__ import annotations

import json
import os
import runpy
import subprocess
from pathlib import Path

import numpy as np
import pytest

import gmwm

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
DATA = Path(os.environ.get("GMWM_DATA_DIR", REPO.parent / "shared" / "data"))
ADIS = DATA / "adis_16405_imu1.csv.gz"
GMWM_BIN = Path(os.environ.get("GMWM_BIN", REPO / "target" / "release" / "gmwm"))


def cli_json(*args: str):
    """The CLI's --json document for the same call."""
    assert GMWM_BIN.exists(), f"build the CLI first (cargo build --release): {GMWM_BIN}"
    out = subprocess.run([str(GMWM_BIN), *args, "--json"], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


# ---------------------------------------------------------------- parity with the CLI


def test_wv_to_dict_is_the_cli_json():
    assert gmwm.wv(str(ADIS)).to_dict() == cli_json("wv", str(ADIS))
    robust = gmwm.wv(str(ADIS), columns="gyro_x,accel_z", robust=True, eff=0.8)
    assert robust.to_dict() == cli_json("wv", str(ADIS), "--columns", "gyro_x,accel_z", "--robust", "--eff", "0.8")


def test_avar_to_dict_is_the_cli_json():
    doc = gmwm.avar(str(ADIS), columns=["gyro_y"], kind="hadamard").to_dict()
    assert doc == cli_json("avar", str(ADIS), "--columns", "gyro_y", "--kind", "hadamard")


def test_avar_pairs_the_deviation_with_a_deviation_interval():
    s = gmwm.avar(str(ADIS), columns=["gyro_x"])["gyro_x"]
    np.testing.assert_allclose(s.adev_ci_low, np.sqrt(s.ci_low), rtol=1e-15)
    np.testing.assert_allclose(s.adev_ci_high, np.sqrt(s.ci_high), rtol=1e-15)
    assert np.all((s.adev_ci_low <= s.adev) & (s.adev <= s.adev_ci_high))


def test_fit_to_dict_is_the_cli_json():
    model = "AR1()+WN()+RW()"
    py = gmwm.fit(str(ADIS), columns=["gyro_x"], model=model, G=2000, seed=7).to_dict()
    cli = cli_json("fit", str(ADIS), "--columns", "gyro_x", "--model", model, "--G", "2000", "--seed", "7")
    assert py == cli


def test_fit_augment_is_the_cli_json():
    # GMWM+ (docs/methods.md §5.15) beside the fit, as `gmwm fit --augment`
    model = "AR1()+WN()+RW()"
    py = gmwm.fit(str(ADIS), columns=["gyro_y"], model=model, G=2000, seed=7, augment="acf:2").to_dict()
    cli = cli_json(
        "fit", str(ADIS), "--columns", "gyro_y", "--model", model, "--G", "2000", "--seed", "7", "--augment", "acf:2"
    )
    assert py == cli
    assert py["fits"][0]["augmented"]["augment"] == "acf:2"
    with pytest.raises(gmwm.GmwmError, match="augment"):
        gmwm.fit(str(ADIS), columns=["gyro_y"], model=model, augment="acf:0")


def test_select_to_dict_is_the_cli_json():
    model = "AR1()+WN()+RW()+QN()"
    py = gmwm.select(str(ADIS), columns=["gyro_z"], model=model, bootstrap=10, G=2000).to_dict()
    cli = cli_json(
        "select", str(ADIS), "--columns", "gyro_z", "--model", model, "--bootstrap", "10", "--G", "2000"
    )
    assert py == cli


def test_fit_inference_covariance_is_the_cli_json():
    # the exact V by default, the package's bootstrap on request; each as the CLI gives it
    model = "AR1()+WN()+RW()"
    for method in ("auto", "bootstrap"):
        py = gmwm.fit(
            str(ADIS), columns=["gyro_x"], model=model, G=2000, inference=True, covariance=method
        ).to_dict()
        cli = cli_json(
            "fit", str(ADIS), "--columns", "gyro_x", "--model", model, "--G", "2000", "--inference",
            "--covariance", method,
        )
        assert py == cli
        assert py["fits"][0]["inference"]["v_method"] == ("exact" if method == "auto" else "bootstrap")


def test_calibrate_to_dict_is_the_cli_json():
    py = gmwm.calibrate(str(ADIS), model="2*AR1()+WN()+RW()", bootstrap=10, G=2000)
    # calibrate writes its JSON with --json FILE; "-" is standard output
    out = subprocess.run(
        [str(GMWM_BIN), "calibrate", str(ADIS), "--model", "2*AR1()+WN()+RW()", "--bootstrap", "10", "--G", "2000", "--json", "-"],
        capture_output=True, text=True, timeout=300,
    )
    assert out.returncode == 0, out.stderr
    cli = json.loads(out.stdout)
    assert py.to_dict() == cli
    table = py.to_dataframe()
    assert list(table["axis"]) == ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]
    assert table.loc[0, "noise_density"] == cli["axes"][0]["noise_density"]["value"]


def test_calibrate_a_saved_wavelet_variance_is_the_cli_json():
    saved = DATA / "precomputed" / "imar_wv.json"
    py = gmwm.calibrate(str(saved), columns=["gyro_x"], bootstrap=10, G=2000)
    out = subprocess.run(
        [str(GMWM_BIN), "calibrate", str(saved), "--columns", "gyro_x", "--bootstrap", "10",
         "--G", "2000", "--json", "-"],
        capture_output=True, text=True, timeout=300,
    )
    assert out.returncode == 0, out.stderr
    cli = json.loads(out.stdout)
    assert py.to_dict() == cli
    assert cli["samples"] == 5_760_000
    assert any("saved wavelet variances" in c for c in cli["checks"])


def test_calibrate_pooled_is_the_cli_json():
    second = ADIS.parent / "adis_16405_imu2.csv.gz"
    py = gmwm.calibrate_pooled(
        [str(ADIS), str(second)], columns=["gyro_x"], model="2*AR1()+WN()+RW()", bootstrap=10, G=2000
    )
    out = subprocess.run(
        [str(GMWM_BIN), "calibrate", str(ADIS), str(second), "--pool", "--columns", "gyro_x",
         "--model", "2*AR1()+WN()+RW()", "--bootstrap", "10", "--G", "2000", "--json", "-"],
        capture_output=True, text=True, timeout=300,
    )
    assert out.returncode == 0, out.stderr
    cli = json.loads(out.stdout)
    assert py.to_dict() == cli
    assert [r["name"] for r in cli["recordings"]] == [str(ADIS), str(second)]
    assert cli["samples"] == 2_000_000
    with pytest.raises(gmwm.GmwmError, match="at least two"):
        gmwm.calibrate_pooled([str(ADIS)], columns=["gyro_x"])


# ---------------------------------------------------------------- arrays: dtypes and layouts


@pytest.fixture(scope="module")
def imu():
    """Six columns of simulated noise, 2^14 samples, as (6, n) C order."""
    cols = [gmwm.simulate("WN(sigma2=1e-4)+RW(gamma2=1e-10)", n=1 << 14, freq=100, seed=s) for s in range(6)]
    return np.vstack(cols)


def wv_values(result):
    return [s.value for s in result]


def test_contiguous_float64_is_borrowed_not_copied(imu):
    before = gmwm._copies()
    gmwm.wv(imu[0], freq=100)
    gmwm.wv(imu, freq=100)  # (6, n) C order: each row is contiguous
    gmwm.wv(np.asfortranarray(imu.T), freq=100)  # (n, 6) Fortran order: each column is contiguous
    assert gmwm._copies() == before


def test_strided_columns_are_copied_and_counted(imu):
    before = gmwm._copies()
    by_rows = gmwm.wv(imu, freq=100)
    by_cols = gmwm.wv(np.ascontiguousarray(imu.T), freq=100)  # (n, 6) C order: strided columns
    assert gmwm._copies() == before + 6
    for a, b in zip(wv_values(by_rows), wv_values(by_cols)):
        np.testing.assert_array_equal(a, b)
    every_other = gmwm.wv(imu[0][::2], freq=50)
    np.testing.assert_array_equal(every_other[0].value, gmwm.wv(imu[0][::2].copy(), freq=50)[0].value)


def test_other_dtypes_and_containers_give_the_float64_results(imu):
    x = imu[0]
    ref = gmwm.wv(x, freq=100)[0].value
    x32 = x.astype(np.float32)
    np.testing.assert_array_equal(gmwm.wv(x32, freq=100)[0].value, gmwm.wv(x32.astype(np.float64), freq=100)[0].value)
    ints = np.round(x * 1e4).astype(np.int32)
    np.testing.assert_array_equal(gmwm.wv(ints, freq=100)[0].value, gmwm.wv(ints.astype(float), freq=100)[0].value)
    np.testing.assert_array_equal(gmwm.wv(list(x), freq=100)[0].value, ref)
    by_name = gmwm.wv({"gyro_x": x, "gyro_y": imu[1]}, freq=100)
    assert by_name.names() == ["gyro_x", "gyro_y"]
    np.testing.assert_array_equal(by_name["gyro_x"].value, ref)
    import pandas as pd

    df = pd.DataFrame({"a": x, "b": imu[1]})
    assert gmwm.wv(df, freq=100).names() == ["a", "b"]
    long = gmwm.wv(df, freq=100).to_dataframe()
    assert list(long.columns)[:3] == ["series", "level", "tau"]


def test_calibrate_arrays_with_units(imu):
    names = ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]
    units = ["rad/s"] * 3 + ["m/s^2"] * 3
    cal = gmwm.calibrate(imu, freq=100, names=names, units=units, model="AR1()+WN()+RW()", bootstrap=10, G=1000)
    n = cal.axis("gyro_x")["noise_density"]["value"]
    assert abs(n / 1e-3 - 1) < 0.1, n  # sigma2 = N^2 f: N = 1e-3 rad/s/sqrt(Hz)
    assert cal.axis("gyro_x")["noise_density"]["unit"] == "rad/s/√Hz"


def test_calibrate_tolerance_reaches_the_verdict(imu):
    names = ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]
    cal = gmwm.calibrate(imu, freq=100, names=names, model="WN()", bootstrap=10, G=200, tolerance=0.5)
    verdict = cal.axis("gyro_x")["verdict"]
    assert verdict["tolerance"] == 0.5
    assert all(s["explained"] == (s["inside_band"] or abs(s["deviation"]) <= 0.5) for s in verdict["scales"])
    with pytest.raises(ValueError, match="tolerance"):
        gmwm.calibrate(imu, freq=100, names=names, model="WN()", tolerance=2.0)


def test_calibrate_compares_with_a_datasheet(imu):
    names = ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]
    units = ["rad/s"] * 3 + ["m/s^2"] * 3
    cal = gmwm.calibrate(
        imu, freq=100, names=names, units=units, model="WN()", bootstrap=10, G=200, datasheet="N=2 deg/sqrt(h)"
    )
    n = cal.axis("gyro_x")["datasheet"]["N"]
    # 2 deg/sqrt(h) = 2 (pi / 180) / 60 rad/s/sqrt(Hz)
    assert abs(n["value_si"] / (2 * np.pi / 180 / 60) - 1) < 1e-12, n
    assert "N" not in (cal.axis("accel_x").get("datasheet") or {})
    with pytest.raises(ValueError, match="datasheet"):
        gmwm.calibrate(imu, freq=100, names=names, model="WN()", datasheet="N=2 furlongs")


def test_progress_is_called_and_the_gil_is_released(imu):
    import threading

    calls = []
    ticks = []
    stop = threading.Event()

    def spin():  # runs only while the engine has released the GIL
        while not stop.is_set():
            ticks.append(1)

    t = threading.Thread(target=spin)
    t.start()
    try:
        gmwm.select(imu[0], freq=100, model="AR1()+WN()+RW()", bootstrap=10, G=1000, progress=lambda d, n: calls.append((d, n)))
    finally:
        stop.set()
        t.join()
    done = [d for d, _ in calls]
    assert done == sorted(set(done)), "increasing, each count once"
    assert done[-1] == 7 and all(n == 7 for _, n in calls), calls
    assert len(ticks) > 1000, "another Python thread ran while the engine worked"


def test_simulate_components_sum_to_the_series():
    x, parts = gmwm.simulate("AR1(phi=0.9, sigma2=1)+WN(sigma2=2)", n=1000, seed=3, components=True)
    assert set(parts) == {"AR1(phi=0.9, sigma2=1)", "WN(sigma2=2)"}
    np.testing.assert_allclose(x, sum(parts.values()))
    np.testing.assert_array_equal(gmwm.simulate("WN(sigma2=1)", n=10, seed=1), gmwm.simulate("WN(sigma2=1)", n=10, seed=1))


def test_implied_and_read():
    imp = gmwm.implied("WN(sigma2=1)+RW(gamma2=0.01)", levels=8, freq=10)
    assert set(imp.processes) == {"WN(sigma2=1)", "RW(gamma2=0.01)"}
    np.testing.assert_allclose(imp.wv, imp.processes["WN(sigma2=1)"] + imp.processes["RW(gamma2=0.01)"])
    rec = gmwm.read(str(ADIS), columns=["gyro_x", "accel_z"])
    assert rec.names == ["gyro_x", "accel_z"] and rec.freq_hz == 100
    assert rec.units["gyro_x"].startswith("deg/s") and len(rec) == 1_000_000
    # the reader's row accounting is among its notes
    assert any(
        n.startswith("1000000 rows read, 1000000 samples used in each of 2 columns (gyro_x, accel_z)")
        for n in rec.notes
    ), rec.notes


def test_read_time_policy(tmp_path):
    p = tmp_path / "imu.csv"
    p.write_text("time,gyro_x\n0,0\n0.01,1\n0.01,9\n0.03,3\n0.02,2\n0.04,4\n")
    with pytest.raises(gmwm.GmwmError, match="--time-policy"):
        gmwm.read(str(p))
    rec = gmwm.read(str(p), time_policy="sort")
    np.testing.assert_array_equal(rec["gyro_x"], [0.0, 1.0, 2.0, 3.0, 4.0])
    rec = gmwm.read(str(p), time_policy="drop-duplicates")
    np.testing.assert_array_equal(rec["gyro_x"], [0.0, 1.0, 3.0, 4.0])
    with pytest.raises(gmwm.GmwmError, match="time_policy"):
        gmwm.read(str(p), time_policy="nope")


# ---------------------------------------------------------------- bad input raises, never crashes


@pytest.mark.parametrize(
    "call, needle",
    [
        (lambda: gmwm.wv(np.zeros(100), freq=-1), "freq"),
        (lambda: gmwm.wv(np.zeros(100)), "freq"),
        (lambda: gmwm.wv(np.zeros((2, 3, 4)), freq=1), "1-D or 2-D"),
        (lambda: gmwm.wv(np.array(["a", "b"]), freq=1), "real numbers"),
        (lambda: gmwm.wv(np.array([]), freq=1), ""),
        (lambda: gmwm.wv(np.array([1.0, np.nan, 2.0, 3.0]), freq=1), ""),
        (lambda: gmwm.wv(np.random.default_rng(1).normal(size=256), freq=1, levels=0), "levels"),
        (lambda: gmwm.wv(np.random.default_rng(1).normal(size=256), freq=1, robust=True, eff=2.0), ""),
        (lambda: gmwm.wv(np.random.default_rng(1).normal(size=256), freq=1, filter="nope"), "nope"),
        (lambda: gmwm.wv(np.ones((2, 256)), freq=1, names=["a"]), "name"),
        (lambda: gmwm.wv("/nonexistent/imu.csv", freq=1), "/nonexistent/imu.csv"),
        (lambda: gmwm.wv(str(ADIS), format="nope"), "format"),
        (lambda: gmwm.avar(np.ones(256), freq=1, kind="nope"), "kind"),
        (lambda: gmwm.wv(np.random.default_rng(1).normal(size=256), freq=1, alpha=0.95), "for 95% intervals give 0.05"),
        (lambda: gmwm.implied("WN(sigma2=-1)", levels=4), ""),
        (lambda: gmwm.implied("XYZ()", levels=4), "XYZ"),
        (lambda: gmwm.simulate("WN(sigma2=1)", n=0), "n"),
        (lambda: gmwm.fit(np.random.default_rng(1).normal(size=4096), freq=1, model="WN(("), ""),
        (lambda: gmwm.fit(np.random.default_rng(1).normal(size=4096), freq=1, model="WN()", weights="nope"), "weights"),
        (lambda: gmwm.select(np.random.default_rng(1).normal(size=4096), freq=1, model="WN()+RW()", bootstrap=1), "bootstrap"),
        (lambda: gmwm.select(np.random.default_rng(1).normal(size=4096), freq=1), "model"),
        (lambda: gmwm.select(np.random.default_rng(1).normal(size=4096), freq=1, model="WN()+RW()", covariance="nope"), "covariance"),
        (lambda: gmwm.calibrate(np.ones((6, 4096)), freq=100), ""),
        (lambda: gmwm.calibrate(str(ADIS), gyro_unit="furlong"), "gyro_unit"),
        (lambda: gmwm.calibrate(str(ADIS), inflate=2, conservative=True), "inflate"),
    ],
)
def test_bad_input_raises_a_clear_exception(call, needle):
    with pytest.raises((gmwm.GmwmError, ValueError)) as e:
        call()
    assert str(e.value), "the message says what is wrong"
    assert needle in str(e.value)


def test_engine_errors_pickle_with_their_message():
    # a worker process sends its exceptions back pickled (the fleet relies on it)
    import pickle

    with pytest.raises(gmwm.GmwmError) as e:
        gmwm.wv(np.zeros(100), freq=-1)
    back = pickle.loads(pickle.dumps(e.value))
    assert type(back) is gmwm.GmwmError and str(back) == str(e.value)
    assert type(back).__module__ == "gmwm._native"


def test_unknown_keywords_are_type_errors():
    with pytest.raises(TypeError):
        gmwm.wv(np.ones(64), freq=1, robustt=True)
    with pytest.raises(TypeError):
        gmwm.wv(np.ones(64), freq=1, columns=["a"])  # a read option on an array


def test_the_notebook_example_runs_end_to_end():
    runpy.run_path(str(HERE.parent / "examples" / "notebook.py"), run_name="__main__")
