//! How a model's error grows with time (docs/methods.md §17.1): its Allan variance at any
//! cluster of `m` samples and the mean square of the sum of `n` samples as a filter that holds
//! its bias sees it, the quantities a navigation filter's white-noise + random-walk model has
//! to cover.
//!
//! # Definitions
//! For a process `x` sampled at `f`, with `S_n = x_1 + ... + x_n`:
//! - the Allan variance at `tau = m / f` is `AV(m) = E (ybar_2 - ybar_1)^2 / 2` over two
//!   adjacent means of `m` samples; for a stationary `x` with `G(n) = Var S_n`,
//!   `AV(m) = (4 G(m) - G(2m)) / (2 m^2)` (two adjacent sums `A`, `B`: `Var(B - A) =
//!   4 G(m) - G(2m)`), so `AV(m) = 2 nu2(2m)`, the Haar WV of docs/methods.md §3.4, at every
//!   `m`, not only at powers of two;
//! - the integrated error is the sum over the mission of what the filter does not predict,
//!   divided by `f` (angle for a gyroscope, velocity for an accelerometer); its mean square is
//!   returned in unit² per sample² (divide by `f^2`). A white-noise + random-walk filter
//!   predicts its bias constant at the value it has estimated when the mission starts, so
//!   - the **bias terms** are held at their value `x_0` before the first sample: the error is
//!     `sum (x_t - x_0)`, of variance `H(n) = 2 sum_{h=1}^{n} h V(h)` with the variogram
//!     `V(h) = E (x_{t+h} - x_t)^2 / 2` (since `Cov(x_s - x_0, x_t - x_0) = V(s) + V(t) -
//!     V(|s - t|)`). They are the random walk, flicker noise, a drift (deterministic: its
//!     sum `omega n (n + 1) / 2` counts as its square), and every AR-type term (AR1, GM,
//!     ARMA11 with `phi > 0`) slow enough that holding its start value lowers its error at the
//!     horizon (`H(n_T) < G(n_T)`: a correlation time beyond about half the horizon);
//!   - the **noise terms** (WN, QN, MA1, MAF, SIN, ARMA(p, q) and the faster AR-type terms)
//!     are not in the bias: their sum has variance `G(n)`, their value at the start unknown.
//!
//! # Closed forms
//! | term | `AV(m)` | error mean square |
//! |---|---|---|
//! | WN `sigma2` | `sigma2 / m` | `n sigma2` |
//! | QN `q2` | `3 q2 / m^2` | `2 q2` |
//! | RW `gamma2` | `gamma2 (2 m^2 + 1) / (6 m)` | `gamma2 n (n + 1) (2n + 1) / 6` |
//! | DR `omega` | `omega^2 m^2 / 2` | `(omega n (n + 1) / 2)^2` |
//! | FN `b2` | `2 b2 nu2_1(2m)` | `(4 b2 / pi) [n (n + 1) H(n) / 2 - (n^2 - H(n)) / 8]` |
//! | AR-type | from `G` | `G(n)`, or held: `G(n) + n^2 r0 - 2 n r1 (1 - phi^n) / (1 - phi)` |
//! | SIN | from `G` | `G(n) = (A^2 / 2) sin^2(pi omega n) / sin^2(pi omega)` |
//! | MAF(L) | from `G` | `G(n)` summed over its `L` lags |
//! | ARMA(p, q) | from `G` | `G` from the autocovariance, cumulated |
//!
//! The AR-type `G(n) = n r0 + 2 r1 q(n) / (1 - phi)^2` is the exact covariance's
//! (`crate::variance::implied_cov`), computed without cancellation for `phi` near 1; the held
//! form is `Var(S_n - n x_0)` with `Cov(S_n, x_0) = r1 (1 - phi^n) / (1 - phi)`.

use super::implied_cov::Autoregressive;
use crate::process::{flicker, CovariancePart, LatentProcess, Process};

/// A model's Allan variance and integrated-error mean square at sample counts.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ErrorGrowth {
    /// The counts, ascending, `>= 1`.
    pub(crate) counts: Vec<usize>,
    /// `AV(m)` at a cluster of `counts[i]` samples, unit².
    pub(crate) allan: Vec<f64>,
    /// The integrated error's mean square over `counts[i]` samples times `f^2`, unit².
    pub(crate) integrated: Vec<f64>,
    /// Per process of the model, whether it is held in the bias (module doc).
    pub(crate) held: Vec<bool>,
}

impl ErrorGrowth {
    /// The growth of the sum of `processes` (independent) at `counts` (ascending, `>= 1`);
    /// the last count is the horizon that decides which AR-type terms are held.
    pub(crate) fn of(processes: &[Process], counts: &[usize]) -> Self {
        debug_assert!(counts.windows(2).all(|w| w[0] < w[1]) && counts[0] >= 1);
        let mut allan = vec![0.0; counts.len()];
        let mut integrated = vec![0.0; counts.len()];
        let mut held = Vec::with_capacity(processes.len());
        for p in processes {
            let one = Term::of(p, counts);
            for i in 0..counts.len() {
                allan[i] += one.allan[i];
                integrated[i] += one.integrated[i];
            }
            held.push(one.held);
        }
        Self {
            counts: counts.to_vec(),
            allan,
            integrated,
            held,
        }
    }
}

/// One process's growth.
struct Term {
    allan: Vec<f64>,
    integrated: Vec<f64>,
    held: bool,
}

impl Term {
    fn of(p: &Process, counts: &[usize]) -> Self {
        let each = |f: &dyn Fn(f64) -> f64| counts.iter().map(|&c| f(c as f64)).collect::<Vec<_>>();
        let bias = |allan, integrated| Self {
            allan,
            integrated,
            held: true,
        };
        match p {
            Process::Flicker(fl) => bias(
                each(&|m| 2.0 * fl.b2() * flicker::unit_wv(m)),
                each(&|n| fl.held_sum_variance(n)),
            ),
            Process::Sin(s) => noise(counts, &|n| s.increment_variance(n)),
            Process::Maf(f) => noise(counts, &|n| f.increment_variance(n as usize)),
            Process::Arma(a) => {
                let last = 2 * counts.last().copied().unwrap_or(1);
                let g = cumulated_increment_variances(&a.autocovariance(last), last);
                noise(counts, &|n| g[n as usize])
            }
            _ => match p.covariance_part() {
                Ok(CovariancePart::White(s2)) => noise(counts, &|n| n * s2),
                Ok(CovariancePart::Quantization(q2)) => {
                    // G(n) = 2 q2 for n >= 1 (the sum telescopes)
                    noise(counts, &|n| if n >= 1.0 { 2.0 * q2 } else { 0.0 })
                }
                Ok(CovariancePart::RandomWalk(g2)) => bias(
                    each(&|m| g2 * (2.0 * m * m + 1.0) / (6.0 * m)),
                    each(&|n| g2 * n * (n + 1.0) * (2.0 * n + 1.0) / 6.0),
                ),
                Ok(CovariancePart::Drift(w)) => bias(
                    each(&|m| 0.5 * w * w * m * m),
                    each(&|n| (0.5 * w * n * (n + 1.0)).powi(2)),
                ),
                Ok(CovariancePart::Autoregressive { phi, r0, r1 }) => {
                    autoregressive(counts, Autoregressive::new(phi, r0, r1))
                }
                // every process without a part is matched above
                Err(_) => unreachable!("{} has a covariance part or its own arm", p.name()),
            },
        }
    }
}

/// A noise term: `(AV(m), G(n))` from its `G`.
fn noise(counts: &[usize], g: &dyn Fn(f64) -> f64) -> Term {
    let (allan, integrated) = counts
        .iter()
        .map(|&c| {
            let m = c as f64;
            let gm = g(m);
            ((4.0 * gm - g(2.0 * m)) / (2.0 * m * m), gm)
        })
        .unzip();
    Term {
        allan,
        integrated,
        held: false,
    }
}

/// An AR-type term: held when that lowers its error at the last count (module doc).
fn autoregressive(counts: &[usize], part: Autoregressive) -> Term {
    let g = |n: f64| part.increment_variance(n);
    let mut term = noise(counts, &g);
    let Some(&last) = counts.last() else {
        return term;
    };
    if part.held_sum_variance(last as f64) < g(last as f64) {
        term.integrated = counts
            .iter()
            .map(|&c| part.held_sum_variance(c as f64))
            .collect();
        term.held = true;
    }
    term
}

/// `G(0..=last)` from the autocovariance `gamma_0..=gamma_last`:
/// `G(n) = G(n - 1) + gamma_0 + 2 sum_{h=1}^{n-1} gamma_h`.
fn cumulated_increment_variances(gamma: &[f64], last: usize) -> Vec<f64> {
    let mut g = Vec::with_capacity(last + 1);
    g.push(0.0);
    let mut tail = 0.0; // sum_{h=1}^{n-1} gamma_h
    for n in 1..=last {
        let prev = g[n - 1];
        g.push(prev + gamma[0] + 2.0 * tail);
        tail += gamma[n];
    }
    g
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;

    fn processes(text: &str, freq: f64) -> Vec<Process> {
        Model::parse(text).unwrap().processes(freq).unwrap()
    }

    /// `AV(m) = 2 nu2(2m)`: at powers of two, the implied Haar WV of every process
    /// (docs/methods.md §4.2, computed by each process's own closed form).
    #[test]
    fn allan_variance_is_twice_the_implied_wv_at_powers_of_two() {
        let freq = 100.0;
        for text in [
            "WN(sigma2=2.5)",
            "QN(q2=0.7)",
            "RW(gamma2=1e-4)",
            "DR(omega=1e-3)",
            "AR1(phi=0.9, sigma2=1)",
            "AR1(phi=-0.6, sigma2=1)",
            "GM(beta=0.02, sigma2_gm=4)",
            "MA1(theta=0.4, sigma2=1)",
            "ARMA11(phi=0.8, theta=-0.3, sigma2=1)",
            "ARMA(2,1)(ar1=0.5, ar2=0.2, ma1=0.3, sigma2=1)",
            "SIN(amplitude=0.5, omega=0.013)",
            "MAF(8)(sigma2=1)",
            "FN(b2=0.3)",
        ] {
            let ps = processes(text, freq);
            let levels = 12;
            let wv = crate::process::LatentProcess::wv(&ps[0], levels);
            let counts: Vec<usize> = (0..levels).map(|j| 1usize << j).collect();
            let g = ErrorGrowth::of(&ps, &counts);
            for (j, (av, nu2)) in g.allan.iter().zip(&wv).enumerate() {
                let rel = (av - 2.0 * nu2).abs() / (2.0 * nu2).abs();
                assert!(
                    rel < 1e-8,
                    "{text} level {}: AV {av} vs 2 nu2 {}",
                    j + 1,
                    2.0 * nu2
                );
            }
        }
    }

    /// `E S_n^2` against the direct double sum of the autocovariance (stationary terms) and
    /// of the started weights (RW, FN).
    #[test]
    fn integrated_mean_square_matches_direct_sums() {
        let counts = [1usize, 2, 3, 7, 50, 333];
        let direct = |gamma: &dyn Fn(usize) -> f64, n: usize| -> f64 {
            (0..n)
                .flat_map(|i| (0..n).map(move |j| (i, j)))
                .map(|(i, j)| gamma(i.abs_diff(j)))
                .sum()
        };
        let check = |text: &str, gamma: &dyn Fn(usize) -> f64| {
            let g = ErrorGrowth::of(&processes(text, 10.0), &counts);
            for (k, &n) in counts.iter().enumerate() {
                let want = direct(gamma, n);
                let rel = (g.integrated[k] - want).abs() / want.abs().max(1e-300);
                assert!(rel < 1e-9, "{text} n = {n}: {} vs {want}", g.integrated[k]);
            }
        };
        check("WN(sigma2=2)", &|h| if h == 0 { 2.0 } else { 0.0 });
        check("AR1(phi=0.95, sigma2=1)", &|h| {
            0.95f64.powi(h as i32) / (1.0 - 0.95 * 0.95)
        });
        check("AR1(phi=-0.5, sigma2=1)", &|h| {
            (-0.5f64).powi(h as i32) / 0.75
        });
        check("SIN(amplitude=2, omega=0.1234)", &|h| {
            2.0 * (2.0 * std::f64::consts::PI * 0.1234 * h as f64).cos()
        });
        check("MAF(5)(sigma2=3)", &|h| {
            if h < 5 {
                3.0 * (5 - h) as f64 / 25.0
            } else {
                0.0
            }
        });
        let arma = crate::process::Arma::new(vec![0.5, 0.2], vec![0.3], 1.0).unwrap();
        let gamma = arma.autocovariance(400);
        check("ARMA(2,1)(ar1=0.5, ar2=0.2, ma1=0.3, sigma2=1)", &|h| {
            gamma[h]
        });
        // held terms: Var(sum_t (x_t - x_0)) = sum_{s,t} [V(s) + V(t) - V(|s - t|)]
        let held = |text: &str, variogram: &dyn Fn(usize) -> f64| {
            let g = ErrorGrowth::of(&processes(text, 10.0), &counts);
            assert!(g.held[0], "{text} is held");
            for (k, &n) in counts.iter().enumerate() {
                let want: f64 = (1..=n)
                    .flat_map(|i| (1..=n).map(move |j| (i, j)))
                    .map(|(i, j)| variogram(i) + variogram(j) - variogram(i.abs_diff(j)))
                    .sum();
                let rel = (g.integrated[k] - want).abs() / want;
                assert!(rel < 1e-9, "{text} n = {n}: {} vs {want}", g.integrated[k]);
            }
        };
        held("RW(gamma2=0.5)", &|h| 0.25 * h as f64);
        let odd = |h: usize| (1..=h).map(|k| 1.0 / (2 * k - 1) as f64).sum::<f64>();
        held("FN(b2=2)", &|h| 2.0 * 2.0 / std::f64::consts::PI * odd(h));
        // a correlation time of 1000 samples against a horizon of 333: held
        let r0 = 1.0 / (1.0 - 0.999f64 * 0.999);
        held("AR1(phi=0.999, sigma2=1)", &|h| {
            r0 * (1.0 - 0.999f64.powi(h as i32))
        });
    }
}
