//! `gmwm demo`: the main job on a built-in default — simulate a sensor with known truth
//! (METHODS §5.10) and show its empirical wavelet variance against the truth's implied WV.

use crate::args::DemoArgs;
use crate::cmd::wv::options;
use crate::render::Style;
use anyhow::Result;
use gmwm::model::ImpliedWv;
use gmwm::sim::DemoSensor;
use gmwm::{wavelet_variance, WaveletVariance};
use serde::Serialize;
use std::io::Write;

/// What `gmwm demo --json` prints.
#[derive(Serialize)]
struct DemoReport<'a> {
    truth: String,
    freq_hz: f64,
    n: usize,
    seed: u64,
    empirical: &'a WaveletVariance,
    implied: &'a ImpliedWv,
}

/// Runs the subcommand.
pub fn run(args: &DemoArgs, out: &mut impl Write) -> Result<()> {
    let opts = options(&args.estimator)?;
    anyhow::ensure!(
        opts.filter == gmwm::WaveletFilter::Haar && opts.transform == gmwm::Transform::Modwt,
        "gmwm demo compares with the implied WV of METHODS §4, which exists for the Haar MODWT only; drop --filter/--transform"
    );
    let sensor = DemoSensor::default();
    let x = sensor.simulate(args.n, args.seed)?;
    let wv = wavelet_variance(&x, sensor.freq_hz, &opts)?;
    let implied = sensor.model.implied_wv(wv.levels(), sensor.freq_hz)?;
    let report = DemoReport {
        truth: sensor.model.to_string(),
        freq_hz: sensor.freq_hz,
        n: args.n,
        seed: args.seed,
        empirical: &wv,
        implied: &implied,
    };
    match Style::from(&args.output) {
        Style::Json => {
            serde_json::to_writer_pretty(&mut *out, &report)?;
            writeln!(out)?;
        }
        Style::Csv => {
            writeln!(out, "level,tau,tau_s,wv,ci_low,ci_high,implied_wv")?;
            for j in 0..wv.levels() {
                writeln!(
                    out,
                    "{},{},{:e},{:e},{:e},{:e},{:e}",
                    j + 1,
                    wv.tau[j],
                    wv.tau_s[j],
                    wv.wv[j],
                    wv.ci_low[j],
                    wv.ci_high[j],
                    implied.wv[j]
                )?;
            }
        }
        Style::Table => table(out, &report)?,
    }
    Ok(())
}

fn table(out: &mut impl Write, r: &DemoReport) -> Result<()> {
    let (wv, implied) = (r.empirical, r.implied);
    writeln!(
        out,
        "demo sensor (NavChip gyroscope, paper Table I), simulated with known truth"
    )?;
    writeln!(out, "  truth: {}", r.truth)?;
    writeln!(out, "  {} Hz, N = {}, seed {}", r.freq_hz, r.n, r.seed)?;
    writeln!(out)?;
    let kind = match wv.robust {
        Some(ro) => format!("robust (eff {}) WV", ro.eff),
        None => "WV".to_string(),
    };
    writeln!(
        out,
        "{:>5} {:>12} {:>13} {:>13} {:>13} {:>13}  truth in CI",
        "level",
        "tau_s",
        format!("empirical {kind}"),
        "ci_low",
        "ci_high",
        "implied WV",
    )?;
    let mut inside = 0;
    for j in 0..wv.levels() {
        let hit = wv.ci_low[j] <= implied.wv[j] && implied.wv[j] <= wv.ci_high[j];
        inside += usize::from(hit);
        writeln!(
            out,
            "{:>5} {:>12.4} {:>13.6e} {:>13.6e} {:>13.6e} {:>13.6e}  {}",
            j + 1,
            wv.tau_s[j],
            wv.wv[j],
            wv.ci_low[j],
            wv.ci_high[j],
            implied.wv[j],
            if hit { "yes" } else { "no" }
        )?;
    }
    writeln!(
        out,
        "\nthe implied WV of the truth lies inside the {:.0}% CI at {inside} of {} levels",
        100.0 * (1.0 - wv.alpha),
        wv.levels()
    )?;
    Ok(())
}
