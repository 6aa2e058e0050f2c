//! Batch mode of `gmwm calibrate` and `gmwm wv`: a folder, a glob or several files in one
//! command; per-recording outputs; resumable runs (up to date, `--force`); a corrupt recording
//! reported by name while the others complete; duplicate stems refused.

mod common;

use common::{gmwm, run_json};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

/// Samples per recording: small, so that a calibration takes milliseconds.
const N: usize = 1 << 12;

/// The fast calibration flags of these tests: a two-term model, two bootstrap replicates.
const FAST: [&str; 6] = ["--model", "WN()+RW()", "--bootstrap", "2", "--G", "200"];

/// A seeded normal generator (xorshift64* and Box-Muller), enough for fixtures.
struct Normal(u64);

impl Normal {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d);
        ((x >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    fn next(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// A 100 Hz recording of a gyroscope (white noise and a random walk) and an accelerometer
/// (white noise): with a time column when `time`, else with a JSON sidecar giving the rate.
fn recording(dir: &Path, name: &str, seed: u64, time: bool) -> PathBuf {
    let mut g = Normal(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1);
    let mut text = String::from(if time {
        "time,gyro_x,accel_x\n"
    } else {
        "gyro_x,accel_x\n"
    });
    let mut walk = 0.0;
    for i in 0..N {
        walk += 0.01 * g.next();
        let (gyro, accel) = (g.next() + walk, 2.0 * g.next());
        if time {
            text.push_str(&format!("{:.2},", i as f64 / 100.0));
        }
        text.push_str(&format!("{gyro:.6},{accel:.6}\n"));
    }
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    if !time {
        std::fs::write(
            dir.join(format!("{name}.json")),
            r#"{"sampling_frequency_hz": 100}"#,
        )
        .unwrap();
    }
    path
}

/// A recording with a text cell in its middle: its reader fails.
fn corrupt(dir: &Path, name: &str) -> PathBuf {
    let path = recording(dir, name, 99, true);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    lines[1000] = "9.99,abc,0.5".into();
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    path
}

/// `imu00.csv` ... : `n` recordings, every other one with a sidecar instead of a time column.
fn recordings(dir: &Path, n: usize) -> Vec<PathBuf> {
    (0..n)
        .map(|i| recording(dir, &format!("imu{i:02}.csv"), i as u64 + 1, i % 2 == 0))
        .collect()
}

fn mtime(path: &Path) -> SystemTime {
    std::fs::metadata(path)
        .and_then(|m| m.modified())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Every file of `dir` and its modification time.
fn mtimes(dir: &Path) -> BTreeMap<PathBuf, SystemTime> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .map(|p| {
            let t = mtime(&p);
            (p, t)
        })
        .collect()
}

/// Runs the command, expecting exit code `code`; returns stdout and stderr.
fn run(cmd: &mut assert_cmd::Command, code: i32) -> (String, String) {
    let out = cmd.output().unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    );
    assert_eq!(out.status.code(), Some(code), "{stdout}\n{stderr}");
    (stdout, stderr)
}

/// The status of each recording in a JSON summary, by file name.
fn statuses(summary: &Value) -> BTreeMap<String, String> {
    summary["recordings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            let file = Path::new(r["file"].as_str().unwrap());
            (
                file.file_name().unwrap().to_string_lossy().into_owned(),
                r["status"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

/// The issue's bar: a folder of 20 small recordings and a corrupt one calibrates in one
/// command (the corrupt one reported by name with its reader's message, exit code 1 after the
/// others completed, their outputs written and the same documents as `--json FILE`); a second
/// run skips them all and rewrites nothing; a newer sidecar redoes its recording; `--force`
/// redoes them all.
#[test]
fn a_folder_calibrates_in_one_command_resumes_and_names_the_corrupt_recording() {
    let tmp = tempfile::tempdir().unwrap();
    let runs = tmp.path().join("runs");
    std::fs::create_dir(&runs).unwrap();
    let files = recordings(&runs, 20);
    let bad = corrupt(&runs, "broken.csv");
    std::fs::write(runs.join("README.md"), "not a recording").unwrap();

    let (output, stderr) = run(gmwm().arg("calibrate").arg(&runs).args(FAST), 1);
    // the table, then the spread of N, B, K across the 20 calibrated recordings (issue 29)
    let (table, spread) = output.split_once("\n\nacross ").expect("a spread section");
    assert!(
        spread.starts_with("20 recordings of one sensor"),
        "{spread}"
    );
    let n_row = spread
        .lines()
        .find(|l| l.trim_start().starts_with("gyro_x    N"))
        .unwrap();
    assert!(n_row.contains("spread"), "{n_row}");
    let lines: Vec<&str> = table.lines().collect();
    assert_eq!(lines.len(), 23, "header, 21 rows, counts: {table}");
    assert!(lines[0].starts_with("recording") && lines[0].contains("status"));
    assert!(lines[0].len() <= 100, "{table}");
    assert_eq!(
        lines[22],
        "21 recordings: 20 calibrated, 0 up to date, 1 failed"
    );
    let message = format!(
        "{}:1001: column gyro_x: \"abc\" is not a number",
        bad.display()
    );
    let row = lines.iter().find(|l| l.contains("broken.csv")).unwrap();
    assert!(row.contains("failed") && row.ends_with(&message), "{row}");
    assert!(
        stderr.contains(&format!("gmwm: error: {message}")),
        "{stderr}"
    );
    assert!(
        stderr.contains("gmwm: error: 1 of 21 recordings failed: "),
        "{stderr}"
    );
    for f in &files {
        let name = f.file_name().unwrap().to_string_lossy();
        let row = lines.iter().find(|l| l.contains(&*name)).unwrap();
        assert!(row.contains("calibrated"), "{row}");
        let json = f.with_extension("calibration.json");
        let doc: Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
        assert_eq!(
            doc["axes"].as_array().unwrap().len(),
            2,
            "{}",
            json.display()
        );
        assert_eq!(doc["freq_hz"], 100.0, "{}", json.display());
    }
    // the same document as a single run's --json FILE
    let single = tmp.path().join("single.json");
    run(
        gmwm()
            .arg("calibrate")
            .arg(&files[3])
            .args(FAST)
            .arg("--json")
            .arg(&single),
        0,
    );
    assert_eq!(
        std::fs::read(&single).unwrap(),
        std::fs::read(files[3].with_extension("calibration.json")).unwrap()
    );

    // a second run: every recording up to date, the corrupt one still failed, nothing written
    let before = mtimes(&runs);
    let out = gmwm()
        .arg("calibrate")
        .arg(&runs)
        .args(FAST)
        .args(["--json", "-"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let summary: Value = serde_json::from_slice(&out.stdout).unwrap();
    let s = statuses(&summary);
    assert_eq!(s.len(), 21);
    assert_eq!(s["broken.csv"], "failed");
    assert!(
        s.iter()
            .all(|(f, st)| f == "broken.csv" || st == "up_to_date"),
        "{s:?}"
    );
    assert_eq!(
        summary["counts"],
        serde_json::json!({"total": 21, "calibrated": 0, "up_to_date": 20, "failed": 1})
    );
    let broken = summary["recordings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["status"] == "failed")
        .unwrap();
    assert_eq!(broken["error"], message.as_str());
    assert_eq!(broken["outputs"], serde_json::json!([]));
    let ok = &summary["recordings"][1];
    assert_eq!(ok["axes"], 2);
    assert_eq!(
        ok["outputs"][0].as_str().unwrap(),
        files[0]
            .with_extension("calibration.json")
            .to_str()
            .unwrap()
    );
    assert_eq!(mtimes(&runs), before, "an up-to-date run writes nothing");

    // a sidecar newer than the outputs redoes its recording only
    let sidecar = runs.join("imu01.csv.json");
    std::fs::File::options()
        .write(true)
        .open(&sidecar)
        .unwrap()
        .set_modified(SystemTime::now())
        .unwrap();
    let (table, _) = run(gmwm().arg("calibrate").arg(&runs).args(FAST), 1);
    assert!(
        table.contains("21 recordings: 1 calibrated, 19 up to date, 1 failed"),
        "{table}"
    );
    let redone = files[1].with_extension("calibration.json");
    assert!(mtime(&redone) > before[&redone]);

    // --force redoes every one
    let before = mtimes(&runs);
    let (table, _) = run(
        gmwm().arg("calibrate").arg(&runs).args(FAST).arg("--force"),
        1,
    );
    assert!(
        table.contains("21 recordings: 20 calibrated, 0 up to date, 1 failed"),
        "{table}"
    );
    for f in &files {
        let json = f.with_extension("calibration.json");
        assert!(mtime(&json) > before[&json], "{}", json.display());
    }
    let leftovers: Vec<_> = mtimes(&runs)
        .into_keys()
        .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

/// `gmwm wv` over a glob into --out-dir: each recording's `<stem>.wv.json` is the document of
/// `gmwm wv FILE --json`; the corrupt one fails by name; a second run is up to date; --force
/// recomputes.
#[test]
fn wv_over_a_glob_writes_each_recordings_document() {
    let tmp = tempfile::tempdir().unwrap();
    let files = recordings(tmp.path(), 4);
    corrupt(tmp.path(), "broken.csv");
    let out_dir = tmp.path().join("wv");
    let glob = tmp.path().join("*.csv");
    let batch = || {
        let mut cmd = gmwm();
        cmd.arg("wv").arg(&glob).arg("--out-dir").arg(&out_dir);
        cmd
    };
    let (table, stderr) = run(&mut batch(), 1);
    assert!(
        table.contains("5 recordings: 4 computed, 0 up to date, 1 failed"),
        "{table}"
    );
    assert!(stderr.contains("broken.csv"), "{stderr}");
    for f in &files {
        let stem = f.file_stem().unwrap().to_string_lossy();
        let written = std::fs::read(out_dir.join(format!("{stem}.wv.json"))).unwrap();
        let single = gmwm().arg("wv").arg(f).arg("--json").output().unwrap();
        assert!(single.status.success());
        assert_eq!(written, single.stdout, "{stem}");
    }
    let before = mtimes(&out_dir);
    assert_eq!(before.len(), 4);
    let summary: Value = {
        let out = batch().arg("--json").output().unwrap();
        assert_eq!(out.status.code(), Some(1));
        serde_json::from_slice(&out.stdout).unwrap()
    };
    assert_eq!(
        summary["counts"],
        serde_json::json!({"total": 5, "computed": 0, "up_to_date": 4, "failed": 1})
    );
    let row = &summary["recordings"][1];
    assert_eq!(
        (row["series"].as_u64(), row["levels"].as_u64()),
        (Some(2), Some(11))
    );
    assert_eq!(mtimes(&out_dir), before);
    let (table, _) = run(batch().arg("--force"), 1);
    assert!(
        table.contains("4 computed, 0 up to date, 1 failed"),
        "{table}"
    );
    for (p, t) in &before {
        assert!(mtime(p) > *t, "{}", p.display());
    }
}

/// A folder and the glob of everything in it choose the same recordings: text and raw binary
/// with a sidecar, a rosbag2 folder as one recording; not sidecars, gmwm's outputs, hidden
/// files, raw binary without a sidecar, other folders or other files.
#[test]
fn a_glob_and_a_folder_choose_the_same_recordings() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    recording(dir, "a.csv", 1, false);
    recording(dir, "d.tsv", 2, true);
    std::fs::write(dir.join("c.f64"), [0u8; 8 * 64]).unwrap();
    std::fs::write(dir.join("c.f64.json"), r#"{"sampling_frequency_hz": 10}"#).unwrap();
    std::fs::write(dir.join("raw.bin"), [0u8; 64]).unwrap();
    std::fs::write(dir.join("e.bin"), [0u8; 8 * 64]).unwrap();
    std::fs::write(dir.join("e.bin.json"), r#"{"format": "f64"}"#).unwrap();
    std::fs::write(dir.join("a.calibration.json"), "{}").unwrap();
    std::fs::write(dir.join("a.report.html"), "").unwrap();
    std::fs::write(dir.join(".hidden.csv"), "x\n1\n").unwrap();
    std::fs::write(dir.join("notes.md"), "").unwrap();
    std::fs::create_dir(dir.join("bag2")).unwrap();
    std::fs::write(
        dir.join("bag2/metadata.yaml"),
        "rosbag2_bagfile_information:\n",
    )
    .unwrap();
    std::fs::create_dir(dir.join("other")).unwrap();
    std::fs::write(dir.join("other/x.csv"), "x\n1\n").unwrap();

    let chosen = |arg: &Path| {
        let out = gmwm().arg("wv").arg(arg).arg("--json").output().unwrap();
        let summary: Value = serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)));
        statuses(&summary).into_keys().collect::<Vec<_>>()
    };
    let expected = ["a.csv", "bag2", "c.f64", "d.tsv", "e.bin"];
    assert_eq!(chosen(dir), expected);
    assert_eq!(chosen(&dir.join("*")), expected);
    assert_eq!(chosen(&dir.join("*.csv")), ["a.csv"]);
}

/// Two recordings with the same stem into the same folder are refused before any work, in
/// one line naming both; separate folders are fine; in batch mode a file flag is a suffix,
/// never a path.
#[test]
fn duplicate_stems_and_file_flags_with_folders_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let (one, two) = (tmp.path().join("one"), tmp.path().join("two"));
    std::fs::create_dir(&one).unwrap();
    std::fs::create_dir(&two).unwrap();
    let a = recording(&one, "imu.csv", 1, true);
    let b = recording(&one, "imu.tsv", 2, true);
    let c = recording(&two, "imu.csv", 3, true);
    let out = tmp.path().join("out");
    for cmd in ["calibrate", "wv"] {
        common::assert_usage_error(
            gmwm().arg(cmd).arg(&a).arg(&b),
            &[
                &a.display().to_string(),
                &b.display().to_string(),
                "both write",
            ],
        );
        common::assert_usage_error(
            gmwm().arg(cmd).arg(&a).arg(&two).arg("--out-dir").arg(&out),
            &[&a.display().to_string(), &c.display().to_string()],
        );
    }
    assert!(!out.exists(), "refused before any work");
    let summary = run_json(gmwm().arg("wv").arg(&a).arg(&c).arg("--json"));
    assert_eq!(summary["counts"]["computed"], 2);
    common::assert_usage_error(
        gmwm()
            .arg("calibrate")
            .arg(&one)
            .args(["--kalibr", "out/imu.yaml"]),
        &["--kalibr out/imu.yaml", "batch mode", "without a folder"],
    );
    common::assert_usage_error(
        gmwm().arg("wv").arg(&one).arg("--csv"),
        &["--csv", "batch mode"],
    );
}

/// In batch mode --kalibr, --report and --export name suffixes of each recording's files in
/// --out-dir; all of them count for up to date: a missing one redoes its recording.
#[test]
fn batch_exports_and_reports_are_per_recording() {
    let tmp = tempfile::tempdir().unwrap();
    let files = recordings(tmp.path(), 2);
    let out = tmp.path().join("calib");
    let batch = || {
        let mut cmd = gmwm();
        cmd.arg("calibrate")
            .args(&files)
            .args(FAST)
            .args(["--gyro-unit", "rad/s", "--accel-unit", "m/s^2"])
            .args(["--kalibr", "imu.yaml", "--report", "report.html"])
            .args(["--export", "openvins", "ov.yaml", "--out-dir"])
            .arg(&out);
        cmd
    };
    let (table, _) = run(&mut batch(), 0);
    assert!(
        table.contains("2 recordings: 2 calibrated, 0 up to date, 0 failed"),
        "{table}"
    );
    for stem in ["imu00", "imu01"] {
        for suffix in ["imu.yaml", "ov.yaml", "report.html", "calibration.json"] {
            let p = out.join(format!("{stem}.{suffix}"));
            assert!(p.is_file(), "{} missing: {table}", p.display());
        }
        let yaml = std::fs::read_to_string(out.join(format!("{stem}.imu.yaml"))).unwrap();
        assert!(yaml.contains("gyroscope_noise_density"), "{yaml}");
    }
    let summary = run_json(batch().args(["--json", "-"]));
    assert_eq!(summary["counts"]["up_to_date"], 2);
    assert_eq!(
        summary["recordings"][0]["outputs"]
            .as_array()
            .unwrap()
            .len(),
        4
    );
    std::fs::remove_file(out.join("imu01.report.html")).unwrap();
    let summary = run_json(batch().args(["--json", "-"]));
    let s = statuses(&summary);
    assert_eq!(
        (s["imu00.csv"].as_str(), s["imu01.csv"].as_str()),
        ("up_to_date", "calibrated")
    );
    assert!(out.join("imu01.report.html").is_file());
}

/// One plain FILE keeps the single-recording behaviour: the full summary on stdout, nothing
/// written beside it; --out-dir makes it a batch of one.
#[test]
fn one_file_runs_as_before_unless_a_batch_flag_is_given() {
    let tmp = tempfile::tempdir().unwrap();
    let f = recording(tmp.path(), "imu.csv", 5, true);
    let (summary, _) = run(gmwm().arg("calibrate").arg(&f).args(FAST), 0);
    assert!(summary.contains("gyro_x: "), "{summary}");
    assert!(!tmp.path().join("imu.calibration.json").exists());
    let out = tmp.path().join("out");
    let (table, _) = run(
        gmwm()
            .arg("calibrate")
            .arg(&f)
            .args(FAST)
            .arg("--out-dir")
            .arg(&out),
        0,
    );
    assert!(table.contains("1 recording: 1 calibrated"), "{table}");
    assert!(out.join("imu.calibration.json").is_file());
}

/// A recording of the batch whose raw floats no sensor gives (f64 read as `--format f32`) gets
/// the single-file command's warning, naming it, in `gmwm wv` and `gmwm calibrate`.
#[test]
fn batch_warns_of_implausible_raw_floats_per_recording() {
    let dir = tempfile::tempdir().unwrap();
    // small doubles whose halves, read as f32, are finite but far beyond any sensor
    let bytes: Vec<u8> = (0..N)
        .flat_map(|i| (0.01 * (i % 7) as f64).to_le_bytes())
        .collect();
    let bad = dir.path().join("doubles.f32");
    std::fs::write(&bad, bytes).unwrap();
    // a sidecar naming the column a gyroscope axis, so that calibrate takes it
    std::fs::write(
        dir.path().join("doubles.f32.json"),
        r#"{"n_columns": 1, "columns": [{"name": "gyro_x"}]}"#,
    )
    .unwrap();
    let out = dir.path().join("out");
    for args in [
        vec!["wv", "--format", "f32", "--freq", "100"],
        [
            vec!["calibrate", "--format", "f32", "--freq", "100"],
            FAST.to_vec(),
        ]
        .concat(),
    ] {
        let (_, stderr) = run(
            gmwm()
                .args(&args)
                .arg(dir.path())
                .arg("--out-dir")
                .arg(&out)
                .arg("--force"),
            0,
        );
        let warning = format!("gmwm: warning: {}: read as f32", bad.display());
        assert!(stderr.contains(&warning), "{args:?}: {stderr}");
    }
}

/// `--datasheet` in batch mode: each recording's row counts its datasheet values by verdict, in
/// the table and the JSON summary (gyro N given 10x the simulated 0.1 rad/s/√Hz: better than
/// specified; accel N 10x below the simulated 0.2 m/s²/√Hz: worse), also when up to date;
/// without a datasheet neither the column nor the key.
#[test]
fn batch_counts_datasheet_verdicts_per_recording() {
    let tmp = tempfile::tempdir().unwrap();
    let files = recordings(tmp.path(), 2);
    let out = tmp.path().join("calib");
    let batch = |sheet: bool| {
        let mut cmd = gmwm();
        cmd.arg("calibrate")
            .args(&files)
            .args(FAST)
            .args(["--gyro-unit", "rad/s", "--accel-unit", "m/s^2", "--out-dir"])
            .arg(&out);
        if sheet {
            // 0.1 rad/s/√Hz = 343.8 °/√h; 0.2 m/s²/√Hz = 12 m/s/√h
            cmd.args(["--datasheet", "N=3438 deg/sqrt(h), N=1.2 m/s/sqrt(h)"]);
        }
        cmd
    };
    let (table, _) = run(&mut batch(true), 0);
    assert!(table.contains("datasheet"), "{table}");
    assert_eq!(
        table.matches("0 as specified, 1 better, 1 worse").count(),
        2,
        "{table}"
    );
    let summary = run_json(batch(true).args(["--json", "-"]));
    assert_eq!(summary["counts"]["up_to_date"], 2);
    for r in summary["recordings"].as_array().unwrap() {
        assert_eq!(r["datasheet"]["better"], 1, "{r}");
        assert_eq!(r["datasheet"]["worse"], 1, "{r}");
        assert_eq!(r["datasheet"]["as_specified"], 0, "{r}");
    }
    // dropping the datasheet redoes the recordings: no column, no key
    let summary = run_json(batch(false).args(["--json", "-"]));
    assert_eq!(summary["counts"]["calibrated"], 2, "{summary}");
    for r in summary["recordings"].as_array().unwrap() {
        assert!(r.get("datasheet").is_none(), "{r}");
    }
    // and giving it again redoes them with their counts
    let summary = run_json(batch(true).args(["--json", "-"]));
    assert_eq!(summary["counts"]["calibrated"], 2, "{summary}");
    assert_eq!(summary["recordings"][0]["datasheet"]["worse"], 1);
}
