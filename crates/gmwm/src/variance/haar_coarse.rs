//! The coarse levels of the classical Haar MODWT wavelet variance of a series that can be read
//! again at any position (a file), in memory independent of the scale.
//!
//! [`HaarWvAccumulator`](crate::HaarWvAccumulator) keeps the last `2^{j-1}` scaling
//! coefficients of every level, `8 · 2^J` bytes: 512 MiB at `J = 26` (10^8 samples). A
//! coefficient of level `j` needs the samples `2^j` back, and only them, so when the series
//! can be read again at any position the coarse levels need no ring: this module reads the
//! lagged blocks it needs.
//!
//! # Formula
//! With blocks of `B = 2^{j0}` samples, `P_b[r]` the sum of samples `0..=r` of block `b` and
//! `T_b = P_b[B - 1]` its total, the prefix sum is `S_{bB + r} = sum_{b' < b} T_{b'} + P_b[r]`.
//! At a level `j > j0` (`L = 2^j`, `H = L / 2 = c B`) the coefficient at `t = kB + r` is
//!
//! `L W_{j,t} = S_t - 2 S_{t-H} + S_{t-L} = D_{j,k} + P_k[r] - 2 P_{k-c}[r] + P_{k-2c}[r]`,
//!
//! `D_{j,k} = sum_{b=k-c}^{k-1} T_b - sum_{b=k-2c}^{k-c-1} T_b` (blocks before the series are
//! zero). It is kept for `t >= L - 1` (METHODS §1.3). So block `k` needs the within-block sums
//! of the blocks `k - 2^i`, `i = 0..=J-j0`, and the block totals: `J - j0 + 2` blocks in
//! memory and each block read `J - j0 + 1` times. The squares are summed per block and the
//! block sums added with Neumaier's compensation.

use crate::math::sum::NeumaierSum;
use std::collections::HashMap;
use std::sync::Arc;

/// Sums of squared coefficients (and kept counts) at levels `j0 + 1 ..= levels` of the
/// `n`-sample series of `columns` columns whose block `k` (samples `k B .. (k+1) B`, `B =
/// 2^{j0}`, the last one shorter) `read_block(k, out)` writes into `out[column]`, after
/// subtracting `offsets[column]` from every sample (numerical care, as the accumulator does;
/// the Haar filter annihilates constants).
///
/// Returns per column, per level `j0 + 1 ..= levels`, `(sum of W^2, kept count)`.
///
/// # Errors
/// Those of `read_block`.
pub(crate) fn coarse_square_sums<E>(
    n: usize,
    j0: usize,
    levels: usize,
    offsets: &[f64],
    mut read_block: impl FnMut(usize, &mut [Vec<f64>]) -> Result<(), E>,
) -> Result<Vec<Vec<(f64, usize)>>, E> {
    let columns = offsets.len();
    let block = 1usize << j0;
    let blocks = n.div_ceil(block);
    let coarse = levels.saturating_sub(j0);
    let mut sums = vec![vec![NeumaierSum::default(); coarse]; columns];
    let mut counts = vec![vec![0usize; coarse]; columns];
    // within-block prefix sums of the blocks still needed, by block index
    let mut cache: HashMap<usize, Arc<Vec<Vec<f64>>>> = HashMap::new();
    let mut totals: Vec<Vec<f64>> = Vec::with_capacity(blocks);
    let mut raw = vec![Vec::with_capacity(block); columns];
    let mut load = |b: usize, raw: &mut Vec<Vec<f64>>| -> Result<Arc<Vec<Vec<f64>>>, E> {
        for r in raw.iter_mut() {
            r.clear();
        }
        read_block(b, raw)?;
        Ok(Arc::new(
            raw.iter()
                .zip(offsets)
                .map(|(x, &o)| {
                    let mut s = 0.0;
                    x.iter()
                        .map(|v| {
                            s += v - o;
                            s
                        })
                        .collect()
                })
                .collect(),
        ))
    };
    for k in 0..blocks {
        let current = load(k, &mut raw)?;
        totals.push(
            current
                .iter()
                .map(|p| p.last().copied().unwrap_or(0.0))
                .collect(),
        );
        let len = current[0].len();
        // the lagged blocks of this step, each read once: k - 2^i, i = 0..=levels-j0
        let mut lagged: HashMap<usize, Arc<Vec<Vec<f64>>>> = HashMap::new();
        for i in 0..=coarse {
            let d = 1usize << i;
            if d > k {
                break; // before the series: zero blocks
            }
            let b = k - d;
            let p = match cache.get(&b) {
                Some(p) => p.clone(),
                None => load(b, &mut raw)?,
            };
            lagged.insert(d, p);
        }
        for (level, j) in (j0 + 1..=levels).enumerate() {
            let c = 1usize << (j - 1 - j0);
            let l = 1usize << j;
            // first kept t = L - 1 (METHODS §1.3)
            let t0 = k * block;
            if t0 + len < l {
                continue;
            }
            let r_from = (l - 1).saturating_sub(t0);
            let mid = lagged.get(&c);
            let far = lagged.get(&(2 * c));
            for col in 0..columns {
                let window = |from: usize, to: usize| -> f64 {
                    // sum of T_b for b in from..to (blocks before the series are zero)
                    let mut s = NeumaierSum::default();
                    for total in &totals[from..to] {
                        s.add(total[col]);
                    }
                    s.total()
                };
                let d = window(k.saturating_sub(c), k)
                    - window(k.saturating_sub(2 * c), k.saturating_sub(c));
                let p = &current[col];
                let pm = mid.map(|m| &m[col]);
                let pf = far.map(|f| &f[col]);
                let mut acc = 0.0;
                for r in r_from..len {
                    let w = d + p[r] - 2.0 * pm.map_or(0.0, |m| m[r]) + pf.map_or(0.0, |f| f[r]);
                    acc += w * w;
                }
                sums[col][level].add(acc / (l as f64 * l as f64));
                counts[col][level] += len - r_from;
            }
        }
        // keep what the next blocks read most: the last two (lags 1 and 2)
        cache.insert(k, current);
        cache.retain(|&b, _| b + 2 > k);
    }
    Ok(sums
        .into_iter()
        .zip(counts)
        .map(|(s, c)| s.iter().map(|x| x.total()).zip(c).collect())
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::variance::wv::{wavelet_variance, WvOptions};

    #[test]
    fn coarse_levels_match_the_in_memory_wv() {
        // a random walk with a large offset and a white noise, two columns; blocks of 2^6 and
        // levels 7..=11 of 3000 samples (a partial last block)
        let n = 3000;
        let mut state = 7u64;
        let mut uniform = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let mut rw = Vec::with_capacity(n);
        let mut level = 1e3;
        let mut wn = Vec::with_capacity(n);
        for _ in 0..n {
            level += uniform();
            rw.push(level);
            wn.push(uniform());
        }
        let cols = [rw, wn];
        let j0 = 6;
        let levels = 11;
        let got = coarse_square_sums(n, j0, levels, &[1e3, 0.0], |k, out: &mut [Vec<f64>]| {
            let from = k << j0;
            let to = (from + (1 << j0)).min(n);
            for (o, c) in out.iter_mut().zip(&cols) {
                o.extend_from_slice(&c[from..to]);
            }
            Ok::<_, ()>(())
        })
        .unwrap();
        for (col, x) in cols.iter().enumerate() {
            let wv = wavelet_variance(
                x,
                1.0,
                &WvOptions {
                    levels: Some(levels),
                    ..WvOptions::default()
                },
            )
            .unwrap();
            for (i, j) in (j0 + 1..=levels).enumerate() {
                let (sum, kept) = got[col][i];
                assert_eq!(kept, n + 1 - (1 << j));
                let v = sum / kept as f64;
                let want = wv.wv()[j - 1];
                assert!(
                    (v - want).abs() <= 1e-12 * want,
                    "col {col} level {j}: {v} vs {want}"
                );
            }
        }
    }
}
