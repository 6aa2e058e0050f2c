//! Navigation-stack noise files (docs/methods.md §14.4): each format renders, parses by hand, and
//! holds the right numbers under the right keys; missing values are typed errors naming the key.

use crate::tests::common::rel_diff;
use gmwm::calib::export::{render_export, ExportError, ExportFormat, NavNoise, SensorNoise};
use std::collections::BTreeMap;

/// Values are written with 8 significant digits: relative rounding at most 5e-8.
const TOL_WRITTEN: f64 = 5e-8;

const GYRO: SensorNoise = SensorNoise {
    noise_density: Some(1.6968e-4),
    random_walk: Some(1.9393e-5),
    bias_correlation_time_s: Some(1000.0),
    bias_sigma: Some(8.7e-3),
    bias_driving_density: Some(1.9393e-5),
};
const ACCEL: SensorNoise = SensorNoise {
    noise_density: Some(2.0e-3),
    random_walk: Some(3.0e-3),
    bias_correlation_time_s: Some(300.0),
    bias_sigma: Some(0.196),
    bias_driving_density: Some(3.0e-3),
};

fn noise() -> NavNoise {
    NavNoise {
        update_rate_hz: 200.0,
        rostopic: Some("/imu0".to_string()),
        gyroscope: GYRO,
        accelerometer: ACCEL,
        comments: vec![
            "gmwm calibration of imu.csv.gz (provenance)".to_string(),
            "axis policy: worst of x, y, z; inflation: none".to_string(),
        ],
    }
}

/// A YAML 1.1 / OpenCV float: optional sign, digits, '.', digits, optionally 'e' with a sign and
/// digits (YAML 1.1 resolves an unsigned exponent as a string).
fn is_yaml_float(s: &str) -> bool {
    let s = s.strip_prefix('-').unwrap_or(s);
    let (mantissa, exp) = match s.split_once('e') {
        Some((m, e)) => (m, Some(e)),
        None => (s, None),
    };
    let Some((int, frac)) = mantissa.split_once('.') else {
        return false;
    };
    let digits = |t: &str| !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit());
    digits(int)
        && digits(frac)
        && exp.map_or(true, |e| {
            (e.starts_with('+') || e.starts_with('-')) && digits(&e[1..])
        })
}

/// The `key: value` lines of a flat or one-level YAML file, checked by hand: every line is a
/// comment, blank, the `%YAML:1.0` header (first line only), a list item, or `key: value`
/// with an optional ` # comment`. Keys are prefixed with their parent (`imu0.`).
fn yaml_pairs(text: &str) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    // (indent, key) of the open mappings
    let mut parents: Vec<(usize, String)> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.starts_with("%YAML") {
            assert_eq!(i, 0, "directive not on the first line: {line:?}");
            assert_eq!(line, "%YAML:1.0");
            continue;
        }
        let body = match line.find(" #") {
            Some(p) => &line[..p],
            None => line,
        };
        if body.trim().is_empty() || body.trim_start().starts_with('#') {
            continue;
        }
        if body.trim_start().starts_with("- [") {
            assert!(body.trim_end().ends_with(']'), "{line:?}");
            continue;
        }
        let indent = body.len() - body.trim_start().len();
        let (key, value) = body
            .trim()
            .split_once(':')
            .unwrap_or_else(|| panic!("not key: value: {line:?}"));
        assert!(!key.contains(' '), "key with a space: {line:?}");
        let value = value.trim();
        while parents.last().is_some_and(|(i, _)| *i >= indent) {
            parents.pop();
        }
        let mut path: Vec<&str> = parents.iter().map(|(_, k)| k.as_str()).collect();
        path.push(key);
        if value.is_empty() {
            parents.push((indent, key.to_string()));
        } else {
            out.insert(path.join("."), value.to_string());
        }
    }
    out
}

fn number(pairs: &BTreeMap<String, String>, key: &str) -> f64 {
    let v = pairs
        .get(key)
        .unwrap_or_else(|| panic!("no key {key}: {pairs:?}"));
    assert!(is_yaml_float(v), "{key}: {v} is not a YAML 1.1 float");
    v.parse().unwrap()
}

fn check_numbers(pairs: &BTreeMap<String, String>, expect: &[(&str, f64)]) {
    for &(key, v) in expect {
        let got = number(pairs, key);
        assert!(rel_diff(got, v) < TOL_WRITTEN, "{key}: {got} vs {v}");
    }
}

/// Every comment line of the caller appears as a comment.
fn check_comments(text: &str, prefix: &str) {
    for c in &noise().comments {
        assert!(
            text.lines()
                .any(|l| l.starts_with(prefix) && l.contains(c.as_str())),
            "comment {c:?} missing:\n{text}"
        );
    }
}

#[test]
fn export_kalibr_holds_the_densities_under_kalibr_keys() {
    let text = render_export(ExportFormat::KALIBR, &noise()).unwrap();
    println!("{text}");
    assert!(!text.starts_with('%'), "Kalibr's PyYAML rejects %YAML:1.0");
    let pairs = yaml_pairs(&text);
    check_numbers(
        &pairs,
        &[
            ("accelerometer_noise_density", 2.0e-3),
            ("accelerometer_random_walk", 3.0e-3),
            ("gyroscope_noise_density", 1.6968e-4),
            ("gyroscope_random_walk", 1.9393e-5),
            ("update_rate", 200.0),
        ],
    );
    assert_eq!(pairs["rostopic"], "/imu0");
    assert_eq!(pairs.len(), 6, "{pairs:?}");
    check_comments(&text, "# ");
    assert!(text.contains("[rad/s^2/sqrt(Hz)]") && text.contains("[m/s^3/sqrt(Hz)]"));
}

#[test]
fn export_openvins_nests_the_kalibr_keys_under_imu0() {
    let text = render_export(ExportFormat::OPENVINS, &noise()).unwrap();
    println!("{text}");
    assert!(text.starts_with("%YAML:1.0\n"));
    let pairs = yaml_pairs(&text);
    check_numbers(
        &pairs,
        &[
            ("imu0.accelerometer_noise_density", 2.0e-3),
            ("imu0.accelerometer_random_walk", 3.0e-3),
            ("imu0.gyroscope_noise_density", 1.6968e-4),
            ("imu0.gyroscope_random_walk", 1.9393e-5),
            ("imu0.update_rate", 200.0),
            ("imu0.time_offset", 0.0),
        ],
    );
    assert_eq!(pairs["imu0.model"], "calibrated");
    assert_eq!(pairs["imu0.rostopic"], "/imu0");
    assert!(
        text.contains("  T_i_b:\n    - [1.0, 0.0, 0.0, 0.0]\n"),
        "{text}"
    );
    check_comments(&text, "# ");
}

#[test]
fn export_vins_writes_its_short_keys() {
    let text = render_export(ExportFormat::VINS, &noise()).unwrap();
    println!("{text}");
    assert!(text.starts_with("%YAML:1.0\n"));
    let pairs = yaml_pairs(&text);
    check_numbers(
        &pairs,
        &[
            ("acc_n", 2.0e-3),
            ("acc_w", 3.0e-3),
            ("gyr_n", 1.6968e-4),
            ("gyr_w", 1.9393e-5),
            ("g_norm", 9.80665),
        ],
    );
    assert_eq!(pairs["imu"], "1");
    assert_eq!(pairs["imu_topic"], "\"/imu0\"");
    check_comments(&text, "# ");
}

#[test]
fn export_orbslam3_writes_its_imu_block() {
    let text = render_export(ExportFormat::ORBSLAM3, &noise()).unwrap();
    println!("{text}");
    assert!(text.starts_with("%YAML:1.0\n"));
    let pairs = yaml_pairs(&text);
    check_numbers(
        &pairs,
        &[
            ("IMU.NoiseGyro", 1.6968e-4),
            ("IMU.NoiseAcc", 2.0e-3),
            ("IMU.GyroWalk", 1.9393e-5),
            ("IMU.AccWalk", 3.0e-3),
            ("IMU.Frequency", 200.0),
        ],
    );
    assert_eq!(pairs.len(), 5, "{pairs:?}");
    check_comments(&text, "# ");
}

/// Checks tags balance by hand (comments skipped) and returns `element -> text` of the leaves.
fn xml_leaves(text: &str) -> BTreeMap<String, String> {
    let mut stack: Vec<String> = Vec::new();
    let mut leaves = BTreeMap::new();
    let mut roots = 0;
    let mut rest = text;
    while let Some(start) = rest.find('<') {
        let last_text = rest[..start].to_string();
        rest = &rest[start..];
        if let Some(after) = rest.strip_prefix("<!--") {
            let end = after.find("-->").expect("unterminated comment");
            assert!(!after[..end].contains("--"), "'--' inside a comment");
            rest = &after[end + 3..];
            continue;
        }
        let end = rest.find('>').expect("unterminated tag");
        let tag = &rest[1..end];
        rest = &rest[end + 1..];
        if let Some(name) = tag.strip_prefix('/') {
            let open = stack.pop().expect("closing tag without an opening one");
            assert_eq!(open, name, "mismatched tags");
            leaves.insert(name.to_string(), last_text.trim().to_string());
        } else if !tag.ends_with('/') {
            if stack.is_empty() {
                roots += 1;
            }
            let name = tag.split_whitespace().next().unwrap().to_string();
            stack.push(name);
        }
    }
    assert!(stack.is_empty(), "unclosed tags: {stack:?}");
    assert!(rest.trim().is_empty() && roots == 1, "one root element");
    leaves
}

#[test]
fn export_px4_is_a_balanced_plugin_fragment_with_the_gauss_markov_bias() {
    let text = render_export(ExportFormat::PX4, &noise()).unwrap();
    println!("{text}");
    assert!(
        text.contains("<plugin name=\"gazebo_imu_plugin\" filename=\"libgazebo_imu_plugin.so\">")
    );
    let leaves = xml_leaves(&text);
    for (key, v) in [
        ("gyroscopeNoiseDensity", 1.6968e-4),
        ("gyroscopeRandomWalk", 1.9393e-5),
        ("gyroscopeBiasCorrelationTime", 1000.0),
        ("gyroscopeTurnOnBiasSigma", 8.7e-3),
        ("accelerometerNoiseDensity", 2.0e-3),
        ("accelerometerRandomWalk", 3.0e-3),
        ("accelerometerBiasCorrelationTime", 300.0),
        ("accelerometerTurnOnBiasSigma", 0.196),
    ] {
        let got: f64 = leaves[key].parse().unwrap();
        assert!(rel_diff(got, v) < TOL_WRITTEN, "{key}: {got} vs {v}");
    }
    assert_eq!(leaves["imuTopic"], "/imu0");
    // the implied stationary sd of the plugin's GM bias is stated: 1.9393e-5 sqrt(500)
    assert!(text.contains(&format!("{:.7e}", 1.9393e-5 * 500f64.sqrt()).replace("e-4", "e-04")));
    check_comments(&text, "<!-- ");
}

#[test]
fn export_missing_values_are_errors_naming_the_key() {
    let cases = [
        (ExportFormat::KALIBR, "gyroscope_random_walk"),
        (ExportFormat::OPENVINS, "gyroscope_random_walk"),
        (ExportFormat::VINS, "gyr_w"),
        (ExportFormat::ORBSLAM3, "IMU.GyroWalk"),
    ];
    let mut n = noise();
    n.gyroscope.random_walk = None;
    // PX4's random walk drives its Gauss–Markov bias: it is the GM driving density, present
    let px4 = render_export(ExportFormat::PX4, &n).unwrap();
    assert!(px4.contains("gyroscopeRandomWalk"));
    n.gyroscope.bias_driving_density = None;
    let e = render_export(ExportFormat::PX4, &n).unwrap_err();
    assert!(e.to_string().contains("gyroscopeRandomWalk"), "{e}");
    assert!(
        e.to_string().contains("--model"),
        "the hint says how to get one: {e}"
    );
    for (format, key) in cases {
        let e = render_export(format, &n).unwrap_err();
        assert!(
            matches!(e, ExportError::Missing { key: k, format: f, .. } if k == key && f == format),
            "{e:?}"
        );
        assert!(e.to_string().contains(key), "{e}");
    }
    // PX4 needs the GM keys too; the others do not
    let mut n = noise();
    n.accelerometer.bias_correlation_time_s = None;
    n.accelerometer.bias_sigma = None;
    let e = render_export(ExportFormat::PX4, &n).unwrap_err();
    assert!(
        e.to_string().contains("accelerometerBiasCorrelationTime"),
        "{e}"
    );
    assert!(render_export(ExportFormat::KALIBR, &n).is_ok());
    // not a positive finite number
    let mut n = noise();
    n.accelerometer.noise_density = Some(f64::NAN);
    let e = render_export(ExportFormat::ORBSLAM3, &n).unwrap_err();
    assert!(
        matches!(
            e,
            ExportError::Invalid {
                key: "IMU.NoiseAcc",
                ..
            }
        ),
        "{e:?}"
    );
    let mut n = noise();
    n.update_rate_hz = 0.0;
    assert!(matches!(
        render_export(ExportFormat::KALIBR, &n),
        Err(ExportError::Invalid {
            key: "update_rate",
            ..
        })
    ));
}

#[test]
fn export_without_a_topic_writes_a_marked_placeholder() {
    let mut n = noise();
    n.rostopic = None;
    let text = render_export(ExportFormat::KALIBR, &n).unwrap();
    assert_eq!(yaml_pairs(&text)["rostopic"], "/imu0");
    assert!(text.contains("# the IMU topic was not given: /imu0 is a placeholder"));
}

#[test]
fn export_formats_parse_and_name_their_files() {
    for f in ExportFormat::ALL {
        assert_eq!(f.to_string().parse::<ExportFormat>(), Ok(f));
        assert_eq!(
            serde_json::to_string(&f).unwrap(),
            format!("\"{}\"", f.name())
        );
        let name = f.default_file_name();
        assert!(name.ends_with(".yaml") || name.ends_with(".sdf"), "{name}");
    }
    assert_eq!(
        "ORBSLAM3".parse::<ExportFormat>(),
        Ok(ExportFormat::ORBSLAM3)
    );
    assert_eq!(ExportFormat::KALIBR.default_file_name(), "imu.yaml");
    assert_eq!(
        ExportFormat::OPENVINS.default_file_name(),
        "kalibr_imu_chain.yaml"
    );
    let e = "rovio".parse::<ExportFormat>().unwrap_err();
    assert_eq!(e.name, "format");
    assert!(
        e.to_string()
            .contains("kalibr, openvins, vins, orbslam3, px4"),
        "{e}"
    );
}

/// STYLE §6.9: public results are `Send + Sync + Clone`.
#[test]
fn export_calib_and_units_results_are_send_sync_clone() {
    fn check<T: Send + Sync + Clone>() {}
    check::<NavNoise>();
    check::<ExportError>();
    check::<gmwm::calib::ieee::IeeeReadoff>();
    check::<gmwm::units::UnitForms>();
}
