//! Hostile inputs (issue 30): small files crafted to make a reader hold far more than their
//! content, each generated here (no large fixture) and run under a 1.5 GB address-space limit
//! and a time bound (`common::gmwm_bounded`): one error line naming the file and what is wrong,
//! exit 1, no abort, no panic, no hang. The MCAP summaries are in `topics.rs`; the chunk
//! decompression bounds in the engine's `imu::ros::decompress` tests.

mod common;

use flate2::write::GzEncoder;
use flate2::Compression;
use std::io::Write;
use std::path::Path;

/// A gzip file of `head` then `repeat` copies of `unit` (written in blocks: the test holds
/// megabytes, the file decompresses to `repeat * unit.len()` bytes).
fn gzip_bomb(path: &Path, head: &[u8], unit: &[u8], repeat: usize) {
    let mut enc = GzEncoder::new(std::fs::File::create(path).unwrap(), Compression::fast());
    enc.write_all(head).unwrap();
    let block = unit.repeat((1 << 20) / unit.len().max(1));
    let mut left = repeat * unit.len();
    while left > 0 {
        let n = left.min(block.len());
        enc.write_all(&block[..n]).unwrap();
        left -= n;
    }
    enc.finish().unwrap();
}

fn assert_one_error(path: &Path, args: &[&str], needle: &str) {
    let out = common::gmwm_bounded()
        .args(args)
        .arg(path)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    let errors: Vec<&str> = stderr
        .lines()
        .filter(|l| !l.starts_with("gmwm: note:") && !l.starts_with("gmwm: warning:"))
        .collect();
    assert_eq!(errors.len(), 1, "{args:?}: {stderr}");
    assert!(
        errors[0].starts_with("gmwm: error: ") && errors[0].contains(needle),
        "{args:?}: {stderr}"
    );
}

/// A 1 GiB line in a 1 MB gzip file, and a 1 GiB cell after a header: both were read whole.
#[test]
fn gzip_bombs_of_one_line_or_cell_stop_at_the_line_cap() {
    let dir = tempfile::tempdir().unwrap();
    let line = dir.path().join("line.csv.gz");
    gzip_bomb(&line, b"", b"1,", 1 << 29);
    let cell = dir.path().join("cell.csv.gz");
    gzip_bomb(&cell, b"time,gyro_x\n0.000,", b"1", 1 << 30);
    assert!(std::fs::metadata(&cell).unwrap().len() < 8 << 20);
    for path in [&line, &cell] {
        for command in ["wv", "calibrate"] {
            assert_one_error(path, &[command], "a line longer than 1 MiB");
        }
    }
}

/// A CSV of 10^6 columns (a 2.4 MB gzip): `wv`, `avar` and `plot` aborted; its header line is
/// beyond the line cap.
#[test]
fn a_million_columns_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("wide.csv.gz");
    let mut header: Vec<u8> = (0..1_000_000)
        .flat_map(|k| format!("c{k},").into_bytes())
        .collect();
    header.pop();
    header.push(b'\n');
    gzip_bomb(&path, &header, b"0.5,", 1_000_000);
    for command in ["wv", "avar"] {
        assert_one_error(&path, &[command], "a line longer than 1 MiB");
    }
}

/// `gmwm wv /dev/zero` (also `topics`, `calibrate`, and `-` fed from it) copied the device into
/// TMPDIR until the disk was full: a character device is refused before anything is copied.
#[test]
fn a_character_device_is_refused() {
    for command in ["wv", "topics", "calibrate"] {
        assert_one_error(Path::new("/dev/zero"), &[command], "is a character device");
    }
    let out = std::process::Command::new("bash")
        .args([
            "-c",
            &format!(
                "ulimit -v {} && exec timeout {} \"$0\" wv - --freq 100 < /dev/zero",
                common::MEMORY_LIMIT_KB,
                common::TIME_LIMIT_S
            ),
        ])
        .arg(assert_cmd::cargo::cargo_bin("gmwm"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("<stdin>: is a character device"),
        "{stderr}"
    );
}
