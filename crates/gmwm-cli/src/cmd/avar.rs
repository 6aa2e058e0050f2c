//! `gmwm avar`: Allan, modified Allan or Hadamard variance of each selected column.

use crate::args::{AvarArgs, ConventionArg, KindArg};
use crate::input::{analyse_columns, column_context, is_wv, load, load_wv, named, note};
use crate::render::{self, Style};
use anyhow::Result;
use gmwm::imu::allan_from_wv;
use gmwm::{allan_variance, AllanKind, AllanOptions, AllanVariance, AvConvention};
use std::io::Write;

/// A saved wavelet variance: the overlapping Allan variance by METHODS §3.4,
/// `AV(m) = 2 WV(2m)`, exact for the classical Haar MODWT WV and the textbook estimator; other
/// kinds and conventions need the recording.
fn run_saved(args: &AvarArgs, opts: &AllanOptions) -> Result<Vec<(String, AllanVariance)>> {
    let file = &args.input.file;
    anyhow::ensure!(
        opts.kind == AllanKind::Overlapping && opts.convention == AvConvention::Textbook,
        "{}: --kind {} --convention {} needs the raw recording; a saved wavelet variance gives \
         only the overlapping textbook Allan variance (AV(m) = 2 WV(2m), METHODS §3.4)",
        file.display(),
        opts.kind,
        opts.convention.name()
    );
    let series = load_wv(&args.input, None)?;
    let mut items = Vec::with_capacity(series.len());
    for (name, wv) in &series {
        anyhow::ensure!(
            (wv.alpha - opts.alpha).abs() <= 1e-12 || opts.alpha == 0.05,
            "{}: series {}: --alpha {} needs the raw recording; the file's intervals are at \
             alpha {}",
            file.display(),
            gmwm::imu::quote(name),
            opts.alpha,
            wv.alpha
        );
        let av = allan_from_wv(wv).map_err(gmwm::Error::from);
        items.push((name.clone(), column_context(av, file, name)?));
    }
    note(
        file,
        "Allan variance from the saved Haar wavelet variance, AV(m) = 2 WV(2m) (METHODS §3.4), \
         intervals the WV's times 2; not recomputed from a recording",
    );
    Ok(items)
}

/// Runs the subcommand.
pub fn run(args: &AvarArgs, out: &mut impl Write) -> Result<()> {
    let items = compute(args)?;
    render::series(out, &named(&items), Style::from(&args.output))
}

/// The Allan-type variance of every selected column (from a saved WV: the overlapping one).
pub fn compute(args: &AvarArgs) -> Result<Vec<(String, AllanVariance)>> {
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
    if is_wv(&args.input) {
        return run_saved(args, &opts);
    }
    let loaded = load(&args.input)?;
    analyse_columns(&loaded, &args.input.file, |x| {
        Ok(allan_variance(x, loaded.freq_hz, &opts)?)
    })
}
