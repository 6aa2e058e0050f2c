//! The fuzz targets on stable (issue 15): the bodies of `fuzz/fuzz_targets/*` live in
//! `fuzz/src/lib.rs`, included here, and run on every seed of `fuzz/corpus/<target>/`, on
//! every crash input the fuzzers found (`tests/fixtures/fuzz/<target>/`, each one a bug fixed
//! in a reader), and as property tests on mutated seeds and arbitrary bytes. The long libFuzzer
//! runs are in `fuzz/README.md`.

// the fuzz crate's public bodies, private here
#[allow(unreachable_pub)]
#[path = "../../../../fuzz/src/lib.rs"]
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
    #![proptest_config(ProptestConfig::with_cases(256 * TARGETS.len() as u32))]

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

// Each crash the fuzzers found, by name: the input (tests/fixtures/fuzz/<target>/<name>) and the
// typed error it now gets. Each of these panicked, or broke a documented property, before its
// fix.

fn fixture(target: &str, name: &str) -> Vec<u8> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/fuzz")
        .join(target)
        .join(name);
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// A fixture written to a temporary file named `file_name` (the readers choose a container by
/// its extension); the directory lives as long as the guard returned with the path.
fn fixture_file(target: &str, name: &str, file_name: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(file_name);
    std::fs::write(&path, fixture(target, name)).unwrap();
    (dir, path)
}

/// Writes `files` into a fresh directory and reads the first one with `opts`.
fn read_files(
    files: &[(&str, &[u8])],
    opts: &gmwm::imu::ReadOptions,
) -> (
    tempfile::TempDir,
    Result<gmwm::imu::Table, gmwm::imu::ReadError>,
) {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in files {
        std::fs::write(dir.path().join(name), bytes).unwrap();
    }
    let read = gmwm::imu::read_table(&dir.path().join(files[0].0), opts);
    (dir, read)
}

fn one_line(e: &impl std::fmt::Display) -> String {
    let s = e.to_string();
    assert!(!s.contains('\n'), "message on several lines: {s:?}");
    s
}

fn records(input: &[u8]) -> (gmwm::imu::ReadOptions, &[u8]) {
    let t = gmwm::imu::ImuRecordType::ALL[usize::from(input[0]) % 6];
    let opts = gmwm::imu::ReadOptions {
        format: gmwm::imu::InputFormat::ImuRecord(t),
        ..Default::default()
    };
    (opts, &input[1..])
}

/// IMU records whose first time is -6e112 and the next ones about 100 s: strictly increasing as
/// read, all equal once taken relative to the first stamp (Table::time promised strictly
/// increasing times; the table was returned with a constant time column).
#[test]
fn fuzz_regression_relative_time_collapses() {
    let input = fixture("imu_record", "relative_time_collapses");
    let (opts, content) = records(&input);
    let (_dir, read) = read_files(&[("x.imu", content)], &opts);
    let e = read.unwrap_err();
    assert!(
        matches!(e, gmwm::imu::ReadError::TimeResolution { row: 2, .. }),
        "{e:?}"
    );
    assert!(one_line(&e).contains("sample 2 (0-based)"), "{e}");
}

/// IMU record times 1e-300 s apart: a rate so high that increment × rate × scale is infinite
/// (the table held infinite rates).
#[test]
fn fuzz_regression_record_rate_overflows() {
    let input = fixture("imu_record", "rate_times_increment_overflows");
    let (opts, content) = records(&input);
    let (_dir, read) = read_files(&[("x.imu", content)], &opts);
    let e = read.unwrap_err();
    assert!(
        matches!(e, gmwm::imu::ReadError::RecordRateOverflow { .. }),
        "{e:?}"
    );
    one_line(&e);
    // the same through a sidecar stating the record format
    let input = fixture("sidecar", "record_rate_overflow");
    let k = input.iter().position(|&b| b == 0).unwrap();
    let (_dir, read) = read_files(
        &[("x.dat", &input[k + 1..]), ("x.dat.json", &input[..k])],
        &Default::default(),
    );
    let e = read.unwrap_err();
    assert!(
        matches!(e, gmwm::imu::ReadError::RecordRateOverflow { .. }),
        "{e:?}"
    );
}

/// A text file whose only column is the time column: the table had no columns (`is_empty`,
/// documented never to be).
#[test]
fn fuzz_regression_time_column_only() {
    let input = fixture("text", "time_column_only");
    assert_eq!(input, b"b0.0");
    let opts = gmwm::imu::ReadOptions {
        header: gmwm::imu::HeaderMode::Absent,
        time_column: Some(gmwm::imu::ColumnSelector::Index(1)),
        ..Default::default()
    };
    let (_dir, read) = read_files(&[("x.txt", &input[1..])], &opts);
    let e = read.unwrap_err();
    assert!(
        matches!(e, gmwm::imu::ReadError::NoDataColumn { .. }),
        "{e:?}"
    );
    assert!(one_line(&e).contains("no column to analyse: every column is a time column (col1)"));
    let (_dir, read) = read_files(
        &[("t.csv", b"time,timestamp\n1,5\n2,6\n")],
        &Default::default(),
    );
    assert!(one_line(&read.unwrap_err()).contains("time column (time, timestamp)"));
}

/// Stamps with gaps of absurd length (each counting usize::MAX missing samples): summing the
/// missing samples overflowed (a panic with overflow checks, a wrong count without).
#[test]
fn fuzz_regression_gap_count_overflows() {
    use gmwm::imu::{check_times, TimeUnit, TimingWarning, UnitSource};
    let r = check_times(
        "t",
        &[0.0, 1e-300, 2e-300, 1e300, 2e300],
        TimeUnit::Seconds,
        UnitSource::Stated,
    );
    assert_eq!(r.gaps.len(), 2);
    let w = r.warnings();
    assert!(
        matches!(
            w[0],
            TimingWarning::Gaps {
                missing: usize::MAX,
                ..
            }
        ),
        "{w:?}"
    );
    // the fuzzer's input: a raw f64 file read with its sidecar
    (TARGETS.iter().find(|t| t.0 == "sidecar").unwrap().1)(&fixture(
        "sidecar",
        "gap_count_overflow",
    ));
}

/// A corrupt rosbag2 sqlite3 schema: SQLite's message quotes the schema, newlines and all.
#[test]
fn fuzz_regression_sqlite_message_one_line() {
    let (_dir, path) = fixture_file("db3", "sqlite_message_multiline", "x.db3");
    let e = gmwm::imu::ros::list_topics(&path).unwrap_err();
    assert!(one_line(&e).contains("malformed database schema"), "{e}");
}

/// A ROS1 bag whose connection's type field runs into the next fields (NUL bytes, newlines of
/// the message definition): the topic list in the error was printed raw.
#[test]
fn fuzz_regression_topic_names_escaped() {
    let (_dir, path) = fixture_file("ros1_bag", "topic_type_control_chars", "x.bag");
    let e = gmwm::imu::ros::read_imu_messages(&path, None).unwrap_err();
    let s = one_line(&e);
    assert!(s.contains("\\0"), "{s}");
}

/// An MCAP chunk whose compression field runs into the chunk's records (a newline, NUL bytes):
/// the unsupported-compression error printed it raw, over several lines.
#[test]
fn fuzz_regression_chunk_compression_escaped() {
    let (_dir, path) = fixture_file("mcap", "chunk_compression_newline", "x.mcap");
    let e = gmwm::imu::ros::read_imu_messages(&path, None).unwrap_err();
    assert!(
        matches!(
            e,
            gmwm::imu::ReadError::Ros(gmwm::imu::ros::RosError::UnsupportedCompression { .. })
        ),
        "{e:?}"
    );
    let s = one_line(&e);
    assert!(s.contains("MCAP chunk compression \"$\\n\\0"), "{s}");
}

/// The `db3` fuzzer's crash (long run, 2026-11-24, 2.3 M executions): a topic named with tabs
/// and newlines went raw into the recording's first note, breaking the one-line rule; the
/// topic and the frame are now escaped.
#[test]
fn fuzz_regression_topic_name_escaped_in_notes() {
    let (_dir, path) = fixture_file("db3", "topic_name_newlines", "x.db3");
    let rec = gmwm::imu::Recording::open(&path, &Default::default()).unwrap();
    for n in &rec.notes {
        assert!(!n.contains('\n') && !n.contains('\t'), "{n:?}");
    }
    assert!(
        rec.notes[0].contains("topic \\t\\n\\t8\\n"),
        "{:?}",
        rec.notes[0]
    );
}

/// Not found by the fuzzers in their runs but a known allocation bomb of the same family: a
/// sidecar stating 10^12 (or 2^64 - 1) interleaved columns of a 96-byte file; the column names
/// were made before the size was checked, and `8 * ncols` overflowed.
#[test]
fn sidecar_column_count_allocates_nothing_before_the_size_check() {
    let data: Vec<u8> = (0..12u32)
        .flat_map(|k| f64::from(k).to_le_bytes())
        .collect();
    for n in ["1000000000000", "18446744073709551615"] {
        let sidecar = format!(r#"{{"format": "f64", "n_columns": {n}}}"#);
        let files: [(&str, &[u8]); 2] = [("x.dat", &data), ("x.dat.json", sidecar.as_bytes())];
        let (dir, read) = read_files(&files, &Default::default());
        let e = read.unwrap_err();
        assert!(
            matches!(
                e,
                gmwm::imu::ReadError::BinarySize { .. } | gmwm::imu::ReadError::InvalidOption(_)
            ),
            "{e:?}"
        );
        let e =
            gmwm::imu::binary_layout(&dir.path().join("x.dat"), &Default::default()).unwrap_err();
        one_line(&e);
    }
}

/// `76*GM+66*GM` parses (each multiplier at most 100) but its canonical text was `142*GM()`,
/// which does not: the round trip of a parsed model broke. Runs are now split at
/// MAX_MULTIPLIER.
#[test]
fn fuzz_regression_long_gm_run_round_trips() {
    let text = String::from_utf8(fixture("model_text", "long_gm_run_round_trip")).unwrap();
    assert_eq!(text, "76*GM+66*GM");
    let m = gmwm::model::Model::parse(&text).unwrap();
    assert_eq!(m.n_components(), 142);
    assert_eq!(m.to_string(), "100*GM()+42*GM()");
    assert_eq!(gmwm::model::Model::parse(&m.to_string()).unwrap(), m);
}

/// A WV JSON whose `transform` is an unknown variant holding a newline: serde's message quotes
/// the variant unescaped, and the error was printed on two lines.
#[test]
fn fuzz_regression_wv_json_unknown_variant_one_line() {
    let (_dir, path) = fixture_file("wv_json", "unknown_variant_with_newline", "x.json");
    let e = gmwm::variance::read_wv_json(&path, None).unwrap_err();
    assert!(matches!(e, gmwm::imu::ReadError::WvJson { .. }), "{e:?}");
    // one line whichever stage of the JSON reading refuses it
    let s = e.to_string();
    assert!(!s.contains('\n') && s.contains("x.json"), "{s}");
}

/// The `mcap` fuzzer's crash (long run, 2026-11-24, 0.93 M executions): a topic named with a
/// newline went raw into the "index counts N messages on TOPIC" reason of a corrupt file; the
/// topic is now quoted there, and every corrupt-file reason is escaped when displayed.
#[test]
fn fuzz_regression_index_count_topic_escaped() {
    let (_dir, path) = fixture_file("mcap", "index_count_topic_newline", "x.mcap");
    // two IMU topics: the fuzz target reads each by name
    let e = gmwm::imu::ros::read_imu_messages(&path, Some("/i\nu0")).unwrap_err();
    assert!(
        matches!(
            e,
            gmwm::imu::ReadError::Ros(gmwm::imu::ros::RosError::Corrupt { .. })
        ),
        "{e:?}"
    );
    let s = one_line(&e);
    assert!(s.contains("the index counts 2 messages on /i\\nu0"), "{s}");
}

/// The `mcap` fuzzer's crash (long run, 2026-11-24, 2.58 M executions): a chunk record in the
/// summary section, holding a record longer than the chunk, made the `mcap` crate's remaining
/// count underflow (a panic with overflow checks, a wrapped count without). The summary is now
/// walked first and a chunk there refused.
#[test]
fn fuzz_regression_chunk_in_summary_refused() {
    let (_dir, path) = fixture_file("mcap", "chunk_in_summary_overflow", "x.mcap");
    let e = gmwm::imu::ros::list_topics(&path).unwrap_err();
    let s = one_line(&e);
    assert!(s.contains("summary section: a chunk record at byte"), "{s}");
}

/// The `mcap` fuzzer's crash (long run, 2026-11-24 second session, 1.53 M executions): an
/// attachment record in the summary section with fewer than 4 bytes after its header for the
/// CRC made the `mcap` crate slice out of bounds (0.26.0, `read.rs:176`). The summary walk
/// now refuses attachments there too (the format keeps them in the data section).
#[test]
fn fuzz_regression_attachment_in_summary_refused() {
    let (_dir, path) = fixture_file("mcap", "attachment_in_summary_short", "x.mcap");
    let e = gmwm::imu::ros::list_topics(&path).unwrap_err();
    let s = one_line(&e);
    assert!(
        s.contains("summary section: an attachment record at byte"),
        "{s}"
    );
    assert!(
        !s.contains("mcap crate"),
        "refused before the crate reads it: {s}"
    );
}

/// The `mcap` fuzzer's crash (long run, 2026-11-24, 5.15 M executions): statistics whose
/// per-channel message counts sum beyond `u64::MAX` overflowed the count of messages on other
/// topics (a panic with overflow checks); the counts are now summed saturating, and the read
/// ends in an error naming the file, not a panic.
#[test]
fn fuzz_regression_message_counts_sum_saturates() {
    let (_dir, path) = fixture_file("mcap", "message_counts_overflow", "x.mcap");
    let (_, topics) = gmwm::imu::ros::list_topics(&path).unwrap();
    let total = topics
        .iter()
        .fold(0u64, |n, t| n.saturating_add(t.messages));
    assert_eq!(total, u64::MAX, "{topics:?}");
    for t in topics.iter().filter(|t| t.is_imu()) {
        if let Err(e) = gmwm::imu::ros::read_imu_messages(&path, Some(&t.topic)) {
            one_line(&e);
        }
    }
}

/// The `mcap` fuzzer's crash (CI's short run, 2026-11-24): a compressed chunk declaring
/// `u64::MAX` uncompressed bytes overflowed the decoder's read limit (size + 1, a panic with
/// overflow checks); the limit now saturates and the chunk is refused by its size check.
#[test]
fn fuzz_regression_declared_size_max() {
    let (_dir, path) = fixture_file("mcap", "declared_size_max", "x.mcap");
    if let Err(e) = gmwm::imu::ros::list_topics(&path) {
        one_line(&e);
    }
    if let Err(e) = gmwm::imu::ros::read_imu_messages(&path, None) {
        one_line(&e);
    }
}
