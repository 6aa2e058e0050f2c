//! `gmwm avar`: Allan, modified Allan or Hadamard variance of each selected column.

use super::Command;
use crate::config::AvarConfig;
use crate::input::{analyse_columns, column_context, gaps_of, is_wv, load, load_wv, named};
use crate::prepare::Inputs;
use crate::render;
use crate::style::OutputStyle;
use anyhow::Result;
use gmwm::{allan_from_wv, allan_variance, AllanVariance};
use std::io::Write;
use std::path::Path;

/// A saved wavelet variance: the overlapping Allan variance by docs/methods.md §3.4,
/// `AV(m) = 2 WV(2m)`, exact for the classical Haar MODWT WV and the textbook estimator; other
/// kinds and conventions need the recording.
fn run_saved(config: &AvarConfig, style: OutputStyle) -> Result<Vec<(String, AllanVariance)>> {
    let (file, opts) = (&config.input.file, &config.allan);
    config.saved_wv.check(file)?;
    let series = load_wv(&config.input, None)?;
    let mut items = Vec::with_capacity(series.len());
    for (name, wv) in &series {
        anyhow::ensure!(
            (wv.alpha() - opts.alpha).abs() <= 1e-12 || opts.alpha == 0.05,
            "{}: series {}: --alpha {} needs the raw recording; the file's intervals are at \
             alpha {}",
            file.display(),
            gmwm::quote(name),
            opts.alpha,
            wv.alpha()
        );
        let av = allan_from_wv(wv).map_err(gmwm::Error::from);
        items.push((name.clone(), column_context(av, file, name)?));
    }
    style.note(
        file,
        "Allan variance from the saved Haar wavelet variance, AV(m) = 2 WV(2m) \
         (docs/methods.md §3.4), intervals the WV's times 2; not recomputed from a recording",
    );
    Ok(items)
}

impl Command for AvarConfig {
    fn inputs(&mut self) -> Inputs<'_> {
        Inputs::Recording(&mut self.input)
    }

    fn outputs(&self) -> Vec<&Path> {
        Vec::new()
    }

    fn levels(&self) -> Option<usize> {
        None
    }

    fn run(&self, style: OutputStyle, mut out: &mut dyn Write) -> Result<()> {
        let items = compute(self, style)?;
        render::series(&mut out, &named(&items), self.output)
    }
}

/// The Allan-type variance of every selected column (from a saved WV: the overlapping one).
pub fn compute(config: &AvarConfig, style: OutputStyle) -> Result<Vec<(String, AllanVariance)>> {
    if is_wv(&config.input) {
        return run_saved(config, style);
    }
    let loaded = load(&config.input, style)?;
    let gaps = gaps_of(&loaded, &config.input, style);
    if gaps.is_empty() {
        return analyse_columns(&loaded, &config.input.file, |x| {
            Ok(allan_variance(x, loaded.freq_hz, &config.allan)?)
        });
    }
    // the gap-aware estimator is the overlapping Allan variance, twice the gap-aware Haar WV
    // (docs/methods.md §3.4, §1.11)
    let file = &config.input.file;
    anyhow::ensure!(
        config.allan.kind == gmwm::AllanKind::Overlapping
            && config.allan.convention == gmwm::AvConvention::Textbook,
        "{}: the time stamps have {} gaps: the gap-aware estimator is the overlapping Allan \
         variance (textbook convention); give --gaps contiguous for this kind or convention",
        file.display(),
        gaps.len()
    );
    let opts = gmwm::WvOptions {
        alpha: config.allan.alpha,
        ..gmwm::WvOptions::default()
    };
    let wvs = super::wv::gap_aware(&loaded, file, &gaps, &opts, style)?;
    wvs.iter()
        .map(|(name, wv)| {
            let av = allan_from_wv(wv).map_err(gmwm::Error::from);
            Ok((name.clone(), column_context(av, file, name)?))
        })
        .collect()
}
