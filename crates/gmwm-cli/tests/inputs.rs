//! End-to-end tests of how `gmwm` reads its inputs: time columns (unit, rate, gaps, `--freq`),
//! common IMU layouts, content sniffing, saved wavelet variances in every command, binary IMU
//! records, and `simulate -o` by extension. One test per problem a new user reported.

mod common;

use common::{gmwm, run_json, simulate};
use std::path::{Path, PathBuf};

/// Exit code 1, one `gmwm: error: ` line (notes and warnings aside) containing every needle,
/// nothing on stdout; returns the error line.
fn one_line_error(cmd: &mut assert_cmd::Command, needles: &[&str]) -> String {
    let out = cmd.output().expect("runs");
    assert_eq!(out.status.code(), Some(1), "{cmd:?}: {out:?}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<&str> = stderr
        .lines()
        .filter(|l| !l.starts_with("gmwm: warning:") && !l.starts_with("gmwm: note:"))
        .collect();
    assert_eq!(lines.len(), 1, "one line expected, got {stderr:?}");
    assert!(lines[0].starts_with("gmwm: error: "), "{stderr}");
    for n in needles {
        assert!(lines[0].contains(n), "{n:?} not in {stderr:?}");
    }
    assert!(out.stdout.is_empty(), "no partial results on stdout");
    lines[0].to_string()
}

/// Runs, asserts success, returns (stdout JSON, stderr).
fn json_and_stderr(cmd: &mut assert_cmd::Command) -> (serde_json::Value, String) {
    let out = cmd.output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{stderr}");
    (serde_json::from_slice(&out.stdout).unwrap(), stderr)
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// A deterministic pseudo-random value in [-0.5, 0.5).
fn noise(state: &mut u64) -> f64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    (*state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}

/// `rostopic echo -p` CSV at 100 Hz: ns stamps, a text column, orientation, rates.
fn rostopic_csv(dir: &Path, n: u64) -> PathBuf {
    let mut s = String::from(
        "%time,field.header.seq,field.header.stamp,field.header.frame_id,field.orientation.x,\
         field.angular_velocity.x,field.angular_velocity.y,field.angular_velocity.z,\
         field.linear_acceleration.x,field.linear_acceleration.y,field.linear_acceleration.z\n",
    );
    let mut st = 9u64;
    for i in 0..n {
        let stamp = 1_700_000_000_000_000_000 + i * 10_000_000;
        s.push_str(&format!("{},{i},{stamp},imu_link,0", stamp + 1_500_000));
        for _ in 0..6 {
            s.push_str(&format!(",{}", noise(&mut st)));
        }
        s.push('\n');
    }
    write(dir, "imu.csv", s.as_bytes())
}

/// A ROS-style time column in nanoseconds was read as seconds (rate 1e-7 Hz, no warning).
#[test]
fn issue_ros_nanosecond_stamps_give_the_rate() {
    let dir = tempfile::tempdir().unwrap();
    let p = rostopic_csv(dir.path(), 4096);
    let (doc, stderr) = json_and_stderr(gmwm().arg("wv").arg(&p).arg("--json"));
    let series = doc["series"].as_array().unwrap();
    let names: Vec<&str> = series.iter().map(|s| s["name"].as_str().unwrap()).collect();
    assert_eq!(
        names,
        [
            "field.angular_velocity.x",
            "field.angular_velocity.y",
            "field.angular_velocity.z",
            "field.linear_acceleration.x",
            "field.linear_acceleration.y",
            "field.linear_acceleration.z"
        ]
    );
    assert_eq!(series[0]["freq_hz"], 100.0);
    assert!(
        stderr.contains(&format!(
            "gmwm: note: {}: time column \"field.header.stamp\" (ns, from the header): 100 Hz",
            p.display()
        )),
        "{stderr}"
    );
    assert!(
        stderr.contains("not analysed: %time, field.header.seq"),
        "{stderr}"
    );
    // the same stamps given by index with the unit stated by the flag
    let (doc, stderr) = json_and_stderr(
        gmwm()
            .arg("wv")
            .arg(&p)
            .args(["--time-column", "3", "--time-unit", "ns", "--json"])
            .args(["--columns", "field.angular_velocity.z"]),
    );
    assert_eq!(doc["series"][0]["freq_hz"], 100.0);
    assert!(stderr.contains("(ns, as given)"), "{stderr}");
}

/// A 0.5 s gap in a 200 Hz log was averaged into the rate silently.
#[test]
fn issue_gap_is_warned_and_not_averaged() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = String::from(
        "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],\
         a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n",
    );
    let mut t = 1_403_636_579_758_555_392u64;
    let mut st = 3u64;
    for i in 0..8000 {
        if i == 4010 {
            t += 500_000_000;
        }
        s.push_str(&t.to_string());
        for _ in 0..6 {
            s.push_str(&format!(",{}", noise(&mut st)));
        }
        s.push('\n');
        t += 5_000_000;
    }
    let p = write(dir.path(), "data.csv", s.as_bytes());
    let (doc, stderr) = json_and_stderr(gmwm().arg("avar").arg(&p).arg("--json"));
    assert_eq!(doc["series"].as_array().unwrap().len(), 6);
    assert_eq!(doc["series"][0]["freq_hz"], 200.0);
    let warnings: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("gmwm: warning:"))
        .collect();
    assert_eq!(
        warnings,
        [format!(
            "gmwm: warning: {}: time column \"#timestamp [ns]\": 1 gap (100 samples missing), \
             largest 0.50 s at line 4012 (20.05 s after the start); 200 Hz between them",
            p.display()
        )]
    );
}

/// `--freq 100` silently overrode a 200 Hz time column; columns named `time` or `timestamp`
/// were analysed as sensor data.
#[test]
fn issue_freq_flag_disagreeing_with_the_time_column_and_time_not_analysed() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = String::from("time,x,timestamp\n");
    let mut st = 5u64;
    for i in 0..2048 {
        let t = i as f64 * 0.005;
        s.push_str(&format!("{t},{},{}\n", noise(&mut st), 1000.0 + t));
    }
    let p = write(dir.path(), "log.csv", s.as_bytes());
    let (doc, stderr) = json_and_stderr(gmwm().arg("wv").arg(&p).arg("--json"));
    let series = doc["series"].as_array().unwrap();
    assert_eq!(series.len(), 1, "only x is analysed");
    assert_eq!(series[0]["name"], "x");
    assert_eq!(series[0]["freq_hz"], 200.0);
    assert!(stderr.contains("not analysed: timestamp"), "{stderr}");
    let (doc, stderr) = json_and_stderr(gmwm().arg("wv").arg(&p).args(["--freq", "100", "--json"]));
    assert_eq!(doc["series"][0]["freq_hz"], 100.0, "the flag still wins");
    assert!(
        stderr.contains(&format!(
            "gmwm: warning: {}: --freq 100 Hz differs by 50% from time column \"time\" (200 Hz); \
             --freq is used",
            p.display()
        )),
        "{stderr}"
    );
}

/// `gmwm select`, `wv` and `avar` read a saved WV JSON as CSV; `--columns 1` was refused for a
/// WV JSON although the help promises indices.
#[test]
fn issue_saved_wv_json_in_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulate(
        dir.path(),
        "sim.csv",
        "AR1(phi=0.9, sigma2=0.1)+WN(sigma2=1)",
        4096,
        10.0,
        4,
    );
    let out = gmwm().arg("wv").arg(&csv).arg("--json").output().unwrap();
    assert!(out.status.success());
    let saved = write(dir.path(), "wv.json", &out.stdout);
    let original: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // wv: shown as read, by index too
    let (doc, stderr) =
        json_and_stderr(
            gmwm()
                .arg("wv")
                .arg(&saved)
                .args(["--columns", "1", "--json"]),
        );
    assert_eq!(doc["series"][0]["wv"], original["series"][0]["wv"]);
    assert_eq!(doc["series"][0]["ci_low"], original["series"][0]["ci_low"]);
    assert!(stderr.contains("not recomputed"), "{stderr}");
    // the content says JSON whatever the name
    let renamed = write(dir.path(), "wv.out", &out.stdout);
    let (doc, _) = json_and_stderr(gmwm().arg("wv").arg(&renamed).arg("--json"));
    assert_eq!(doc["series"][0]["wv"], original["series"][0]["wv"]);
    // avar: docs/methods.md §3.4 from the Haar WV, equal to the avar of the recording
    let (from_wv, stderr) = json_and_stderr(gmwm().arg("avar").arg(&saved).arg("--json"));
    assert!(stderr.contains("AV(m) = 2 WV(2m)"), "{stderr}");
    let (from_csv, _) = json_and_stderr(gmwm().arg("avar").arg(&csv).arg("--json"));
    let a = from_wv["series"][0]["avar"].as_array().unwrap();
    let b = from_csv["series"][0]["avar"].as_array().unwrap();
    assert!(!a.is_empty() && a.len() <= b.len());
    for (x, y) in a.iter().zip(b) {
        let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
        assert!((x - y).abs() <= 1e-9 * y.abs(), "{x} vs {y}");
    }
    one_line_error(
        gmwm().arg("avar").arg(&saved).args(["--kind", "modified"]),
        &["needs the raw recording", "docs/methods.md §3.4"],
    );
    // select, by index
    let (doc, _) = json_and_stderr(
        gmwm()
            .arg("select")
            .arg(&saved)
            .args(["--model", "AR1()+WN()", "--bootstrap", "10", "--G", "200"])
            .args(["--columns", "1", "--json"]),
    );
    assert_eq!(doc["selections"][0]["column"], "x");
    assert!(doc["selections"][0]["selected"].is_string());
    // fit, by index
    let doc = run_json(gmwm().arg("fit").arg(&saved).args([
        "--model",
        "AR1()+WN()",
        "--G",
        "200",
        "--columns",
        "1",
        "--json",
    ]));
    assert_eq!(doc["fits"][0]["column"], "x");
    one_line_error(
        gmwm()
            .arg("fit")
            .arg(&saved)
            .args(["--model", "WN()", "--columns", "2"]),
        &["series 2 is out of range; the file has 1 series"],
    );
}

/// A `.bin` file without `--format` was parsed as text and ~19 KB of raw bytes landed in the
/// error.
#[test]
fn issue_binary_without_format_is_a_short_error() {
    let dir = tempfile::tempdir().unwrap();
    let mut st = 11u64;
    let bytes: Vec<u8> = (0..19_000)
        .map(|_| (noise(&mut st) * 255.0 + 128.0) as u8)
        .collect();
    let p = write(dir.path(), "x.bin", &bytes);
    for cmd in ["wv", "avar", "fit", "select"] {
        let mut c = gmwm();
        c.arg(cmd).arg(&p);
        if cmd == "fit" || cmd == "select" {
            c.args(["--model", "WN()"]);
        }
        let line = one_line_error(
            &mut c,
            &["looks like binary data, not text", "--format f64"],
        );
        assert!(line.len() < 200 + p.as_os_str().len(), "{line}");
    }
}

/// `gmwm simulate -o x.f64` wrote CSV text into `x.f64`, and `-o x.txt` / `-o x.f64` both
/// wrote their sidecar to `x.json`.
#[test]
fn issue_simulate_output_follows_the_extension() {
    let dir = tempfile::tempdir().unwrap();
    let n = 3000;
    let model = "GM(beta=2, sigma2_gm=1)+WN(sigma2=0.01)";
    let files: Vec<PathBuf> = ["x.f64", "x.txt", "x.csv.gz", "x.tsv", "x.f32.bin"]
        .iter()
        .map(|name| {
            let p = simulate(dir.path(), name, model, n, 250.0, 6);
            let side = dir.path().join(format!("{name}.json"));
            assert!(side.is_file(), "{}", side.display());
            p
        })
        .collect();
    assert!(!dir.path().join("x.json").exists(), "no shared sidecar");
    assert_eq!(std::fs::metadata(&files[0]).unwrap().len(), 8 * n as u64);
    assert_eq!(std::fs::metadata(&files[4]).unwrap().len(), 4 * n as u64);
    let wv = |p: &Path| {
        let (doc, _) = json_and_stderr(gmwm().arg("wv").arg(p).arg("--json"));
        doc["series"][0].clone()
    };
    let text = wv(&files[1]);
    assert_eq!(text["freq_hz"], 250.0);
    for p in &files[..4] {
        let s = wv(p);
        assert_eq!(s["name"], "x", "{}", p.display());
        assert_eq!(s["n"], n);
        assert_eq!(
            s["freq_hz"],
            250.0,
            "rate from the sidecar: {}",
            p.display()
        );
        // same numbers; the raw binary streams (a chunked accumulator): rounding only
        let (a, b) = (s["wv"].as_array().unwrap(), text["wv"].as_array().unwrap());
        assert_eq!(a.len(), b.len());
        for (a, b) in a.iter().zip(b) {
            let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
            assert!(
                (a - b).abs() <= 1e-12 * b.abs(),
                "{}: {a} vs {b}",
                p.display()
            );
        }
    }
    assert_eq!(wv(&files[4])["n"], n);
    // --components into raw binary: the sidecar names the columns for --columns
    let comp = dir.path().join("c.f64");
    gmwm()
        .args([
            "simulate",
            "--model",
            model,
            "--n",
            "1000",
            "--components",
            "-o",
        ])
        .arg(&comp)
        .assert()
        .success();
    let (doc, _) =
        json_and_stderr(
            gmwm()
                .arg("wv")
                .arg(&comp)
                .args(["--columns", "x,3", "--json"]),
        );
    let names: Vec<&str> = doc["series"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["x", "WN(sigma2=0.01)"]);
    // unknown extension: one line listing the supported ones, nothing written
    let bad = dir.path().join("x.xyz");
    one_line_error(
        gmwm()
            .args(["simulate", "--model", model, "--n", "10", "-o"])
            .arg(&bad),
        &["a file name ending in .csv, .txt, .tsv", ".f64"],
    );
    assert!(!bad.exists());
}

fn ln200_records(times: &[f64], gyro_x: i32) -> Vec<u8> {
    let mut b = Vec::new();
    for (i, t) in times.iter().enumerate() {
        b.extend_from_slice(&t.to_le_bytes());
        let k = i as i32;
        let counts = [
            gyro_x + k % 3,
            k % 2,
            1 + k % 7,
            16384 - k % 4,
            k % 11,
            -(k % 5),
        ];
        for c in counts {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    b
}

/// Binary IMU records through `--format`: rates in rad/s at the records' rate, `--columns`
/// among gyro_x..accel_z; truncated and non-monotonic files are one-line errors.
#[test]
fn imu_records_through_format() {
    let dir = tempfile::tempdir().unwrap();
    let times: Vec<f64> = (0..512).map(|i| i as f64 * 0.005).collect();
    let p = write(dir.path(), "ln200.bin", &ln200_records(&times, 2_097_152));
    let (doc, _) = json_and_stderr(gmwm().arg("wv").arg(&p).args([
        "--format",
        "ln200",
        "--columns",
        "gyro_x,6",
        "--json",
    ]));
    let s = &doc["series"];
    assert_eq!(s[0]["name"], "gyro_x");
    assert_eq!(s[1]["name"], "accel_z");
    assert_eq!(s[0]["freq_hz"], 200.0);
    assert_eq!(s[0]["n"], 512);
    let (doc, _) = json_and_stderr(
        gmwm()
            .arg("avar")
            .arg(&p)
            .args(["--format", "ln200ig", "--json"]),
    );
    assert_eq!(doc["series"].as_array().unwrap().len(), 6);
    let mut cut = std::fs::read(&p).unwrap();
    cut.truncate(32 * 10 + 7);
    let t = write(dir.path(), "cut.bin", &cut);
    one_line_error(
        gmwm().arg("wv").arg(&t).args(["--format", "navchip-int"]),
        &[
            "size 327 bytes",
            "record size 32 bytes",
            "(7 bytes left over)",
        ],
    );
    let mut back = times.clone();
    back[100] = back[99];
    let t = write(dir.path(), "back.bin", &ln200_records(&back, 1));
    one_line_error(
        gmwm().arg("wv").arg(&t).args(["--format", "imar"]),
        &["record 100 (0-based): time 0.495 is not greater than the previous time 0.495"],
    );
}

#[test]
fn help_documents_the_input_detection() {
    let out = gmwm().args(["wv", "--help"]).output().unwrap();
    let help = String::from_utf8(out.stdout).unwrap();
    for needle in [
        "#timestamp [ns]",
        "--time-unit",
        "Unix-epoch",
        "1.5 median",
        "navchip-int",
        "binary data without --format is refused",
    ] {
        assert!(help.contains(needle), "{needle:?} not in --help");
    }
}

/// Row accounting (issue 15): every command that reads a recording says on stderr how many
/// rows it read and how many samples of each column it used, and what held none; the
/// calibration JSON carries the same account as `rows`; a streamed raw file says it too.
#[test]
fn every_command_accounts_for_the_rows_it_read() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate(
        dir.path(),
        "gyro.csv",
        "WN(sigma2=1e-4)+RW(gamma2=1e-10)",
        4096,
        100.0,
        3,
    );
    // a blank line and a header: 4096 rows, 1 header line, 1 blank line
    let text = std::fs::read_to_string(&sim).unwrap();
    let (_, rest) = text.split_once('\n').unwrap();
    let p = write(
        dir.path(),
        "gyro_x.csv",
        format!("gyro_x\n\n{rest}").as_bytes(),
    );
    let want = "4096 rows read, 4096 samples used in each of";
    let none = "no samples in 1 header line, 1 blank line; nothing dropped or filled in";
    for args in [
        vec!["wv"],
        vec!["avar"],
        vec!["fit", "--model", "WN()+RW()"],
        vec!["select", "--model", "WN()+RW()"],
    ] {
        let out = gmwm()
            .args(&args)
            .arg(&p)
            .args(["--freq", "100"])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{args:?}: {stderr}");
        let line = stderr
            .lines()
            .find(|l| l.starts_with("gmwm: note: ") && l.contains(want))
            .unwrap_or_else(|| panic!("{args:?}: no account in {stderr:?}"));
        assert!(line.contains(none), "{args:?}: {line}");
    }
    let (doc, _) = json_and_stderr(
        gmwm()
            .args(["calibrate", "--freq", "100", "--json", "-"])
            .arg(&p),
    );
    let rows = &doc["rows"];
    assert_eq!(rows["read"], 4096, "{rows}");
    assert_eq!(rows["used"], 4096);
    assert_eq!(rows["unit"], "row");
    assert_eq!(rows["missing"], 0);
    assert_eq!(rows["without_samples"][1]["what"], "blank line");
    assert!(doc["notes"]
        .as_array()
        .unwrap()
        .iter()
        .any(|n| n.as_str().unwrap().contains(want)));
    // raw binary, streamed by `gmwm wv`: every row
    let raw: Vec<u8> = (0..1000u32)
        .flat_map(|i| f64::from(i % 7).to_le_bytes())
        .collect();
    let p = write(dir.path(), "raw.f64", &raw);
    let out = gmwm()
        .args(["wv", "--freq", "10"])
        .arg(&p)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("1000 rows read, 1000 samples used in each of 1 column (col1); nothing dropped or filled in"),
        "{stderr}"
    );
}
