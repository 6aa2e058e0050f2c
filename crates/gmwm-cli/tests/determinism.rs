//! Determinism (issue 15): every randomised command gives the same bits for the same seed at
//! 1, 2, 3 and 16 threads (`RAYON_NUM_THREADS`): simulate, fit in guess mode, fit with the
//! simulated weights, bootstrap inference, selection with a simulated V and with the bootstrap
//! optimism, and calibrate. The engine's own tests cover the chunkings (the simulator's fill,
//! the WV accumulator's blocks, the streamed WV's read sizes).
//!
//! Each command's whole standard output is compared byte for byte; the series is 2^14 samples,
//! so that every parallel loop (draws, replicates, candidates, levels) splits at 2 and 3
//! threads.

mod common;

use std::path::Path;
use std::process::Command;

/// Standard output of `gmwm ARGS` at `threads` threads; the command must succeed.
fn stdout_at(threads: usize, args: &[&str], dir: &Path) -> Vec<u8> {
    let out = Command::new(assert_cmd::cargo::cargo_bin("gmwm"))
        .args(args)
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", threads.to_string())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{args:?} at {threads} threads: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!out.stdout.is_empty(), "{args:?}: no output");
    out.stdout
}

fn same_bits_at_1_2_3_16_threads(args: &[&str], dir: &Path) {
    let one = stdout_at(1, args, dir);
    for threads in [2, 3, 16] {
        let other = stdout_at(threads, args, dir);
        assert!(
            one == other,
            "{args:?}: 1 and {threads} threads differ:\n{}\n---\n{}",
            String::from_utf8_lossy(&one),
            String::from_utf8_lossy(&other)
        );
    }
}

#[test]
fn randomised_commands_give_the_same_bits_at_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = "AR1(phi=0.95, sigma2=1e-6)+WN(sigma2=1e-4)+RW(gamma2=1e-10)";
    // simulate: the series itself, as CSV on standard output
    same_bits_at_1_2_3_16_threads(
        &["simulate", "--model", model, "--n", "16384", "--seed", "5"],
        d,
    );
    let file = common::simulate(d, "x.csv", model, 1 << 14, 100.0, 5);
    let file = file.to_str().unwrap();
    let fit = ["fit", file, "--model", "AR1()+WN()+RW()", "--json"];
    // guess mode (the G draws run in parallel batches)
    same_bits_at_1_2_3_16_threads(&[&fit[..], &["--G", "3000", "--seed", "9"]].concat(), d);
    // simulated weights (replicates in parallel, then a refit)
    same_bits_at_1_2_3_16_threads(
        &[&fit[..], &["--G", "500", "--weights", "bootstrap"]].concat(),
        d,
    );
    // bootstrap inference (replicates refitted in parallel)
    same_bits_at_1_2_3_16_threads(
        &[
            &fit[..],
            &[
                "--G",
                "500",
                "--inference",
                "--bootstrap",
                "20",
                "--seed",
                "3",
            ],
        ]
        .concat(),
        d,
    );
    // selection: candidates in parallel, V simulated, and the bootstrap optimism
    let select = [
        "select",
        file,
        "--model",
        "AR1()+WN()+RW()",
        "--json",
        "--G",
        "500",
    ];
    same_bits_at_1_2_3_16_threads(
        &[
            &select[..],
            &["--covariance", "bootstrap", "--bootstrap", "20"],
        ]
        .concat(),
        d,
    );
    same_bits_at_1_2_3_16_threads(
        &[
            &select[..],
            &["--optimism", "bootstrap", "--bootstrap", "10"],
        ]
        .concat(),
        d,
    );
}

#[test]
fn calibrate_gives_the_same_bits_at_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sim = common::simulate(
        d,
        "sim.csv",
        "AR1(phi=0.999, sigma2=1e-9)+WN(sigma2=1e-6)+RW(gamma2=1e-12)",
        1 << 14,
        100.0,
        11,
    );
    let text = std::fs::read_to_string(&sim).unwrap();
    let body = text.split_once('\n').unwrap().1;
    std::fs::write(d.join("imu.csv"), format!("gyro_x\n{body}")).unwrap();
    std::fs::write(
        d.join("imu.csv.json"),
        r#"{"sampling_frequency_hz": 100, "units": {"gyro": "rad/s"}}"#,
    )
    .unwrap();
    same_bits_at_1_2_3_16_threads(&["calibrate", "imu.csv", "--json", "-", "--G", "500"], d);
}
