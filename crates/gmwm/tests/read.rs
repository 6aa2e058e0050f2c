//! Readers (METHODS §9): every malformed-input class with its exact message, text/gzip/binary
//! round trips, the chunked reader, IMU binary records (§9.2–9.3) and the shared recordings.

use crate::common::data_dir;
use flate2::write::GzEncoder;
use flate2::Compression;
use gmwm::imu::{
    for_each_chunk, read_imu_record_file, read_table, BinaryChunks, ColumnSelector, HeaderMode,
    Imu, ImuRecordType, InputFormat, ReadError, ReadOptions, Sensor,
};
use gmwm::math::sum::NeumaierSum;
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
    assert_eq!(t.freq_hz, None);
    assert_eq!(t.len(), 2);
    assert_eq!(t.path, p);
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
    assert_eq!(t.freq_hz, Some(62.5));
    assert_eq!(t.time.as_ref().unwrap().values, [0.0, 0.016, 0.032]);
    // an explicit rate wins over the time column
    let o = ReadOptions {
        freq_hz: Some(60.0),
        ..o
    };
    assert_eq!(read_table(&p, &o).unwrap().freq_hz, Some(60.0));
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
             the time column must be strictly increasing",
            p.display()
        )
    );
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
    assert_eq!(t.freq_hz, Some(250.0));
    assert_eq!(t.sidecar.as_ref().unwrap().name.as_deref(), Some("rec"));
    let o = ReadOptions {
        freq_hz: Some(10.0),
        ..ReadOptions::default()
    };
    assert_eq!(read_table(&p, &o).unwrap().freq_hz, Some(10.0));
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
    assert_eq!(t.freq_hz, Some(2.0));
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

// ---------------------------------------------------------------- IMU records, METHODS §9.2-9.3

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

/// METHODS §9.2 test value: 2 LN200 epochs 5 ms apart, gyro X 2^21 counts → 200 Hz, 200 rad/s.
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

/// METHODS §9.2 test value: a 33-byte LN200 file is refused.
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

/// METHODS §9.3 test value: IXSEA, 1 count of gyro at 100 Hz = 4.8481368e-4 rad/s.
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
    let mut s = NeumaierSum::default();
    for &v in x {
        s.add(v);
    }
    s.total() / x.len() as f64
}

#[test]
fn data_adis_16405_imu1_reads_whole() {
    let p = data_dir().join("adis_16405_imu1.csv.gz");
    let t = read(&p).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(t.columns.len(), 6);
    assert_eq!(t.len(), 1_000_000);
    assert_eq!(t.freq_hz, Some(100.0));
    let first: Vec<f64> = t.columns.iter().map(|c| c.values[0]).collect();
    assert_eq!(first, [-0.05, -0.3, 0.7, -0.00666, 0.0, -1.01565]);
    let sidecar = t.sidecar.as_ref().unwrap();
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
