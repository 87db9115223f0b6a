//! Loading maps from image files: a pixel limit checked from the file header before any
//! pixel buffer exists (a defence against decompression bombs), decoding straight into
//! the map's own buffer, and progress reports for a user interface.
//!
//! ## The pixel limit
//! [`LoadOptions::max_pixels`] (default [`DEFAULT_MAX_PIXELS`] = 32768 × 16384) is
//! checked twice before anything the size of the image is allocated: first from the
//! header alone (`imagesize` reads the PNG IHDR, the JPEG SOF, the EXR and Radiance
//! headers, nothing more), then from the decoder's own dimensions. `image`'s [`Limits`]
//! are set as a second line of defence (sides at most `max_pixels / 2` and
//! [`MAX_MAP_WIDTH`], decoder allocations at most 16 bytes per
//! allowed pixel). [`MAX_MAP_PIXELS`] stays the hard limit whatever is asked. A JPEG
//! header must also fit its file: a file of `n` bytes cannot describe more than `512·n`
//! pixels, so a tiny file claiming a huge size is refused before anything is allocated
//! (see `jpeg.rs`).
//!
//! ## Decoders and damaged files
//! JPEG goes to zune-jpeg directly, strictly: a truncated or corrupt file is an error,
//! never a picture with a grey part (`jpeg.rs`). OpenEXR goes to the `exr` crate's
//! block reader (`io/exr.rs`): RGB or luminance-only (Y) images, the memory a damaged
//! DWA-compressed file can claim bounded, blocks that do not cover the image refused.
//! PNG, Radiance `.hdr` and anything else go through `image`. Only regular files are
//! opened (a FIFO would block; see `file.rs`).
//!
//! ## Memory
//! 8-bit images (gray, gray + alpha, RGB, RGBA: every JPEG and 8-bit PNG) are decoded
//! straight into the first bytes of the map's padded 0RGB buffer and expanded in place,
//! from the end, to 0RGB with the padding column and row. The peak is the map itself,
//! 4 × (W + 1) × (H + 1) bytes, plus what the decoder holds: for JPEG the compressed file
//! (the decoder needs it whole in memory; a progressive JPEG also holds its coefficients,
//! about 2 bytes per pixel per colour plane). OpenEXR blocks are decoded in parallel
//! batches and tone-mapped straight into the map (the peak is the map plus a few
//! blocks). 16-bit PNGs and Radiance `.hdr` are first decoded to an
//! `image::DynamicImage` (6 to 12 bytes per pixel) and then written into the map.
//!
//! ## Progress
//! A load reports [`LoadProgress`] events, in phase order [`LoadPhase::Reading`] (JPEG
//! only: the decoder reads the whole file before decoding), [`LoadPhase::Decoding`],
//! [`LoadPhase::Converting`]. Each phase starts with one event. A phase that can be
//! measured reports fractions that never decrease and ends with `Some(1.0)`: reading is
//! bytes read; decoding is bytes consumed for the streaming decoders (PNG, Radiance) and
//! blocks read for OpenEXR; converting is rows written (OpenEXR converts while it
//! decodes: its converting phase is the padding alone). JPEG decoding (zune-jpeg)
//! reports no progress: that phase starts with `fraction: None` and reports `Some(1.0)`
//! only when it is finished. Events are throttled to steps of at least 1/200.

use crate::error::{MapError, SizeProblem};
use crate::geom::limits::{MAX_MAP_PIXELS, MAX_MAP_WIDTH};
use crate::geom::projection::Projection;
use crate::io::exr::Exr;
use crate::jpeg::{check_jpeg_size, prepare, Jpeg};
use crate::map::envmap::{check_map_size, EnvMap};
use crate::map::tone::{tone_map, Tone};
use image::{ColorType, DynamicImage, ImageDecoder, Limits};
use rayon::prelude::*;
use std::cell::{Cell, RefCell};
use std::io::{BufRead, Read, Seek, SeekFrom};
use std::path::Path;

/// The default pixel limit: 32768 × 16384 = 536 870 912 pixels (a 32k equirectangular
/// map; its padded 0RGB buffer is 2.0 GiB).
pub const DEFAULT_MAX_PIXELS: u64 = 32768 * 16384;

/// Smallest fraction step reported within a phase.
const PROGRESS_STEP: f32 = 1.0 / 200.0;

/// How to load a map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadOptions {
    /// The projection (`None`: auto, a 2:1 image is equirectangular).
    pub projection: Option<Projection>,
    /// How HDR images become 8-bit pixels.
    pub tone: Tone,
    /// Largest accepted width × height, checked from the header before decoding.
    pub max_pixels: u64,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            projection: None,
            tone: Tone::default(),
            max_pixels: DEFAULT_MAX_PIXELS,
        }
    }
}

/// A step of loading.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LoadPhase {
    /// Reading the compressed file into memory (JPEG: before decoding starts).
    Reading,
    /// Decoding pixels.
    Decoding,
    /// Writing the decoded pixels into the map (0RGB, padding).
    Converting,
}

impl LoadPhase {
    /// A short name for a progress label.
    pub fn name(self) -> &'static str {
        match self {
            LoadPhase::Reading => "reading",
            LoadPhase::Decoding => "decoding",
            LoadPhase::Converting => "converting",
        }
    }
}

/// One progress report.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadProgress {
    /// The current phase.
    pub phase: LoadPhase,
    /// Done fraction of the phase in [0, 1]; `None` when the decoder does not tell.
    pub fraction: Option<f32>,
}

/// Check `width × height` against `limit`.
///
/// # Errors
/// [`MapError::TooManyPixels`] naming `what`, the size and the limit.
pub fn check_pixel_limit(what: &str, width: u64, height: u64, limit: u64) -> Result<(), MapError> {
    let pixels = width.saturating_mul(height);
    if pixels > limit {
        return Err(MapError::TooManyPixels {
            what: what.to_string(),
            width,
            height,
            pixels,
            limit,
        });
    }
    Ok(())
}

/// Throttles progress events and keeps them monotone within a phase.
struct Sink<'a> {
    cb: RefCell<&'a mut dyn FnMut(LoadProgress)>,
    last: Cell<Option<(LoadPhase, Option<f32>)>>,
    /// The phase that bytes read from the source count toward (`None`: they do not).
    bytes_phase: Cell<Option<LoadPhase>>,
    total: u64,
}

impl<'a> Sink<'a> {
    fn new(cb: &'a mut dyn FnMut(LoadProgress), total: u64) -> Self {
        Sink {
            cb: RefCell::new(cb),
            last: Cell::new(None),
            bytes_phase: Cell::new(None),
            total,
        }
    }

    fn report(&self, phase: LoadPhase, fraction: Option<f32>) {
        let fraction = fraction.map(|f| if f.is_nan() { 0.0 } else { f.clamp(0.0, 1.0) });
        if let Some((p, last)) = self.last.get() {
            if p == phase {
                match (last, fraction) {
                    (_, None) => return,
                    (Some(l), Some(f)) if f <= l || (f < 1.0 && f - l < PROGRESS_STEP) => return,
                    _ => {}
                }
            }
        }
        self.last.set(Some((phase, fraction)));
        if let Ok(mut cb) = self.cb.try_borrow_mut() {
            (*cb)(LoadProgress { phase, fraction });
        }
    }

    fn bytes(&self, pos: u64) {
        if let (Some(p), true) = (self.bytes_phase.get(), self.total > 0) {
            self.report(p, Some((pos as f64 / self.total as f64) as f32));
        }
    }
}

/// A reader that reports how far into the source it is.
struct Counted<'s, 'a, R> {
    inner: R,
    pos: u64,
    sink: &'s Sink<'a>,
}

impl<R: Read> Read for Counted<'_, '_, R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.pos += n as u64;
        self.sink.bytes(self.pos);
        Ok(n)
    }
}

impl<R: BufRead> BufRead for Counted<'_, '_, R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        self.inner.fill_buf()
    }
    fn consume(&mut self, amt: usize) {
        self.inner.consume(amt);
        self.pos += amt as u64;
        self.sink.bytes(self.pos);
    }
}

impl<R: Seek> Seek for Counted<'_, '_, R> {
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        self.pos = self.inner.seek(to)?;
        Ok(self.pos)
    }
}

/// Load an image file as a map with `opts`, reporting progress to `progress` (see the
/// [`LoadOptions`] and [`LoadProgress`] docs for the phases and the pixel limit). The file
/// is streamed, never read whole into memory by this function. `opts.projection` `None`
/// means *auto*: a 2:1 image is equirectangular, anything else is an error.
///
/// # Errors
/// [`MapError::TooManyPixels`] when the header announces more than `opts.max_pixels`
/// (nothing decoded), [`MapError::Decode`] for an unreadable or undecodable file,
/// [`MapError::Size`] for an unsupported size, [`MapError::UnknownProjection`] /
/// [`MapError::EquirectNotTwoToOne`] when the projection does not fit the image.
pub fn load_map(
    path: &Path,
    opts: &LoadOptions,
    progress: &mut dyn FnMut(LoadProgress),
) -> Result<EnvMap, MapError> {
    let what = path.display().to_string();
    let io_err = |e: std::io::Error| MapError::Decode {
        path: path.to_path_buf(),
        reason: e.to_string(),
    };
    let file = crate::file::open_regular(path).map_err(io_err)?;
    let len = file.metadata().map_err(io_err)?.len();
    decode_reader(
        std::io::BufReader::with_capacity(1 << 20, file),
        len,
        &what,
        opts,
        progress,
    )
}

/// As [`load_map`] for an in-memory encoded image; `what` names it in errors.
///
/// # Errors
/// As [`load_map`].
pub fn decode_map(
    bytes: &[u8],
    what: &str,
    opts: &LoadOptions,
    progress: &mut dyn FnMut(LoadProgress),
) -> Result<EnvMap, MapError> {
    decode_reader(
        std::io::Cursor::new(bytes),
        bytes.len() as u64,
        what,
        opts,
        progress,
    )
}

/// A map from a decoded image (any colour type; 8-bit images as stored, HDR
/// (floating-point) ones through `tone`: exposure, the tone curve `x / (1 + x)`, then sRGB
/// encoding; negative and NaN values become 0 and +∞ white, never propagated).
///
/// # Errors
/// [`MapError::Size`] for an empty or oversized image.
pub fn map_from_image(
    img: &DynamicImage,
    projection: Projection,
    tone: Tone,
) -> Result<EnvMap, MapError> {
    image_to_map("image", img, projection, tone, &mut |_| {})
}

/// `image`'s limits for a load under `max_pixels`: the second line of defence after the
/// header check.
fn image_limits(max_pixels: u64) -> Limits {
    let max = max_pixels.min(MAX_MAP_PIXELS);
    let side = u32::try_from((max / 2).min(u64::from(MAX_MAP_WIDTH))).unwrap_or(MAX_MAP_WIDTH);
    let mut l = Limits::no_limits();
    l.max_image_width = Some(side);
    l.max_image_height = Some(side);
    l.max_alloc = Some(max.saturating_mul(16));
    l
}

/// A decoder that panicked: the file's [`MapError::Decode`].
impl From<crate::guard::DecoderPanic> for MapError {
    fn from(p: crate::guard::DecoderPanic) -> MapError {
        MapError::Decode {
            path: p.path,
            reason: format!(
                "the file is damaged or of a kind the decoder cannot handle (the decoder failed \
                 on it: {})",
                p.message
            ),
        }
    }
}

/// Decode an image from `src` behind the crate's one containment
/// ([`crate::guard::contain`]): a panic in any decoder (PNG, JPEG, HDR, EXR, TIFF, and
/// whatever `image` reads) is the file's error, never the end of the process or the
/// loading thread.
pub(crate) fn decode_reader<R: BufRead + Seek>(
    src: R,
    len: u64,
    what: &str,
    opts: &LoadOptions,
    progress: &mut dyn FnMut(LoadProgress),
) -> Result<EnvMap, MapError> {
    crate::guard::contain(Path::new(what), || {
        decode_contained(src, len, what, opts, progress)
    })
}

fn decode_contained<R: BufRead + Seek>(
    mut src: R,
    len: u64,
    what: &str,
    opts: &LoadOptions,
    progress: &mut dyn FnMut(LoadProgress),
) -> Result<EnvMap, MapError> {
    crate::guard::fault_point("decoder");
    let err = |reason: String| MapError::Decode {
        path: what.into(),
        reason,
    };
    // 1. The header alone: nothing of the image's size exists yet.
    let header = imagesize::reader_size(&mut src).ok();
    if let Some(size) = header {
        let (w, h) = (size.width as u64, size.height as u64);
        check_pixel_limit(what, w, h, opts.max_pixels)?;
        check_map_size(
            what,
            u32::try_from(w).unwrap_or(u32::MAX),
            u32::try_from(h).unwrap_or(u32::MAX),
        )?;
    }
    src.seek(SeekFrom::Start(0))
        .map_err(|e| err(e.to_string()))?;
    let mut magic = [0u8; 16];
    let n = read_up_to(&mut src, &mut magic).map_err(|e| err(e.to_string()))?;
    src.seek(SeekFrom::Start(0))
        .map_err(|e| err(e.to_string()))?;
    let Ok(format) = image::guess_format(&magic[..n]) else {
        return Err(err("unrecognized or unsupported image format".into()));
    };
    let sink = Sink::new(progress, len);
    match format {
        image::ImageFormat::Jpeg => {
            if let Some(size) = header {
                check_jpeg_size(what, size.width as u64, size.height as u64, len)?;
            }
            decode_jpeg(src, len, what, opts, &sink)
        }
        image::ImageFormat::OpenExr => decode_exr(src, what, opts, &sink),
        _ => decode_with_image(src, what, opts, &sink),
    }
}

/// Read until `buf` is full or the source ends; the number of bytes read.
fn read_up_to(src: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match src.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}

/// The size and projection checks every decoder's own dimensions pass (after the header
/// check, before the map exists).
fn check_decoded(what: &str, w: u32, h: u32, opts: &LoadOptions) -> Result<Projection, MapError> {
    check_pixel_limit(what, w.into(), h.into(), opts.max_pixels)?;
    check_map_size(what, w, h)?;
    resolve_projection(what, w, h, opts.projection)
}

/// JPEG: the whole file read (the decoder needs it in memory), decoded strictly (see
/// `jpeg.rs`) into the map's buffer and expanded in place.
fn decode_jpeg<R: BufRead + Seek>(
    src: R,
    len: u64,
    what: &str,
    opts: &LoadOptions,
    sink: &Sink,
) -> Result<EnvMap, MapError> {
    let err = |reason: String| MapError::Decode {
        path: what.into(),
        reason,
    };
    sink.report(LoadPhase::Reading, Some(0.0));
    sink.bytes_phase.set(Some(LoadPhase::Reading));
    let mut bytes = Vec::new();
    bytes
        .try_reserve_exact(usize::try_from(len).unwrap_or(usize::MAX))
        .map_err(|_| err(format!("cannot hold its {len} bytes in memory")))?;
    Counted {
        inner: src,
        pos: 0,
        sink,
    }
    .read_to_end(&mut bytes)
    .map_err(|e| err(e.to_string()))?;
    sink.bytes_phase.set(None);
    // The stream must be whole; its image data (not the file's metadata or padding)
    // bounds the size the header may claim (jpeg.rs).
    let scan = prepare(&mut bytes, what)?;
    let jpeg = Jpeg::new(&bytes, what)?;
    let (w, h) = (jpeg.width, jpeg.height);
    check_jpeg_size(what, w.into(), h.into(), scan)?;
    let projection = check_decoded(what, w, h, opts)?;
    sink.report(LoadPhase::Reading, Some(1.0));
    sink.report(LoadPhase::Decoding, None);
    let ct = jpeg.color;
    let mut data = alloc_map(what, w, h)?;
    let n = w as usize * h as usize * usize::from(ct.bytes_per_pixel());
    jpeg.decode_into(&mut bytemuck::cast_slice_mut(&mut data)[..n], what)?;
    drop(bytes);
    Ok(finish_8bit(data, ct, w, h, projection, sink))
}

/// OpenEXR through `io/exr.rs`: blocks decoded in parallel straight into the map.
fn decode_exr<R: BufRead + Seek>(
    src: R,
    what: &str,
    opts: &LoadOptions,
    sink: &Sink,
) -> Result<EnvMap, MapError> {
    sink.report(LoadPhase::Decoding, Some(0.0));
    let exr = Exr::new(src, what)?;
    let (w, h) = (exr.width, exr.height);
    let projection = check_decoded(what, w, h, opts)?;
    let mut data = alloc_map(what, w, h)?;
    exr.decode_into(&mut data, what, opts.tone, &mut |f| {
        sink.report(LoadPhase::Decoding, Some(f))
    })?;
    sink.report(LoadPhase::Decoding, Some(1.0));
    sink.report(LoadPhase::Converting, Some(0.0));
    let (wu, hu) = (w as usize, h as usize);
    let wraps = projection.wraps();
    for row in data[..hu * (wu + 1)].chunks_exact_mut(wu + 1) {
        row[wu] = if wraps { row[0] } else { row[wu - 1] };
    }
    pad_last_row(&mut data, w, h);
    sink.report(LoadPhase::Converting, Some(1.0));
    Ok(EnvMap::from_padded(w, h, projection, data))
}

/// PNG, Radiance HDR and anything else `image` reads.
fn decode_with_image<R: BufRead + Seek>(
    src: R,
    what: &str,
    opts: &LoadOptions,
    sink: &Sink,
) -> Result<EnvMap, MapError> {
    let err = |reason: String| MapError::Decode {
        path: what.into(),
        reason,
    };
    let mut reader = image::ImageReader::new(Counted {
        inner: src,
        pos: 0,
        sink,
    })
    .with_guessed_format()
    .map_err(|e| err(e.to_string()))?;
    if reader.format().is_none() {
        return Err(err("unrecognized or unsupported image format".into()));
    }
    // These decoders stream, so bytes consumed measure decoding.
    sink.report(LoadPhase::Decoding, Some(0.0));
    sink.bytes_phase.set(Some(LoadPhase::Decoding));
    reader.limits(image_limits(opts.max_pixels));
    // 2. The decoder's own dimensions (it has read the header, no pixels).
    let decoder = reader.into_decoder().map_err(|e| err(e.to_string()))?;
    let (w, h) = decoder.dimensions();
    let projection = check_decoded(what, w, h, opts)?;
    let ct = decoder.color_type();
    match ct {
        ColorType::L8 | ColorType::La8 | ColorType::Rgb8 | ColorType::Rgba8 => {
            let mut data = alloc_map(what, w, h)?;
            let n = w as usize * h as usize * usize::from(ct.bytes_per_pixel());
            decoder
                .read_image(&mut bytemuck::cast_slice_mut(&mut data)[..n])
                .map_err(|e| err(e.to_string()))?;
            sink.bytes_phase.set(None);
            Ok(finish_8bit(data, ct, w, h, projection, sink))
        }
        _ => {
            let img = DynamicImage::from_decoder(decoder).map_err(|e| err(e.to_string()))?;
            sink.bytes_phase.set(None);
            sink.report(LoadPhase::Decoding, Some(1.0));
            sink.report(LoadPhase::Converting, Some(0.0));
            let map = image_to_map(what, &img, projection, opts.tone, &mut |f| {
                sink.report(LoadPhase::Converting, Some(f))
            })?;
            sink.report(LoadPhase::Converting, Some(1.0));
            Ok(map)
        }
    }
}

/// 8-bit pixels of colour type `ct` decoded into the first bytes of `data` (a padded map
/// buffer): expanded in place to padded 0RGB, reporting the end of decoding and the
/// conversion.
fn finish_8bit(
    mut data: Vec<u32>,
    ct: ColorType,
    w: u32,
    h: u32,
    projection: Projection,
    sink: &Sink,
) -> EnvMap {
    sink.report(LoadPhase::Decoding, Some(1.0));
    sink.report(LoadPhase::Converting, Some(0.0));
    {
        let bytes: &mut [u8] = bytemuck::cast_slice_mut(&mut data);
        let mut rows = |f: f32| sink.report(LoadPhase::Converting, Some(f));
        let wraps = projection.wraps();
        match ct {
            ColorType::L8 => expand_in_place::<1>(bytes, w, h, wraps, &mut rows),
            ColorType::La8 => expand_in_place::<2>(bytes, w, h, wraps, &mut rows),
            ColorType::Rgb8 => expand_in_place::<3>(bytes, w, h, wraps, &mut rows),
            _ => expand_in_place::<4>(bytes, w, h, wraps, &mut rows),
        }
    }
    pad_last_row(&mut data, w, h);
    sink.report(LoadPhase::Converting, Some(1.0));
    EnvMap::from_padded(w, h, projection, data)
}

/// A zeroed padded map buffer, `(w + 1) × (h + 1)` pixels, or an error when the memory
/// cannot be had.
fn alloc_map(what: &str, w: u32, h: u32) -> Result<Vec<u32>, MapError> {
    let n = (w as usize + 1) * (h as usize + 1);
    // Ask first, so a refusal is an error rather than an abort; then take zeroed memory
    // from the system (calloc: pages are zeroed lazily as the decoder writes them,
    // rather than cleared up front).
    let mut probe: Vec<u32> = Vec::new();
    probe.try_reserve_exact(n).map_err(|_| MapError::Size {
        what: what.into(),
        width: w,
        height: h,
        problem: SizeProblem::OutOfMemory {
            bytes: n as u64 * 4,
        },
    })?;
    drop(probe);
    Ok(vec![0u32; n])
}

/// Row `h` repeats row `h − 1` (vertical clamp for the bilinear sampler).
fn pad_last_row(data: &mut [u32], w: u32, h: u32) {
    let s = w as usize + 1;
    let h = h as usize;
    data.copy_within((h - 1) * s..h * s, h * s);
}

/// One 8-bit pixel of `BPP` bytes (gray, gray + alpha, RGB, RGBA) as 0RGB; alpha is
/// dropped, as `DynamicImage::to_rgb8` drops it.
#[inline(always)]
fn px<const BPP: usize>(s: &[u8]) -> u32 {
    if BPP <= 2 {
        u32::from(s[0]) * 0x0001_0101
    } else {
        (u32::from(s[0]) << 16) | (u32::from(s[1]) << 8) | u32::from(s[2])
    }
}

/// Convert one row from `src` (`w` pixels of `BPP` bytes) into `dst` (`w + 1` 0RGB
/// pixels as native-endian bytes, the last one the padding column).
#[inline]
fn convert_row<const BPP: usize>(src: &[u8], dst: &mut [u8], w: usize, wraps: bool) {
    for (d, s) in dst.chunks_exact_mut(4).zip(src.chunks_exact(BPP)) {
        d.copy_from_slice(&px::<BPP>(s).to_ne_bytes());
    }
    let from = if wraps { 0 } else { 4 * (w - 1) };
    dst.copy_within(from..from + 4, 4 * w);
}

/// Convert row `y` where its source and destination overlap: pixel by pixel from the
/// right end, so no source byte is overwritten before it is read (the destination of
/// pixel x starts at or after the end of the source of pixel x − 1).
fn convert_row_in_place<const BPP: usize>(bytes: &mut [u8], y: usize, w: usize, wraps: bool) {
    let s0 = y * w * BPP;
    let d0 = y * (w + 1) * 4;
    for x in (0..w).rev() {
        let v = px::<BPP>(&bytes[s0 + x * BPP..s0 + (x + 1) * BPP]);
        bytes[d0 + 4 * x..d0 + 4 * x + 4].copy_from_slice(&v.to_ne_bytes());
    }
    let from = d0 + if wraps { 0 } else { 4 * (w - 1) };
    bytes.copy_within(from..from + 4, d0 + 4 * w);
}

/// Expand `w × h` pixels of `BPP` bytes, packed at the start of `bytes`, to the padded
/// 0RGB layout of the same buffer (`(w + 1) × (h + 1)` u32, the last row left for
/// [`pad_last_row`]).
///
/// Rows are converted from the bottom: a band of rows `[a, b)` whose sources all end
/// before its destinations begin (`b·w·BPP ≤ a·(w+1)·4`) is converted in parallel
/// (rayon) through disjoint slices; the first few rows, where a row's destination
/// overlaps its own source, go pixel by pixel from the right. `rows_done` gets the done
/// fraction after each band.
fn expand_in_place<const BPP: usize>(
    bytes: &mut [u8],
    w: u32,
    h: u32,
    wraps: bool,
    rows_done: &mut dyn FnMut(f32),
) {
    let (w, h) = (w as usize, h as usize);
    let src_row = w * BPP;
    let dst_row = (w + 1) * 4;
    debug_assert!(bytes.len() >= (h + 1) * dst_row);
    let max_band = (h / 64).max(1);
    let mut b = h;
    while b > 0 {
        let a_min = (b * src_row).div_ceil(dst_row);
        if a_min >= b {
            convert_row_in_place::<BPP>(bytes, b - 1, w, wraps);
            b -= 1;
        } else {
            let a = a_min.max(b.saturating_sub(max_band));
            let (lo, hi) = bytes.split_at_mut(a * dst_row);
            let src = &lo[a * src_row..b * src_row];
            let dst = &mut hi[..(b - a) * dst_row];
            dst.par_chunks_exact_mut(dst_row)
                .zip(src.par_chunks_exact(src_row))
                .for_each(|(d, s)| convert_row::<BPP>(s, d, w, wraps));
            b = a;
        }
        rows_done((h - b) as f32 / h as f32);
    }
}

/// Fill a new padded map from `row(y, out)` (`out` is the `w` pixels of row y), in
/// parallel bands of rows, reporting the done fraction after each band.
fn fill_rows(
    what: &str,
    w: u32,
    h: u32,
    wraps: bool,
    rows_done: &mut dyn FnMut(f32),
    row: impl Fn(usize, &mut [u32]) + Sync,
) -> Result<Vec<u32>, MapError> {
    let mut data = alloc_map(what, w, h)?;
    let (wu, hu) = (w as usize, h as usize);
    let s = wu + 1;
    let band = (hu / 64).max(1);
    for (bi, chunk) in data[..hu * s].chunks_mut(band * s).enumerate() {
        chunk
            .par_chunks_exact_mut(s)
            .enumerate()
            .for_each(|(i, r)| {
                row(bi * band + i, &mut r[..wu]);
                r[wu] = if wraps { r[0] } else { r[wu - 1] };
            });
        rows_done(((bi + 1) * band).min(hu) as f32 / hu as f32);
    }
    pad_last_row(&mut data, w, h);
    Ok(data)
}

/// A decoded image as a map: 8-bit images as stored, floating-point ones through `tone`
/// (see [`map_from_image`]).
fn image_to_map(
    what: &str,
    img: &DynamicImage,
    projection: Projection,
    tone: Tone,
    rows_done: &mut dyn FnMut(f32),
) -> Result<EnvMap, MapError> {
    let (w, h) = (img.width(), img.height());
    check_map_size(what, w, h)?;
    let wraps = projection.wraps();
    let k = 2f32.powf(tone.exposure_ev as f32);
    let hdr = |p: &[f32]| {
        let c = |x: f32| u32::from(tone_map(x * k));
        (c(p[0]) << 16) | (c(p[1]) << 8) | c(p[2])
    };
    let wu = w as usize;
    let data = match img {
        DynamicImage::ImageRgb32F(b) => {
            let raw: &[f32] = b.as_raw();
            fill_rows(what, w, h, wraps, rows_done, |y, out| {
                let src = &raw[y * wu * 3..(y + 1) * wu * 3];
                for (o, p) in out.iter_mut().zip(src.chunks_exact(3)) {
                    *o = hdr(p);
                }
            })?
        }
        DynamicImage::ImageRgba32F(b) => {
            let raw: &[f32] = b.as_raw();
            fill_rows(what, w, h, wraps, rows_done, |y, out| {
                let src = &raw[y * wu * 4..(y + 1) * wu * 4];
                for (o, p) in out.iter_mut().zip(src.chunks_exact(4)) {
                    *o = hdr(p);
                }
            })?
        }
        _ => {
            let owned;
            let rgb = match img.as_rgb8() {
                Some(b) => b,
                None => {
                    owned = img.to_rgb8();
                    &owned
                }
            };
            let raw: &[u8] = rgb.as_raw();
            fill_rows(what, w, h, wraps, rows_done, |y, out| {
                let src = &raw[y * wu * 3..(y + 1) * wu * 3];
                for (o, p) in out.iter_mut().zip(src.chunks_exact(3)) {
                    *o = px::<3>(p);
                }
            })?
        }
    };
    Ok(EnvMap::from_padded(w, h, projection, data))
}

/// Pick the projection for an image: explicit, or auto (2:1 → equirect, else an error).
///
/// # Errors
/// [`MapError::UnknownProjection`] when auto cannot decide,
/// [`MapError::EquirectNotTwoToOne`] when an equirect is not 2:1.
pub fn resolve_projection(
    what: &str,
    w: u32,
    h: u32,
    projection: Option<Projection>,
) -> Result<Projection, MapError> {
    match projection {
        None if w != 2 * h => Err(MapError::UnknownProjection {
            what: what.into(),
            width: w,
            height: h,
        }),
        Some(Projection::Equirect) if w != 2 * h => Err(MapError::EquirectNotTwoToOne {
            what: what.into(),
            width: w,
            height: h,
        }),
        None => Ok(Projection::Equirect),
        Some(p) => Ok(p),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn encode(img: &DynamicImage, format: image::ImageFormat) -> Vec<u8> {
        let mut v = Vec::new();
        img.write_to(&mut std::io::Cursor::new(&mut v), format)
            .unwrap();
        v
    }

    fn noise(w: u32, h: u32, seed: u32) -> image::RgbaImage {
        let mut s = seed;
        image::RgbaImage::from_fn(w, h, |_, _| {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            image::Rgba((s >> 8).to_le_bytes())
        })
    }

    fn same(a: &EnvMap, b: &EnvMap) {
        assert_eq!((a.width(), a.height()), (b.width(), b.height()));
        assert_eq!(a.projection(), b.projection());
        assert!(a.padded() == b.padded(), "padded buffers differ");
    }

    /// Every 8-bit colour type decoded in place equals the map built from the decoded
    /// `DynamicImage` (the independent path), padding included, wrapping or not.
    #[test]
    fn in_place_expansion_matches_the_image_path() {
        let base = DynamicImage::ImageRgba8(noise(46, 23, 7));
        let imgs = [
            DynamicImage::ImageLuma8(base.to_luma8()),
            DynamicImage::ImageLumaA8(base.to_luma_alpha8()),
            DynamicImage::ImageRgb8(base.to_rgb8()),
            base.clone(),
        ];
        for img in &imgs {
            for proj in [Projection::Equirect, Projection::Elliptical] {
                let png = encode(img, image::ImageFormat::Png);
                let opts = LoadOptions {
                    projection: Some(proj),
                    ..LoadOptions::default()
                };
                let got = decode_map(&png, "t.png", &opts, &mut |_| {}).unwrap();
                let want = map_from_image(img, proj, Tone::default()).unwrap();
                same(&got, &want);
            }
        }
        // A JPEG (zune-jpeg into the map buffer) against image's own decode of it.
        let jpg = encode(
            &DynamicImage::ImageRgb8(base.to_rgb8()),
            image::ImageFormat::Jpeg,
        );
        let got = decode_map(&jpg, "t.jpg", &LoadOptions::default(), &mut |_| {}).unwrap();
        let dec = image::load_from_memory(&jpg).unwrap();
        same(
            &got,
            &map_from_image(&dec, Projection::Equirect, Tone::default()).unwrap(),
        );
    }

    /// Sizes where the in-place bands change shape (a few rows, one row per band).
    #[test]
    fn in_place_expansion_at_odd_sizes() {
        for (w, h) in [(2, 2), (3, 2), (4, 2), (6, 3), (10, 5), (130, 65)] {
            let img = DynamicImage::ImageRgb8(DynamicImage::ImageRgba8(noise(w, h, w)).to_rgb8());
            let png = encode(&img, image::ImageFormat::Png);
            let opts = LoadOptions {
                projection: Some(Projection::Cylinder),
                ..LoadOptions::default()
            };
            let got = decode_map(&png, "t.png", &opts, &mut |_| {}).unwrap();
            same(
                &got,
                &map_from_image(&img, Projection::Cylinder, Tone::default()).unwrap(),
            );
        }
    }

    fn events(bytes: &[u8]) -> Vec<LoadProgress> {
        let mut ev = Vec::new();
        decode_map(bytes, "t", &LoadOptions::default(), &mut |p| ev.push(p)).unwrap();
        ev
    }

    /// Phases in order, each starting once; fractions never decrease within a phase
    /// and every phase ends at 1.
    fn check_events(ev: &[LoadProgress], phases: &[LoadPhase]) {
        let mut seen: Vec<LoadPhase> = Vec::new();
        for e in ev {
            if seen.last() != Some(&e.phase) {
                assert!(
                    !seen.contains(&e.phase),
                    "phase {:?} came back: {ev:?}",
                    e.phase
                );
                seen.push(e.phase);
            }
        }
        assert_eq!(seen, phases, "{ev:?}");
        for p in phases {
            let fr: Vec<Option<f32>> = ev
                .iter()
                .filter(|e| e.phase == *p)
                .map(|e| e.fraction)
                .collect();
            let known: Vec<f32> = fr.iter().flatten().copied().collect();
            assert!(known.windows(2).all(|w| w[0] < w[1]), "{p:?}: {fr:?}");
            assert_eq!(fr.last(), Some(&Some(1.0)), "{p:?} ends at 1: {fr:?}");
            assert!(known.iter().all(|f| (0.0..=1.0).contains(f)));
            if fr.first() == Some(&None) {
                // Unmeasured: one `None`, then only the end.
                assert_eq!(fr.len(), 2, "{p:?}: {fr:?}");
            }
        }
    }

    #[test]
    fn progress_is_monotone_and_ends_at_one() {
        let img = DynamicImage::ImageRgb8(DynamicImage::ImageRgba8(noise(512, 256, 3)).to_rgb8());
        let png = encode(&img, image::ImageFormat::Png);
        let ev = events(&png);
        check_events(&ev, &[LoadPhase::Decoding, LoadPhase::Converting]);
        // PNG decoding is measured: more than start and end.
        let dec = ev.iter().filter(|e| e.phase == LoadPhase::Decoding).count();
        assert!(dec > 3, "{ev:?}");
        let jpg = encode(&img, image::ImageFormat::Jpeg);
        let ev = events(&jpg);
        check_events(
            &ev,
            &[
                LoadPhase::Reading,
                LoadPhase::Decoding,
                LoadPhase::Converting,
            ],
        );
        // JPEG decoding is not measured, and says so.
        assert_eq!(
            ev.iter()
                .find(|e| e.phase == LoadPhase::Decoding)
                .map(|e| e.fraction),
            Some(None)
        );
        // The floating-point path.
        let hdr = DynamicImage::ImageRgb32F(img.to_rgb32f());
        let ev = events(&encode(&hdr, image::ImageFormat::Hdr));
        check_events(&ev, &[LoadPhase::Decoding, LoadPhase::Converting]);
    }

    #[test]
    fn limit_is_checked_from_the_header() {
        let img = DynamicImage::ImageRgb8(image::RgbImage::new(64, 32));
        let png = encode(&img, image::ImageFormat::Png);
        let opts = LoadOptions {
            max_pixels: 64 * 32 - 1,
            ..LoadOptions::default()
        };
        let e = decode_map(&png, "pano.png", &opts, &mut |_| {}).unwrap_err();
        assert!(matches!(
            e,
            MapError::TooManyPixels {
                width: 64,
                height: 32,
                pixels: 2048,
                limit: 2047,
                ..
            }
        ));
        let msg = e.to_string();
        for part in ["pano.png", "64x32", "2047"] {
            assert!(msg.contains(part), "{msg}");
        }
        // No command-line flag names in library messages (the viewer adds its hints).
        assert!(!msg.contains("--"), "{msg}");
        let ok = LoadOptions {
            max_pixels: 64 * 32,
            ..LoadOptions::default()
        };
        assert!(decode_map(&png, "pano.png", &ok, &mut |_| {}).is_ok());
    }

    #[test]
    fn hdr_images_are_toned_and_clamped() {
        let mut img = image::Rgb32FImage::new(4, 2);
        for (i, p) in img.pixels_mut().enumerate() {
            let v = [f32::NAN, -1.0, 1.0, f32::INFINITY, 0.5, 2.0, 0.0, 1e9][i];
            *p = image::Rgb([v, v, v]);
        }
        let dynimg = image::DynamicImage::ImageRgb32F(img);
        let m = map_from_image(&dynimg, Projection::Equirect, Tone::default()).unwrap();
        let g = |x, y| m.pixel(x, y) & 0xFF;
        assert_eq!((g(0, 0), g(1, 0), g(2, 0), g(3, 0)), (0, 0, 188, 255));
        let brighter =
            map_from_image(&dynimg, Projection::Equirect, Tone { exposure_ev: 1.0 }).unwrap();
        // +1 EV on 0.5 is 1.0
        assert_eq!(brighter.pixel(0, 1) & 0xFF, 188);
    }

    #[test]
    fn auto_projection() {
        assert!(resolve_projection("x", 100, 50, None).is_ok());
        assert!(resolve_projection("x", 100, 60, None).is_err());
        assert!(resolve_projection("x", 100, 60, Some(Projection::Equirect)).is_err());
        assert!(resolve_projection("x", 100, 60, Some(Projection::Cylinder)).is_ok());
    }
}
