#!/usr/bin/env python3
"""Writes the seed corpus of the fuzz targets: fuzz/corpus/<target>/<name>, small generated files.

Nothing is copied from the shared recordings. ROS recordings are written by the real writer the
engine's tests use (crates/gmwm/tests/fixtures/write_imu_bag.py, Python `rosbags`); the sqlite3
ones are then vacuumed to 512-byte pages to stay a few KB. The first byte of the text, raw_binary
and imu_record seeds is the target's selector byte (see fuzz/src/lib.rs).

Usage: python3 fuzz/make_seeds.py   (needs `python3 -m pip install rosbags`; rewrites the corpus)
"""

import gzip
import shutil
import sqlite3
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

FUZZ = Path(__file__).resolve().parent
CORPUS = FUZZ / "corpus"
WRITER = FUZZ.parent / "crates" / "gmwm" / "tests" / "fixtures" / "write_imu_bag.py"


def put(target, name, data):
    d = CORPUS / target
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_bytes(data if isinstance(data, bytes) else data.encode())


def text_seeds():
    rows = [(k / 100.0, 0.01 * k, -0.02 * k, 1e-3, 9.81, 0.1, -0.1) for k in range(6)]
    csv = "time,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n" + "".join(
        ",".join(repr(v) for v in r) + "\n" for r in rows
    )
    tsv = csv.replace(",", "\t")
    plain = "".join(f"{0.5 * k:.3f},{1e-4 * k:.6e}\n" for k in range(8))
    # selector: bits 0-1 name (csv, tsv, txt, csv.gz), 2-3 format, 4-5 header, 6 time column 1
    put("text", "header_csv", b"\x00" + csv.encode())
    put("text", "header_tsv", b"\x01" + tsv.encode())
    put("text", "no_header_forced_csv", b"\x28" + plain.encode())
    put("text", "time_col1_absent", b"\x62" + plain.encode())
    put("text", "gzip_csv", b"\x03" + gzip.compress(csv.encode(), mtime=0))
    put("text", "ns_stamps_blank_lines",
        b"\x00#timestamp [ns],w_x,w_y\n1000000000,0.1,0.2\n\n1010000000,0.3,0.4\n"
        b"1020000000,0.5,0.6\n")
    put("text", "semicolon_quoted", b"\x10\"a\";\"b\"\n1;2\n3;4\n")


def raw_seeds():
    # selector: bit 0 f32, bits 1-3 ncols - 1, bit 4 format from the name
    vals = [0.25 * k - 1.0 for k in range(12)]
    put("raw_binary", "f64_1col", b"\x00" + struct.pack("<12d", *vals))
    put("raw_binary", "f64_3col_by_name", bytes([0x10 | (2 << 1)]) + struct.pack("<12d", *vals))
    put("raw_binary", "f32_2col", bytes([1 | (1 << 1)]) + struct.pack("<12f", *vals))
    put("raw_binary", "f32_4col_by_name", bytes([0x11 | (3 << 1)]) + struct.pack("<12f", *vals))


def record_seeds():
    # record types in ImuRecordType::ALL order; doubles for IXSEA (3) and NAVCHIP_FLT (4)
    names = ["imar", "ln200", "ln200ig", "ixsea", "navchip_flt", "navchip_int"]
    for sel, name in enumerate(names):
        double = sel in (3, 4)
        out = bytearray([sel])
        for k in range(8):
            t = 100.0 + k / 400.0
            incs = [k + 1, -k, 2 * k, 7, -7, 1000 + k]
            if double:
                out += struct.pack("<d6d", t, *[0.5 * v for v in incs])
            else:
                out += struct.pack("<d6i", t, *incs)
        put("imu_record", name, bytes(out))
    # a gap in the epochs
    out = bytearray([1])
    for k in [0, 1, 2, 5, 6]:
        out += struct.pack("<d6i", k / 200.0, 1, 2, 3, 4, 5, 6)
    put("imu_record", "ln200_gap", bytes(out))


NOISE = ["--rate", "200", "--gyro-wn-density", "1e-4", "--gyro-rw-density", "1e-6",
         "--accel-wn-density", "1e-3", "--accel-rw-density", "1e-5"]


def write_bag(tmp, container, name, extra):
    out = Path(tmp) / container / name
    out.parent.mkdir(exist_ok=True)
    subprocess.run([sys.executable, str(WRITER), "--container", container, "--out", str(out),
                    "--seed", "1", *NOISE, *extra], check=True)
    if container == "ros1":
        return out.read_bytes()
    storage = next(p for p in out.iterdir() if p.suffix in (".mcap", ".db3"))
    if storage.suffix == ".db3":
        db = sqlite3.connect(storage)
        db.execute("PRAGMA page_size=512")
        db.execute("VACUUM")
        db.close()
    return storage.read_bytes()


def ros_seeds():
    variants = {
        "ros1": ("ros1_bag", [("plain", ["--n", "3"]),
                              ("temperature", ["--n", "3", "--temperature-topic", "/imu/temperature",
                                               "--temperature-rate", "200", "--temperature-ramp", "20:21"]),
                              ("lz4", ["--n", "3", "--compression", "lz4"]),
                              ("bz2", ["--n", "3", "--compression", "bz2"]),
                              ("two_topics_extra", ["--n", "2", "--topic", "/imu0", "--topic",
                                                    "/imu1", "--extra-topic",
                                                    "/note:std_msgs/msg/String"])]),
        "mcap": ("mcap", [("plain", ["--n", "3"]),
                          ("temperature", ["--n", "3", "--temperature-topic", "/imu/temperature",
                                           "--temperature-rate", "200", "--temperature-ramp", "20:21"]),
                          ("zstd", ["--n", "3", "--compression", "zstd"]),
                          ("message_zstd", ["--n", "3", "--compression", "message"]),
                          ("two_topics_extra", ["--n", "2", "--topic", "/imu0", "--topic",
                                                "/imu1", "--extra-topic",
                                                "/note:std_msgs/msg/String"])]),
        "sqlite3": ("db3", [("plain", ["--n", "3"]),
                            ("temperature", ["--n", "3", "--temperature-topic", "/imu/temperature",
                                             "--temperature-rate", "200", "--temperature-ramp", "20:21"]),
                            ("message_zstd", ["--n", "3", "--compression", "message"]),
                            ("two_topics_extra", ["--n", "2", "--topic", "/imu0", "--topic",
                                                  "/imu1", "--extra-topic",
                                                  "/note:std_msgs/msg/String"])]),
    }
    with tempfile.TemporaryDirectory() as tmp:
        for container, (target, cases) in variants.items():
            for name, extra in cases:
                ext = {"ros1": ".bag"}.get(container, "")
                put(target, name, write_bag(tmp, container, name + ext, extra))


def wv_seeds():
    def series(name, n, levels, freq=None):
        wv = [1e-4 / 2**j for j in range(levels)]
        s = {"name": name, "n": n, "tau": [2.0 ** (j + 1) for j in range(levels)], "wv": wv,
             "ci_low": [0.8 * v for v in wv], "ci_high": [1.25 * v for v in wv]}
        if freq is not None:
            s["freq_hz"] = freq
        return s

    import json
    put("wv_json", "one_series", json.dumps({"freq_hz": 100.0, "series": [
        series("gyro_x", 1024, 6)]}))
    put("wv_json", "two_series_own_rate", json.dumps({"series": [
        series("gyro_x", 4096, 8, 200.0), series("accel_z", 4096, 8, 200.0)]}))
    full = series("gyro_y", 512, 5)
    full.update({"transform": "modwt", "filter": "haar", "alpha": 0.05,
                 "n_coefficients": [511, 509, 505, 497, 481], "eta": [255, 127, 63, 31, 15]})
    full["wv"][2] = None
    put("wv_json", "full_with_null", json.dumps({"freq_hz": 50, "series": [full]}))
    # wv_fit: a model's text, a newline, a saved WV (one claims n = 2^40 over 40 levels)
    for i, (model, s) in enumerate([
        ("WN()+RW()", series("gyro_x", 4096, 8)),
        ("ARMA(2,1)", series("x", 2.0 ** 40, 40)),
        ("GM()+WN()+QN()", series("gyro_z", 2 ** 20, 16, 200.0)),
        ("AR(2)(0.5, -0.2, 1e-4)+MA(1)", series("y", 1e6, 12)),
    ]):
        put("wv_fit", f"fit{i}", model + "\n" + json.dumps({"freq_hz": 100.0, "series": [s]}))


def sidecar_seeds():
    vals12 = struct.pack("<12d", *[float(k) for k in range(12)])
    put("sidecar", "f64_named", b'{"name": "x", "format": "f64", "n_columns": 3, "columns": '
        b'[{"name": "time"}, {"name": "gyro_x", "meaning": "gyroscope X axis"}, '
        b'{"name": "w", "meaning": "accelerometer Z axis"}], "sampling_frequency_hz": 1.0}\x00'
        + vals12)
    put("sidecar", "f32_summary", b'{"format": "f32", "n_columns": 2, "n_rows": 6, '
        b'"units": {"gyro": "deg/s", "accel": "g"}, "summary": {"col1": {"mean": 0.5, '
        b'"var": 1e-3, "min": -1, "max": 2}}}\x00' + struct.pack("<12f", *range(12)))
    put("sidecar", "csv_rate", b'{"format": "csv", "sampling_frequency_hz": 100, "sensor": '
        b'"ADIS"}\x00gyro_x,gyro_y\n1,2\n3,4\n5,6\n')
    put("sidecar", "record_type", b'{"format": "ln200"}\x00'
        + b"".join(struct.pack("<d6i", k / 100.0, 1, 2, 3, 4, 5, 6) for k in range(4)))
    put("sidecar", "default_payload", b'{"n_columns": 2}')


def model_seeds():
    for i, m in enumerate([
        "3*GM()+WN()+QN()+RW()",
        "AR1(phi=0.9, sigma2=0.1)+WN()",
        "ARMA(2,1)(ar1=0.5, ma1=0.3, sigma2=1)",
        "AR(2)(0.5, -0.2, 1e-3) + MA(3) + DR(1e-7)",
        "GM(beta=2.5, sigma2_gm=1e-6)+GM(0.1, 2e-5)+WN(sigma2=3.2e-9)+RW",
        "ma1(theta=-0.4, sigma2=.5)+qn(1e-10)",
        "ARMA11(0.2, 0.3, 1.0)+2*AR1()",
    ]):
        put("model_text", f"model{i}", m)


def main():
    if CORPUS.exists():
        shutil.rmtree(CORPUS)
    text_seeds()
    raw_seeds()
    record_seeds()
    ros_seeds()
    wv_seeds()
    sidecar_seeds()
    model_seeds()
    for d in sorted(CORPUS.iterdir()):
        sizes = [p.stat().st_size for p in d.iterdir()]
        print(f"{d.name}: {len(sizes)} seeds, largest {max(sizes)} bytes")


if __name__ == "__main__":
    main()
