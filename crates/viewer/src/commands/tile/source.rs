//! Where the faces' pixels come from: a [`FaceSource`] renders any rectangle of a
//! full-resolution cube face by exact per-pixel inverse mapping (f64: face pixel centre →
//! world direction → the input's coordinates → bilinear).
//!
//! * [`Synthetic`]: the test scene (`lut_core::scene_color`, a latitude/longitude grid on
//!   a colour field) as a function of direction, with a fine grain (`synth.rs`): any
//!   size, no image anywhere.
//! * [`MapSource`] and [`CubeSource`]: a panorama the viewer opened into memory (any
//!   projection, partial panoramas, cube maps), sampled by lut-core's samplers.
//! * [`StoreSource`]: an equirectangular image streamed from its file into a temporary
//!   store of 256×256 blocks on disk (pass 1), read back per tile (pass 2): only the
//!   blocks a tile's pixels touch are read, so memory does not grow with the input.

use super::bands::RowReader;
use anyhow::{Context, Result};
use glam::DVec3;
use lut_core::{dir_to_lat_long, face_dir, sample_at, CubeMap, EnvMap, Face, Sampler};
use std::fs::File;
use std::path::Path;

/// Something that can draw the cube's faces at full resolution.
pub trait FaceSource: Sync {
    /// The width of the equirectangular panorama this stands for (the cube face size is
    /// generate.py's `8 * int(width / pi / 8)` of it), or `None` when the source has its
    /// own face size ([`FaceSource::face_size`]).
    fn width(&self) -> Option<u64>;
    /// The face size a cube source has.
    fn face_size(&self) -> Option<u32> {
        None
    }
    /// Draw columns `x0..x0 + w`, rows `y0..y0 + h` of `face` for faces of side `n`, as
    /// RGB8 rows into `out` (`3 · w · h` bytes).
    ///
    /// # Errors
    /// Reading the store failed.
    fn render(&self, face: Face, n: u32, rect: Rect, out: &mut [u8]) -> Result<()>;
}

/// A rectangle of a face: columns `x..x + w`, rows `y..y + h`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rect {
    /// First column.
    pub x: u32,
    /// First row.
    pub y: u32,
    /// Columns.
    pub w: u32,
    /// Rows.
    pub h: u32,
}

/// The world direction through the centre of pixel (x, y) of a face of side `n`.
#[inline]
pub fn pixel_dir(face: Face, n: u32, x: u32, y: u32) -> DVec3 {
    let half = f64::from(n) / 2.0;
    let s = (f64::from(x) + 0.5) / half - 1.0;
    let t = 1.0 - (f64::from(y) + 0.5) / half;
    face_dir(face, s, t)
}

fn per_pixel(face: Face, n: u32, r: Rect, out: &mut [u8], f: impl Fn(DVec3) -> u32) {
    for (j, row) in out.chunks_exact_mut(3 * r.w as usize).enumerate() {
        for (i, p) in row.chunks_exact_mut(3).enumerate() {
            let c = f(pixel_dir(face, n, r.x + i as u32, r.y + j as u32));
            p.copy_from_slice(&[(c >> 16) as u8, (c >> 8) as u8, c as u8]);
        }
    }
}

/// The generated test scene, for a panorama `width` pixels wide.
#[derive(Debug, Clone, Copy)]
pub struct Synthetic {
    /// The equirect width it stands for.
    pub width: u64,
}

impl FaceSource for Synthetic {
    fn width(&self) -> Option<u64> {
        Some(self.width)
    }
    fn render(&self, face: Face, n: u32, r: Rect, out: &mut [u8]) -> Result<()> {
        super::synth::render(face, n, (r.x, r.y, r.w), grain_octaves(n), out);
        Ok(())
    }
}

/// Layers of the synthetic scene's grain for faces of side `n`: one for each time the
/// face halves before it fits a 512-px tile, plus one (the levels of a pyramid of 512-px
/// tiles: the coarsest level still has pixel-scale grain). The same for every tile size.
pub fn grain_octaves(n: u32) -> u32 {
    let mut k = 1;
    let mut s = n;
    while s > 512 {
        s /= 2;
        k += 1;
    }
    k
}

/// A map panorama in memory (any projection; partial maps show their background
/// outside the covered area).
pub struct MapSource(pub EnvMap);

impl FaceSource for MapSource {
    fn width(&self) -> Option<u64> {
        Some(u64::from(self.0.width()))
    }
    fn render(&self, face: Face, n: u32, r: Rect, out: &mut [u8]) -> Result<()> {
        let m = &self.0;
        let (w, h, proj) = (f64::from(m.width()), f64::from(m.height()), m.projection());
        per_pixel(face, n, r, out, |d| {
            let (l, p) = dir_to_lat_long(d);
            sample_at(m, Sampler::Bilinear, proj.uv(l, p, w, h))
        });
        Ok(())
    }
}

/// A cube map in memory; its faces are the pyramid's at their own size.
pub struct CubeSource(pub CubeMap);

impl FaceSource for CubeSource {
    fn width(&self) -> Option<u64> {
        None
    }
    fn face_size(&self) -> Option<u32> {
        Some(self.0.face_size())
    }
    fn render(&self, face: Face, n: u32, r: Rect, out: &mut [u8]) -> Result<()> {
        per_pixel(face, n, r, out, |d| self.0.sample_dir(Sampler::Bilinear, d));
        Ok(())
    }
}

/// The block side of the temporary store.
pub const BLOCK: u32 = 256;
const BLOCK_BYTES: usize = (BLOCK * BLOCK * 3) as usize;

/// An equirectangular image in a temporary file of `BLOCK`² RGB8 blocks (row-major
/// blocks, edge blocks padded), deleted when dropped (an unnamed file).
pub struct StoreSource {
    file: File,
    width: u32,
    height: u32,
    blocks_x: u32,
    blocks_y: u32,
}

impl StoreSource {
    /// Pass 1: stream every row of `reader` into a new store in folder `tmp_dir`;
    /// `progress(rows done)` after each band.
    ///
    /// # Errors
    /// The reader's errors; the store cannot be written (a full disk).
    pub fn build(
        reader: &mut dyn RowReader,
        tmp_dir: &Path,
        progress: &mut dyn FnMut(u32),
    ) -> Result<StoreSource> {
        use std::os::unix::fs::FileExt;
        let (width, height) = (reader.width(), reader.height());
        let file = tempfile::tempfile_in(tmp_dir).with_context(|| {
            format!(
                "{}: cannot create the temporary block store",
                tmp_dir.display()
            )
        })?;
        let blocks_x = width.div_ceil(BLOCK);
        let blocks_y = height.div_ceil(BLOCK);
        let row_bytes = 3 * width as usize;
        let mut band = vec![0u8; row_bytes * BLOCK as usize];
        let mut block = vec![0u8; BLOCK_BYTES];
        for by in 0..blocks_y {
            let rows = (height - by * BLOCK).min(BLOCK) as usize;
            let mut got = 0;
            while got < rows {
                let n = reader.read_rows(&mut band[got * row_bytes..rows * row_bytes])?;
                anyhow::ensure!(n > 0, "the image ended early");
                got += n;
            }
            for bx in 0..blocks_x {
                let cols = (width - bx * BLOCK).min(BLOCK) as usize;
                for (y, dst) in block.chunks_exact_mut(3 * BLOCK as usize).enumerate() {
                    if y < rows {
                        let s = y * row_bytes + 3 * (bx * BLOCK) as usize;
                        dst[..3 * cols].copy_from_slice(&band[s..s + 3 * cols]);
                    }
                }
                let at = (u64::from(by) * u64::from(blocks_x) + u64::from(bx)) * BLOCK_BYTES as u64;
                file.write_all_at(&block, at)
                    .context("cannot write the temporary block store")?;
            }
            progress(by * BLOCK + rows as u32);
        }
        Ok(StoreSource {
            file,
            width,
            height,
            blocks_x,
            blocks_y,
        })
    }

    fn read_block(&self, bx: u32, by: u32, buf: &mut [u8]) -> Result<()> {
        use std::os::unix::fs::FileExt;
        let at = (u64::from(by) * u64::from(self.blocks_x) + u64::from(bx)) * BLOCK_BYTES as u64;
        self.file
            .read_exact_at(buf, at)
            .context("cannot read the temporary block store")
    }
}

/// The bilinear footprint of a position: columns x0, x1 (wrapped) and rows y0, y1
/// (clamped), with the fractions.
#[inline]
fn footprint(u: f64, v: f64, w: u32, h: u32) -> (u32, u32, u32, u32, f64, f64) {
    let x = u - 0.5;
    let y = v - 0.5;
    let xf = x.floor();
    let yf = y.floor();
    let fx = x - xf;
    let fy = y - yf;
    let wi = i64::from(w);
    let x0 = (xf as i64).rem_euclid(wi) as u32;
    let x1 = ((xf as i64) + 1).rem_euclid(wi) as u32;
    let hi = i64::from(h) - 1;
    let y0 = (yf as i64).clamp(0, hi) as u32;
    let y1 = ((yf as i64) + 1).clamp(0, hi) as u32;
    (x0, x1, y0, y1, fx, fy)
}

impl FaceSource for StoreSource {
    fn width(&self) -> Option<u64> {
        Some(u64::from(self.width))
    }

    fn render(&self, face: Face, n: u32, r: Rect, out: &mut [u8]) -> Result<()> {
        let (w, h) = (self.width, self.height);
        let (wf, hf) = (f64::from(w), f64::from(h));
        // Positions of every pixel (equirect: u = (λ + π)/2π · W, v = (π/2 − φ)/π · H).
        let mut pos = Vec::with_capacity((r.w * r.h) as usize);
        for y in r.y..r.y + r.h {
            for x in r.x..r.x + r.w {
                let (l, p) = dir_to_lat_long(pixel_dir(face, n, x, y));
                let u = (l + std::f64::consts::PI) / (2.0 * std::f64::consts::PI) * wf;
                let v = (std::f64::consts::FRAC_PI_2 - p) / std::f64::consts::PI * hf;
                pos.push((u, v));
            }
        }
        // The block rows touched, then a slot for every block touched.
        let (mut by0, mut by1) = (u32::MAX, 0);
        for &(u, v) in &pos {
            let (_, _, y0, y1, _, _) = footprint(u, v, w, h);
            by0 = by0.min(y0 / BLOCK);
            by1 = by1.max(y1 / BLOCK);
        }
        let bw = self.blocks_x as usize;
        let rows = (by1 - by0 + 1) as usize;
        let mut slot = vec![u32::MAX; bw * rows];
        let mut count = 0u32;
        for &(u, v) in &pos {
            let (x0, x1, y0, y1, _, _) = footprint(u, v, w, h);
            for (x, y) in [(x0, y0), (x1, y0), (x0, y1), (x1, y1)] {
                let k = ((y / BLOCK - by0) as usize) * bw + (x / BLOCK) as usize;
                if slot[k] == u32::MAX {
                    slot[k] = count;
                    count += 1;
                }
            }
        }
        let mut data = vec![0u8; count as usize * BLOCK_BYTES];
        for (k, &s) in slot.iter().enumerate() {
            if s != u32::MAX {
                let (bx, by) = ((k % bw) as u32, (k / bw) as u32 + by0);
                debug_assert!(by < self.blocks_y);
                let at = s as usize * BLOCK_BYTES;
                self.read_block(bx, by, &mut data[at..at + BLOCK_BYTES])?;
            }
        }
        let texel = |x: u32, y: u32| -> &[u8] {
            let k = ((y / BLOCK - by0) as usize) * bw + (x / BLOCK) as usize;
            let at =
                slot[k] as usize * BLOCK_BYTES + 3 * ((y % BLOCK) * BLOCK + x % BLOCK) as usize;
            &data[at..at + 3]
        };
        for (p, &(u, v)) in out.chunks_exact_mut(3).zip(&pos) {
            let (x0, x1, y0, y1, fx, fy) = footprint(u, v, w, h);
            let (a, b, c, d) = (texel(x0, y0), texel(x1, y0), texel(x0, y1), texel(x1, y1));
            for ch in 0..3 {
                let top = f64::from(a[ch]) * (1.0 - fx) + f64::from(b[ch]) * fx;
                let bot = f64::from(c[ch]) * (1.0 - fx) + f64::from(d[ch]) * fx;
                p[ch] = (top * (1.0 - fy) + bot * fy).round().clamp(0.0, 255.0) as u8;
            }
        }
        Ok(())
    }
}
