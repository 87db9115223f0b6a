//! OpenEXR decoding (the `exr` crate's block reader, used directly): colour (R, G, B) and
//! luminance-only (Y) images, every compression `exr` reads, with the memory a damaged
//! file can claim bounded.
//!
//! ## Channels
//! The first part (layer) with `R`, `G` and `B` channels is read as colour; else the
//! first with a `Y` channel as gray (a luminance-only image: Y is shown on all three
//! channels). Names match in any case, as `exr` matches them. Alpha and other channels
//! are ignored. Luminance/chroma images (`Y` with `RY`, `BY`) and subsampled channels
//! are refused rather than shown in gray or misplaced. Only the full-resolution level of
//! a mip- or rip-mapped file is read.
//!
//! ## Memory
//! Chunks are read in order and decompressed in parallel batches (two per thread), each
//! block written straight into the map through the tone curve: the peak is the map, plus
//! a batch of compressed and decompressed blocks (no whole-image float copy). `exr`
//! bounds every chunk's stored size by its block's raw size. DWAA/DWAB chunks carry
//! eleven 64-bit counts that `exr` trusts when it allocates (a damaged 200 KB file asked
//! for 572 MB, or for exabytes, which aborts the process); [`check_dwa_counts`] refuses
//! counts larger than the block can need before `exr` sees them. A file whose chunks do
//! not cover the image exactly is refused, never shown with a black part.

use crate::error::MapError;
use crate::map::tone::{tone_map, Tone};
use exr::block::chunk::{Chunk, CompressedBlock};
use exr::block::reader::ChunksReader;
use exr::block::UncompressedBlock;
use exr::compression::Compression;
use exr::math::Vec2;
use exr::meta::attribute::SampleType;
use exr::meta::header::Header;
use rayon::prelude::*;
use std::io::{Read, Seek};

/// The channels read: R, G, B, or Y (indices into the part's channel list).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Channels {
    Rgb([usize; 3]),
    Y(usize),
}

/// A decoded block: its position and size in the image, its 0RGB pixels row by row.
type Block = (Vec2<usize>, Vec2<usize>, Vec<u32>);

/// An EXR whose headers have been read.
pub(crate) struct Exr<R> {
    reader: exr::block::reader::Reader<R>,
    layer: usize,
    channels: Channels,
    /// Width of the part read.
    pub width: u32,
    /// Height of the part read.
    pub height: u32,
}

fn invalid(what: &str, reason: String) -> MapError {
    MapError::Decode {
        path: what.into(),
        reason,
    }
}

/// The channels to read from `h`, or why there are none.
fn pick_channels(h: &Header) -> Result<Channels, String> {
    let list = &h.channels.list;
    let find = |n: &str| list.iter().position(|c| c.name.eq_case_insensitive(n));
    let chosen = match (find("R"), find("G"), find("B"), find("Y")) {
        (Some(r), Some(g), Some(b), _) => Channels::Rgb([r, g, b]),
        (_, _, _, Some(_)) if find("RY").is_some() || find("BY").is_some() => {
            return Err(
                "luminance/chroma channels (Y, RY, BY) are not supported; save it as RGB".into(),
            )
        }
        (_, _, _, Some(y)) => Channels::Y(y),
        _ => {
            let names: Vec<String> = list
                .iter()
                .map(|c| format!("{:?}", c.name.to_string()))
                .collect();
            return Err(format!(
                "no R, G, B or Y channels to show (it has {})",
                if names.is_empty() {
                    "none".into()
                } else {
                    names.join(", ")
                }
            ));
        }
    };
    if list.iter().any(|c| c.sampling != Vec2(1, 1)) {
        return Err("subsampled channels are not supported".into());
    }
    Ok(chosen)
}

impl<R: Read + Seek> Exr<R> {
    /// Read the headers and choose the part and channels (see the module docs).
    ///
    /// # Errors
    /// [`MapError::Decode`] naming `what`.
    pub(crate) fn new(src: R, what: &str) -> Result<Self, MapError> {
        let reader =
            exr::block::read(src, false).map_err(|e| invalid(what, format!("OpenEXR: {e}")))?;
        let mut first_problem = None;
        let mut found = None;
        for (i, h) in reader.headers().iter().enumerate() {
            if h.deep {
                first_problem.get_or_insert_with(|| "deep data is not supported".to_string());
                continue;
            }
            match pick_channels(h) {
                Ok(c) => {
                    found = Some((i, c));
                    break;
                }
                Err(e) => {
                    first_problem.get_or_insert(e);
                }
            }
        }
        let Some((layer, channels)) = found else {
            return Err(invalid(
                what,
                first_problem.unwrap_or_else(|| "no image parts".into()),
            ));
        };
        let size = reader.headers()[layer].layer_size;
        Ok(Exr {
            reader,
            layer,
            channels,
            width: u32::try_from(size.x()).unwrap_or(u32::MAX),
            height: u32::try_from(size.y()).unwrap_or(u32::MAX),
        })
    }

    /// True for a luminance-only image.
    #[cfg(test)]
    fn is_gray(&self) -> bool {
        matches!(self.channels, Channels::Y(_))
    }

    /// Decode into `data`, a padded map buffer of `(width + 1) × (height + 1)` 0RGB
    /// pixels (only the `width × height` image pixels are written), through `tone`.
    /// `progress` gets the fraction of chunks read.
    ///
    /// # Errors
    /// [`MapError::Decode`] naming `what`: damaged chunks, implausible DWA counts, chunks
    /// that do not cover the image.
    pub(crate) fn decode_into(
        self,
        data: &mut [u32],
        what: &str,
        tone: Tone,
        progress: &mut dyn FnMut(f32),
    ) -> Result<(), MapError> {
        let err = |e: exr::error::Error| invalid(what, format!("OpenEXR: {e}"));
        let (w, h) = (self.width as usize, self.height as usize);
        let stride = w + 1;
        let layer = self.layer;
        let channels = self.channels;
        let mut chunks = self.reader.all_chunks(false).map_err(err)?;
        let meta = chunks.meta_data().clone();
        let header = &meta.headers[layer];
        let total = chunks.expected_chunk_count().max(1);
        let batch_len = 2 * rayon::current_num_threads().max(1);
        let k = 2f32.powf(tone.exposure_ev as f32);
        let mut read = 0usize;
        let mut covered = 0u64;
        let mut seen = std::collections::HashSet::new();
        loop {
            let mut batch: Vec<Chunk> = Vec::with_capacity(batch_len);
            let mut ended = false;
            while batch.len() < batch_len {
                let Some(chunk) = chunks.next() else {
                    ended = true;
                    break;
                };
                read += 1;
                let chunk = chunk.map_err(err)?;
                if chunk.layer_index != layer {
                    continue;
                }
                let tile = header
                    .get_block_data_indices(&chunk.compressed_block)
                    .map_err(err)?;
                if tile.level_index == Vec2(0, 0) {
                    batch.push(chunk);
                }
            }
            let blocks: Vec<Result<Block, MapError>> = batch
                .into_par_iter()
                .map(|chunk| {
                    check_dwa_counts(header, &chunk).map_err(|r| invalid(what, r))?;
                    let block =
                        UncompressedBlock::decompress_chunk(chunk, &meta, false).map_err(err)?;
                    let px =
                        block_pixels(header, channels, &block, k).map_err(|r| invalid(what, r))?;
                    Ok((block.index.pixel_position, block.index.pixel_size, px))
                })
                .collect();
            for b in blocks {
                let (pos, size, px) = b?;
                let (x0, y0, bw, bh) = (pos.x(), pos.y(), size.x(), size.y());
                if x0 + bw > w || y0 + bh > h || !seen.insert((x0, y0)) {
                    return Err(invalid(
                        what,
                        format!("OpenEXR: block at ({x0}, {y0}) is outside the image or repeated"),
                    ));
                }
                for (r, row) in px.chunks_exact(bw.max(1)).enumerate() {
                    let start = (y0 + r) * stride + x0;
                    data[start..start + bw].copy_from_slice(row);
                }
                covered += (bw * bh) as u64;
            }
            progress(read as f32 / total as f32);
            if ended {
                break;
            }
        }
        let want = (w * h) as u64;
        if covered != want {
            return Err(invalid(
                what,
                format!(
                    "OpenEXR: the file's blocks cover {covered} of the image's {want} pixels \
                     (truncated or damaged)"
                ),
            ));
        }
        Ok(())
    }
}

/// One sample of type `t` at byte offset `at` of native-endian `bytes`, as f32.
#[inline]
fn sample(bytes: &[u8], t: SampleType, at: usize) -> f32 {
    match t {
        SampleType::F16 => {
            exr::prelude::f16::from_bits(u16::from_ne_bytes([bytes[at], bytes[at + 1]])).to_f32()
        }
        SampleType::F32 => {
            f32::from_ne_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
        }
        SampleType::U32 => {
            u32::from_ne_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]) as f32
        }
    }
}

/// A decompressed block as 0RGB pixels (row by row), values times `k` through the tone
/// curve.
fn block_pixels(
    header: &Header,
    channels: Channels,
    block: &UncompressedBlock,
    k: f32,
) -> Result<Vec<u32>, String> {
    let list = &header.channels.list;
    let (bw, bh) = (block.index.pixel_size.x(), block.index.pixel_size.y());
    let sizes: Vec<usize> = list
        .iter()
        .map(|c| c.sample_type.bytes_per_sample())
        .collect();
    let row_bytes: usize = sizes.iter().map(|s| s * bw).sum();
    if block.data.len() != row_bytes * bh {
        return Err(format!(
            "OpenEXR: a block holds {} bytes, not the {} its {bw}x{bh} pixels need",
            block.data.len(),
            row_bytes * bh
        ));
    }
    // Byte offset of each channel's samples within a row.
    let offsets: Vec<usize> = sizes
        .iter()
        .scan(0, |acc, s| {
            let o = *acc;
            *acc += s * bw;
            Some(o)
        })
        .collect();
    let c = |x: f32| u32::from(tone_map(x * k));
    let mut out = Vec::with_capacity(bw * bh);
    for row in block.data.chunks_exact(row_bytes.max(1)).take(bh) {
        let at =
            |ch: usize, x: usize| sample(row, list[ch].sample_type, offsets[ch] + x * sizes[ch]);
        match channels {
            Channels::Rgb([r, g, b]) => {
                out.extend((0..bw).map(|x| (c(at(r, x)) << 16) | (c(at(g, x)) << 8) | c(at(b, x))))
            }
            Channels::Y(y) => out.extend((0..bw).map(|x| c(at(y, x)) * 0x0001_0101)),
        }
    }
    Ok(out)
}

/// Refuse a DWAA/DWAB chunk whose counts exceed what its block can need, before `exr`
/// allocates for them (see the module docs). The bound per block of `n` pixels padded
/// to whole 8×8 DCT blocks and `c` channels: at most 64 values per DCT block and channel
/// (`n·c` AC or DC values), and no section larger than twice the block's raw bytes at
/// 4 bytes per sample (`8·n·c`); the slack covers run-length coding's worst case.
///
/// # Errors
/// The reason, for a message.
pub(crate) fn check_dwa_counts(header: &Header, chunk: &Chunk) -> Result<(), String> {
    if !matches!(
        header.compression,
        Compression::DWAA(_) | Compression::DWAB(_)
    ) {
        return Ok(());
    }
    let bytes = match &chunk.compressed_block {
        CompressedBlock::ScanLine(b) => &b.compressed_pixels_le,
        CompressedBlock::Tile(b) => &b.compressed_pixels_le,
        _ => return Ok(()), // deep data is refused before decoding
    };
    let tile = header
        .get_block_data_indices(&chunk.compressed_block)
        .map_err(|e| format!("OpenEXR: {e}"))?;
    let rect = header
        .get_absolute_block_pixel_coordinates(tile)
        .map_err(|e| format!("OpenEXR: {e}"))?;
    let raw = rect.size.area() * header.channels.bytes_per_pixel;
    // Stored raw (compression did not help) or empty: no counts to trust.
    if bytes.is_empty() || bytes.len() == raw {
        return Ok(());
    }
    let padded = (rect.size.x().div_ceil(8) * 8) as u64 * (rect.size.y().div_ceil(8) * 8) as u64;
    let values = padded * header.channels.list.len() as u64 + 64;
    let max_bytes = 8 * values + 1024;
    let count = |i: usize| -> u64 {
        bytes
            .get(8 * i..8 * i + 8)
            .map_or(0, |b| u64::from_le_bytes(b.try_into().unwrap_or([0; 8])))
    };
    // (index in the chunk leader, name, limit)
    let checks = [
        (1, "unknown uncompressed size", max_bytes),
        (2, "unknown compressed size", bytes.len() as u64),
        (3, "AC compressed size", bytes.len() as u64),
        (4, "DC compressed size", bytes.len() as u64),
        (5, "RLE compressed size", bytes.len() as u64),
        (6, "RLE uncompressed size", max_bytes),
        (7, "RLE raw size", max_bytes),
        (8, "AC count", values),
        (9, "DC count", values),
    ];
    for (i, name, limit) in checks {
        let v = count(i);
        if v > limit {
            return Err(format!(
                "OpenEXR: a DWA block of {}x{} pixels claims {name} {v} (at most {limit} \
                 is possible): the file is damaged",
                rect.size.x(),
                rect.size.y()
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    use exr::prelude::Blocks;
    use test_support::exr_files::exr_file;

    fn write_exr(w: usize, h: usize, names: &[&str], compression: Compression) -> Vec<u8> {
        exr_file(w, h, names, compression, Blocks::ScanLines, false)
    }

    #[test]
    fn gray_and_colour_parts_are_found() {
        let y = write_exr(16, 8, &["Y"], Compression::ZIP1);
        let e = Exr::new(std::io::Cursor::new(&y), "y.exr").unwrap();
        assert!(e.is_gray());
        assert_eq!((e.width, e.height), (16, 8));
        let rgb = write_exr(16, 8, &["R", "G", "B", "A"], Compression::PIZ);
        assert!(!Exr::new(std::io::Cursor::new(&rgb), "c.exr")
            .unwrap()
            .is_gray());
        let yc = write_exr(16, 8, &["Y", "RY", "BY"], Compression::ZIP1);
        let msg = Exr::new(std::io::Cursor::new(&yc), "yc.exr")
            .err()
            .unwrap()
            .to_string();
        assert!(msg.contains("yc.exr") && msg.contains("chroma"), "{msg}");
        let z = write_exr(16, 8, &["Z", "depth\x1b[2J"], Compression::ZIP1);
        let msg = Exr::new(std::io::Cursor::new(&z), "z.exr")
            .err()
            .unwrap()
            .to_string();
        assert!(msg.contains("\"Z\"") && !msg.contains('\x1b'), "{msg}");
    }

    #[test]
    fn damaged_dwa_counts_are_refused_before_decoding() {
        let bytes = write_exr(64, 40, &["R", "G", "B"], Compression::DWAA(None));
        // Find each chunk's leader through exr's own reader and raise one count.
        let reader = exr::block::read(std::io::Cursor::new(&bytes), false).unwrap();
        let header = reader.headers()[0].clone();
        let chunks: Vec<Chunk> = reader
            .all_chunks(false)
            .unwrap()
            .collect::<Result<_, _>>()
            .unwrap();
        assert!(chunks.iter().all(|c| check_dwa_counts(&header, c).is_ok()));

        for field in [1usize, 6, 7, 8, 9] {
            let mut c = chunks[0].clone();
            if let CompressedBlock::ScanLine(b) = &mut c.compressed_block {
                b.compressed_pixels_le[8 * field..8 * field + 8]
                    .copy_from_slice(&(1u64 << 40).to_le_bytes());
            }
            let e = check_dwa_counts(&header, &c).unwrap_err();
            assert!(e.contains("damaged"), "{field}: {e}");
        }
    }
}
