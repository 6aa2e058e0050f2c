//! `gmwm wv`: wavelet variance of each selected column.

use crate::args::{RobustConventionArg, TransformArg, WvArgs, WvEstimatorArgs};
use crate::input::{column_context, load};
use crate::render::{self, Named, Style};
use anyhow::Result;
use gmwm::variance::per_column;
use gmwm::{
    wavelet_variance, RobustConvention, RobustOptions, Transform, WaveletFilter, WvOptions,
};
use std::io::Write;

/// Validated estimator options from the flags.
pub fn options(a: &WvEstimatorArgs) -> Result<WvOptions> {
    let robust = if a.robust {
        let convention = match a.robust_convention {
            RobustConventionArg::Exact => RobustConvention::Exact,
            RobustConventionArg::Package => RobustConvention::Package,
        };
        Some(RobustOptions::new(a.eff, convention)?)
    } else {
        None
    };
    gmwm::variance::ci::check_alpha(a.alpha)?;
    Ok(WvOptions {
        transform: match a.transform {
            TransformArg::Modwt => Transform::Modwt,
            TransformArg::Dwt => Transform::Dwt,
        },
        filter: a.filter.parse::<WaveletFilter>()?,
        levels: a.levels,
        alpha: a.alpha,
        robust,
    })
}

/// Runs the subcommand.
pub fn run(args: &WvArgs, out: &mut impl Write) -> Result<()> {
    let opts = options(&args.estimator)?;
    let loaded = load(&args.input)?;
    let columns: Vec<&[f64]> = loaded
        .table
        .columns
        .iter()
        .map(|c| c.values.as_slice())
        .collect();
    let results = per_column(&columns, |x| wavelet_variance(x, loaded.freq_hz, &opts));
    let mut items = Vec::with_capacity(results.len());
    for (col, r) in loaded.table.columns.iter().zip(results) {
        items.push((
            col.name.as_str(),
            column_context(r, &args.input.file, &col.name)?,
        ));
    }
    let named: Vec<Named<_>> = items
        .iter()
        .map(|(name, result)| Named { name, result })
        .collect();
    render::wavelet_variances(out, &named, Style::from(&args.output))
}
