//! Chunk decompression, pure Rust: LZ4 frames (ROS1 `lz4`, MCAP `lz4`), bzip2 (ROS1 `bz2`) and
//! Zstandard (MCAP `zstd`).

use std::io::Read;

/// Output reserved up front even for a tiny input (a 64 MiB chunk is ten times the usual
/// recorder's chunk size); Zstandard decodes into reserved capacity only.
const MIN_RESERVE: usize = 1 << 26;

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
        // the declared size is data: never reserve more than a generous ratio of the input
        dst.reserve(size.min(src.len().saturating_mul(1024).max(MIN_RESERVE)));
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
