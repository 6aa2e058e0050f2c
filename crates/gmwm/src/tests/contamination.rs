//! Classical against robust WV (`calib::contamination`): clean Gaussian data pass, outliers are
//! caught at the scales they reach, an undefined robust level is reported, and the real
//! contaminated recording `cont_imu1` is flagged.

use gmwm::calib::{compare_classical_robust, FitUses};
use gmwm::{wavelet_variance, RobustOptions, WaveletVariance, WvOptions};

const FREQ: f64 = 100.0;

fn pair(x: &[f64]) -> (WaveletVariance, WaveletVariance) {
    let classical = wavelet_variance(x, FREQ, &WvOptions::default()).unwrap();
    let robust = wavelet_variance(
        x,
        FREQ,
        &WvOptions {
            robust: Some(RobustOptions::default()),
            ..WvOptions::default()
        },
    )
    .unwrap();
    (classical, robust)
}

fn white_noise(n: usize, seed: u64) -> Vec<f64> {
    crate::tests::common::white_noise(n, 1e-4, seed)
}

#[test]
fn contamination_clean_gaussian_data_does_not_matter() {
    // over seeds, the verdict must hold on clean data (the rule allows ceil(alpha J) misses)
    for seed in 1..=5 {
        let x = white_noise(1 << 16, seed);
        let (c, r) = pair(&x);
        let check = compare_classical_robust(c, r, FitUses::Classical, 0.05, 0.1);
        assert!(!check.matters, "seed {seed}: {}", check.summary);
        assert!(check.max_ratio < 1.1, "seed {seed}: {}", check.max_ratio);
        assert!(
            check.summary.contains("does not matter"),
            "{}",
            check.summary
        );
    }
}

#[test]
fn contamination_outliers_inflate_the_first_scales() {
    // spikes of 30 standard deviations added to 0.2% of the samples
    let mut x = white_noise(1 << 16, 7);
    for k in (0..x.len()).step_by(500) {
        x[k] += 0.3 * if k % 1000 == 0 { 1.0 } else { -1.0 };
    }
    let (c, r) = pair(&x);
    let check = compare_classical_robust(c, r, FitUses::Classical, 0.05, 0.1);
    assert!(check.matters, "{}", check.summary);
    assert!(check.levels_above.contains(&1), "{:?}", check.levels_above);
    // the spikes add 0.002 * 0.09 / 2 = 9e-5 to the level-1 WV of 5e-5: a factor near 2.8
    assert!(check.max_ratio > 2.0, "{}", check.max_ratio);
    assert!(
        check.summary.contains("contamination matters"),
        "{}",
        check.summary
    );
}

#[test]
fn contamination_undefined_robust_level_is_named_not_compared() {
    let x = white_noise(1 << 12, 3);
    let (c, r) = pair(&x);
    let r = crate::tests::common::edited_wv(&r, |doc| {
        for key in ["wv", "ci_low", "ci_high"] {
            doc[key][2] = serde_json::Value::Null;
        }
    });
    let levels = c.wv().len();
    let check = compare_classical_robust(c, r, FitUses::Classical, 0.05, 0.1);
    assert_eq!(check.undefined_levels, vec![3]);
    assert_eq!(check.levels, levels - 1);
    assert!(
        check.summary.contains("undefined at level(s) 3"),
        "{}",
        check.summary
    );
}

#[test]
fn contamination_real_contaminated_recording_is_flagged() {
    let x = crate::tests::common::read_column("cont_imu1", "gyro_x");
    let (c, r) = pair(&x);
    let check = compare_classical_robust(c, r, FitUses::Classical, 0.05, 0.1);
    assert!(check.matters, "{}", check.summary);
    assert!(!check.levels_above.is_empty());
}

#[test]
fn contamination_advice_follows_the_estimator_the_fit_used() {
    let x = crate::tests::common::read_column("cont_imu1", "gyro_x");
    let (c, r) = pair(&x);
    let check = compare_classical_robust(c, r, FitUses::Robust, 0.05, 0.1);
    assert!(check.matters, "{}", check.summary);
    assert!(
        check.summary.contains("the robust fit used here"),
        "{}",
        check.summary
    );
    assert!(!check.summary.contains("--robust"), "{}", check.summary);
}

#[test]
fn contamination_nothing_to_compare_says_so() {
    let x = white_noise(1 << 10, 9);
    let (c, r) = pair(&x);
    let undefined = vec![serde_json::Value::Null; r.levels()];
    let r = crate::tests::common::edited_wv(&r, |doc| doc["wv"] = serde_json::json!(undefined));
    let check = compare_classical_robust(c, r, FitUses::Classical, 0.05, 0.1);
    assert_eq!(check.levels, 0);
    assert!(!check.matters);
    assert!(
        check.summary.contains("could not be compared"),
        "{}",
        check.summary
    );
}
