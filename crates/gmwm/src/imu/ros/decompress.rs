//! Chunk decompression, pure Rust: LZ4 frames (ROS1 `lz4`, MCAP `lz4`), bzip2 (ROS1 `bz2`) and
//! Zstandard (MCAP `zstd`).

use std::io::Read;

/// Largest decompressed chunk accepted: 256 MiB (recorders write chunks of 768 KiB to a few
/// MiB); a larger declared size is refused before anything is allocated, so that a small
/// hostile file cannot make the reader hold gigabytes (a bz2 bomb declaring 4 GiB).
pub(crate) const MAX_CHUNK: usize = 1 << 28;

/// Output reserved up front for lz4 and bzip2 beyond 16 times the input: 1 MiB; the buffer
/// grows as the data come (Zstandard decodes into reserved capacity only: it gets `size`).
const MIN_RESERVE: usize = 1 << 20;

/// A chunk compression.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Codec {
    Lz4,
    Bz2,
    Zstd,
}

/// Reusable state: the Zstandard frame decoder keeps its buffers between chunks.
pub(crate) struct Decompressor {
    zstd: Option<ruzstd::decoding::FrameDecoder>,
}

impl Decompressor {
    pub(crate) fn new() -> Self {
        Self { zstd: None }
    }

    /// Decompresses `src` into `dst` (cleared first), which must then hold exactly `size` bytes.
    ///
    /// # Errors
    /// A one-line reason: the decoder's error, or a size other than the declared one.
    pub(crate) fn decompress(
        &mut self,
        codec: Codec,
        src: &[u8],
        size: usize,
        dst: &mut Vec<u8>,
    ) -> Result<(), String> {
        dst.clear();
        if size > MAX_CHUNK {
            return Err(format!(
                "the chunk declares {size} bytes decompressed, more than the {} MiB accepted \
                 (recorders write chunks of a few MiB)",
                MAX_CHUNK >> 20
            ));
        }
        // the declared size is data: reserve what the input can plausibly give, then grow
        dst.reserve(match codec {
            Codec::Zstd => size,
            _ => size.min(src.len().saturating_mul(16).max(MIN_RESERVE)),
        });
        // one byte beyond the declared size shows a stream that is longer (a declared size of
        // u64::MAX from the file reads to the end of the stream)
        let limit = (size as u64).saturating_add(1);
        let res = match codec {
            Codec::Lz4 => lz4_flex::frame::FrameDecoder::new(src)
                .take(limit)
                .read_to_end(dst)
                .map(drop)
                .map_err(|e| format!("lz4: {e}")),
            Codec::Bz2 => bzip2::read::BzDecoder::new(src)
                .take(limit)
                .read_to_end(dst)
                .map(drop)
                .map_err(|e| format!("bz2: {e}")),
            Codec::Zstd => {
                let dec = self
                    .zstd
                    .get_or_insert_with(ruzstd::decoding::FrameDecoder::new);
                dec.decode_all_to_vec(src, dst)
                    .map_err(|e| format!("zstd: {e}"))
            }
        };
        res?;
        if dst.len() != size {
            return Err(format!(
                "decompressed to {}{} bytes, the chunk declares {size}",
                dst.len(),
                if dst.len() > size { " or more" } else { "" }
            ));
        }
        Ok(())
    }
}

/// Largest decompressed message accepted (a `sensor_msgs/Imu` is about 350 bytes).
const MAX_MESSAGE: u64 = 1 << 20;

/// Decompresses one Zstandard frame (a message of a rosbag2 bag with `compression_mode:
/// message`) into `dst`.
///
/// # Errors
/// The decoder's message as one line.
pub(crate) fn zstd_frame(src: &[u8], dst: &mut Vec<u8>) -> Result<(), String> {
    let dec = ruzstd::decoding::StreamingDecoder::new(src).map_err(|e| e.to_string())?;
    dec.take(MAX_MESSAGE)
        .read_to_end(dst)
        .map(drop)
        .map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn declared_sizes_are_capped_before_anything_is_allocated() {
        let mut d = Decompressor::new();
        let mut out = Vec::new();
        // a bz2 bomb: 300 MB of zeros in a few hundred bytes, declaring what it holds
        let mut enc = bzip2::write::BzEncoder::new(Vec::new(), bzip2::Compression::best());
        let block = vec![0u8; 1 << 20];
        for _ in 0..300 {
            std::io::Write::write_all(&mut enc, &block).unwrap();
        }
        let bomb = enc.finish().unwrap();
        assert!(bomb.len() < 4096, "{}", bomb.len());
        for (codec, size) in [
            (Codec::Bz2, 300 << 20),
            (Codec::Bz2, u32::MAX as usize),
            (Codec::Zstd, usize::MAX),
        ] {
            let e = d.decompress(codec, &bomb, size, &mut out).unwrap_err();
            assert!(e.contains("more than the 256 MiB accepted"), "{e}");
            assert!(out.capacity() < 1 << 20, "{}", out.capacity());
        }
        // 1.6 MB of garbage declaring 1.6 GB: refused; declaring 200 MB: at most 16x the
        // input reserved, then the decoder's error
        let garbage: Vec<u8> = (0..1_600_000u32)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 24) as u8)
            .collect();
        assert!(d
            .decompress(Codec::Lz4, &garbage, 1_600_000_000, &mut out)
            .is_err());
        let e = d
            .decompress(Codec::Lz4, &garbage, 200 << 20, &mut out)
            .unwrap_err();
        assert!(e.starts_with("lz4"), "{e}");
        assert!(
            out.capacity() <= 16 * garbage.len() + (1 << 20),
            "{}",
            out.capacity()
        );
    }

    #[test]
    fn lz4_round_trip_and_size_check() {
        let data: Vec<u8> = (0..10_000u32)
            .flat_map(|i| (i % 97).to_le_bytes())
            .collect();
        let mut enc = lz4_flex::frame::FrameEncoder::new(Vec::new());
        std::io::Write::write_all(&mut enc, &data).unwrap();
        let packed = enc.finish().unwrap();
        let mut d = Decompressor::new();
        let mut out = Vec::new();
        d.decompress(Codec::Lz4, &packed, data.len(), &mut out)
            .unwrap();
        assert_eq!(out, data);
        let e = d
            .decompress(Codec::Lz4, &packed, data.len() - 1, &mut out)
            .unwrap_err();
        assert!(e.contains("or more bytes"), "{e}");
        assert!(d
            .decompress(
                Codec::Lz4,
                &packed[..packed.len() / 2],
                data.len(),
                &mut out
            )
            .is_err());
        assert!(d
            .decompress(Codec::Zstd, &packed, data.len(), &mut out)
            .is_err());
        assert!(d
            .decompress(Codec::Bz2, &packed, data.len(), &mut out)
            .is_err());
    }
}
