//! Numerical care at scale (issue 14): the classical Haar WV of long integer-valued white noise
//! and random walk against an exact reference computed in integer arithmetic, in memory
//! ([`wavelet_variance`]) and streamed ([`HaarWvAccumulator`]).
//!
//! The reference: with prefix sums `S`, the level-j Haar MODWT coefficient at `t` is
//! `W = (S[t+1] - 2 S[t+1-m] + S[t+1-2m]) / 2^j`, `m = 2^(j-1)` (docs/methods.md §1.2), so
//! `nu2_j = sum D^2 / (M_j 4^j)` with integer `D`; the sum of squares is exact in `i128`, and
//! the only rounding is its final conversion to `f64` (half an ulp). The engine computes the
//! same numbers through its f64 pyramid (averages of averages, each exact for integers until
//! the level's denominator exceeds 2^53 / |x|) and compensated sums.

use gmwm::{wavelet_variance, HaarWvAccumulator, WvOptions};

/// The bar of issue 14: the WV within 1e-9 relative of the exact one at every level.
const TOL_EXACT: f64 = 1e-9;
/// Streamed against in memory: the same pyramid, with different constant offsets subtracted
/// (the first sample against the mean) and different block boundaries of the compensated
/// sums, so equal up to rounding, not bit for bit.
const TOL_STREAM: f64 = 1e-12;

/// A deterministic stream of integers in `-k..=k` (splitmix64).
struct Ints {
    state: u64,
    k: i64,
}

impl Iterator for Ints {
    type Item = i64;
    fn next(&mut self) -> Option<i64> {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        Some((z % (2 * self.k as u64 + 1)) as i64 - self.k)
    }
}

/// The series, sample by sample: white noise `offset + e_t` or a random walk `sum e_t`.
fn series(kind: &str, n: usize, seed: u64) -> impl Iterator<Item = i64> + '_ {
    let mut level = 0i64;
    Ints {
        state: seed,
        k: 1000,
    }
    .take(n)
    .map(move |e| match kind {
        "wn" => 1_000_000 + e,
        _ => {
            level += e;
            level
        }
    })
}

/// The exact `nu2_j`, j = 1..=levels, in one pass over the series with a ring of prefix sums.
fn exact_wv(samples: impl Iterator<Item = i64>, n: usize, levels: usize) -> Vec<f64> {
    let span = 1usize << levels;
    let mut ring = vec![0i64; span + 1];
    let mut prefix = 0i64;
    let mut sums = vec![0i128; levels];
    for (t, x) in samples.enumerate() {
        prefix = prefix.checked_add(x).expect("prefix sum fits in i64");
        ring[(t + 1) % (span + 1)] = prefix;
        for (j, sum) in sums.iter_mut().enumerate() {
            let m = 1usize << j;
            if t + 1 < 2 * m {
                break;
            }
            let at = |back: usize| ring[(t + 1 - back) % (span + 1)];
            let d = i128::from(at(0)) - 2 * i128::from(at(m)) + i128::from(at(2 * m));
            *sum = sum.checked_add(d * d).expect("sum of squares fits in i128");
        }
    }
    sums.iter()
        .enumerate()
        .map(|(j, &s)| {
            let kept = (n + 1 - (2usize << j)) as f64;
            s as f64 / (kept * 4f64.powi(j as i32 + 1))
        })
        .collect()
}

/// The WV streamed in chunks of `chunk` samples.
fn streamed(samples: impl Iterator<Item = i64>, levels: usize, chunk: usize) -> Vec<f64> {
    let mut acc = HaarWvAccumulator::new(levels).unwrap();
    let mut buf = Vec::with_capacity(chunk);
    for x in samples {
        buf.push(x as f64);
        if buf.len() == chunk {
            acc.push(&buf).unwrap();
            buf.clear();
        }
    }
    acc.push(&buf).unwrap();
    acc.finish(1.0, 0.05).unwrap().wv().to_vec()
}

fn worst_rel(a: &[f64], b: &[f64]) -> (usize, f64) {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| ((x - y) / y).abs())
        .enumerate()
        .fold((0, 0.0), |w, (j, r)| if r > w.1 { (j + 1, r) } else { w })
}

/// Exact reference, in memory and streamed, for `n` samples of `kind`.
fn check(kind: &str, n: usize, levels: usize, in_memory: bool) {
    let seed = 14;
    let exact = exact_wv(series(kind, n, seed), n, levels);
    let stream = streamed(series(kind, n, seed), levels, 1 << 16);
    let (j, r) = worst_rel(&stream, &exact);
    println!("{kind} n = {n}: streamed vs exact, worst level {j}: {r:.2e}");
    assert!(r < TOL_EXACT, "{kind}: streamed level {j} off by {r:e}");
    // another chunk size gives the same bits: the accumulator blocks its sums itself
    let odd = streamed(series(kind, n, seed), levels, 1000);
    assert_eq!(odd, stream, "{kind}: chunking changed the streamed WV");
    if in_memory {
        let x: Vec<f64> = series(kind, n, seed).map(|v| v as f64).collect();
        let opts = WvOptions {
            levels: Some(levels),
            ..WvOptions::default()
        };
        let memory = wavelet_variance(&x, 1.0, &opts).unwrap().wv().to_vec();
        let (j, r) = worst_rel(&memory, &exact);
        println!("{kind} n = {n}: in memory vs exact, worst level {j}: {r:.2e}");
        assert!(r < TOL_EXACT, "{kind}: in-memory level {j} off by {r:e}");
        let (j, r) = worst_rel(&stream, &memory);
        println!("{kind} n = {n}: streamed vs in memory, worst level {j}: {r:.2e}");
        assert!(
            r < TOL_STREAM,
            "{kind}: streamed and in-memory differ at level {j} by {r:e}"
        );
    }
}

#[test]
fn scale_white_noise_and_random_walk_match_the_exact_integer_wv() {
    // 2^22 samples, every level of the series: the CI-sized run of the 1e9 study below
    let n = 1 << 22;
    for kind in ["wn", "rw"] {
        check(kind, n, 20, true);
    }
}

/// The 10^9-sample study of issue 14 (minutes, 8 GB for the in-memory copy):
/// `cargo test -p gmwm --release --lib scale::scale_1e9 -- --ignored --nocapture`.
#[test]
#[ignore = "10^9 samples: minutes and 8 GB; run by hand, figures in the issue note"]
fn scale_1e9_white_noise_and_random_walk_match_the_exact_integer_wv() {
    let n = 1_000_000_000;
    for kind in ["wn", "rw"] {
        check(kind, n, 26, true);
    }
}
