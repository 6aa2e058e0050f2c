//! The datasheet of a sensor (issue 28, item 6): its units, its text, its comparison with
//! measured values and its lines, against hand values.

use crate::tests::common::rel_diff;
use gmwm::calib::datasheet::{Datasheet, DatasheetError, DatasheetVerdict, Measured};
use gmwm::units::{
    datasheet_unit, from_datasheet, DatasheetUnitError, NoiseTerm, SignalKind, SignalUnit,
};
use std::f64::consts::PI;

/// One or two multiplications: a few ulps.
const TOL_EXACT: f64 = 1e-12;

const GYRO: SignalKind = SignalKind::Gyroscope;
const ACCEL: SignalKind = SignalKind::Accelerometer;

#[test]
fn datasheet_unit_reads_the_datasheet_units_with_their_si_factors() {
    let deg = PI / 180.0;
    let g = 9.80665;
    for (text, kind, term, factor) in [
        // 1 deg/sqrt(h) = (pi/180) rad / 60 sqrt(s)
        ("deg/sqrt(h)", GYRO, NoiseTerm::NoiseDensity, deg / 60.0),
        ("°/√h", GYRO, NoiseTerm::NoiseDensity, deg / 60.0),
        ("deg/√hr", GYRO, NoiseTerm::NoiseDensity, deg / 60.0),
        (
            "deg/h/sqrt(Hz)",
            GYRO,
            NoiseTerm::NoiseDensity,
            deg / 3600.0,
        ),
        ("deg/s/sqrt(Hz)", GYRO, NoiseTerm::NoiseDensity, deg),
        ("mdps/√Hz", GYRO, NoiseTerm::NoiseDensity, deg * 1e-3),
        ("rad/s/sqrt(Hz)", GYRO, NoiseTerm::NoiseDensity, 1.0),
        ("deg h^(-1/2)", GYRO, NoiseTerm::NoiseDensity, deg / 60.0),
        ("deg/h", GYRO, NoiseTerm::BiasInstability, deg / 3600.0),
        ("dph", GYRO, NoiseTerm::BiasInstability, deg / 3600.0),
        ("deg/s", GYRO, NoiseTerm::BiasInstability, deg),
        ("rad/s", GYRO, NoiseTerm::BiasInstability, 1.0),
        (
            "deg/h/sqrt(h)",
            GYRO,
            NoiseTerm::RandomWalk,
            deg / 3600.0 / 60.0,
        ),
        (
            "deg/h^1.5",
            GYRO,
            NoiseTerm::RandomWalk,
            deg / 3600f64.powf(1.5),
        ),
        ("rad/s^2/sqrt(Hz)", GYRO, NoiseTerm::RandomWalk, 1.0),
        ("m/s/sqrt(h)", ACCEL, NoiseTerm::NoiseDensity, 1.0 / 60.0),
        ("ug/sqrt(Hz)", ACCEL, NoiseTerm::NoiseDensity, g * 1e-6),
        ("µg/√Hz", ACCEL, NoiseTerm::NoiseDensity, g * 1e-6),
        ("m/s^2/sqrt(Hz)", ACCEL, NoiseTerm::NoiseDensity, 1.0),
        ("mg", ACCEL, NoiseTerm::BiasInstability, g * 1e-3),
        ("ug", ACCEL, NoiseTerm::BiasInstability, g * 1e-6),
        ("m/s²", ACCEL, NoiseTerm::BiasInstability, 1.0),
        (
            "m/s/h/sqrt(h)",
            ACCEL,
            NoiseTerm::RandomWalk,
            1.0 / 3600.0 / 60.0,
        ),
        ("m/s^3/sqrt(Hz)", ACCEL, NoiseTerm::RandomWalk, 1.0),
        ("mg/sqrt(h)", ACCEL, NoiseTerm::RandomWalk, g * 1e-3 / 60.0),
    ] {
        let u = datasheet_unit(text).unwrap_or_else(|e| panic!("{text}: {e}"));
        assert_eq!((u.kind, u.term), (kind, term), "{text}");
        assert!(
            rel_diff(u.to_si, factor) < TOL_EXACT,
            "{text}: {} vs {factor}",
            u.to_si
        );
    }
}

/// The parser agrees with the module table's datasheet forms (`units::forms`).
#[test]
fn datasheet_unit_agrees_with_the_datasheet_forms() {
    for (text, kind, term) in [
        ("deg/sqrt(h)", GYRO, NoiseTerm::NoiseDensity),
        ("deg/h/sqrt(h)", GYRO, NoiseTerm::RandomWalk),
        ("deg/h", GYRO, NoiseTerm::BiasInstability),
        ("m/s/sqrt(h)", ACCEL, NoiseTerm::NoiseDensity),
        ("m/s/h/sqrt(h)", ACCEL, NoiseTerm::RandomWalk),
        ("mg", ACCEL, NoiseTerm::BiasInstability),
    ] {
        let u = datasheet_unit(text).unwrap();
        let table = from_datasheet(term, kind, 1.0).unwrap();
        assert!(rel_diff(u.to_si, table) < TOL_EXACT, "{text}");
    }
}

#[test]
fn datasheet_unit_refuses_what_is_no_noise_term() {
    for (text, what) in [
        ("furlong", "unknown"),
        ("deg/fortnight", "unknown"),
        ("G", "unknown"),
        ("s", "not inertial"),
        ("deg m/s", "not inertial"),
        ("deg", "term"),
        ("deg/h^2", "term"),
    ] {
        let e = datasheet_unit(text).unwrap_err();
        let ok = match what {
            "unknown" => matches!(e, DatasheetUnitError::Unknown { .. }),
            "not inertial" => matches!(e, DatasheetUnitError::NotInertial { .. }),
            _ => matches!(e, DatasheetUnitError::NotNoiseTerm { .. }),
        };
        assert!(ok, "{text}: {e:?}");
    }
}

/// The example and the ADIS16405 datasheet: 2 deg/sqrt(h) = 2 (pi/180) / 60
/// rad/s/sqrt(Hz), 25 deg/h = 25 (pi/180) / 3600 rad/s, 0.2 m/s/sqrt(h) = 0.2/60 m/s^2/sqrt(Hz),
/// 0.2 mg = 0.2e-3 g.
#[test]
fn datasheet_reads_both_sensors_in_si() {
    let d: Datasheet = "N=2 deg/sqrt(h), B=25 deg/h, n=0.2 m/s/sqrt(h); accel:B=0.2 mg"
        .parse()
        .unwrap();
    let v = d.values();
    assert_eq!(v.len(), 4);
    let want = [
        ("N", GYRO, 2.0 * (PI / 180.0) / 60.0, "rad/s/√Hz"),
        ("B", GYRO, 25.0 * (PI / 180.0) / 3600.0, "rad/s"),
        ("N", ACCEL, 0.2 / 60.0, "m/s²/√Hz"),
        ("B", ACCEL, 0.2e-3 * 9.80665, "m/s²"),
    ];
    for (v, (key, kind, si, unit)) in v.iter().zip(want) {
        assert_eq!((v.key, v.kind, v.unit_si.as_str()), (key, kind, unit));
        assert!(rel_diff(v.value_si, si) < TOL_EXACT, "{v}");
    }
    assert_eq!(v[0].unit, "deg/sqrt(h)");
    assert_eq!(
        d.to_string(),
        "N=2 deg/sqrt(h), B=25 deg/h, N=0.2 m/s/sqrt(h), B=0.2 mg"
    );
    assert_eq!(d.to_string().parse::<Datasheet>().unwrap(), d);
}

/// Whether an error is the expected variant.
type IsVariant = fn(&DatasheetError) -> bool;

#[test]
fn datasheet_refuses_bad_items_naming_them() {
    let cases: [(&str, IsVariant, &str); 11] = [
        ("", |e| matches!(e, DatasheetError::Empty), "no item"),
        (" , ", |e| matches!(e, DatasheetError::Empty), "no item"),
        (
            "N 2 deg/sqrt(h)",
            |e| matches!(e, DatasheetError::NoEquals { .. }),
            "\"N 2 deg/sqrt(h)\"",
        ),
        (
            "X=2 deg/sqrt(h)",
            |e| matches!(e, DatasheetError::UnknownKey { .. }),
            "unknown key \"X\"",
        ),
        (
            "N=deg/sqrt(h)",
            |e| matches!(e, DatasheetError::MissingNumber { .. }),
            "no number",
        ),
        (
            "N=0 deg/sqrt(h)",
            |e| matches!(e, DatasheetError::NotPositive { .. }),
            "positive",
        ),
        (
            "N=2",
            |e| matches!(e, DatasheetError::MissingUnit { .. }),
            "no unit",
        ),
        (
            "N=2 furlong",
            |e| matches!(e, DatasheetError::Unit { .. }),
            "furlong",
        ),
        (
            "N=25 deg/h",
            |e| matches!(e, DatasheetError::WrongDimension { .. }),
            "bias instability (B) unit",
        ),
        (
            "accel:N=2 deg/sqrt(h)",
            |e| matches!(e, DatasheetError::SensorMismatch { .. }),
            "gyroscope",
        ),
        (
            "N=2 deg/sqrt(h), B=25 deg/h, N=3 deg/sqrt(h)",
            |e| matches!(e, DatasheetError::Duplicate { .. }),
            "\"N=3 deg/sqrt(h)\": the gyroscope N is given twice",
        ),
    ];
    for (text, is, says) in cases {
        let e = text.parse::<Datasheet>().unwrap_err();
        assert!(is(&e), "{text}: {e:?}");
        let msg = e.to_string();
        assert!(msg.contains(says), "{text}: {msg}");
        assert!(!msg.contains('\n'), "{text}: one line: {msg}");
    }
    // a gyroscope N and an accelerometer N are no duplicate
    assert!("N=2 deg/sqrt(h), N=0.2 m/s/sqrt(h)"
        .parse::<Datasheet>()
        .is_ok());
}

/// The lines at their read-off times: the Allan deviation equals N at 1 s and K at 3 s, the
/// floor is 0.664 B; the Haar WV is AV(tau/2)/2 (docs/methods.md §3.4): N²/τ, K² τ/12,
/// (0.664 B)²/2; in a data unit the coefficient is divided by the unit's SI factor.
#[test]
fn datasheet_lines_follow_the_ieee_slopes() {
    let d: Datasheet = "N=2 deg/sqrt(h), B=25 deg/h, K=3 deg/h/sqrt(h)"
        .parse()
        .unwrap();
    let si = d.lines(SignalUnit::RadPerSecond);
    let deg = d.lines(SignalUnit::DegreePerSecond);
    assert!(d.lines(SignalUnit::MeterPerSecond2).is_empty());
    let (n, b, k) = (
        d.values()[0].value_si,
        d.values()[1].value_si,
        d.values()[2].value_si,
    );
    let close = |a: f64, b: f64| rel_diff(a, b) < TOL_EXACT;
    assert!(close(si[0].adev(1.0), n) && close(si[0].adev(4.0), n / 2.0));
    assert!(close(si[1].adev(7.0), 0.664 * b));
    assert!(close(si[2].adev(3.0), k) && close(si[2].adev(12.0), 2.0 * k));
    assert!(close(si[0].wv(8.0), n * n / 8.0));
    assert!(close(si[1].wv(8.0), (0.664 * b).powi(2) / 2.0));
    assert!(close(si[2].wv(8.0), k * k * 8.0 / 12.0));
    assert_eq!(
        (si[0].at_tau_s(), si[1].at_tau_s(), si[2].at_tau_s()),
        (Some(1.0), None, Some(3.0))
    );
    // 2 deg/sqrt(h) in deg/s/sqrt(Hz) is 2/60
    assert!(close(deg[0].coefficient, 2.0 / 60.0));
    assert!(close(deg[0].adev(1.0) * PI / 180.0, si[0].adev(1.0)));
    assert_eq!(si[0].label, "datasheet N = 2 deg/sqrt(h)");
}

#[test]
fn datasheet_compare_places_the_datasheet_against_the_interval() {
    let d: Datasheet = "N=2 deg/sqrt(h), B=25 deg/h, K=3 deg/h/sqrt(h)"
        .parse()
        .unwrap();
    let n = d.values()[0].value_si;
    let b = d.values()[1].value_si;
    let k = d.values()[2].value_si;
    let est = |v: f64, lo: f64, hi: f64| Measured {
        value: v,
        interval: Some((lo, hi)),
        upper_bound: false,
    };
    let bound = |v: f64| Measured {
        value: v,
        interval: None,
        upper_bound: true,
    };
    // N measured at half the datasheet with a tight interval: the datasheet lies above it
    let c = d
        .compare(
            GYRO,
            Some(est(n / 2.0, 0.45 * n, 0.55 * n)),
            Some(bound(0.5 * b)),
            None,
        )
        .unwrap();
    let cn = c.n.as_ref().unwrap();
    assert_eq!(cn.verdict, DatasheetVerdict::Above);
    assert!(rel_diff(cn.ratio.unwrap(), 0.5) < TOL_EXACT);
    assert!(
        rel_diff(cn.measured.unwrap(), 1.0) < TOL_EXACT,
        "1 deg/sqrt(h)"
    );
    // a measured bound below the datasheet: above; the bound is its interval's top
    let cb = c.b.as_ref().unwrap();
    assert_eq!(cb.verdict, DatasheetVerdict::Above);
    assert!(cb.upper_bound && cb.ci_low_si == Some(0.0));
    assert_eq!(c.k.as_ref().unwrap().verdict, DatasheetVerdict::NotMeasured);
    let c = d
        .compare(
            GYRO,
            Some(est(2.0 * n, 1.5 * n, 2.5 * n)),
            Some(bound(2.0 * b)),
            Some(est(k, 0.5 * k, 2.0 * k)),
        )
        .unwrap();
    assert_eq!(c.n.as_ref().unwrap().verdict, DatasheetVerdict::Below);
    assert_eq!(c.b.as_ref().unwrap().verdict, DatasheetVerdict::Inside);
    assert_eq!(c.k.as_ref().unwrap().verdict, DatasheetVerdict::Inside);
    let no_ci = Measured {
        value: n,
        interval: None,
        upper_bound: false,
    };
    let c = d.compare(GYRO, Some(no_ci), None, None).unwrap();
    assert_eq!(c.n.unwrap().verdict, DatasheetVerdict::NoInterval);
    assert!(d.compare(ACCEL, None, None, None).is_none());
    let json =
        serde_json::to_value(d.compare(GYRO, Some(est(n, n, n)), None, None).unwrap()).unwrap();
    assert_eq!(json["N"]["verdict"], "inside");
    assert!(json.get("K").is_some() && json["K"]["verdict"] == "not-measured");
}
