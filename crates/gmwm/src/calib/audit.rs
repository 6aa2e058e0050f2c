//! The self-audit (docs/methods.md §19): how far to trust each exported number of this
//! calibration, for this sensor and this length.
//!
//! Each calibrated axis' identified model (its fit, with the estimates) is simulated at the
//! recording's length and rate `R` times (seeded, replicates in parallel) and the whole
//! calibration — selection, refinement, identification, read-off — is rerun on each replicate
//! with the same options. Per exported number (N, B, K) against its value in the simulated
//! model (the target): the median relative error (bias), the relative spread, and how often
//! the 95% interval covers the target; the same bias and spread for the IEEE 952 slope
//! read-off of the replicates' Allan deviations, so the user sees which method is more
//! accurate here; and how often the same canonical model was selected.
//!
//! Targets: N and K are the calibration's own (the identified model's white noise and random
//! walk; K is left out when the calibration only bounded it), B the simulated model's: its
//! flicker term's, else the IEEE read-off of its implied Allan deviation over the scales the
//! read-off uses at this length (`min sqrt(2 nu2_j) / 0.664`; left out without an interior
//! minimum there, where the read-off only bounds B).

use super::pipeline::{
    AxisCalibration, CalibError, Calibration, CalibrationReport, Estimate, EstimateStatus,
};
use super::plan::readoff_levels;
use crate::imu::{Imu, Sensor, SensorInfo};
use crate::process::{LatentProcess, Process};
use crate::progress::Progress;
use crate::sim::simulate_model;
use crate::units::SignalKind;
use crate::Column;
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Bias, spread and coverage of one method's values of a quantity over the replicates.
///
/// Wire format: `values` (replicates that gave one), `bias` (median of `value / target - 1`),
/// `spread` (standard deviation of `value / target`), `coverage` (fraction of the replicates
/// with an interval whose interval holds the target; null without intervals), `intervals`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AuditStats {
    /// Replicates that gave a value.
    pub values: usize,
    /// Median relative error.
    pub bias: f64,
    /// Relative standard deviation.
    pub spread: f64,
    /// Fraction of intervals holding the target.
    pub coverage: Option<f64>,
    /// Replicates that gave an interval.
    pub intervals: usize,
}

/// One exported number audited.
///
/// Wire format: `name` (`N`, `B`, `K`), `target`, `unit`, `gmwm` and `ieee`
/// ([`AuditStats`]; `ieee` null when no replicate's read-off gave the number).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AuditQuantity {
    /// `N`, `B` or `K`.
    pub name: String,
    /// Its value in the simulated model.
    pub target: f64,
    /// Its unit.
    pub unit: String,
    /// The calibration's values.
    pub gmwm: AuditStats,
    /// The IEEE 952 read-off's values.
    pub ieee: Option<AuditStats>,
}

/// The self-audit of one axis.
///
/// Wire format: `replicates`, `seed`, `model` (the simulated model), `canonical_model` (the
/// calibration's), `same_model` (fraction of replicates selecting it), `models` (each
/// canonical model selected and how often, most frequent first), `quantities`
/// ([`AuditQuantity`]), `failed` (replicates whose calibration failed).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Audit {
    /// Replicates run.
    pub replicates: usize,
    /// The simulations' seed.
    pub seed: u64,
    /// The simulated model.
    pub model: String,
    /// The canonical model of the calibration audited.
    pub canonical_model: String,
    /// Fraction of replicates whose calibration selected the same canonical model.
    pub same_model: f64,
    /// Canonical models selected, with counts.
    pub models: Vec<(String, usize)>,
    /// N, B, K.
    pub quantities: Vec<AuditQuantity>,
    /// Replicates whose calibration failed.
    pub failed: usize,
}

/// What one replicate's calibration gave for one axis.
struct Replicate {
    canonical: String,
    gmwm: [Option<Estimate>; 3],
    ieee: [Option<f64>; 3],
}

impl Calibration {
    /// Audits every axis of `report` (calibrated with these options) with `replicates`
    /// simulations each (module doc); `None` for an axis of unknown kind. Progress counts the
    /// replicates over all axes.
    ///
    /// # Errors
    /// [`CalibError`] when an axis' identified model cannot be simulated.
    pub fn audit(
        &self,
        report: &CalibrationReport,
        replicates: usize,
        seed: u64,
        progress: &dyn Progress,
    ) -> Result<Vec<Option<Audit>>, CalibError> {
        let mut options = self.options().clone();
        options.horizon_s = None;
        options.robust_check = None;
        options.datasheet = None;
        let inner = Calibration::new(options);
        let axes: Vec<&AxisCalibration> = report.axes.iter().collect();
        let audited = axes.iter().filter(|a| a.kind.is_some()).count();
        progress.start(audited * replicates);
        let done = AtomicUsize::new(0);
        axes.iter()
            .enumerate()
            .map(|(i, a)| {
                let Some(kind) = a.kind else { return Ok(None) };
                let axis_seed = seed.wrapping_add(1_000_003 * i as u64);
                let rows: Vec<Option<Replicate>> = (0..replicates as u64)
                    .into_par_iter()
                    .map(|r| {
                        let out = replicate(&inner, a, kind, report.freq_hz, axis_seed + r);
                        progress.advance(done.fetch_add(1, Ordering::Relaxed) + 1);
                        out
                    })
                    .collect::<Result<_, _>>()?;
                Ok(Some(summarise(
                    a,
                    rows,
                    replicates,
                    axis_seed,
                    report.freq_hz,
                    report.alpha,
                )?))
            })
            .collect()
    }
}

/// One replicate: the axis' model simulated and calibrated.
fn replicate(
    inner: &Calibration,
    a: &AxisCalibration,
    kind: SignalKind,
    freq_hz: f64,
    seed: u64,
) -> Result<Option<Replicate>, CalibError> {
    let unit = (a.unit != "u").then_some(a.unit.as_str());
    let simulated = SimulatedAxis {
        column: &a.column,
        axis: &a.axis,
        kind,
        unit,
    };
    let Some(b) = simulated.calibrate(inner, a.fit.model(), a.samples, freq_hz, seed)? else {
        return Ok(None);
    };
    Ok(Some(Replicate {
        canonical: b.canonical_model,
        ieee: [b.ieee.n.value, b.ieee.b.value, b.ieee.k.value],
        gmwm: [b.noise_density, b.bias_instability, b.random_walk],
    }))
}

/// The axis a simulated recording stands for: its column, axis, kind and unit.
pub(crate) struct SimulatedAxis<'a> {
    pub(crate) column: &'a str,
    pub(crate) axis: &'a str,
    pub(crate) kind: SignalKind,
    /// Unit of the samples (`None`: unknown, results in the data unit).
    pub(crate) unit: Option<&'a str>,
}

impl SimulatedAxis<'_> {
    /// `model` simulated (`samples` at `freq_hz`, seeded) and calibrated as this axis with
    /// `inner`'s options; `None` when that calibration fails (a replicate that fails counts
    /// as failed, not as an error of the study).
    ///
    /// # Errors
    /// [`CalibError`] when the model cannot be simulated.
    pub(crate) fn calibrate(
        &self,
        inner: &Calibration,
        model: &crate::model::Model,
        samples: usize,
        freq_hz: f64,
        seed: u64,
    ) -> Result<Option<AxisCalibration>, CalibError> {
        let x = simulate_model(model, samples, freq_hz, seed)?;
        let sensor = match self.kind {
            SignalKind::Gyroscope => Sensor::Gyroscope,
            SignalKind::Accelerometer => Sensor::Accelerometer,
        };
        let imu = Imu::new(
            vec![Column {
                name: self.column.to_string(),
                values: x,
            }],
            vec![SensorInfo {
                sensor,
                axis: self.axis.to_string(),
                unit: self.unit.map(str::to_string),
            }],
            freq_hz,
        )
        .map_err(crate::InputError::from)?;
        Ok(inner.run(&imu).ok().and_then(|r| r.axes.into_iter().next()))
    }
}

/// B of the simulated model: its flicker term's, else `min sqrt(2 nu2_j) / 0.664` over the
/// levels the read-off uses at this length (those whose interval spans at most 10x), `None`
/// when that minimum is at either end of them (no floor: the read-off gives a bound).
pub(crate) fn model_b(processes: &[Process], samples: usize, alpha: f64) -> Option<f64> {
    if let Some(b) = processes.iter().find_map(|p| match p {
        Process::Flicker(f) => Some(f.bias_instability()),
        _ => None,
    }) {
        return Some(b);
    }
    let levels = crate::variance::default_levels(
        samples,
        crate::wavelet::Transform::Modwt,
        crate::wavelet::WaveletFilter::Haar,
    );
    let mut nu = vec![0.0; levels];
    for p in processes {
        p.add_wv(&mut nu);
    }
    let reliable: Vec<f64> = readoff_levels(samples, levels, alpha)
        .into_iter()
        .zip(&nu)
        .filter_map(|(kept, v)| kept.then_some(*v))
        .collect();
    let (k, min) = reliable
        .iter()
        .copied()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    (k > 0 && k + 1 < reliable.len() && min > 0.0).then(|| (2.0 * min).sqrt() / 0.664)
}

fn stats(values: &[(f64, Option<(f64, f64)>)], target: f64) -> AuditStats {
    let mut rel: Vec<f64> = values.iter().map(|(v, _)| v / target - 1.0).collect();
    rel.sort_by(f64::total_cmp);
    let n = rel.len();
    let bias = if n == 0 { f64::NAN } else { rel[n / 2] };
    let mean = rel.iter().sum::<f64>() / n.max(1) as f64;
    let spread = if n > 1 {
        (rel.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
    } else {
        f64::NAN
    };
    let with: Vec<(f64, f64)> = values.iter().filter_map(|(_, ci)| *ci).collect();
    let covered = with
        .iter()
        .filter(|(lo, hi)| *lo <= target && target <= *hi)
        .count();
    AuditStats {
        values: n,
        bias,
        spread,
        coverage: (!with.is_empty()).then(|| covered as f64 / with.len() as f64),
        intervals: with.len(),
    }
}

fn summarise(
    a: &AxisCalibration,
    rows: Vec<Option<Replicate>>,
    replicates: usize,
    seed: u64,
    freq_hz: f64,
    alpha: f64,
) -> Result<Audit, CalibError> {
    let failed = rows.iter().filter(|r| r.is_none()).count();
    let rows: Vec<Replicate> = rows.into_iter().flatten().collect();
    let mut models: Vec<(String, usize)> = Vec::new();
    for r in &rows {
        match models.iter_mut().find(|(m, _)| *m == r.canonical) {
            Some(m) => m.1 += 1,
            None => models.push((r.canonical.clone(), 1)),
        }
    }
    models.sort_by_key(|m| std::cmp::Reverse(m.1));
    let same = rows
        .iter()
        .filter(|r| r.canonical == a.canonical_model)
        .count();
    let processes = a.fit.model().processes(freq_hz)?;
    let estimated = |e: &Option<Estimate>| {
        e.as_ref()
            .filter(|e| e.status != EstimateStatus::UpperBound)
            .map(|e| e.value)
    };
    let targets = [
        ("N", estimated(&a.noise_density), &a.noise_density),
        (
            "B",
            model_b(&processes, a.samples, alpha),
            &a.bias_instability,
        ),
        ("K", estimated(&a.random_walk), &a.random_walk),
    ];
    let mut quantities = Vec::new();
    for (k, (name, target, own)) in targets.into_iter().enumerate() {
        let Some(target) = target.filter(|t| *t > 0.0) else {
            continue;
        };
        let gmwm: Vec<(f64, Option<(f64, f64)>)> = rows
            .iter()
            .filter_map(|r| r.gmwm[k].as_ref())
            .filter(|e| e.status != EstimateStatus::UpperBound)
            .map(|e| (e.value, e.ci_low.zip(e.ci_high)))
            .collect();
        let ieee: Vec<(f64, Option<(f64, f64)>)> = rows
            .iter()
            .filter_map(|r| r.ieee[k])
            .map(|v| (v, None))
            .collect();
        quantities.push(AuditQuantity {
            name: name.to_string(),
            target,
            unit: own
                .as_ref()
                .map_or_else(|| a.unit.clone(), |e| e.unit.clone()),
            gmwm: stats(&gmwm, target),
            ieee: (!ieee.is_empty()).then(|| stats(&ieee, target)),
        });
    }
    Ok(Audit {
        replicates,
        seed,
        model: a.fit.model().to_string(),
        canonical_model: a.canonical_model.clone(),
        same_model: same as f64 / replicates.max(1) as f64,
        models,
        quantities,
        failed,
    })
}
