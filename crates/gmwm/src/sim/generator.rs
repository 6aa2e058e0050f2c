//! Streaming, seeded simulation of a sum of independent processes (METHODS §10.1–§10.2).
//!
//! A [`Simulator`] holds one small state per component (the last `p` values and `q`
//! innovations of an ARMA, the last uniform of QN, the level of RW, the time of DR) and one
//! ChaCha8 stream per component, derived from `(seed, component index)`. Because no stream is
//! shared, the output depends only on the seed and the sample index: splitting `n` samples
//! across any number of [`Simulator::fill`] calls gives the same bits, and so does drawing the
//! components separately with [`Simulator::fill_components`] and adding them in model order.
//!
//! The parameters are plain per-sample values (GM already converted to AR1 with `freq`,
//! METHODS §4.3). Random streams cannot match R's Mersenne Twister, so only the laws match the
//! package (METHODS §12).

use crate::error::ParamError;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

/// `sqrt(12)`: scales `U(0, 1)` to variance 1 for quantisation noise (METHODS §10.1).
const SQRT_12: f64 = 3.464_101_615_137_754_6;

/// Relative size of the AR transient left after the burn-in of a stationary-mode ARMA(p, q):
/// below the 53-bit resolution of most downstream sums, so the start is stationary for every
/// practical purpose (METHODS §10.1 port).
const STATIONARY_BURN_IN_TOL: f64 = 1e-12;

/// R's `arima.sim` burn-in constant: `n0 = p + q + ceil(6 / ln(min root modulus))`, a transient
/// of `e^-6 ≈ 2.5e-3` relative (METHODS §10.1).
const R_BURN_IN_LOG: f64 = 6.0;

/// Longest burn-in a generic ARMA may need (AR root moduli down to about `1 + 2.8e-7`);
/// beyond it, starting would take seconds to minutes and the model is numerically a unit root.
const MAX_BURN_IN: usize = 100_000_000;

/// One component of a simulated sum, with plain per-sample parameters (METHODS §0.2, §10.1).
///
/// The variants carry the METHODS parameter names; the caller converts GM to AR1 first
/// (METHODS §4.3). [`Simulator::new`] checks what it needs to run (finite values, variances
/// `>= 0`, stationary AR parts).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Generator {
    /// METHODS §10.1 white noise: `x_t ~ N(0, sigma2)` i.i.d.
    Wn {
        /// Variance.
        sigma2: f64,
    },
    /// METHODS §10.1 quantisation noise: `x_t = sqrt(q2) (u_{t+1} - u_t)`,
    /// `u ~ sqrt(12) U(0, 1)` (see [`quantisation_noise`]).
    Qn {
        /// Quantisation parameter `Q^2` (variance of `x_t` is `2 q2`).
        q2: f64,
    },
    /// METHODS §10.1 random walk: `x_t = sum_{i=0}^{t} w_i`, `w ~ N(0, gamma2)` (the first
    /// value is `w_0`, not 0).
    Rw {
        /// Increment variance.
        gamma2: f64,
    },
    /// METHODS §10.1 deterministic drift: `x_t = omega (t + 1)`, t = 0, 1, ... across calls.
    Dr {
        /// Slope per sample.
        omega: f64,
    },
    /// METHODS §10.1 first-order autoregression: `x_t = phi x_{t-1} + w_t`,
    /// `w ~ N(0, sigma2)`; start per [`StartMode`].
    Ar1 {
        /// Autoregressive coefficient, `|phi| < 1`.
        phi: f64,
        /// Innovation variance.
        sigma2: f64,
    },
    /// METHODS §10.1 first-order moving average: `x_t = w_t + theta w_{t-1}`, stationary in
    /// both start modes (one extra innovation).
    Ma1 {
        /// Moving-average coefficient.
        theta: f64,
        /// Innovation variance.
        sigma2: f64,
    },
    /// METHODS §10.1 ARMA(1, 1): `x_t = phi x_{t-1} + w_t + theta w_{t-1}`; start per
    /// [`StartMode`].
    Arma11 {
        /// Autoregressive coefficient, `|phi| < 1`.
        phi: f64,
        /// Moving-average coefficient.
        theta: f64,
        /// Innovation variance.
        sigma2: f64,
    },
    /// METHODS §10.1 ARMA(p, q) in R's sign convention (§0.2); start per [`StartMode`]:
    /// `x_t = sum_i ar_i x_{t-i} + w_t + sum_k ma_k w_{t-k}`.
    Arma {
        /// `ar_1..ar_p`; the AR polynomial `1 - sum ar_i B^i` must have all roots outside the
        /// unit circle.
        ar: Vec<f64>,
        /// `ma_1..ma_q` (no invertibility needed to simulate).
        ma: Vec<f64>,
        /// Innovation variance.
        sigma2: f64,
    },
}

/// How the autoregressive components (AR1, ARMA11, ARMA) start.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum StartMode {
    /// Default of the port (METHODS §10.1): every sample follows the stationary law. AR1 and
    /// ARMA11 draw their initial state exactly from it; a generic ARMA(p, q) runs a burn-in of
    /// `p + q + ceil(ln(1e-12) / ln(rho))` samples, `rho` the largest modulus of the inverse
    /// AR roots, so the leftover transient is below `1e-12` relative.
    #[default]
    Stationary,
    /// The package (METHODS §10.1, §13.21): AR1 and ARMA11 start at `x = 0` (the first kept
    /// value is `w_1`, resp. `w_1 + theta w_0`); a generic ARMA follows R's `arima.sim`
    /// (first `q` MA outputs set to 0, AR recursion from zeros, burn-in
    /// `p + q + ceil(6 / ln(min root modulus))`). The burn-in innovations come first in the
    /// component's stream (R draws them after the kept ones); the law is the same.
    Zero,
}

/// A streaming simulator of a sum of independent [`Generator`]s (METHODS §10.2, `gen_model`).
///
/// Same seed, same bits, whatever the chunking of [`fill`](Self::fill) calls. `Send + Sync +
/// Clone`; a clone continues the same streams.
#[derive(Debug, Clone)]
pub struct Simulator {
    generators: Vec<Generator>,
    seed: u64,
    start: StartMode,
    components: Vec<Component>,
}

impl Simulator {
    /// Validates the generators and prepares one stream per component, in
    /// [`StartMode::Stationary`].
    ///
    /// Cost: O(p^3) root finding per generic ARMA plus its burn-in (O(n0 (p + q))); O(1)
    /// otherwise.
    ///
    /// # Errors
    /// [`ParamError`] for an empty list, a non-finite parameter, a negative variance,
    /// `|phi| >= 1`, an AR polynomial with a root of modulus `<= 1`, or a generic ARMA whose
    /// burn-in would exceed 10^8 samples (AR root too close to the unit circle).
    pub fn new(generators: Vec<Generator>, seed: u64) -> Result<Self, ParamError> {
        if generators.is_empty() {
            return Err(ParamError::new(
                "generators",
                "[]",
                "at least one process to simulate",
            ));
        }
        for g in &generators {
            validate(g)?;
        }
        let start = StartMode::default();
        let components = build(&generators, seed, start)?;
        Ok(Self {
            generators,
            seed,
            start,
            components,
        })
    }

    /// Chooses how AR parts start (METHODS §10.1, §13.21) and restarts the simulation from its
    /// first sample (same seed). Cost: the burn-ins of generic ARMA components again.
    pub fn with_start(mut self, mode: StartMode) -> Self {
        self.start = mode;
        // Validation and burn-in lengths do not depend on the mode beyond what `new` checked:
        // the R burn-in is shorter than the stationary one, so it cannot fail where that
        // succeeded.
        if let Ok(components) = build(&self.generators, self.seed, mode) {
            self.components = components;
        }
        self
    }

    /// The generators, in model order.
    pub fn generators(&self) -> &[Generator] {
        &self.generators
    }

    /// The start mode in use.
    pub fn start(&self) -> StartMode {
        self.start
    }

    /// Writes the next `out.len()` samples of the sum of the components, added in model order.
    ///
    /// Cost: O(len (1 + p + q)) per call, no allocation.
    pub fn fill(&mut self, out: &mut [f64]) {
        // Blocks keep the running sum in cache while every component adds to it; the bits do
        // not depend on the block size (each component's stream is its own).
        for block in out.chunks_mut(FILL_BLOCK) {
            block.fill(0.0);
            for c in &mut self.components {
                c.run(block, |o, v| *o += v);
            }
        }
    }

    /// Writes the next samples of each component separately (METHODS §10.2, `gen_lts`):
    /// `out[k]` receives the next `out[k].len()` values of component `k`. Adding the columns
    /// in model order reproduces [`fill`](Self::fill) bit for bit.
    ///
    /// # Errors
    /// [`ParamError`] when `out` has not one column per component or the columns differ in
    /// length (nothing is drawn then).
    pub fn fill_components(&mut self, out: &mut [Vec<f64>]) -> Result<(), ParamError> {
        if out.len() != self.components.len() {
            return Err(ParamError::new(
                "columns",
                out.len(),
                format!("one column per component ({})", self.components.len()),
            ));
        }
        let len = out.first().map_or(0, Vec::len);
        if let Some(bad) = out.iter().find(|c| c.len() != len) {
            return Err(ParamError::new(
                "column length",
                bad.len(),
                format!("every column as long as the first ({len})"),
            ));
        }
        for (c, col) in self.components.iter_mut().zip(out.iter_mut()) {
            c.run(col, |o, v| *o = v);
        }
        Ok(())
    }
}

/// Simulates `n` samples of the sum of `generators` from the stationary start (METHODS §10.2).
///
/// # Errors
/// As [`Simulator::new`], and for `n == 0`.
///
/// # Examples
/// ```
/// use gmwm::sim::{simulate, Generator};
/// let x = simulate(&[Generator::Dr { omega: 2.0 }], 4, 1).unwrap();
/// assert_eq!(x, vec![2.0, 4.0, 6.0, 8.0]); // METHODS §10.3 test value
/// ```
pub fn simulate(generators: &[Generator], n: usize, seed: u64) -> Result<Vec<f64>, ParamError> {
    if n == 0 {
        return Err(ParamError::new("n", n, "must be at least 1"));
    }
    let mut sim = Simulator::new(generators.to_vec(), seed)?;
    let mut x = vec![0.0; n];
    sim.fill(&mut x);
    Ok(x)
}

/// Seed of bootstrap replicate `replicate` under the master `seed`, so results do not depend
/// on thread count or scheduling (STYLE §4). Distinct replicates of one seed get distinct
/// seeds (the map is a bijection in `replicate`).
///
/// # Formula
/// SplitMix64 finaliser of `splitmix64(seed) XOR (replicate * 0x9E3779B97F4A7C15)`.
pub fn replicate_seed(seed: u64, replicate: u64) -> u64 {
    splitmix64(splitmix64(seed) ^ replicate.wrapping_mul(0x9E37_79B9_7F4A_7C15))
}

/// METHODS §10.1 (QN): `x_t = sqrt(q2) (u_{t+1} - u_t)` for given `u_0..u_N` (`N + 1`
/// values give `N` samples; fewer than two give none). The deterministic path of the QN
/// simulator, exposed for the hand test values of METHODS §10.3.
///
/// # Examples
/// ```
/// let s12 = 12f64.sqrt();
/// let x = gmwm::sim::quantisation_noise(1.0, &[0.0, s12, 0.0]);
/// assert!((x[0] - 3.4641016).abs() < 1e-7 && (x[1] + 3.4641016).abs() < 1e-7);
/// ```
pub fn quantisation_noise(q2: f64, u: &[f64]) -> Vec<f64> {
    let s = q2.sqrt();
    u.windows(2).map(|w| qn_value(s, w[0], w[1])).collect()
}

/// Whether the AR polynomial `1 - sum ar_i B^i` has every root outside the unit circle,
/// by the Schur–Cohn (step-down Levinson) test: every reflection coefficient `|k| < 1`
/// (METHODS §10.1, §12). Exact up to rounding; an empty `ar` is stationary.
///
/// # Formula
/// `k_p = ar_p`; `ar'_i = (ar_i + k_p ar_{p-i}) / (1 - k_p^2)`, i = 1..p-1; repeat on `ar'`.
pub fn ar_is_stationary(ar: &[f64]) -> bool {
    if ar.iter().any(|a| !a.is_finite()) {
        return false;
    }
    let mut a = ar.to_vec();
    while let Some(&k) = a.last() {
        if k.abs() >= 1.0 {
            return false;
        }
        let p = a.len();
        let d = 1.0 - k * k;
        let next: Vec<f64> = (0..p - 1).map(|i| (a[i] + k * a[p - 2 - i]) / d).collect();
        a = next;
    }
    true
}

// ------------------------------------------------------------------------------------------
// Internals

/// SplitMix64 output function (Steele, Lea & Flood 2014).
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// One QN value from consecutive uniforms (METHODS §10.1).
#[inline]
fn qn_value(sqrt_q2: f64, u_t: f64, u_next: f64) -> f64 {
    sqrt_q2 * (u_next - u_t)
}

#[cold]
fn bad(name: &'static str, value: f64, expected: &str) -> ParamError {
    ParamError::new(name, value, expected)
}

/// A variance of a simulated process: the same domain as the process's own (finite and > 0,
/// [`crate::process`]), so that anything the simulator accepts is a model the estimators
/// accept too; a zero-variance component is no process (leave it out of the model).
fn check_variance(name: &'static str, v: f64) -> Result<(), ParamError> {
    crate::process::check_positive(name, v)
}

fn check_finite(name: &'static str, v: f64) -> Result<(), ParamError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(bad(name, v, "must be a finite number"))
    }
}

fn check_phi(v: f64) -> Result<(), ParamError> {
    if v.is_finite() && v.abs() < 1.0 {
        Ok(())
    } else {
        Err(bad("phi", v, "must satisfy |phi| < 1 (stationary)"))
    }
}

fn validate(g: &Generator) -> Result<(), ParamError> {
    match g {
        Generator::Wn { sigma2 } => check_variance("sigma2", *sigma2),
        Generator::Qn { q2 } => check_variance("q2", *q2),
        Generator::Rw { gamma2 } => check_variance("gamma2", *gamma2),
        Generator::Dr { omega } => check_finite("omega", *omega),
        Generator::Ar1 { phi, sigma2 } => {
            check_phi(*phi)?;
            check_variance("sigma2", *sigma2)
        }
        Generator::Ma1 { theta, sigma2 } => {
            check_finite("theta", *theta)?;
            check_variance("sigma2", *sigma2)
        }
        Generator::Arma11 { phi, theta, sigma2 } => {
            check_phi(*phi)?;
            check_finite("theta", *theta)?;
            check_variance("sigma2", *sigma2)
        }
        Generator::Arma { ar, ma, sigma2 } => {
            for &a in ar {
                check_finite("ar", a)?;
            }
            for &m in ma {
                check_finite("ma", m)?;
            }
            check_variance("sigma2", *sigma2)?;
            if !ar_is_stationary(ar) {
                return Err(ParamError::new(
                    "ar",
                    format!("{ar:?}"),
                    "an AR polynomial 1 - sum ar_i B^i with every root outside the unit circle",
                ));
            }
            Ok(())
        }
    }
}

/// Largest modulus `rho` of the inverse roots of the AR polynomial `1 - sum ar_i B^i` (the
/// roots of `lambda^p - ar_1 lambda^{p-1} - ... - ar_p`), by bisection on `r` with the
/// Schur–Cohn test: the coefficients `ar_i / r^i` are stationary iff `r > rho`. Robust to
/// repeated and complex roots; returns an upper bracket (a conservative burn-in), to about
/// 1e-15 for simple roots and 1e-6 for a double root. Used only to size burn-ins.
fn inverse_root_radius(ar: &[f64]) -> f64 {
    let m = ar.iter().rposition(|&a| a != 0.0).map_or(0, |i| i + 1);
    let a = &ar[..m];
    match m {
        0 => return 0.0,
        1 => return a[0].abs(),
        _ => {}
    }
    // Cauchy bound: every inverse root has modulus < 1 + max |ar_i|.
    let mut hi = 1.0 + a.iter().fold(0.0f64, |b, x| b.max(x.abs()));
    let mut lo = 0.0f64;
    let mut scaled = vec![0.0; m];
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        let mut rk = 1.0;
        for (s, &ai) in scaled.iter_mut().zip(a) {
            rk *= mid;
            *s = ai / rk;
        }
        if ar_is_stationary(&scaled) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// Burn-in length of a generic ARMA in each start mode (METHODS §10.1).
fn arma_burn_in(ar: &[f64], q: usize, mode: StartMode) -> Result<usize, ParamError> {
    let p = ar.len();
    let rho = inverse_root_radius(ar);
    let log_len = match mode {
        StartMode::Stationary => -STATIONARY_BURN_IN_TOL.ln(),
        StartMode::Zero => R_BURN_IN_LOG,
    };
    let extra = if p == 0 || rho == 0.0 {
        0.0
    } else {
        // ln(min root modulus) = -ln(rho).
        (log_len / -rho.ln()).ceil()
    };
    if !(extra.is_finite() && extra >= 0.0 && extra <= MAX_BURN_IN as f64) {
        return Err(ParamError::new(
            "ar",
            format!("{ar:?}"),
            format!(
                "AR roots far enough from the unit circle for a burn-in of at most \
                 {MAX_BURN_IN} samples (largest inverse root modulus {rho})"
            ),
        ));
    }
    Ok(p + q + extra as usize)
}

/// Samples per cache block of [`Simulator::fill`] (32 KiB of `f64`, an L1 data cache).
const FILL_BLOCK: usize = 4096;

/// The running state of one component.
#[derive(Debug, Clone)]
enum Component {
    Wn {
        rng: ChaCha8Rng,
        sd: f64,
    },
    Qn {
        rng: ChaCha8Rng,
        sqrt_q2: f64,
        u: f64,
    },
    Rw {
        rng: ChaCha8Rng,
        sd: f64,
        level: f64,
    },
    Dr {
        omega: f64,
        t: u64,
    },
    Ar1 {
        rng: ChaCha8Rng,
        phi: f64,
        sd: f64,
        x: f64,
    },
    Ma1 {
        rng: ChaCha8Rng,
        theta: f64,
        sd: f64,
        w: f64,
    },
    Arma11 {
        rng: ChaCha8Rng,
        phi: f64,
        theta: f64,
        sd: f64,
        x: f64,
        w: f64,
    },
    Arma(Box<ArmaState>),
}

/// Generic ARMA(p, q) state: `xs[i] = x_{t-1-i}`, `es[k] = e_{t-1-k}`.
#[derive(Debug, Clone)]
struct ArmaState {
    rng: ChaCha8Rng,
    ar: Vec<f64>,
    ma: Vec<f64>,
    sd: f64,
    xs: Vec<f64>,
    es: Vec<f64>,
    /// MA outputs still to be set to 0 (R's `x[seq_along(ma)] <- 0`).
    ma_zeros: usize,
}

impl ArmaState {
    /// METHODS §10.1 (ARMA(p, q), R's `arima.sim`): `y_t = e_t + sum_k ma_k e_{t-k}` (0 for
    /// the first q), `x_t = y_t + sum_i ar_i x_{t-i}`.
    #[inline]
    fn step(&mut self) -> f64 {
        let e = self.sd * normal(&mut self.rng);
        let y = if self.ma_zeros > 0 {
            self.ma_zeros -= 1;
            0.0
        } else {
            e + self
                .ma
                .iter()
                .zip(&self.es)
                .map(|(m, w)| m * w)
                .sum::<f64>()
        };
        let x = y + self
            .ar
            .iter()
            .zip(&self.xs)
            .map(|(a, v)| a * v)
            .sum::<f64>();
        if !self.es.is_empty() {
            self.es.rotate_right(1);
            self.es[0] = e;
        }
        if !self.xs.is_empty() {
            self.xs.rotate_right(1);
            self.xs[0] = x;
        }
        x
    }
}

#[inline]
fn normal(rng: &mut ChaCha8Rng) -> f64 {
    rng.sample(StandardNormal)
}

/// The stream of component `index`: ChaCha8 keyed by the seed, stream number = index.
fn stream(seed: u64, index: usize) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index as u64);
    rng
}

fn build(gens: &[Generator], seed: u64, mode: StartMode) -> Result<Vec<Component>, ParamError> {
    gens.iter()
        .enumerate()
        .map(|(i, g)| component(g, stream(seed, i), mode))
        .collect()
}

/// Initial state of one component (METHODS §10.1). Initial draws come first in its stream.
fn component(g: &Generator, mut rng: ChaCha8Rng, mode: StartMode) -> Result<Component, ParamError> {
    let stationary = mode == StartMode::Stationary;
    Ok(match g {
        Generator::Wn { sigma2 } => Component::Wn {
            rng,
            sd: sigma2.sqrt(),
        },
        Generator::Qn { q2 } => {
            let u = SQRT_12 * rng.random::<f64>();
            Component::Qn {
                rng,
                sqrt_q2: q2.sqrt(),
                u,
            }
        }
        Generator::Rw { gamma2 } => Component::Rw {
            rng,
            sd: gamma2.sqrt(),
            level: 0.0,
        },
        Generator::Dr { omega } => Component::Dr {
            omega: *omega,
            t: 0,
        },
        Generator::Ar1 { phi, sigma2 } => {
            // Stationary: x_{-1} ~ N(0, sigma2 / (1 - phi^2)), so every kept value is
            // stationary; Zero: x_{-1} = 0 (the package's x_0 = 0, dropped).
            let x = if stationary {
                (sigma2 / (1.0 - phi * phi)).sqrt() * normal(&mut rng)
            } else {
                0.0
            };
            Component::Ar1 {
                rng,
                phi: *phi,
                sd: sigma2.sqrt(),
                x,
            }
        }
        Generator::Ma1 { theta, sigma2 } => {
            let sd = sigma2.sqrt();
            let w = sd * normal(&mut rng);
            Component::Ma1 {
                rng,
                theta: *theta,
                sd,
                w,
            }
        }
        Generator::Arma11 { phi, theta, sigma2 } => {
            let sd = sigma2.sqrt();
            let w = sd * normal(&mut rng);
            // Stationary joint law of (x_{-1}, w_{-1}): Cov = sigma2, Var x = gamma_0, so
            // x_{-1} = w_{-1} + N(0, gamma_0 - sigma2), gamma_0 - sigma2 =
            // sigma2 (phi + theta)^2 / (1 - phi^2).
            let x = if stationary {
                w + (sigma2 / (1.0 - phi * phi)).sqrt() * (phi + theta).abs() * normal(&mut rng)
            } else {
                0.0
            };
            Component::Arma11 {
                rng,
                phi: *phi,
                theta: *theta,
                sd,
                x,
                w,
            }
        }
        Generator::Arma { ar, ma, sigma2 } => {
            let n0 = arma_burn_in(ar, ma.len(), mode)?;
            let mut s = ArmaState {
                rng,
                ar: ar.clone(),
                ma: ma.clone(),
                sd: sigma2.sqrt(),
                xs: vec![0.0; ar.len()],
                es: vec![0.0; ma.len()],
                ma_zeros: ma.len(),
            };
            for _ in 0..n0 {
                s.step();
            }
            Component::Arma(Box::new(s))
        }
    })
}

impl Component {
    /// Combines the next `out.len()` values into `out` with `f` (add or store).
    #[inline]
    fn run(&mut self, out: &mut [f64], f: impl Fn(&mut f64, f64)) {
        match self {
            Component::Wn { rng, sd } => {
                for o in out.iter_mut() {
                    f(o, *sd * normal(rng));
                }
            }
            Component::Qn { rng, sqrt_q2, u } => {
                for o in out.iter_mut() {
                    let next = SQRT_12 * rng.random::<f64>();
                    f(o, qn_value(*sqrt_q2, *u, next));
                    *u = next;
                }
            }
            Component::Rw { rng, sd, level } => {
                for o in out.iter_mut() {
                    *level += *sd * normal(rng);
                    f(o, *level);
                }
            }
            Component::Dr { omega, t } => {
                for o in out.iter_mut() {
                    *t += 1;
                    f(o, *omega * *t as f64);
                }
            }
            Component::Ar1 { rng, phi, sd, x } => {
                for o in out.iter_mut() {
                    *x = *phi * *x + *sd * normal(rng);
                    f(o, *x);
                }
            }
            Component::Ma1 { rng, theta, sd, w } => {
                for o in out.iter_mut() {
                    let next = *sd * normal(rng);
                    f(o, next + *theta * *w);
                    *w = next;
                }
            }
            Component::Arma11 {
                rng,
                phi,
                theta,
                sd,
                x,
                w,
            } => {
                for o in out.iter_mut() {
                    let next = *sd * normal(rng);
                    *x = *phi * *x + next + *theta * *w;
                    *w = next;
                    f(o, *x);
                }
            }
            Component::Arma(s) => {
                for o in out.iter_mut() {
                    f(o, s.step());
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ar_is_stationary_matches_known_cases() {
        assert!(ar_is_stationary(&[]));
        assert!(ar_is_stationary(&[0.9]));
        assert!(!ar_is_stationary(&[1.0]));
        assert!(ar_is_stationary(&[0.5, 0.3]));
        assert!(!ar_is_stationary(&[0.5, 0.6]));
        assert!(ar_is_stationary(&[1.8, -0.81])); // double root at 1/0.9
        assert!(!ar_is_stationary(&[2.0, -1.0])); // double unit root
        assert!(ar_is_stationary(&[0.0, 0.0, 0.5]));
        assert!(!ar_is_stationary(&[f64::NAN]));
    }

    #[test]
    fn inverse_root_radius_matches_hand_values() {
        assert_eq!(inverse_root_radius(&[]), 0.0);
        assert_eq!(inverse_root_radius(&[-0.7, 0.0]), 0.7);
        // (1 - 0.5B)(1 - 0.8B) = 1 - 1.3B + 0.4B^2
        assert!((inverse_root_radius(&[1.3, -0.4]) - 0.8).abs() < 1e-10);
        // complex pair of modulus 0.9: lambda^2 - 2*0.9 cos(1) lambda + 0.81
        let c = 2.0 * 0.9 * 1f64.cos();
        assert!((inverse_root_radius(&[c, -0.81]) - 0.9).abs() < 1e-10);
        // double root 0.9: rounding in the Schur–Cohn step blurs the boundary to ~1e-6, on the
        // conservative side (longer burn-in)
        let r = inverse_root_radius(&[1.8, -0.81]);
        assert!((0.9..0.9 + 1e-5).contains(&r), "{r}");
    }

    #[test]
    fn arma_burn_in_follows_r_and_tolerance() {
        // R: p + q + ceil(6 / ln(1 / 0.5)) = 1 + 1 + 9
        assert_eq!(arma_burn_in(&[0.5], 1, StartMode::Zero).unwrap(), 11);
        // stationary: 1 + 0 + ceil(27.63 / ln 2) = 41
        assert_eq!(arma_burn_in(&[0.5], 0, StartMode::Stationary).unwrap(), 41);
        assert_eq!(arma_burn_in(&[], 3, StartMode::Stationary).unwrap(), 3);
        assert!(arma_burn_in(&[1.0 - 1e-12], 0, StartMode::Stationary).is_err());
    }

    #[test]
    fn replicate_seed_is_distinct_per_replicate() {
        let seeds: std::collections::HashSet<u64> =
            (0..10_000).map(|r| replicate_seed(7, r)).collect();
        assert_eq!(seeds.len(), 10_000);
        assert_ne!(replicate_seed(7, 0), replicate_seed(8, 0));
    }
}
