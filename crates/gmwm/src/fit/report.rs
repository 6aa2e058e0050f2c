//! Views of a [`GmwmFit`] for people and navigation filters: the estimates in model order,
//! every AR1/GM component in both forms (docs/methods.md §4.3, rate-aware), and the parameters in
//! the physical units a Kalman filter or an Allan-variance chart uses.
//!
//! Physical forms, with `f` the sampling rate in Hz and `u` the unit of the data (e.g. rad/s
//! for a gyroscope, m/s^2 for an accelerometer); each is fixed by the Allan variance it implies
//! (`AV(T) = 2 WV(2T)`, docs/methods.md §3.4, with the §4.2 closed forms):
//!
//! | process | quantity | value | unit | AV at cluster time T |
//! |---|---|---|---|---|
//! | WN(sigma2) | white-noise density N (ARW / VRW) | `sqrt(sigma2 / f)` | `u/sqrt(Hz)` | `N^2 / T` |
//! | QN(q2) | quantisation coefficient Q | `sqrt(q2) / f` | `u s` | `3 Q^2 / T^2` |
//! | RW(gamma2) | rate random-walk density K | `sqrt(gamma2 f)` | `u sqrt(Hz)` | `K^2 T / 3` |
//! | DR(omega) | drift rate | `omega f` | `u/s` | `(omega f)^2 T^2 / 2` |
//! | GM(beta, sigma2_gm) | correlation time `1/beta`, std `sqrt(sigma2_gm)`, driving-noise density `sqrt(2 beta sigma2_gm)` | | `s`, `u`, `u sqrt(Hz)` | |
//!
//! The GM form is the first-order Gauss–Markov state `b' = -beta b + w` with white `w` of
//! (two-sided) spectral density `2 beta sigma2_gm`: what a navigation filter's process-noise
//! matrix needs.

use super::GmwmFit;
use crate::process::{spec, ProcessKind};
use serde::Serialize;
use std::fmt;

/// One estimate, in model order (original parametrisation, docs/methods.md §0.2 names).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterEstimate {
    /// Process of the component (`GM`, `WN`, ...).
    pub process: String,
    /// 0-based position of the component in the model.
    pub index: usize,
    /// Parameter name (`beta`, `sigma2_gm`, `phi`, `sigma2`, `q2`, `gamma2`, `omega`, ...).
    pub name: String,
    /// Estimate.
    pub value: f64,
    /// Starting value used.
    pub start: f64,
}

/// An AR1 or GM component in both forms (docs/methods.md §4.3, `dt = 1 / freq_hz`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(crate) struct Ar1GmForms {
    /// Process as written in the model (`AR1` or `GM`).
    pub(crate) process: String,
    /// 0-based position of the component in the model.
    pub(crate) index: usize,
    /// Per-sample autoregressive coefficient.
    pub(crate) phi: f64,
    /// Per-sample innovation variance.
    pub(crate) sigma2: f64,
    /// Inverse correlation time, 1/s.
    pub(crate) beta: f64,
    /// Stationary variance (data unit squared).
    pub(crate) sigma2_gm: f64,
    /// Correlation time `1 / beta`, seconds.
    pub(crate) correlation_time_s: f64,
}

/// A parameter in physical units (see the module table).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NavParameter {
    /// Process of the component.
    pub process: String,
    /// 0-based position of the component in the model.
    pub index: usize,
    /// Quantity, e.g. `white_noise_density`.
    pub name: &'static str,
    /// Value in `unit`.
    pub value: f64,
    /// Unit, in terms of the data unit.
    pub unit: String,
}

impl GmwmFit {
    /// The estimates in model order with their names and starting values.
    pub fn parameters(&self) -> Vec<ParameterEstimate> {
        let mut out = Vec::with_capacity(self.theta.len());
        let mut k = 0;
        for (index, c) in self.model.components().iter().enumerate() {
            for name in c.kind.param_names() {
                out.push(ParameterEstimate {
                    process: c.kind.name(),
                    index,
                    name,
                    value: self.theta[k],
                    start: self.start.get(k).copied().unwrap_or(f64::NAN),
                });
                k += 1;
            }
        }
        out
    }

    /// Every AR1/GM component in both the per-sample AR1 and the rate-aware GM form.
    pub(crate) fn ar1_gm_forms(&self) -> Vec<Ar1GmForms> {
        let mut out = Vec::new();
        let mut k = 0;
        for (index, c) in self.model.components().iter().enumerate() {
            let n = c.kind.n_params();
            if let Some(forms) = self
                .theta
                .get(k..k + n)
                .and_then(|theta| Ar1GmForms::of(c.kind, index, theta, self.freq_hz))
            {
                out.push(forms);
            }
            k += n;
        }
        out
    }

    /// The parameters in physical units (module table), `unit` naming the data unit (`"u"`
    /// when `None`). MA/ARMA terms have no physical form and are left out.
    pub fn navigation(&self, unit: Option<&str>) -> Vec<NavParameter> {
        let mut out = Vec::new();
        let mut k = 0;
        for (index, c) in self.model.components().iter().enumerate() {
            let n = c.kind.n_params();
            if let Some(theta) = self.theta.get(k..k + n) {
                out.extend(physical_parameters(
                    c.kind,
                    index,
                    theta,
                    self.freq_hz,
                    unit,
                ));
            }
            k += n;
        }
        out
    }
}

impl Ar1GmForms {
    /// Both forms of a correlated component (AR1 `theta = [phi, sigma2]`, GM `[beta,
    /// sigma2_gm]`) at `freq_hz` (docs/methods.md §4.3); `None` for other kinds.
    pub(crate) fn of(
        kind: ProcessKind,
        index: usize,
        theta: &[f64],
        freq_hz: f64,
    ) -> Option<Ar1GmForms> {
        let markov = spec(kind).markov?;
        if theta.len() < 2 {
            return None;
        }
        let (phi, sigma2, beta, sigma2_gm) = (markov.forms)(theta, freq_hz);
        Some(Ar1GmForms {
            process: kind.name(),
            index,
            phi,
            sigma2,
            beta,
            sigma2_gm,
            correlation_time_s: 1.0 / beta,
        })
    }
}

/// The physical parameters of one component (module table) with parameters `theta` (docs/methods.md
/// §0.2 order) at `freq_hz`, as its kind reads them off ([`Spec`](crate::process::Spec)); `unit`
/// names the data unit (`"u"` when `None`); empty for the MA and ARMA kinds. `index` is the
/// component's position, copied into each entry.
pub(crate) fn physical_parameters(
    kind: ProcessKind,
    index: usize,
    theta: &[f64],
    freq_hz: f64,
    unit: Option<&str>,
) -> Vec<NavParameter> {
    if theta.is_empty() {
        return Vec::new();
    }
    (spec(kind).physical)(theta, freq_hz, unit.unwrap_or("u"))
        .into_iter()
        .map(|(name, value, unit)| NavParameter {
            process: kind.name(),
            index,
            name,
            value,
            unit,
        })
        .collect()
}

/// Six significant digits ([`significant`]).
fn short(v: f64) -> String {
    significant(v, 6)
}

pub(crate) use crate::math::significant;

impl fmt::Display for GmwmFit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "GMWM fit of {} at {} Hz",
            self.model.without_values(),
            self.freq_hz
        )?;
        writeln!(f, "{:<22} {:>14} {:>14}", "parameter", "estimate", "start")?;
        for (p, label) in self.parameters().iter().zip(&self.param_names) {
            writeln!(
                f,
                "{label:<22} {:>14} {:>14}",
                short(p.value),
                short(p.start)
            )?;
        }
        let forms = self.ar1_gm_forms();
        if !forms.is_empty() {
            writeln!(
                f,
                "{:<22} {:>14} {:>14} {:>14} {:>14}",
                "AR1/GM forms", "phi", "sigma2", "beta [1/s]", "sigma2_gm"
            )?;
            for g in &forms {
                writeln!(
                    f,
                    "{:<22} {:>14} {:>14} {:>14} {:>14}",
                    format!("{}[{}]", g.process, g.index),
                    short(g.phi),
                    short(g.sigma2),
                    short(g.beta),
                    short(g.sigma2_gm)
                )?;
            }
        }
        let nav = self.navigation(None);
        if !nav.is_empty() {
            writeln!(f, "physical units (u = data unit)")?;
            for p in &nav {
                writeln!(
                    f,
                    "  {:<30} {:>14} {}",
                    format!("{}[{}].{}", p.process, p.index, p.name),
                    short(p.value),
                    p.unit
                )?;
            }
        }
        let weighting = match (self.weighting, self.bootstrap_replicates) {
            (super::Weighting::Bootstrap, Some(h)) => format!("bootstrap (H = {h})"),
            (w, _) => format!("{w:?}").to_lowercase(),
        };
        writeln!(
            f,
            "objective Q = {:e} over {} levels, {weighting} weights",
            self.objective,
            self.nu_hat.len()
        )?;
        if !self.collapsed.is_empty() {
            writeln!(
                f,
                "at the boundary, fitted to nothing (not supported by the data): {}",
                self.collapsed.join(", ")
            )?;
        }
        write!(f, "optimiser: {}", self.convergence)
    }
}

#[cfg(test)]
mod tests {
    use super::significant;
    use crate::fit::Gmwm;

    #[test]
    fn significant_keeps_the_asked_digits() {
        assert_eq!(significant(118.265458, 6), "118.265");
        assert_eq!(significant(0.0055, 4), "0.005500");
        assert_eq!(significant(0.999915, 6), "0.999915");
        assert_eq!(significant(2.14553e-8, 6), "2.14553e-8");
        assert_eq!(significant(1638.4, 4), "1638");
        assert_eq!(significant(-0.25, 2), "-0.25");
        assert_eq!(significant(0.0, 4), "0");
    }

    use crate::model::Model;
    use crate::sim::DemoSensor;

    /// The §5.10 truth in GM form converts to the published AR1 form, and the physical units
    /// invert to the per-sample values.
    #[test]
    fn forms_and_units_of_the_navchip_truth() {
        let sensor = DemoSensor::default();
        let truth = &sensor.model;
        let levels = 12;
        let nu = truth.implied_wv(levels, sensor.freq_hz).unwrap().wv;
        let theta: Vec<f64> = truth.values().into_iter().map(Option::unwrap).collect();
        let fit = Gmwm::new(truth.clone())
            .fit_weighted(
                &nu,
                crate::fit::Weights::unit(levels),
                sensor.freq_hz,
                &theta,
            )
            .unwrap();
        let forms = fit.ar1_gm_forms();
        assert_eq!(forms.len(), 3);
        // docs/methods.md §5.10 AR1 forms, printed to 7 digits: relative 5e-7
        let published = [
            (0.9990005, 1.414585e-11),
            (0.9999749, 6.430559e-13),
            (0.9666488, 4.250234e-10),
        ];
        // the fit may have reordered the GMs by phi (§5.6): look each one up
        for (phi, s2) in published {
            let hit = forms
                .iter()
                .any(|h| (h.phi / phi - 1.0).abs() < 5e-7 && (h.sigma2 / s2 - 1.0).abs() < 5e-6);
            assert!(hit, "no GM with phi {phi}, sigma2 {s2}: {forms:?}");
        }
        let nav = fit.navigation(Some("rad/s"));
        let wn = nav
            .iter()
            .find(|p| p.name == "white_noise_density")
            .unwrap();
        // N^2 f = sigma2 (6.94e-7), to rounding
        assert!((wn.value * wn.value * 250.0 / 6.94e-7 - 1.0).abs() < 1e-9);
        assert_eq!(wn.unit, "rad/s/sqrt(Hz)");
        let rw = nav
            .iter()
            .find(|p| p.name == "rate_random_walk_density")
            .unwrap();
        assert!((rw.value * rw.value / 250.0 / 3.90e-14 - 1.0).abs() < 1e-9);
        let q = nav
            .iter()
            .find(|p| p.name == "quantization_coefficient")
            .unwrap();
        assert!(((q.value * 250.0).powi(2) / 2.29e-6 - 1.0).abs() < 1e-9);
        let tau: Vec<f64> = nav
            .iter()
            .filter(|p| p.name == "correlation_time")
            .map(|p| p.value)
            .collect();
        assert_eq!(tau.len(), 3);
        assert!(tau.iter().any(|t| (t * 0.250 - 1.0).abs() < 1e-9));
        let text = fit.to_string();
        assert!(
            text.contains("AR1/GM forms") && text.contains("physical units"),
            "{text}"
        );
    }

    #[test]
    fn ar1_components_get_a_gm_form() {
        let m = Model::parse("AR1(phi=0.9, sigma2=0.19)+WN(sigma2=1)").unwrap();
        let nu = m.implied_wv(6, 10.0).unwrap().wv;
        let fit = Gmwm::new(m)
            .fit_weighted(&nu, crate::fit::Weights::unit(6), 10.0, &[0.9, 0.19, 1.0])
            .unwrap();
        let g = &fit.ar1_gm_forms()[0];
        // beta = -10 ln 0.9, sigma2_gm = 0.19 / 0.19 = 1
        assert!((g.beta / (-10.0 * 0.9f64.ln()) - 1.0).abs() < 1e-6);
        assert!((g.sigma2_gm - 1.0).abs() < 1e-5);
        let p = fit.parameters();
        assert_eq!(p.len(), 3);
        assert_eq!(
            (p[2].process.as_str(), p[2].index, p[2].name.as_str()),
            ("WN", 1, "sigma2")
        );
    }
}
