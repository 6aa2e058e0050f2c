//! Safe outputs (issue 15): `gmwm calibrate` killed while it writes its outputs leaves each
//! output file as it was before the run or complete, never partial; an output that is one of
//! the inputs is refused before any work.
//!
//! The kill is timed by the files, not by the clock: the test watches the output folder and
//! sends SIGKILL as soon as anything in it changes (a file created, grown or truncated), or
//! after the k-th change, so it lands inside the write phase on any machine. A writer that
//! truncated the destination and then filled it (`File::create` + writes) fails the first
//! case: the watcher sees the truncation and the file is left empty or partial.

#![cfg(unix)]

mod common;

use common::{assert_one_line_error, gmwm};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

const OLD_JSON: &str = "{\"previous\": \"run\"}\n";
const OLD_HTML: &str = "<!doctype html><title>previous run</title></html>\n";

/// A 2^15-sample gyro recording at 100 Hz (white noise and a random walk) with its sidecar.
fn recording(dir: &Path) -> PathBuf {
    let sim = common::simulate(
        dir,
        "sim.csv",
        "WN(sigma2=1e-6)+RW(gamma2=1e-12)",
        1 << 15,
        100.0,
        1,
    );
    let text = std::fs::read_to_string(&sim).unwrap();
    let body = text.split_once('\n').unwrap().1;
    let path = dir.join("imu.csv");
    std::fs::write(&path, format!("gyro_x\n{body}")).unwrap();
    std::fs::write(
        dir.join("imu.csv.json"),
        r#"{"sampling_frequency_hz": 100, "units": {"gyro": "rad/s"}}"#,
    )
    .unwrap();
    path
}

/// Name -> (length, modification time) of every entry in `dir`.
fn snapshot(dir: &Path) -> BTreeMap<String, (u64, Option<SystemTime>)> {
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(Result::ok)
        .filter_map(|e| {
            let m = e.metadata().ok()?;
            Some((
                e.file_name().to_string_lossy().into_owned(),
                (m.len(), m.modified().ok()),
            ))
        })
        .collect()
}

/// Runs the calibration writing `out/calib.json` and `out/report.html` over the old contents
/// and kills it at the `after`-th change seen in `out` (0: the first); returns whether it was
/// killed before it ended by itself.
fn run_and_kill(input: &Path, out: &Path, after: usize) -> bool {
    std::fs::write(out.join("calib.json"), OLD_JSON).unwrap();
    std::fs::write(out.join("report.html"), OLD_HTML).unwrap();
    let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("gmwm"))
        .arg("calibrate")
        .arg(input)
        .arg("--json")
        .arg(out.join("calib.json"))
        .arg("--report")
        .arg(out.join("report.html"))
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mut seen = snapshot(out);
    let mut changes = 0;
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        if child.try_wait().unwrap().is_some() {
            return false;
        }
        assert!(Instant::now() < deadline, "calibrate did not end");
        let now = snapshot(out);
        if now != seen {
            if changes == after {
                child.kill().unwrap();
                child.wait().unwrap();
                return true;
            }
            changes += 1;
            seen = now;
        }
    }
}

/// Every visible output is the old file or a complete new one; leftovers are only the hidden
/// temporary files of a killed writer.
fn check_outputs(out: &Path) {
    let json = std::fs::read_to_string(out.join("calib.json")).unwrap();
    if json != OLD_JSON {
        let doc: serde_json::Value = serde_json::from_str(&json)
            .unwrap_or_else(|e| panic!("calib.json is partial ({e}): {} bytes", json.len()));
        assert!(doc.get("axes").is_some() || doc.is_object(), "{doc}");
    }
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    if html != OLD_HTML {
        assert!(
            html.trim_end().ends_with("</html>"),
            "report.html is partial: {} bytes ending {:?}",
            html.len(),
            &html[html.len().saturating_sub(40)..]
        );
    }
    for name in snapshot(out).keys() {
        if name != "calib.json" && name != "report.html" {
            assert!(
                name.starts_with('.') && name.ends_with(".tmp"),
                "unexpected file {name}"
            );
        }
    }
}

#[test]
fn calibrate_killed_while_writing_leaves_the_old_outputs_or_complete_ones() {
    let dir = tempfile::tempdir().unwrap();
    let input = recording(dir.path());
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    // the first change is the first write (nothing else is written in `out`), so the runs
    // killed at it are always killed while writing; later ones are further into the write
    // phase, up to the renames (how many changes the watcher sees depends on the machine: a
    // run whose write phase shows fewer simply completes)
    let mut killed = 0;
    for after in [0, 0, 0, 0, 1, 1, 2, 3] {
        killed += usize::from(run_and_kill(&input, &out, after));
        check_outputs(&out);
    }
    assert!(killed >= 4, "only {killed} runs were killed while writing");
    // and a run left alone writes both, complete
    assert!(!run_and_kill(&input, &out, usize::MAX));
    check_outputs(&out);
    assert_ne!(
        std::fs::read_to_string(out.join("calib.json")).unwrap(),
        OLD_JSON
    );
    assert_ne!(
        std::fs::read_to_string(out.join("report.html")).unwrap(),
        OLD_HTML
    );
}

#[test]
fn an_output_over_an_input_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let input = recording(dir.path());
    let before = std::fs::read(&input).unwrap();
    assert_one_line_error(
        gmwm()
            .arg("calibrate")
            .arg(&input)
            .arg("--json")
            .arg(&input),
        &["--json", "imu.csv", "is an input"],
    );
    let sidecar = dir.path().join(".").join("imu.csv.json");
    assert_one_line_error(
        gmwm()
            .arg("calibrate")
            .arg(&input)
            .arg("--report")
            .arg(&sidecar),
        &["--report", "imu.csv.json", "is an input"],
    );
    assert_eq!(std::fs::read(&input).unwrap(), before);
}
