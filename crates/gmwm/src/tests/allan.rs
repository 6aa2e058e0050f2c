//! Allan, modified Allan and Hadamard variances (docs/methods.md §3): hand values, slow oracles,
//! the AV = 2 WV identity (§3.4), R package and allantools references, white-noise closed forms.

use crate::tests::common::{data_dir, f64s, read_ref, rel_diff};
use gmwm::variance::allan::package_error;
use gmwm::{
    allan_variance, AllanKind, AllanOptions, AllanVariance, AvConvention, InputError, SeriesError,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::io::Read;
use std::sync::OnceLock;

/// docs/methods.md §3 test values carry 7 significant digits.
const TOL_METHODS: f64 = 5e-7;
/// Fast (prefix sums) versus slow (compensated direct sums) on the same data: both are accurate
/// to a few ulps per term, so 1e-12 leaves a wide margin while catching any off-by-one term.
const TOL_ORACLE: f64 = 1e-12;
/// R package / allantools outputs versus ours: different summation orders over 1e5..1e6 terms
/// (allantools itself is 1e-11 from 2 WV on accel_x), far below any estimator difference (>= 1e-7).
const TOL_REF: f64 = 1e-9;
/// Seed of all random series here.
const SEED: u64 = 20_260_322;

const TEXTBOOK: AvConvention = AvConvention::Textbook;
const PACKAGE: AvConvention = AvConvention::Package;

fn opts(kind: AllanKind, convention: AvConvention) -> AllanOptions {
    AllanOptions {
        kind,
        convention,
        ..AllanOptions::default()
    }
}

fn av(x: &[f64], kind: AllanKind, convention: AvConvention) -> AllanVariance {
    allan_variance(x, 1.0, &opts(kind, convention)).unwrap()
}

fn white_noise(n: usize, sigma2: f64, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let normal = Normal::new(0.0, sigma2.sqrt()).unwrap();
    (0..n).map(|_| normal.sample(&mut rng)).collect()
}

// ------------------------------------------------------------------------------------------
// Slow, obviously correct oracles: direct double loops with compensated sums.

/// Neumaier-compensated sum.
fn csum(values: impl IntoIterator<Item = f64>) -> f64 {
    crate::tests::common::neumaier_sum(values)
}

/// `sum_i w_i * mean(x_{s_i} .. x_{s_i + m - 1})` for windows `(s_i, w_i)`, summed as one
/// compensated sum of all weighted samples (exact up to one rounding even with a large offset).
fn windows(x: &[f64], m: usize, parts: &[(usize, f64)]) -> f64 {
    csum(
        parts
            .iter()
            .flat_map(|&(s, w)| x[s..s + m].iter().map(move |v| w * v)),
    ) / m as f64
}

/// Overlapping AV (§3.2); `package`: N - 2m terms, same divisor.
fn slow_av_overlap(x: &[f64], m: usize, package: bool) -> f64 {
    let n = x.len();
    let full = n - 2 * m + 1;
    let terms = if package { full - 1 } else { full };
    let ss = csum((0..terms).map(|k| windows(x, m, &[(k + m, 1.0), (k, -1.0)]).powi(2)));
    ss / (2.0 * full as f64)
}

/// Non-overlapping AV (§3.1): all consecutive differences, or (package) disjoint pairs.
fn slow_av_nonoverlap(x: &[f64], m: usize, package: bool) -> f64 {
    let k = x.len() / m;
    let d = |i: usize| windows(x, m, &[((i + 1) * m, 1.0), (i * m, -1.0)]).powi(2);
    if package {
        let pairs = x.len() / (2 * m);
        csum((0..pairs).map(|p| d(2 * p))) / (2.0 * pairs as f64)
    } else {
        csum((0..k - 1).map(d)) / (2.0 * (k - 1) as f64)
    }
}

/// Modified AV (§3.6), Riley's double sum written out.
fn slow_mvar(x: &[f64], m: usize) -> f64 {
    let terms = x.len() + 2 - 3 * m;
    let ss = csum((0..terms).map(|j| {
        let parts: Vec<(usize, f64)> = (j..j + m).flat_map(|i| [(i + m, 1.0), (i, -1.0)]).collect();
        windows(x, m, &parts).powi(2)
    }));
    ss / (2.0 * (m * m) as f64 * terms as f64)
}

/// Overlapping Hadamard variance (§3.5); `package`: N - 3m terms, same divisor.
fn slow_hv_overlap(x: &[f64], m: usize, package: bool) -> f64 {
    let full = x.len() - 3 * m + 1;
    let terms = if package { full - 1 } else { full };
    let ss = csum(
        (0..terms).map(|k| windows(x, m, &[(k + 2 * m, 1.0), (k + m, -2.0), (k, 1.0)]).powi(2)),
    );
    ss / (6.0 * full as f64)
}

/// Non-overlapping Hadamard variance (§3.5): all consecutive second differences / 6(K-2), or
/// (package) disjoint triples / 6(M-2).
fn slow_hv_nonoverlap(x: &[f64], m: usize, package: bool) -> f64 {
    let d = |i: usize| {
        windows(
            x,
            m,
            &[((i + 2) * m, 1.0), ((i + 1) * m, -2.0), (i * m, 1.0)],
        )
        .powi(2)
    };
    if package {
        let triples = x.len() / (3 * m);
        csum((0..triples).map(|t| d(3 * t))) / (6.0 * (triples as f64 - 2.0))
    } else {
        let k = x.len() / m;
        csum((0..k - 2).map(d)) / (6.0 * (k - 2) as f64)
    }
}

fn slow(x: &[f64], m: usize, kind: AllanKind, convention: AvConvention) -> f64 {
    let package = convention == PACKAGE;
    match kind {
        AllanKind::Overlapping => slow_av_overlap(x, m, package),
        AllanKind::NonOverlapping => slow_av_nonoverlap(x, m, package),
        AllanKind::Modified => slow_mvar(x, m),
        AllanKind::Hadamard => slow_hv_overlap(x, m, package),
        AllanKind::HadamardNonOverlapping => slow_hv_nonoverlap(x, m, package),
    }
}

/// Haar MODWT WV at level j (m = 2^{j-1}) by its direct formula (docs/methods.md §3.4):
/// `W_t = (mean(x_{t-m+1..t}) - mean(x_{t-2m+1..t-m})) / 2`, `t = 2m-1..N-1`, mean of squares.
fn haar_wv_direct(x: &[f64], m: usize) -> f64 {
    let coefs: Vec<f64> = (2 * m - 1..x.len())
        .map(|t| 0.5 * windows(x, m, &[(t + 1 - m, 1.0), (t + 1 - 2 * m, -1.0)]))
        .collect();
    csum(coefs.iter().map(|w| w * w)) / coefs.len() as f64
}

#[test]
fn oracles_match_methods_3_hand_values() {
    let x8 = [1.0, 3.0, 2.0, 5.0, 4.0, 6.0, 8.0, 7.0];
    assert!((slow_av_overlap(&x8, 2, false) - 2.1).abs() < 1e-12);
    assert!((slow_av_nonoverlap(&x8, 2, true) - 2.125).abs() < 1e-12);
    assert!((slow_av_overlap(&x8, 2, true) - 1.475).abs() < 1e-12);
    assert!((2.0 * haar_wv_direct(&x8, 2) - 2.1).abs() < 1e-12);
}

// ------------------------------------------------------------------------------------------
// docs/methods.md §3 test values

#[test]
fn allan_variance_matches_methods_3_test_values() {
    let close = |a: f64, b: f64| (a - b).abs() <= TOL_METHODS * b.abs().max(1.0);
    // x = (1,3,2,5,4,6,8,7): package AV_to (tau 2, 4) = (2.125, 6.125)
    let x8 = [1.0, 3.0, 2.0, 5.0, 4.0, 6.0, 8.0, 7.0];
    let to = av(&x8, AllanKind::NonOverlapping, PACKAGE);
    assert_eq!(to.tau(), vec![2.0, 4.0]);
    assert!(
        close(to.avar()[0], 2.125) && close(to.avar()[1], 6.125),
        "{:?}",
        to.avar()
    );
    // package AV_mo = (1.475, 0.0): the sum at tau = 4 has no term
    let mo = av(&x8, AllanKind::Overlapping, PACKAGE);
    assert_eq!(mo.tau(), vec![2.0, 4.0]);
    assert!(
        close(mo.avar()[0], 1.475) && mo.avar()[1] == 0.0,
        "{:?}",
        mo.avar()
    );
    // textbook (complete sum) AV_mo(2) = 2.1 = 2 x 1.05 (§3.4)
    let tb = av(&x8, AllanKind::Overlapping, TEXTBOOK);
    assert_eq!(tb.tau(), vec![1.0, 2.0, 4.0]);
    assert!(close(tb.avar()[1], 2.1), "{:?}", tb.avar());
    // error column, T = 8, tau = 2
    assert!(close(to.error()[0], 0.4082483) && close(package_error(8, 2), 0.4082483));

    // 16 values: package AV_mo (tau 2, 4, 8) = (2.173077, 7.100694, 0.0)
    let x16 = [
        1.0, 3.0, 2.0, 5.0, 4.0, 6.0, 8.0, 7.0, 9.0, 12.0, 10.0, 11.0, 15.0, 13.0, 14.0, 18.0,
    ];
    let mo = av(&x16, AllanKind::Overlapping, PACKAGE);
    assert_eq!(mo.tau(), vec![2.0, 4.0, 8.0]);
    assert!(
        close(mo.avar()[0], 2.173077) && close(mo.avar()[1], 7.100694),
        "{:?}",
        mo.avar()
    );
    assert_eq!(mo.avar()[2], 0.0);

    // T = 27: HV_to(3) = 6.851852. Block means 10/3, 6, 11/3 | 17/3, 13/3, 10/3 | 14/3, 10/3, 6,
    // squared second differences of the M = 3 disjoint triples 25, 1/9, 16, summed and divided by
    // the package's 6(M - 2) = 6: the value is the Package convention's (a textbook disjoint-triple
    // version would divide by 6M = 18, the textbook all-differences one by 6(K-2) = 42).
    let x27 = [
        2.0, 7.0, 1.0, 8.0, 2.0, 8.0, 1.0, 8.0, 2.0, 8.0, 4.0, 5.0, 9.0, 0.0, 4.0, 5.0, 2.0, 3.0,
        5.0, 3.0, 6.0, 0.0, 2.0, 8.0, 7.0, 4.0, 7.0,
    ];
    let hv = av(&x27, AllanKind::HadamardNonOverlapping, PACKAGE);
    assert_eq!(hv.tau(), vec![3.0]);
    assert!(close(hv.avar()[0], 6.851852), "{:?}", hv.avar());
    assert!(close(hv.avar()[0], (25.0 + 1.0 / 9.0 + 16.0) / 6.0));
    let hv_tb = av(&x27, AllanKind::HadamardNonOverlapping, TEXTBOOK);
    assert_eq!(hv_tb.tau(), vec![1.0, 3.0, 9.0]);
    assert!(close(hv_tb.avar()[1], slow_hv_nonoverlap(&x27, 3, false)));
}

// ------------------------------------------------------------------------------------------
// Fast versus slow oracle, AV = 2 WV

#[test]
fn allan_variance_matches_slow_oracle() {
    let mut checked = 0;
    for (i, &n) in [2usize, 3, 4, 5, 8, 9, 26, 27, 28, 81, 100, 257, 1000, 1023]
        .iter()
        .enumerate()
    {
        let mut x = white_noise(n, 1.0, SEED + i as u64);
        // a random walk component so that the scales differ
        let mut acc = 0.0;
        for v in x.iter_mut() {
            acc += 0.1 * *v;
            *v += acc;
        }
        for kind in AllanKind::ALL {
            for convention in [TEXTBOOK, PACKAGE] {
                let Ok(fast) = allan_variance(&x, 1.0, &opts(kind, convention)) else {
                    continue;
                };
                for (&m, &v) in fast.tau().iter().zip(fast.avar()) {
                    let s = slow(&x, m as usize, kind, convention);
                    assert!(
                        (v - s).abs() <= TOL_ORACLE * s.abs().max(1e-300),
                        "{kind} {convention} n {n} m {m}: fast {v} slow {s}"
                    );
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 300, "{checked}");
}

#[test]
fn allan_variance_cluster_sets_are_documented_ones() {
    let x = white_noise(1000, 1.0, SEED);
    let taus = |k, c| av(&x, k, c).tau().to_vec();
    let pow2: Vec<f64> = (0..9).map(|i| f64::from(1u32 << i)).collect(); // 2m <= 1000
    assert_eq!(taus(AllanKind::Overlapping, TEXTBOOK), pow2);
    assert_eq!(taus(AllanKind::NonOverlapping, TEXTBOOK), pow2);
    assert_eq!(taus(AllanKind::Modified, TEXTBOOK), pow2[..9].to_vec()); // 3m <= 1001
    assert_eq!(
        taus(AllanKind::Hadamard, TEXTBOOK),
        vec![1.0, 3.0, 9.0, 27.0, 81.0, 243.0]
    );
    assert_eq!(taus(AllanKind::Overlapping, PACKAGE), pow2[1..9].to_vec());
    assert_eq!(
        taus(AllanKind::Hadamard, PACKAGE),
        vec![3.0, 9.0, 27.0, 81.0, 243.0]
    );
    assert_eq!(
        taus(AllanKind::HadamardNonOverlapping, PACKAGE),
        vec![3.0, 9.0, 27.0, 81.0]
    );
    let a = av(&x, AllanKind::Overlapping, TEXTBOOK);
    assert_eq!(
        a.terms(),
        a.tau()
            .iter()
            .map(|&m| 1001 - 2 * m as usize)
            .collect::<Vec<_>>()
    );
}

#[test]
fn allan_variance_overlapping_is_twice_haar_wv() {
    for (i, (n, offset)) in [(1000usize, 0.0), (1001, 0.0), (4099, 1e3), (777, -1e3)]
        .into_iter()
        .enumerate()
    {
        let x: Vec<f64> = white_noise(n, 1.0, SEED + 100 + i as u64)
            .into_iter()
            .map(|v| v + offset)
            .collect();
        let a = av(&x, AllanKind::Overlapping, TEXTBOOK);
        assert_eq!(a.tau().len(), (n as f64).log2().floor() as usize); // J = floor(log2 N) levels
        for (&m, &v) in a.tau().iter().zip(a.avar()) {
            let wv2 = 2.0 * haar_wv_direct(&x, m as usize);
            assert!(
                rel_diff(v, wv2) <= TOL_ORACLE,
                "n {n} offset {offset} m {m}: AV {v} 2WV {wv2} rel {}",
                rel_diff(v, wv2)
            );
            // the CI is the eta3 interval of the Haar WV at tau = 2m (§1.7 through §3.4)
            let j = (2.0 * m).log2() as usize;
            let eta = gmwm::variance::ci::eta3(n - 2 * m as usize + 1, j);
            let k = a.tau().iter().position(|&t| t == m).unwrap();
            assert!((a.edf()[k] - eta).abs() < 1e-12);
            // (statrs returns NaN for some bounds at eta near 1; ours then falls back to bisection)
            let (lo, hi) = gmwm::variance::ci::chi_square_interval(v, eta, 0.05).unwrap();
            assert!(
                a.ci_low()[k].is_finite() && a.ci_high()[k].is_finite(),
                "m {m}"
            );
            assert!(a.ci_low()[k] < v && v < a.ci_high()[k], "m {m}");
            assert!(
                !lo.is_finite() || rel_diff(a.ci_low()[k], lo) < 1e-8,
                "m {m}: {lo}"
            );
            assert!(
                !hi.is_finite() || rel_diff(a.ci_high()[k], hi) < 1e-8,
                "m {m}: {hi}"
            );
        }
    }
}

// ------------------------------------------------------------------------------------------
// Real data: R package and allantools references

/// gyro_x and accel_x of adis_16405_imu1 (1e6 samples each), read once.
fn imu_columns() -> &'static (Vec<f64>, Vec<f64>) {
    static DATA: OnceLock<(Vec<f64>, Vec<f64>)> = OnceLock::new();
    DATA.get_or_init(|| {
        let path = data_dir().join("adis_16405_imu1.csv.gz");
        let file = std::fs::File::open(&path)
            .unwrap_or_else(|e| panic!("cannot open {}: {e}", path.display()));
        let mut text = String::new();
        flate2::read::GzDecoder::new(file)
            .read_to_string(&mut text)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut reader = csv::Reader::from_reader(text.as_bytes());
        let headers = reader.headers().unwrap().clone();
        let col = |name: &str| {
            headers
                .iter()
                .position(|h| h == name)
                .unwrap_or_else(|| panic!("{}: no column {name}", path.display()))
        };
        let (g, a) = (col("gyro_x"), col("accel_x"));
        let (mut gyro, mut accel) = (Vec::new(), Vec::new());
        for (line, rec) in reader.records().enumerate() {
            let rec = rec.unwrap_or_else(|e| panic!("{}:{}: {e}", path.display(), line + 2));
            gyro.push(rec[g].parse::<f64>().unwrap());
            accel.push(rec[a].parse::<f64>().unwrap());
        }
        assert_eq!(gyro.len(), 1_000_000);
        (gyro, accel)
    })
}

fn column(name: &str) -> &'static [f64] {
    let (gyro, accel) = imu_columns();
    match name {
        "gyro_x" => gyro,
        "accel_x" => accel,
        _ => panic!("unknown column {name}"),
    }
}

fn assert_all_close(what: &str, ours: &[f64], reference: &[f64], tol: f64) {
    assert_eq!(ours.len(), reference.len(), "{what}: lengths");
    for (i, (&a, &b)) in ours.iter().zip(reference).enumerate() {
        assert!(
            rel_diff(a, b) <= tol,
            "{what}[{i}]: ours {a} ref {b} rel {}",
            rel_diff(a, b)
        );
    }
}

fn check_against_package(reference: &serde_json::Value, x: &[f64], kind: AllanKind, what: &str) {
    let a = allan_variance(x, 100.0, &opts(kind, PACKAGE)).unwrap();
    let (var, dev) = if kind.is_hadamard() {
        ("hadamard", "hdev")
    } else {
        ("allan", "adev")
    };
    assert_all_close(
        &format!("{what} clusters"),
        a.tau(),
        &f64s(&reference["clusters"]),
        0.0,
    );
    assert_all_close(
        &format!("{what} tau_s"),
        a.tau_s(),
        &f64s(&reference["tau_seconds"]),
        1e-15,
    );
    assert_all_close(
        &format!("{what} {var}"),
        a.avar(),
        &f64s(&reference[var]),
        TOL_REF,
    );
    assert_all_close(
        &format!("{what} errors"),
        a.error(),
        &f64s(&reference["errors"]),
        TOL_REF,
    );
    assert_all_close(
        &format!("{what} {dev}"),
        a.adev(),
        &f64s(&reference[dev]),
        TOL_REF,
    );
    let (lci, uci) = a.package_band();
    assert_all_close(
        &format!("{what} lci"),
        &lci,
        &f64s(&reference["lci"]),
        TOL_REF,
    );
    assert_all_close(
        &format!("{what} uci"),
        &uci,
        &f64s(&reference["uci"]),
        TOL_REF,
    );
}

#[test]
fn allan_variance_package_reproduces_r_reference() {
    let reference = read_ref("avar_hadam_adis_16405_imu1.json");
    for name in ["gyro_x", "accel_x"] {
        let col = &reference["columns"][name];
        let x = column(name);
        let first = &col["first_100000"];
        assert_eq!(first["n"].as_u64(), Some(100_000));
        for (key, kind) in [
            ("avar_mo", AllanKind::Overlapping),
            ("avar_to", AllanKind::NonOverlapping),
            ("hadam_mo", AllanKind::Hadamard),
            ("hadam_to", AllanKind::HadamardNonOverlapping),
        ] {
            check_against_package(
                &first[key],
                &x[..100_000],
                kind,
                &format!("{name} 1e5 {key}"),
            );
        }
        for (key, kind) in [
            ("avar_to", AllanKind::NonOverlapping),
            ("hadam_to", AllanKind::HadamardNonOverlapping),
        ] {
            check_against_package(&col["full"][key], x, kind, &format!("{name} 1e6 {key}"));
        }
    }
}

#[test]
fn allan_variance_textbook_matches_allantools() {
    let reference = read_ref("allantools_compare.json");
    for name in ["gyro_x", "accel_x"] {
        let rows = reference["oavar_vs_2wv"]["columns"][name]["rows"]
            .as_array()
            .unwrap();
        let a = allan_variance(column(name), 100.0, &AllanOptions::default()).unwrap();
        assert_eq!(a.tau().len(), rows.len(), "{name}: octave taus");
        for (k, row) in rows.iter().enumerate() {
            assert_eq!(a.tau()[k], row["m"].as_f64().unwrap());
            assert_eq!(a.terms()[k] as u64, row["n_terms"].as_u64().unwrap());
            let oavar = row["allantools_oavar"].as_f64().unwrap();
            assert!(
                rel_diff(a.avar()[k], oavar) <= TOL_REF,
                "{name} m {}: ours {} allantools {oavar}",
                a.tau()[k],
                a.avar()[k]
            );
            assert!(rel_diff(a.tau_s()[k], row["tau_s"].as_f64().unwrap()) < 1e-15);
        }
    }
}

/// Sizes of the package-versus-textbook differences quoted in the module doc of `allan.rs`,
/// measured on the first 1e5 samples of both columns.
#[test]
fn allan_variance_package_differs_from_textbook_as_documented() {
    for name in ["gyro_x", "accel_x"] {
        let x = &column(name)[..100_000];
        // "mo": one term short of the textbook sum, same divisor: 0 <= 1 - ratio <= 2e-4
        let tb = av(x, AllanKind::Overlapping, TEXTBOOK);
        let pk = av(x, AllanKind::Overlapping, PACKAGE);
        for (k, &m) in pk.tau().iter().enumerate() {
            let t = tb.tau().iter().position(|&v| v == m).unwrap();
            let ratio = pk.avar()[k] / tb.avar()[t];
            assert!(
                (0.9998..=1.0).contains(&ratio),
                "{name} mo m {m}: ratio {ratio}"
            );
        }
        // Hadamard "to": divisor 6(M-2) instead of 6M for the same disjoint triples
        let pk = av(x, AllanKind::HadamardNonOverlapping, PACKAGE);
        for (k, &m) in pk.tau().iter().enumerate() {
            let triples = (x.len() / (3 * m as usize)) as f64;
            let textbook_disjoint = pk.avar()[k] * (triples - 2.0) / triples;
            assert!(textbook_disjoint < pk.avar()[k]);
            assert!(
                pk.avar()[k] / textbook_disjoint <= 5.0 / 3.0 + 1e-12,
                "{name} to m {m}"
            );
        }
        // "to" AV (disjoint pairs) versus all consecutive differences: sampling noise only,
        // within the textbook chi-square interval at every cluster length
        let tb = av(x, AllanKind::NonOverlapping, TEXTBOOK);
        let pk = av(x, AllanKind::NonOverlapping, PACKAGE);
        for (k, &m) in pk.tau().iter().enumerate() {
            let t = tb.tau().iter().position(|&v| v == m).unwrap();
            assert!(
                pk.avar()[k] > tb.ci_low()[t] && pk.avar()[k] < tb.ci_high()[t],
                "{name} to m {m}"
            );
        }
    }
}

// ------------------------------------------------------------------------------------------
// White noise: closed forms and the degrees of freedom

/// E[MVAR(m)] for white noise of variance sigma2 (docs/methods.md §3.6): the inner sum is
/// `(1/m) sum_t w_t x_t` with `w` the difference of two triangular weight vectors offset by m.
fn mvar_white_noise(m: usize, sigma2: f64) -> f64 {
    let mut w = vec![0.0_f64; 3 * m];
    for i in 0..m {
        for t in 0..m {
            w[i + m + t] += 1.0;
            w[i + t] -= 1.0;
        }
    }
    let sw2: f64 = w.iter().map(|v| v * v).sum();
    sigma2 * sw2 / (2.0 * (m as f64).powi(4))
}

#[test]
fn allan_variance_white_noise_is_sigma2_over_m() {
    let sigma2 = 2.5;
    let n = 1 << 16;
    let x = white_noise(n, sigma2, SEED + 7);
    assert!((mvar_white_noise(1, 1.0) - 1.0).abs() < 1e-15); // MVAR(1) = AVAR(1)
    for kind in AllanKind::ALL {
        let a = av(&x, kind, TEXTBOOK);
        for k in 0..a.tau().len() {
            let m = a.tau()[k] as usize;
            if m > n / 64 {
                break;
            }
            let truth = if kind == AllanKind::Modified {
                mvar_white_noise(m, sigma2)
            } else {
                // AV, HV of white noise (docs/methods.md §3; no m dependence beyond 1/m)
                sigma2 / m as f64
            };
            // five standard errors of a chi-square estimate with edf degrees of freedom
            let bound = 5.0 * (2.0 / a.edf()[k]).sqrt();
            let rel = (a.avar()[k] - truth) / truth;
            assert!(
                rel.abs() < bound,
                "{kind} m {m}: {} vs {truth} ({rel})",
                a.avar()[k]
            );
            assert!(a.ci_low()[k] < a.avar()[k] && a.avar()[k] < a.ci_high()[k]);
        }
    }
    // the modified AV of white noise tends to half the AV (Riley's ratio for white FM)
    assert!((mvar_white_noise(64, 1.0) * 64.0 - 0.5).abs() < 0.01);
}

/// The non-overlapping edf rules are exact for Gaussian white noise: Var(estimate) =
/// 2 E^2 / edf. B = 400 replicates estimate the variance to about 7% (1 sd); bound 25%.
#[test]
fn allan_variance_nonoverlapping_edf_matches_monte_carlo() {
    let b = 400;
    let cases = [
        (AllanKind::NonOverlapping, TEXTBOOK, 4usize),
        (AllanKind::NonOverlapping, PACKAGE, 4),
        (AllanKind::HadamardNonOverlapping, TEXTBOOK, 3),
        (AllanKind::HadamardNonOverlapping, PACKAGE, 3),
    ];
    for (kind, convention, m) in cases {
        let mut values = Vec::with_capacity(b);
        let mut edf = 0.0;
        let mut mean_truth = 0.0;
        for r in 0..b {
            let x = white_noise(1024, 1.0, SEED + 1000 + r as u64);
            let a = av(&x, kind, convention);
            let k = a.tau().iter().position(|&t| t == m as f64).unwrap();
            values.push(a.avar()[k]);
            edf = a.edf()[k];
            mean_truth = 1.0 / m as f64;
            if convention == PACKAGE && kind.is_hadamard() {
                let triples = (1024 / (3 * m)) as f64;
                mean_truth *= triples / (triples - 2.0); // the 6(M-2) divisor
            }
        }
        let mean = values.iter().sum::<f64>() / b as f64;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (b - 1) as f64;
        let predicted = 2.0 * mean_truth * mean_truth / edf;
        assert!(
            (var / predicted - 1.0).abs() < 0.25,
            "{kind} {convention} m {m}: MC var {var}, predicted {predicted} (edf {edf})"
        );
        assert!(
            (mean / mean_truth - 1.0).abs() < 0.05,
            "{kind} {convention}: mean {mean}"
        );
    }
}

// ------------------------------------------------------------------------------------------
// Bad input, display

#[test]
fn allan_variance_rejects_bad_input() {
    let x = white_noise(100, 1.0, SEED);
    let ok = AllanOptions::default();
    assert!(matches!(
        allan_variance(&[], 1.0, &ok),
        Err(InputError::Series(SeriesError::Empty))
    ));
    let mut nan = x.clone();
    nan[3] = f64::NAN;
    assert!(matches!(
        allan_variance(&nan, 1.0, &ok),
        Err(InputError::Series(SeriesError::NonFinite { index: 3, .. }))
    ));
    assert!(matches!(
        allan_variance(&[1.0; 10], 1.0, &ok),
        Err(InputError::Series(SeriesError::Constant { .. }))
    ));
    for f in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        match allan_variance(&x, f, &ok) {
            Err(InputError::Param(p)) => assert_eq!(p.name, "freq"),
            other => panic!("freq {f}: {other:?}"),
        }
    }
    for alpha in [0.0, 1.0, -0.5, f64::NAN] {
        let o = AllanOptions { alpha, ..ok };
        match allan_variance(&x, 1.0, &o) {
            Err(InputError::Param(p)) => assert_eq!(p.name, "alpha"),
            other => panic!("alpha {alpha}: {other:?}"),
        }
    }
    for (kind, convention, n, needed) in [
        (AllanKind::Hadamard, TEXTBOOK, 2, 3),
        (AllanKind::HadamardNonOverlapping, TEXTBOOK, 2, 3),
        (AllanKind::Overlapping, PACKAGE, 3, 4),
        (AllanKind::Hadamard, PACKAGE, 8, 9),
        (AllanKind::HadamardNonOverlapping, PACKAGE, 26, 27),
    ] {
        match allan_variance(&x[..n], 1.0, &opts(kind, convention)) {
            Err(InputError::Series(SeriesError::TooShort {
                n: got,
                needed: need,
                ..
            })) => {
                assert_eq!((got, need), (n, needed), "{kind} {convention}")
            }
            other => panic!("{kind} {convention} n {n}: {other:?}"),
        }
        assert!(allan_variance(&x[..needed], 1.0, &opts(kind, convention)).is_ok());
    }
    // the shortest textbook Allan series: two distinct samples
    let a = allan_variance(&[0.0, 1.0], 1.0, &ok).unwrap();
    assert_eq!(
        (a.tau().to_vec(), a.avar().to_vec()),
        (vec![1.0], vec![0.5])
    );
}

#[test]
fn allan_variance_display_is_a_table() {
    let x = white_noise(64, 1.0, SEED);
    let a = allan_variance(&x, 100.0, &AllanOptions::default()).unwrap();
    let text = a.to_string();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), a.tau().len() + 2);
    assert!(
        lines[1].contains("tau_s") && lines[1].contains("adev") && lines[1].contains("ci_high")
    );
    // aligned: every row as wide as the header
    assert!(
        lines[2..].iter().all(|l| l.len() == lines[1].len()),
        "{text}"
    );
    let h = allan_variance(&x, 100.0, &opts(AllanKind::Hadamard, TEXTBOOK)).unwrap();
    assert!(h.to_string().contains("hdev"));
}

#[test]
fn allan_variance_types_are_send_sync_clone() {
    fn check<T: Send + Sync + Clone>() {}
    check::<AllanVariance>();
    check::<AllanOptions>();
}

#[test]
fn allan_variance_every_short_length_matches_oracle() {
    for n in 2..=90usize {
        let x = white_noise(n, 1.0, SEED + 5000 + n as u64);
        for kind in AllanKind::ALL {
            for convention in [TEXTBOOK, PACKAGE] {
                match allan_variance(&x, 1.0, &opts(kind, convention)) {
                    Ok(fast) => {
                        for (&m, &v) in fast.tau().iter().zip(fast.avar()) {
                            let s = slow(&x, m as usize, kind, convention);
                            assert!(
                                (v - s).abs() <= TOL_ORACLE * s.abs().max(1e-300),
                                "{kind} {convention} n {n} m {m}: fast {v} slow {s}"
                            );
                        }
                    }
                    Err(InputError::Series(SeriesError::TooShort { needed, .. })) => {
                        assert!(n < needed, "{kind} {convention} n {n}")
                    }
                    Err(e) => panic!("{kind} {convention} n {n}: {e}"),
                }
            }
        }
    }
}
