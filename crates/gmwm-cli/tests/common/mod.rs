//! Helpers shared by the CLI test binaries (each binary uses a subset).
#![allow(dead_code)]

use assert_cmd::Command;
use std::path::{Path, PathBuf};

/// The `gmwm` binary under test.
pub fn gmwm() -> Command {
    Command::cargo_bin("gmwm").expect("binary built")
}

/// Address space a hostile-input run may use: 1.5 GB, as in a small container.
pub const MEMORY_LIMIT_KB: u64 = 1_536_000;
/// Wall-clock bound of a hostile-input run, s: a hang fails the test instead of the CI job.
pub const TIME_LIMIT_S: u64 = 120;

/// `gmwm` run by bash under `ulimit -v` [`MEMORY_LIMIT_KB`] and `timeout` [`TIME_LIMIT_S`]:
/// arguments added to the command go to `gmwm`. An allocation past the limit aborts the run
/// (exit 134), a hang ends with exit 124: either fails an assertion on the exit code.
pub fn gmwm_bounded() -> Command {
    let bin = assert_cmd::cargo::cargo_bin("gmwm");
    let mut cmd = Command::new("bash");
    cmd.args([
        "-c",
        &format!("ulimit -v {MEMORY_LIMIT_KB} && exec timeout {TIME_LIMIT_S} \"$0\" \"$@\""),
    ])
    .arg(bin);
    cmd
}

/// `gmwm simulate --model MODEL --n N --freq F --seed S -o DIR/NAME` (with its sidecar).
pub fn simulate(dir: &Path, name: &str, model: &str, n: usize, freq: f64, seed: u64) -> PathBuf {
    let path = dir.join(name);
    let out = gmwm()
        .args(["simulate", "--model", model])
        .args(["--n", &n.to_string(), "--freq", &freq.to_string()])
        .args(["--seed", &seed.to_string(), "-o"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    path
}

/// Runs `gmwm ARGS`, asserts success and parses stdout as JSON.
pub fn run_json(cmd: &mut Command) -> serde_json::Value {
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Exit code 1, exactly one `gmwm: error: ` line on stderr (warnings aside) containing every
/// needle, and nothing on stdout.
pub fn assert_one_line_error(cmd: &mut Command, needles: &[&str]) {
    assert_one_line_exit(cmd, 1, needles);
}

/// A flag value outside its domain: exit code 2 (a usage error), one `gmwm: error: ` line
/// containing every needle, nothing on stdout.
pub fn assert_usage_error(cmd: &mut Command, needles: &[&str]) {
    assert_one_line_exit(cmd, 2, needles);
}

fn assert_one_line_exit(cmd: &mut Command, code: i32, needles: &[&str]) {
    let out = cmd.output().expect("runs");
    assert_eq!(out.status.code(), Some(code), "{cmd:?}: {out:?}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    // warnings and notes (what the reader found, the samples' account) are not error lines
    let lines: Vec<&str> = stderr
        .lines()
        .filter(|l| !l.contains("warning:") && !l.starts_with("gmwm: note: "))
        .collect();
    assert_eq!(lines.len(), 1, "one line expected, got {stderr:?}");
    assert!(lines[0].starts_with("gmwm: error: "), "{stderr}");
    for n in needles {
        assert!(lines[0].contains(n), "{n:?} not in {stderr:?}");
    }
    assert!(out.stdout.is_empty(), "no partial results on stdout");
}
