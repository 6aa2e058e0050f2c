//! The fuzz targets on stable (issue 15): the bodies of `fuzz/fuzz_targets/*` live in
//! `fuzz/src/lib.rs`, included here, and run on every seed of `fuzz/corpus/<target>/`, on
//! every crash input the fuzzers found (`tests/fixtures/fuzz/<target>/`, each one a bug fixed
//! in a reader), and as property tests on mutated seeds and arbitrary bytes. The long libFuzzer
//! runs are in `fuzz/README.md`.

#[path = "../../../fuzz/src/lib.rs"]
mod bodies;

use bodies::TARGETS;
use proptest::prelude::*;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The files of `dir`, sorted, with their bytes (none if `dir` does not exist).
fn files(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut paths: Vec<PathBuf> = entries
        .map(|e| e.expect("a directory entry").path())
        .collect();
    paths.sort();
    paths
        .into_iter()
        .map(|p| {
            let bytes = std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            (p, bytes)
        })
        .collect()
}

/// The seed corpus of every target, loaded once.
fn seeds() -> &'static [Vec<Vec<u8>>] {
    static SEEDS: std::sync::OnceLock<Vec<Vec<Vec<u8>>>> = std::sync::OnceLock::new();
    SEEDS.get_or_init(|| {
        TARGETS
            .iter()
            .map(|(name, _)| {
                files(&repo().join("fuzz/corpus").join(name))
                    .into_iter()
                    .map(|(_, b)| b)
                    .collect()
            })
            .collect()
    })
}

#[test]
fn every_target_passes_its_seed_corpus() {
    for ((name, body), seeds) in TARGETS.iter().zip(seeds()) {
        assert!(!seeds.is_empty(), "fuzz/corpus/{name} has no seeds");
        for s in seeds {
            body(s);
        }
    }
}

/// Every input a fuzzer crashed on, kept as `tests/fixtures/fuzz/<target>/<name>`.
#[test]
fn fuzz_crash_regressions() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/fuzz");
    for (name, body) in TARGETS {
        for (path, bytes) in files(&root.join(name)) {
            eprintln!("regression {}", path.display());
            body(&bytes);
        }
    }
}

/// A byte-level edit of a seed, libFuzzer style.
#[derive(Debug, Clone)]
enum Edit {
    Flip(prop::sample::Index, u8),
    Truncate(prop::sample::Index),
    Insert(prop::sample::Index, Vec<u8>),
    Remove(prop::sample::Index, usize),
    /// A 32-bit little-endian boundary value (lengths, counts, offsets).
    Word(prop::sample::Index, u32),
}

fn edit() -> impl Strategy<Value = Edit> {
    let index = any::<prop::sample::Index>;
    prop_oneof![
        (index(), 1..=255u8).prop_map(|(i, x)| Edit::Flip(i, x)),
        index().prop_map(Edit::Truncate),
        (index(), prop::collection::vec(any::<u8>(), 1..16)).prop_map(|(i, b)| Edit::Insert(i, b)),
        (index(), 1..64usize).prop_map(|(i, n)| Edit::Remove(i, n)),
        (
            index(),
            prop_oneof![
                Just(0u32),
                Just(1),
                Just(0x7fff_ffff),
                Just(0xffff_ffff),
                Just(0x8000_0000),
                any::<u32>()
            ]
        )
            .prop_map(|(i, w)| Edit::Word(i, w)),
    ]
}

fn apply(mut b: Vec<u8>, edits: &[Edit]) -> Vec<u8> {
    for e in edits {
        if b.is_empty() {
            break;
        }
        match e {
            Edit::Flip(i, x) => {
                let k = i.index(b.len());
                b[k] ^= x;
            }
            Edit::Truncate(i) => b.truncate(i.index(b.len())),
            Edit::Insert(i, bytes) => {
                let k = i.index(b.len() + 1);
                b.splice(k..k, bytes.iter().copied());
            }
            Edit::Remove(i, n) => {
                let k = i.index(b.len());
                let end = (k + n).min(b.len());
                b.drain(k..end);
            }
            Edit::Word(i, w) => {
                let k = i.index(b.len());
                for (j, x) in w.to_le_bytes().into_iter().enumerate() {
                    if let Some(slot) = b.get_mut(k + j) {
                        *slot = x;
                    }
                }
            }
        }
    }
    b
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96 * TARGETS.len() as u32))]

    /// Seeds with a few byte-level edits: reaches the readers' checks deep in valid files.
    #[test]
    fn mutated_seeds_never_break_a_reader(
        target in 0..TARGETS.len(),
        seed in any::<prop::sample::Index>(),
        edits in prop::collection::vec(edit(), 1..6),
    ) {
        let seeds = &seeds()[target];
        let input = apply(seeds[seed.index(seeds.len())].clone(), &edits);
        (TARGETS[target].1)(&input);
    }

    /// Arbitrary bytes (the first one being the selector byte of some targets).
    #[test]
    fn arbitrary_bytes_never_break_a_reader(
        target in 0..TARGETS.len(),
        input in prop::collection::vec(any::<u8>(), 0..384),
    ) {
        (TARGETS[target].1)(&input);
    }
}
