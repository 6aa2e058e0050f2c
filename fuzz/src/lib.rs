//! Bodies of the fuzz targets of the gmwm readers, one function per target, shared by the
//! cargo-fuzz binaries (`fuzz/fuzz_targets/<target>.rs`, nightly, libFuzzer) and by the stable
//! property tests of the engine (`crates/gmwm/src/tests/fuzz_props.rs` includes this file), so the
//! two never drift apart.
//!
//! Each body takes arbitrary bytes, hands them to a reader through the engine's public API and
//! checks, beyond "no panic", the properties a caller relies on: a table read has columns of
//! one length >= 1 holding only finite values, a strictly increasing time column starting at
//! 0, a positive finite rate; raw binary values are exactly the bytes decoded; a parsed model's
//! canonical text parses back to the same model; a sidecar survives a JSON round trip.
//!
//! The readers take paths (they read or query files), so the input is written to a small
//! file in a per-thread scratch directory (under `/dev/shm` where it exists), one subdirectory
//! per target so that one target's sidecars are never seen by another.
//!
//! The first byte of several inputs is a selector (options, record type, column count); see
//! each function.

use gmwm::{
    allan_from_wv, is_wv_json, list_topics, read_imu_messages, read_table, read_wv_json,
    ColumnSelector, Gmwm, HeaderMode, Imu, ImuMessages, ImuRecordType, InputFormat, Model,
    ReadError, ReadOptions, Recording, RecordingOptions, Sidecar, StartInputs, Table,
};
use std::cell::RefCell;
use std::path::{Path, PathBuf};

/// The body of a target: takes any bytes, panics on a broken property.
pub type Body = fn(&[u8]);

/// Every target: name (as in `fuzz/Cargo.toml` and `fuzz/corpus/<name>/`) and body.
pub const TARGETS: &[(&str, Body)] = &[
    ("text", text),
    ("raw_binary", raw_binary),
    ("imu_record", imu_record),
    ("ros1_bag", ros1_bag),
    ("mcap", mcap),
    ("db3", db3),
    ("wv_json", wv_json),
    ("sidecar", sidecar),
    ("model_text", model_text),
    ("wv_fit", wv_fit),
];

thread_local! {
    /// This thread's scratch directory (removed when the thread ends).
    static SCRATCH: RefCell<Option<tempfile::TempDir>> = const { RefCell::new(None) };
}

/// Writes `files` (name, bytes) into the scratch subdirectory `target` and
/// returns the path of the first one.
fn scratch(target: &str, files: &[(&str, &[u8])]) -> PathBuf {
    SCRATCH.with(|s| {
        let mut s = s.borrow_mut();
        let root = s.get_or_insert_with(|| {
            let shm = Path::new("/dev/shm");
            let parent = if shm.is_dir() {
                shm.to_path_buf()
            } else {
                std::env::temp_dir()
            };
            tempfile::Builder::new()
                .prefix("gmwm-fuzz-")
                .tempdir_in(parent)
                .expect("cannot create the fuzz scratch directory")
        });
        // each target writes the same file names every time: they are overwritten
        let dir = root.path().join(target);
        if !dir.is_dir() {
            std::fs::create_dir_all(&dir).expect("cannot create a fuzz scratch subdirectory");
        }
        for (name, bytes) in files {
            std::fs::write(dir.join(name), bytes).expect("cannot write a fuzz input file");
        }
        dir.join(files[0].0)
    })
}

/// The properties of any table [`read_table`] returns.
fn check_table(table: &Table) {
    let n = table.len();
    assert!(n >= 1, "a table without rows was returned");
    assert!(
        !table.columns.is_empty(),
        "a table without columns was returned"
    );
    for c in &table.columns {
        assert_eq!(c.values.len(), n, "column {} has another length", c.name);
        assert!(
            c.values.iter().all(|v| v.is_finite()),
            "column {} holds a non-finite value",
            c.name
        );
    }
    if let Some(t) = &table.time {
        assert_eq!(t.values.len(), n, "the time column has another length");
        assert!(t.values.iter().all(|v| v.is_finite()), "non-finite time");
        assert_eq!(t.values[0], 0.0, "the time column does not start at 0");
        assert!(
            t.values.windows(2).all(|w| w[0] < w[1]),
            "the time column does not strictly increase"
        );
        assert!(
            table.facts.timing.is_some(),
            "a time column without a timing report"
        );
    }
    if let Some(f) = table.facts.freq_hz {
        assert!(f.is_finite() && f > 0.0, "freq_hz = {f}");
    }
    // errors of every kind render as one line naming the file
    for w in &table.facts.warnings {
        assert!(!w.to_string().contains('\n'), "multi-line warning: {w}");
    }
}

/// An error renders as one non-empty line.
fn check_error(e: &impl std::fmt::Display) {
    let s = e.to_string();
    assert!(
        !s.is_empty() && !s.contains('\n'),
        "bad error message: {s:?}"
    );
}

/// [`check_table`] on a successful read, then [`Imu::from_table`] (must not panic).
fn check_read(read: Result<Table, ReadError>) -> Option<Table> {
    match read {
        Ok(table) => {
            check_table(&table);
            if let Err(e) = Imu::from_table(table.clone()) {
                check_error(&e);
            }
            Some(table)
        }
        Err(e) => {
            check_error(&e);
            None
        }
    }
}

/// CSV/TSV text (plain or gzip) through [`read_table`].
///
/// Selector byte: bits 0-1 the file name (`x.csv`, `x.tsv`, `x.txt`, `x.csv.gz`), bits 2-3 the
/// format (auto, auto, csv, tsv), bits 4-5 the header mode (auto, present, absent, auto),
/// bit 6 the time column forced to column 1; the rest is the file.
pub fn text(data: &[u8]) {
    let Some((&sel, content)) = data.split_first() else {
        return;
    };
    let name = ["x.csv", "x.tsv", "x.txt", "x.csv.gz"][usize::from(sel & 3)];
    let format = [
        InputFormat::Auto,
        InputFormat::Auto,
        InputFormat::Csv,
        InputFormat::Tsv,
    ][usize::from((sel >> 2) & 3)];
    let header = [
        HeaderMode::Auto,
        HeaderMode::Present,
        HeaderMode::Absent,
        HeaderMode::Auto,
    ][usize::from((sel >> 4) & 3)];
    let opts = ReadOptions {
        format,
        header,
        time_column: (sel & 0x40 != 0).then_some(ColumnSelector::Index(1)),
        ..ReadOptions::default()
    };
    let path = scratch("text", &[(name, content)]);
    if let Some(table) = check_read(read_table(&path, &opts)) {
        if !content.starts_with(&[0x1f, 0x8b]) {
            // one data row per line at most
            let lines = content.split(|&b| b == b'\n' || b == b'\r').count();
            assert!(
                table.len() <= lines,
                "{} rows from {lines} lines",
                table.len()
            );
        }
    }
}

/// Raw little-endian f64/f32 through [`read_table`].
///
/// Selector byte: bit 0 f32 (else f64), bits 1-3 the number of interleaved columns minus 1,
/// bit 4 the format from the name (`x.f64`/`x.f32`, else given explicitly); the rest is the
/// file. A read succeeds exactly when the size is a positive multiple of the record and every
/// value is finite, and then returns exactly the decoded values.
pub fn raw_binary(data: &[u8]) {
    let Some((&sel, content)) = data.split_first() else {
        return;
    };
    let (width, format, name) = if sel & 1 == 1 {
        (4, InputFormat::F32, "x.f32")
    } else {
        (8, InputFormat::F64, "x.f64")
    };
    let ncols = usize::from((sel >> 1) & 7) + 1;
    let by_name = sel & 0x10 != 0;
    let opts = ReadOptions {
        format: if by_name { InputFormat::Auto } else { format },
        ncols: Some(ncols),
        ..ReadOptions::default()
    };
    let path = scratch(
        "raw_binary",
        &[(if by_name { name } else { "x.bin" }, content)],
    );
    let decode = |b: &[u8]| -> f64 {
        if width == 8 {
            f64::from_le_bytes(b.try_into().expect("8 bytes"))
        } else {
            f64::from(f32::from_le_bytes(b.try_into().expect("4 bytes")))
        }
    };
    let record = width * ncols;
    let valid = !content.is_empty()
        && content.len() % record == 0
        && content.chunks_exact(width).all(|b| decode(b).is_finite());
    match check_read(read_table(&path, &opts)) {
        Some(table) => {
            assert!(valid, "an invalid raw file was read");
            assert_eq!(table.columns.len(), ncols);
            assert_eq!(table.len(), content.len() / record);
            for (k, c) in table.columns.iter().enumerate() {
                for (i, &v) in c.values.iter().enumerate() {
                    let at = i * record + k * width;
                    assert_eq!(v.to_bits(), decode(&content[at..at + width]).to_bits());
                }
            }
        }
        None => assert!(!valid, "a valid raw file was refused"),
    }
}

/// Binary IMU epoch records (METHODS §9.2) of every type through [`read_table`].
///
/// Selector byte: the record type ([`ImuRecordType::ALL`], modulo 6); the rest is the file.
pub fn imu_record(data: &[u8]) {
    let Some((&sel, content)) = data.split_first() else {
        return;
    };
    let t = ImuRecordType::ALL[usize::from(sel) % ImuRecordType::ALL.len()];
    let opts = ReadOptions {
        format: InputFormat::ImuRecord(t),
        ..ReadOptions::default()
    };
    let path = scratch("imu_record", &[("x.imu", content)]);
    if let Some(table) = check_read(read_table(&path, &opts)) {
        assert_eq!(table.columns.len(), 6);
        assert_eq!(table.len(), content.len() / t.record_size());
        assert_eq!(content.len() % t.record_size(), 0);
        assert_eq!(table.facts.record_type, Some(t));
        let f = table.facts.freq_hz.expect("IMU records have a rate");
        assert_eq!(f, f.round(), "an IMU record rate is a whole number");
        assert!(table.time.is_some(), "IMU records carry their time");
    }
}

/// The properties of messages read from a ROS recording.
fn check_messages(m: &ImuMessages) {
    let n = m.len();
    assert!(n >= 1, "no messages returned");
    assert_eq!(m.header_stamp_ns.len(), n);
    for v in m.angular_velocity.iter().chain(&m.linear_acceleration) {
        assert_eq!(v.len(), n);
        assert!(v.iter().all(|x| x.is_finite()), "a non-finite sample");
    }
    assert!(
        m.log_time_ns.windows(2).all(|w| w[0] <= w[1]),
        "log times out of order"
    );
}

/// A ROS recording (`x.<ext>`): the topic list, the single IMU topic, the recording opened for
/// calibration ([`Recording::open`]), then each IMU topic listed (at most 4).
fn ros(ext: &str, data: &[u8]) {
    let name = format!("x.{ext}");
    let path = scratch(ext, &[(&name, data)]);
    let topics = match list_topics(&path) {
        Ok((_, topics)) => topics,
        Err(e) => {
            check_error(&e);
            Vec::new()
        }
    };
    match read_imu_messages(&path, None) {
        Ok(m) => check_messages(&m),
        Err(e) => check_error(&e),
    }
    // the calibration's entry point: messages to IMU axes, their rate and timing notes
    match Recording::open(&path, &RecordingOptions::default()) {
        Ok(r) => {
            assert!(r.imu.freq_hz().is_finite() && r.imu.freq_hz() > 0.0);
            for (_, axis) in r.imu.iter() {
                assert!(axis.values().iter().all(|v| v.is_finite()));
            }
            for note in &r.notes {
                assert!(!note.contains('\n'), "multi-line note: {note:?}");
            }
        }
        Err(e) => check_error(&e),
    }
    for t in topics.iter().filter(|t| t.is_imu()).take(4) {
        match read_imu_messages(&path, Some(&t.topic)) {
            Ok(m) => {
                check_messages(&m);
                assert_eq!(m.topic, t.topic);
            }
            Err(e) => check_error(&e),
        }
    }
    // a covariate (docs/methods.md §5.13): a scalar topic aligned to the IMU messages, and a
    // magnitude of their fields; one value per IMU message, all finite
    for name in ["temperature", "angular_rate"] {
        match gmwm::read_ros_covariate(&path, None, name) {
            Ok(c) => {
                assert!(c.values.iter().all(|v| v.is_finite()));
                let n = read_imu_messages(&path, None).map(|m| m.len()).unwrap_or(0);
                assert_eq!(c.values.len(), n, "one covariate value per IMU message");
                for note in &c.notes {
                    assert!(!note.contains('\n'), "multi-line note: {note:?}");
                }
            }
            Err(e) => check_error(&e),
        }
    }
}

/// A ROS1 bag (`x.bag`).
pub fn ros1_bag(data: &[u8]) {
    ros("bag", data);
}

/// An MCAP file (`x.mcap`).
pub fn mcap(data: &[u8]) {
    ros("mcap", data);
}

/// A rosbag2 sqlite3 storage file (`x.db3`).
pub fn db3(data: &[u8]) {
    ros("db3", data);
}

/// A model's text on the first line, a saved WV (JSON) after it: the WV read, the model's
/// implied WV at the WV's levels and the model fitted to it (`gmwm fit WV.json --model M`).
/// Any `n` and level count a file claims must cost no more than the levels: a 3 KB file
/// claiming `n = 2^40` over 40 levels made an ARMA fit allocate 4 TB.
pub fn wv_fit(data: &[u8]) {
    let Some(split) = data.iter().position(|&b| b == b'\n') else {
        return;
    };
    let Ok(text) = std::str::from_utf8(&data[..split]) else {
        return;
    };
    // a fit's cost grows with the parameters (its guessed starts, its numeric Jacobian): an
    // ARMA(6,1) fit of a 40-level WV takes 3 s in a release build, past libFuzzer's timeout
    // in the fuzz build; six parameters cover the IMU models and ARMA(4,1)
    let Ok(model) = Model::parse(text) else {
        return;
    };
    if model.n_params() > 6 {
        return;
    }
    let path = scratch("wv_fit", &[("x.json", &data[split + 1..])]);
    let Ok(series) = read_wv_json(&path, None) else {
        return;
    };
    for (_, wv) in series.iter().take(2) {
        let levels = wv.tau().len();
        match model.implied_wv(levels, wv.freq_hz()) {
            Ok(implied) => assert_eq!(implied.wv.len(), levels),
            Err(e) => check_error(&e),
        }
        // the starting-value search's draws (20000 by default) repeat one computation, and so
        // do the optimiser's steps past the first hundred (2000 by default: a deep-level ARMA
        // fit that never converges ran them all, 1.4 s natively and 4 s in this build): a few
        // cover their paths (100 steps include the refresh of the scaling at step 50) and
        // leave the executions to the inputs
        let gmwm = Gmwm::new(model.clone())
            .with_draws(64)
            .with_max_iterations(100);
        match gmwm.fit_from_wv(wv, StartInputs::from_wv(wv)) {
            Ok(fit) => assert_eq!(fit.implied_wv().wv.len(), levels),
            Err(e) => check_error(&e),
        }
    }
}

/// A WV JSON (`gmwm wv --json`) through [`read_wv_json`], then [`allan_from_wv`] on each
/// series.
pub fn wv_json(data: &[u8]) {
    let path = scratch("wv_json", &[("x.json", data)]);
    let _ = is_wv_json(&path);
    match read_wv_json(&path, None) {
        Ok(series) => {
            assert!(!series.is_empty());
            for (name, wv) in &series {
                assert!(!name.is_empty());
                let levels = wv.tau().len();
                assert!(levels >= 1);
                assert_eq!(wv.wv().len(), levels);
                assert_eq!(wv.tau_s().len(), levels);
                assert!(wv.n() >= 2);
                assert!(wv.freq_hz().is_finite() && wv.freq_hz() > 0.0);
                for (k, &t) in wv.tau().iter().enumerate() {
                    assert_eq!(t, 2f64.powi(k as i32 + 1));
                }
                if let Err(e) = allan_from_wv(wv) {
                    check_error(&e);
                }
            }
        }
        Err(e) => check_error(&e),
    }
}

/// A JSON sidecar: [`Sidecar::from_json`] (a parsed sidecar survives a JSON round trip), then
/// as the sidecar of a data file read with [`read_table`] in auto mode.
///
/// Input: the sidecar text, optionally followed by a NUL byte and the data file's bytes (by
/// default 12 increasing little-endian f64).
pub fn sidecar(data: &[u8]) {
    let (json, payload) = match data.iter().position(|&b| b == 0) {
        Some(k) => (&data[..k], data[k + 1..].to_vec()),
        None => (
            data,
            (0..12u32)
                .flat_map(|k| f64::from(k).to_le_bytes())
                .collect(),
        ),
    };
    let Ok(text) = std::str::from_utf8(json) else {
        return;
    };
    match Sidecar::from_json(text, Path::new("x.dat.json")) {
        Ok(s) => {
            let again = serde_json::to_string(&s).expect("a sidecar serializes");
            let back = Sidecar::from_json(&again, Path::new("again.json"))
                .expect("a serialized sidecar parses");
            assert_eq!(back, s, "sidecar JSON round trip");
        }
        Err(e) => check_error(&e),
    }
    let path = scratch("sidecar", &[("x.dat", &payload), ("x.dat.json", json)]);
    check_read(read_table(&path, &ReadOptions::default()));
}

/// The model text language through [`Model::parse`]: a parsed model's canonical text
/// (`Display`) parses back to the same model and is a fixed point; an error renders.
pub fn model_text(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match Model::parse(text) {
        Ok(m) => {
            let canonical = m.to_string();
            let back = Model::parse(&canonical)
                .unwrap_or_else(|e| panic!("canonical text {canonical:?} does not parse: {e}"));
            assert_eq!(
                back, m,
                "canonical text {canonical:?} parses to another model"
            );
            assert_eq!(back.to_string(), canonical);
            assert_eq!(m.n_params(), m.values().len());
        }
        Err(e) => {
            assert!(e.offset() <= text.len(), "error offset past the end");
            let _ = e.render();
            check_error(&e);
        }
    }
}
