//! `gmwm avar`: Allan, modified Allan or Hadamard variance of each selected column.

use crate::args::{AvarArgs, ConventionArg, KindArg};
use crate::input::{analyse_columns, load, named};
use crate::render::{self, Style};
use anyhow::Result;
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
    let items = analyse_columns(&loaded, &args.input.file, |x| {
        allan_variance(x, loaded.freq_hz, &opts)
    })?;
    render::series(out, &named(&items), Style::from(&args.output))
}
