//! In-memory Haar MODWT kernel behind [`wavelet_variance`](crate::wavelet_variance)
//! (docs/methods.md §1.2, §1.3, §1.5): the classical Haar wavelet variance by a cache-blocked
//! pyramid split in time (low levels) and in phase (high levels).
//!
//! The pyramid is the one of [`HaarWvAccumulator`](crate::HaarWvAccumulator) with two changes
//! that do not change a single rounding: the scaling coefficients are kept as window *sums*
//! (`V_j = V_{j-1,t} + V_{j-1,t-h}`, `2^j` times the MODWT's window means) and the wavelet
//! coefficient is the unscaled difference `V_{j-1,t} - V_{j-1,t-h}` (`2^j W_{j,t}`), whose
//! square sum is scaled by `4^-j` once per level. Scaling by a power of two is exact, so every
//! coefficient is bit-identical to the accumulator's (barring overflow or underflow, which the
//! caller detects); only the order in which the squares are added differs. Each level is one
//! branch-free, auto-vectorised loop (2 loads, 1–2 stores, 4 flops per coefficient).
//!
//! Low levels run over blocks of [`BLOCK`] samples that stay in L1 (stage A); high levels,
//! whose lag rings would not fit any cache, run per phase on short sub-series (stage B, see
//! [`haar_square_sums`]). The work is cut into parts and tiles fixed by N alone (never by the
//! thread count) and the per-level sums are added in that fixed order: the result is the same on
//! any number of threads.

use crate::math::elementary;
use crate::math::sum::NeumaierSum;

/// Samples per block of stage A: the block's input and output (2 x 16 KiB) and the rings of the
/// small levels stay in a 48 KiB L1 cache. Must divide `2^11` (stage B rows).
pub(crate) const BLOCK: usize = 2048;

/// Lanes of the vectorised accumulations: four 2-wide SSE2 chains hide the add latency.
const LANES: usize = 8;

/// Total of the lane accumulators. Even and odd lanes are added separately first: that is the
/// order of two-wide vector registers, so the compiler keeps lanes `(2i, 2i + 1)` in one register
/// (any other order makes it shuffle in the hot loop).
#[inline(always)]
fn lane_total(acc: &[f64; LANES]) -> f64 {
    let even = (acc[0] + acc[2]) + (acc[4] + acc[6]);
    let odd = (acc[1] + acc[3]) + (acc[5] + acc[7]);
    even + odd
}

/// Levels run by the time-blocked pyramid (stage A) for a series of length `n`: their lag rings
/// (`2^L` values in all) stay in L1/L2, and stage B's sub-series (`n / 2^L` samples per phase)
/// stay short enough for L2: `L = max(11, ceil(log2 n) - 12)`.
fn low_levels(n: usize) -> usize {
    let ceil_log2 = usize::BITS - n.saturating_sub(1).leading_zeros();
    (ceil_log2 as usize).saturating_sub(12).max(11)
}

/// Samples per time part of stage A (a multiple of [`BLOCK`]); parts run in parallel and each
/// is warmed up on the `2^L` samples before it. Raised to `2^L` for `L > 16` (N > 2^28), so
/// that a part always holds whole rows of stage B.
const PART: usize = 1 << 16;

/// Phases per tile of stage B: 16 doubles, two cache lines per row.
const TILE: usize = 16;

/// What the pyramid of [`haar_pass`] does with the boundary-free coefficients of each level.
///
/// The coefficients handed over are unscaled: `2^j W_{j,t}` (exact powers of two away from the
/// MODWT's). A pass creates one sink per part and per tile and merges them in a fixed order.
pub(crate) trait LevelSink: Send {
    /// With `true` the kernels hand over the coefficients ([`push`](Self::push)), otherwise
    /// only the sum of their squares per block ([`add_square_sum`](Self::add_square_sum)).
    const COEFFICIENTS: bool;
    /// Sum of squared unscaled coefficients of a block of level `j` (1-based).
    fn add_square_sum(&mut self, j: usize, sum: f64);
    /// Unscaled coefficients of level `j` (1-based).
    fn push(&mut self, j: usize, w: &[f64]);
    /// Appends a sink of a later part of the pass.
    fn merge(&mut self, later: &Self);
}

/// Per-level compensated sums of squared unscaled coefficients: the classical WV.
pub(crate) struct SquareSums(Vec<NeumaierSum>);

impl LevelSink for SquareSums {
    const COEFFICIENTS: bool = false;
    fn add_square_sum(&mut self, j: usize, sum: f64) {
        self.0[j - 1].add(sum);
    }
    fn push(&mut self, j: usize, w: &[f64]) {
        self.0[j - 1].add(w.iter().map(|v| v * v).sum());
    }
    fn merge(&mut self, later: &Self) {
        for (a, b) in self.0.iter_mut().zip(&later.0) {
            a.add(b.total());
        }
    }
}

/// Per-level sums of squared Haar MODWT wavelet coefficients `sum_t W_{j,t}^2` over the
/// boundary-free `t >= 2^j - 1` (docs/methods.md §1.3, §1.5), `j = 1..=levels`, of `x - offset`, by
/// [`haar_pass`].
///
/// Non-finite sums (window sums or squares overflowing for data near `f64::MAX`, or a
/// non-finite sample) are returned as they are; the caller checks.
pub(crate) fn haar_square_sums(x: &[f64], levels: usize, offset: f64) -> Vec<f64> {
    let sums = haar_pass(x, levels, offset, || {
        SquareSums(vec![NeumaierSum::default(); levels])
    });
    sums.0
        .iter()
        .zip(1..)
        // the kernels square 2^j W: scale by 4^-j (exact)
        .map(|(s, j)| s.total() * elementary::exp2(-2.0 * j as f64))
        .collect()
}

/// The Haar MODWT pyramid of `x - offset` (docs/methods.md §1.2), levels `1..=levels`, feeding
/// every level's boundary-free coefficients (docs/methods.md §1.3) to sinks made by `make`.
///
/// Stage A runs levels `1..=L` ([`low_levels`]) as a pyramid over blocks of [`BLOCK`] samples,
/// in parts of [`PART`] samples; each part first runs the pyramid, without counting, over the
/// `2^L` samples before it, which reproduces the lag rings of a single pass bit for bit. It
/// stores `V_L`. Stage B runs levels `L+1..=J` on `V_L`: their lags are multiples of `2^L`, so
/// the series splits into `2^L` independent phases `r` (samples `r, r + 2^L, ...`), each a Haar
/// pyramid with lags `1, 2, 4, ...` on a short sub-series; tiles of [`TILE`] adjacent phases run
/// vectorised across phases. Every coefficient is the one of a single sequential pyramid; the
/// sinks are merged in a fixed order (parts, then tiles), so the result does not depend on the
/// thread count.
pub(crate) fn haar_pass<S: LevelSink>(
    x: &[f64],
    levels: usize,
    offset: f64,
    make: impl Fn() -> S + Sync,
) -> S {
    use rayon::prelude::*;
    let n = x.len();
    let low = levels.min(low_levels(n));
    let stage_b_levels = levels > low;
    let part_len = PART.max(1usize << low);
    let parts: Vec<(S, Vec<f64>)> = (0..n.div_ceil(part_len))
        .into_par_iter()
        .map(|p| {
            stage_a(
                x,
                p * part_len,
                part_len,
                low,
                offset,
                stage_b_levels,
                make(),
            )
        })
        .collect();
    let mut parts = parts.into_iter();
    let (mut total, first_region) = parts.next().expect("a non-empty series");
    let mut regions = vec![first_region];
    for (sink, region) in parts {
        total.merge(&sink);
        regions.push(region);
    }
    if stage_b_levels {
        let regions: Vec<&[f64]> = regions.iter().map(Vec::as_slice).collect();
        let tiles: Vec<S> = (0..(1usize << low) / TILE)
            .into_par_iter()
            .map(|g| stage_b(&regions, n, g, low, levels, make()))
            .collect();
        for tile in &tiles {
            total.merge(tile);
        }
    }
    total
}

/// Stage A on the part starting at `t0` (`part_len` samples, or what is left): levels
/// `1..=levels` into `sink`. With `keep`, also returns `V_levels` of the part in stage B's
/// layout: the part's rows `k` (samples `k 2^L + r`) tile by tile, `region[g][k][lane]` with
/// phase `r = g TILE + lane`.
fn stage_a<S: LevelSink>(
    x: &[f64],
    t0: usize,
    part_len: usize,
    levels: usize,
    offset: f64,
    keep: bool,
    mut sink: S,
) -> (S, Vec<f64>) {
    let t1 = (t0 + part_len).min(x.len());
    let stride = 1usize << levels;
    let rows = (t1 - t0).div_ceil(stride);
    let mut region = if keep {
        vec![0.0f64; rows * stride]
    } else {
        Vec::new()
    };
    let mut rings: Vec<Vec<f64>> = (1..=levels).map(|j| vec![0.0; 1usize << (j - 1)]).collect();
    let mut pos = vec![0usize; levels];
    let mut cur = vec![0.0f64; BLOCK];
    let mut next = vec![0.0f64; BLOCK];
    let mut diff = if S::COEFFICIENTS {
        vec![0.0f64; BLOCK]
    } else {
        Vec::new()
    };
    // warm-up: the pyramid over the 2^L samples before the part fills the rings exactly as a
    // single pass from t = 0 would (rings start at zero = the pyramid's pre-start values)
    let warm = t0.saturating_sub(stride);
    let mut t = warm;
    while t < t1 {
        let b = BLOCK
            .min(t1 - t)
            .min(if t < t0 { t0 - t } else { usize::MAX });
        for (c, &v) in cur[..b].iter_mut().zip(&x[t..t + b]) {
            *c = v - offset;
        }
        for j in 1..=levels {
            // the first boundary-free coefficient of level j is at t = 2^j - 1 (docs/methods.md
            // §1.3)
            let skip = if t < t0 {
                b
            } else {
                ((1usize << j) - 1).saturating_sub(t).min(b)
            };
            if S::COEFFICIENTS {
                level_block::<true>(
                    &cur[..b],
                    &mut next[..b],
                    &mut rings[j - 1],
                    &mut pos[j - 1],
                    skip,
                    &mut diff[..b],
                );
                if skip < b {
                    sink.push(j, &diff[skip..b]);
                }
            } else {
                let ss = level_block::<false>(
                    &cur[..b],
                    &mut next[..b],
                    &mut rings[j - 1],
                    &mut pos[j - 1],
                    skip,
                    &mut [],
                );
                if skip < b {
                    sink.add_square_sum(j, ss);
                }
            }
            std::mem::swap(&mut cur, &mut next);
        }
        if keep && t >= t0 {
            // a block lies within one row (BLOCK divides 2^L, parts start on rows)
            let k = (t - t0) / stride;
            let r = (t - t0) % stride;
            let mut pieces = cur[..b].chunks_exact(TILE);
            for (i, piece) in (&mut pieces).enumerate() {
                let at = ((r / TILE + i) * rows + k) * TILE;
                let dst: &mut [f64; TILE] =
                    (&mut region[at..at + TILE]).try_into().expect("a tile row");
                *dst = piece.try_into().expect("a tile row");
            }
            let rest = pieces.remainder();
            if !rest.is_empty() {
                let at = ((r + b) / TILE * rows + k) * TILE;
                region[at..at + rest.len()].copy_from_slice(rest);
            }
        }
        t += b;
    }
    (sink, region)
}

/// Stage B on tile `g` (phases `g TILE .. (g + 1) TILE`) of `V_low`, given as the parts' regions
/// of [`stage_a`]: levels `low+1..=levels` into `sink`.
fn stage_b<S: LevelSink>(
    regions: &[&[f64]],
    n: usize,
    g: usize,
    low: usize,
    levels: usize,
    mut sink: S,
) -> S {
    let stride = 1usize << low;
    let r0 = g * TILE;
    // rows valid for every phase of the tile, and the rows of the longest phase
    let rows_full = (n - (r0 + TILE - 1)).div_ceil(stride);
    let rows = (n - r0).div_ceil(stride);
    let mut tile = Vec::with_capacity(rows * TILE);
    for region in regions {
        let part_rows = region.len() / stride;
        tile.extend_from_slice(&region[g * part_rows * TILE..(g + 1) * part_rows * TILE]);
    }
    tile.truncate(rows * TILE);
    let mut diff = Vec::new();
    for j in low + 1..=levels {
        let lag = 1usize << (j - 1 - low);
        // rows before first_row hold boundary coefficients (docs/methods.md §1.3): t = r + k 2^low
        // is kept iff k >= 2^{j-low}, or k = 2^{j-low} - 1 for the last phase r = 2^low - 1
        let first_row = 1usize << (j - low);
        let mut tail = 0.0;
        diff.clear();
        // the partially valid last row (phases past the end of the series are ignored)
        if rows > rows_full {
            let k = rows - 1;
            for lane in 0..TILE {
                if k * stride + r0 + lane < n && k >= lag {
                    let (a, b) = (tile[k * TILE + lane], tile[(k - lag) * TILE + lane]);
                    if k >= first_row || (k + 1 == first_row && r0 + lane + 1 == stride) {
                        tail += (a - b) * (a - b);
                        diff.push(a - b);
                    }
                    tile[k * TILE + lane] = a + b;
                }
            }
        }
        let main = if S::COEFFICIENTS {
            tile_rows::<true>(&mut tile, lag, first_row, rows_full, &mut diff)
        } else {
            tile_rows::<false>(&mut tile, lag, first_row, rows_full, &mut diff)
        };
        // boundary rows: update the scaling coefficients, count nothing (but the last phase's
        // first kept row)
        for k in (lag..first_row.min(rows_full)).rev() {
            let (older, newer) = tile.split_at_mut(k * TILE);
            for lane in 0..TILE {
                let old = older[(k - lag) * TILE + lane];
                if k + 1 == first_row && r0 + lane + 1 == stride {
                    tail += (newer[lane] - old) * (newer[lane] - old);
                    diff.push(newer[lane] - old);
                }
                newer[lane] += old;
            }
        }
        if S::COEFFICIENTS {
            sink.push(j, &diff);
        } else {
            sink.add_square_sum(j, main + tail);
        }
    }
    sink
}

/// Rows `lo..hi` of a stage-B tile at one level, newest first, in place: row `k` becomes
/// `row k + row k - lag` (the scaling coefficients of the level). Returns the sum of the squared
/// differences `row k - row k - lag` (the unscaled wavelet coefficients), or with `D` appends the
/// differences to `diff` (and returns 0). Row `k - lag` is read before it is overwritten;
/// `lo >= lag`.
#[inline(never)]
fn tile_rows<const D: bool>(
    tile: &mut [f64],
    lag: usize,
    lo: usize,
    hi: usize,
    diff: &mut Vec<f64>,
) -> f64 {
    let mut acc = [0.0f64; TILE];
    for k in (lo..hi).rev() {
        let (older, newer) = tile.split_at_mut(k * TILE);
        let new: &mut [f64; TILE] = (&mut newer[..TILE]).try_into().expect("a full tile row");
        let old: &[f64; TILE] = older[(k - lag) * TILE..(k - lag + 1) * TILE]
            .try_into()
            .expect("a full tile row");
        if D {
            let mut w = [0.0f64; TILE];
            for g in 0..TILE {
                w[g] = new[g] - old[g];
                new[g] += old[g];
            }
            diff.extend_from_slice(&w);
        } else {
            for g in 0..TILE {
                let w = new[g] - old[g];
                acc[g] += w * w;
                new[g] += old[g];
            }
        }
    }
    // even and odd lanes apart: the two-wide register order (see `lane_total`)
    let mut even = 0.0;
    let mut odd = 0.0;
    for pair in acc.chunks_exact(2) {
        even += pair[0];
        odd += pair[1];
    }
    even + odd
}

/// One pyramid level over a block: `out = V_j` from `cur = V_{j-1}`, the lags `V_{j-1,t-h}`
/// taken from the ring (length `h`, oldest at `*pos`) for the first `h` samples and from `cur`
/// after; updates the ring. Returns the sum of squared differences `V_{j-1,t} - V_{j-1,t-h}`
/// from index `skip` on, or with `D` writes every difference to `diff` instead (and returns 0).
#[inline]
fn level_block<const D: bool>(
    cur: &[f64],
    out: &mut [f64],
    ring: &mut [f64],
    pos: &mut usize,
    skip: usize,
    diff: &mut [f64],
) -> f64 {
    let h = ring.len();
    let b = cur.len();
    if h >= b {
        // all lags in the ring; with full blocks and h a multiple of BLOCK the segment is
        // contiguous, otherwise (short levels of a partial last block) in two runs
        let mut ss = 0.0;
        let mut i = 0;
        while i < b {
            let run = (h - *pos).min(b - i);
            let seg = &mut ring[*pos..*pos + run];
            let d = if D {
                &mut diff[i..i + run]
            } else {
                &mut [][..]
            };
            ss += swap_span::<D>(
                &cur[i..i + run],
                seg,
                &mut out[i..i + run],
                skip.saturating_sub(i),
                d,
            );
            i += run;
            *pos = (*pos + run) % h;
        }
        ss
    } else {
        if *pos != 0 {
            // after a short block (a warm-up shorter than a block): oldest first again
            ring.rotate_left(*pos);
            *pos = 0;
        }
        let (d_head, d_body) = if D {
            diff[..b].split_at_mut(h)
        } else {
            (&mut [][..], &mut [][..])
        };
        let mut ss = span::<D>(&cur[..h], ring, &mut out[..h], skip, d_head);
        let (_, body) = out.split_at_mut(h);
        ss += span::<D>(
            &cur[h..],
            &cur[..b - h],
            body,
            skip.saturating_sub(h),
            d_body,
        );
        ring.copy_from_slice(&cur[b - h..]);
        ss
    }
}

/// `out = new + old`; returns `sum (new - old)^2` over indices `>= skip`, or with `D` writes
/// `diff = new - old` (all indices) and returns 0.
#[inline(always)]
fn span<const D: bool>(
    new: &[f64],
    old: &[f64],
    out: &mut [f64],
    skip: usize,
    diff: &mut [f64],
) -> f64 {
    if D {
        for (((o, d), &v), &u) in out.iter_mut().zip(diff.iter_mut()).zip(new).zip(old) {
            *o = v + u;
            *d = v - u;
        }
        return 0.0;
    }
    let skip = skip.min(new.len());
    for ((o, &v), &u) in out[..skip].iter_mut().zip(&new[..skip]).zip(&old[..skip]) {
        *o = v + u;
    }
    let (new, old, out) = (&new[skip..], &old[skip..], &mut out[skip..]);
    let mut acc = [0.0f64; LANES];
    let mut o8 = out.chunks_exact_mut(LANES);
    let mut n8 = new.chunks_exact(LANES);
    let mut u8 = old.chunks_exact(LANES);
    for ((o, v), u) in (&mut o8).zip(&mut n8).zip(&mut u8) {
        for k in 0..LANES {
            o[k] = v[k] + u[k];
            let w = v[k] - u[k];
            acc[k] += w * w;
        }
    }
    let mut tail = 0.0;
    for ((o, &v), &u) in o8
        .into_remainder()
        .iter_mut()
        .zip(n8.remainder())
        .zip(u8.remainder())
    {
        *o = v + u;
        tail += (v - u) * (v - u);
    }
    lane_total(&acc) + tail
}

/// As [`span`] with the lags in `ring`, which then receives `new` (a FIFO step).
#[inline(always)]
fn swap_span<const D: bool>(
    new: &[f64],
    ring: &mut [f64],
    out: &mut [f64],
    skip: usize,
    diff: &mut [f64],
) -> f64 {
    if D {
        for (((o, d), &v), r) in out
            .iter_mut()
            .zip(diff.iter_mut())
            .zip(new)
            .zip(ring.iter_mut())
        {
            let u = *r;
            *o = v + u;
            *d = v - u;
            *r = v;
        }
        return 0.0;
    }
    let skip = skip.min(new.len());
    for ((o, &v), r) in out[..skip]
        .iter_mut()
        .zip(&new[..skip])
        .zip(ring[..skip].iter_mut())
    {
        *o = v + *r;
        *r = v;
    }
    let (new, ring, out) = (&new[skip..], &mut ring[skip..], &mut out[skip..]);
    let mut acc = [0.0f64; LANES];
    let mut o8 = out.chunks_exact_mut(LANES);
    let mut n8 = new.chunks_exact(LANES);
    let mut r8 = ring.chunks_exact_mut(LANES);
    for ((o, v), r) in (&mut o8).zip(&mut n8).zip(&mut r8) {
        for k in 0..LANES {
            let u = r[k];
            o[k] = v[k] + u;
            let w = v[k] - u;
            acc[k] += w * w;
            r[k] = v[k];
        }
    }
    let mut tail = 0.0;
    for ((o, &v), r) in o8
        .into_remainder()
        .iter_mut()
        .zip(n8.remainder())
        .zip(r8.into_remainder())
    {
        let u = *r;
        *o = v + u;
        tail += (v - u) * (v - u);
        *r = v;
    }
    lane_total(&acc) + tail
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::variance::wv::HaarWvAccumulator;

    fn series(n: usize, seed: u64) -> Vec<f64> {
        // a biased random walk plus noise: every level carries signal, the offset matters
        let mut state = seed;
        let mut level = 0.0;
        (0..n)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let u = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                level += 0.01 * u;
                -9.81 + level + u
            })
            .collect()
    }

    fn accumulator_sums(x: &[f64], levels: usize, offset: f64) -> Vec<f64> {
        let mut acc = HaarWvAccumulator::with_offset(levels, offset).unwrap();
        acc.push(x).unwrap();
        let wv = acc.finish(1.0, 0.05).unwrap();
        wv.wv
            .iter()
            .zip(&wv.n_coefficients)
            .map(|(v, &m)| v * m as f64)
            .collect()
    }

    /// Direct `sum_t W_{j,t}^2` from the closed form of docs/methods.md §1.2 (window means).
    fn naive_sums(x: &[f64], levels: usize) -> Vec<f64> {
        (1..=levels)
            .map(|j| {
                let m = 1usize << (j - 1);
                ((2 * m - 1)..x.len())
                    .map(|t| {
                        let newer: f64 = x[t + 1 - m..=t].iter().sum::<f64>() / m as f64;
                        let older: f64 = x[t + 1 - 2 * m..=t - m].iter().sum::<f64>() / m as f64;
                        (0.5 * (newer - older)).powi(2)
                    })
                    .sum()
            })
            .collect()
    }

    #[test]
    fn haar_square_sums_match_the_closed_form() {
        // stage A only (n < 2^11 samples per level), and stage B with one and two levels
        for (n, levels) in [(37, 5), (2047, 10), (5000, 12), (9000, 13)] {
            let x = series(n, n as u64);
            let fast = haar_square_sums(&x, levels, x[0]);
            let oracle = naive_sums(&x, levels);
            for j in 0..levels {
                // different summation orders and a random-walk level: 1e-11 relative
                let d = (fast[j] - oracle[j]).abs() / oracle[j];
                assert!(d < 1e-11, "n {n} level {}: {d:e}", j + 1);
            }
        }
    }

    #[test]
    fn haar_square_sums_match_the_streaming_pyramid() {
        // several parts (PART = 2^16), partial last blocks, partial last rows of stage B, and
        // n = 2^J - 1 .. 2^J + 1 around the level limits
        for n in [
            (1 << 16) - 1,
            1 << 16,
            (1 << 16) + 1,
            3 * (1 << 16) + 12_345,
            (1 << 18) + 2047,
        ] {
            let x = series(n, 7 + n as u64);
            let levels = crate::variance::default_levels(
                n,
                crate::wavelet::Transform::Modwt,
                crate::wavelet::WaveletFilter::Haar,
            );
            let offset = x[..BLOCK].iter().sum::<f64>() / BLOCK as f64;
            let fast = haar_square_sums(&x, levels, offset);
            let stream = accumulator_sums(&x, levels, offset);
            for j in 0..levels {
                // the coefficients are bit-identical, the sums are taken in another order: the
                // relative difference is a few roundings of a long positive sum
                let d = (fast[j] - stream[j]).abs() / stream[j];
                assert!(d < 1e-13, "n {n} level {}: {d:e}", j + 1);
            }
        }
    }

    #[test]
    fn haar_square_sums_do_not_depend_on_the_thread_count() {
        let n = 5 * (1 << 16) + 999;
        let x = series(n, 3);
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| haar_square_sums(&x, 18, -9.8))
        };
        let one = run(1);
        for threads in [2, 3, 5] {
            assert_eq!(run(threads), one, "{threads} threads");
        }
    }
}
