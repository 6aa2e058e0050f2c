//! `gmwm wv`: wavelet variance of each selected column.

use crate::args::{FormatArg, RobustConventionArg, TransformArg, WvArgs, WvEstimatorArgs};
use crate::input::{analyse_columns, column_context, load, named};
use crate::render::{self, Style};
use anyhow::Result;
use gmwm::imu::{BinaryChunks, InputFormat};
use gmwm::variance::default_levels;
use gmwm::{
    wavelet_variance, HaarWvAccumulator, RobustConvention, RobustOptions, Transform, WaveletFilter,
    WaveletVariance, WvOptions,
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

/// Samples per read of the streaming path: 1 Mi values (8 MiB) per chunk.
const STREAM_CHUNK: usize = 1 << 20;

/// Raw binary input with the classical Haar MODWT estimator streams: each selected column is
/// read in chunks through [`HaarWvAccumulator`], never materialised, so memory stays at the
/// accumulator's `8 · 2^J` bytes plus one chunk whatever the file size.
fn streamable(args: &WvArgs, opts: &WvOptions) -> bool {
    matches!(args.input.format, FormatArg::F64 | FormatArg::F32)
        && args.input.time_column.is_none()
        && opts.robust.is_none()
        && opts.transform == Transform::Modwt
        && opts.filter == WaveletFilter::Haar
}

fn run_streaming(args: &WvArgs, opts: &WvOptions, out: &mut impl Write) -> Result<()> {
    let input = &args.input;
    let format = match input.format {
        FormatArg::F32 => InputFormat::F32,
        _ => InputFormat::F64,
    };
    let ncols = input.ncols.unwrap_or(1);
    let columns: Vec<usize> = if input.columns.is_empty() {
        (1..=ncols).collect()
    } else {
        input
            .columns
            .iter()
            .map(|c| binary_column_index(c, ncols))
            .collect::<Result<_>>()?
    };
    let freq_hz = match input.freq {
        Some(f) => f,
        None => stream_freq(&input.file)?,
    };
    let mut results = Vec::with_capacity(columns.len());
    for &col in &columns {
        let name = format!("col{col}");
        let wv = column_context(
            stream_column(&input.file, format, ncols, col, opts, freq_hz),
            &input.file,
            &name,
        )?;
        results.push((name, wv));
    }
    render::series(out, &named(&results), Style::from(&args.output))
}

fn stream_column(
    path: &std::path::Path,
    format: InputFormat,
    ncols: usize,
    column: usize,
    opts: &WvOptions,
    freq_hz: f64,
) -> Result<WaveletVariance, gmwm::Error> {
    let mut chunks = BinaryChunks::open(path, format, ncols, column, STREAM_CHUNK)?;
    let n = usize::try_from(chunks.rows()).unwrap_or(usize::MAX);
    let levels = opts
        .levels
        .unwrap_or_else(|| default_levels(n, Transform::Modwt, WaveletFilter::Haar).max(1));
    let mut acc = HaarWvAccumulator::new(levels)?;
    while let Some(chunk) = chunks.next_chunk()? {
        acc.push(chunk)?;
    }
    acc.finish(freq_hz, opts.alpha)
}

fn binary_column_index(text: &str, ncols: usize) -> Result<usize> {
    let t = text.trim();
    let index = t
        .strip_prefix("col")
        .unwrap_or(t)
        .parse::<usize>()
        .map_err(|_| {
            anyhow::anyhow!(
                "invalid --columns {t:?}: binary columns are 1-based indices (or col1, col2, ...)"
            )
        })?;
    anyhow::ensure!(
        (1..=ncols).contains(&index),
        "invalid --columns {t}: the file has {ncols} interleaved column(s) (--ncols)"
    );
    Ok(index)
}

fn stream_freq(path: &std::path::Path) -> Result<f64> {
    let sidecar = gmwm::imu::find_sidecar(path)?;
    Ok(match sidecar.and_then(|s| s.sampling_frequency_hz) {
        Some(f) => f,
        None => {
            eprintln!(
                "gmwm: warning: {}: no sampling rate (no --freq or JSON sidecar); using 1 Hz, so tau_s is in samples",
                path.display()
            );
            1.0
        }
    })
}

/// Runs the subcommand.
pub fn run(args: &WvArgs, out: &mut impl Write) -> Result<()> {
    let opts = options(&args.estimator)?;
    if let Some(f) = args.input.freq {
        anyhow::ensure!(
            f.is_finite() && f > 0.0,
            "invalid --freq {f}: must be a positive number of hertz"
        );
    }
    if let Some(k) = args.input.ncols {
        anyhow::ensure!(
            k >= 1,
            "invalid --ncols 0: a binary file has at least one column"
        );
    }
    if streamable(args, &opts) {
        return run_streaming(args, &opts, out);
    }
    let loaded = load(&args.input)?;
    let items = analyse_columns(&loaded, &args.input.file, |x| {
        wavelet_variance(x, loaded.freq_hz, &opts)
    })?;
    for (name, wv) in &items {
        for w in &wv.warnings {
            eprintln!(
                "gmwm: warning: {}: column {name}: {w}",
                args.input.file.display()
            );
        }
    }
    render::series(out, &named(&items), Style::from(&args.output))
}
