//! The canonical model of a fit (`gmwm::fit::canonical`): each rule on simulated data with a
//! known answer, the separation measure, and the real recordings named by issue 10 (KVH1750
//! GM()+WN()+RW() with beta -> infinity, 3*GM() at one beta; ADIS16405 gyro_x 2*AR1()).

use crate::tests::common::{data_dir, read_column};
use gmwm::fit::canonical::wv_separation;
use gmwm::fit::{CanonicalModel, Gmwm, GmwmFit, Reading, StartInputs};
use gmwm::model::{Model, ProcessKind};
use gmwm::sim::simulate_model;
use gmwm::variance::read_wv_json;
use gmwm::{allan_variance, AllanOptions, WvOptions};

fn model(text: &str) -> Model {
    Model::parse(text).unwrap_or_else(|e| panic!("{text}: {e}"))
}

fn fit(text: &str, x: &[f64], freq: f64) -> GmwmFit {
    Gmwm::new(model(text))
        .with_draws(2000)
        .fit(x, freq, &WvOptions::default())
        .unwrap_or_else(|e| panic!("{text}: {e}"))
}

/// `text` fitted to a precomputed WV (guess mode).
fn fit_wv(text: &str, wv: &gmwm::WaveletVariance) -> GmwmFit {
    Gmwm::new(model(text))
        .fit_from_wv(wv, StartInputs::from_wv(wv))
        .unwrap_or_else(|e| panic!("{text}: {e}"))
}

fn has_reading(c: &CanonicalModel, f: impl Fn(&Reading) -> bool) -> bool {
    c.readings.iter().any(f)
}

#[test]
fn wv_separation_is_a_symmetric_scale_free_distance_in_standard_errors() {
    let a = [1.0, 0.5, 0.25, 0.2];
    let b = [1.1, 0.45, 0.3, 0.2];
    let v = [0.01, 0.04, 0.25, 1.0];
    let d = wv_separation(&a, &b, &v);
    // by hand: sum ln(a/b)^2 / v
    let want: f64 = (0..4)
        .map(|j| (a[j] / b[j]).ln().powi(2) / v[j])
        .sum::<f64>()
        .sqrt();
    assert!((d - want).abs() < 1e-15, "{d} vs {want}");
    assert!((d - wv_separation(&b, &a, &v)).abs() < 1e-15);
    assert_eq!(wv_separation(&a, &a, &v), 0.0);
    let (ca, cb): (Vec<f64>, Vec<f64>) = a.iter().zip(&b).map(|(x, y)| (3.0 * x, 3.0 * y)).unzip();
    assert!((wv_separation(&ca, &cb, &v) - d).abs() < 1e-14);
    // levels without a positive value are skipped, not NaN
    assert_eq!(wv_separation(&[1.0, 0.0], &[1.0, 1.0], &[1.0, 1.0]), 0.0);
}

#[test]
fn canonical_replaces_a_fast_ar1_the_wv_cannot_tell_from_white_noise() {
    // white noise plus one slow AR1, fitted as 2*AR1(): one AR1 plays the white noise with a
    // correlation time far below the sampling interval; its WV is white noise's within the
    // noise, so the reduced model has the white noise itself
    let truth = model("AR1(phi=0.995, sigma2=2e-3)+WN(sigma2=1)");
    let x = simulate_model(&truth, 50_000, 100.0, 11).unwrap();
    for text in ["2*AR1()", "2*GM()"] {
        let f = fit(text, &x, 100.0);
        let forms = f.ar1_gm_forms();
        assert!(
            forms.iter().any(|g| g.phi < (-1.0f64).exp()),
            "{text}: no AR1 below the sampling interval: {forms:?}"
        );
        let c = f.canonical().unwrap();
        let kind = if text.contains("GM") { "GM" } else { "AR1" };
        assert_eq!(c.model.to_string(), format!("{kind}()+WN()"), "{f}\n{c}");
        assert_eq!(c.reduced, c.model, "{c}");
        assert!(has_reading(&c, |r| matches!(
            r,
            Reading::WhiteAtObservedScales { separation, .. } if *separation <= 2.0
        )));
        assert!(c.separation <= 2.0 && c.separation > 0.0, "{c}");
        // the white noise of the refit is the truth's, and the read-off is N = sqrt(sigma2 / f)
        let wn = c.term(ProcessKind::Wn).unwrap().parameters[0].value;
        assert!((wn - 1.0).abs() < 0.03, "{text}: white noise {wn} vs 1");
        let n = c.physical(ProcessKind::Wn, "white_noise_density").unwrap();
        assert!((n / (wn / 100.0).sqrt() - 1.0).abs() < 1e-12);
    }
}

#[test]
fn canonical_merges_ar1s_the_wv_cannot_separate_and_keeps_those_it_can() {
    let x = simulate_model(
        &model("AR1(phi=0.99, sigma2=1e-2)+WN(sigma2=1)"),
        100_000,
        100.0,
        3,
    )
    .unwrap();
    // a start with two AR1s at nearly one correlation time: the fit keeps them there
    let close = Gmwm::new(model(
        "AR1(phi=0.991, sigma2=5e-3)+AR1(phi=0.989, sigma2=5e-3)+WN(sigma2=1)",
    ))
    .fit(&x, 100.0, &WvOptions::default())
    .unwrap();
    let c = close.canonical().unwrap();
    assert_eq!(c.model.to_string(), "AR1()+WN()", "{close}\n{c}");
    assert_eq!(c.correlated_terms(), 1);
    assert!(c.separation <= gmwm::fit::SEPARATION_LIMIT, "{c}");
    // the merged AR1 stands for both fitted ones
    let ar1 = c.term(ProcessKind::Ar1).unwrap();
    assert_eq!(ar1.from, [0, 1], "{c}");
    let phi = ar1.parameters[0].value;
    assert!((phi - 0.99).abs() < 0.003, "{c}");
    // two AR1s a decade apart in correlation time, each dominating a band of scales, stay
    let y = simulate_model(
        &model("AR1(phi=0.9, sigma2=0.05)+AR1(phi=0.999, sigma2=1e-4)+WN(sigma2=1)"),
        100_000,
        100.0,
        4,
    )
    .unwrap();
    let apart = fit("2*AR1()+WN()", &y, 100.0);
    let c = apart.canonical().unwrap();
    assert_eq!(c.model.to_string(), "2*AR1()+WN()", "{apart}\n{c}");
    assert!(c.is_as_fitted(), "{c}");
}

#[test]
fn canonical_reads_a_slow_ar1_as_the_random_walk_it_stands_for() {
    // the WV of white noise and a random walk, fitted with an AR1 in place of the random walk:
    // the AR1 runs to phi -> 1 and rises over every observed scale
    let truth = model("WN(sigma2=1)+RW(gamma2=1e-3)");
    let wv = exact_wv(&truth, 1 << 15, 10.0);
    let f = fit_wv("AR1()+WN()", &wv);
    let c = f.canonical().unwrap();
    assert_eq!(c.model.to_string(), "WN()+RW()", "{f}\n{c}");
    assert!(
        has_reading(&c, |r| matches!(
            r,
            Reading::RandomWalkAtObservedScales { separation, .. } if *separation <= 2.0
        )),
        "{c}"
    );
    // the canonical random walk is the truth's (the refit of WN+RW on its exact WV)
    let k = c
        .physical(ProcessKind::Rw, "rate_random_walk_density")
        .unwrap();
    let want = (1e-3f64 * 10.0).sqrt();
    assert!((k / want - 1.0).abs() < 1e-3, "{k} vs {want}");
}

/// The WV a series of length `n` would have if its estimate hit `truth`'s implied WV exactly:
/// the levels, counts and degrees of freedom of a real estimate, values and intervals scaled
/// to the implied WV (the chi-square interval is proportional to the estimate).
fn exact_wv(truth: &Model, n: usize, freq: f64) -> gmwm::WaveletVariance {
    let dummy = crate::tests::common::white_noise(n, 1.0, 99);
    let wv = gmwm::wavelet_variance(&dummy, freq, &WvOptions::default()).unwrap();
    let implied = truth.implied_wv(wv.levels(), freq).unwrap().wv;
    let ratio: Vec<f64> = implied.iter().zip(wv.wv()).map(|(i, w)| i / w).collect();
    let scaled = |v: &[f64]| -> Vec<f64> { v.iter().zip(&ratio).map(|(v, r)| v * r).collect() };
    let (low, high) = (scaled(wv.ci_low()), scaled(wv.ci_high()));
    crate::tests::common::edited_wv(&wv, |doc| {
        doc["wv"] = serde_json::json!(implied);
        doc["ci_low"] = serde_json::json!(low);
        doc["ci_high"] = serde_json::json!(high);
    })
}

#[test]
fn canonical_rising_ar1s_are_random_walks_and_peaked_ones_stay() {
    // correlation length 5000 samples: the AR1's WV peaks near tau = 19000, beyond the last
    // scale of a 2^15-sample recording (2^14): it rises over every observed scale. Its bend
    // lies in the last octaves, where the WV has a few degrees of freedom, so even noise-free
    // it cannot be told from a random walk (separation about 1): a correlation time beyond
    // the recording is not measured by it.
    let phi = (-1.0f64 / 5000.0).exp();
    let truth = model(&format!("AR1(phi={phi}, sigma2=1e-3)+WN(sigma2=1e-2)"));
    let wv = exact_wv(&truth, 1 << 15, 1.0);
    let f = fit_wv("AR1()+WN()", &wv);
    let own = &f.implied_wv().processes[0].wv;
    let j = own.len();
    assert!(
        own[j - 1] > own[j - 2],
        "the AR1 rises at the last level: {f}"
    );
    let c = f.canonical().unwrap();
    assert_eq!(c.model.to_string(), "WN()+RW()", "{f}\n{c}");
    // with a thousand times the degrees of freedom at every level (as no recording of this
    // length has), the bend would show: the AR1 stays, and the note says it rises everywhere
    let eta: Vec<f64> = wv.eta().iter().map(|e| e * 1000.0).collect();
    let precise = crate::tests::common::edited_wv(&wv, |doc| doc["eta"] = serde_json::json!(eta));
    let f = fit_wv("AR1()+WN()", &precise);
    let c = f.canonical().unwrap();
    assert_eq!(c.model.to_string(), "AR1()+WN()", "{f}\n{c}");
    assert!(
        has_reading(&c, |r| matches!(
            r,
            Reading::CorrelationBeyondRecording { separation, .. } if *separation > 2.0
        )),
        "{c}"
    );
    // ten times faster, its bump peaks inside the observed scales: correlated noise, kept
    let phi = (-1.0f64 / 500.0).exp();
    let truth = model(&format!("AR1(phi={phi}, sigma2=1e-3)+WN(sigma2=1e-2)"));
    let wv = exact_wv(&truth, 1 << 15, 1.0);
    let f = fit_wv("AR1()+WN()", &wv);
    let c = f.canonical().unwrap();
    assert_eq!(c.model.to_string(), "AR1()+WN()", "{f}\n{c}");
    assert!(c.is_as_fitted(), "{c}");
}

#[test]
fn canonical_reads_a_drift_as_a_random_walk_when_the_wv_cannot_tell_them_apart() {
    // a random walk that shows only at the last scales of a short recording, fitted with a drift
    let x = simulate_model(&model("WN(sigma2=1)+RW(gamma2=2e-5)"), 1 << 13, 1.0, 21).unwrap();
    let f = fit("WN()+DR()", &x, 1.0);
    let c = f.canonical().unwrap();
    assert_eq!(c.model.to_string(), "WN()+RW()", "{f}\n{c}");
    assert!(has_reading(&c, |r| matches!(
        r,
        Reading::DriftAsRandomWalk { .. }
    )));
    // a strong drift stays a drift
    let y: Vec<f64> =
        simulate_model(&model("WN(sigma2=1)+DR(omega=2e-3)"), 1 << 13, 1.0, 22).unwrap();
    let g = fit("WN()+DR()", &y, 1.0);
    let d = g.canonical().unwrap();
    assert_eq!(d.model.to_string(), "WN()+DR()", "{g}\n{d}");
    assert!(d.is_as_fitted(), "{d}");
}

#[test]
fn canonical_drops_components_fitted_to_nothing() {
    // QN and DR fitted to the exact WV of an AR1 and a white noise: the fit drives both to
    // nothing, the canonical model leaves them out and says so, and the reduced model is the
    // truth's
    let truth = model("AR1(phi=0.95, sigma2=0.1)+WN(sigma2=1)");
    let wv = exact_wv(&truth, 20_000, 1.0);
    let f = fit_wv("AR1()+WN()+QN()+DR()", &wv);
    let c = f.canonical().unwrap();
    assert_eq!(c.model.to_string(), "AR1()+WN()", "{f}\n{c}");
    assert_eq!(c.reduced.to_string(), "AR1()+WN()", "{c}");
    for i in [2, 3] {
        assert!(
            has_reading(
                &c,
                |r| matches!(r, Reading::AtBoundary { component, .. } if *component == i)
            ),
            "{c}"
        );
    }
    // nothing was refitted: the canonical model is the fit's own
    assert_eq!((c.separation, c.objective), (0.0, f.objective()));
}

#[test]
fn canonical_of_a_fit_without_its_wv_or_with_a_bad_limit_is_an_error() {
    let truth = model("AR1(phi=0.9, sigma2=0.1)+WN(sigma2=1)");
    let nu = truth.implied_wv(10, 1.0).unwrap().wv;
    let bare = Gmwm::new(truth.without_values())
        .fit_weighted(&nu, gmwm::fit::Weights::unit(10), 1.0, &[0.9, 0.1, 1.0])
        .unwrap();
    let e = bare.canonical().unwrap_err();
    assert!(
        e.to_string()
            .contains("without an empirical wavelet variance"),
        "{e}"
    );
    let wv = exact_wv(&truth, 4096, 1.0);
    let f = fit_wv("AR1()+WN()", &wv);
    for limit in [-1.0, f64::NAN, f64::INFINITY] {
        assert!(f.canonical_with(limit).is_err(), "{limit}");
    }
    // limit 0 accepts exact reductions only: none here
    assert!(f.canonical_with(0.0).unwrap().is_as_fitted());
}

fn kvh_gyro_x() -> gmwm::WaveletVariance {
    let path = data_dir().join("precomputed/kvh1750_wv.json");
    read_wv_json(&path, None)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .into_iter()
        .find(|(n, _)| n == "gyro_x")
        .unwrap()
        .1
}

#[test]
fn issue_10_kvh1750_gm_at_infinite_beta_is_white_noise() {
    // gmwm fit kvh1750_wv.json --columns gyro_x --model "GM()+WN()+RW()" printed beta =
    // 1.29e181 (phi = 0), nothing at the boundary, and --inference failed
    let wv = kvh_gyro_x();
    let f = fit_wv("GM()+WN()+RW()", &wv);
    let c = f.canonical().unwrap();
    // the RW of this fit is negligible (a random-walk density of 1e-8 against the coarse
    // levels' noise): fitted to nothing; the GM at phi = 0 is exactly a white noise
    assert_eq!(c.model.to_string(), "WN()", "{f}\n{c}");
    assert_eq!(c.reduced.to_string(), "WN()", "{c}");
    assert!(has_reading(&c, |r| matches!(
        r,
        Reading::WhiteAtObservedScales { separation, .. } if *separation < 0.01
    )));
    assert!(has_reading(&c, |r| matches!(
        r,
        Reading::AtBoundary { component: 2, .. }
    )));
    // the white noise of the canonical model carries the GM's variance and the WN's
    let gm = f.ar1_gm_forms()[0].clone();
    let wn = c.term(ProcessKind::Wn).unwrap().parameters[0].value;
    let want = gm.sigma2_gm + f.theta()[2];
    assert!((wn / want - 1.0).abs() < 1e-6, "{wn} vs {want}");
    // the correlation time in the note is 1 / beta, not a phi that underflowed to 0
    assert!(has_reading(&c, |r| matches!(
        r,
        Reading::WhiteAtObservedScales { correlation_time_s, .. } if *correlation_time_s > 0.0
    )));
    // inference no longer fails: beta gets no standard error, with a warning
    let inf = gmwm::inference::infer(
        &Gmwm::parse("GM()+WN()+RW()").unwrap(),
        &f,
        wv.n(),
        &WvOptions {
            levels: Some(wv.levels()),
            ..WvOptions::default()
        },
        &gmwm::inference::InferenceOptions {
            v_replicates: 30,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(inf.parameters()[0].se.is_none(), "{inf}");
    assert!(inf.parameters()[1].se.is_some(), "{inf}");
    assert!(inf
        .warnings()
        .iter()
        .any(|w| matches!(w, gmwm::inference::InferenceWarning::NoInfluence { .. })));
}

#[test]
fn issue_10_kvh1750_three_gms_at_one_beta_are_one() {
    // 3*GM()+WN()+QN()+RW() gave three GMs at beta 408-415 and flagged one
    let wv = kvh_gyro_x();
    let f = fit_wv("3*GM()+WN()+QN()+RW()", &wv);
    let c = f.canonical().unwrap();
    assert_eq!(c.correlated_terms(), 1, "{f}\n{c}");
    assert!(
        has_reading(&c, |r| matches!(r, Reading::Merged { .. })),
        "{c}"
    );
    // the reduced model, refitted, is within the separation limit of the fit
    assert_eq!(c.reduced, c.model, "{c}");
    assert!(c.separation <= 2.0, "{c}");
    let refit = fit_wv(&c.reduced.to_string(), &wv);
    assert!(
        refit.objective() <= c.objective * (1.0 + 1e-6),
        "{refit}\n{c}"
    );
    // every fitted GM is accounted for: merged, dropped or kept
    let mut seen: Vec<usize> = c.terms.iter().flat_map(|t| t.from.clone()).collect();
    for r in &c.readings {
        if let Reading::AtBoundary { component, .. } = r {
            seen.push(*component);
        }
    }
    seen.sort_unstable();
    seen.dedup();
    assert_eq!(
        seen,
        (0..f.model().n_components()).collect::<Vec<_>>(),
        "{c}"
    );
}

#[test]
fn issue_10_adis_gyro_x_white_noise_density_matches_the_allan_read_off() {
    // gmwm fit adis_16405_imu1 --columns gyro_x --model "2*AR1()" returned an AR1 with
    // phi = 0.16 (T = 5.5 ms at dt = 10 ms) and no white noise
    let x = read_column("adis_16405_imu1", "gyro_x");
    let f = fit("2*AR1()", &x, 100.0);
    let c = f.canonical().unwrap();
    assert_eq!(c.model.to_string(), "AR1()+WN()", "{f}\n{c}");
    // the fast AR1's shape at the first scales is real (many standard errors from white
    // noise): the reduced model keeps it, and the canonical model reads it as white noise with
    // its low-frequency variance sigma2 / (1 - phi)^2
    assert_eq!(c.reduced.to_string(), "2*AR1()", "{c}");
    assert!(
        has_reading(&c, |r| matches!(
            r,
            Reading::WhiteAtSamplingRate { separation, correlation_time_s, sampling_interval_s, .. }
                if *separation > 2.0 && correlation_time_s < sampling_interval_s
        )),
        "{c}"
    );
    let fast = f.ar1_gm_forms()[1].clone();
    let wn = c.term(ProcessKind::Wn).unwrap().parameters[0].value;
    assert!((wn / (fast.sigma2 / (1.0 - fast.phi).powi(2)) - 1.0).abs() < 1e-12);
    assert!(!c.is_as_fitted());
    let n = c.physical(ProcessKind::Wn, "white_noise_density").unwrap();
    // IEEE 952: N = sigma(tau) sqrt(tau) on the -1/2 slope; at tau = 1.28 s (m = 128 samples)
    // the white noise dominates the Allan variance of this gyro by far
    let av = allan_variance(&x, 100.0, &AllanOptions::default()).unwrap();
    let i = av.tau().iter().position(|&t| t == 128.0).unwrap();
    let ieee = (av.avar()[i] * av.tau_s()[i]).sqrt();
    assert!(
        (n / ieee - 1.0).abs() < 0.05,
        "canonical N {n} vs Allan {ieee}"
    );
}

#[test]
fn one_reading_of_a_refitted_term_is_said_once_with_either_fits_values() {
    // the WIC's selection and the calibration's refinement both read an AR1 below the sampling
    // interval, at slightly different correlation times and indexes: one subject
    let selected = Reading::WhiteAtSamplingRate {
        component: 1,
        process: "AR1".into(),
        correlation_time_s: 0.005467,
        sampling_interval_s: 0.01,
        separation: 3.0,
    };
    let refined = Reading::WhiteAtSamplingRate {
        component: 0,
        process: "AR1".into(),
        correlation_time_s: 0.005460,
        sampling_interval_s: 0.01,
        separation: 3.1,
    };
    assert!(selected.same_subject(&refined));
    // another process, or another reading of the same process, is another subject
    let gm = Reading::WhiteAtSamplingRate {
        component: 0,
        process: "GM".into(),
        correlation_time_s: 0.005460,
        sampling_interval_s: 0.01,
        separation: 3.1,
    };
    assert!(!gm.same_subject(&refined));
    let boundary = Reading::AtBoundary {
        component: 0,
        process: "AR1".into(),
    };
    assert!(!boundary.same_subject(&refined));
}
