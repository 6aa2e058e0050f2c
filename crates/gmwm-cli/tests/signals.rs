//! SIGINT/SIGTERM mid-run (issue 30): the copy of standard input and the spool of a streamed
//! recording are removed before the process ends, and the process ends by the signal.

mod common;

use std::io::Write;
use std::os::unix::process::ExitStatusExt;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn entries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect()
}

/// Waits (up to 60 s) until `dir` holds an entry starting with `prefix`.
fn wait_for(dir: &Path, prefix: &str, child: &mut std::process::Child) {
    let start = Instant::now();
    while !entries(dir).iter().any(|e| e.starts_with(prefix)) {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the run ended before its temporary {prefix}* appeared"
        );
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no {prefix}* in 60 s"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn signal(child: &std::process::Child, name: &str) {
    let ok = Command::new("kill")
        .args([&format!("-{name}"), &child.id().to_string()])
        .status()
        .unwrap();
    assert!(ok.success());
}

/// `gmwm wv -` reading a pipe that stays open: its copy of standard input is in TMPDIR.
#[test]
fn sigterm_while_standard_input_is_copied_leaves_no_copy() {
    for (name, number) in [("TERM", 15), ("INT", 2)] {
        let tmp = tempfile::tempdir().unwrap();
        let mut child = Command::new(assert_cmd::cargo::cargo_bin("gmwm"))
            .args(["wv", "-", "--freq", "100"])
            .env("TMPDIR", tmp.path())
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let mut stdin = child.stdin.take().unwrap();
        stdin.write_all(b"gyro_x\n0.1\n0.2\n").unwrap();
        wait_for(tmp.path(), "gmwm-input-", &mut child);
        signal(&child, name);
        let status = child.wait().unwrap();
        drop(stdin);
        assert_eq!(status.signal(), Some(number), "{status:?}");
        assert!(entries(tmp.path()).is_empty(), "{:?}", entries(tmp.path()));
    }
}

/// A text recording streamed (`--stream-from 1`): its spool of binary columns is in TMPDIR
/// while the text is read.
#[test]
fn sigterm_while_a_recording_is_spooled_leaves_no_spool() {
    let tmp = tempfile::tempdir().unwrap();
    let data = tempfile::tempdir().unwrap();
    let csv = data.path().join("long.csv");
    let mut text = String::from("gyro_x,gyro_y\n");
    for k in 0..3_000_000u64 {
        text.push_str(&format!("{}.{:03},{}\n", k % 7, k % 997, k % 5));
    }
    std::fs::write(&csv, text).unwrap();
    let mut child = Command::new(assert_cmd::cargo::cargo_bin("gmwm"))
        .args(["wv", "--freq", "100", "--stream-from", "1"])
        .arg(&csv)
        .env("TMPDIR", tmp.path())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    wait_for(tmp.path(), "gmwm-spool-", &mut child);
    signal(&child, "TERM");
    let status = child.wait().unwrap();
    assert_eq!(status.signal(), Some(15), "{status:?}");
    assert!(entries(tmp.path()).is_empty(), "{:?}", entries(tmp.path()));
}
