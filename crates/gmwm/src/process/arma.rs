//! General ARMA(p, q) (docs/methods.md §0.2, §4.4, §4.7), with AR(p) (`ma` empty) and MA(q) (`ar`
//! empty) as special cases. R sign convention: AR polynomial `1 - sum ar_i B^i`, MA polynomial
//! `1 + sum ma_i B^i`.

use super::draw::{unif, Draw};
use super::{CovariancePart, ParamTransform, Role, TransformPreset, BASE};
use crate::math::elementary;
use crate::process::sampler::SimRng;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::scalar::{sum, Dual, Scalar};
use super::{
    autocovariance_wv, check_positive, LatentProcess, Occurs, Orders, Params, Process, Simulate,
    Spec,
};
use crate::error::ParamError;
use crate::process::sampler::{normal, Sampler, Step};
use crate::process::ProcessKind;
use crate::process::StartMode;

/// `AR(p)`, `p` from 1 to [`MAX_ORDER`](crate::model::MAX_ORDER): of the ARMA family.
pub(crate) const AR_SPEC: Spec = Spec {
    name: "AR",
    syntax: "AR(p)",
    params: Params::Arma,
    orders: Some(Orders {
        ar: true,
        ma: false,
        min: 1,
        expected: "an order from 1 to 100",
        all_zero: "an order from 1 to 100",
        example: "AR(2)",
        make: |p, _| ProcessKind::Ar(p),
    }),
    occurs: Occurs::ArmaFamily,
    build,
    role: Role::Other,
    transforms,
    draw,
    ..BASE
};

/// `MA(q)`, `q` from 1 to [`MAX_ORDER`](crate::model::MAX_ORDER): of the ARMA family.
pub(crate) const MA_SPEC: Spec = Spec {
    name: "MA",
    syntax: "MA(q)",
    params: Params::Arma,
    orders: Some(Orders {
        ar: false,
        ma: true,
        min: 1,
        expected: "an order from 1 to 100",
        all_zero: "an order from 1 to 100",
        example: "MA(2)",
        make: |_, q| ProcessKind::Ma(q),
    }),
    occurs: Occurs::ArmaFamily,
    build,
    role: Role::Other,
    transforms,
    draw,
    ..BASE
};

/// `ARMA(p,q)`, each order from 0 to [`MAX_ORDER`](crate::model::MAX_ORDER), `p + q >= 1`
/// (the package's `SARIMA` without seasonal part): of the ARMA family.
pub(crate) const ARMA_SPEC: Spec = Spec {
    name: "ARMA",
    syntax: "ARMA(p,q)",
    params: Params::Arma,
    orders: Some(Orders {
        ar: true,
        ma: true,
        min: 0,
        expected: "orders from 0 to 100",
        all_zero: "p + q >= 1 (ARMA(0,0) is white noise: use WN)",
        example: "ARMA(2,1)",
        make: ProcessKind::Arma,
    }),
    occurs: Occurs::ArmaFamily,
    build,
    role: Role::Other,
    transforms,
    draw,
    ..BASE
};

/// docs/methods.md §5.3: the coefficients pseudo-logit, under the SSM preset logit2 for a
/// polynomial of order above 1; the innovation variance log.
fn transforms(kind: ProcessKind, preset: TransformPreset) -> Vec<ParamTransform> {
    use ParamTransform as T;
    let (p, q) = kind.orders();
    let coef = |order: usize| match preset {
        TransformPreset::Ssm if order > 1 => T::Logit2,
        _ => T::PseudoLogit,
    };
    let mut out = vec![coef(p); p];
    out.extend(std::iter::repeat(coef(q)).take(q));
    out.push(T::Log);
    out
}

/// AR coefficient bounds of the §6.5 ARMA draws (the package's constants).
const ARMA_LO: f64 = -0.99999999;
const ARMA_HI: f64 = 0.999999999;
/// Tries of the §6.5 stationarity rejection loop before falling back to zero AR
/// coefficients (the package loops without bound; a high order can make acceptance rare).
const ARMA_TRIES: usize = 1000;
/// Number of psi weights in the §6.5 ARMA variance scaling.
const PSI_TERMS: usize = 1000;

/// Levinson step-down: the AR polynomial `1 - sum a_i z^i` has all roots outside the unit
/// circle iff every partial autocorrelation has modulus < 1.
pub(crate) fn ar_stationary(a: &[f64]) -> bool {
    let mut cur = a.to_vec();
    while let Some(&k) = cur.last() {
        if k.is_nan() || k.abs() >= 1.0 {
            return false;
        }
        let m = cur.len() - 1;
        let d = 1.0 - k * k;
        cur = (0..m).map(|i| (cur[i] + k * cur[m - 1 - i]) / d).collect();
    }
    true
}

/// The increasing nested draw of §6.5, randomly permuted.
fn nested_draw(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
    let mut v = Vec::with_capacity(n);
    let mut lo = ARMA_LO;
    for _ in 0..n {
        let a = unif(rng, lo, ARMA_HI);
        v.push(a);
        lo = a;
    }
    // Fisher–Yates
    for i in (1..v.len()).rev() {
        let j = rng.random_range(0..=i);
        v.swap(i, j);
    }
    v
}

/// `1 + sum_{k=1}^{1000} psi_k^2` of `x_t = sum a_i x_{t-i} + e_t + sum m_j e_{t-j}`.
pub(crate) fn psi_norm(ar: &[f64], ma: &[f64]) -> f64 {
    let mut psi = vec![1.0];
    let mut total = 1.0;
    for k in 1..=PSI_TERMS {
        let mut v = if k <= ma.len() { ma[k - 1] } else { 0.0 };
        for (i, a) in ar.iter().enumerate().take(k) {
            v += a * psi[k - 1 - i];
        }
        psi.push(v);
        total += v * v;
        if !total.is_finite() {
            break;
        }
    }
    total
}

/// docs/methods.md §6.5 (port) for every ARMA-family kind: AR coefficients by the nested draw,
/// redrawn until stationary (zeros after [`ARMA_TRIES`] tries), MA coefficients by the nested
/// draw, the innovation variance `sigma2_T / (1 + sum psi_k^2)`; given values kept.
pub(crate) fn draw(d: &mut Draw<'_>, kind: ProcessKind, g: &[Option<f64>], theta: &mut Vec<f64>) {
    let (p, q) = kind.orders();
    let rng = &mut *d.rng;
    let mut ar = nested_draw(rng, p);
    let mut tries = 1;
    while !ar_stationary(&ar) {
        if tries >= ARMA_TRIES {
            ar = vec![0.0; p];
            break;
        }
        ar = nested_draw(rng, p);
        tries += 1;
    }
    let ma = nested_draw(rng, q);
    for (k, a) in ar.iter_mut().enumerate() {
        *a = g[k].unwrap_or(*a);
    }
    let mut ma = ma;
    for (k, m) in ma.iter_mut().enumerate() {
        *m = g[p + k].unwrap_or(*m);
    }
    let s = g[p + q].unwrap_or(d.ctx.sigma2_t / psi_norm(&ar, &ma));
    theta.extend_from_slice(&ar);
    theta.extend_from_slice(&ma);
    theta.push(s);
}

/// The [`Arma`] of an order kind from `ar1..arp, ma1..maq, sigma2`.
fn build(kind: ProcessKind, v: &[f64], _freq_hz: f64) -> Result<Process, ParamError> {
    let (p, q) = kind.orders();
    Ok(Arma::new(v[..p].to_vec(), v[p..p + q].to_vec(), v[p + q])?.into())
}

/// General ARMA(p, q): `x_t = sum ar_i x_{t-i} + w_t + sum ma_i w_{t-i}`, `Var w_t = sigma2`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Arma {
    /// Autoregressive coefficients `ar_1..ar_p`.
    pub(crate) ar: Vec<f64>,
    /// Moving-average coefficients `ma_1..ma_q`.
    pub(crate) ma: Vec<f64>,
    /// Innovation variance per sample.
    pub(crate) sigma2: f64,
}

impl Arma {
    /// AR coefficients `a_1..a_p` (R sign convention).
    pub fn ar(&self) -> &[f64] {
        &self.ar
    }
    /// MA coefficients `m_1..m_q` (R sign convention).
    pub fn ma(&self) -> &[f64] {
        &self.ma
    }
    /// Innovation variance per sample.
    pub fn sigma2(&self) -> f64 {
        self.sigma2
    }
}

/// Durand–Kerner iterations for the polynomial roots (quadratic convergence once close; the
/// loop also stops as soon as no root moves by more than `ROOT_TOL`).
const ROOT_ITERATIONS: usize = 2000;
/// Relative movement below which the root iteration stops.
const ROOT_TOL: f64 = 1e-15;

impl Arma {
    /// Builds an ARMA(p, q). Non-invertible MA parts are valid processes (accepted) but are not
    /// identifiable from second moments; see `Arma::is_invertible`.
    ///
    /// # Errors
    /// [`ParamError`] naming `ar`/`ma` for a non-finite coefficient, `ar` when the AR polynomial
    /// has a root on or inside the unit circle (the value reported is that root's modulus), or
    /// `sigma2` unless finite and `> 0`.
    pub fn new(ar: Vec<f64>, ma: Vec<f64>, sigma2: f64) -> Result<Self, ParamError> {
        if let Some(v) = ar.iter().find(|v| !v.is_finite()) {
            return Err(ParamError::new("ar", v, "finite AR coefficients"));
        }
        if let Some(v) = ma.iter().find(|v| !v.is_finite()) {
            return Err(ParamError::new("ma", v, "finite MA coefficients"));
        }
        check_positive("sigma2", sigma2)?;
        let min_modulus = min_root_modulus(&ar, -1.0);
        if min_modulus.is_nan() || min_modulus <= 1.0 {
            return Err(ParamError::new(
                "ar",
                min_modulus,
                "every root of the AR polynomial 1 - sum ar_i z^i outside the unit circle \
                 (stationarity); the value is the smallest root modulus",
            ));
        }
        Ok(Self { ar, ma, sigma2 })
    }

    /// Whether every root of the MA polynomial `1 + sum ma_i z^i` lies outside the unit circle.
    #[cfg(test)]
    pub(crate) fn is_invertible(&self) -> bool {
        let m = min_root_modulus(&self.ma, 1.0);
        m > 1.0
    }

    /// docs/methods.md §4.4: autocovariances `gamma_0..gamma_{max_lag}` from the exact
    /// `(r+1) x (r+1)` linear system (`r = max(p, q+1)`), then the AR recursion; `gamma_0` is
    /// exact, not the package's 1000-term MA(inf) truncation (§13.12). Values are NaN only if
    /// the system were singular, which stationarity (checked by [`Arma::new`]) excludes.
    pub(crate) fn autocovariance(&self, max_lag: usize) -> Vec<f64> {
        autocovariance(&self.ar, &self.ma, self.sigma2, max_lag)
    }
}

/// Smallest modulus of the roots of `1 + s * sum c_i z^i` (`s = -1` for AR, `+1` for MA);
/// infinity when the polynomial is constant. The roots are the reciprocals of those of the
/// monic `w^n + s c_1 w^{n-1} + ... + s c_n` (trailing zero coefficients dropped).
fn min_root_modulus(c: &[f64], s: f64) -> f64 {
    let n = c.iter().rposition(|v| *v != 0.0).map_or(0, |i| i + 1);
    if n == 0 {
        return f64::INFINITY;
    }
    let coef: Vec<f64> = c[..n].iter().map(|v| s * v).collect();
    let roots = monic_roots(&coef);
    roots
        .iter()
        .map(|r| 1.0 / r.abs())
        .fold(f64::INFINITY, f64::min)
}

#[derive(Debug, Clone, Copy)]
struct C64 {
    re: f64,
    im: f64,
}

impl C64 {
    fn mul(self, o: C64) -> C64 {
        C64 {
            re: self.re * o.re - self.im * o.im,
            im: self.re * o.im + self.im * o.re,
        }
    }
    fn sub(self, o: C64) -> C64 {
        C64 {
            re: self.re - o.re,
            im: self.im - o.im,
        }
    }
    fn div(self, o: C64) -> C64 {
        let d = o.re * o.re + o.im * o.im;
        C64 {
            re: (self.re * o.re + self.im * o.im) / d,
            im: (self.im * o.re - self.re * o.im) / d,
        }
    }
    fn abs(self) -> f64 {
        elementary::hypot(self.re, self.im)
    }
}

/// Roots of `w^n + a_1 w^{n-1} + ... + a_n` by Durand–Kerner (Weierstrass) iteration.
fn monic_roots(a: &[f64]) -> Vec<C64> {
    let n = a.len();
    // start on a circle of the Cauchy bound radius, at non-symmetric angles
    let radius = 1.0 + a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut z: Vec<C64> = (0..n)
        .map(|k| {
            let ang = 2.0 * std::f64::consts::PI * k as f64 / n as f64 + 0.4;
            C64 {
                re: radius * elementary::cos(ang),
                im: radius * elementary::sin(ang),
            }
        })
        .collect();
    let eval = |w: C64| {
        let mut acc = C64 { re: 1.0, im: 0.0 };
        for &c in a {
            acc = acc.mul(w);
            acc.re += c;
        }
        acc
    };
    for _ in 0..ROOT_ITERATIONS {
        let mut moved = 0.0f64;
        for i in 0..n {
            let mut den = C64 { re: 1.0, im: 0.0 };
            for k in 0..n {
                if k != i {
                    den = den.mul(z[i].sub(z[k]));
                }
            }
            if den.abs() == 0.0 {
                continue;
            }
            let step = eval(z[i]).div(den);
            z[i] = z[i].sub(step);
            moved = moved.max(step.abs() / z[i].abs().max(1e-300));
        }
        if moved < ROOT_TOL {
            break;
        }
    }
    z
}

/// docs/methods.md §4.4: `psi_i = ma_i (0 if i > q) + sum_{l=1}^{min(i,p)} ar_l psi_{i-l}`,
/// `psi_0 = 1`.
fn psi<T: Scalar>(ar: &[T], ma: &[T], n: usize) -> Vec<T> {
    let mut out = vec![T::lift(0.0); n.max(1)];
    out[0] = T::lift(1.0);
    for i in 1..n {
        let mut v = if i <= ma.len() {
            ma[i - 1]
        } else {
            T::lift(0.0)
        };
        for l in 1..=i.min(ar.len()) {
            v = v + ar[l - 1] * out[i - l];
        }
        out[i] = v;
    }
    out.truncate(n);
    out
}

/// docs/methods.md §4.4 linear system plus recursion; see [`Arma::autocovariance`].
fn autocovariance<T: Scalar>(ar: &[T], ma: &[T], sigma2: f64, max_lag: usize) -> Vec<T> {
    let (p, q) = (ar.len(), ma.len());
    let r = p.max(q + 1);
    let zero = T::lift(0.0);
    let phi: Vec<T> = (0..r).map(|i| ar.get(i).copied().unwrap_or(zero)).collect();
    let ps = psi(ar, ma, q + 1);
    let ma0 = |l: usize| if l == 0 { T::lift(1.0) } else { ma[l - 1] };
    // A gamma = rhs, unknowns gamma_0..gamma_r
    let n = r + 1;
    let mut a = vec![vec![zero; n]; n];
    let mut rhs = vec![zero; n];
    for k in 0..n {
        a[k][k] = a[k][k] + T::lift(1.0);
        for i in 1..=r {
            let c = k.abs_diff(i);
            a[k][c] = a[k][c] - phi[i - 1];
        }
        rhs[k] = if k <= q {
            sum((k..=q).map(|l| ma0(l) * ps[l - k])) * sigma2
        } else {
            zero
        };
    }
    let Some(g) = solve(a, rhs) else {
        return vec![T::nan(); max_lag + 1];
    };
    let mut gamma = g;
    gamma.resize(max_lag.max(r) + 1, zero);
    for h in r + 1..=max_lag {
        gamma[h] = sum((1..=r).map(|i| phi[i - 1] * gamma[h - i]));
    }
    gamma.truncate(max_lag + 1);
    gamma
}

/// Gaussian elimination with partial pivoting (on the values); `None` when singular.
// Row operations read two rows of one matrix by index; iterators would obscure that.
#[allow(clippy::needless_range_loop)]
fn solve<T: Scalar>(mut a: Vec<Vec<T>>, mut b: Vec<T>) -> Option<Vec<T>> {
    let n = b.len();
    for col in 0..n {
        let piv = (col..n)
            .max_by(|&i, &k| a[i][col].value().abs().total_cmp(&a[k][col].value().abs()))?;
        let pivot = a[piv][col].value();
        if pivot == 0.0 || !pivot.is_finite() {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        for row in col + 1..n {
            let f = a[row][col] / a[col][col];
            for k in col..n {
                a[row][k] = a[row][k] - f * a[col][k];
            }
            b[row] = b[row] - f * b[col];
        }
    }
    let mut x = vec![T::lift(0.0); n];
    for row in (0..n).rev() {
        let s = sum((row + 1..n).map(|k| a[row][k] * x[k]));
        x[row] = (b[row] - s) / a[row][row];
    }
    Some(x)
}

/// Levels whose WV is summed lag by lag (§4.1 over `2^10` autocovariances); deeper levels
/// come from the recurrence of [`deep_levels`], in memory and time linear in the levels.
const DIRECT_LEVELS: usize = 10;

/// Deepest level computed: `m = 2^61` is far beyond any recording (and keeps `2m` finite).
const MAX_LEVELS: usize = 62;

/// docs/methods.md §4.4: WV through §4.1 from the exact autocovariances (no validation). In
/// [`Dual`] numbers (one variable per coefficient of `ar ++ ma`) it gives the exact Jacobian.
fn arma_wv<T: Scalar>(ar: &[T], ma: &[T], sigma2: f64, levels: usize) -> Vec<T> {
    if levels == 0 {
        return Vec::new();
    }
    let r = ar.len().max(ma.len() + 1);
    // the recurrence starts from lag 2^direct - 1, which must reach past the ARMA orders
    let floor = usize::BITS as usize - r.leading_zeros() as usize;
    let direct = levels.min(DIRECT_LEVELS.max(floor));
    let gamma = autocovariance(ar, ma, sigma2, (1usize << direct) - 1);
    let mut out = autocovariance_wv(&gamma, direct);
    if levels > direct {
        out.extend(deep_levels(ar, ma.len(), &gamma, levels.min(MAX_LEVELS)));
    }
    out
}

/// docs/methods.md §4.4, deep levels: the WV at levels `direct+1..=levels` (where `gamma`
/// holds lags `0..2^direct`) without storing `2^levels` autocovariances.
///
/// With `A(n) = sum_{h=1..n} gamma_h` and `B(n) = sum_{h=1..n} h gamma_h`, the §4.1 sum at
/// half-width `m` is `m gamma_0 + 2m A(m-1) - 2B(m-1) - 2B(m) - 2m (A(2m-1) - A(m))
/// + B(2m-1)`, over `2m^2`. Beyond the MA order the autocovariances follow the AR
/// recursion, so the state `(gamma_h.., h gamma_h.., A(h), B(h))` (the last `r` lags of
/// each) advances by a constant matrix `M`, and `2^k` lags at once by `M^(2^k)`, one
/// squaring per level. `B` is carried, not formed as a difference, so nothing cancels.
fn deep_levels<T: Scalar>(ar: &[T], q: usize, gamma: &[T], levels: usize) -> Vec<T> {
    let r = ar.len().max(q + 1);
    let zero = T::lift(0.0);
    let phi = |i: usize| ar.get(i).copied().unwrap_or(zero);
    let d = 2 * r + 2;
    let (ia, ib) = (2 * r, 2 * r + 1);
    // M, row-major d x d
    let mut step = vec![zero; d * d];
    let at = |row: usize, col: usize| row * d + col;
    for i in 0..r {
        // gamma_{h+1} = sum phi_i gamma_{h+1-i}; (h+1) gamma_{h+1} = sum phi_i ((h+1-i) gamma.. + i gamma..)
        let (gi, ei) = (i, r + i);
        step[at(0, gi)] = phi(i);
        step[at(r, ei)] = phi(i);
        step[at(r, gi)] = phi(i) * (i + 1) as f64;
        step[at(ia, gi)] = phi(i);
        step[at(ib, ei)] = phi(i);
        step[at(ib, gi)] = phi(i) * (i + 1) as f64;
        if i + 1 < r {
            step[at(gi + 1, gi)] = T::lift(1.0);
            step[at(ei + 1, ei)] = T::lift(1.0);
        }
    }
    step[at(ia, ia)] = T::lift(1.0);
    step[at(ib, ib)] = T::lift(1.0);
    let h0 = gamma.len() - 1;
    let mut state = vec![zero; d];
    for i in 0..r {
        state[i] = gamma[h0 - i];
        state[r + i] = gamma[h0 - i] * (h0 - i) as f64;
    }
    state[ia] = sum(gamma[1..].iter().copied());
    state[ib] = sum(gamma.iter().enumerate().map(|(h, &g)| g * h as f64));
    // jump = M^(2^k), from M^(2^direct); squared in place through one scratch matrix. Once
    // the AR part has decayed to nothing, M^(2n) = M^n to rounding (the accumulators take the
    // whole sums): a fixed point, squared no more.
    let mut jump = step.clone();
    let mut scratch = vec![zero; d * d];
    let mut fixed = false;
    let mut square = |jump: &mut Vec<T>| {
        if fixed {
            return;
        }
        mat_mul(jump, jump, &mut scratch, d);
        fixed = T::settled(&scratch, jump);
        std::mem::swap(jump, &mut scratch);
    };
    let direct = h0.trailing_ones() as usize;
    for _ in 0..direct {
        square(&mut jump);
    }
    let mut next = vec![zero; d];
    let mut out = Vec::with_capacity(levels.saturating_sub(direct));
    for k in direct..levels {
        let m = 2f64.powi(k as i32);
        let (a_m1, b_m1) = (state[ia], state[ib]);
        mat_vec(&step, &state, &mut next);
        let (a_m, b_m) = (next[ia], next[ib]);
        mat_vec(&jump, &state, &mut next);
        std::mem::swap(&mut state, &mut next);
        let (a_2m1, b_2m1) = (state[ia], state[ib]);
        let s =
            gamma[0] * m + a_m1 * (2.0 * m) - b_m1 * 2.0 - b_m * 2.0 - (a_2m1 - a_m) * (2.0 * m)
                + b_2m1;
        out.push(s / (2.0 * m * m));
        if k + 1 < levels {
            square(&mut jump);
        }
    }
    out
}

/// `out = a b` for row-major `d x d` matrices (zero entries of `a` skipped: the early
/// powers of the companion matrix are sparse).
fn mat_mul<T: Scalar>(a: &[T], b: &[T], out: &mut [T], d: usize) {
    out.fill(T::lift(0.0));
    for (row, o) in a.chunks_exact(d).zip(out.chunks_exact_mut(d)) {
        for (&x, bk) in row.iter().zip(b.chunks_exact(d)) {
            if !x.is_zero() {
                for (o, &b) in o.iter_mut().zip(bk) {
                    *o = *o + x * b;
                }
            }
        }
    }
}

/// `out = a x` for a row-major `d x d` matrix.
fn mat_vec<T: Scalar>(a: &[T], x: &[T], out: &mut [T]) {
    for (o, row) in out.iter_mut().zip(a.chunks_exact(x.len())) {
        *o = sum(row.iter().zip(x).map(|(&a, &x)| a * x));
    }
}

/// Largest half-width `m = 2^{levels-1}` (1 for no levels).
fn max_half_width(levels: usize) -> f64 {
    2f64.powi(levels.clamp(1, 1000) as i32 - 1)
}

impl Arma {
    /// The coefficients `ar ++ ma` with `sigma2` last, as in [`LatentProcess::params`].
    fn coefs(&self) -> Vec<f64> {
        self.ar.iter().chain(&self.ma).copied().collect()
    }

    fn wv_at(&self, c: &[f64], levels: usize) -> Vec<f64> {
        let p = self.ar.len();
        arma_wv(&c[..p], &c[p..], self.sigma2, levels)
    }

    /// `d nu2 / d c_k` for the coefficients `k = first..first + W` (those that exist), as columns,
    /// by one pass of [`arma_wv`] in [`Dual`] numbers seeded on them; and the WV itself (the
    /// values, computed by the same operations as in `f64`, up to how long the deep levels'
    /// squaring runs: that waits for the derivatives to settle too).
    fn d_coefs<const W: usize>(
        &self,
        c: &[f64],
        first: usize,
        levels: usize,
    ) -> (Vec<f64>, Vec<Vec<f64>>) {
        let p = self.ar.len();
        let seeded: Vec<Dual<W>> = c
            .iter()
            .enumerate()
            .map(|(k, &v)| match k.checked_sub(first) {
                Some(lane) if lane < W => Dual::var(v, lane),
                _ => Dual::lift(v),
            })
            .collect();
        let wv = arma_wv(&seeded[..p], &seeded[p..], self.sigma2, levels);
        let width = W.min(c.len() - first);
        let cols = (0..width)
            .map(|lane| wv.iter().map(|x| x.g[lane]).collect())
            .collect();
        (wv.iter().map(|x| x.v).collect(), cols)
    }

    /// docs/methods.md §4.7: the exact derivatives of the §4.4 computation with respect to the
    /// coefficients (forward mode, [`Dual`] passes of up to eight coefficients), and
    /// `nu2 / sigma2` (§4.5) for `sigma2`.
    fn jacobian_at(&self, c: &[f64], levels: usize) -> Vec<Vec<f64>> {
        let mut cols: Vec<Vec<f64>> = Vec::with_capacity(c.len());
        let mut nu: Option<Vec<f64>> = None;
        while cols.len() < c.len() {
            let (first, left) = (cols.len(), c.len() - cols.len());
            let (values, more) = match left {
                1 => self.d_coefs::<1>(c, first, levels),
                2 => self.d_coefs::<2>(c, first, levels),
                3 | 4 => self.d_coefs::<4>(c, first, levels),
                5 | 6 => self.d_coefs::<6>(c, first, levels),
                _ => self.d_coefs::<8>(c, first, levels),
            };
            nu.get_or_insert(values);
            cols.extend(more);
        }
        let nu = nu.unwrap_or_else(|| self.wv_at(c, levels));
        (0..nu.len())
            .map(|j| {
                let mut row: Vec<f64> = cols.iter().map(|col| col[j]).collect();
                row.push(nu[j] / self.sigma2);
                row
            })
            .collect()
    }
}

/// Relative step of the Richardson-extrapolated central differences of the Jacobian used for the
/// generic ARMA Hessian (capped at `0.05 / m_max`, as the WV varies through `phi^m`): the §4.7
/// Jacobian is exact to rounding, so the rounding noise is about `eps / h`, near 1e-13 for a few
/// levels, 1e-10 at 14 and 1e-9 at 20 (the cap grows with the deepest half-width `m_max`).
const HESSIAN_STEP: f64 = 1e-3;

impl LatentProcess for Arma {
    fn name(&self) -> &'static str {
        ARMA_SPEC.name
    }
    fn param_names(&self) -> Vec<&'static str> {
        const AR: [&str; 12] = [
            "ar1", "ar2", "ar3", "ar4", "ar5", "ar6", "ar7", "ar8", "ar9", "ar10", "ar11", "ar12",
        ];
        const MA: [&str; 12] = [
            "ma1", "ma2", "ma3", "ma4", "ma5", "ma6", "ma7", "ma8", "ma9", "ma10", "ma11", "ma12",
        ];
        let mut v: Vec<&'static str> = (0..self.ar.len())
            .map(|i| AR.get(i).copied().unwrap_or("ar"))
            .collect();
        v.extend((0..self.ma.len()).map(|i| MA.get(i).copied().unwrap_or("ma")));
        v.push("sigma2");
        v
    }
    fn params(&self) -> Vec<f64> {
        let mut v = self.coefs();
        v.push(self.sigma2);
        v
    }
    fn wv(&self, levels: usize) -> Vec<f64> {
        arma_wv(&self.ar, &self.ma, self.sigma2, levels)
    }
    /// docs/methods.md §4.7 for the coefficients; `nu2 / sigma2` (§4.5) for `sigma2`.
    fn jacobian(&self, levels: usize) -> Vec<Vec<f64>> {
        self.jacobian_at(&self.coefs(), levels)
    }
    /// Richardson-extrapolated central differences of the §4.7 Jacobian for coefficient pairs; `(sigma2, sigma2) = 0`
    /// and `(c, sigma2) = (d nu2 / d c) / sigma2` exactly.
    // symmetric [level][a][b] fills read both triangles by index
    #[allow(clippy::needless_range_loop)]
    fn hessian(&self, levels: usize) -> Vec<Vec<Vec<f64>>> {
        let c = self.coefs();
        let n = c.len();
        let base = self.jacobian_at(&c, levels);
        let nl = base.len();
        let mut h = vec![vec![vec![0.0; n + 1]; n + 1]; nl];
        for b in 0..n {
            let step = (HESSIAN_STEP * c[b].abs().max(0.1)).min(0.05 / max_half_width(levels));
            let central = |step: f64| {
                let mut up = c.clone();
                up[b] += step;
                let mut dn = c.clone();
                dn[b] -= step;
                let (ju, jd) = (self.jacobian_at(&up, levels), self.jacobian_at(&dn, levels));
                (0..nl)
                    .map(|j| {
                        (0..n)
                            .map(|a| (ju[j][a] - jd[j][a]) / (2.0 * step))
                            .collect::<Vec<f64>>()
                    })
                    .collect::<Vec<_>>()
            };
            // one Richardson step: (4 D(h/2) - D(h)) / 3, error O(h^4)
            let (d1, d2) = (central(step), central(step / 2.0));
            for j in 0..nl {
                for a in 0..n {
                    h[j][a][b] = (4.0 * d2[j][a] - d1[j][a]) / 3.0;
                }
            }
        }
        for j in 0..nl {
            for a in 0..n {
                for b in 0..a {
                    let s = 0.5 * (h[j][a][b] + h[j][b][a]);
                    h[j][a][b] = s;
                    h[j][b][a] = s;
                }
                h[j][a][n] = base[j][a] / self.sigma2;
                h[j][n][a] = base[j][a] / self.sigma2;
            }
        }
        h
    }
    fn spectral_density(&self, f: f64) -> Option<f64> {
        let w = 2.0 * std::f64::consts::PI * f;
        // |1 + sum c_k e^{-i k w}|^2 with sign s
        let gain = |c: &[f64], s: f64| {
            let (mut re, mut im) = (1.0, 0.0);
            for (k, v) in c.iter().enumerate() {
                let a = w * (k + 1) as f64;
                re += s * v * elementary::cos(a);
                im -= s * v * elementary::sin(a);
            }
            re * re + im * im
        };
        Some(self.sigma2 * gain(&self.ma, 1.0) / gain(&self.ar, -1.0))
    }
}

// ------------------------------------------------------------------------------------------
// Simulation (docs/methods.md §10.1)

/// Relative size of the AR transient left after the burn-in of a stationary-mode ARMA(p, q):
/// below the 53-bit resolution of most downstream sums, so the start is stationary for every
/// practical purpose (docs/methods.md §10.1 port).
const STATIONARY_BURN_IN_TOL: f64 = 1e-12;

/// R's `arima.sim` burn-in constant: `n0 = p + q + ceil(6 / ln(min root modulus))`, a transient
/// of `e^-6 ≈ 2.5e-3` relative (docs/methods.md §10.1).
const R_BURN_IN_LOG: f64 = 6.0;

/// Longest burn-in a generic ARMA may need (AR root moduli down to about `1 + 2.8e-7`);
/// beyond it, starting would take seconds to minutes and the model is numerically a unit root.
const MAX_BURN_IN: usize = 100_000_000;

/// Whether the AR polynomial `1 - sum ar_i B^i` has every root outside the unit circle,
/// by the Schur–Cohn (step-down Levinson) test: every reflection coefficient `|k| < 1`
/// (docs/methods.md §10.1, §12). Exact up to rounding; an empty `ar` is stationary.
///
/// # Formula
/// `k_p = ar_p`; `ar'_i = (ar_i + k_p ar_{p-i}) / (1 - k_p^2)`, i = 1..p-1; repeat on `ar'`.
pub(crate) fn ar_is_stationary(ar: &[f64]) -> bool {
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

/// Burn-in length of a generic ARMA in each start mode (docs/methods.md §10.1).
fn arma_burn_in(ar: &[f64], q: usize, mode: StartMode) -> Result<usize, ParamError> {
    let p = ar.len();
    let rho = inverse_root_radius(ar);
    let log_len = match mode {
        StartMode::Stationary => -elementary::log(STATIONARY_BURN_IN_TOL),
        StartMode::Zero => R_BURN_IN_LOG,
    };
    let extra = if p == 0 || rho == 0.0 {
        0.0
    } else {
        // ln(min root modulus) = -ln(rho).
        (log_len / -elementary::log(rho)).ceil()
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

/// Generic ARMA(p, q) state: `xs[i] = x_{t-1-i}`, `es[k] = e_{t-1-k}`.
#[derive(Debug, Clone)]
struct ArmaState {
    rng: SimRng,
    ar: Vec<f64>,
    ma: Vec<f64>,
    sd: f64,
    xs: Vec<f64>,
    es: Vec<f64>,
    /// MA outputs still to be set to 0 (R's `x[seq_along(ma)] <- 0`).
    ma_zeros: usize,
}

impl Step for ArmaState {
    /// docs/methods.md §10.1 (ARMA(p, q), R's `arima.sim`): `y_t = e_t + sum_k ma_k e_{t-k}` (0 for
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

impl Simulate for Arma {
    fn covariance_part(&self) -> Result<CovariancePart, ParamError> {
        Err(ParamError::new(
            "model",
            "a generic ARMA(p, q) term",
            "only WN, QN, RW, DR, AR1, GM, MA1 and ARMA11 terms for the exact WV covariance (--covariance auto or bootstrap simulates V)",
        ))
    }
    /// Runs the burn-in of [`arma_burn_in`] first, from zeros with the first `q` MA outputs
    /// set to 0 (R's `arima.sim`), in both start modes; only its length depends on the mode.
    fn sampler(&self, rng: SimRng, start: StartMode) -> Result<Box<dyn Sampler>, ParamError> {
        let n0 = arma_burn_in(&self.ar, self.ma.len(), start)?;
        let mut s = ArmaState {
            rng,
            ar: self.ar.clone(),
            ma: self.ma.clone(),
            sd: self.sigma2.sqrt(),
            xs: vec![0.0; self.ar.len()],
            es: vec![0.0; self.ma.len()],
            ma_zeros: self.ma.len(),
        };
        for _ in 0..n0 {
            s.step();
        }
        Ok(Box::new(s))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stationarity_check() {
        assert!(ar_stationary(&[0.5]));
        assert!(!ar_stationary(&[1.2]));
        assert!(ar_stationary(&[0.5, 0.3]));
        assert!(!ar_stationary(&[0.6, 0.5]));
    }

    #[test]
    fn psi_of_ar1() {
        // AR1 with a = 0.5: sum psi_k^2 = 1 / (1 - 0.25)
        assert!((psi_norm(&[0.5], &[]) - 4.0 / 3.0).abs() < 1e-12);
        assert!((psi_norm(&[], &[0.5]) - 1.25).abs() < 1e-12);
    }

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
}
