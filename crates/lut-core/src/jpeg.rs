//! JPEG decoding (zune-jpeg, the decoder inside `image`, used directly): damaged files
//! are refused, never shown with a grey part.
//!
//! ## Truncated and corrupt files
//! The headers are read leniently (stray bytes between segments, which some cameras
//! write, are accepted), but the compressed image data is decoded in zune-jpeg's strict
//! mode: data that ends before the last block of the image (a truncated download, a file
//! cut right after its scan header) or entropy-coded data that does not decode is an
//! error naming the file. In lenient mode the decoder fills the missing part with grey
//! and reports success, which is what `image` does. Strict mode does not notice data
//! missing from the last row of blocks, so the stream must also reach its end-of-image
//! marker ([`end_of_image`], a walk over the segments and scans; data after the marker
//! is allowed). A panic inside the decoder (zune-jpeg 0.5.15 has one on some damaged
//! files, `without_panics`) refuses the file too.
//!
//! ## What the compressed data can hold
//! A Huffman-coded JPEG spends at least one bit on every 8×8 block of its
//! full-resolution component in its first scan (the shortest Huffman code, for a DC
//! difference of 0; a baseline scan also needs an end-of-block code). So a file of `n`
//! bytes describes at most `8·n` blocks, that is `512·n` pixels: a 2.3 KB file cannot
//! hold more than 1.2 million pixels, whatever its header claims. [`check_jpeg_size`]
//! refuses a header beyond that before anything of the image's size is allocated. Real
//! photographs use 1–4 bits per *pixel*, 64–256 times this bound; a flat grey
//! 32768×16384 JPEG is about 5 MB, five times it. (Arithmetic-coded JPEGs, which could
//! go below one bit per block, are not supported by the decoder.)

use crate::error::MapError;
use image::ColorType;
use zune_core::bytestream::ZCursor;
use zune_core::colorspace::ColorSpace;
use zune_core::options::DecoderOptions;
use zune_jpeg::errors::DecodeErrors;

/// The most pixels `len` bytes of Huffman-coded JPEG can describe: one bit per 8×8 block
/// (see the module docs).
pub fn jpeg_max_pixels(len: u64) -> u64 {
    len.saturating_mul(8 * 64)
}

/// Refuse a `width × height` JPEG header that `len` bytes of file cannot fill.
///
/// # Errors
/// [`MapError::Decode`] naming `what`, the claimed size and what the file can hold.
pub(crate) fn check_jpeg_size(
    what: &str,
    width: u64,
    height: u64,
    len: u64,
) -> Result<(), MapError> {
    let blocks = width.div_ceil(8).saturating_mul(height.div_ceil(8));
    if blocks > len.saturating_mul(8) {
        return Err(MapError::Decode {
            path: what.into(),
            reason: format!(
                "the JPEG header claims {width}x{height} pixels, but its {len} bytes of image data can hold \
                 at most about {} pixels (every 8x8 block costs at least one bit): the file \
                 is truncated or corrupt",
                jpeg_max_pixels(len)
            ),
        });
    }
    Ok(())
}

/// The offset of the end-of-image marker that closes the JPEG stream in `bytes`, found
/// by walking its segments and scans (so data after the marker, such as the video of a
/// "motion photo", does not matter), or `None` when the data ends first.
#[cfg(test)]
pub(crate) fn end_of_image(bytes: &[u8]) -> Option<usize> {
    walk(bytes).eoi
}

/// The bytes of entropy-coded image data in `bytes` (every scan's, up to the end marker
/// or the end of the data): what [`check_jpeg_size`] measures, so padding in metadata
/// segments or after the image does not count.
#[cfg(test)]
pub(crate) fn scan_bytes(bytes: &[u8]) -> u64 {
    walk(bytes).scan
}

/// What [`walk`] finds in a JPEG stream.
struct Walk {
    /// The end marker's offset, if the stream reaches it.
    eoi: Option<usize>,
    /// Bytes of entropy-coded data seen.
    scan: u64,
    /// A progressive frame header (SOF2, SOF6, SOF10, SOF14) was seen.
    progressive: bool,
}

/// Walk the segments and scans.
fn walk(bytes: &[u8]) -> Walk {
    let mut scan = 0u64;
    let mut progressive = false;
    let eoi = (|| {
        if !bytes.starts_with(&[0xFF, 0xD8]) {
            return None;
        }
        let mut i = 2;
        loop {
            // Find the next marker: 0xFF (fill bytes allowed) then a non-zero code.
            while *bytes.get(i)? != 0xFF {
                i += 1; // stray bytes between segments (lenient, as the decoder)
            }
            while *bytes.get(i + 1)? == 0xFF {
                i += 1;
            }
            let marker = *bytes.get(i + 1)?;
            match marker {
                0xD9 => return Some(i),
                0x00 | 0x01 | 0xD0..=0xD7 => {
                    i += 2;
                    continue;
                }
                _ => {}
            }
            if matches!(marker, 0xC2 | 0xC6 | 0xCA | 0xCE) {
                progressive = true;
            }
            let len = usize::from(u16::from_be_bytes([*bytes.get(i + 2)?, *bytes.get(i + 3)?]));
            i += 2 + len;
            if marker == 0xDA {
                // Entropy-coded data: runs to the next marker that is not a stuffed
                // 0xFF00 or a restart marker.
                let start = i;
                let end = loop {
                    let Some(&b) = bytes.get(i) else {
                        break i.min(bytes.len());
                    };
                    if b == 0xFF {
                        match bytes.get(i + 1) {
                            Some(0x00 | 0xD0..=0xD7) => i += 2,
                            Some(0xFF) => i += 1,
                            Some(_) => break i,
                            None => break bytes.len(),
                        }
                    } else {
                        i += 1;
                    }
                };
                scan += end.saturating_sub(start) as u64;
                bytes.get(i)?;
            }
        }
    })();
    Walk {
        eoi,
        scan,
        progressive,
    }
}

/// Zero bytes put after the image data in place of the end marker ([`prepare`]): more
/// than the decoder reads ahead (8 bytes), so a complete image never reads past them.
const PAD: usize = 16;

/// Make a whole JPEG file ready for [`Jpeg::new`], in place, and check what its data can
/// hold: the stream must reach its end-of-image marker; the marker (and anything after
/// it) is replaced by [`PAD`] zero bytes and the buffer ends there. zune-jpeg, on
/// reaching a marker before the image's last row, feeds zero bits for the rest — even in
/// strict mode — and "decodes" the missing rows as a repeated pattern; with no marker it
/// reaches the end of the buffer instead, which strict mode refuses. So a header claiming
/// more lines than the data holds is an error naming the file (at most [`PAD`] bytes of
/// zero bits, a few blocks of the last row, can go unnoticed). A progressive file keeps its
/// end marker (the decoder finishes its scans there and refuses a stream without one;
/// every scan covers the whole image, so a missing scan is missing detail, not rows).
/// Returns the bytes of entropy-coded data ([`scan_bytes`]).
///
/// # Errors
/// [`MapError::Decode`] naming `what` when the stream ends before its end marker.
pub(crate) fn prepare(bytes: &mut Vec<u8>, what: &str) -> Result<u64, MapError> {
    let Walk {
        eoi,
        scan,
        progressive,
    } = walk(bytes);
    let Some(eoi) = eoi else {
        return Err(MapError::Decode {
            path: what.into(),
            reason: format!(
                "the file ends before its end-of-image marker (truncated after {} bytes)",
                bytes.len()
            ),
        });
    };
    bytes.truncate(if progressive { eoi + 2 } else { eoi });
    bytes.extend_from_slice(&[0; PAD]);
    Ok(scan)
}

/// A JPEG whose headers have been read: its size and the 8-bit colour type it decodes to.
pub(crate) struct Jpeg<'a> {
    decoder: zune_jpeg::JpegDecoder<ZCursor<&'a [u8]>>,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Gray, gray + alpha, RGB or RGBA, 8 bits per channel.
    pub color: ColorType,
}

/// `f`, with a panic inside it returned as `Err` (its message), not printed: the
/// crate's one containment ([`crate::guard::catch_quiet`]). zune-jpeg 0.5.15's AVX2 IDCT
/// unwraps an output slice that some damaged files make too short (found by the
/// `map_jpeg` fuzz target; `tests/damaged.rs`, `a_jpeg_that_trips_the_decoder_is_refused`).
fn without_panics<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    crate::guard::catch_quiet(f)
}

fn reason(e: &DecodeErrors) -> String {
    match e {
        DecodeErrors::ExhaustedData => {
            "the file ends before the image data does (truncated)".to_string()
        }
        DecodeErrors::FormatStatic(s) if s.contains("Premature end") => {
            "the file ends before the image data does (truncated)".to_string()
        }
        other => format!("the image data is truncated or corrupt ({other})"),
    }
}

impl<'a> Jpeg<'a> {
    /// Read the headers of the JPEG in `bytes` (a whole file made ready by [`prepare`]).
    ///
    /// # Errors
    /// [`MapError::Decode`] naming `what` for headers that do not parse.
    pub(crate) fn new(bytes: &'a [u8], what: &str) -> Result<Self, MapError> {
        let err = |e: DecodeErrors| MapError::Decode {
            path: what.into(),
            reason: reason(&e),
        };
        let opts = DecoderOptions::default()
            .set_strict_mode(false)
            .set_max_width(usize::MAX)
            .set_max_height(usize::MAX);
        let mut decoder = zune_jpeg::JpegDecoder::new_with_options(ZCursor::new(bytes), opts);
        without_panics(|| decoder.decode_headers())
            .map_err(|panic| MapError::Decode {
                path: what.into(),
                reason: format!(
                    "the headers are corrupt (the JPEG decoder failed on them: {panic})"
                ),
            })?
            .map_err(err)?;
        let (w, h) = decoder.dimensions().unwrap_or((0, 0));
        let input = decoder.input_colorspace().unwrap_or(ColorSpace::YCbCr);
        let (out, color) = match input {
            ColorSpace::Luma => (ColorSpace::Luma, ColorType::L8),
            ColorSpace::LumaA => (ColorSpace::LumaA, ColorType::La8),
            ColorSpace::RGBA => (ColorSpace::RGBA, ColorType::Rgba8),
            _ => (ColorSpace::RGB, ColorType::Rgb8),
        };
        // Headers were lenient; the image data is decoded strictly.
        let strict = decoder
            .options()
            .set_strict_mode(true)
            .jpeg_set_out_colorspace(out);
        decoder.set_options(strict);
        Ok(Jpeg {
            decoder,
            width: u32::try_from(w).unwrap_or(u32::MAX),
            height: u32::try_from(h).unwrap_or(u32::MAX),
            color,
        })
    }

    /// Decode the pixels into `out` (exactly `width × height × bytes per pixel` bytes).
    ///
    /// # Errors
    /// [`MapError::Decode`] naming `what`: truncated or corrupt image data.
    pub(crate) fn decode_into(mut self, out: &mut [u8], what: &str) -> Result<(), MapError> {
        let decoder = &mut self.decoder;
        without_panics(move || decoder.decode_into(out))
            .map_err(|panic| MapError::Decode {
                path: what.into(),
                reason: format!(
                    "the image data is corrupt (the JPEG decoder failed on it: {panic})"
                ),
            })?
            .map_err(|e| MapError::Decode {
                path: what.into(),
                reason: reason(&e),
            })?;
        // Data missing from the last rows reaches the end of the buffer (`prepare`), which
        // strict mode refuses above.
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn jpeg(w: u32, h: u32) -> Vec<u8> {
        let img = image::RgbImage::from_fn(w, h, |x, y| {
            image::Rgb([(x * 7) as u8, (y * 5) as u8, ((x + y) * 3) as u8])
        });
        let mut v = Vec::new();
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut v, 90)
            .encode(img.as_raw(), w, h, image::ExtendedColorType::Rgb8)
            .unwrap();
        v
    }

    fn decode(bytes: &[u8]) -> Result<Vec<u8>, MapError> {
        let mut bytes = bytes.to_vec();
        prepare(&mut bytes, "t.jpg")?;
        let j = Jpeg::new(&bytes, "t.jpg")?;
        let mut out = vec![0u8; j.width as usize * j.height as usize * 3];
        j.decode_into(&mut out, "t.jpg")?;
        Ok(out)
    }

    #[test]
    fn whole_files_decode_like_image_does() {
        let bytes = jpeg(64, 32);
        let ours = decode(&bytes).unwrap();
        let theirs = image::load_from_memory(&bytes)
            .unwrap()
            .to_rgb8()
            .into_raw();
        assert_eq!(ours, theirs);
    }

    #[test]
    fn truncated_files_are_refused_at_every_cut() {
        let bytes = jpeg(64, 32);
        let sos = bytes
            .windows(2)
            .position(|w| w == [0xFF, 0xDA])
            .expect("a scan");
        // From right after the scan header to the end marker (every cut in the last
        // hundred bytes: the decoder alone misses those).
        let cuts = (sos + 14..bytes.len() - 100)
            .step_by(7)
            .chain(bytes.len() - 100..bytes.len() - 1);
        for cut in cuts {
            let e = decode(&bytes[..cut]).expect_err("truncated file decoded");
            let msg = e.to_string();
            assert!(
                msg.contains("t.jpg") && msg.contains("truncated"),
                "{cut}: {msg}"
            );
        }
    }

    /// `bytes` with the frame header's height set to `h`.
    fn claim_height(bytes: &[u8], h: u16) -> Vec<u8> {
        let mut v = bytes.to_vec();
        let sof = v.windows(2).position(|w| w == [0xFF, 0xC0]).expect("SOF0");
        v[sof + 5..sof + 7].copy_from_slice(&h.to_be_bytes());
        v
    }

    #[test]
    fn a_header_claiming_more_lines_than_the_data_is_refused() {
        let bytes = jpeg(64, 32);
        assert!(decode(&claim_height(&bytes, 32)).is_ok());
        for h in [40, 48, 64, 640] {
            let e = decode(&claim_height(&bytes, h)).expect_err("filled in");
            let msg = e.to_string();
            assert!(
                msg.contains("t.jpg") && msg.contains("truncated"),
                "{h}: {msg}"
            );
        }
        // Fewer lines than the data: the image is what the header says (as libjpeg).
        assert!(decode(&claim_height(&bytes, 16)).is_ok());
    }

    #[test]
    fn only_image_data_counts_toward_the_size_bound() {
        let bytes = jpeg(64, 32);
        let scan = scan_bytes(&bytes);
        assert!(scan > 100 && scan < bytes.len() as u64 - 100, "{scan}");
        // Padding in comment segments or after the end marker is not image data.
        let mut padded = bytes[..2].to_vec();
        for _ in 0..20 {
            padded.extend_from_slice(&[0xFF, 0xFE, 0xFF, 0xFF]);
            padded.extend(std::iter::repeat_n(b'x', 0xFFFD));
        }
        padded.extend_from_slice(&bytes[2..]);
        padded.extend(std::iter::repeat_n(0u8, 1 << 20));
        assert_eq!(scan_bytes(&padded), scan);
    }

    #[test]
    fn the_end_marker_is_found_before_trailing_data() {
        let bytes = jpeg(64, 32);
        assert_eq!(end_of_image(&bytes), Some(bytes.len() - 2));
        let mut motion = bytes.clone();
        motion.extend_from_slice(b"\0\0\0\x18ftypmp42 and a video after the image");
        assert_eq!(end_of_image(&motion), Some(bytes.len() - 2));
        assert!(decode(&motion).is_ok());
        assert_eq!(end_of_image(&bytes[..bytes.len() - 1]), None);
        assert_eq!(end_of_image(b"\x89PNG"), None);
    }

    #[test]
    fn the_size_bound_follows_the_block_count() {
        // 32768 x 16384 needs 8 Mi blocks, so at least 1 MiB.
        assert!(check_jpeg_size("a.jpg", 32768, 16384, 2300).is_err());
        assert!(check_jpeg_size("a.jpg", 32768, 16384, 1 << 20).is_ok());
        assert!(check_jpeg_size("a.jpg", 32768, 16384, (1 << 20) - 1).is_err());
        // Partial blocks count whole.
        assert!(check_jpeg_size("a.jpg", 9, 9, 0).is_err());
        assert!(check_jpeg_size("a.jpg", 9, 9, 1).is_ok());
        let msg = check_jpeg_size("a.jpg", 32768, 16384, 2300)
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("a.jpg") && msg.contains("32768x16384"),
            "{msg}"
        );
        // A real encoder's flat image is far above the bound.
        let flat = {
            let mut v = Vec::new();
            image::codecs::jpeg::JpegEncoder::new_with_quality(&mut v, 50)
                .encode(
                    &vec![128u8; 512 * 256 * 3],
                    512,
                    256,
                    image::ExtendedColorType::Rgb8,
                )
                .unwrap();
            v
        };
        let blocks = 64 * 32;
        assert!(flat.len() * 8 > 2 * blocks, "{} bytes", flat.len());
        assert!(check_jpeg_size("flat.jpg", 512, 256, flat.len() as u64).is_ok());
    }
}
