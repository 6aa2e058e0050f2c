//! Readers (docs/methods.md §9): every malformed-input class with its exact message,
//! text/gzip/binary round trips, the chunked reader, IMU binary records (§9.2–9.3) and the shared
//! recordings.

use crate::tests::common::data_dir;
use flate2::write::GzEncoder;
use flate2::Compression;
use gmwm::imu::write::write_sidecar;
use gmwm::imu::{
    binary_layout, for_each_chunk, read_imu_record_file, read_table, sniff, BinaryChunks,
    ColumnSelector, Content, HeaderMode, Imu, ImuRecordType, InputFormat, ReadError, ReadOptions,
    ReadWarning, Sensor, SeriesWriter, Sidecar, SidecarColumn, TimeUnit, TimingWarning, UnitSource,
};
use gmwm::variance::{allan_from_wv, is_wv_json, select_series};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Relative tolerance of the sidecar means: they were computed from the same float64 values,
/// so a compensated sum must agree to rounding of the final division (brief: 1e-12).
const MEAN_REL_TOL: f64 = 1e-12;

fn write(dir: &tempfile::TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = GzEncoder::new(Vec::new(), Compression::default());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

fn read(p: &Path) -> Result<gmwm::imu::Table, ReadError> {
    read_table(p, &ReadOptions::default())
}

fn err(p: &Path, opts: &ReadOptions) -> String {
    read_table(p, opts).unwrap_err().to_string()
}

fn names(opts: &[&str]) -> Vec<ColumnSelector> {
    opts.iter().map(|s| s.parse().unwrap()).collect()
}

fn f64_bytes(v: &[f64]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

// ---------------------------------------------------------------- text, well formed

#[test]
fn read_csv_with_header() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "imu.csv", b"gyro_x,accel_z\n1,2.5\n-3e-2, 4\n");
    let t = read(&p).unwrap();
    assert_eq!(t.columns.len(), 2);
    assert_eq!(t.columns[0].name, "gyro_x");
    assert_eq!(t.columns[0].values, [1.0, -0.03]);
    assert_eq!(t.columns[1].values, [2.5, 4.0]);
    assert_eq!(t.facts.freq_hz, None);
    assert_eq!(t.len(), 2);
    assert_eq!(t.facts.path, p);
}

#[test]
fn read_without_header_names_columns() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "imu.csv", b"1,2\r\n3,4\r\n");
    let t = read(&p).unwrap();
    assert_eq!(t.columns[0].name, "col1");
    assert_eq!(t.columns[1].name, "col2");
    assert_eq!(t.columns[1].values, [2.0, 4.0]);
    // forced header: the first numeric row becomes names
    let o = ReadOptions {
        header: HeaderMode::Present,
        ..ReadOptions::default()
    };
    let t = read_table(&p, &o).unwrap();
    assert_eq!(t.columns[0].name, "1");
    assert_eq!(t.columns[0].values, [3.0]);
}

#[test]
fn read_header_absent_forced_reports_line_1() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "imu.csv", b"a,b\n1,2\n");
    let o = ReadOptions {
        header: HeaderMode::Absent,
        ..ReadOptions::default()
    };
    assert_eq!(
        err(&p, &o),
        format!("{}:1: column col1: \"a\" is not a number", p.display())
    );
}

#[test]
fn read_tsv_and_sniffed_delimiters() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "imu.tsv", b"x\ty\n1\t2\n");
    assert_eq!(read(&p).unwrap().columns[1].values, [2.0]);
    let p = write(&d, "imu.txt", b"x;y\n1;2\n");
    assert_eq!(read(&p).unwrap().columns[1].values, [2.0]);
    let p = write(&d, "tabs.csv", b"x\ty\n1\t2\n");
    assert_eq!(read(&p).unwrap().columns[1].name, "y");
    // explicit TSV, no sniffing
    let p = write(&d, "data.dat", b"x\ty\n1\t2\n");
    let o = ReadOptions {
        format: InputFormat::Tsv,
        ..ReadOptions::default()
    };
    assert_eq!(read_table(&p, &o).unwrap().columns[0].values, [1.0]);
}

#[test]
fn read_single_column_and_bom() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "x.csv", b"\xef\xbb\xbfx\n1\n2\n3\n");
    let t = read(&p).unwrap();
    assert_eq!(t.columns[0].name, "x");
    assert_eq!(t.columns[0].values, [1.0, 2.0, 3.0]);
}

#[test]
fn read_selects_by_name_and_index_only_selected_are_parsed() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "imu.csv", b"a,b,c\n1,junk,3\n4,junk,6\n");
    let o = ReadOptions {
        columns: names(&["c", "1"]),
        ..ReadOptions::default()
    };
    let t = read_table(&p, &o).unwrap();
    assert_eq!(t.columns[0].name, "c");
    assert_eq!(t.columns[0].values, [3.0, 6.0]);
    assert_eq!(t.columns[1].name, "a");
    assert_eq!(t.columns[1].values, [1.0, 4.0]);
}

#[test]
fn read_time_column_gives_unrounded_freq() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "imu.csv", b"t,x\n0,1\n0.016,2\n0.032,3\n");
    let o = ReadOptions {
        time_column: Some(ColumnSelector::Name("t".into())),
        ..ReadOptions::default()
    };
    let t = read_table(&p, &o).unwrap();
    assert_eq!(t.columns.len(), 1);
    assert_eq!(t.columns[0].name, "x");
    assert_eq!(t.facts.freq_hz, Some(62.5));
    assert_eq!(t.time.as_ref().unwrap().values, [0.0, 0.016, 0.032]);
    // an explicit rate wins over the time column
    let o = ReadOptions {
        freq_hz: Some(60.0),
        ..o
    };
    assert_eq!(read_table(&p, &o).unwrap().facts.freq_hz, Some(60.0));
}

#[test]
fn read_time_not_increasing() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "imu.csv", b"t,x\n0,1\n0.01,2\n0.01,3\n");
    let o = ReadOptions {
        time_column: Some(ColumnSelector::Index(1)),
        ..ReadOptions::default()
    };
    assert_eq!(
        err(&p, &o),
        format!(
            "{}:4: column t: time 0.01 is not greater than the previous time 0.01; \
             the time column must be strictly increasing (--time-policy drop-duplicates drops \
             such rows, --time-policy sort sorts them)",
            p.display()
        )
    );
}

/// A repeated stamp and a swapped pair: `drop-duplicates` drops both kinds, `sort` puts the
/// pair in order and drops the repeat; each says what it did and the account counts it.
#[test]
fn time_policies_drop_or_sort_and_say_so() {
    let d = tempfile::tempdir().unwrap();
    let p = write(
        &d,
        "imu.csv",
        b"time,x\n0,0\n0.01,1\n0.01,9\n0.03,3\n0.02,2\n0.04,4\n",
    );
    let with = |policy| ReadOptions {
        time_policy: policy,
        ..ReadOptions::default()
    };
    let t = read_table(&p, &with(gmwm::TimePolicy::DropDuplicates)).unwrap();
    assert_eq!(t.columns[0].values, vec![0.0, 1.0, 3.0, 4.0]);
    assert_eq!((t.facts.samples.read, t.facts.samples.used), (6, 4));
    assert_eq!(
        t.facts.warnings.last().unwrap().to_string(),
        format!(
            "{}: --time-policy drop-duplicates: 1 row repeating the previous stamp dropped, 1 row \
             stamped before the previous one dropped",
            p.display()
        )
    );
    let t = read_table(&p, &with(gmwm::TimePolicy::Sort)).unwrap();
    assert_eq!(t.columns[0].values, vec![0.0, 1.0, 2.0, 3.0, 4.0]);
    assert_eq!(t.time.as_ref().unwrap().values.len(), 5);
    assert_eq!((t.facts.samples.read, t.facts.samples.used), (6, 5));
    assert!(t.facts.warnings.iter().any(|w| w.to_string().ends_with(
        "--time-policy sort: 2 rows out of order sorted into place, 1 row repeating the previous \
         stamp dropped"
    )));
    // a first row that is not the earliest: the stamps count from the earliest
    let p = write(&d, "late.csv", b"time,x\n0.02,2\n0,0\n0.01,1\n0.03,3\n");
    let t = read_table(&p, &with(gmwm::TimePolicy::Sort)).unwrap();
    assert_eq!(t.columns[0].values, vec![0.0, 1.0, 2.0, 3.0]);
    assert_eq!(t.time.as_ref().unwrap().values[0], 0.0);
}

#[test]
fn read_sidecar_freq_and_precedence() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "rec.csv.gz", &gzip(b"gyro_x\n1\n2\n"));
    write(
        &d,
        "rec.json",
        br#"{"name": "rec", "sampling_frequency_hz": 250, "unknown": {"a": 1}}"#,
    );
    let t = read(&p).unwrap();
    assert_eq!(t.facts.freq_hz, Some(250.0));
    assert_eq!(
        t.facts.sidecar.as_ref().unwrap().name.as_deref(),
        Some("rec")
    );
    let o = ReadOptions {
        freq_hz: Some(10.0),
        ..ReadOptions::default()
    };
    assert_eq!(read_table(&p, &o).unwrap().facts.freq_hz, Some(10.0));
}

#[test]
fn read_bad_options() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "x.csv", b"1\n2\n");
    let o = ReadOptions {
        freq_hz: Some(-1.0),
        ..ReadOptions::default()
    };
    assert_eq!(
        err(&p, &o),
        "invalid freq = -1: must be a positive number of hertz"
    );
}

// ---------------------------------------------------------------- text, malformed

#[test]
fn read_error_missing_file() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("nope.csv");
    let e = read(&p).unwrap_err();
    assert!(
        matches!(&e, ReadError::Io { source, .. } if source.kind() == std::io::ErrorKind::NotFound)
    );
    assert!(e.to_string().starts_with(&format!("{}: ", p.display())));
}

#[test]
fn read_error_empty_file() {
    let d = tempfile::tempdir().unwrap();
    for (name, bytes) in [
        ("a.csv", &b""[..]),
        ("b.csv", b"\n\n"),
        ("c.csv.gz", &gzip(b"")),
    ] {
        let p = write(&d, name, bytes);
        assert_eq!(
            err(&p, &ReadOptions::default()),
            format!("{}: file is empty (no data rows)", p.display())
        );
    }
}

#[test]
fn read_error_header_only() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "h.csv", b"gyro_x,gyro_y\n");
    assert_eq!(
        err(&p, &ReadOptions::default()),
        format!(
            "{}: file has a header (line 1) but no data rows",
            p.display()
        )
    );
}

#[test]
fn read_error_ragged_row() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "r.csv", b"a,b\n1,2\n3\n");
    assert_eq!(
        err(&p, &ReadOptions::default()),
        format!(
            "{}:3: row has 1 fields; expected 2 like line 1",
            p.display()
        )
    );
}

#[test]
fn read_error_not_a_number_counts_physical_lines() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "n.csv", b"gyro_x,gyro_y\n1,2\n\n3,abc\n");
    assert_eq!(
        err(&p, &ReadOptions::default()),
        format!("{}:4: column gyro_y: \"abc\" is not a number", p.display())
    );
    let p = write(&d, "e.csv", b"gyro_x,gyro_y\n1,2\n3,\n");
    assert_eq!(
        err(&p, &ReadOptions::default()),
        format!("{}:3: column gyro_y: \"\" is not a number", p.display())
    );
}

#[test]
fn read_error_non_finite_cell() {
    let d = tempfile::tempdir().unwrap();
    for cell in ["nan", "NaN", "inf", "-Infinity"] {
        let p = write(
            &d,
            "imu.csv.gz",
            &gzip(format!("gyro_x\n1\n{cell}\n").as_bytes()),
        );
        assert_eq!(
            err(&p, &ReadOptions::default()),
            format!(
                "{}:3: column gyro_x: \"{cell}\" is not a finite number",
                p.display()
            )
        );
    }
}

#[test]
fn read_error_unknown_column() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "u.csv", b"gyro_x,gyro_y\n1,2\n");
    let o = ReadOptions {
        columns: names(&["gyro_w"]),
        ..ReadOptions::default()
    };
    assert_eq!(
        err(&p, &o),
        format!(
            "{}: no column named \"gyro_w\"; available: gyro_x, gyro_y",
            p.display()
        )
    );
}

#[test]
fn read_error_column_out_of_range() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "o.csv", b"1,2\n");
    let o = ReadOptions {
        columns: vec![ColumnSelector::Index(3)],
        ..ReadOptions::default()
    };
    assert_eq!(
        err(&p, &o),
        format!(
            "{}: column 3 is out of range; the file has 2 columns (1-based: 1..=2)",
            p.display()
        )
    );
}

#[test]
fn read_gzip_by_magic_bytes_and_bad_streams() {
    let d = tempfile::tempdir().unwrap();
    let body: String = (0..20_000).map(|i| format!("{i}.25\n")).collect();
    let z = gzip(format!("x\n{body}").as_bytes());
    // gzip without a .gz name
    let p = write(&d, "plain.csv", &z);
    let t = read(&p).unwrap();
    assert_eq!(t.columns[0].values.len(), 20_000);
    assert_eq!(t.columns[0].values[19_999], 19_999.25);
    // truncated
    let p = write(&d, "trunc.csv.gz", &z[..z.len() / 2]);
    let msg = err(&p, &ReadOptions::default());
    assert!(
        msg.starts_with(&format!(
            "{}: corrupt or truncated gzip stream: ",
            p.display()
        )),
        "{msg}"
    );
    // corrupt deflate data
    let mut bad = z.clone();
    for b in &mut bad[20..60] {
        *b = 0xff;
    }
    let p = write(&d, "bad.csv.gz", &bad);
    let msg = err(&p, &ReadOptions::default());
    assert!(
        msg.starts_with(&format!(
            "{}: corrupt or truncated gzip stream: ",
            p.display()
        )),
        "{msg}"
    );
}

#[test]
fn read_error_sidecar_unreadable() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "s.csv", b"1\n2\n");
    let j = write(&d, "s.json", b"{\"sampling_frequency_hz\": ");
    let msg = err(&p, &ReadOptions::default());
    assert!(
        msg.starts_with(&format!("{}: sidecar JSON is unreadable: ", j.display())),
        "{msg}"
    );
}

/// `gmwm wv s.csv --json > s.json`: the shell creates the empty `s.json` before the run, and
/// afterwards it holds a WV document; neither is the recording's sidecar, the real one (at the
/// writers' name) is read, and each file passed over is a warning.
#[test]
fn files_at_a_sidecar_name_that_are_not_sidecars_are_passed_over() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "s.csv", b"1\n2\n3\n");
    let legacy = write(&d, "s.json", b"");
    let table = read(&p).unwrap();
    assert_eq!(table.facts.freq_hz, None);
    let said: Vec<String> = table.facts.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(
        said,
        vec![format!(
            "{}: not read as the recording's sidecar: it is empty",
            legacy.display()
        )]
    );
    for (doc, what) in [
        ("{\"series\": []}", "a wavelet or Allan variance document"),
        ("{\"name\": \"x\", \"axes\": []}", "a calibration document"),
        ("{\"fits\": []}", "a fit document"),
        ("[1, 2]", "it is JSON but not an object"),
        ("{\"hello\": 1}", "none of a sidecar's keys"),
    ] {
        std::fs::write(&legacy, doc).unwrap();
        write(&d, "s.csv.json", b"{\"sampling_frequency_hz\": 50}");
        let table = read(&p).unwrap();
        assert_eq!(table.facts.freq_hz, Some(50.0), "{doc}");
        // the writers' name comes first: the legacy one is not even looked at
        assert!(table.facts.warnings.is_empty(), "{doc}");
        std::fs::remove_file(d.path().join("s.csv.json")).unwrap();
        let table = read(&p).unwrap();
        assert_eq!(table.facts.freq_hz, None, "{doc}");
        let said = table.facts.warnings[0].to_string();
        assert!(said.contains(what), "{doc}: {said}");
    }
    // a sidecar with a typo stays an error, not passed over
    std::fs::write(&legacy, b"{\"sampling_frequency_hz\": ").unwrap();
    assert!(err(&p, &ReadOptions::default()).contains("sidecar JSON is unreadable"));
}

/// A truncated copy beside the sidecar of the whole recording: read, with a warning naming
/// both counts; a sidecar stating a raw layout the file's name contradicts: refused.
#[test]
fn a_sidecar_is_held_against_the_file() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "s.csv", b"1\n2\n3\n");
    write(
        &d,
        "s.csv.json",
        b"{\"n_rows\": 5, \"sampling_frequency_hz\": 10}",
    );
    let table = read(&p).unwrap();
    let said: Vec<String> = table.facts.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(
        said,
        vec![format!(
            "{}: its sidecar says n_rows = 5 but the file holds 3 rows (a truncated or partial copy?); the 3 rows are analysed",
            p.display()
        )]
    );
    let raw = write(&d, "r.f64", &[0u8; 64]);
    write(&d, "r.f64.json", b"{\"format\": \"f32\", \"n_rows\": 8}");
    let msg = err(&raw, &ReadOptions::default());
    assert!(
        msg.contains("invalid sidecar format = f32") && msg.contains("(f64)"),
        "{msg}"
    );
    // the flag decides
    let opts = ReadOptions {
        format: InputFormat::F64,
        ..ReadOptions::default()
    };
    let table = read_table(&raw, &opts).unwrap();
    assert_eq!(table.columns[0].values.len(), 8);
    assert_eq!(table.facts.warnings.len(), 0, "{:?}", table.facts.warnings);
}

#[test]
fn imu_from_table_without_freq_fails() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "nofreq.csv", b"gyro_x\n1\n2\n");
    let e = Imu::from_table(read(&p).unwrap()).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "{}: sampling frequency cannot be derived: no freq_hz given, no time column, \
             no sampling_frequency_hz in a sidecar",
            p.display()
        )
    );
}

#[test]
fn imu_from_table_refuses_duplicate_axes() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "dup.csv", b"gyro_x,Gyro. X\n1,2\n");
    let o = ReadOptions {
        freq_hz: Some(100.0),
        ..ReadOptions::default()
    };
    let e = Imu::from_table(read_table(&p, &o).unwrap()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "invalid axis = Gyroscope X twice: each axis at most once per sensor"
    );
}

// ---------------------------------------------------------------- binary

#[test]
fn binary_f64_f32_round_trip_ncols_3() {
    let d = tempfile::tempdir().unwrap();
    let rows = 1000;
    let data: Vec<f64> = (0..rows * 3).map(|i| i as f64 * 0.5 - 7.0).collect();
    let p = write(&d, "x.f64le.bin", &f64_bytes(&data));
    let o = ReadOptions {
        ncols: Some(3),
        ..ReadOptions::default()
    };
    let t = read_table(&p, &o).unwrap();
    assert_eq!(t.columns.len(), 3);
    for k in 0..3 {
        assert_eq!(t.columns[k].name, format!("col{}", k + 1));
        let want: Vec<f64> = data.iter().skip(k).step_by(3).copied().collect();
        assert_eq!(t.columns[k].values, want);
    }
    // f32, explicit format, selection of column 2
    let bytes: Vec<u8> = data
        .iter()
        .flat_map(|&x| (x as f32).to_le_bytes())
        .collect();
    let p = write(&d, "x.raw", &bytes);
    let o = ReadOptions {
        format: InputFormat::F32,
        ncols: Some(3),
        columns: vec![ColumnSelector::Index(2)],
        ..ReadOptions::default()
    };
    let t = read_table(&p, &o).unwrap();
    let want: Vec<f64> = data.iter().skip(1).step_by(3).copied().collect();
    assert_eq!(t.columns[0].values, want);
}

#[test]
fn binary_time_column() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "t.f64", &f64_bytes(&[0.0, 1.0, 0.5, 2.0, 1.0, 3.0]));
    let o = ReadOptions {
        ncols: Some(2),
        time_column: Some(ColumnSelector::Index(1)),
        ..ReadOptions::default()
    };
    let t = read_table(&p, &o).unwrap();
    assert_eq!(t.facts.freq_hz, Some(2.0));
    assert_eq!(t.columns[0].values, [1.0, 2.0, 3.0]);
}

#[test]
fn binary_error_size_not_multiple() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "s.f64", &[0u8; 20]);
    let o = ReadOptions {
        ncols: Some(3),
        ..ReadOptions::default()
    };
    assert_eq!(
        err(&p, &o),
        format!(
            "{}: size 20 bytes is not a multiple of the record size 24 bytes (20 bytes left over)",
            p.display()
        )
    );
    let p = write(&d, "e.f64", b"");
    assert_eq!(
        err(&p, &ReadOptions::default()),
        format!("{}: file is empty (no data rows)", p.display())
    );
}

#[test]
fn binary_error_non_finite() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "n.f64", &f64_bytes(&[1.0, 2.0, 3.0, f64::NAN]));
    let o = ReadOptions {
        ncols: Some(2),
        ..ReadOptions::default()
    };
    assert_eq!(
        err(&p, &o),
        format!(
            "{}: sample 1 (0-based) of column 2: NaN is not a finite number",
            p.display()
        )
    );
    let o = ReadOptions {
        ncols: Some(0),
        ..ReadOptions::default()
    };
    assert_eq!(
        err(&p, &o),
        "invalid ncols = 0: at least 1 interleaved column"
    );
}

#[test]
fn binary_chunks_equal_full_read() {
    let d = tempfile::tempdir().unwrap();
    let rows: usize = 10_007;
    let data: Vec<f64> = (0..rows * 3).map(|i| (i as f64).sin()).collect();
    let p = write(&d, "c.f64le.bin", &f64_bytes(&data));
    let full = read_table(
        &p,
        &ReadOptions {
            ncols: Some(3),
            ..ReadOptions::default()
        },
    )
    .unwrap();
    for chunk_len in [1, 7, 4096] {
        let mut got = Vec::new();
        let mut sizes = Vec::new();
        for_each_chunk(&p, InputFormat::F64, 3, 2, chunk_len, |c| {
            sizes.push(c.len());
            got.extend_from_slice(c);
            Ok(())
        })
        .unwrap();
        assert_eq!(got, full.columns[1].values, "chunk_len {chunk_len}");
        assert!(sizes.iter().all(|&s| s <= chunk_len && s > 0));
        assert_eq!(sizes.len(), rows.div_ceil(chunk_len));
    }
    let chunks = BinaryChunks::open(&p, InputFormat::F64, 3, 1, 10).unwrap();
    assert_eq!(chunks.rows(), rows as u64);
}

#[test]
fn binary_chunks_of_several_columns_in_one_pass() {
    // three interleaved columns: a read of columns 3 and 1 gives each column's values, chunk
    // by chunk, and a bad value is named by its row and column, the first in file order
    let d = tempfile::tempdir().unwrap();
    let rows = 37;
    let mut data: Vec<f64> = (0..rows * 3).map(|i| i as f64).collect();
    let p = write(&d, "c3.f64", &f64_bytes(&data));
    let mut chunks = BinaryChunks::open(&p, InputFormat::F64, 3, 1, 10).unwrap();
    let mut out = vec![Vec::new(), Vec::new()];
    let (mut third, mut first) = (Vec::new(), Vec::new());
    while let Some(n) = chunks.next_chunk_of(&[3, 1], &mut out).unwrap() {
        assert_eq!(out[0].len(), n);
        third.extend_from_slice(&out[0]);
        first.extend_from_slice(&out[1]);
    }
    assert_eq!(
        third,
        (0..rows).map(|r| (3 * r + 2) as f64).collect::<Vec<_>>()
    );
    assert_eq!(first, (0..rows).map(|r| (3 * r) as f64).collect::<Vec<_>>());
    data[3 * 21 + 2] = f64::NAN;
    data[3 * 22] = f64::INFINITY;
    let p = write(&d, "bad.f64", &f64_bytes(&data));
    let mut chunks = BinaryChunks::open(&p, InputFormat::F64, 3, 1, 40).unwrap();
    let e = chunks.next_chunk_of(&[1, 3], &mut out).unwrap_err();
    assert!(
        e.to_string().contains("sample 21 (0-based) of column 3"),
        "{e}"
    );
    assert!(chunks.next_chunk_of(&[4], &mut out).is_err());
}

#[test]
fn binary_chunks_errors() {
    let d = tempfile::tempdir().unwrap();
    let mut data = vec![1.0; 100];
    data[57] = f64::INFINITY;
    let p = write(&d, "c.f64", &f64_bytes(&data));
    let mut chunks = BinaryChunks::open(&p, InputFormat::F64, 1, 1, 16).unwrap();
    let mut e = None;
    while e.is_none() {
        match chunks.next_chunk() {
            Ok(Some(_)) => {}
            Ok(None) => break,
            Err(x) => e = Some(x),
        }
    }
    assert_eq!(
        e.unwrap().to_string(),
        format!(
            "{}: sample 57 (0-based) of column 1: inf is not a finite number",
            p.display()
        )
    );
    assert_eq!(
        BinaryChunks::open(&p, InputFormat::F64, 2, 3, 16)
            .unwrap_err()
            .to_string(),
        format!(
            "{}: column 3 is out of range; the file has 2 columns (1-based: 1..=2)",
            p.display()
        )
    );
    assert!(BinaryChunks::open(&p, InputFormat::Csv, 1, 1, 16).is_err());
    assert!(BinaryChunks::open(&p, InputFormat::F64, 1, 1, 0).is_err());
    // an error of the consumer stops the loop and comes back unchanged
    let mut calls = 0;
    let r = for_each_chunk(&p, InputFormat::F32, 1, 1, 8, |_| {
        calls += 1;
        Err(gmwm::ParamError::new("x", 1, "stop").into())
    });
    assert_eq!(r.unwrap_err().to_string(), "invalid x = 1: stop");
    assert_eq!(calls, 1);
}

// ---------------------------------------------------------------- IMU records, docs/methods.md
// §9.2-9.3

fn int_record(t: f64, v: [i32; 6]) -> Vec<u8> {
    let mut b = t.to_le_bytes().to_vec();
    for x in v {
        b.extend_from_slice(&x.to_le_bytes());
    }
    b
}

fn double_record(t: f64, v: [f64; 6]) -> Vec<u8> {
    let mut b = t.to_le_bytes().to_vec();
    for x in v {
        b.extend_from_slice(&x.to_le_bytes());
    }
    b
}

/// docs/methods.md §9.2 test value: 2 LN200 epochs 5 ms apart, gyro X 2^21 counts → 200 Hz, 200
/// rad/s.
#[test]
fn imu_record_ln200_test_value() {
    let d = tempfile::tempdir().unwrap();
    let mut b = int_record(0.0, [2_097_152, 0, 0, 0, 0, 16_384]);
    b.extend(int_record(0.005, [2_097_152, 0, 0, 0, 0, -16_384]));
    let p = write(&d, "ln200.bin", &b);
    let imu = read_imu_record_file(&p, ImuRecordType::Ln200).unwrap();
    assert_eq!(imu.freq_hz(), 200.0);
    assert_eq!(imu.len(), 2);
    assert_eq!(imu.num_sensor(), (3, 3));
    assert_eq!(imu.axis("gyro_x").unwrap().values(), [200.0, 200.0]);
    assert_eq!(imu.axis("accel_z").unwrap().values(), [200.0, -200.0]);
    assert_eq!(imu.record_type(), Some(ImuRecordType::Ln200));
    let tags: Vec<String> = imu.iter().map(|(t, _)| t).collect();
    assert_eq!(
        tags,
        ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]
    );
}

/// docs/methods.md §9.2 test value: a 33-byte LN200 file is refused.
#[test]
fn imu_record_33_bytes_refused() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "bad.bin", &[0u8; 33]);
    assert_eq!(
        read_imu_record_file(&p, ImuRecordType::Ln200)
            .unwrap_err()
            .to_string(),
        format!(
            "{}: size 33 bytes is not a multiple of the record size 32 bytes (1 bytes left over)",
            p.display()
        )
    );
}

/// docs/methods.md §9.3 test value: IXSEA, 1 count of gyro at 100 Hz = 4.8481368e-4 rad/s.
#[test]
fn imu_record_ixsea_test_value() {
    let d = tempfile::tempdir().unwrap();
    let mut b = Vec::new();
    for i in 0..5 {
        b.extend(double_record(
            10.0 + i as f64 * 0.01,
            [1.0, 0.0, 0.0, 0.0, 0.0, 2.0],
        ));
    }
    let p = write(&d, "ixsea.bin", &b);
    let imu = read_imu_record_file(&p, ImuRecordType::Ixsea).unwrap();
    assert_eq!(imu.freq_hz(), 100.0);
    let g = imu.axis("gyro_x").unwrap().values()[0];
    assert!((g - 4.8481368e-4).abs() < 1e-7 * 4.8481368e-4, "{g}");
    assert!((imu.axis("accel_z").unwrap().values()[0] - 0.2).abs() < 1e-15);
}

#[test]
fn imu_record_errors() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "one.bin", &int_record(0.0, [1; 6]));
    assert_eq!(
        read_imu_record_file(&p, ImuRecordType::Imar)
            .unwrap_err()
            .to_string(),
        format!(
            "{}: sampling frequency cannot be derived: fewer than 2 epochs",
            p.display()
        )
    );
    let mut b = double_record(0.0, [1.0; 6]);
    b.extend(double_record(0.01, [1.0, 1.0, f64::NAN, 1.0, 1.0, 1.0]));
    let p = write(&d, "nan.bin", &b);
    assert_eq!(
        read_imu_record_file(&p, ImuRecordType::NavchipFlt)
            .unwrap_err()
            .to_string(),
        format!(
            "{}: sample 1 (0-based) of column 4: NaN is not a finite number",
            p.display()
        )
    );
}

// ---------------------------------------------------------------- shared recordings

fn mean(x: &[f64]) -> f64 {
    crate::tests::common::neumaier_sum(x.iter().copied()) / x.len() as f64
}

#[test]
fn data_adis_16405_imu1_reads_whole() {
    let p = data_dir().join("adis_16405_imu1.csv.gz");
    let t = read(&p).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(t.columns.len(), 6);
    assert_eq!(t.len(), 1_000_000);
    assert_eq!(t.facts.freq_hz, Some(100.0));
    let first: Vec<f64> = t.columns.iter().map(|c| c.values[0]).collect();
    assert_eq!(first, [-0.05, -0.3, 0.7, -0.00666, 0.0, -1.01565]);
    let sidecar = t.facts.sidecar.as_ref().unwrap();
    for c in &t.columns {
        let want = sidecar.summary[&c.name].mean.unwrap();
        let got = mean(&c.values);
        assert!(
            (got - want).abs() <= MEAN_REL_TOL * want.abs(),
            "{}: {got} vs {want}",
            c.name
        );
    }
    let imu = Imu::from_table(t).unwrap();
    assert_eq!(imu.num_sensor(), (3, 3));
    assert_eq!(imu.name(), Some("adis_16405_imu1"));
    let tags: Vec<String> = imu.iter().map(|(t, _)| t).collect();
    assert_eq!(
        tags,
        ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]
    );
    assert!(imu.gyroscopes().all(|a| a
        .info
        .unit
        .as_deref()
        .is_some_and(|u| u.starts_with("deg/s"))));
}

#[test]
fn data_adis_16405_imu1_select_by_name_and_index() {
    let p = data_dir().join("adis_16405_imu1.csv.gz");
    let by_name = read_table(
        &p,
        &ReadOptions {
            columns: names(&["accel_z", "gyro_x"]),
            ..ReadOptions::default()
        },
    )
    .unwrap();
    let by_index = read_table(
        &p,
        &ReadOptions {
            columns: names(&["6", "1"]),
            ..ReadOptions::default()
        },
    )
    .unwrap();
    assert_eq!(by_name, by_index);
    assert_eq!(by_name.columns[0].name, "accel_z");
    assert_eq!(by_name.columns[0].values[0], -1.01565);
    assert_eq!(by_name.columns[1].values[0], -0.05);
    assert_eq!(by_name.columns[1].values.len(), 1_000_000);
}

#[test]
fn data_cont_imu1_is_one_gyroscope() {
    let p = data_dir().join("cont_imu1.csv.gz");
    let imu = Imu::from_table(read(&p).unwrap_or_else(|e| panic!("{e}"))).unwrap();
    assert_eq!(imu.num_sensor(), (1, 0));
    assert_eq!(imu.len(), 500_000);
    assert_eq!(imu.freq_hz(), 100.0);
    let g = imu.gyroscopes().next().unwrap();
    assert_eq!(g.tag(), "gyro_x");
    assert_eq!(g.sensor(), Sensor::Gyroscope);
    assert_eq!(imu.accelerometers().count(), 0);
}

#[test]
fn read_line_numbers_with_crlf_blank_lines_and_no_final_newline() {
    let d = tempfile::tempdir().unwrap();
    let cases: [(&[u8], u64); 4] = [
        (b"x,y\r\n1,2\r\n\r\n3,4\r\n5,bad\r\n", 5),
        (b"x,y\n1,2\n  \n\n3,4\n5,bad", 6),
        (b"x,y\n5,bad\n", 2),
        (b"\n\nx,y\n1,2\n5,bad\n", 5),
    ];
    for (i, (bytes, line)) in cases.into_iter().enumerate() {
        let p = write(&d, &format!("l{i}.csv"), bytes);
        assert_eq!(
            err(&p, &ReadOptions::default()),
            format!("{}:{line}: column y: \"bad\" is not a number", p.display()),
            "case {i}"
        );
    }
    let p = write(&d, "ok.csv", b"x,y\r\n1,2\r\n\r\n3,4");
    assert_eq!(read(&p).unwrap().columns[1].values, [2.0, 4.0]);
}

#[test]
fn read_multi_member_gzip() {
    let d = tempfile::tempdir().unwrap();
    let mut z = gzip(b"x\n1\n2\n");
    z.extend(gzip(b"3\n4\n"));
    let p = write(&d, "m.csv.gz", &z);
    assert_eq!(read(&p).unwrap().columns[0].values, [1.0, 2.0, 3.0, 4.0]);
}

// ---------------------------------------------------------------- time columns (issue: new user)

/// `n` rows `t,gyro_x` with stamps `t0 + i * step` (plus `hole` after row `gap_at`).
fn timed_csv(header: &str, t0: f64, step: f64, n: usize, gap_at: usize, hole: f64) -> String {
    let mut s = format!("{header},gyro_x\n");
    for i in 0..n {
        let t = t0 + i as f64 * step + if i >= gap_at { hole } else { 0.0 };
        s.push_str(&format!("{t},{}\n", (i % 7) as f64 * 0.1));
    }
    s
}

/// A ROS-style time column in nanoseconds was read as seconds (rate 1e-7 Hz, no warning).
#[test]
fn issue_time_column_in_ns_is_not_read_as_seconds() {
    let d = tempfile::tempdir().unwrap();
    // relative ns stamps (ROS sim time): the step says ns
    let p = write(
        &d,
        "ros.csv",
        timed_csv("stamp", 0.0, 5e6, 100, usize::MAX, 0.0).as_bytes(),
    );
    let t = read(&p).unwrap();
    assert_eq!(t.facts.freq_hz, Some(200.0));
    let timing = t.facts.timing.as_ref().unwrap();
    assert_eq!(timing.unit, TimeUnit::Nanoseconds);
    assert_eq!(timing.unit_source, UnitSource::Inferred);
    assert_eq!(
        t.time.as_ref().unwrap().values[1],
        0.005,
        "stamps in seconds"
    );
    // Unix-epoch ns stamps, the column given by index: the magnitude says ns
    let mut epoch = String::from("when,gyro_x\n");
    for i in 0..100u64 {
        epoch.push_str(&format!(
            "{},{}\n",
            1_700_000_000_000_000_000 + i * 5_000_000,
            i % 3
        ));
    }
    let p = write(&d, "epoch.csv", epoch.as_bytes());
    let o = ReadOptions {
        time_column: Some(ColumnSelector::Index(1)),
        ..ReadOptions::default()
    };
    let t = read_table(&p, &o).unwrap();
    assert!(
        (t.facts.freq_hz.unwrap() - 200.0).abs() < 1e-6,
        "{:?}",
        t.facts.freq_hz
    );
    assert_eq!(t.facts.timing.as_ref().unwrap().unit, TimeUnit::Nanoseconds);
    // the name states the unit; a given unit wins and is reported as given
    let p = write(
        &d,
        "stated.csv",
        timed_csv("%time", 0.0, 5e6, 100, usize::MAX, 0.0).as_bytes(),
    );
    let t = read(&p).unwrap();
    assert_eq!(
        t.facts.timing.as_ref().unwrap().unit_source,
        UnitSource::Stated
    );
    assert_eq!(t.facts.freq_hz, Some(200.0));
    let o = ReadOptions {
        time_unit: Some(TimeUnit::Microseconds),
        ..ReadOptions::default()
    };
    let t = read_table(&p, &o).unwrap();
    assert_eq!(
        t.facts.timing.as_ref().unwrap().unit_source,
        UnitSource::Flag
    );
    assert!((t.facts.freq_hz.unwrap() - 0.2).abs() < 1e-12);
}

/// A 0.5 s gap in a 200 Hz log was averaged into the rate silently.
#[test]
fn issue_gap_is_not_averaged_into_the_rate() {
    let d = tempfile::tempdir().unwrap();
    let p = write(
        &d,
        "gap.csv",
        timed_csv("time", 0.0, 0.005, 2000, 1000, 0.5).as_bytes(),
    );
    let t = read(&p).unwrap();
    assert!(
        (t.facts.freq_hz.unwrap() - 200.0).abs() < 1e-9,
        "{:?}",
        t.facts.freq_hz
    );
    let timing = t.facts.timing.as_ref().unwrap();
    assert!((timing.mean_rate_hz - 1999.0 / 10.495).abs() < 1e-9);
    assert_eq!(timing.gaps.len(), 1);
    let g = &timing.gaps[0];
    assert_eq!((g.row, g.line, g.missing), (1000, Some(1002), 100));
    assert!((g.duration_s - 0.5).abs() < 1e-9);
    assert_eq!(t.facts.warnings.len(), 1);
    assert_eq!(
        t.facts.warnings[0].to_string(),
        format!(
            "{}: time column \"time\": 1 gap (100 samples missing), largest 0.50 s at line 1002 \
             (5.00 s after the start); 200 Hz between them",
            p.display()
        )
    );
    assert!(matches!(
        &t.facts.warnings[0],
        ReadWarning::Timing {
            warning: TimingWarning::Gaps { count: 1, .. },
            ..
        }
    ));
}

/// `--freq 100` silently overrode a 200 Hz time column.
#[test]
fn issue_freq_disagreeing_with_the_time_column_is_warned() {
    let d = tempfile::tempdir().unwrap();
    let p = write(
        &d,
        "t.csv",
        timed_csv("t", 0.0, 0.005, 100, usize::MAX, 0.0).as_bytes(),
    );
    let o = ReadOptions {
        freq_hz: Some(100.0),
        ..ReadOptions::default()
    };
    let t = read_table(&p, &o).unwrap();
    assert_eq!(t.facts.freq_hz, Some(100.0), "the given rate still wins");
    assert_eq!(t.facts.warnings.len(), 1);
    assert_eq!(
        t.facts.warnings[0].to_string(),
        format!(
            "{}: the rate given (100 Hz) differs by 50% from time column \"t\" (200 Hz); the \
             given rate is used",
            p.display()
        )
    );
    // within 1%: no warning
    let o = ReadOptions {
        freq_hz: Some(200.5),
        ..ReadOptions::default()
    };
    assert!(read_table(&p, &o).unwrap().facts.warnings.is_empty());
    // a sidecar rate that disagrees is reported, the time column's is used
    write(&d, "t.csv.json", br#"{"sampling_frequency_hz": 100}"#);
    let t = read(&p).unwrap();
    assert!((t.facts.freq_hz.unwrap() - 200.0).abs() < 1e-9);
    assert!(matches!(
        t.facts.warnings[..],
        [ReadWarning::SidecarFreqDisagrees { .. }]
    ));
}

/// Columns named `time` or `timestamp` were analysed as sensor data.
#[test]
fn issue_time_columns_are_not_analysed() {
    let d = tempfile::tempdir().unwrap();
    let p = write(
        &d,
        "two.csv",
        b"timestamp,x,time\n0,1,10\n0.01,2,10.01\n0.02,4,10.02\n",
    );
    let t = read(&p).unwrap();
    let names: Vec<&str> = t.columns.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["x"]);
    assert_eq!(t.facts.timing.as_ref().unwrap().column, "timestamp");
    assert_eq!(t.facts.skipped, ["time"]);
    assert!((t.facts.freq_hz.unwrap() - 100.0).abs() < 1e-9);
    // selecting the time column explicitly analyses it (and it is then not the time)
    let o = ReadOptions {
        columns: names_of(&["timestamp", "x"]),
        ..ReadOptions::default()
    };
    let t = read_table(&p, &o).unwrap();
    assert_eq!(t.columns.len(), 2);
    assert_eq!(t.facts.timing.as_ref().unwrap().column, "time");
    // time stamps that go backwards stay an error naming the line
    let p = write(&d, "back.csv", b"time,x\n0,1\n0.01,2\n0.005,3\n");
    assert_eq!(
        err(&p, &ReadOptions::default()),
        format!(
            "{}:4: column time: time 0.005 is not greater than the previous time 0.01; the time \
             column must be strictly increasing (--time-policy drop-duplicates drops such rows, \
             --time-policy sort sorts them)",
            p.display()
        )
    );
}

fn names_of(v: &[&str]) -> Vec<ColumnSelector> {
    v.iter().map(|s| s.parse().unwrap()).collect()
}

/// EuRoC / TUM-VI `imu0/data.csv`: ns stamps named in the header, gyro `w_*`, accel `a_*`,
/// units from the brackets.
#[test]
fn euroc_layout_reads_as_an_imu() {
    let d = tempfile::tempdir().unwrap();
    let mut s = String::from(
        "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],\
         a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n",
    );
    for i in 0..400u64 {
        let t = 1_403_636_579_758_555_392 + i * 5_000_000;
        s.push_str(&format!("{t},0.1,-0.2,{},9.8,0.1,0.2\n", i % 3));
    }
    let p = write(&d, "data.csv", s.as_bytes());
    let imu = Imu::from_table(read(&p).unwrap()).unwrap();
    assert_eq!(imu.num_sensor(), (3, 3));
    assert!((imu.freq_hz() - 200.0).abs() < 1e-6);
    let timing = imu.timing().unwrap();
    assert_eq!(timing.column, "#timestamp [ns]");
    assert_eq!(
        (timing.unit, timing.unit_source),
        (TimeUnit::Nanoseconds, UnitSource::Stated)
    );
    let g = imu.axis("gyro_z").unwrap();
    assert_eq!(g.info.unit.as_deref(), Some("rad s^-1"));
    assert_eq!(g.column.name, "w_RS_S_z [rad s^-1]");
    assert_eq!(
        imu.axis("accel_x").unwrap().info.unit.as_deref(),
        Some("m s^-2")
    );
    assert!(imu.warnings().is_empty());
}

/// `rostopic echo -p` CSV: `%time` and `field.header.stamp` (ns, the header stamp preferred),
/// non-sensor columns (one of them text) left out of the default selection.
#[test]
fn rostopic_layout_reads_the_sensor_columns() {
    let d = tempfile::tempdir().unwrap();
    let mut s = String::from(
        "%time,field.header.seq,field.header.stamp,field.header.frame_id,field.orientation.x,\
         field.angular_velocity.x,field.angular_velocity.y,field.angular_velocity.z,\
         field.linear_acceleration.x,field.linear_acceleration.y,field.linear_acceleration.z\n",
    );
    for i in 0..300u64 {
        let stamp = 1_700_000_000_000_000_000 + i * 10_000_000;
        let recv = stamp + 2_000_000 + (i % 5) * 100_000;
        s.push_str(&format!(
            "{recv},{i},{stamp},imu_link,0,0.1,0.2,0.3,0,0,9.8\n"
        ));
    }
    let p = write(&d, "imu.csv", s.as_bytes());
    let t = read(&p).unwrap();
    assert_eq!(
        t.facts.timing.as_ref().unwrap().column,
        "field.header.stamp"
    );
    assert!((t.facts.freq_hz.unwrap() - 100.0).abs() < 1e-6);
    assert_eq!(
        t.facts.skipped,
        [
            "%time",
            "field.header.seq",
            "field.header.frame_id",
            "field.orientation.x"
        ]
    );
    let imu = Imu::from_table(t).unwrap();
    let tags: Vec<String> = imu.iter().map(|(t, _)| t).collect();
    assert_eq!(
        tags,
        ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]
    );
}

#[test]
fn short_headers_time_ax_gx() {
    let d = tempfile::tempdir().unwrap();
    let mut s = String::from("time,ax,ay,az,gx,gy,gz,temp\n");
    for i in 0..50 {
        s.push_str(&format!("{},1,2,3,4,5,{},25\n", i as f64 * 0.01, i % 4));
    }
    let p = write(&d, "log.txt", s.as_bytes());
    let t = read(&p).unwrap();
    assert_eq!(t.facts.skipped, ["temp"]);
    let imu = Imu::from_table(t).unwrap();
    assert_eq!(imu.num_sensor(), (3, 3));
    assert!((imu.freq_hz() - 100.0).abs() < 1e-9);
}

// ---------------------------------------------------------------- content sniffing

/// A `.bin` without a format was parsed as text and ~19 KB of raw bytes landed in the error.
#[test]
fn issue_binary_content_without_format_is_one_short_line() {
    let d = tempfile::tempdir().unwrap();
    let mut state = 12345u64;
    let bytes: Vec<u8> = (0..19_000)
        .map(|_| {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
            (state >> 33) as u8
        })
        .collect();
    let p = write(&d, "x.bin", &bytes);
    let e = err(&p, &ReadOptions::default());
    assert_eq!(
        e,
        format!(
            "{}: looks like binary data, not text; give --format \
             f64|f32|imar|ln200|ln200ig|ixsea|navchip-int|navchip-flt",
            p.display()
        )
    );
    assert_eq!(sniff(&p).unwrap(), Content::Binary);
    // gzip of binary data too
    let p = write(&d, "y.gz", &gzip(&bytes));
    assert!(matches!(read(&p), Err(ReadError::LooksBinary { .. })));
    // forcing csv does not dump the bytes either
    let o = ReadOptions {
        format: InputFormat::Csv,
        ..ReadOptions::default()
    };
    assert!(matches!(
        read_table(&p, &o),
        Err(ReadError::LooksBinary { .. })
    ));
}

/// Text quoted in an error is at most 40 characters, non-printables escaped.
#[test]
fn quoted_file_text_is_cut_and_escaped() {
    let d = tempfile::tempdir().unwrap();
    let long = "y".repeat(500);
    let p = write(&d, "q.csv", format!("x\n1\n{long}\x07\n").as_bytes());
    let e = err(&p, &ReadOptions::default());
    assert_eq!(
        e,
        format!(
            "{}:3: column x: \"{}...\" is not a number",
            p.display(),
            "y".repeat(40)
        )
    );
    assert_eq!(gmwm::imu::quote("a\u{0}b\tc"), "a\\0b\\tc");
    // a long header in an unknown-column error
    let names: Vec<String> = (0..30).map(|k| format!("{}{k}", "h".repeat(60))).collect();
    let p = write(&d, "h.csv", format!("{}\n", names.join(",")).as_bytes());
    let o = ReadOptions {
        columns: names_of(&["nope"]),
        ..ReadOptions::default()
    };
    let e = err(&p, &o);
    assert!(e.len() < 1200, "{}", e.len());
    assert!(e.ends_with("... (10 more)"), "{e}");
}

#[test]
fn json_is_not_a_table() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "wv.txt", b"  {\"series\": []}");
    assert_eq!(sniff(&p).unwrap(), Content::Json);
    assert!(is_wv_json(&p));
    assert!(matches!(read(&p), Err(ReadError::NotATable { .. })));
}

// ---------------------------------------------------------------- writers and sidecars

/// `x.f64` was written as CSV text, and `x.txt` / `x.f64` both wrote `x.json`.
#[test]
fn issue_series_files_follow_their_extension_and_sidecars_do_not_collide() {
    let d = tempfile::tempdir().unwrap();
    let a: Vec<f64> = (0..100).map(|i| (i as f64 * 0.37).sin()).collect();
    let b: Vec<f64> = (0..100).map(|i| i as f64 * 1e-3 - 0.05).collect();
    for (name, format) in [
        ("x.f64", "f64"),
        ("x.txt", "csv"),
        ("x.f32.bin", "f32"),
        ("x.tsv", "tsv"),
        ("x.csv.gz", "csv"),
    ] {
        let p = d.path().join(name);
        let mut w = SeriesWriter::create(&p, &["a", "b"]).unwrap();
        w.write_rows(&[&a[..50], &b[..50]]).unwrap();
        w.write_rows(&[&a[50..], &b[50..]]).unwrap();
        assert_eq!(w.format().sidecar_name(), format);
        w.finish().unwrap();
        let sidecar = Sidecar {
            sampling_frequency_hz: Some(50.0),
            format: Some(format.into()),
            n_columns: Some(2),
            columns: ["a", "b"]
                .iter()
                .map(|n| SidecarColumn {
                    name: n.to_string(),
                    meaning: None,
                    unit: None,
                })
                .collect(),
            ..Sidecar::default()
        };
        let side = write_sidecar(&p, &sidecar).unwrap();
        assert_eq!(side, d.path().join(format!("{name}.json")));
        // read back without options
        let t = read(&p).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(t.facts.freq_hz, Some(50.0));
        assert_eq!(t.columns[0].name, "a", "{name}");
        if format == "f32" {
            let a32: Vec<f64> = a.iter().map(|&v| f64::from(v as f32)).collect();
            assert_eq!(t.columns[0].values, a32);
        } else {
            assert_eq!(t.columns[0].values, a, "{name}: same bits");
            assert_eq!(t.columns[1].values, b, "{name}");
        }
    }
    let raw = std::fs::read(d.path().join("x.f64")).unwrap();
    assert_eq!(raw.len(), 100 * 2 * 8, "raw interleaved f64, no text");
    assert_eq!(raw[..8], a[0].to_le_bytes());
    assert_eq!(raw[8..16], b[0].to_le_bytes());
    // the binary layout from the sidecar, for streaming readers
    let layout = binary_layout(&d.path().join("x.f64"), &ReadOptions::default())
        .unwrap()
        .unwrap();
    assert_eq!((layout.format, layout.ncols), (InputFormat::F64, 2));
    assert_eq!(layout.names, ["a", "b"]);
    assert!(
        binary_layout(&d.path().join("x.txt"), &ReadOptions::default())
            .unwrap()
            .is_none()
    );
    // unknown extensions are refused with the list
    let e = SeriesWriter::create(&d.path().join("x.xyz"), &["a"])
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("a file name ending in .csv, .txt, .tsv"), "{e}");
}

// ---------------------------------------------------------------- IMU records, every type

/// Hand scale factors of docs/methods.md §9.3 (rad or m/s per count), independent of the library's.
fn scales(t: ImuRecordType) -> (f64, f64) {
    let arcsec = std::f64::consts::PI / (180.0 * 3600.0);
    match t {
        ImuRecordType::Imar => (0.1 * arcsec, 1.52588e-6),
        ImuRecordType::Ln200 => (2f64.powi(-21), 2f64.powi(-14)),
        ImuRecordType::Ln200Ig => (2f64.powi(-19), 2f64.powi(-14)),
        ImuRecordType::Ixsea => (arcsec, 0.001),
        ImuRecordType::NavchipFlt => (2.0 * std::f64::consts::PI / (3600.0 * 360.0), 0.001),
        ImuRecordType::NavchipInt => (6.25e-6, 3.90625e-5),
    }
}

pub(crate) fn record(t: ImuRecordType, time: f64, counts: [i32; 6]) -> Vec<u8> {
    if t.is_double() {
        double_record(time, counts.map(f64::from))
    } else {
        int_record(time, counts)
    }
}

/// Every record type: known counts at 400 Hz read back as `counts · 400 · scale`, through
/// `read_table` (with `--columns`) and `read_imu_record_file`; truncated and non-monotonic
/// files refused with their errors.
#[test]
fn imu_records_every_type_rates_and_errors() {
    let d = tempfile::tempdir().unwrap();
    let counts = [[1000, -2000, 3, 10, -20, 30], [7, 0, -1, 16384, 1, -5]];
    for t in ImuRecordType::ALL {
        let mut b = Vec::new();
        for i in 0..6 {
            b.extend(record(t, 100.0 + i as f64 * 0.0025, counts[i % 2]));
        }
        let name = format!("{t}.bin");
        let p = write(&d, &name, &b);
        let (sg, sa) = scales(t);
        let imu = read_imu_record_file(&p, t).unwrap_or_else(|e| panic!("{t}: {e}"));
        assert_eq!(imu.freq_hz(), 400.0, "{t}");
        assert_eq!(imu.record_type(), Some(t));
        for (k, (tag, axis)) in imu.iter().enumerate() {
            let scale = if k < 3 { sg } else { sa };
            for (i, &v) in axis.values().iter().enumerate() {
                let want = f64::from(counts[i % 2][k]) * 400.0 * scale;
                assert!(
                    (v - want).abs() <= 1e-12 * want.abs(),
                    "{t} {tag}[{i}]: {v} vs {want}"
                );
            }
        }
        assert_eq!(
            imu.gyroscopes().next().unwrap().info.unit.as_deref(),
            Some("rad/s")
        );
        // read_table with the format and a column selection
        let o = ReadOptions {
            format: InputFormat::ImuRecord(t),
            columns: names_of(&["accel_z", "2"]),
            ..ReadOptions::default()
        };
        let table = read_table(&p, &o).unwrap();
        assert_eq!(table.facts.freq_hz, Some(400.0));
        assert_eq!(table.columns[0].name, "accel_z");
        assert_eq!(
            table.columns[0].values,
            imu.axis("accel_z").unwrap().values()
        );
        assert_eq!(
            table.columns[1].values,
            imu.axis("gyro_y").unwrap().values()
        );
        assert_eq!(table.facts.record_type, Some(t));
        // truncated
        let mut cut = b[..2 * t.record_size()].to_vec();
        cut.extend_from_slice(&[0; 5]);
        let p = write(&d, &format!("cut_{name}"), &cut);
        assert_eq!(
            read_imu_record_file(&p, t).unwrap_err().to_string(),
            format!(
                "{}: size {} bytes is not a multiple of the record size {} bytes (5 bytes left \
                 over)",
                p.display(),
                cut.len(),
                t.record_size()
            )
        );
        // time going backwards at record 2
        let mut back = record(t, 0.0, counts[0]);
        back.extend(record(t, 0.005, counts[0]));
        back.extend(record(t, 0.004, counts[0]));
        let p = write(&d, &format!("back_{name}"), &back);
        assert_eq!(
            read_table(
                &p,
                &ReadOptions {
                    format: InputFormat::ImuRecord(t),
                    ..ReadOptions::default()
                }
            )
            .unwrap_err()
            .to_string(),
            format!(
                "{}: record 2 (0-based): time 0.004 is not greater than the previous time 0.005; \
                 the epochs must be in strictly increasing time order",
                p.display()
            )
        );
    }
}

/// A gap in the epochs does not lower the rate that converts every increment.
#[test]
fn imu_record_gap_keeps_the_rate() {
    let d = tempfile::tempdir().unwrap();
    let mut b = Vec::new();
    for i in 0..100 {
        let t = i as f64 * 0.005 + if i >= 50 { 1.0 } else { 0.0 };
        b.extend(int_record(t, [2_097_152, 0, 0, 0, 0, 0]));
    }
    let p = write(&d, "gap.bin", &b);
    let imu = read_imu_record_file(&p, ImuRecordType::Ln200).unwrap();
    assert_eq!(imu.freq_hz(), 200.0);
    assert_eq!(imu.axis("gyro_x").unwrap().values()[0], 200.0);
    assert_eq!(imu.timing().unwrap().gaps.len(), 1);
    assert_eq!(imu.warnings().len(), 1);
}

// ---------------------------------------------------------------- WV JSON

#[test]
fn wv_json_series_by_name_or_index_and_allan_by_methods_3_4() {
    use gmwm::{allan_variance, wavelet_variance, AllanOptions, WvOptions};
    let x: Vec<f64> = (0..4096)
        .map(|i| ((i as f64) * 0.731).sin() + ((i * i) as f64 * 1e-3).cos())
        .collect();
    let wv = wavelet_variance(&x, 10.0, &WvOptions::default()).unwrap();
    let av = allan_variance(&x, 10.0, &AllanOptions::default()).unwrap();
    let conv = allan_from_wv(&wv).unwrap();
    let levels = conv.tau().len();
    assert_eq!(conv.tau()[..], av.tau()[..levels]);
    for j in 0..levels {
        for (a, b) in [
            (conv.avar()[j], av.avar()[j]),
            (conv.ci_low()[j], av.ci_low()[j]),
            (conv.ci_high()[j], av.ci_high()[j]),
            (conv.edf()[j], av.edf()[j]),
        ] {
            assert!((a - b).abs() <= 1e-9 * b.abs(), "level {j}: {a} vs {b}");
        }
        assert_eq!(conv.terms()[j], av.terms()[j]);
    }
    let robust = wavelet_variance(
        &x,
        10.0,
        &WvOptions {
            robust: Some(gmwm::RobustOptions::default()),
            ..WvOptions::default()
        },
    )
    .unwrap();
    assert!(allan_from_wv(&robust).is_err());
    // selection by name and index
    let p = Path::new("wv.json");
    let series = vec![("a".to_string(), wv.clone()), ("b".to_string(), wv)];
    let picked = select_series(p, series.clone(), &names_of(&["2", "a"])).unwrap();
    let names: Vec<&str> = picked.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["b", "a"]);
    assert_eq!(
        select_series(p, series.clone(), &names_of(&["3"]))
            .unwrap_err()
            .to_string(),
        "wv.json: series 3 is out of range; the file has 2 series (1-based: 1..=2)"
    );
    assert_eq!(
        select_series(p, series, &names_of(&["c"]))
            .unwrap_err()
            .to_string(),
        "wv.json: no series named \"c\"; available: a, b"
    );
}

/// `Wic::select_wv` on the WV of a series is `Wic::select` on the series (no drift in the
/// model, so the series range of the starting values plays no part).
#[test]
fn wic_select_wv_equals_select_on_the_series() {
    use gmwm::{wavelet_variance, Wic, WvOptions};
    let x = crate::tests::common::white_noise(2000, 1.0, 5);
    let wic = Wic::nested("AR1()+WN()".parse().unwrap())
        .unwrap()
        .with_bootstrap(10)
        .with_draws(200)
        .with_seed(3);
    let from_series = wic.select(&x, 10.0).unwrap();
    let wv = wavelet_variance(&x, 10.0, &WvOptions::default()).unwrap();
    let from_wv = wic.select_wv(&wv).unwrap();
    assert_eq!(from_wv.selected(), from_series.selected());
    assert_eq!(from_wv.candidates(), from_series.candidates());
}

/// Row accounting: the rows read, the samples used in each selected column, the header and
/// blank lines that hold none and the samples the stamps' gaps lack, counted exactly for
/// text (with blank and whitespace-only lines and a gap), raw binary and IMU records.
#[test]
fn read_accounts_for_every_row() {
    let d = tempfile::tempdir().unwrap();
    // 2 blank lines before the header, a whitespace-only and an empty line between rows, a
    // step of 4 nominal steps (3 samples missing), 7 data rows
    let text = "\n\ntime,gx,gy,label_count\n0,1,2,3\n   \n0.01,2,3,4\n\n0.02,3,4,5\n0.06,1,2,3\n\
                0.07,2,2,2\n0.08,4,1,0\n0.09,5,5,5\n";
    let p = write(&d, "gaps.csv", text.as_bytes());
    let opts = ReadOptions {
        columns: names(&["gx", "gy"]),
        ..ReadOptions::default()
    };
    let t = read_table(&p, &opts).unwrap();
    let s = &t.facts.samples;
    assert_eq!(s.columns, ["gx", "gy"]);
    assert_eq!((s.unit, s.read, s.used, s.missing), ("row", 7, 7, 3));
    let parts: Vec<(u64, &str)> = s
        .without_samples
        .iter()
        .map(|w| (w.count, w.what.as_str()))
        .collect();
    assert_eq!(parts, [(1, "header line"), (4, "blank line")]);
    assert_eq!(
        s.to_string(),
        "7 rows read, 7 samples used in each of 2 columns (gx, gy); no samples in 1 header \
         line, 4 blank lines; nothing dropped; 3 samples missing in the time stamps' gaps, not \
         filled in"
    );
    // gzip: the same account
    let gz = write(&d, "gaps.csv.gz", &gzip(text.as_bytes()));
    assert_eq!(
        read_table(&gz, &opts).unwrap().facts.samples,
        t.facts.samples
    );
    // no header, no blank line, no time column
    let p = write(&d, "plain.csv", b"1,2\n3,4\n5,6\n");
    let s = read(&p).unwrap().facts.samples;
    assert_eq!((s.read, s.used, s.missing), (3, 3, 0));
    assert!(s.without_samples.is_empty());
    assert!(
        s.to_string().ends_with("; nothing dropped or filled in"),
        "{s}"
    );
    // raw binary: rows of ncols values
    let p = write(&d, "raw.f64", &f64_bytes(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]));
    let s = read_table(
        &p,
        &ReadOptions {
            ncols: Some(2),
            ..ReadOptions::default()
        },
    )
    .unwrap()
    .facts
    .samples;
    assert_eq!((s.unit, s.read, s.used), ("row", 3, 3));
    assert_eq!(s.columns, ["col1", "col2"]);
    // IMU records: one sample of each axis per record
    let t = ImuRecordType::ALL[0];
    let b: Vec<u8> = (0..5)
        .flat_map(|i| record(t, 100.0 + f64::from(i) * 0.0025, [1, 2, 3, 4, 5, 6]))
        .collect();
    let p = write(&d, "rec.bin", &b);
    let s = read_table(
        &p,
        &ReadOptions {
            format: InputFormat::ImuRecord(t),
            ..ReadOptions::default()
        },
    )
    .unwrap()
    .facts
    .samples;
    assert_eq!(
        (s.unit, s.read, s.used, s.columns.len()),
        ("record", 5, 5, 6)
    );
}
