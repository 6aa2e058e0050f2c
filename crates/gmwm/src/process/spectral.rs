//! Slow quadrature oracle of the spectral definition of the Haar WV (docs/methods.md §1.9, paper
//! eq. 2), for tests and validation only.
//!
//! `nu2_j = int_{-1/2}^{1/2} |H_j(f)|^2 S(f) df`, `|H_j(f)|^2 = sin^4(pi f m) / (m^2 sin^2(pi f))`,
//! `m = 2^{j-1}`. The integrand is even, so twice the integral over `[0, 1/2]` is computed.
//! That interval is cut at the zeros `f = k/m` of the gain ("lobes"); on lobe `k` the variable
//! `s = m f - k` in `[0, 1]` gives `sin^4(pi f m) = sin^4(pi s)` without the rounding of a large
//! argument. The first lobe is cut geometrically towards `f = 0` (the peak of width `~1 - phi`
//! of an AR1 near the unit root) and the last one towards `f = 1/2` (peak of `phi < 0`); every
//! piece is integrated by adaptive 20-point Gauss–Legendre (a piece is split in halves until the
//! halves agree with the whole to `REL_TOL`).
//!
//! Cost: `O(2^j)` lobes per level, tens of evaluations each: about 0.1 s at level 20.

use super::LatentProcess;
use crate::math::elementary;

/// Gauss–Legendre order.
const GL_N: usize = 20;
/// Local relative agreement required between a piece and its two halves: 100 times the
/// rounding noise of a 20-term sum, so that noise never drives the bisection.
const REL_TOL: f64 = 1e-13;
/// Absolute agreement, relative to a first estimate of the whole level, below which a piece is
/// accepted whatever its own size (negligible pieces).
const ABS_TOL: f64 = 1e-17;
/// Maximum bisection depth of a piece (the geometric cuts already resolve the finest feature).
const MAX_DEPTH: usize = 24;
/// Geometric cuts towards the ends of the interval (`2^-60` of a lobe).
const GRADING_CUTS: i32 = 60;

/// Nodes and weights of Gauss–Legendre on `[-1, 1]` by Newton iteration on `P_n`.
fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        let mut z = elementary::cos(std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5));
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let kf = k as f64;
                let p2 = ((2.0 * kf - 1.0) * z * p1 - (kf - 1.0) * p0) / kf;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        x[i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
    (x, w)
}

struct Rule {
    x: Vec<f64>,
    w: Vec<f64>,
}

impl Rule {
    fn apply(&self, g: &dyn Fn(f64) -> f64, a: f64, b: f64) -> f64 {
        let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
        h * self
            .x
            .iter()
            .zip(&self.w)
            .map(|(x, w)| w * g(c + h * x))
            .sum::<f64>()
    }

    fn adaptive(
        &self,
        g: &dyn Fn(f64) -> f64,
        piece: [f64; 2],
        whole: f64,
        abs: f64,
        depth: usize,
    ) -> f64 {
        let [a, b] = piece;
        let mid = 0.5 * (a + b);
        let (l, r) = (self.apply(g, a, mid), self.apply(g, mid, b));
        let halves = l + r;
        if (halves - whole).abs() <= (REL_TOL * halves.abs()).max(abs) || depth >= MAX_DEPTH {
            halves
        } else {
            self.adaptive(g, [a, mid], l, abs, depth + 1)
                + self.adaptive(g, [mid, b], r, abs, depth + 1)
        }
    }
}

/// docs/methods.md §1.9: `nu2_j` of a spectral density `density(f)` on `[-1/2, 1/2]` (even in `f`)
/// by quadrature; slow oracle (see the module doc). `j >= 1`; `j = 0` gives NaN.
pub(crate) fn spectral_wv_level(density: &dyn Fn(f64) -> f64, j: usize) -> f64 {
    if j == 0 || j > 40 {
        return f64::NAN;
    }
    let rule = {
        let (x, w) = gauss_legendre(GL_N);
        Rule { x, w }
    };
    let m = 2f64.powi(j as i32 - 1);
    // lobes k = 0.. with s in [0, s_max(k)], f = (k + s)/m <= 1/2
    let n_lobes = (m / 2.0).ceil().max(1.0) as usize;
    // pass 0: plain rule on every piece (the scale of the absolute tolerance); pass 1: adaptive
    let mut crude = 0.0;
    let mut total = 0.0;
    for pass in 0..2 {
        for k in 0..n_lobes {
            let kf = k as f64;
            let s_max = (m / 2.0 - kf).min(1.0);
            let g = move |s: f64| {
                let f = (kf + s) / m;
                let ss = elementary::sin(std::f64::consts::PI * s);
                let sf = elementary::sin(std::f64::consts::PI * f);
                let gain = ss * ss * ss * ss / (m * m * sf * sf);
                gain * density(f) / m
            };
            let mut cuts = vec![0.0, s_max];
            if k == 0 {
                cuts.extend((1..=GRADING_CUTS).map(|i| s_max * 2f64.powi(-i)));
            }
            if k + 1 == n_lobes {
                cuts.extend((1..=GRADING_CUTS).map(|i| s_max * (1.0 - 2f64.powi(-i))));
            }
            cuts.sort_by(f64::total_cmp);
            cuts.dedup();
            for p in cuts.windows(2) {
                let whole = rule.apply(&g, p[0], p[1]);
                if pass == 0 {
                    crude += whole;
                } else {
                    total += rule.adaptive(&g, [p[0], p[1]], whole, ABS_TOL * crude.abs(), 0);
                }
            }
        }
    }
    2.0 * total
}

/// docs/methods.md §1.9: the implied WV of a process at levels `1..=levels` by quadrature of its
/// spectral density; `None` for a process without one (DR). Slow oracle.
pub(crate) fn spectral_wv(process: &dyn LatentProcess, levels: usize) -> Option<Vec<f64>> {
    process.spectral_density(0.25)?;
    let density = |f: f64| process.spectral_density(f).unwrap_or(f64::NAN);
    Some(
        (1..=levels)
            .map(|j| spectral_wv_level(&density, j))
            .collect(),
    )
}
