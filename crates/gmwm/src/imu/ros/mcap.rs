//! MCAP (<https://mcap.dev/spec>), read record by record ([`StorageFile`]), through the `mcap`
//! crate's summary reader and record parser; chunks are decompressed here (pure-Rust zstd and
//! lz4).
//!
//! Topics are listed from the summary (channels, schemas, statistics) when the file has one,
//! else from a scan of the data section. Messages are read chunk by chunk: with chunk indexes,
//! only the chunks holding the topic's channels are opened; without them the data section is
//! scanned. Messages come out in file order; the caller sorts by log time when needed.

use super::decompress::{Codec, Decompressor};
use super::error::RosError;
use super::file::{Bytes, Memory, StorageFile};
use super::{Collector, Encoding, RosContainer};
use crate::imu::ReadError;
use mcap::records::{op, Record};
use mcap::sans_io::summary_reader::{SummaryReadEvent, SummaryReader, SummaryReaderOptions};
use std::collections::{BTreeMap, HashMap};
use std::io::SeekFrom;
use std::path::Path;

/// One channel (topic + schema + encoding) of an MCAP file.
#[derive(Debug, Clone)]
pub(crate) struct Channel {
    pub(crate) id: u16,
    pub(crate) topic: String,
    /// Schema name, e.g. `sensor_msgs/msg/Imu` (empty for a schemaless channel).
    pub(crate) message_type: String,
    /// Message encoding, e.g. `cdr` or `ros1`.
    pub(crate) encoding: String,
    pub(crate) messages: u64,
}

/// The channels of a file, and its summary when it has one.
pub(crate) struct Catalog {
    pub(crate) channels: Vec<Channel>,
    summary: Option<mcap::Summary>,
}

fn corrupt(path: &Path, reason: String) -> RosError {
    RosError::Corrupt {
        path: path.to_path_buf(),
        container: RosContainer::Mcap,
        reason,
    }
}

/// An `mcap` crate error as a lowercase phrase.
fn describe(e: &mcap::McapError) -> String {
    let text = e.to_string();
    let mut chars = text.chars();
    match chars.next() {
        Some(c) => c.to_lowercase().chain(chars).collect(),
        None => text,
    }
}

/// Runs `read`, a use of the `mcap` crate, and turns a panic inside it into a corrupt-file
/// error naming `what` was read. The crate's readers have crashed on crafted files (0.26.0, see
/// `check_summary_records`); the workspace builds the crate with overflow checks in release
/// too (Cargo.toml), so another such bug stops here as a panic, where unchecked arithmetic
/// would wrap into a bogus length. A panic is still a bug (the CLI's panic hook prints it as
/// such, one line, before this error); the guard only keeps it from ending the program or a
/// batch. The fuzz targets abort on any panic (libFuzzer's hook), so it hides nothing from them.
fn guarded<T>(
    path: &Path,
    what: &dyn Fn() -> String,
    read: impl FnOnce() -> Result<T, ReadError>,
) -> Result<T, ReadError> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(read)).unwrap_or_else(|payload| {
        let message = payload
            .downcast_ref::<&str>()
            .copied()
            .or_else(|| payload.downcast_ref::<String>().map(String::as_str))
            .unwrap_or("no message");
        Err(corrupt(path, format!("{}: reading it panicked ({message})", what())).into())
    })
}

/// One record parsed by the `mcap` crate ([`guarded`]); `at` says where it is for an error.
fn parse<'a>(
    path: &Path,
    opcode: u8,
    body: &'a [u8],
    at: &dyn Fn() -> String,
) -> Result<Record<'a>, ReadError> {
    if let Err(why) = check_lengths(opcode, body) {
        return Err(corrupt(path, format!("{}: {why}", at())).into());
    }
    guarded(path, at, || {
        mcap::parse_record(opcode, body)
            .map_err(|e| corrupt(path, format!("{}: {}", at(), describe(&e))).into())
    })
}

/// A field of a record body, as the MCAP specification lays them out.
#[derive(Clone, Copy)]
enum Field {
    /// Fixed-width bytes.
    Fixed(usize),
    /// A string or byte array: u32 length, then the bytes.
    Prefixed,
    /// A map or array of fixed-width entries: u32 byte length, then the entries.
    Block,
    /// A map of strings to strings: u32 byte length, then prefixed keys and values.
    StringMap,
    /// The rest of the body as the record's data, or a u64 length then the data.
    Rest,
    Long,
}

/// The fields of the records whose lengths the `mcap` crate trusts (the other opcodes are
/// fixed-size or ours to read).
fn layout(opcode: u8) -> &'static [Field] {
    use Field::*;
    match opcode {
        op::HEADER => &[Prefixed, Prefixed],
        op::SCHEMA => &[Fixed(2), Prefixed, Prefixed, Prefixed],
        op::CHANNEL => &[Fixed(4), Prefixed, Prefixed, StringMap],
        op::MESSAGE => &[Fixed(22), Rest],
        op::CHUNK => &[Fixed(28), Prefixed, Long],
        op::MESSAGE_INDEX => &[Fixed(2), Block],
        op::CHUNK_INDEX => &[Fixed(32), Block, Fixed(8), Prefixed, Fixed(16)],
        op::ATTACHMENT => &[Fixed(16), Prefixed, Prefixed, Long],
        op::ATTACHMENT_INDEX => &[Fixed(40), Prefixed, Prefixed],
        op::STATISTICS => &[Fixed(42), Block],
        op::METADATA => &[Prefixed, StringMap],
        op::METADATA_INDEX => &[Fixed(16), Prefixed],
        _ => &[Rest],
    }
}

/// Every length inside a record body held against the bytes left in it, before the `mcap`
/// crate sees the body: the crate reserves what a string's length prefix says (`mcap` 0.26,
/// through `binrw`), so a 4 KiB summary with a topic of length 0xFFFFFFFF asked for 4 GiB.
fn check_lengths(opcode: u8, body: &[u8]) -> Result<(), String> {
    fn prefixed(b: &[u8], at: &mut usize, wide: bool) -> Result<usize, String> {
        let w = if wide { 8 } else { 4 };
        let head = b
            .get(*at..*at + w)
            .ok_or_else(|| format!("a length field at byte {at} runs past the record's end"))?;
        let n = if wide {
            u64::from_le_bytes(head.try_into().expect("8 bytes"))
        } else {
            u64::from(u32::from_le_bytes(head.try_into().expect("4 bytes")))
        };
        *at += w;
        let left = (b.len() - *at) as u64;
        if n > left {
            return Err(format!(
                "a field at byte {} claims {n} bytes where the record holds {left} more",
                *at - w
            ));
        }
        let start = *at;
        *at += n as usize;
        Ok(start)
    }
    let mut at = 0usize;
    for field in layout(opcode) {
        match *field {
            Field::Fixed(n) => {
                if body.len() - at < n {
                    return Err(format!(
                        "the record ends before its {n}-byte field at byte {at}"
                    ));
                }
                at += n;
            }
            Field::Prefixed | Field::Block => {
                prefixed(body, &mut at, false)?;
            }
            Field::Long => {
                prefixed(body, &mut at, true)?;
            }
            Field::StringMap => {
                let start = prefixed(body, &mut at, false)?;
                let map = &body[start..at];
                let mut k = 0;
                while k < map.len() {
                    prefixed(map, &mut k, false)?;
                    prefixed(map, &mut k, false)?;
                }
            }
            Field::Rest => return Ok(()),
        }
    }
    Ok(())
}

/// Checks both magics (a file without the end magic was cut short or never closed).
fn check_magic(file: &mut StorageFile) -> Result<(), ReadError> {
    let path = file.path().to_path_buf();
    let len = file.len();
    let m = mcap::MAGIC.len();
    if file.get(0, m.min(len))? != mcap::MAGIC {
        return Err(RosError::NotRecording {
            path,
            expected: "expected the MCAP magic (0x89 MCAP0 \\r\\n) at the start of an .mcap file"
                .into(),
        }
        .into());
    }
    if len < 2 * m || file.get(len - m, m)? != mcap::MAGIC {
        return Err(corrupt(
            &path,
            format!(
                "the file ({len} bytes) does not end with the MCAP magic: it is cut short or the \
                 recorder never closed it"
            ),
        )
        .into());
    }
    Ok(())
}

/// Called for each record: (opcode, body, position).
type RecordVisitor<'v> = dyn FnMut(u8, &[u8], usize) -> Result<(), ReadError> + 'v;

/// Iterates the records of `buf` from `from` (opcode u8, length u64, body): calls
/// `visit(opcode, body, position)` for each opcode in `wanted` (the others' bodies are not
/// read), stopping after a DataEnd record. `chunk_at` is the file offset of the chunk `buf` is
/// (None for the file itself), for messages.
fn records<B: Bytes>(
    path: &Path,
    buf: &mut B,
    from: usize,
    chunk_at: Option<u64>,
    wanted: &dyn Fn(u8) -> bool,
    visit: &mut RecordVisitor<'_>,
) -> Result<(), ReadError> {
    let at = |pos: usize| match chunk_at {
        None => format!("record at byte {pos}"),
        Some(c) => format!("chunk at byte {c}: record at byte {pos} of the chunk"),
    };
    let end = buf.end();
    let mut pos = from;
    while pos < end {
        if end - pos < 9 {
            return Err(corrupt(
                path,
                format!("{}: 9-byte record header is cut off", at(pos)),
            )
            .into());
        }
        let head = buf.get(pos, 9)?;
        let opcode = head[0];
        let mut len = [0u8; 8];
        len.copy_from_slice(&head[1..9]);
        let len = u64::from_le_bytes(len);
        let remain = end - pos - 9;
        let n = usize::try_from(len)
            .ok()
            .filter(|&l| l <= remain)
            .ok_or_else(|| {
                corrupt(
                    path,
                    format!(
                        "{}: record (opcode 0x{opcode:02x}) of {len} bytes runs past the end \
                         ({remain} bytes remain)",
                        at(pos),
                    ),
                )
            })?;
        if wanted(opcode) {
            visit(opcode, buf.get(pos + 9, n)?, pos)?;
        }
        if opcode == op::DATA_END {
            break;
        }
        pos += 9 + n;
    }
    Ok(())
}

/// Called for each record of a chunk: (opcode, body, chunk offset in the file, record offset
/// in the decompressed chunk).
type ChunkVisitor<'v> = dyn FnMut(u8, &[u8], u64, usize) -> Result<(), ReadError> + 'v;

/// Decompresses a chunk record's body if needed and walks its records.
fn chunk(
    path: &Path,
    body: &[u8],
    offset: u64,
    dec: &mut Decompressor,
    buf: &mut Vec<u8>,
    visit: &mut ChunkVisitor<'_>,
) -> Result<(), ReadError> {
    let at = || format!("chunk at byte {offset}");
    let (header, data) = match parse(path, op::CHUNK, body, &at)? {
        Record::Chunk { header, data } => (header, data),
        _ => return Err(corrupt(path, format!("{}: not a chunk", at())).into()),
    };
    let codec = match header.compression.as_str() {
        "" => None,
        "zstd" => Some(Codec::Zstd),
        "lz4" => Some(Codec::Lz4),
        other => {
            return Err(RosError::UnsupportedCompression {
                path: path.to_path_buf(),
                what: format!("MCAP chunk compression \"{other}\""),
                hint: "supported: none, zstd, lz4",
            }
            .into())
        }
    };
    let size = usize::try_from(header.uncompressed_size).map_err(|_| {
        corrupt(
            path,
            format!(
                "chunk at byte {offset}: uncompressed size {} is too large",
                header.uncompressed_size
            ),
        )
    })?;
    let inner: &[u8] = match codec {
        None => {
            if data.len() != size {
                return Err(corrupt(
                    path,
                    format!(
                        "chunk at byte {offset}: uncompressed chunk holds {} bytes, its header \
                         says {size}",
                        data.len()
                    ),
                )
                .into());
            }
            &data
        }
        Some(codec) => {
            dec.decompress(codec, &data, size, buf)
                .map_err(|e| corrupt(path, format!("chunk at byte {offset}: {e}")))?;
            buf
        }
    };
    records(
        path,
        &mut Memory(inner),
        0,
        Some(offset),
        &|_| true,
        &mut |opcode, body, pos| visit(opcode, body, offset, pos),
    )
}

/// Collects schemas and channels met in a scan, and counts messages per channel.
#[derive(Default)]
struct Scan {
    schemas: HashMap<u16, String>,
    channels: BTreeMap<u16, (String, u16, String)>,
    counts: HashMap<u16, u64>,
}

impl Scan {
    fn record(&mut self, path: &Path, opcode: u8, body: &[u8], at: &str) -> Result<(), ReadError> {
        let parsed = || parse(path, opcode, body, &|| at.to_string());
        match opcode {
            op::SCHEMA => {
                if let Record::Schema { header, .. } = parsed()? {
                    self.schemas.entry(header.id).or_insert(header.name);
                }
            }
            op::CHANNEL => {
                if let Record::Channel(c) = parsed()? {
                    self.channels
                        .entry(c.id)
                        .or_insert((c.topic, c.schema_id, c.message_encoding));
                }
            }
            op::MESSAGE => {
                let id = body
                    .get(..2)
                    .map(|b| u16::from_le_bytes([b[0], b[1]]))
                    .ok_or_else(|| corrupt(path, format!("{at}: message record is cut off")))?;
                *self.counts.entry(id).or_insert(0) += 1;
            }
            _ => {}
        }
        Ok(())
    }
}

/// Footer record: opcode, length, `summary_start`, `summary_offset_start`, `summary_crc`.
const FOOTER_LEN: usize = 1 + 8 + 8 + 8 + 4;

/// Refuses a summary section holding a chunk or an attachment record before the `mcap` crate
/// reads it. The format keeps both in the data section; the summary holds only schemas,
/// channels, indexes and statistics. The crate's summary reader parses them there anyway, and
/// both have crashed it (`mcap` 0.26.0, the `mcap` fuzzer's long runs): a record inside a chunk
/// longer than the chunk makes its remaining count underflow (`linear_reader.rs:745`), and an
/// attachment with fewer than 4 bytes left for its CRC after its header makes it slice out of
/// bounds (`read.rs:176`). Footers and records this walk cannot follow are left to the crate,
/// which reports them.
fn check_summary_records(file: &StorageFile) -> Result<(), ReadError> {
    let len = file.len();
    let m = mcap::MAGIC.len();
    let Some(footer) = len.checked_sub(m + FOOTER_LEN).filter(|&f| f >= m) else {
        return Ok(());
    };
    let mut buf = [0u8; FOOTER_LEN];
    file.read_into(footer, &mut buf)?;
    if buf[0] != op::FOOTER {
        return Ok(());
    }
    let u64_at = |b: &[u8]| u64::from_le_bytes(b.try_into().expect("8 bytes"));
    let Ok(mut pos) = usize::try_from(u64_at(&buf[9..17])) else {
        return Ok(());
    };
    if pos == 0 {
        return Ok(());
    }
    let mut header = [0u8; 9];
    while pos < footer && footer - pos >= header.len() {
        file.read_into(pos, &mut header)?;
        let misplaced = match header[0] {
            op::CHUNK => Some("a chunk"),
            op::ATTACHMENT => Some("an attachment"),
            _ => None,
        };
        if let Some(record) = misplaced {
            return Err(corrupt(
                file.path(),
                format!(
                    "summary section: {record} record at byte {pos} (the format keeps it in the data section; the summary holds only schemas, channels, indexes and statistics)"
                ),
            )
            .into());
        }
        let claimed = u64_at(&header[1..9]);
        if !matches!(layout(header[0]), [Field::Rest]) {
            // the body is read (its length held against the summary first) and its own
            // lengths checked before the crate parses it
            let room = (footer - pos - header.len()) as u64;
            if claimed > room {
                return Err(corrupt(
                    file.path(),
                    format!("summary section: record at byte {pos} claims {claimed} bytes where the summary holds {room} more"),
                )
                .into());
            }
            let mut body = vec![0u8; claimed as usize];
            file.read_into(pos + header.len(), &mut body)?;
            if let Err(why) = check_lengths(header[0], &body) {
                return Err(corrupt(
                    file.path(),
                    format!("summary section: record at byte {pos}: {why}"),
                )
                .into());
            }
        }
        match usize::try_from(u64_at(&header[1..9]))
            .ok()
            .and_then(|n| pos.checked_add(header.len())?.checked_add(n))
        {
            Some(next) => pos = next,
            None => break,
        }
    }
    Ok(())
}

/// The summary section, if the file has one: the `mcap` crate's summary reader fed by
/// positioned reads of the file as opened (reads stop at its size then, as a read of the whole
/// file would).
fn summary(file: &StorageFile) -> Result<Option<mcap::Summary>, ReadError> {
    check_summary_records(file)?;
    guarded(file.path(), &|| "summary section".to_string(), || {
        crate_summary(file)
    })
}

/// [`summary`] as the `mcap` crate's summary reader gives it, unguarded.
fn crate_summary(file: &StorageFile) -> Result<Option<mcap::Summary>, ReadError> {
    let path = file.path();
    let len = file.len() as u64;
    let fail = |e: mcap::McapError| -> ReadError {
        corrupt(path, format!("summary section: {}", describe(&e))).into()
    };
    let mut reader =
        SummaryReader::new_with_options(SummaryReaderOptions::default().with_file_size(len));
    let mut pos: u64 = 0;
    while let Some(event) = reader.next_event() {
        match event.map_err(fail)? {
            SummaryReadEvent::ReadRequest(n) => {
                // what the file holds from here, never the length a record claims: a
                // summary record declaring 4 GiB in a 4 KiB file costs nothing
                let k = usize::try_from(len.saturating_sub(pos)).map_or(n, |left| left.min(n));
                let into = reader.insert(k);
                file.read_into(pos as usize, into)?;
                reader.notify_read(k);
                pos += k as u64;
            }
            SummaryReadEvent::SeekRequest(to) => {
                let target = match to {
                    SeekFrom::Start(p) => Some(p),
                    SeekFrom::End(d) => len.checked_add_signed(d),
                    SeekFrom::Current(d) => pos.checked_add_signed(d),
                };
                pos = target.ok_or_else(|| {
                    fail(mcap::McapError::Io(std::io::Error::new(
                        std::io::ErrorKind::InvalidInput,
                        "invalid seek to a negative or overflowing position",
                    )))
                })?;
                reader.notify_seeked(pos);
            }
        }
    }
    Ok(reader.finish())
}

/// Lists the channels with their message counts.
pub(crate) fn catalog(file: &mut StorageFile) -> Result<Catalog, ReadError> {
    let path = file.path().to_path_buf();
    let path = path.as_path();
    check_magic(file)?;
    let summary = summary(file)?;
    if let Some(s) = summary.as_ref() {
        if let Some(stats) = s.stats.as_ref() {
            let mut channels: Vec<Channel> = s
                .channels
                .values()
                .map(|c| Channel {
                    id: c.id,
                    topic: c.topic.clone(),
                    message_type: c
                        .schema
                        .as_ref()
                        .map(|s| s.name.clone())
                        .unwrap_or_default(),
                    encoding: c.message_encoding.clone(),
                    messages: stats
                        .channel_message_counts
                        .get(&c.id)
                        .copied()
                        .unwrap_or(0),
                })
                .collect();
            channels.sort_by_key(|c| c.id);
            return Ok(Catalog { channels, summary });
        }
    }
    // no statistics: scan the data section, opening every chunk
    let mut scan = Scan::default();
    let mut dec = Decompressor::new();
    let mut buf = Vec::new();
    let data_end = file.len() - mcap::MAGIC.len();
    records(
        path,
        &mut file.region(data_end),
        mcap::MAGIC.len(),
        None,
        &|opcode| matches!(opcode, op::CHUNK | op::SCHEMA | op::CHANNEL | op::MESSAGE),
        &mut |opcode, body, pos| {
            let offset = pos as u64;
            if opcode == op::CHUNK {
                chunk(path, body, offset, &mut dec, &mut buf, &mut |o, b, c, p| {
                    scan.record(
                        path,
                        o,
                        b,
                        &format!("chunk at byte {c}: record at byte {p} of the chunk"),
                    )
                })
            } else {
                scan.record(path, opcode, body, &format!("record at byte {offset}"))
            }
        },
    )?;
    let channels = scan
        .channels
        .into_iter()
        .map(|(id, (topic, schema, encoding))| Channel {
            id,
            topic,
            message_type: scan.schemas.get(&schema).cloned().unwrap_or_default(),
            encoding,
            messages: scan.counts.get(&id).copied().unwrap_or(0),
        })
        .collect();
    Ok(Catalog { channels, summary })
}

/// Reads the messages of the channels in `wanted` (id -> encoding) into `out`, in file order.
pub(crate) fn read(
    file: &mut StorageFile,
    catalog: &Catalog,
    wanted: &HashMap<u16, Encoding>,
    out: &mut Collector<'_>,
) -> Result<(), ReadError> {
    let path = file.path().to_path_buf();
    let path = path.as_path();
    check_magic(file)?;
    let mut dec = Decompressor::new();
    let mut buf = Vec::new();
    let mut message = |body: &[u8], at: &dyn Fn() -> String| -> Result<(), ReadError> {
        let Some(id) = body.get(..2).map(|b| u16::from_le_bytes([b[0], b[1]])) else {
            return Err(corrupt(path, format!("{}: message record is cut off", at())).into());
        };
        let Some(&encoding) = wanted.get(&id) else {
            return Ok(());
        };
        let (header, data) = match parse(path, op::MESSAGE, body, at)? {
            Record::Message { header, data } => (header, data),
            _ => return Err(corrupt(path, format!("{}: not a message", at())).into()),
        };
        let log_time = i64::try_from(header.log_time).map_err(|_| {
            corrupt(
                path,
                format!(
                    "{}: log time {} ns is past the year 2262",
                    at(),
                    header.log_time
                ),
            )
        })?;
        out.push(encoding, log_time, &data)
    };
    let indexes = catalog
        .summary
        .as_ref()
        .map(|s| s.chunk_indexes.as_slice())
        .unwrap_or_default();
    if !indexes.is_empty() {
        let mut chunks: Vec<&mcap::records::ChunkIndex> = indexes
            .iter()
            .filter(|c| {
                c.message_index_offsets.is_empty()
                    || c.message_index_offsets
                        .keys()
                        .any(|k| wanted.contains_key(k))
            })
            .collect();
        chunks.sort_by_key(|c| c.chunk_start_offset);
        for c in chunks {
            let offset = c.chunk_start_offset;
            let missing = || {
                corrupt(
                    path,
                    format!(
                        "the chunk index points to a chunk at byte {offset} ({} bytes) that is \
                         not there",
                        c.chunk_length
                    ),
                )
            };
            // checked against the size before anything is read
            let (start, length) = usize::try_from(offset)
                .ok()
                .zip(usize::try_from(c.chunk_length).ok())
                .filter(|&(s, l)| l >= 9 && s.checked_add(l).is_some_and(|e| e <= file.len()))
                .ok_or_else(missing)?;
            let record = file.get(start, length)?;
            if record[0] != op::CHUNK {
                return Err(missing().into());
            }
            chunk(
                path,
                &record[9..],
                offset,
                &mut dec,
                &mut buf,
                &mut |opcode, body, c, p| {
                    if opcode == op::MESSAGE {
                        message(body, &|| {
                            format!("chunk at byte {c}: record at byte {p} of the chunk")
                        })
                    } else {
                        Ok(())
                    }
                },
            )?;
        }
        return Ok(());
    }
    let data_end = file.len() - mcap::MAGIC.len();
    records(
        path,
        &mut file.region(data_end),
        mcap::MAGIC.len(),
        None,
        &|opcode| opcode == op::CHUNK || opcode == op::MESSAGE,
        &mut |opcode, body, pos| {
            let offset = pos as u64;
            match opcode {
                op::CHUNK => chunk(path, body, offset, &mut dec, &mut buf, &mut |o, b, c, p| {
                    if o == op::MESSAGE {
                        message(b, &|| {
                            format!("chunk at byte {c}: record at byte {p} of the chunk")
                        })
                    } else {
                        Ok(())
                    }
                }),
                op::MESSAGE => message(body, &|| format!("record at byte {offset}")),
                _ => Ok(()),
            }
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The guard meets a real bug of the `mcap` crate: its summary reader, fed a chunk in the
    /// summary section (the fuzzer's `chunk_in_summary_overflow`) without our check before it,
    /// underflows (0.26.0; tests build with overflow checks, as release builds the crate). It
    /// must come back as an error, and the reader proper must refuse the file before the crate
    /// sees it.
    #[test]
    fn a_crate_bug_under_the_guard_is_an_error() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures/fuzz/mcap/chunk_in_summary_overflow");
        let file = StorageFile::open(&path).unwrap();
        let what = || "summary section".to_string();
        assert!(guarded(&path, &what, || crate_summary(&file)).is_err());
        let text = summary(&file).unwrap_err().to_string();
        assert!(text.contains("a chunk record at byte"), "{text}");
    }

    #[test]
    fn a_panic_under_the_guard_is_a_corrupt_file_error() {
        let path = Path::new("bag.mcap");
        let err = guarded(
            path,
            &|| "chunk at byte 8".to_string(),
            || -> Result<(), _> {
                let n: Vec<u8> = Vec::new();
                let _ = n[3];
                Ok(())
            },
        )
        .unwrap_err();
        assert!(
            matches!(err, ReadError::Ros(RosError::Corrupt { .. })),
            "{err:?}"
        );
        let text = err.to_string();
        assert!(text.contains("bag.mcap"), "{text}");
        assert!(
            text.contains("chunk at byte 8: reading it panicked (index out of bounds: the len is 0 but the index is 3)"),
            "{text}"
        );
    }
}
