//! The robust-WV fault monitor (`gmwm::monitor`, docs/methods.md §16): injected faults are
//! flagged where they are and (almost) nowhere else; a clean recording flags about alpha of its
//! windows at most.

use gmwm::model::Model;
use gmwm::monitor::{monitor, monitor_against, MonitorOptions, Reference};
use gmwm::sim::simulate_model;

const MODEL: &str = "GM(beta=0.5, sigma2_gm=0.05)+WN(sigma2=1)+RW(gamma2=1e-7)";

fn opts() -> MonitorOptions {
    MonitorOptions {
        window: 1 << 14,
        step: Some(1 << 13),
        alpha: 0.05,
        ..MonitorOptions::default()
    }
}

/// A clean recording of 2^20 samples (127 windows of 2^14): flagged windows at most alpha of
/// them plus 3 binomial SE (Bonferroni makes the true rate lower).
#[test]
fn monitor_clean_recording_flags_about_alpha() {
    let model = Model::parse(MODEL).unwrap();
    let x = simulate_model(&model, 1 << 20, 100.0, 3).unwrap();
    let r = monitor(&x, 100.0, &model, &opts()).unwrap();
    let w = r.windows.len() as f64;
    let bound = 0.05 * w + 3.0 * (0.05 * 0.95 * w).sqrt();
    assert!((r.flagged as f64) <= bound, "{} of {w} flagged", r.flagged);
    assert!(r.exact_eta);
}

/// A burst of spikes (every 10th sample of 2000 raised by 30 standard deviations) and a step in
/// variance (noise doubled in amplitude over 30000 samples): every window holding the burst or
/// a quarter window of the step is flagged (spikes by the classical WV, the step by the robust
/// one), and at most 4 windows away from the faults (alpha 0.01 per window).
#[test]
fn monitor_flags_injected_faults_where_they_are() {
    let model = Model::parse(MODEL).unwrap();
    let mut x = simulate_model(&model, 1 << 20, 100.0, 4).unwrap();
    let spikes = 300_000..302_000;
    for t in spikes.clone().step_by(10) {
        x[t] += 30.0;
    }
    let step = 700_000..730_000;
    let extra =
        simulate_model(&Model::parse("WN(sigma2=3)").unwrap(), step.len(), 100.0, 9).unwrap();
    for (t, e) in step.clone().zip(extra) {
        x[t] += e;
    }
    // alpha 0.01 per window: of the ~120 windows away from the faults, 1.2 are flagged by
    // chance on average (at most 4 within 3 binomial SE)
    let strict = MonitorOptions {
        alpha: 0.01,
        ..opts()
    };
    let r = monitor(&x, 100.0, &model, &strict).unwrap();
    let overlaps = |w: &gmwm::monitor::MonitorWindow, f: &std::ops::Range<usize>| {
        w.start < f.end && w.end > f.start
    };
    let overlap = |w: &gmwm::monitor::MonitorWindow, f: &std::ops::Range<usize>| {
        w.end.min(f.end).saturating_sub(w.start.max(f.start))
    };
    let mut elsewhere = 0;
    for w in &r.windows {
        // a window holding the whole burst, or a quarter of a window of the step, must be
        // flagged; one that only grazes a fault may or may not be
        if overlap(w, &spikes) == spikes.len() {
            assert!(
                w.out.iter().any(|o| o.estimator == "classical"),
                "spikes missed: {w:?}"
            );
        } else if overlap(w, &step) >= (1 << 12) {
            assert!(
                w.out.iter().any(|o| o.estimator == "robust"),
                "step missed: {:?}",
                w.start
            );
        } else if overlaps(w, &spikes) || overlaps(w, &step) {
            continue;
        } else if w.flagged {
            elsewhere += 1;
        }
    }
    assert!(
        elsewhere <= 4,
        "{elsewhere} windows flagged away from the faults"
    );
    // one event per fault, plus one per stray window
    assert!(
        (2..=2 + elsewhere).contains(&r.events.len()),
        "{:?}",
        r.events
    );
}

/// Bad inputs: one clear error each.
#[test]
fn monitor_refuses_bad_inputs() {
    let model = Model::parse(MODEL).unwrap();
    let x = simulate_model(&model, 1000, 100.0, 1).unwrap();
    let e = monitor(&x, 100.0, &model, &opts()).unwrap_err();
    assert!(e.to_string().contains("window"), "{e}");
    let guess = Model::parse("GM()+WN()").unwrap();
    let e = monitor(
        &x,
        100.0,
        &guess,
        &MonitorOptions {
            window: 512,
            ..opts()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("every parameter"), "{e}");
}

/// docs/methods.md §16.6: a model that misfits by a few percent at the fine scales (WN alone,
/// where the truth adds a small fast GM) flags nearly every long window against its own WV,
/// while against the calibration's empirical WV (from another, longer recording of the same
/// process) at most alpha of the windows plus 3 binomial SE are flagged; and a step in
/// variance is still flagged there.
#[test]
fn monitor_against_the_calibration_wv_ignores_model_misfit_and_keeps_faults() {
    let truth = Model::parse("GM(beta=40, sigma2_gm=0.05)+WN(sigma2=1)").unwrap();
    let misfit = Model::parse("WN(sigma2=1.05)").unwrap();
    let reference = simulate_model(&truth, 1 << 22, 100.0, 21).unwrap();
    let cal = gmwm::wavelet_variance(&reference, 100.0, &gmwm::WvOptions::default()).unwrap();
    let robust_cal = gmwm::wavelet_variance(
        &reference,
        100.0,
        &gmwm::WvOptions {
            robust: Some(gmwm::RobustOptions::default()),
            ..gmwm::WvOptions::default()
        },
    )
    .unwrap();
    let mut x = simulate_model(&truth, 1 << 20, 100.0, 22).unwrap();
    let o = opts();
    let against_model = monitor(&x, 100.0, &misfit, &o).unwrap();
    let against_wv = |x: &[f64]| {
        monitor_against(
            x,
            100.0,
            &misfit,
            Reference::Wv {
                classical: &cal,
                robust: Some(&robust_cal),
            },
            &o,
        )
        .unwrap()
    };
    let clean = against_wv(&x);
    let w = clean.windows.len() as f64;
    assert!(
        against_model.flagged as f64 > 0.9 * w,
        "against the misfit model: {} of {w}",
        against_model.flagged
    );
    let bound = 0.05 * w + 3.0 * (0.05 * 0.95 * w).sqrt();
    assert!(
        (clean.flagged as f64) <= bound,
        "against the calibration WV: {} of {w} flagged",
        clean.flagged
    );
    assert_eq!(clean.reference, "calibration WV");
    assert_eq!(clean.reference_wv[0], cal.wv()[0]);
    // a variance step over 30000 samples is flagged in every window holding a quarter of it
    let step = 500_000..530_000;
    let extra = simulate_model(
        &Model::parse("WN(sigma2=3)").unwrap(),
        step.len(),
        100.0,
        23,
    )
    .unwrap();
    for (t, e) in step.clone().zip(extra) {
        x[t] += e;
    }
    let faulty = against_wv(&x);
    for win in &faulty.windows {
        let held = win
            .end
            .min(step.end)
            .saturating_sub(win.start.max(step.start));
        if held >= win.end - win.start || held >= (1 << 14) / 4 {
            assert!(
                win.flagged,
                "window {}..{} holds {held} samples of the step",
                win.start, win.end
            );
        }
    }
}
