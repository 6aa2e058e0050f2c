//! Parameter transforms: the optimiser works on unconstrained `u`, the model on `theta`
//! (docs/methods.md §5.3).
//!
//! # Ordered AR1/GM components (deviation from the package, documented)
//! With [`PhiOrder::Ordered`] and two or more AR1 (or GM) components, their `phi`s are
//! parametrised jointly so that they are strictly decreasing in model order (largest `phi` first,
//! the order §5.6 intends): with `c = 1 - phi`, lower bound `lo` (0 for GM and for AR1 in the IMU
//! preset, -1 for AR1 in the SSM preset) and the AR1/GM slots `s = 0..k` in model order,
//! `c_{k-1} = (1 - lo) logistic(-u_{k-1})` and `c_s = c_{s+1} logistic(-u_s)`. This is the chain
//! `phi_{i+1} = phi_i + (1 - phi_i) logistic(u_{i+1})` of §5.3 written from the smallest `phi`
//! upwards and in `1 - phi`, which keeps full relative precision for `phi` near 1. A GM slot holds
//! `beta = -freq ln(1 - c)`. Label switching then cannot happen and §5.6 needs no reordering.

use super::FitError;
use crate::math::elementary;
use crate::model::Model;
pub(crate) use crate::process::TransformPreset;
pub(crate) use crate::process::{logistic, ParamTransform, RESTART_EDGE};
use crate::process::{spec, ChainSlot as Slot};
use serde::{Deserialize, Serialize};

/// How several AR1/GM components are parametrised (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PhiOrder {
    /// Jointly, with strictly decreasing `phi` in model order (the §5.3 port suggestion;
    /// default because it makes the output order well defined).
    #[default]
    Ordered,
    /// Each `phi` (GM: `beta`) on its own, as the package (no ordering constraint).
    Free,
}

/// The map `u -> theta` of a whole model (docs/methods.md §5.3).
#[derive(Debug, Clone, PartialEq)]
pub struct Parametrisation {
    /// Per parameter: its scalar transform, `None` for the ordered slots.
    single: Vec<Option<ParamTransform>>,
    /// Ordered slots in model order: (theta index, component index, what it holds).
    ordered: Vec<(usize, usize, Slot)>,
    /// `1 - lo` of the ordered chain.
    width: f64,
    /// Parameter labels such as `GM[0].beta`.
    names: Vec<String>,
}

impl Parametrisation {
    /// The transforms of docs/methods.md §5.3 for `model` (values are ignored): with
    /// [`TransformPreset::Imu`] AR1/GM `phi` logit (0, 1), GM `beta` log, MA1 `theta` logit,
    /// ARMA11 and ARMA coefficients pseudo-logit; with [`TransformPreset::Ssm`] AR1 `phi` and MA1
    /// `theta` pseudo-logit, ARMA coefficients of polynomial order 1 pseudo-logit and of
    /// higher order logit2; in both GM `beta` log (a GM has `phi` in (0, 1)), every variance
    /// log and the DR slope `ln |omega|`. Two or more AR1/GM
    /// components with [`PhiOrder::Ordered`] share the ordered chain of the module doc.
    ///
    /// # Errors
    /// [`FitError::BadStart`] if `freq_hz` is not a positive finite number and the model has GM
    /// terms.
    pub fn new(
        model: &Model,
        preset: TransformPreset,
        order: PhiOrder,
        freq_hz: f64,
    ) -> Result<Self, FitError> {
        let specs: Vec<_> = model.components().iter().map(|c| spec(c.kind)).collect();
        let n_ordered = specs.iter().filter(|s| s.chain.is_some()).count();
        let chain = order == PhiOrder::Ordered && n_ordered >= 2;
        if specs.iter().any(|s| s.needs_rate) && !(freq_hz.is_finite() && freq_hz > 0.0) {
            return Err(FitError::BadStart(
                crate::ParamError::new("freq", freq_hz, "must be a positive number of hertz")
                    .into(),
            ));
        }
        let mut single = Vec::with_capacity(model.n_params());
        let mut ordered = Vec::new();
        let mut names = Vec::with_capacity(model.n_params());
        // the chain's `1 - phi` spans `1 - lo`, `lo` the highest lower end of its phis (a GM's
        // phi lies in (0, 1) whatever the preset; an AR1's follows it)
        let mut lo = f64::NEG_INFINITY;
        for (ci, (c, s)) in model.components().iter().zip(&specs).enumerate() {
            let kind = c.kind;
            for name in kind.param_names() {
                names.push(format!("{}[{ci}].{name}", kind.base_name()));
            }
            let at = single.len();
            let mut transforms: Vec<Option<ParamTransform>> =
                (s.transforms)(kind, preset).into_iter().map(Some).collect();
            if let Some(slot) = s.chain.map(|slot| slot(freq_hz)) {
                lo = lo.max(slot.lower(preset));
                if chain {
                    ordered.push((at, ci, slot));
                    transforms[0] = None;
                }
            }
            single.extend(transforms);
        }
        let width = if lo == f64::NEG_INFINITY {
            1.0
        } else {
            1.0 - lo
        };
        Ok(Self {
            single,
            ordered,
            width,
            names,
        })
    }

    /// Number of parameters.
    pub fn n_params(&self) -> usize {
        self.single.len()
    }

    /// The parametrisation of the concatenated parameters of several models (the blocks of a
    /// stacked fit, `crate::shared`), names prefixed by each block's label. The blocks must
    /// use scalar transforms only ([`PhiOrder::Free`] or at most one AR1/GM each): `None`
    /// when a block carries an ordered chain.
    pub(crate) fn concat(blocks: &[(&str, Parametrisation)]) -> Option<Self> {
        if blocks.iter().any(|(_, b)| b.is_ordered()) {
            return None;
        }
        let mut out = Self {
            single: Vec::new(),
            ordered: Vec::new(),
            width: 1.0,
            names: Vec::new(),
        };
        for (label, b) in blocks {
            out.single.extend_from_slice(&b.single);
            out.names
                .extend(b.names.iter().map(|n| format!("{label}.{n}")));
        }
        Some(out)
    }

    /// Parameter labels, `KIND[component].name` (e.g. `GM[0].beta`).
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The scalar transform of each parameter; `None` for a `phi`/`beta` of the ordered chain.
    pub(crate) fn transforms(&self) -> &[Option<ParamTransform>] {
        &self.single
    }

    /// Whether the AR1/GM components are parametrised by the ordered chain.
    pub(crate) fn is_ordered(&self) -> bool {
        !self.ordered.is_empty()
    }

    fn check_len(&self, what: &'static str, found: usize) -> Result<(), FitError> {
        if found == self.n_params() {
            Ok(())
        } else {
            Err(FitError::Length {
                what,
                expected: self.n_params(),
                found,
            })
        }
    }

    /// docs/methods.md §5.3 (and the ordered chain of the module doc): `u` from `theta`.
    ///
    /// # Errors
    /// [`FitError::Length`]; [`FitError::OutOfDomain`] naming the parameter; with the ordered
    /// chain, [`FitError::PhiNotOrdered`] unless the phis strictly decrease in model order.
    #[cfg(test)]
    pub(crate) fn to_u(&self, theta: &[f64]) -> Result<Vec<f64>, FitError> {
        self.to_u_with(theta, false)
    }

    /// [`Parametrisation::to_u`] of an estimate to restart an optimisation from: values on
    /// the closed edge of their domain ([`ParamTransform::inside`]) and, in the ordered chain,
    /// a `1 - phi` at 0, at its upper bound or tied with its neighbour are moved inside by
    /// [`RESTART_EDGE`] (relative). Values outside the closed domain are still refused.
    ///
    /// # Errors
    /// As [`Parametrisation::to_u`].
    pub(crate) fn to_u_restart(&self, theta: &[f64]) -> Result<Vec<f64>, FitError> {
        self.to_u_with(theta, true)
    }

    fn to_u_with(&self, theta: &[f64], restart: bool) -> Result<Vec<f64>, FitError> {
        self.check_len("theta", theta.len())?;
        let mut u = vec![0.0; theta.len()];
        for (i, (t, &v)) in self.single.iter().zip(theta).enumerate() {
            if let Some(t) = t {
                let v = if restart { t.inside(v) } else { v };
                u[i] = t
                    .to_u(v)
                    .ok_or_else(|| self.out_of_domain(i, v, t.domain()))?;
            }
        }
        let k = self.ordered.len();
        let mut upper = self.width; // c of the next slot (or 1 - lo for the last one)
        for s in (0..k).rev() {
            let (i, ci, slot) = self.ordered[s];
            let v = theta[i];
            let mut c = slot.complement(v);
            if restart && c.is_finite() && (0.0..=upper).contains(&c) {
                c = c.clamp(upper * RESTART_EDGE, upper * (1.0 - RESTART_EDGE));
            }
            let domain = slot.domain(self.width);
            if !(c.is_finite() && c > 0.0 && c < self.width) {
                return Err(self.out_of_domain(i, v, domain));
            }
            if c >= upper {
                let (j, cj, slot_j) = self.ordered[s + 1];
                return Err(FitError::PhiNotOrdered {
                    first: ci,
                    second: cj,
                    phi_first: slot.phi(v),
                    phi_second: slot_j.phi(theta[j]),
                });
            }
            // c = upper * logistic(-u)  =>  u = ln((upper - c) / c)
            u[i] = elementary::log((upper - c) / c);
            upper = c;
        }
        Ok(u)
    }

    fn out_of_domain(&self, index: usize, value: f64, expected: &'static str) -> FitError {
        FitError::OutOfDomain {
            index,
            name: self.names.get(index).cloned().unwrap_or_default(),
            value,
            expected,
        }
    }

    /// docs/methods.md §5.3: `theta` from `u`.
    ///
    /// # Errors
    /// [`FitError::Length`].
    pub(crate) fn to_theta(&self, u: &[f64]) -> Result<Vec<f64>, FitError> {
        self.check_len("u", u.len())?;
        let mut theta = vec![0.0; u.len()];
        self.eval(u, &mut theta, None);
        Ok(theta)
    }

    /// `d theta_i / d u_k`, indexed `[i][k]` (diagonal except inside the ordered chain, which
    /// is triangular).
    ///
    /// # Errors
    /// [`FitError::Length`].
    pub fn jacobian(&self, u: &[f64]) -> Result<Vec<Vec<f64>>, FitError> {
        self.check_len("u", u.len())?;
        let p = u.len();
        let mut theta = vec![0.0; p];
        let mut jac = vec![0.0; p * p];
        self.eval(u, &mut theta, Some(&mut jac));
        Ok(jac.chunks(p).map(<[f64]>::to_vec).collect())
    }

    /// `theta = g(u)` into `theta` and, if given, `d theta / d u` into `jac` (row-major p x p,
    /// fully overwritten). Lengths are the caller's invariant.
    pub(crate) fn eval(&self, u: &[f64], theta: &mut [f64], mut jac: Option<&mut [f64]>) {
        let p = self.n_params();
        if let Some(j) = jac.as_deref_mut() {
            j.fill(0.0);
        }
        for (i, t) in self.single.iter().enumerate() {
            if let Some(t) = t {
                theta[i] = t.to_theta(u[i]);
                if let Some(j) = jac.as_deref_mut() {
                    j[i * p + i] = t.dtheta_du(u[i]);
                }
            }
        }
        // c_s = width * prod_{r >= s} logistic(-u_r); d c_s / d u_r = -c_s logistic(u_r).
        let k = self.ordered.len();
        let mut c = self.width;
        for s in (0..k).rev() {
            let (i, _, slot) = self.ordered[s];
            c *= logistic(-u[i]);
            let (value, dvalue_dc) = slot.value(c);
            theta[i] = value;
            if let Some(j) = jac.as_deref_mut() {
                for &(r, _, _) in &self.ordered[s..] {
                    j[i * p + r] = -dvalue_dc * c * logistic(u[r]);
                }
            }
        }
    }

    /// docs/methods.md §5.6 (port): theta with the AR1/GM blocks `(phi, sigma2)` / `(beta,
    /// sigma2_gm)` stably sorted by `phi` decreasing (GM: `beta` increasing), wherever they appear;
    /// other parameters stay in place. Use it on a start before `Parametrisation::to_u` with the
    /// ordered chain, and on a [`PhiOrder::Free`] result.
    ///
    /// # Errors
    /// [`FitError::Length`].
    pub fn canonical_order(model: &Model, theta: &[f64]) -> Result<Vec<f64>, FitError> {
        if theta.len() != model.n_params() {
            return Err(FitError::Length {
                what: "theta",
                expected: model.n_params(),
                found: theta.len(),
            });
        }
        let mut starts = Vec::new();
        let mut at = 0;
        for c in model.components() {
            // the rate does not change the order: phi decreasing is beta increasing
            if let Some(slot) = spec(c.kind).chain.map(|slot| slot(1.0)) {
                starts.push((at, slot));
            }
            at += c.kind.n_params();
        }
        // sort key: phi decreasing; NaN keys keep their place last
        let key = |&(i, slot): &(usize, Slot)| slot.order_key(theta[i]);
        let mut sorted = starts.clone();
        sorted.sort_by(|a, b| key(b).total_cmp(&key(a)));
        let mut out = theta.to_vec();
        for (&(dst, _), &(src, _)) in starts.iter().zip(&sorted) {
            out[dst] = theta[src];
            out[dst + 1] = theta[src + 1];
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// docs/methods.md §5.9 test values carry 7 significant digits.
    const METHODS_TOL: f64 = 5e-7;

    #[test]
    #[allow(clippy::approx_constant)] // the docs/methods.md §5.9 value, as printed
    fn to_u_matches_methods_5_9() {
        let close = |a: f64, b: f64| (a / b - 1.0).abs() < METHODS_TOL;
        assert!(close(ParamTransform::Logit.to_u(0.9).unwrap(), 2.1972246));
        assert!(close(ParamTransform::Log.to_u(2.0).unwrap(), 0.6931472));
        assert!(close(ParamTransform::LogAbs.to_u(0.5).unwrap(), -0.6931472));
        assert!(close(
            ParamTransform::PseudoLogit.to_u(-0.9).unwrap(),
            -2.944439
        ));
        assert_eq!(ParamTransform::Logit.to_u(1.0), None);
        assert_eq!(ParamTransform::Log.to_u(0.0), None);
        assert_eq!(ParamTransform::LogAbs.to_u(0.0), None);
        assert_eq!(ParamTransform::Logit2.to_u(-2.0), None);
        assert_eq!(ParamTransform::Identity.to_u(f64::NAN), None);
    }

    #[test]
    fn logistic_is_stable() {
        assert_eq!(logistic(-800.0), 0.0);
        assert_eq!(logistic(800.0), 1.0);
        assert!((logistic(0.0) - 0.5).abs() < 1e-16);
    }

    /// Central differences with step `FD_STEP` have truncation error ~h^2 |theta'''| ~ 1e-8 and
    /// rounding error ~eps/h ~ 1e-11 on these O(1) functions.
    const FD_STEP: f64 = 1e-4;
    /// Tolerance of the central-difference comparisons (see `FD_STEP`).
    const FD_TOL: f64 = 1e-7;

    const ALL: [ParamTransform; 6] = [
        ParamTransform::Identity,
        ParamTransform::Log,
        ParamTransform::Logit,
        ParamTransform::PseudoLogit,
        ParamTransform::Logit2,
        ParamTransform::LogAbs,
    ];

    #[test]
    fn param_transform_round_trips_and_differentiates() {
        for t in ALL {
            for u in [-7.0, -1.3, 0.0, 0.4, 2.5, 9.0] {
                let theta = t.to_theta(u);
                let back = t.to_u(theta).unwrap();
                assert!(
                    (back - u).abs() < 1e-9 * (1.0 + u.abs()),
                    "{t:?} {u} {back}"
                );
                let fd = (t.to_theta(u + FD_STEP) - t.to_theta(u - FD_STEP)) / (2.0 * FD_STEP);
                let d = t.dtheta_du(u);
                assert!(
                    (fd - d).abs() < FD_TOL * (1.0 + d.abs()),
                    "{t:?} {u}: {fd} vs {d}"
                );
            }
        }
        assert_eq!(
            ParamTransform::LogAbs.to_theta(ParamTransform::LogAbs.to_u(-0.5).unwrap()),
            0.5
        );
    }

    fn model(text: &str) -> Model {
        Model::parse(text).unwrap()
    }

    fn check_jacobian(p: &Parametrisation, u: &[f64]) {
        let jac = p.jacobian(u).unwrap();
        for k in 0..u.len() {
            let mut up = u.to_vec();
            let mut dn = u.to_vec();
            // absolute step: every map has derivatives of order theta itself in u
            let h = FD_STEP;
            up[k] += h;
            dn[k] -= h;
            let (tp, td) = (p.to_theta(&up).unwrap(), p.to_theta(&dn).unwrap());
            for i in 0..u.len() {
                let fd = (tp[i] - td[i]) / (2.0 * h);
                let scale = jac[i][k].abs().max(jac[i][i].abs()).max(1e-300);
                assert!(
                    (fd - jac[i][k]).abs() <= 1e-6 * scale,
                    "d theta_{i} / d u_{k}: fd {fd} vs {}",
                    jac[i][k]
                );
            }
        }
    }

    #[test]
    fn parametrisation_round_trips_imu_presets() {
        let m = model("3*GM()+WN()+QN()+RW()+DR()");
        let p = Parametrisation::new(&m, TransformPreset::Imu, PhiOrder::Ordered, 250.0).unwrap();
        assert!(p.is_ordered());
        assert_eq!(p.names()[0], "GM[0].beta");
        // docs/methods.md §5.10 truth, betas increasing = phis decreasing
        let theta = [
            6.28e-3, 1.28e-8, 0.25, 7.08e-9, 8.48, 6.48e-9, 6.94e-7, 2.29e-6, 3.9e-14, 1e-6,
        ];
        let u = p.to_u(&theta).unwrap();
        let back = p.to_theta(&u).unwrap();
        for (a, b) in theta.iter().zip(&back) {
            assert!((a / b - 1.0).abs() < 1e-12, "{a} {b}");
        }
        check_jacobian(&p, &u);
        // not ordered: named error; canonical order fixes it
        let swapped = [
            0.25, 7.08e-9, 6.28e-3, 1.28e-8, 8.48, 6.48e-9, 6.94e-7, 2.29e-6, 3.9e-14, 1e-6,
        ];
        let e = p.to_u(&swapped).unwrap_err();
        assert!(
            matches!(
                e,
                FitError::PhiNotOrdered {
                    first: 0,
                    second: 1,
                    ..
                }
            ),
            "{e}"
        );
        assert_eq!(
            Parametrisation::canonical_order(&m, &swapped).unwrap(),
            theta
        );
        // free order: each parameter on its own
        let free = Parametrisation::new(&m, TransformPreset::Imu, PhiOrder::Free, 250.0).unwrap();
        assert!(!free.is_ordered());
        assert_eq!(free.transforms()[0], Some(ParamTransform::Log));
        let u = free.to_u(&swapped).unwrap();
        check_jacobian(&free, &u);
    }

    #[test]
    fn parametrisation_ar1_chain_in_both_presets() {
        let m = model("3*AR1()+WN()");
        for (preset, phis) in [
            (TransformPreset::Imu, [0.9999, 0.99, 0.3]),
            (TransformPreset::Ssm, [0.9, 0.2, -0.7]),
        ] {
            let p = Parametrisation::new(&m, preset, PhiOrder::Ordered, 1.0).unwrap();
            let theta = [phis[0], 1e-3, phis[1], 2.0, phis[2], 0.5, 1.0];
            let u = p.to_u(&theta).unwrap();
            let back = p.to_theta(&u).unwrap();
            for (a, b) in theta.iter().zip(&back) {
                assert!(
                    (a - b).abs() < 1e-12 * a.abs().max(1.0),
                    "{preset:?} {a} {b}"
                );
            }
            check_jacobian(&p, &u);
        }
        // imu: a negative phi is outside (0, 1)
        let p = Parametrisation::new(&m, TransformPreset::Imu, PhiOrder::Ordered, 1.0).unwrap();
        let e = p.to_u(&[0.9, 1.0, 0.5, 1.0, -0.1, 1.0, 1.0]).unwrap_err();
        assert!(matches!(e, FitError::OutOfDomain { index: 4, .. }), "{e}");
        // any u maps to ordered phis
        let theta = p.to_theta(&[-30.0, 0.0, 30.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
        assert!(theta[0] >= theta[2] && theta[2] >= theta[4]);
    }

    #[test]
    fn parametrisation_arma_presets_follow_methods_5_3() {
        use ParamTransform as T;
        let m = model("ARMA(2,1)+WN()");
        let imu = Parametrisation::new(&m, TransformPreset::Imu, PhiOrder::Ordered, 1.0).unwrap();
        let ssm = Parametrisation::new(&m, TransformPreset::Ssm, PhiOrder::Ordered, 1.0).unwrap();
        let l = Some(T::Log);
        assert_eq!(
            imu.transforms(),
            [
                Some(T::PseudoLogit),
                Some(T::PseudoLogit),
                Some(T::PseudoLogit),
                l,
                l
            ]
        );
        assert_eq!(
            ssm.transforms(),
            [Some(T::Logit2), Some(T::Logit2), Some(T::PseudoLogit), l, l]
        );
        let ma1 = model("MA1()+AR1()");
        let imu = Parametrisation::new(&ma1, TransformPreset::Imu, PhiOrder::Ordered, 1.0).unwrap();
        assert_eq!(imu.transforms(), [Some(T::Logit), l, Some(T::Logit), l]);
        let e = imu.to_u(&[0.5, 1.0]).unwrap_err();
        assert!(matches!(
            e,
            FitError::Length {
                expected: 4,
                found: 2,
                ..
            }
        ));
    }
    #[test]
    fn restart_moves_edge_values_inside_and_refuses_outside_ones() {
        let m = model("2*AR1()+WN()+DR()");
        let p = Parametrisation::new(&m, TransformPreset::Imu, PhiOrder::Ordered, 1.0).unwrap();
        // a phi of 0 and a drift of 0 (edges), then a phi of 1 and two equal phis
        for theta in [
            [0.9, 1.0, 0.0, 1.0, 2.0, 0.0],
            [1.0, 1.0, 0.5, 1.0, 2.0, 0.1],
            [0.7, 1.0, 0.7, 1.0, 2.0, 0.1],
        ] {
            assert!(p.to_u(&theta).is_err(), "{theta:?}");
            let u = p.to_u_restart(&theta).unwrap();
            let back = p.to_theta(&u).unwrap();
            for (a, b) in back.iter().zip(&theta) {
                assert!((a - b).abs() < 1e-8, "{theta:?} -> {back:?}");
            }
            assert!(
                back[0] > back[2] && back[2] > 0.0 && back[0] < 1.0,
                "{back:?}"
            );
        }
        // outside the closed domain: still refused
        assert!(p.to_u_restart(&[1.5, 1.0, 0.5, 1.0, 2.0, 0.1]).is_err());
        assert!(p.to_u_restart(&[0.9, -1.0, 0.5, 1.0, 2.0, 0.1]).is_err());
    }
}
