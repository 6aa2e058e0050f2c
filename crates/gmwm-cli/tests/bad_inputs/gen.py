#!/usr/bin/env python3
"""Writes the bad-input corpus files beside this script (run from anywhere; deterministic).

The signal of every well-formed file is gyro_x[k] = ((k*7919 + 13) % 1009) / 1000 - 0.5 and
gyro_y[k] = ((k*104729 + 7) % 997) / 1000 - 0.5, written with 3 decimals: the test computes the
expected Haar wavelet variance from the same formula. manifest.txt says how each file is run.
"""
import gzip, json, os, struct

HERE = os.path.dirname(os.path.abspath(__file__))
N = 256


def gx(k):
    return ((k * 7919 + 13) % 1009) / 1000 - 0.5


def gy(k):
    return ((k * 104729 + 7) % 997) / 1000 - 0.5


def rows(n=N, sep=",", header="gyro_x,gyro_y", end="\n", fmt="{:.3f}"):
    out = [] if header is None else [header.replace(",", sep)]
    for k in range(n):
        out.append(sep.join(fmt.format(v) for v in (gx(k), gy(k))))
    return end.join(out) + end


def one_col(n=N, header="gyro_x"):
    out = [] if header is None else [header]
    out += ["{:.3f}".format(gx(k)) for k in range(n)]
    return "\n".join(out) + "\n"


def timed(times, n=None):
    n = len(times) if n is None else n
    out = ["time,gyro_x,gyro_y"]
    for k, t in enumerate(times[:n]):
        out.append("{},{:.3f},{:.3f}".format(t, gx(k), gy(k)))
    return "\n".join(out) + "\n"


def put(name, data):
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(data)


def with_cell(text_cell, line_no=5):
    """The well-formed file with gyro_x on physical line `line_no` replaced by text_cell."""
    lines = rows().split("\n")
    parts = lines[line_no - 1].split(",")
    parts[0] = text_cell
    lines[line_no - 1] = ",".join(parts)
    return "\n".join(lines)


def f64(values):
    return struct.pack("<%dd" % len(values), *values)


def f32(values):
    return struct.pack("<%df" % len(values), *values)


base = rows()
# --- well formed in several spellings (expected to work)
put("ok_plain.csv", base)
put("ok_bom.csv", b"\xef\xbb\xbf" + base.encode())
put("ok_crlf.csv", rows(end="\r\n"))
put("ok_bom_crlf.csv", b"\xef\xbb\xbf" + rows(end="\r\n").encode())
put("ok_tab.tsv", rows(sep="\t"))
put("ok_tab_named.csv", rows(sep="\t"))
put("ok_semicolon.csv", rows(sep=";"))
put("ok_no_final_newline.csv", base.rstrip("\n"))
put("ok_spaces.csv", rows(sep=" , ", header="gyro_x , gyro_y").replace("\n", "  \n"))
put("ok_quoted_header.csv", rows(header='"gyro_x","gyro_y"'))
put("ok_utf8_header.csv", rows(header="gyro_x [°/s],gyro_y [°/s]"))
put("ok_gzip.csv.gz", gzip.compress(base.encode(), mtime=0))
put("ok_pow2_1024.csv", rows(n=1024))
put("ok_prime_1021.csv", rows(n=1021))
put("ok_prime_257.csv", rows(n=257))
put("ok_pow2_plus1_513.csv", rows(n=513))
put("ok_one_column.csv", one_col())
put("ok_gyro_accel.csv", rows(header="gyro_x,accel_x"))
put("ok_one_column_no_header.csv", one_col(header=None))
put("ok_scientific.csv", rows(fmt="{:.3e}"))
put("ok_f64.f64", f64([v for k in range(N) for v in (gx(k), gy(k))]))
put("ok_f64.f64.json", json.dumps({"sampling_frequency_hz": 100, "format": "f64", "n_columns": 2,
                                   "columns": [{"name": "gyro_x"}, {"name": "gyro_y"}]}))
put("ok_f32_prime_509.f32", f32([gx(k) for k in range(509)]))
put("ok_time_seconds.csv", timed([k / 100 for k in range(N)]))
put("ok_time_ns_epoch.csv", timed([1_700_000_000_000_000_000 + k * 10_000_000 for k in range(N)]))
put("ok_time_gap.csv", timed([k / 100 + (1.0 if k >= 128 else 0.0) for k in range(N)]))
put("ok_large_integers.csv", "gyro_x\n" + "".join("%d\n" % (12345678901234567890 + (k * 7919) % 1009 * 10**10) for k in range(N)))
# --- text that is not well formed
put("utf16le_bom.csv", b"\xff\xfe" + base.encode("utf-16-le"))
put("utf16be_bom.csv", b"\xfe\xff" + base.encode("utf-16-be"))
put("latin1_header.csv", rows(header="gyro_x (\xb0/s),gyro_y (\xb0/s)").encode("latin-1"))
put("cr_only.csv", rows(end="\r"))
put("blank_lines.csv", base.replace("\n", "\n\n", 20))
put("comment_lines.csv", "# ADIS16405, 100 Hz\n# deg/s\n" + base)
put("decimal_comma.csv", rows(sep=";").replace(".", ","))
put("pipe_separated.csv", rows(sep="|"))
put("trailing_comma.csv", base.replace("\n", ",\n"))
put("ragged_short.csv", "\n".join(base.split("\n")[:6] + ["0.100"] + base.split("\n")[7:]))
put("ragged_long.csv", "\n".join(base.split("\n")[:6] + ["0.1,0.2,0.3"] + base.split("\n")[7:]))
put("truncated_last_row.csv", base.rstrip("\n").rsplit(",", 1)[0] + "\n")
put("quoted_numbers.csv", rows(fmt='"{:.3f}"'))
put("hex_value.csv", with_cell("0x1F"))
put("nan_lower.csv", with_cell("nan"))
put("nan_upper.csv", with_cell("NaN"))
put("nan_na.csv", with_cell("NA"))
put("nan_null.csv", with_cell("null"))
put("nan_n_a.csv", with_cell("N/A"))
put("nan_dash.csv", with_cell("-"))
put("empty_cell.csv", with_cell(""))
put("inf_lower.csv", with_cell("inf"))
put("inf_signed.csv", with_cell("-Infinity"))
put("inf_plus.csv", with_cell("+inf"))
put("inf_windows.csv", with_cell("1.#INF"))
put("overflow_1e400.csv", with_cell("1e400"))
put("huge_1e300.csv", "gyro_x\n" + "".join("%.3fe300\n" % gx(k) for k in range(N)))
put("huge_1e200.csv", "gyro_x\n" + "".join("%.3fe200\n" % gx(k) for k in range(N)))
put("tiny_1e-300.csv", "gyro_x\n" + "".join("%.3fe-300\n" % gx(k) for k in range(N)))
put("denormal.csv", "gyro_x\n" + "".join("%de-324\n" % (k % 7) for k in range(N)))
# --- time stamps
put("time_out_of_order.csv", timed([k / 100 for k in range(10)] + [0.05] + [k / 100 for k in range(11, N)]))
put("time_duplicated.csv", timed([k / 100 if k != 10 else 9 / 100 for k in range(N)]))
put("time_constant.csv", timed([5.0] * N))
put("time_decreasing.csv", timed([(N - k) / 100 for k in range(N)]))
put("time_nan.csv", timed([k / 100 if k != 10 else "nan" for k in range(N)]))
put("time_only.csv", "time\n" + "".join("%g\n" % (k / 100) for k in range(N)))
# --- sizes
put("empty.csv", b"")
put("empty.f64", b"")
put("blank_only.csv", "\n  \n\n")
put("header_only.csv", "gyro_x,gyro_y\n")
put("one_sample.csv", rows(n=1))
put("two_samples.csv", rows(n=2))
put("three_samples.csv", rows(n=3))
put("constant.csv", "gyro_x,gyro_y\n" + "0.25,0.25\n" * N)
put("constant_zero.csv", "gyro_x,gyro_y\n" + "0,0\n" * N)
put("one_sample.f64", f64([0.5]))
# --- binary
put("odd_size.f64", f64([gx(k) for k in range(N)]) + b"\x01\x02\x03")
put("odd_size.f32", f32([gx(k) for k in range(N)]) + b"\x01\x02")
put("ncols_mismatch.f64", f64([gx(k) for k in range(N + 1)]))
put("ncols_mismatch.f64.json", json.dumps({"sampling_frequency_hz": 100, "n_columns": 2}))
put("nan.f64", f64([gx(k) if k != 17 else float("nan") for k in range(N)]))
put("f64_data.bin", f64([gx(k) * 1e-3 for k in range(N)]))
put("binary_noext.dat", bytes((k * 37 + 11) % 256 for k in range(2048)))
put("gzip_truncated.csv.gz", gzip.compress(rows(n=4096).encode(), mtime=0)[:3000])
put("gzip_garbage.csv.gz", b"\x1f\x8b\x08\x00" + bytes((k * 91) % 256 for k in range(500)))
put("ln200_truncated.bin", bytes(100))
# --- JSON where a recording or a saved WV is read
put("json_array.json", "[]")
put("json_object_empty.json", "{}")
put("json_series_empty.json", '{"series": []}')
put("json_broken.json", '{"series": [')
put("json_bad_tau.json", json.dumps({"freq_hz": 100, "series": [{"name": "x", "n": 256, "tau": [2, 3],
                                     "wv": [1, 0.5], "ci_low": [0.9, 0.4], "ci_high": [1.1, 0.6]}]}))
put("json_named_csv.csv", '{"series": []}')
put("sidecar_broken.csv", base)
put("sidecar_broken.csv.json", "{ not json")
