//! The classical Haar MODWT wavelet variance of the columns of a raw binary file, streamed from
//! the file in bounded memory and split in time across threads ([`binary_wavelet_variance`]).
//!
//! The series is cut into parts of [`PART`] samples (fixed: never a function of the thread
//! count or of the reads), each run by one [`HaarWvAccumulator`] whose rings are primed from the
//! samples before it, and the parts' sums are added in part order, so the result is the same bit
//! for bit on any number of threads. Levels up to [`RING_LEVELS`] run through the accumulator's
//! pyramid; the levels above, whose rings would be megabytes of memory touched once per sample,
//! run a lag recurrence on samples read back from the file ([`TopLevel`]).
//!
//! Only the schedule depends on the threads: one column's parts run in parallel; several
//! columns run in parallel part after part; a series of one part has its pyramid split in two
//! halves, the levels above a split level running each chunk while the levels below run the
//! next ([`HaarWvAccumulator::upper_part`]), which computes exactly what one pass would.

use crate::error::{check_freq, InputError, ParamError, SeriesError};
use crate::imu::read::binary::RawRows;
use crate::imu::read::stream::StreamedTable;
use crate::imu::{BinaryLayout, ReadError};
use crate::math::elementary;
use crate::math::sum::NeumaierSum;
use crate::variance::ci::check_alpha;
use crate::variance::wv::{
    check_levels, default_levels, sum_plain, sum_squares, HaarWvAccumulator, WaveletVariance,
    WvOptions, BLOCK, PRIME_ALIGN,
};
use crate::wavelet::{Transform, WaveletFilter};
use rayon::prelude::*;
use std::path::Path;
use std::sync::Mutex;

/// Samples per part of a split pass: `2^22`.
pub(crate) const PART: usize = 1 << 22;

/// Rows per read: 16 Ki (128 KiB a column of f64): the chunk, its demeaned copy and the
/// samples read back for the top levels stay in the L2 cache.
const CHUNK: usize = 1 << 14;

/// Levels run through the rings of the pyramid (at most `8 · 2^20` bytes a column); the levels
/// above run the lag recurrence of [`TopLevel`].
pub(crate) const RING_LEVELS: usize = 20;

/// How a split pass cuts and reads the series; only the part length and the ring levels change
/// the result, the chunk length never does.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Plan {
    /// Samples per part: a power of two, at least [`BLOCK`].
    pub(crate) part: usize,
    /// Rows per read: a multiple of [`BLOCK`].
    pub(crate) chunk: usize,
    /// Levels run through the rings.
    pub(crate) ring_levels: usize,
}

impl Plan {
    /// The plan of [`binary_wavelet_variance`].
    pub(crate) const DEFAULT: Plan = Plan {
        part: PART,
        chunk: CHUNK,
        ring_levels: RING_LEVELS,
    };
}

/// The classical Haar MODWT wavelet variance (docs/methods.md §1.5, with the chi-square intervals
/// of §1.7) of columns of a raw little-endian binary file, streamed: the columns are never loaded,
/// and the file is read once (plus, for the highest levels and for the start of each part of
/// 2^22 rows, samples read back from it) by positioned reads spread over the rayon pool.
///
/// `layout` describes the file (as [`binary_layout`](crate::imu::binary_layout) finds it): its
/// format ([`InputFormat::F64`](crate::imu::InputFormat::F64) or `F32`), its number of
/// interleaved columns and their names (which errors quote; `colK` when they do not name every
/// column). `columns` are 1-based indices into it, and the result has one
/// [`WaveletVariance`] per entry, in order. `opts` must be the classical Haar MODWT (the default
/// transform and filter, no robust options); `opts.levels` of `None` takes
/// [`default_levels`] of the file's length.
///
/// The values equal those of [`wavelet_variance`](crate::wavelet_variance) of the loaded column
/// to rounding (the same offset, the mean of the first 2048 samples, and the same coefficients,
/// summed in another order; about 1e-15 relative), and are bit for bit the same whatever the
/// number of threads. Memory: per column and per part in flight (at most one a thread) about
/// `8 · 2^min(J, 20)` bytes (the rings of the pyramid), and per thread a few chunks of 16 Ki
/// rows of the file; it does not grow with the file's length.
///
/// ```no_run
/// use gmwm::{BinaryLayout, InputFormat};
/// use gmwm::binary_wavelet_variance;
/// use std::path::Path;
/// let layout = BinaryLayout {
///     format: InputFormat::F64,
///     ncols: 6,
///     names: ["gx", "gy", "gz", "ax", "ay", "az"].map(String::from).to_vec(),
/// };
/// let wvs = binary_wavelet_variance(
///     Path::new("imu.f64"),
///     &layout,
///     &[1, 2, 3],
///     200.0,
///     &gmwm::WvOptions::default(),
/// )?;
/// println!("{}", wvs[0]);
/// # Ok::<(), gmwm::ReadError>(())
/// ```
///
/// # Errors
/// [`ReadError::Io`], [`ReadError::Empty`], [`ReadError::BinarySize`],
/// [`ReadError::BinaryNonFinite`] (the first in file order) and [`ReadError::ColumnOutOfRange`],
/// each naming the file; [`ReadError::InvalidOption`] for no column, a text format, a bad
/// `freq_hz`, `alpha` or level count, or options that do not stream (robust, the DWT, another
/// filter); [`ReadError::Series`] naming the file and the column when a column is constant or
/// the file too short for the levels asked.
pub fn binary_wavelet_variance(
    path: &Path,
    layout: &BinaryLayout,
    columns: &[usize],
    freq_hz: f64,
    opts: &WvOptions,
) -> Result<Vec<WaveletVariance>, ReadError> {
    let columns = binary_columns_wv(path, layout, columns, freq_hz, opts)?;
    Ok(columns.into_iter().map(|c| c.wv).collect())
}

/// A column of a raw binary file streamed by [`binary_columns_wv`].
#[derive(Debug, Clone, PartialEq)]
pub struct StreamedColumn {
    /// Its wavelet variance, as [`binary_wavelet_variance`] gives it.
    pub wv: WaveletVariance,
    /// Its smallest sample.
    pub min: f64,
    /// Its largest sample.
    pub max: f64,
}

/// [`binary_wavelet_variance`] with each column's smallest and largest sample, found in the
/// same pass: what a GMWM fit needs besides the WV (the range `R = (max - min) / N` of the
/// start search, docs/methods.md §6.1), so a fit of a raw binary file need not load it either.
///
/// # Errors
/// As [`binary_wavelet_variance`].
pub fn binary_columns_wv(
    path: &Path,
    layout: &BinaryLayout,
    columns: &[usize],
    freq_hz: f64,
    opts: &WvOptions,
) -> Result<Vec<StreamedColumn>, ReadError> {
    binary_wv_with(path, layout, columns, freq_hz, opts, &Plan::DEFAULT)
}

/// [`binary_columns_wv`] with another [`Plan`].
pub(crate) fn binary_wv_with(
    path: &Path,
    layout: &BinaryLayout,
    columns: &[usize],
    freq_hz: f64,
    opts: &WvOptions,
    plan: &Plan,
) -> Result<Vec<StreamedColumn>, ReadError> {
    check_options(opts, freq_hz)?;
    if columns.is_empty() {
        return Err(ParamError::new("columns", "none", "at least one column").into());
    }
    let raw = RawRows::open(path, layout.format, layout.ncols)?;
    if let Some(&bad) = columns.iter().find(|c| !(1..=raw.ncols()).contains(*c)) {
        return Err(ReadError::ColumnOutOfRange {
            path: path.to_path_buf(),
            index: bad,
            ncols: raw.ncols(),
        });
    }
    let name = |c: usize| -> String {
        match layout.names.get(c - 1) {
            Some(n) if layout.names.len() == layout.ncols => n.clone(),
            _ => format!("col{c}"),
        }
    };
    let column_error = |c: usize, e: InputError| match e {
        InputError::Series(source) => ReadError::Series {
            path: path.to_path_buf(),
            column: name(c),
            source,
        },
        InputError::Param(e) => e.into(),
        other => ParamError::new(
            "options",
            other.to_string(),
            "those of a classical Haar MODWT wavelet variance",
        )
        .into(),
    };
    let n = usize::try_from(raw.rows()).map_err(|_| {
        ParamError::new(
            "rows",
            raw.rows(),
            "at most usize::MAX rows on this platform",
        )
    })?;
    let levels = opts
        .levels
        .unwrap_or_else(|| default_levels(n, Transform::Modwt, WaveletFilter::Haar).max(1));
    check_levels(n, levels, opts).map_err(|e| column_error(columns[0], e))?;
    let source = FileSource {
        raw: &raw,
        columns: columns.iter().map(|c| c - 1).collect(),
    };
    let sums = split_sums(&source, levels, plan).map_err(|e| match e {
        SplitError::Read(e) => e,
        SplitError::Param(e) => e.into(),
        SplitError::Series(k, e) => column_error(columns[k], e.into()),
    })?;
    sums.into_iter()
        .zip(columns)
        .map(|(sums, &c)| {
            Ok(StreamedColumn {
                wv: sums
                    .acc
                    .finish(freq_hz, opts.alpha)
                    .map_err(|e| column_error(c, e))?,
                min: sums.min,
                max: sums.max,
            })
        })
        .collect()
}

/// Refuses options [`binary_wavelet_variance`] cannot stream, and bad `alpha`, `freq_hz` or
/// level counts.
fn check_options(opts: &WvOptions, freq_hz: f64) -> Result<(), ParamError> {
    if opts.robust.is_some() {
        return Err(ParamError::new(
            "robust",
            "on",
            "the classical estimator: a streamed wavelet variance is not robust",
        ));
    }
    if opts.transform != Transform::Modwt || opts.filter != WaveletFilter::Haar {
        return Err(ParamError::new(
            "transform",
            format!("{} {}", opts.filter, opts.transform),
            "the Haar MODWT: the only wavelet variance that streams",
        ));
    }
    check_alpha(opts.alpha)?;
    check_freq(freq_hz)?;
    Ok(())
}

/// Samples of the selected columns, by rows.
pub(crate) trait Source: Sync {
    /// Number of rows.
    fn rows(&self) -> usize;
    /// Number of selected columns.
    fn columns(&self) -> usize;
    /// Rows `[row, row + n)` of the selected columns into `out[k]` (replaced), checked finite;
    /// `bytes` is a buffer of the caller's, reused between calls.
    fn read(
        &self,
        row: usize,
        n: usize,
        bytes: &mut Vec<u8>,
        out: &mut [Vec<f64>],
    ) -> Result<(), ReadError>;
    /// [`read`](Self::read) of rows already read and checked.
    fn read_again(
        &self,
        row: usize,
        n: usize,
        bytes: &mut Vec<u8>,
        out: &mut [Vec<f64>],
    ) -> Result<(), ReadError> {
        self.read(row, n, bytes, out)
    }
}

/// Columns of a raw binary file.
struct FileSource<'a> {
    raw: &'a RawRows,
    /// 0-based.
    columns: Vec<usize>,
}

impl Source for FileSource<'_> {
    fn rows(&self) -> usize {
        self.raw.rows() as usize
    }

    fn columns(&self) -> usize {
        self.columns.len()
    }

    fn read(
        &self,
        row: usize,
        n: usize,
        bytes: &mut Vec<u8>,
        out: &mut [Vec<f64>],
    ) -> Result<(), ReadError> {
        self.raw.read(row as u64, n, &self.columns, bytes, out)
    }

    fn read_again(
        &self,
        row: usize,
        n: usize,
        bytes: &mut Vec<u8>,
        out: &mut [Vec<f64>],
    ) -> Result<(), ReadError> {
        self.raw
            .read_unchecked(row as u64, n, &self.columns, bytes, out)
    }
}

/// The accumulators of one part, closed, with what the combination needs.
struct PartSums {
    /// One a column, rings handed back.
    accs: Vec<HaarWvAccumulator>,
    /// The lag-recurrence levels of each column.
    tops: Vec<Vec<TopLevel>>,
    /// Sums of the demeaned samples of each block of [`BLOCK`] of the part, a vector a column.
    block_sums: Vec<Vec<f64>>,
    /// Smallest and largest sample of each column in the part.
    extremes: Vec<(f64, f64)>,
}

/// Why a split pass failed.
#[derive(Debug)]
pub(crate) enum SplitError {
    /// Reading the samples failed.
    Read(ReadError),
    /// An impossible level count.
    Param(ParamError),
    /// The series of a column (0-based among the selected) is unusable.
    Series(usize, SeriesError),
}

impl From<ReadError> for SplitError {
    fn from(e: ReadError) -> Self {
        SplitError::Read(e)
    }
}

/// Buffers of one worker, reused from part to part.
#[derive(Default)]
struct Buffers {
    bytes: Vec<u8>,
    /// Ring storage, one a column.
    rings: Vec<Vec<f64>>,
    /// The chunk's samples, a vector a column.
    cur: Vec<Vec<f64>>,
    /// The chunk's demeaned samples, a vector a column.
    y: Vec<Vec<f64>>,
    /// The samples `d` rows back (as read), for each lag `d` in use.
    lags: Vec<(usize, Vec<Vec<f64>>)>,
}

/// The per-level square sums of every selected column of `src` (J = `levels`, valid for its
/// length), in accumulators to [`finish`](HaarWvAccumulator::finish): the split pass of
/// [`binary_wavelet_variance`].
pub(crate) fn split_sums<S: Source>(
    src: &S,
    levels: usize,
    plan: &Plan,
) -> Result<Vec<ColumnSums>, SplitError> {
    debug_assert!(plan.part.is_power_of_two() && plan.part >= BLOCK);
    debug_assert!(plan.chunk % BLOCK == 0 && plan.chunk > 0);
    debug_assert!(plan.ring_levels >= 12, "lags of at least BLOCK samples");
    let n = src.rows();
    let k = src.columns();
    // the offset: the mean of the first 2048 samples, as the in-memory path takes it
    let mut bytes = Vec::new();
    let mut head = vec![Vec::new(); k];
    src.read(
        0,
        n.min(crate::variance::haar::BLOCK),
        &mut bytes,
        &mut head,
    )?;
    let offsets: Vec<f64> = head
        .iter()
        .map(|h| h.iter().sum::<f64>() / h.len() as f64)
        .collect();
    let parts = n.div_ceil(plan.part);
    let pool = Mutex::new(Vec::new());
    let threads = rayon::current_num_threads();
    let run = |p: usize, spread: Spread| {
        let t0 = p * plan.part;
        let t1 = (t0 + plan.part).min(n);
        run_part(src, t0, t1, &offsets, levels, plan, spread, &pool)
    };
    // one column: parts in parallel; several: parts in turn, columns in parallel (each part
    // in flight holds every column's rings); one part of one column: its pyramid split in
    // two halves run side by side. The same sums whichever.
    let results: Vec<Result<PartSums, SplitError>> = if parts > 1 && k < threads {
        (0..parts)
            .into_par_iter()
            .map(|p| run(p, Spread::Serial))
            .collect()
    } else {
        let spread = if k > 1 {
            Spread::Columns
        } else {
            let rings = levels.min(plan.ring_levels).min(n.ilog2() as usize);
            match split_level(rings, levels - levels.min(plan.ring_levels)) {
                Some(split) if threads > 1 => Spread::Levels(split),
                _ => Spread::Serial,
            }
        };
        // on a thread of the pool, so that the parallel steps of a part join there
        rayon::scope(|_| {
            let mut out = Vec::with_capacity(parts);
            for p in 0..parts {
                let r = run(p, spread);
                let failed = r.is_err();
                out.push(r);
                if failed {
                    break;
                }
            }
            out
        })
    };
    // the first error in part order is the first in the file
    let mut done = Vec::with_capacity(parts);
    for r in results {
        done.push(r?);
    }
    Ok(combine(done, levels))
}

/// The sums of one column of a split pass, in an accumulator to
/// [`finish`](HaarWvAccumulator::finish), with the column's smallest and largest sample.
pub(crate) struct ColumnSums {
    pub(crate) acc: HaarWvAccumulator,
    pub(crate) min: f64,
    pub(crate) max: f64,
}

/// Adds the parts' sums in part order, the lag-recurrence levels with the value they start
/// from, known now that every block sum is.
fn combine(parts: Vec<PartSums>, levels: usize) -> Vec<ColumnSums> {
    let k = parts[0].accs.len();
    let mut block_sums: Vec<Vec<f64>> = vec![Vec::new(); k];
    let mut extremes = vec![(f64::INFINITY, f64::NEG_INFINITY); k];
    for part in &parts {
        for (all, own) in block_sums.iter_mut().zip(&part.block_sums) {
            all.extend_from_slice(own);
        }
        for (all, own) in extremes.iter_mut().zip(&part.extremes) {
            *all = (all.0.min(own.0), all.1.max(own.1));
        }
    }
    let mut parts = parts.into_iter();
    let first = parts.next().expect("a non-empty series");
    let mut totals = first.accs;
    let mut tops: Vec<Vec<TopLevel>> = first.tops;
    for part in parts {
        for (total, acc) in totals.iter_mut().zip(&part.accs) {
            total.append(acc);
        }
        for (all, own) in tops.iter_mut().zip(part.tops) {
            all.extend(own);
        }
    }
    for ((total, tops), sums) in totals.iter_mut().zip(&tops).zip(&block_sums) {
        // level by level, parts in order
        for j in 1..=levels {
            for top in tops.iter().filter(|t| t.j == j) {
                total.add_level_sum(j, top.square_sum(sums));
            }
        }
    }
    totals
        .into_iter()
        .zip(extremes)
        .map(|(acc, (min, max))| ColumnSums { acc, min, max })
        .collect()
}

/// Applies `f` to every column's state, in parallel or in turn.
fn each_column<T: Send>(
    parallel: bool,
    states: &mut [T],
    f: impl Fn(usize, &mut T) -> Result<(), SplitError> + Sync,
) -> Result<(), SplitError> {
    if parallel {
        states
            .par_iter_mut()
            .enumerate()
            .try_for_each(|(c, s)| f(c, s))
    } else {
        states.iter_mut().enumerate().try_for_each(|(c, s)| f(c, s))
    }
}

/// One column's state in a part.
struct ColumnPart {
    acc: HaarWvAccumulator,
    tops: Vec<TopLevel>,
    block_sums: Vec<f64>,
    /// Smallest and largest sample of the part so far.
    extremes: (f64, f64),
}

/// How the work of one part is spread over the threads (never a change to the result).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Spread {
    /// One thread.
    Serial,
    /// The columns in parallel.
    Columns,
    /// One column, its pyramid split after this level ([`HaarWvAccumulator::upper_part`]): the
    /// levels below on one chunk while the levels above run the chunk before.
    Levels(usize),
}

/// The level after which to split the pyramid of a part run alone, `levels` levels run
/// through rings and `tops` levels by the lag recurrence, or `None` when there is too little
/// to split: the point that balances a rough cost of the two halves (the lower half also
/// reads the file and runs the lag recurrence). Only the schedule depends on it.
fn split_level(levels: usize, tops: usize) -> Option<usize> {
    // relative costs a sample: a level whose ring is past L1/L2 costs more
    let cost = |j: usize| if j <= 12 { 1.0 } else { 1.6 };
    let fixed = 3.0 + 2.5 * tops as f64;
    let total: f64 = (1..=levels).map(cost).sum::<f64>() + fixed;
    let mut lower = fixed;
    for k in 1..levels {
        lower += cost(k);
        if lower >= total / 2.0 {
            let other = total - lower;
            // the split is worth it only with work on both sides
            return (other >= total / 4.0).then_some(k);
        }
    }
    None
}

/// The chunk `[c0, c1)` of a part starting at `t0` of a pass of `levels` levels, `ring_levels`
/// of them through rings: read, then each column's pyramid (the lower half only, under a level
/// split), lag-recurrence levels `top_levels`, block sums and extremes.
#[allow(clippy::too_many_arguments)]
fn run_chunk<S: Source>(
    src: &S,
    t0: usize,
    c0: usize,
    c1: usize,
    offsets: &[f64],
    (levels, ring_levels): (usize, usize),
    top_levels: &[usize],
    parallel_columns: bool,
    buf: &mut Buffers,
    states: &mut [ColumnPart],
) -> Result<(), SplitError> {
    let len = c1 - c0;
    src.read(c0, len, &mut buf.bytes, &mut buf.cur)?;
    // the demeaned samples feed the lag recurrence and the block sums its start values come
    // from: with no level above the rings in the series, neither is needed
    let tops = levels > ring_levels;
    if tops {
        for (y, (cur, &offset)) in buf.y.iter_mut().zip(buf.cur.iter().zip(offsets)) {
            y.clear();
            y.extend(cur.iter().map(|&v| v - offset));
        }
    }
    // samples read back, for the levels that have started by the chunk's end
    for (d, lag) in buf.lags.iter_mut() {
        let needed = top_levels
            .iter()
            .any(|&j| TopLevel::start_of(j, t0) < c1 && lags_of(j).contains(d));
        if needed {
            read_lag(src, c0, len, *d, offsets, &mut buf.bytes, lag)?;
        }
    }
    let (cur, y, lags) = (&buf.cur, &buf.y, &buf.lags);
    let back = |d: usize, c: usize| -> &[f64] {
        lags.iter()
            .find(|(e, _)| *e == d)
            .map_or(&[][..], |(_, v)| &v[c][..])
    };
    each_column(parallel_columns, states, |c, s| {
        s.acc.push(&cur[c]).map_err(|e| SplitError::Series(c, e))?;
        for top in s.tops.iter_mut().filter(|t| t.start < c1) {
            let m = 1usize << (top.j - 1);
            top.push(c0, &y[c], back(m, c), back(2 * m, c), offsets[c]);
        }
        if tops {
            s.block_sums.extend(y[c].chunks(BLOCK).map(sum_plain));
        }
        let (lo, hi) = extremes(&cur[c]);
        s.extremes = (s.extremes.0.min(lo), s.extremes.1.max(hi));
        Ok(())
    })
}

/// The lags the lag recurrence of level `j` reads back.
fn lags_of(j: usize) -> [usize; 2] {
    [1usize << (j - 1), 1usize << j]
}

/// Smallest and largest of finite values, in eight lanes (a loop the compiler vectorises).
fn extremes(x: &[f64]) -> (f64, f64) {
    let (mut lo, mut hi) = ([f64::INFINITY; 8], [f64::NEG_INFINITY; 8]);
    let mut chunks = x.chunks_exact(8);
    for c in &mut chunks {
        for i in 0..8 {
            lo[i] = if c[i] < lo[i] { c[i] } else { lo[i] };
            hi[i] = if c[i] > hi[i] { c[i] } else { hi[i] };
        }
    }
    let rest = chunks.remainder();
    (
        rest.iter().chain(&lo).fold(f64::INFINITY, |a, &v| a.min(v)),
        rest.iter()
            .chain(&hi)
            .fold(f64::NEG_INFINITY, |a, &v| a.max(v)),
    )
}

/// Runs the part `[t0, t1)` of every column.
#[allow(clippy::too_many_arguments)]
fn run_part<S: Source>(
    src: &S,
    t0: usize,
    t1: usize,
    offsets: &[f64],
    levels: usize,
    plan: &Plan,
    spread: Spread,
    pool: &Mutex<Vec<Buffers>>,
) -> Result<PartSums, SplitError> {
    let k = offsets.len();
    let parallel_columns = spread == Spread::Columns;
    let mut buf = pool
        .lock()
        .ok()
        .and_then(|mut p| p.pop())
        .unwrap_or_default();
    buf.rings.resize_with(k, Vec::new);
    buf.cur.resize_with(k, Vec::new);
    buf.y.resize_with(k, Vec::new);
    // the levels above the rings with a kept coefficient in the part
    let top_levels: Vec<usize> = (plan.ring_levels + 1..=levels)
        .filter(|&j| (1usize << j) <= t1)
        .collect();
    let mut states = Vec::with_capacity(k);
    // a level split (one column, a part needing no priming): the lower half's rings stop at
    // the split
    let split = match spread {
        Spread::Levels(split) if k == 1 && t0 == 0 => Some(split),
        _ => None,
    };
    for (&offset, storage) in offsets.iter().zip(buf.rings.drain(..)) {
        let mut acc = HaarWvAccumulator::for_part_capped(
            levels,
            offset,
            t0,
            t1,
            storage,
            split.unwrap_or(plan.ring_levels),
        )
        .map_err(SplitError::Param)?;
        // the source checks every sample it reads
        acc.trust_finite();
        states.push(ColumnPart {
            acc,
            tops: top_levels.iter().map(|&j| TopLevel::new(j, t0)).collect(),
            block_sums: Vec::with_capacity((t1 - t0).div_ceil(BLOCK)),
            extremes: (f64::INFINITY, f64::NEG_INFINITY),
        });
    }
    // prime the rings from the samples before the part, in reads ending at t0 - i PRIME_ALIGN
    let active = states[0].acc.active_levels();
    if t0 > 0 && active > 0 {
        let mut from = t0.saturating_sub(1usize << active);
        while from < t0 {
            let to = (t0 - (t0 - from - 1) / PRIME_ALIGN * PRIME_ALIGN).min(t0);
            src.read(from, to - from, &mut buf.bytes, &mut buf.cur)?;
            let cur = &buf.cur;
            each_column(parallel_columns, &mut states, |c, s| {
                s.acc.prime(from, &cur[c]);
                Ok(())
            })?;
            from = to;
        }
    }
    let mut lags: Vec<usize> = top_levels.iter().flat_map(|&j| lags_of(j)).collect();
    lags.sort_unstable();
    lags.dedup();
    buf.lags.retain(|(d, _)| lags.contains(d));
    for &d in &lags {
        if !buf.lags.iter().any(|(e, _)| *e == d) {
            buf.lags.push((d, vec![Vec::new(); k]));
        }
    }
    // the upper half of a level split runs each chunk's scaling coefficients while the lower
    // half runs the next chunk
    let mut upper = match split {
        Some(split) if split == active => {
            states[0].acc.emit();
            let mut upper = HaarWvAccumulator::upper_part(levels, t1, split + 1, plan.ring_levels)
                .map_err(SplitError::Param)?;
            upper.trust_finite();
            Some(upper)
        }
        _ => None,
    };
    let mut handoff: Vec<f64> = Vec::new();
    let mut c0 = t0;
    while c0 < t1 {
        let c1 = (c0 + plan.chunk).min(t1);
        let mut chunk = || {
            run_chunk(
                src,
                t0,
                c0,
                c1,
                offsets,
                (levels, plan.ring_levels),
                &top_levels,
                parallel_columns,
                &mut buf,
                &mut states,
            )
        };
        match &mut upper {
            Some(up) => {
                let (lower, higher) = rayon::join(chunk, || up.push(&handoff));
                lower?;
                higher.map_err(|e| SplitError::Series(0, e))?;
                handoff = states[0].acc.take_emitted(handoff);
            }
            None => chunk()?,
        }
        c0 = c1;
    }
    let mut part = PartSums {
        accs: Vec::with_capacity(k),
        tops: Vec::with_capacity(k),
        block_sums: Vec::with_capacity(k),
        extremes: Vec::with_capacity(k),
    };
    for (c, mut s) in states.into_iter().enumerate() {
        buf.rings
            .push(s.acc.close_part().map_err(|e| SplitError::Series(c, e))?);
        if let Some(up) = upper.as_mut().filter(|_| c == 0) {
            // the last chunk's coefficients, then the partial block the close ran
            let last = s.acc.take_emitted(Vec::new());
            for v in [&handoff, &last] {
                up.push(v).map_err(|e| SplitError::Series(0, e))?;
            }
            up.close_part().map_err(|e| SplitError::Series(0, e))?;
            s.acc.append_upper(up);
        }
        part.accs.push(s.acc);
        for top in &mut s.tops {
            top.scratch = Vec::new();
        }
        part.tops.push(s.tops);
        part.block_sums.push(s.block_sums);
        part.extremes.push(s.extremes);
    }
    if let Ok(mut p) = pool.lock() {
        p.push(buf);
    }
    Ok(part)
}

/// The samples `d` rows before `[c0, c0 + len)` of every column into `out`, as read (rows
/// checked by their own part); before the series start, the column's offset (a demeaned 0).
fn read_lag<S: Source>(
    src: &S,
    c0: usize,
    len: usize,
    d: usize,
    offsets: &[f64],
    bytes: &mut Vec<u8>,
    out: &mut [Vec<f64>],
) -> Result<(), ReadError> {
    let before = d.saturating_sub(c0).min(len);
    if before < len {
        src.read_again(c0 + before - d, len - before, bytes, out)?;
    } else {
        out.iter_mut().for_each(Vec::clear);
    }
    if before > 0 {
        for (v, &offset) in out.iter_mut().zip(offsets) {
            v.splice(0..0, std::iter::repeat(offset).take(before));
        }
    }
    Ok(())
}

/// A level above the rings, in one part: `W_{j,t} = E_t / 2^j` with `E_t = A_t - B_t`, `A_t`
/// the sum of the `m = 2^{j-1}` demeaned samples up to `t` and `B_t` that of the `m` before
/// them (zeros before the series start), which follows the recurrence
/// `E_t = E_{t-1} + y_t - 2 y_{t-m} + y_{t-2m}` on samples read back `m` and `2m` rows.
///
/// The part runs it from its start `s` (the part's, or the block of the level's first kept
/// coefficient) as `L_t = E_t - E_{s-1}`, since `E_{s-1}` needs the samples of the earlier
/// parts; it keeps the count `n`, `Σ L` and `Σ L²` over the kept coefficients, and the square
/// sum `Σ E² = n E_{s-1}² + 2 E_{s-1} Σ L + Σ L²` is formed once every block sum is known
/// ([`square_sum`](Self::square_sum)). With `m` at least a quarter of a part (`2^20` against
/// `2^22`), `n E_{s-1}²` is at most a few times `Σ E²`, so this form costs no accuracy.
#[derive(Debug, Clone)]
struct TopLevel {
    /// Level (1-based).
    j: usize,
    /// First sample run, a multiple of [`BLOCK`].
    start: usize,
    /// `L` at the end of the samples run so far.
    carry: f64,
    /// Kept coefficients so far.
    count: u64,
    /// `Σ L` over them.
    s1: NeumaierSum,
    /// `Σ L²` over them.
    s2: NeumaierSum,
    /// The `L` of one block.
    scratch: Vec<f64>,
}

impl TopLevel {
    /// First sample run by level `j` in a part starting at `t0`: the block of its first kept
    /// coefficient (`t = 2^j - 1`) when that comes later.
    fn start_of(j: usize, t0: usize) -> usize {
        t0.max(((1usize << j) - 1) / BLOCK * BLOCK)
    }

    fn new(j: usize, t0: usize) -> Self {
        Self {
            j,
            start: Self::start_of(j, t0),
            carry: 0.0,
            count: 0,
            s1: NeumaierSum::default(),
            s2: NeumaierSum::default(),
            scratch: Vec::with_capacity(BLOCK),
        }
    }

    /// Runs the chunk starting at sample `c0` (a multiple of [`BLOCK`]): demeaned samples `y`,
    /// and the samples `m` and `2m` rows back as read (`offset` not yet subtracted).
    fn push(&mut self, c0: usize, y: &[f64], back_m: &[f64], back_2m: &[f64], offset: f64) {
        let from = self.start.saturating_sub(c0).min(y.len());
        let first_kept = (1usize << self.j) - 1;
        for (b, ((y, ym), y2m)) in y[from..]
            .chunks(BLOCK)
            .zip(back_m[from..].chunks(BLOCK))
            .zip(back_2m[from..].chunks(BLOCK))
            .enumerate()
        {
            let b0 = c0 + from + b * BLOCK;
            let skip = first_kept.saturating_sub(b0).min(y.len());
            let (carry, s1, s2) =
                top_block(&mut self.scratch, self.carry, y, ym, y2m, offset, skip);
            self.carry = carry;
            if skip < y.len() {
                self.count += (y.len() - skip) as u64;
                self.s1.add(s1);
                self.s2.add(s2);
            }
        }
    }

    /// `Σ W²` of the part: `E_{s-1}` from the block sums of the demeaned series.
    fn square_sum(&self, block_sums: &[f64]) -> f64 {
        let m = 1usize << (self.j - 1);
        let window = |from: usize, to: usize| -> f64 {
            // blocks [from, to) of samples, both multiples of BLOCK (or clipped at 0)
            let mut s = NeumaierSum::default();
            for &v in &block_sums[from / BLOCK..to / BLOCK] {
                s.add(v);
            }
            s.total()
        };
        let s = self.start;
        let a = window(s.saturating_sub(m), s);
        let b = window(s.saturating_sub(2 * m), s.saturating_sub(m));
        let e = a - b;
        let n = self.count as f64;
        let (s1, s2) = (self.s1.total(), self.s2.total());
        // W = E / 2^j: scale by 4^-j (exact)
        (n * e * e + 2.0 * e * s1 + s2) * elementary::exp2(-2.0 * self.j as f64)
    }
}

crate::variance::simd::multiversion! {
    /// One block of [`TopLevel::push`]: `L` from `carry` on, into `scratch`; returns the
    /// carry after the block, and `Σ L`, `Σ L²` from index `skip` on. `xm`, `x2m` are the
    /// samples `m` and `2m` back, `offset` not yet subtracted.
    fn top_block(
        scratch: &mut Vec<f64>,
        carry: f64,
        y: &[f64],
        xm: &[f64],
        x2m: &[f64],
        offset: f64,
        skip: usize,
    ) -> (f64, f64, f64) => top_block_impl
}

#[inline(always)]
fn top_block_impl(
    scratch: &mut Vec<f64>,
    carry: f64,
    y: &[f64],
    xm: &[f64],
    x2m: &[f64],
    offset: f64,
    skip: usize,
) -> (f64, f64, f64) {
    let len = y.len();
    scratch.clear();
    scratch.extend(
        y.iter()
            .zip(&xm[..len])
            .zip(&x2m[..len])
            .map(|((&v, &u), &w)| (v - 2.0 * (u - offset)) + (w - offset)),
    );
    let carry = if len == BLOCK {
        // four chains, one a quarter, started from the carry plus the quarter totals
        const Q: usize = BLOCK / 4;
        let totals = [
            sum_plain(&scratch[..Q]),
            sum_plain(&scratch[Q..2 * Q]),
            sum_plain(&scratch[2 * Q..3 * Q]),
            sum_plain(&scratch[3 * Q..]),
        ];
        let mut s = [carry, 0.0, 0.0, 0.0];
        for l in 1..4 {
            s[l] = s[l - 1] + totals[l - 1];
        }
        let after = s[3] + totals[3];
        let (q0, rest) = scratch.split_at_mut(Q);
        let (q1, rest) = rest.split_at_mut(Q);
        let (q2, q3) = rest.split_at_mut(Q);
        for i in 0..Q {
            s[0] += q0[i];
            s[1] += q1[i];
            s[2] += q2[i];
            s[3] += q3[i];
            q0[i] = s[0];
            q1[i] = s[1];
            q2[i] = s[2];
            q3[i] = s[3];
        }
        after
    } else {
        // the series' last, partial block
        let mut s = carry;
        for v in scratch.iter_mut() {
            s += *v;
            *v = s;
        }
        s
    };
    let kept = &scratch[skip.min(len)..];
    (carry, sum_plain(kept), sum_squares(kept))
}

/// The streamed wavelet variance of a recording read in one pass and spooled
/// ([`StreamedTable`]): its spool read like any raw binary recording.
impl StreamedTable {
    /// The classical Haar MODWT wavelet variance of the selected columns `columns` (0-based
    /// among [`names`](Self::names)), streamed from the spool
    /// ([`binary_columns_wv`]: the same bits as for a raw binary file of the same values).
    ///
    /// # Errors
    /// As [`binary_columns_wv`], naming the recording (not the spool).
    pub(crate) fn columns_wv(
        &self,
        columns: &[usize],
        freq_hz: f64,
        opts: &WvOptions,
    ) -> Result<Vec<StreamedColumn>, ReadError> {
        let one_based: Vec<usize> = columns.iter().map(|c| c + 1).collect();
        let (path, layout) = self.spool();
        binary_columns_wv(path, &layout, &one_based, freq_hz, opts).map_err(|e| self.rename(e))
    }

    /// `columns_wv` of every selected column, the WVs only.
    ///
    /// # Errors
    /// As `columns_wv`.
    pub fn wavelet_variance(
        &self,
        freq_hz: f64,
        opts: &WvOptions,
    ) -> Result<Vec<WaveletVariance>, ReadError> {
        let all: Vec<usize> = (0..self.names.len()).collect();
        Ok(self
            .columns_wv(&all, freq_hz, opts)?
            .into_iter()
            .map(|c| c.wv)
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::imu::InputFormat;

    /// Columns in memory.
    struct MemorySource<'a>(Vec<&'a [f64]>);

    impl Source for MemorySource<'_> {
        fn rows(&self) -> usize {
            self.0[0].len()
        }

        fn columns(&self) -> usize {
            self.0.len()
        }

        fn read(
            &self,
            row: usize,
            n: usize,
            _bytes: &mut Vec<u8>,
            out: &mut [Vec<f64>],
        ) -> Result<(), ReadError> {
            for (o, x) in out.iter_mut().zip(&self.0) {
                o.clear();
                o.extend_from_slice(&x[row..row + n]);
            }
            Ok(())
        }
    }

    /// A biased random walk plus noise (every level carries signal, the offset matters), or
    /// white noise.
    fn series(n: usize, seed: u64, walk: bool) -> Vec<f64> {
        let mut state = seed;
        let mut level = 0.0;
        (0..n)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let u = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                if walk {
                    level += 0.01 * u;
                }
                -9.81 + level + u
            })
            .collect()
    }

    /// Parts of 2^14 samples and rings up to level 12: a series of 2^16 + 12345 samples takes
    /// five parts and 16 levels, four of them by the lag recurrence.
    fn small(chunk: usize) -> Plan {
        Plan {
            part: 1 << 14,
            chunk,
            ring_levels: 12,
        }
    }

    fn write_f64(dir: &Path, columns: &[&[f64]]) -> std::path::PathBuf {
        let path = dir.join("x.f64");
        let mut bytes = Vec::new();
        for t in 0..columns[0].len() {
            for c in columns {
                bytes.extend_from_slice(&c[t].to_le_bytes());
            }
        }
        std::fs::write(&path, bytes).unwrap();
        path
    }

    fn layout(ncols: usize) -> BinaryLayout {
        BinaryLayout {
            format: InputFormat::F64,
            ncols,
            names: (1..=ncols).map(|c| format!("c{c}")).collect(),
        }
    }

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn split_streaming_is_the_same_bits_on_any_thread_count_and_read_size() {
        let n = (1 << 16) + 12_345;
        let (a, b) = (series(n, 1, true), series(n, 2, false));
        let dir = tempfile::tempdir().unwrap();
        let path = write_f64(dir.path(), &[&a, &b]);
        let run = |threads: usize, chunk: usize, columns: &[usize]| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    binary_wv_with(
                        &path,
                        &layout(2),
                        columns,
                        100.0,
                        &WvOptions::default(),
                        &small(chunk),
                    )
                    .unwrap()
                    .into_iter()
                    .map(|c| c.wv)
                    .collect::<Vec<_>>()
                })
        };
        let base = run(1, BLOCK, &[1, 2]);
        assert_eq!(base[0].levels(), 16);
        for threads in [1, 2, 3] {
            for chunk in [BLOCK, 3 * BLOCK, 1 << 16] {
                // one column: parts in parallel; two: parts in turn, columns in parallel
                assert_eq!(run(threads, chunk, &[1, 2]), base, "{threads} {chunk}");
                assert_eq!(run(threads, chunk, &[2])[0], base[1], "{threads} {chunk}");
            }
        }
    }

    #[test]
    fn split_streaming_matches_the_in_memory_wavelet_variance() {
        for (n, walk) in [((1 << 16) + 12_345, true), (3 << 15, false), (50_000, true)] {
            let x = series(n, n as u64, walk);
            let memory = crate::wavelet_variance(&x, 1.0, &WvOptions::default()).unwrap();
            let levels = memory.levels();
            let src = MemorySource(vec![&x]);
            let split = split_sums(&src, levels, &small(1 << 15)).unwrap();
            let column = split.into_iter().next().unwrap();
            assert_eq!(column.min, x.iter().copied().fold(f64::INFINITY, f64::min));
            assert_eq!(
                column.max,
                x.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            );
            let split = column.acc.finish(1.0, 0.05).unwrap();
            assert_eq!(split.n_coefficients(), memory.n_coefficients());
            for j in 0..levels {
                let r = rel(split.wv()[j], memory.wv()[j]);
                assert!(r < 1e-12, "n = {n}, level {}: {r:e}", j + 1);
            }
        }
    }

    #[test]
    fn one_part_is_the_single_stream_on_any_thread_count() {
        // below a part and the ring levels: the accumulator of the whole series, bit for bit,
        // whether the pyramid runs on one thread or split in two halves side by side
        let x = series(70_000, 5, true);
        let mut acc = HaarWvAccumulator::new(16).unwrap();
        acc.push(&x).unwrap();
        let one = acc.finish(1.0, 0.05).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = write_f64(dir.path(), &[&x]);
        let opts = WvOptions {
            levels: Some(16),
            ..WvOptions::default()
        };
        for threads in [1, 2, 3] {
            let streamed = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| binary_wavelet_variance(&path, &layout(1), &[1], 1.0, &opts))
                .unwrap();
            assert_eq!(streamed[0], one, "{threads} threads");
        }
    }

    #[test]
    fn one_part_split_in_levels_is_the_same_on_any_thread_count_and_read_size() {
        // one part of 2^17 samples with rings up to level 12 and four levels by the lag
        // recurrence: one thread, or the pyramid in two halves (one column), or the columns in
        // parallel (two)
        let n = 100_000;
        let (a, b) = (series(n, 8, true), series(n, 9, false));
        let dir = tempfile::tempdir().unwrap();
        let path = write_f64(dir.path(), &[&a, &b]);
        let plan = |chunk| Plan {
            part: 1 << 17,
            chunk,
            ring_levels: 12,
        };
        let run = |threads: usize, chunk: usize, columns: &[usize]| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    binary_wv_with(
                        &path,
                        &layout(2),
                        columns,
                        1.0,
                        &WvOptions::default(),
                        &plan(chunk),
                    )
                    .unwrap()
                })
        };
        let base = run(1, BLOCK, &[1, 2]);
        assert_eq!(base[0].wv.levels(), 16);
        for threads in [1, 2, 3] {
            for chunk in [BLOCK, 5 * BLOCK, 1 << 16] {
                assert_eq!(run(threads, chunk, &[1, 2]), base, "{threads} {chunk}");
                assert_eq!(run(threads, chunk, &[1])[0], base[0], "{threads} {chunk}");
            }
        }
        let memory = crate::wavelet_variance(&a, 1.0, &WvOptions::default()).unwrap();
        for j in 0..16 {
            assert!(
                rel(base[0].wv.wv()[j], memory.wv()[j]) < 1e-12,
                "level {}",
                j + 1
            );
        }
    }

    #[test]
    fn errors_name_the_file_and_the_column() {
        let dir = tempfile::tempdir().unwrap();
        let x = series(5000, 3, false);
        let flat = vec![2.5; 5000];
        let path = write_f64(dir.path(), &[&x, &flat]);
        let opts = WvOptions::default();
        let run = |columns: &[usize], opts: &WvOptions| {
            binary_wavelet_variance(&path, &layout(2), columns, 1.0, opts)
        };
        let e = run(&[1, 2], &opts).unwrap_err();
        assert!(
            matches!(&e, ReadError::Series { column, source: SeriesError::Constant { .. }, .. } if column == "c2"),
            "{e}"
        );
        assert!(
            e.to_string()
                .contains("x.f64: column c2: series is constant"),
            "{e}"
        );
        assert!(matches!(
            run(&[3], &opts),
            Err(ReadError::ColumnOutOfRange {
                index: 3,
                ncols: 2,
                ..
            })
        ));
        assert!(matches!(run(&[], &opts), Err(ReadError::InvalidOption(_))));
        let robust = WvOptions {
            robust: Some(crate::RobustOptions::default()),
            ..opts
        };
        assert!(matches!(
            run(&[1], &robust),
            Err(ReadError::InvalidOption(_))
        ));
        let too_many = WvOptions {
            levels: Some(13),
            ..opts
        };
        assert!(matches!(
            run(&[1], &too_many),
            Err(ReadError::Series {
                source: SeriesError::TooShort { .. },
                ..
            })
        ));
        let mut y = x.clone();
        y[4321] = f64::NAN;
        let path = write_f64(dir.path(), &[&x, &y]);
        let e = binary_wavelet_variance(&path, &layout(2), &[1, 2], 1.0, &opts).unwrap_err();
        assert!(
            matches!(
                e,
                ReadError::BinaryNonFinite {
                    index: 4321,
                    column: 2,
                    ..
                }
            ),
            "{e}"
        );
        std::fs::write(&path, [0u8; 8 * 5 + 3]).unwrap();
        assert!(matches!(
            binary_wavelet_variance(&path, &layout(1), &[1], 1.0, &opts),
            Err(ReadError::BinarySize { .. })
        ));
    }
}
