//! The extra moments of the augmented GMWM (GMWM+, paper §IV-C; docs/methods.md §5.15): the
//! mean and the first autocovariances of the series' first differences, stacked after the
//! wavelet variance.
//!
//! Why the differences: an IMU series carries a bias (a constant the model does not describe)
//! and often a random walk, so neither its mean nor its autocovariances are moments of the
//! model. Its first differences `d_t = x_t - x_{t-1}` are stationary under every model the
//! closed forms cover, lose the bias, and keep what the model says:
//!
//! - `mean`: `E d_t = omega`, the slope of the DR terms (per sample). Only a model with a DR
//!   term has a mean to estimate.
//! - `acf:K`: `gamma_d(h) = Cov(d_t, d_{t+h})` for `h = 1..K` (lag 0 is `4 nu2_1`, already in
//!   the WV vector). With the variogram `V(h) = E(x_{t+h} - x_t)^2 / 2` of a term (for a
//!   stationary one `gamma(0) - gamma(h)`), `gamma_d(h) = V(h + 1) + V(h - 1) - 2 V(h)`, which
//!   every term of the model family has in closed form:
//!   - WN(`sigma2`): `-sigma2` at lag 1, 0 beyond; RW: 0 (`V` is linear); DR: 0 (its
//!     differences are its mean, removed by the centring);
//!   - QN(`q2`), `x_t = sqrt(q2) (u_{t+1} - u_t)`: `-4 q2` at lag 1, `q2` at lag 2, 0 beyond;
//!   - AR1/GM/MA1/ARMA11 (`gamma(0) = r0`, `gamma(m) = r1 phi^(m - 1)`), ARMA(p, q) (its §4.4
//!     autocovariances), MAF(L) (`sigma2 (L - k) / L^2`) and SIN (`(A^2 / 2) cos(2 pi omega h)`)
//!     through their autocovariances;
//!   - FN(`b2`), not stationary but with stationary increments: `V(h) = (2 b2 / pi) H(h)`,
//!     `H(h) = sum_{k <= h} 1 / (2k - 1)` (`crate::process::flicker`).
//!
//! The sample moments are `d_bar = (x_{N-1} - x_0) / (N - 1)` and
//! `gamma_d_hat(h) = (1 / (N - 1 - h)) sum_t (d_t - d_bar)(d_{t+h} - d_bar)`; their bias from
//! the centring is of order `1/N` (the differences' spectrum vanishes at 0 except for a RW,
//! whose `-gamma2 / N` is below the estimate's standard error by `sqrt(N)`).
//!
//! The Jacobian of the implied moments is taken by central differences in `theta` (relative step
//! `1e-6`, one-sided at a domain edge): the moments are closed forms, so the error (about 1e-10
//! relative) is far below what the optimiser and the sandwich need.

use crate::error::{InputError, ParamError};
use crate::model::Model;
use crate::process::flicker::odd_harmonic;
use crate::process::{CovariancePart, Process};
use std::fmt;
use std::str::FromStr;

/// Largest autocovariance lag `acf:K` accepts: the differences' autocovariances of the
/// covered processes beyond a few lags carry only the AR terms' geometric tails.
pub(crate) const MAX_AUGMENT_LAGS: usize = 16;

/// Which extra moments GMWM+ stacks after the WV (`--augment mean,acf:3`; module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct Augment {
    /// The mean of the first differences (the DR slope).
    pub mean: bool,
    /// Autocovariances of the first differences at lags `1..=acf_lags`.
    pub acf_lags: usize,
}

impl Augment {
    /// No extra moment: the augmented pipeline then is the two-step GMWM with the full
    /// bootstrap `V` of the WV alone (the comparison that isolates the extra moments' gain).
    pub fn none() -> Self {
        Self::default()
    }

    /// Number of extra moments.
    pub fn len(&self) -> usize {
        usize::from(self.mean) + self.acf_lags
    }

    /// Whether no extra moment is asked for.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The extra moments' names, in stacking order: `mean_diff`, `acf_diff[1]`, ...
    pub fn names(&self) -> Vec<String> {
        let mut out = Vec::with_capacity(self.len());
        if self.mean {
            out.push("mean_diff".to_string());
        }
        out.extend((1..=self.acf_lags).map(|h| format!("acf_diff[{h}]")));
        out
    }

    /// The sample moments of `x` (module docs).
    ///
    /// # Errors
    /// [`ParamError`] when `x` has fewer than `acf_lags + 3` samples.
    pub fn sample(&self, x: &[f64]) -> Result<Vec<f64>, InputError> {
        let n = x.len();
        if n < self.acf_lags + 3 {
            return Err(ParamError::new(
                "augment",
                self.to_string(),
                format!(
                    "a series of at least {} samples (it has {n})",
                    self.acf_lags + 3
                ),
            )
            .into());
        }
        let nd = n - 1;
        let mean = (x[n - 1] - x[0]) / nd as f64;
        let mut out = Vec::with_capacity(self.len());
        if self.mean {
            out.push(mean);
        }
        if self.acf_lags > 0 {
            let d: Vec<f64> = x.windows(2).map(|w| w[1] - w[0] - mean).collect();
            for h in 1..=self.acf_lags {
                let s: f64 = d.iter().zip(&d[h..]).map(|(a, b)| a * b).sum();
                out.push(s / (nd - h) as f64);
            }
        }
        Ok(out)
    }

    /// Checks that `model` has what the moments need: a DR term for `mean`.
    ///
    /// # Errors
    /// [`ParamError`] naming the missing DR.
    pub fn check_model(&self, model: &Model) -> Result<(), InputError> {
        use crate::process::ProcessKind as K;
        let kinds = model.kinds();
        if self.mean && !kinds.contains(&K::Dr) {
            return Err(ParamError::new(
                "augment",
                self.to_string(),
                format!(
                    "a model with a mean: `mean` estimates the slope of a DR() term and {model} \
                     has none (drop `mean`, or add DR())"
                ),
            )
            .into());
        }
        Ok(())
    }

    /// The implied moments of `model` at `theta` (model order) into `out` (length
    /// [`Augment::len`]).
    pub(crate) fn implied(
        &self,
        model: &Model,
        theta: &[f64],
        freq_hz: f64,
        out: &mut [f64],
    ) -> Result<(), InputError> {
        out.fill(0.0);
        let mut failed: Option<ParamError> = None;
        let lags = self.acf_lags;
        let at = usize::from(self.mean);
        model.for_each_process(theta, freq_hz, |p, _| {
            if let Process::Dr(_) = p {
                if let (true, Ok(CovariancePart::Drift(omega))) = (self.mean, p.covariance_part()) {
                    out[0] += omega;
                }
                return;
            }
            if lags == 0 {
                return;
            }
            match variogram(p, lags + 1) {
                Ok(v) => {
                    for h in 1..=lags {
                        out[at + h - 1] += v[h + 1] + v[h - 1] - 2.0 * v[h];
                    }
                }
                Err(e) => {
                    failed.get_or_insert(e);
                }
            }
        })?;
        match failed {
            Some(e) => Err(e.into()),
            None => Ok(()),
        }
    }

    /// The implied moments and their Jacobian (row-major `len x p`, `d m / d theta`) by
    /// central differences (module docs).
    pub(crate) fn implied_with_jacobian(
        &self,
        model: &Model,
        theta: &[f64],
        freq_hz: f64,
        out: &mut [f64],
        jac: &mut [f64],
    ) -> Result<(), InputError> {
        self.implied(model, theta, freq_hz, out)?;
        let (m, p) = (self.len(), theta.len());
        let mut t = theta.to_vec();
        let (mut up, mut down) = (vec![0.0; m], vec![0.0; m]);
        for k in 0..p {
            let step = 1e-6 * theta[k].abs().max(f64::MIN_POSITIVE);
            t[k] = theta[k] + step;
            let ok_up = self.implied(model, &t, freq_hz, &mut up).is_ok();
            t[k] = theta[k] - step;
            let ok_down = self.implied(model, &t, freq_hz, &mut down).is_ok();
            t[k] = theta[k];
            for i in 0..m {
                jac[i * p + k] = match (ok_up, ok_down) {
                    (true, true) => (up[i] - down[i]) / (2.0 * step),
                    (true, false) => (up[i] - out[i]) / step,
                    (false, true) => (out[i] - down[i]) / step,
                    (false, false) => 0.0,
                };
            }
        }
        Ok(())
    }
}

/// The variogram `V(h) = E(x_{t+h} - x_t)^2 / 2` of one term at `h = 0..=lags` (module
/// docs: `gamma_d(h) = V(h + 1) + V(h - 1) - 2 V(h)`); `V(h) = gamma(0) - gamma(h)` for a
/// stationary term. Not for DR (deterministic: its differences are its mean).
fn variogram(p: &Process, lags: usize) -> Result<Vec<f64>, ParamError> {
    let from_gamma = |g: &dyn Fn(usize) -> f64| (0..=lags).map(|h| g(0) - g(h)).collect();
    Ok(match p {
        Process::Flicker(f) => (0..=lags)
            .map(|h| 2.0 * f.b2() / std::f64::consts::PI * odd_harmonic(h as f64))
            .collect(),
        Process::Sin(s) => {
            let g = s.autocovariance(lags + 1);
            from_gamma(&|h| g[h])
        }
        Process::Maf(m) => from_gamma(&|h| m.sigma2() * m.unit_autocovariance(h)),
        Process::Arma(a) => {
            let g = a.autocovariance(lags);
            from_gamma(&|h| g[h])
        }
        _ => match p.covariance_part()? {
            CovariancePart::White(sigma2) => from_gamma(&|h| if h == 0 { sigma2 } else { 0.0 }),
            CovariancePart::RandomWalk(gamma2) => {
                (0..=lags).map(|h| gamma2 * h as f64 / 2.0).collect()
            }
            // x_t = sqrt(q2) (u_{t+1} - u_t): gamma(0) = 2 q2, gamma(1) = -q2
            CovariancePart::Quantization(q2) => from_gamma(&|h| match h {
                0 => 2.0 * q2,
                1 => -q2,
                _ => 0.0,
            }),
            CovariancePart::Autoregressive { phi, r0, r1 } => from_gamma(&|h| {
                if h == 0 {
                    r0
                } else {
                    r1 * phi.powi(h as i32 - 1)
                }
            }),
            CovariancePart::Drift(_) => vec![0.0; lags + 1],
        },
    })
}

impl fmt::Display for Augment {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = Vec::new();
        if self.mean {
            parts.push("mean".to_string());
        }
        if self.acf_lags > 0 {
            parts.push(format!("acf:{}", self.acf_lags));
        }
        if parts.is_empty() {
            return f.write_str("none");
        }
        f.write_str(&parts.join(","))
    }
}

impl FromStr for Augment {
    type Err = ParamError;

    /// `mean`, `acf:K` (`1 <= K <= 16`) or both, comma-separated.
    fn from_str(s: &str) -> Result<Self, ParamError> {
        let expected = "mean, acf:K (K from 1 to 16) or both, comma-separated, e.g. mean,acf:3";
        let mut out = Augment::default();
        for token in s.split(',').map(str::trim) {
            if token == "mean" && !out.mean {
                out.mean = true;
            } else if let Some(k) = token.strip_prefix("acf:") {
                match k.parse::<usize>() {
                    Ok(k) if (1..=MAX_AUGMENT_LAGS).contains(&k) && out.acf_lags == 0 => {
                        out.acf_lags = k
                    }
                    _ => return Err(ParamError::new("augment", token, expected)),
                }
            } else {
                return Err(ParamError::new("augment", token, expected));
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::simulate_model;

    fn theta_of(m: &Model) -> Vec<f64> {
        m.values().into_iter().map(Option::unwrap).collect()
    }

    #[test]
    fn parses_and_prints() {
        let a: Augment = "mean,acf:3".parse().unwrap();
        assert_eq!(
            a,
            Augment {
                mean: true,
                acf_lags: 3
            }
        );
        assert_eq!(a.to_string(), "mean,acf:3");
        assert_eq!(
            a.names(),
            ["mean_diff", "acf_diff[1]", "acf_diff[2]", "acf_diff[3]"]
        );
        for bad in [
            "",
            "acf",
            "acf:0",
            "acf:17",
            "mean,mean",
            "acf:2,acf:3",
            "var",
        ] {
            let e = bad.parse::<Augment>().unwrap_err().to_string();
            assert!(e.contains("augment"), "{bad}: {e}");
        }
    }

    #[test]
    fn implied_matches_closed_forms() {
        // WN(2) + QN(0.5) + AR1(phi=0.6, sigma2=1) + RW + DR(0.01)
        let m = Model::parse(
            "WN(sigma2=2)+QN(q2=0.5)+AR1(phi=0.6, sigma2=1)+RW(gamma2=0.1)+DR(omega=0.01)",
        )
        .unwrap();
        let a = Augment {
            mean: true,
            acf_lags: 3,
        };
        let mut out = vec![0.0; 4];
        a.implied(&m, &theta_of(&m), 1.0, &mut out).unwrap();
        let r0 = 1.0 / (1.0 - 0.36);
        let g = |h: i32| r0 * 0.6f64.powi(h);
        let ar = |h: i32| 2.0 * g(h) - g(h - 1) - g(h + 1);
        let expect = [0.01, -2.0 - 2.0 + ar(1), 0.5 + ar(2), ar(3)];
        for (o, e) in out.iter().zip(expect) {
            assert!((o - e).abs() < 1e-14, "{out:?} vs {expect:?}");
        }
    }

    #[test]
    fn sample_moments_estimate_the_implied_ones() {
        // 2^18 samples: the sample autocovariances have SE about r0 sqrt(6 / N) ~ 0.02 here
        let m = Model::parse("WN(sigma2=1)+AR1(phi=0.8, sigma2=0.5)+QN(q2=0.2)+DR(omega=0.003)")
            .unwrap();
        let x = simulate_model(&m, 1 << 18, 1.0, 5).unwrap();
        let a = Augment {
            mean: true,
            acf_lags: 3,
        };
        let s = a.sample(&x).unwrap();
        let mut imp = vec![0.0; 4];
        a.implied(&m, &theta_of(&m), 1.0, &mut imp).unwrap();
        assert!((s[0] - imp[0]).abs() < 1e-4, "{s:?} vs {imp:?}");
        for h in 1..4 {
            assert!((s[h] - imp[h]).abs() < 0.03, "{s:?} vs {imp:?}");
        }
    }

    #[test]
    fn sensor_terms_match_their_simulated_moments() {
        // FN, SIN and MAF, the terms calibrate identifies on real sensors: 2^18 samples, the
        // sample autocovariances of the differences within 4 SE (SE about
        // sqrt(sum_h gamma_d(h)^2 / N) <= 0.01 here)
        let a = Augment {
            mean: false,
            acf_lags: 3,
        };
        for (k, text) in [
            "FN(b2=1)+WN(sigma2=0.5)",
            "SIN(amplitude=1, omega=0.07)+WN(sigma2=0.5)",
            "MAF(4)(sigma2=2)",
        ]
        .iter()
        .enumerate()
        {
            let m = Model::parse(text).unwrap();
            let x = simulate_model(&m, 1 << 18, 1.0, 40 + k as u64).unwrap();
            let s = a.sample(&x).unwrap();
            let mut imp = vec![0.0; 3];
            a.implied(&m, &theta_of(&m), 1.0, &mut imp).unwrap();
            for h in 0..3 {
                assert!((s[h] - imp[h]).abs() < 0.02, "{text}: {s:?} vs {imp:?}");
            }
        }
    }

    #[test]
    fn jacobian_matches_a_hand_derivative() {
        let m = Model::parse("WN(sigma2=2)+AR1(phi=0.5, sigma2=1)").unwrap();
        let a = Augment {
            mean: false,
            acf_lags: 2,
        };
        let theta = theta_of(&m);
        let (mut out, mut jac) = (vec![0.0; 2], vec![0.0; 2 * 3]);
        a.implied_with_jacobian(&m, &theta, 1.0, &mut out, &mut jac)
            .unwrap();
        // lag 1: -sigma2_wn + (2 phi - 1 - phi^2) sigma2 / (1 - phi^2)
        assert!((jac[0] + 1.0).abs() < 1e-8);
        let d_sigma2 = (2.0 * 0.5 - 1.0 - 0.25) / 0.75;
        assert!((jac[2] - d_sigma2).abs() < 1e-8, "{jac:?}");
    }

    #[test]
    fn refuses_what_it_cannot_describe() {
        let a = Augment {
            mean: true,
            acf_lags: 1,
        };
        let e = a
            .check_model(&Model::parse("WN()+RW()").unwrap())
            .unwrap_err()
            .to_string();
        assert!(e.contains("DR()"), "{e}");
        assert!(a.sample(&[1.0, 2.0, 3.0]).is_err());
    }
}
