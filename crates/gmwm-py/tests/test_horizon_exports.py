"""`gmwm calibrate --horizon T`: the filter files it writes parse as the stacks read them
(Kalibr: PyYAML; OpenVINS, VINS-Fusion, ORB-SLAM3: OpenCV's FileStorage), carry the horizon's
comment lines, and hold the pair the JSON reports; the Python call returns the same pair."""

import json
import subprocess
from pathlib import Path

import cv2
import pytest
import yaml

import gmwm
from test_api import ADIS, GMWM_BIN

HORIZON = 600.0


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    out = tmp_path_factory.mktemp("horizon")
    files = {
        "kalibr": out / "imu.yaml",
        "openvins": out / "kalibr_imu_chain.yaml",
        "vins": out / "vins.yaml",
        "orbslam3": out / "orbslam3.yaml",
    }
    args = [str(GMWM_BIN), "calibrate", str(ADIS), "--horizon", str(HORIZON), "--json", str(out / "c.json"), "-q"]
    for stack, path in files.items():
        args += ["--export", stack, str(path)]
    run = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    return files, json.loads((out / "c.json").read_text())


def worst(doc, kind, key):
    return max(a["horizon"][key] for a in doc["axes"] if a["kind"] == kind)


def test_every_axis_reports_its_pair(exported):
    _, doc = exported
    for a in doc["axes"]:
        h = a["horizon"]
        assert h["horizon_s"] == HORIZON
        # never below the plain estimate, and at most 3x the model at the horizon
        assert h["noise_density"] >= a["noise_density"]["value"] * (1 - 1e-12)
        assert 1.0 - 1e-9 <= h["excess_at_horizon"] <= 3.0 + 1e-6
        assert h["binding"]


def test_kalibr_parses_with_pyyaml_and_says_what_it_bounds(exported):
    files, doc = exported
    text = files["kalibr"].read_text()
    values = yaml.safe_load(text)
    assert values["gyroscope_noise_density"] == pytest.approx(worst(doc, "gyro", "noise_density"), rel=1e-6)
    assert values["gyroscope_random_walk"] == pytest.approx(worst(doc, "gyro", "random_walk"), rel=1e-6)
    assert values["accelerometer_noise_density"] == pytest.approx(worst(doc, "accel", "noise_density"), rel=1e-6)
    assert values["accelerometer_random_walk"] == pytest.approx(worst(doc, "accel", "random_walk"), rel=1e-6)
    comments = [line for line in text.splitlines() if line.startswith("#")]
    assert any("--horizon 600" in c and "at least the fitted model's" in c for c in comments), comments
    assert sum("horizon bound 600 s" in c for c in comments) == 6, comments


@pytest.mark.parametrize(
    "stack, gyro_n, accel_n",
    [
        ("openvins", "imu0/gyroscope_noise_density", "imu0/accelerometer_noise_density"),
        ("vins", "gyr_n", "acc_n"),
        ("orbslam3", "IMU.NoiseGyro", "IMU.NoiseAcc"),
    ],
)
def test_opencv_stacks_read_the_pair(exported, stack, gyro_n, accel_n):
    files, doc = exported
    text = files[stack].read_text()
    assert text.startswith("%YAML:1.0")
    assert "--horizon 600" in text
    fs = cv2.FileStorage(str(files[stack]), cv2.FILE_STORAGE_READ)
    assert fs.isOpened()

    def read(path):
        node = fs.root()
        for part in path.split("/"):
            node = node.getNode(part)
        return node.real()

    assert read(gyro_n) == pytest.approx(worst(doc, "gyro", "noise_density"), rel=1e-6)
    assert read(accel_n) == pytest.approx(worst(doc, "accel", "noise_density"), rel=1e-6)
    fs.release()


def test_python_calibrate_gives_the_same_pair(exported):
    _, doc = exported
    res = gmwm.calibrate(str(ADIS), horizon=HORIZON).to_dict()
    assert [a["horizon"] for a in res["axes"]] == [a["horizon"] for a in doc["axes"]]
    with pytest.raises(Exception, match="one of inflate, conservative and horizon"):
        gmwm.calibrate(str(ADIS), horizon=HORIZON, inflate=2.0)
