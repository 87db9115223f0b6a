//! Reading an image a band of rows at a time, as RGB8, never whole: JPEG through
//! libjpeg's scanline interface (the `mozjpeg` crate), PNG through the `png` crate's row
//! reader, TIFF (classic or BigTIFF, striped or tiled, 8 or 16 bits) through the `tiff`
//! crate's chunk reader. 16-bit samples are rounded to 8 bits; alpha is composited onto
//! black (as generate.py pastes transparent tiles onto its black background); grey is
//! spread to RGB.

use anyhow::{anyhow, bail, Context, Result};
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

/// Rows of an image, top to bottom, as RGB8.
pub trait RowReader {
    /// Width in pixels.
    fn width(&self) -> u32;
    /// Height in pixels.
    fn height(&self) -> u32;
    /// Read the next whole rows into `out` (a multiple of `3 · width` bytes); returns the
    /// number of rows read (0 at the end).
    ///
    /// # Errors
    /// A damaged or truncated file, named.
    fn read_rows(&mut self, out: &mut [u8]) -> Result<usize>;
}

/// The image formats read in bands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BandFormat {
    /// JPEG (baseline or progressive).
    Jpeg,
    /// PNG (not interlaced).
    Png,
    /// TIFF or BigTIFF.
    Tiff,
}

/// The format of the file at `path` from its first bytes, `None` for anything else.
///
/// # Errors
/// The file cannot be opened or read.
pub fn sniff(path: &Path) -> Result<Option<BandFormat>> {
    let mut f =
        lut_core::open_regular(path).with_context(|| format!("{}: cannot open", path.display()))?;
    let mut head = [0u8; 8];
    let n = read_up_to(&mut f, &mut head)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    let h = &head[..n];
    Ok(if h.starts_with(&[0xFF, 0xD8, 0xFF]) {
        Some(BandFormat::Jpeg)
    } else if h.starts_with(b"\x89PNG\r\n\x1a\n") {
        // Interlaced PNGs cannot be read by rows: the caller decodes those whole.
        Some(BandFormat::Png)
    } else if h.starts_with(b"II*\0")
        || h.starts_with(b"MM\0*")
        || h.starts_with(b"II+\0")
        || h.starts_with(b"MM\0+")
    {
        Some(BandFormat::Tiff)
    } else {
        None
    })
}

fn read_up_to(f: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match f.read(&mut buf[n..])? {
            0 => break,
            k => n += k,
        }
    }
    Ok(n)
}

/// Open `path` for reading in bands, checking its size against `max_pixels` from the
/// header before any pixel is decoded.
///
/// # Errors
/// Unreadable or damaged files; an image over the limit; a kind that cannot be read in
/// bands (an interlaced PNG: `Ok(None)`, the caller opens it whole).
pub fn open(
    path: &Path,
    format: BandFormat,
    max_pixels: u64,
) -> Result<Option<Box<dyn RowReader>>> {
    // Opening and every read run behind the decoders' one containment: a decoder's
    // panic is this file's error (docs/reliability.md, class 2).
    let inner = lut_core::contain(path, || -> Result<Option<Box<dyn RowReader>>> {
        lut_core::fault_point("decoder");
        let r: Box<dyn RowReader> = match format {
            BandFormat::Png => match PngRows::open(path)? {
                Some(p) => Box::new(p),
                None => return Ok(None),
            },
            BandFormat::Tiff => Box::new(TiffRows::open(path)?),
            BandFormat::Jpeg => Box::new(JpegRows::open(path)?),
        };
        Ok(Some(r))
    })?;
    let Some(inner) = inner else {
        return Ok(None);
    };
    let r: Box<dyn RowReader> = Box::new(Contained {
        path: path.to_path_buf(),
        inner,
    });
    lut_core::check_pixel_limit(
        &path.display().to_string(),
        u64::from(r.width()),
        u64::from(r.height()),
        max_pixels,
    )
    .map_err(crate::panorama::map_error)?;
    Ok(Some(r))
}

/// A reader whose every read runs behind [`lut_core::contain`].
struct Contained {
    path: PathBuf,
    inner: Box<dyn RowReader>,
}

impl RowReader for Contained {
    fn width(&self) -> u32 {
        self.inner.width()
    }
    fn height(&self) -> u32 {
        self.inner.height()
    }
    fn read_rows(&mut self, out: &mut [u8]) -> Result<usize> {
        let inner = &mut self.inner;
        lut_core::contain(&self.path, || inner.read_rows(out))
    }
}

#[inline]
fn to8(v: u16) -> u8 {
    ((u32::from(v) * 255 + 32767) / 65535) as u8
}

/// Convert one row of `channels` samples per pixel (gray, gray+alpha, RGB, RGBA) to RGB8.
fn row_to_rgb<T: Copy>(src: &[T], channels: usize, dst: &mut [u8], to_u8: impl Fn(T) -> u8) {
    for (d, s) in dst.chunks_exact_mut(3).zip(src.chunks_exact(channels)) {
        let (rgb, a) = match channels {
            1 => ([to_u8(s[0]); 3], 255),
            2 => ([to_u8(s[0]); 3], to_u8(s[1])),
            3 => ([to_u8(s[0]), to_u8(s[1]), to_u8(s[2])], 255),
            _ => ([to_u8(s[0]), to_u8(s[1]), to_u8(s[2])], to_u8(s[3])),
        };
        if a == 255 {
            d.copy_from_slice(&rgb);
        } else {
            for (o, c) in d.iter_mut().zip(rgb) {
                *o = ((u32::from(c) * u32::from(a) + 127) / 255) as u8;
            }
        }
    }
}

/// A PNG read a row at a time.
struct PngRows {
    path: PathBuf,
    reader: png::Reader<BufReader<File>>,
    width: u32,
    height: u32,
    channels: usize,
    sixteen: bool,
    row: u32,
}

impl PngRows {
    fn open(path: &Path) -> Result<Option<PngRows>> {
        let name = || path.display().to_string();
        let f = lut_core::open_regular(path).with_context(|| format!("{}: cannot open", name()))?;
        let mut d = png::Decoder::new(BufReader::new(f));
        d.set_transformations(png::Transformations::EXPAND);
        let reader = d
            .read_info()
            .map_err(|e| anyhow!("{}: cannot read PNG: {e}", name()))?;
        let info = reader.info();
        if info.interlaced {
            return Ok(None);
        }
        let (width, height) = (info.width, info.height);
        let (ct, depth) = reader.output_color_type();
        let channels = match ct {
            png::ColorType::Grayscale => 1,
            png::ColorType::GrayscaleAlpha => 2,
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            png::ColorType::Indexed => bail!("{}: indexed PNG was not expanded", name()),
        };
        let sixteen = depth == png::BitDepth::Sixteen;
        Ok(Some(PngRows {
            path: path.to_path_buf(),
            reader,
            width,
            height,
            channels,
            sixteen,
            row: 0,
        }))
    }
}

impl RowReader for PngRows {
    fn width(&self) -> u32 {
        self.width
    }
    fn height(&self) -> u32 {
        self.height
    }
    fn read_rows(&mut self, out: &mut [u8]) -> Result<usize> {
        let rb = 3 * self.width as usize;
        let mut n = 0;
        for dst in out.chunks_exact_mut(rb) {
            if self.row == self.height {
                break;
            }
            let row = self
                .reader
                .next_row()
                .map_err(|e| anyhow!("{}: cannot read PNG: {e}", self.path.display()))?
                .ok_or_else(|| anyhow!("{}: the PNG ended early", self.path.display()))?;
            let data = row.data();
            if self.sixteen {
                let s: Vec<u16> = data
                    .chunks_exact(2)
                    .map(|b| u16::from_be_bytes([b[0], b[1]]))
                    .collect();
                row_to_rgb(&s, self.channels, dst, to8);
            } else {
                row_to_rgb(data, self.channels, dst, |v| v);
            }
            self.row += 1;
            n += 1;
        }
        Ok(n)
    }
}

/// A TIFF read a chunk row at a time: one strip, or one row of tiles.
struct TiffRows {
    path: PathBuf,
    dec: tiff::decoder::Decoder<BufReader<File>>,
    width: u32,
    height: u32,
    channels: usize,
    tiled: bool,
    chunk_w: u32,
    chunk_h: u32,
    /// Decoded rows of the current chunk row (RGB8), and the next one to hand out.
    band: Vec<u8>,
    band_rows: u32,
    band_next: u32,
    /// The chunk row to decode next.
    chunk_row: u32,
    row: u32,
}

impl TiffRows {
    fn open(path: &Path) -> Result<TiffRows> {
        use tiff::decoder::{ChunkType, Decoder, Limits};
        let name = path.display().to_string();
        let f = lut_core::open_regular(path).with_context(|| format!("{name}: cannot open"))?;
        let mut limits = Limits::default();
        // One chunk (a strip or a tile) is decoded at a time; 512 MiB is far above any
        // sane chunk and keeps a damaged header from asking for more.
        limits.decoding_buffer_size = 512 << 20;
        limits.intermediate_buffer_size = 512 << 20;
        let mut dec = Decoder::new(BufReader::new(f))
            .map_err(|e| anyhow!("{name}: cannot read TIFF: {e}"))?
            .with_limits(limits);
        let (width, height) = dec
            .dimensions()
            .map_err(|e| anyhow!("{name}: cannot read TIFF: {e}"))?;
        let ct = dec
            .colortype()
            .map_err(|e| anyhow!("{name}: cannot read TIFF: {e}"))?;
        let channels = match ct {
            tiff::ColorType::Gray(8 | 16) => 1,
            tiff::ColorType::GrayA(8 | 16) => 2,
            tiff::ColorType::RGB(8 | 16) => 3,
            tiff::ColorType::RGBA(8 | 16) => 4,
            other => bail!(
                "{name}: TIFF colour type {other:?} is not supported (8- or 16-bit gray, gray + alpha, RGB or RGBA)"
            ),
        };
        let tiled = dec.get_chunk_type() == ChunkType::Tile;
        let (chunk_w, chunk_h) = dec.chunk_dimensions();
        if chunk_w == 0 || chunk_h == 0 {
            bail!("{name}: the TIFF has chunks of size 0");
        }
        Ok(TiffRows {
            path: path.to_path_buf(),
            dec,
            width,
            height,
            channels,
            tiled,
            chunk_w,
            chunk_h,
            band: Vec::new(),
            band_rows: 0,
            band_next: 0,
            chunk_row: 0,
            row: 0,
        })
    }

    /// Decode the next chunk row into `band`.
    fn next_band(&mut self) -> Result<()> {
        use tiff::decoder::DecodingResult;
        let name = self.path.display().to_string();
        let y0 = self.chunk_row * self.chunk_h;
        let rows = (self.height - y0).min(self.chunk_h);
        let w = self.width as usize;
        self.band.resize(3 * w * rows as usize, 0);
        let across = if self.tiled {
            self.width.div_ceil(self.chunk_w)
        } else {
            1
        };
        for cx in 0..across {
            let index = self.chunk_row * across + cx;
            let (cw, ch) = self.dec.chunk_data_dimensions(index);
            let data = self
                .dec
                .read_chunk(index)
                .map_err(|e| anyhow!("{name}: cannot read TIFF chunk {index}: {e}"))?;
            let x0 = cx * self.chunk_w;
            let cols = (self.width - x0).min(cw) as usize;
            let stride = cw as usize * self.channels;
            let check = |len: usize| -> Result<()> {
                if len < stride * rows.min(ch) as usize {
                    bail!("{name}: TIFF chunk {index} is short");
                }
                Ok(())
            };
            for y in 0..rows.min(ch) as usize {
                let dst =
                    &mut self.band[3 * (y * w + x0 as usize)..3 * (y * w + x0 as usize + cols)];
                match &data {
                    DecodingResult::U8(v) => {
                        check(v.len())?;
                        row_to_rgb(
                            &v[y * stride..y * stride + cols * self.channels],
                            self.channels,
                            dst,
                            |v| v,
                        );
                    }
                    DecodingResult::U16(v) => {
                        check(v.len())?;
                        row_to_rgb(
                            &v[y * stride..y * stride + cols * self.channels],
                            self.channels,
                            dst,
                            to8,
                        );
                    }
                    _ => bail!("{name}: TIFF sample format not supported (8 or 16-bit unsigned)"),
                }
            }
            if ch < rows {
                bail!("{name}: TIFF chunk {index} has {ch} rows, {rows} expected");
            }
        }
        self.band_rows = rows;
        self.band_next = 0;
        self.chunk_row += 1;
        Ok(())
    }
}

impl RowReader for TiffRows {
    fn width(&self) -> u32 {
        self.width
    }
    fn height(&self) -> u32 {
        self.height
    }
    fn read_rows(&mut self, out: &mut [u8]) -> Result<usize> {
        let rb = 3 * self.width as usize;
        let mut n = 0;
        for dst in out.chunks_exact_mut(rb) {
            if self.row == self.height {
                break;
            }
            if self.band_next == self.band_rows {
                self.next_band()?;
            }
            let at = self.band_next as usize * rb;
            dst.copy_from_slice(&self.band[at..at + rb]);
            self.band_next += 1;
            self.row += 1;
            n += 1;
        }
        Ok(n)
    }
}

/// A JPEG decoded a few scanlines at a time by libjpeg (mozjpeg).
struct JpegRows {
    path: PathBuf,
    width: u32,
    height: u32,
    row: u32,
    dec: Option<mozjpeg::decompress::DecompressStarted<BufReader<File>>>,
}

/// libjpeg's fatal error: unwind out of the decoder (caught around every call).
extern "C-unwind" fn jpeg_error_exit(cinfo: &mut mozjpeg_sys::jpeg_common_struct) {
    let _ = cinfo;
    std::panic::resume_unwind(Box::new(JpegFailure::Error));
}

/// libjpeg's messages: a warning (level −1: corrupt or truncated data, which libjpeg
/// would otherwise paper over with grey rows) fails the read like an error.
extern "C-unwind" fn jpeg_emit_message(
    cinfo: &mut mozjpeg_sys::jpeg_common_struct,
    level: std::os::raw::c_int,
) {
    let _ = cinfo;
    if level < 0 {
        std::panic::resume_unwind(Box::new(JpegFailure::Warning));
    }
}

extern "C-unwind" fn jpeg_quiet(cinfo: &mut mozjpeg_sys::jpeg_common_struct) {
    let _ = cinfo;
}

extern "C-unwind" fn jpeg_no_format(
    cinfo: &mut mozjpeg_sys::jpeg_common_struct,
    buffer: &[u8; 80],
) {
    let _ = (cinfo, buffer);
}

/// Why libjpeg stopped.
#[derive(Debug, Clone, Copy)]
enum JpegFailure {
    Error,
    Warning,
}

/// An error manager that turns libjpeg's errors and warnings into unwinds (no unsafe
/// code: every field set, the callbacks plain Rust).
fn jpeg_error_mgr() -> mozjpeg_sys::jpeg_error_mgr {
    mozjpeg_sys::jpeg_error_mgr {
        error_exit: Some(jpeg_error_exit),
        emit_message: Some(jpeg_emit_message),
        output_message: Some(jpeg_quiet),
        format_message: Some(jpeg_no_format),
        reset_error_mgr: Some(jpeg_quiet),
        msg_code: 0,
        msg_parm: mozjpeg_sys::msg_parm_union::default(),
        trace_level: 0,
        num_warnings: 0,
        jpeg_message_table: std::ptr::null(),
        last_jpeg_message: 0,
        addon_message_table: std::ptr::null(),
        first_addon_message: 0,
        last_addon_message: 0,
    }
}

/// The message for a caught decoder unwind.
fn jpeg_unwind_message(p: &(dyn std::any::Any + Send)) -> &'static str {
    match p.downcast_ref::<JpegFailure>() {
        Some(JpegFailure::Warning) => "corrupt or truncated JPEG data",
        _ => "damaged JPEG (the decoder stopped)",
    }
}

impl JpegRows {
    fn open(path: &Path) -> Result<JpegRows> {
        let name = path.display().to_string();
        let mut f = lut_core::open_regular(path).with_context(|| format!("{name}: cannot open"))?;
        let len = f
            .seek(SeekFrom::End(0))
            .with_context(|| format!("{name}: cannot read"))?;
        f.seek(SeekFrom::Start(0))
            .with_context(|| format!("{name}: cannot read"))?;
        let started = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            let d = mozjpeg::Decompress::builder()
                .with_err(jpeg_error_mgr())
                .from_reader(BufReader::new(f))?;
            d.rgb()
        }));
        let dec = match started {
            Ok(Ok(d)) => d,
            Ok(Err(e)) => bail!("{name}: cannot read JPEG: {e}"),
            Err(p) => bail!(
                "{name}: cannot read JPEG: {}",
                jpeg_unwind_message(p.as_ref())
            ),
        };
        let (width, height) = (dec.width() as u32, dec.height() as u32);
        // Every 8×8 block costs at least a bit: a header claiming more than the file can
        // hold is refused before decoding (as the map loader does).
        if u64::from(width) * u64::from(height) > len.saturating_mul(512) {
            bail!("{name}: the JPEG claims {width}x{height} pixels, more than its {len} bytes can hold");
        }
        Ok(JpegRows {
            path: path.to_path_buf(),
            width,
            height,
            row: 0,
            dec: Some(dec),
        })
    }
}

impl RowReader for JpegRows {
    fn width(&self) -> u32 {
        self.width
    }
    fn height(&self) -> u32 {
        self.height
    }
    fn read_rows(&mut self, out: &mut [u8]) -> Result<usize> {
        let rb = 3 * self.width as usize;
        let want = (out.len() / rb).min((self.height - self.row) as usize);
        if want == 0 {
            if let Some(d) = self.dec.take() {
                let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| d.finish()));
            }
            return Ok(0);
        }
        let dec = self
            .dec
            .as_mut()
            .ok_or_else(|| anyhow!("{}: JPEG already finished", self.path.display()))?;
        let dst = &mut out[..want * rb];
        let pixels: &mut [[u8; 3]] = bytemuck::cast_slice_mut(dst);
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            dec.read_scanlines_into(pixels).map(|s| s.len())
        }));
        match r {
            Ok(Ok(n)) => {
                let rows = n / self.width as usize;
                if rows == 0 {
                    bail!(
                        "{}: the JPEG ended early (row {} of {})",
                        self.path.display(),
                        self.row,
                        self.height
                    );
                }
                self.row += rows as u32;
                Ok(rows)
            }
            Ok(Err(e)) => bail!("{}: cannot read JPEG: {e}", self.path.display()),
            Err(p) => bail!(
                "{}: cannot read JPEG: {}",
                self.path.display(),
                jpeg_unwind_message(p.as_ref())
            ),
        }
    }
}
