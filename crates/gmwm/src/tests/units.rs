//! Units, datasheet forms and discrete forms (docs/methods.md §14.2) against the §14.5 hand values.

use crate::tests::common::rel_diff;
use gmwm::fit::{Gmwm, NavParameter, Weights};
use gmwm::model::Model;
use gmwm::process::Ar1;
use gmwm::units::{
    forms, from_datasheet, si_unit, to_datasheet, NoiseTerm, SignalKind, SignalUnit,
    STANDARD_GRAVITY,
};
use proptest::prelude::*;

/// docs/methods.md §14.5 values are printed with 7 significant digits (ADIS figures with 4).
const TOL_7: f64 = 5e-7;
/// The ARW of §14.5's first line, 0.343775 °/√h, is printed with 6 significant digits.
const TOL_6: f64 = 5e-6;
/// The ADIS16405 figures of §14.5 carry 4 significant digits.
const TOL_4: f64 = 5e-4;
/// Exact conversions (one multiplication or division, or a fit started at its optimum and
/// stopped there): a few ulps.
const TOL_EXACT: f64 = 1e-12;
/// A fit of a one-term model started at the truth, whose objective is zero there: the optimiser
/// may still take a step of its own tolerance.
const TOL_FIT: f64 = 1e-7;

const GYRO: SignalKind = SignalKind::Gyroscope;
const ACCEL: SignalKind = SignalKind::Accelerometer;

/// The physical parameters of a model at its true values, through the fit's own formulas
/// (`GmwmFit::navigation`, docs/methods.md §14.2): the fit starts at the truth, where the objective
/// against the implied WV is zero.
fn navigation(model: &str, freq_hz: f64) -> Vec<NavParameter> {
    let m = Model::parse(model).unwrap();
    let levels = 10;
    let nu = m.implied_wv(levels, freq_hz).unwrap().wv;
    let theta: Vec<f64> = m.values().into_iter().map(Option::unwrap).collect();
    let fit = Gmwm::new(m)
        .fit_weighted(&nu, Weights::unit(levels), freq_hz, &theta)
        .unwrap();
    fit.navigation(Some("u"))
}

fn nav_value(nav: &[NavParameter], name: &str) -> f64 {
    nav.iter()
        .find(|p| p.name == name)
        .unwrap_or_else(|| panic!("no {name} in {nav:?}"))
        .value
}

#[test]
fn units_white_noise_hand_values() {
    // docs/methods.md §14.5: WN sigma2 = 1e-6 (rad/s)^2 at 100 Hz
    let n = nav_value(&navigation("WN(sigma2=1e-6)", 100.0), "white_noise_density");
    assert!(rel_diff(n, 1e-4) < TOL_FIT, "{n}");
    let f = forms(NoiseTerm::NoiseDensity, Some(GYRO), "deg/s", 1e-4, 100.0);
    assert_eq!(f.si.unit, "rad/s/√Hz");
    let d = f.discrete.unwrap();
    assert!(
        rel_diff(d.value, 1e-3) < TOL_EXACT && d.unit == "rad/s",
        "{d:?}"
    );
    let s = f.datasheet.unwrap();
    assert!(
        rel_diff(s.value, 0.343775) < TOL_6 && s.unit == "°/√h",
        "{s:?}"
    );
    assert!(f.conversion.contains("× 180/π × 60"), "{}", f.conversion);
    assert_eq!(f.si.to_string(), "1.000000e-4 rad/s/√Hz");
    // 0.1 °/√h = 2.908882e-5 rad/s/√Hz
    let n = from_datasheet(NoiseTerm::NoiseDensity, GYRO, 0.1).unwrap();
    assert!(rel_diff(n, 2.908882e-5) < TOL_7, "{n}");
}

#[test]
fn units_random_walk_hand_values() {
    // docs/methods.md §14.5: RW gamma2 = 1e-12 at 200 Hz
    let k = nav_value(
        &navigation("RW(gamma2=1e-12)", 200.0),
        "rate_random_walk_density",
    );
    assert!(rel_diff(k, 1.414214e-5) < TOL_7, "{k}");
    let f = forms(NoiseTerm::RandomWalk, Some(GYRO), "rad/s", k, 200.0);
    assert_eq!(f.si.unit, "rad/s²/√Hz");
    assert!(rel_diff(f.discrete.unwrap().value, 1e-6) < TOL_FIT);
    let s = f.datasheet.unwrap();
    assert!(
        rel_diff(s.value, 175.0215) < TOL_7 && s.unit == "°/h/√h",
        "{s:?}"
    );
}

#[test]
fn units_accelerometer_hand_values() {
    // docs/methods.md §14.5: accelerometer WN sd 0.02 m/s^2 at 100 Hz
    let n = nav_value(&navigation("WN(sigma2=4e-4)", 100.0), "white_noise_density");
    assert!(rel_diff(n, 2e-3) < TOL_FIT, "{n}");
    let f = forms(NoiseTerm::NoiseDensity, Some(ACCEL), "g", n, 100.0);
    assert_eq!(f.si.unit, "m/s²/√Hz");
    assert!(rel_diff(f.discrete.unwrap().value, 0.02) < TOL_FIT);
    let s = f.datasheet.unwrap();
    assert!(
        rel_diff(s.value, 0.12) < TOL_FIT && s.unit == "m/s/√h",
        "{s:?}"
    );
    // the µg/√Hz alternative named in the conversion
    assert!(
        f.conversion.contains("µg/√Hz: / 9.80665e-6"),
        "{}",
        f.conversion
    );
    assert!(rel_diff(n / (STANDARD_GRAVITY * 1e-6), 203.9432) < TOL_7);
    // bias in mg (docs/methods.md §14.2)
    let b = to_datasheet(NoiseTerm::BiasInstability, ACCEL, 9.80665e-3).unwrap();
    assert!(
        rel_diff(b.value, 1.0) < TOL_EXACT && b.unit == "mg",
        "{b:?}"
    );
    let b = to_datasheet(NoiseTerm::BiasInstability, GYRO, 1e-5).unwrap();
    assert!(rel_diff(b.value, 1e-5 * 180.0 / std::f64::consts::PI * 3600.0) < TOL_EXACT);
    assert_eq!(b.unit, "°/h");
}

#[test]
fn units_gauss_markov_hand_values() {
    // docs/methods.md §14.5: AR1 phi = 0.999, sigma2 = 1e-8 at 100 Hz
    let gm = Ar1::new(0.999, 1e-8).unwrap().to_gm(100.0).unwrap();
    assert!(rel_diff(gm.beta(), 0.1000500) < TOL_7, "{}", gm.beta());
    assert!(rel_diff(1.0 / gm.beta(), 9.994999) < TOL_7);
    assert!(
        rel_diff(gm.sigma2_gm(), 5.002501e-6) < TOL_7,
        "{}",
        gm.sigma2_gm()
    );
    // the fit's physical forms agree with §14.5
    let nav = navigation("AR1(phi=0.999, sigma2=1e-8)", 100.0);
    let t = nav_value(&nav, "correlation_time");
    let sd = nav_value(&nav, "gm_std");
    let drive = nav_value(&nav, "driving_noise_density");
    assert!(rel_diff(t, 9.994999) < TOL_7, "{t}");
    assert!(rel_diff(sd, 2.236627e-3) < TOL_7, "{sd}");
    assert!(rel_diff(drive, 1.000500e-3) < TOL_7, "{drive}");
    // continuous -> discrete: phi back from T
    let f = forms(NoiseTerm::GmCorrelationTime, Some(GYRO), "rad/s", t, 100.0);
    assert!(rel_diff(f.discrete.unwrap().value, 0.999) < TOL_FIT);
    // the driving density has the unit of K (u²/s under the root), not of N
    assert_eq!(
        si_unit(NoiseTerm::GmDrivingDensity, Some(GYRO), ""),
        "rad/s²/√Hz"
    );
    assert_eq!(si_unit(NoiseTerm::GmDrivingDensity, None, "V"), "V/s/√Hz");
    assert_eq!(
        to_datasheet(NoiseTerm::GmSigma, GYRO, 1e-5).unwrap().unit,
        "°/h"
    );
}

#[test]
fn units_quantization_and_drift_hand_values() {
    // docs/methods.md §14.5: QN q2 = 1e-10 at 100 Hz: Q = 1e-7 u s; DR omega = 1e-7 at 100 Hz: R =
    // 1e-5
    let q = nav_value(
        &navigation("QN(q2=1e-10)", 100.0),
        "quantization_coefficient",
    );
    assert!(rel_diff(q, 1e-7) < TOL_FIT, "{q}");
    let f = forms(NoiseTerm::Quantization, None, "V", q, 100.0);
    assert_eq!(f.si.unit, "V·s");
    assert!(rel_diff(f.discrete.unwrap().value, 1e-5) < TOL_FIT);
    assert!(f.datasheet.is_none());
    let r = nav_value(&navigation("DR(omega=1e-7)", 100.0), "drift_rate");
    assert!(rel_diff(r, 1e-5) < TOL_FIT, "{r}");
    let f = forms(NoiseTerm::RateRamp, Some(GYRO), "rad/s", r, 100.0);
    assert_eq!(f.si.unit, "rad/s²");
    assert!(rel_diff(f.discrete.unwrap().value, 1e-7) < TOL_FIT);
    assert_eq!(f.datasheet.unwrap().unit, "°/h²");
    assert_eq!(si_unit(NoiseTerm::Quantization, Some(GYRO), ""), "rad");
    assert_eq!(si_unit(NoiseTerm::Quantization, Some(ACCEL), ""), "m/s");
    assert_eq!(si_unit(NoiseTerm::RateRamp, Some(ACCEL), ""), "m/s³");
}

#[test]
fn units_adis_datasheet_figures() {
    // docs/methods.md §14.5: ADIS16405 gyro ARW 2.0 °/√h, accel VRW 0.2 m/s/√h
    let n = from_datasheet(NoiseTerm::NoiseDensity, GYRO, 2.0).unwrap();
    assert!(rel_diff(n, 5.818e-4) < TOL_4, "{n}");
    let n = from_datasheet(NoiseTerm::NoiseDensity, ACCEL, 0.2).unwrap();
    assert!(rel_diff(n, 3.333e-3) < TOL_4, "{n}");
}

#[test]
fn units_si_units_without_a_sensor_kind_use_the_data_unit() {
    let expect = [
        (NoiseTerm::NoiseDensity, "V/√Hz"),
        (NoiseTerm::RandomWalk, "V/s/√Hz"),
        (NoiseTerm::BiasInstability, "V"),
        (NoiseTerm::Quantization, "V·s"),
        (NoiseTerm::RateRamp, "V/s"),
        (NoiseTerm::GmSigma, "V"),
        (NoiseTerm::GmCorrelationTime, "s"),
        (NoiseTerm::GmDrivingDensity, "V/s/√Hz"),
    ];
    for (term, unit) in expect {
        assert_eq!(si_unit(term, None, "V"), unit);
        let f = forms(term, None, "V", 1.0, 10.0);
        assert!(f.datasheet.is_none(), "{term:?}");
    }
    // a bad rate gives no discrete form, and no panic
    assert!(forms(NoiseTerm::NoiseDensity, Some(GYRO), "", 1.0, 0.0)
        .discrete
        .is_none());
    assert!(forms(NoiseTerm::RandomWalk, Some(GYRO), "", 1.0, f64::NAN)
        .discrete
        .is_none());
}

#[test]
fn units_signal_units_parse_leniently_and_case_aware() {
    use SignalUnit::*;
    let accept = [
        ("rad/s", RadPerSecond),
        ("rad s^-1", RadPerSecond),
        ("rad/sec", RadPerSecond),
        ("rad·s⁻¹", RadPerSecond),
        ("RAD/S", RadPerSecond),
        ("deg/s", DegreePerSecond),
        ("°/s", DegreePerSecond),
        ("dps", DegreePerSecond),
        ("degrees/second", DegreePerSecond),
        ("deg/h", DegreePerHour),
        ("°/h", DegreePerHour),
        ("dph", DegreePerHour),
        ("deg/hr", DegreePerHour),
        ("m/s^2", MeterPerSecond2),
        ("m/s2", MeterPerSecond2),
        ("m/s²", MeterPerSecond2),
        ("m s^-2", MeterPerSecond2),
        ("m/sec^2", MeterPerSecond2),
        ("g", StandardGravity),
        ("mg", MilliG),
        (" mg ", MilliG),
        (
            "deg/s (inferred: all values are multiples of 0.05, the ADIS16405 gyro LSB)",
            DegreePerSecond,
        ),
        (
            "g (inferred: values are multiples of ~0.00333 (3.33 mg ADIS16405 accel LSB))",
            StandardGravity,
        ),
        ("rad/s; from the header", RadPerSecond),
        ("deg/s inferred", DegreePerSecond),
    ];
    for (text, unit) in accept {
        assert_eq!(text.parse::<SignalUnit>(), Ok(unit), "{text:?}");
    }
    for text in [
        "",
        "G",
        "mG",
        "M/S^2",
        "Mg",
        "rps",
        "rad",
        "furlong/fortnight",
        "(deg/s)",
    ] {
        let e = text.parse::<SignalUnit>().unwrap_err();
        assert_eq!(e.name, "unit");
        let msg = e.to_string();
        assert!(
            msg.contains("rad/s, deg/s, deg/h") && msg.contains("m/s^2, g, mg"),
            "{msg}"
        );
    }
    for u in SignalUnit::ALL {
        assert_eq!(u.to_string().parse::<SignalUnit>(), Ok(u));
    }
    assert!(rel_diff(DegreePerSecond.to_si(), std::f64::consts::PI / 180.0) < TOL_EXACT);
    assert!(rel_diff(DegreePerHour.to_si() * 3600.0, DegreePerSecond.to_si()) < TOL_EXACT);
    assert_eq!(MilliG.to_si(), 9.80665e-3);
    assert_eq!(StandardGravity.kind(), ACCEL);
    assert_eq!(SignalUnit::si(GYRO), RadPerSecond);
    assert_eq!(serde_json::to_string(&GYRO).unwrap(), "\"gyro\"");
    assert_eq!(serde_json::to_string(&ACCEL).unwrap(), "\"accel\"");
}

proptest! {
    /// to_datasheet and from_datasheet invert each other for every term with a datasheet unit.
    #[test]
    fn units_datasheet_round_trips(exp in -15.0f64..5.0, term in 0usize..8, accel in any::<bool>()) {
        let v = 10f64.powf(exp);
        let term = NoiseTerm::ALL[term];
        let kind = if accel { ACCEL } else { GYRO };
        match to_datasheet(term, kind, v) {
            Some(q) => {
                let back = from_datasheet(term, kind, q.value).unwrap();
                prop_assert!(rel_diff(back, v) < TOL_EXACT, "{term:?} {v} -> {q:?} -> {back}");
                let f = forms(term, Some(kind), "", v, 100.0);
                prop_assert_eq!(f.datasheet, Some(q));
            }
            None => prop_assert!(from_datasheet(term, kind, 1.0).is_none()),
        }
    }
}
