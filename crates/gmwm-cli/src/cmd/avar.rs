//! `gmwm avar`: Allan, modified Allan or Hadamard variance of each selected column.

use crate::args::{AvarArgs, ConventionArg, KindArg};
use crate::input::{column_context, load};
use crate::render::{self, Named, Style};
use anyhow::Result;
use gmwm::variance::per_column;
use gmwm::{allan_variance, AllanKind, AllanOptions, AvConvention};
use std::io::Write;

/// Runs the subcommand.
pub fn run(args: &AvarArgs, out: &mut impl Write) -> Result<()> {
    gmwm::variance::ci::check_alpha(args.alpha)?;
    let opts = AllanOptions {
        kind: match args.kind {
            KindArg::Overlapping => AllanKind::Overlapping,
            KindArg::NonOverlapping => AllanKind::NonOverlapping,
            KindArg::Modified => AllanKind::Modified,
            KindArg::Hadamard => AllanKind::Hadamard,
            KindArg::HadamardNonOverlapping => AllanKind::HadamardNonOverlapping,
        },
        alpha: args.alpha,
        convention: match args.convention {
            ConventionArg::Textbook => AvConvention::Textbook,
            ConventionArg::Package => AvConvention::Package,
        },
    };
    let loaded = load(&args.input)?;
    let columns: Vec<&[f64]> = loaded
        .table
        .columns
        .iter()
        .map(|c| c.values.as_slice())
        .collect();
    let results = per_column(&columns, |x| allan_variance(x, loaded.freq_hz, &opts));
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
    render::allan_variances(out, &named, Style::from(&args.output))
}
