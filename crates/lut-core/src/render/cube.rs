//! The paper's two cube renderers: basic (per pixel) and accelerated (per scanline segment).
//!
//! # Rays
//! With the rotation `R` of `docs/conventions.md` (pitch about X, then yaw about Y), the ray of
//! output pixel (x, y) is `R · (dx, dy, f)` with `dx = x + ½ − W/2`, `dy = H/2 − (y + ½)`.
//! Both renderers evaluate it as `P + dx · B`, where `P = dy · R₁ + f · R₂` (the row part)
//! and `B = R₀ = (cos ψ, 0, −sin ψ)` (the image's x axis in the world): each scanline is a
//! straight 3-D line (the paper's formula 6) along a horizontal direction, so its world
//! Y is constant. The basic renderer recomputes the whole product per pixel; the compiler
//! may hoist `P`, which changes no bits.
//!
//! # Segments
//! Along a scanline the ray sweeps a great-circle arc shorter than 180°, and each face's
//! region of the sphere is convex, so the pixels of one face form one run. The accelerated
//! renderer finds the runs by binary search on the face of [`face_of`] (the same function
//! the basic renderer uses) and then *verifies* each run: on a face with axes `(a, b, m)`
//! the margin `min(m − |a|, m − |b|)` is a concave function of `dx` (each term is a linear
//! function minus an absolute value of one), so if the margin computed at both ends of the
//! run exceeds a bound `δ` far above floating-point rounding, the exact margin is above
//! rounding everywhere in between and every pixel's per-pixel face choice is that face,
//! strictly. Ends that fail the check (a pixel center within `δ` of a face edge, or a
//! scanline lying in an edge plane) are peeled off and handled per pixel; a run that still
//! fails is done per pixel.
//!
//! # Runs on the span kernels
//! On a verified run's face the ray's axes `(a, b, m)` are linear in `dx` and the face
//! coordinates `u = h + a·(h/m)`, `v = h − b·(h/m)` are a projective line, evaluated
//! exactly at every pixel with the arithmetic of [`face_uv`] in `f64` SIMD lanes
//! (`render/kernel/face.rs`, `x86/face.rs`), in a pass of their own, and drawn with the
//! LUT's row kernels; trilinear runs do so on the two pyramid levels of each
//! [`TRILINEAR_RUN_CHUNK`] (the second blended in). Every
//! kernel (AVX-512, AVX2, SSE4.1 or the scalar twin, chosen once per process,
//! `LUTPANO_KERNEL=scalar` forcing the portable one) reads the face's bordered texels
//! with the per-pixel path's rounding, so nearest and bilinear images are byte-identical
//! to the basic renderer's (`tests/cube.rs`). (Until 2026-12-02 bilinear runs were
//! stepped linearly between exact points, within 0.0207 face texels; the separate
//! positions pass is faster and exact: `docs/performance.md`.)

use super::exact::render_exact;
use super::frame::Frame;
use super::kernel::{active, ChunkLevels, ChunkWeights, FaceBuf, FaceRun, Texels};
use super::rows::{rows_per_task, Loan};
use super::setup::check_step;
use super::{RenderOptions, RenderPath, RenderReport};
use crate::cube::pyramid::{footprint, footprint_bound, lod_of, TRILINEAR_RUN_CHUNK};
use crate::cube::{
    check_face_size, face_axes, face_of, face_uv, CubeError, CubeMap, Face, UsageProblem,
};
use crate::error::ViewError;
use crate::geom::camera::View;
use crate::map::envmap::EnvMap;
use crate::map::pyramid::{lod_q8, nearest_level_of, LOD0_FOOTPRINT};
use crate::map::sample::Sampler;
use crate::named::{parse_name, unknown_name, Named};
use glam::DVec3;
use rayon::prelude::*;
use std::mem::take;
use std::ops::Range;

/// Which of the paper's renderers to use. With nearest and bilinear sampling both give
/// byte-identical images (see `render/cube.rs`); with trilinear the scanline renderer
/// takes the level of detail per 16 pixels of a face run, the basic one per pixel
/// (`cube/pyramid.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum CubeRenderer {
    /// Section 1: per pixel, ray → face by the largest |coordinate| → face coordinates.
    Basic,
    /// Section 2: per scanline, face runs by binary search, no face choice inside a run.
    #[default]
    Accelerated,
}

impl CubeRenderer {
    /// Name used on the command line (see [`crate::Named`]): `basic` or `scanline`.
    pub fn name(self) -> &'static str {
        Named::name(self)
    }
}

impl std::str::FromStr for CubeRenderer {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        // The names, and the paper's word for the scanline renderer.
        parse_name(s)
            .or(match s {
                "accelerated" | "accel" => Some(CubeRenderer::Accelerated),
                _ => None,
            })
            .ok_or_else(|| unknown_name::<CubeRenderer>("cube renderer", s))
    }
}

impl Named for CubeRenderer {
    const ALL: &'static [Self] = &[CubeRenderer::Basic, CubeRenderer::Accelerated];
    fn name(self) -> &'static str {
        match self {
            CubeRenderer::Basic => "basic",
            CubeRenderer::Accelerated => "scanline",
        }
    }
    fn help(self) -> &'static str {
        match self {
            CubeRenderer::Basic => "Per pixel: face by the largest coordinate",
            CubeRenderer::Accelerated => "Per scanline: face segments split by binary search",
        }
    }
}

/// Per-frame constants: the rotation's columns and the image geometry.
#[derive(Clone, Copy)]
struct Rays {
    /// Column 0 of R: world direction of image +x (B in the module docs).
    b: DVec3,
    /// Column 1 of R: world direction of image +y (up).
    r1: DVec3,
    /// Column 2 of R: world direction of the view axis.
    r2: DVec3,
    focal: f64,
    w: u32,
    h: u32,
    half_face: f64,
    /// Margin a run's ends must exceed to be trusted (see the module docs).
    delta: f64,
}

impl Rays {
    fn new(view: View, w: u32, h: u32, face_size: u32) -> Rays {
        let focal = (w as f64 / 2.0) / (view.hfov() / 2.0).tan();
        let (sp, cp) = view.pitch().sin_cos();
        let (sy, cy) = view.yaw().sin_cos();
        // R = Ry(yaw) · Rx(pitch) as in `Camera::world_ray`.
        let b = DVec3::new(cy, 0.0, -sy);
        let r1 = DVec3::new(-sp * sy, cp, -sp * cy);
        let r2 = DVec3::new(cp * sy, sp, cp * cy);
        // Ray components are at most |P| + |dx| ≤ f + W + H; their rounding error is a few
        // ulps of that (~1e-15 relative). 1e-9 relative is far above it and far below a
        // pixel's change of margin except within 1e-9 px of an edge.
        let delta = 1e-9 * (focal + w as f64 + h as f64);
        Rays {
            b,
            r1,
            r2,
            focal,
            w,
            h,
            half_face: face_size as f64 / 2.0,
            delta,
        }
    }

    #[inline(always)]
    fn dy(&self, y: usize) -> f64 {
        self.h as f64 / 2.0 - (y as f64 + 0.5)
    }

    #[inline(always)]
    fn dx(&self, x: usize) -> f64 {
        x as f64 + 0.5 - self.w as f64 / 2.0
    }

    /// Row part P = dy · R₁ + f · R₂.
    #[inline(always)]
    fn row(&self, dy: f64) -> DVec3 {
        DVec3::new(
            dy * self.r1.x + self.focal * self.r2.x,
            dy * self.r1.y + self.focal * self.r2.y,
            dy * self.r1.z + self.focal * self.r2.z,
        )
    }
}

/// The ray `P + dx · B`: the one expression both renderers use.
#[inline(always)]
fn ray(p: DVec3, b: DVec3, dx: f64) -> DVec3 {
    DVec3::new(p.x + dx * b.x, p.y + dx * b.y, p.z + dx * b.z)
}

/// A face's bordered texels as the span kernels read them (side n + 1: the (n + 2)²
/// stored texels).
#[inline]
fn face_texels(cube: &CubeMap, face: Face) -> Texels<'_> {
    let side = cube.face_size() + 1;
    Texels::new(cube.bordered_face(face), side, side, false)
        .expect("a cube face holds (n + 2)^2 texels, fewer than 2^31")
}

/// `t` toward the next scanline (`Texels::toward_next_scanline`): how far (face texels
/// of `run`'s face, Q.8, positive: down) the next row's ray meets the face below this
/// run's at its middle pixel (`len` pixels; the next row's rays are this row's minus
/// R₁).
#[inline]
fn toward_next<'a>(
    t: Texels<'a>,
    frame: &Rays,
    face: Face,
    run: &FaceRun,
    len: usize,
) -> Texels<'a> {
    let (_, db, dm) = face_axes(face, frame.r1);
    let dx = run.dx + (len / 2) as f64;
    let v_at = |b: f64, m: f64| -b * (run.half / m);
    let (b, m) = (run.p[1] + dx * run.d[1], run.p[2] + dx * run.d[2]);
    let dv = v_at(b - db, m - dm) - v_at(b, m);
    // (Not finite or huge where the next row leaves the face: then no prefetch.)
    let dv = if dv.is_finite() {
        (dv * 256.0).round().clamp(-1e7, 1e7) as i32
    } else {
        0
    };
    t.toward_next_scanline(dv)
}

/// Texel fetch, monomorphized per sampler so the inner loops do not branch on it.
trait Fetch: Copy + Send + Sync {
    /// The sample of ray `d` on `face` (the face of `d`), per pixel.
    fn fetch(self, cube: &CubeMap, frame: &Rays, face: Face, d: DVec3) -> u32;
    /// A verified run on `face` (`run`: its projective line), with the span kernels
    /// (`buf`: the band's scratch for the runs' positions).
    fn span(
        self,
        cube: &CubeMap,
        frame: &Rays,
        face: Face,
        run: &FaceRun,
        out: &mut [u32],
        buf: &mut FaceBuf,
    );
}

#[derive(Clone, Copy)]
struct NearestFetch;
#[derive(Clone, Copy)]
struct BilinearFetch;
#[derive(Clone, Copy)]
struct TrilinearFetch;
#[derive(Clone, Copy)]
struct RegionFetch;

impl Fetch for NearestFetch {
    #[inline(always)]
    fn fetch(self, cube: &CubeMap, frame: &Rays, face: Face, d: DVec3) -> u32 {
        let (u, v) = face_uv(face, d, frame.half_face);
        cube.nearest(face, u, v)
    }
    #[inline(always)]
    fn span(self, c: &CubeMap, fr: &Rays, f: Face, r: &FaceRun, o: &mut [u32], b: &mut FaceBuf) {
        let t = toward_next(face_texels(c, f), fr, f, r, o.len());
        active().face_rows::<false>(&t, r, o, b)
    }
}

impl Fetch for BilinearFetch {
    #[inline(always)]
    fn fetch(self, cube: &CubeMap, frame: &Rays, face: Face, d: DVec3) -> u32 {
        let (u, v) = face_uv(face, d, frame.half_face);
        cube.bilinear(face, u, v)
    }
    #[inline(always)]
    fn span(self, c: &CubeMap, fr: &Rays, f: Face, r: &FaceRun, o: &mut [u32], b: &mut FaceBuf) {
        let t = toward_next(face_texels(c, f), fr, f, r, o.len());
        active().face_rows::<true>(&t, r, o, b)
    }
}

/// Trilinear on the face pyramid (`cube/pyramid.rs`): per pixel, the level of detail of
/// the pixel's own footprint; on a run, one per [`TRILINEAR_RUN_CHUNK`] pixels (at the
/// chunk's middle pixel). The run's chunks that share their finer level are drawn on it
/// in one go, then those that share their coarser level (and blend it in) are blended
/// in one go (`face_rows`, `face_rows_blend`: the positions pass and the row kernels).
impl Fetch for TrilinearFetch {
    #[inline(always)]
    fn fetch(self, cube: &CubeMap, frame: &Rays, face: Face, d: DVec3) -> u32 {
        let lod = lod_of(face, d, frame.b, frame.r1, frame.half_face);
        cube.trilinear_dir(face, d, lod)
    }

    fn span(
        self,
        cube: &CubeMap,
        frame: &Rays,
        face: Face,
        run: &FaceRun,
        out: &mut [u32],
        buf: &mut FaceBuf,
    ) {
        chunked_span(cube, frame, face, run, out, buf, |f| {
            let lod = lod_q8(f).max(0);
            ((lod >> 8) as usize, (lod & 0xFF) as u32)
        })
    }
}

/// Bilinear with a level per region (`Panorama::set_region_lod`): the pyramid level
/// nearest the footprint (`nearest_level_of`: 0 up to √2, so magnified pixels read the
/// faces as [`BilinearFetch`] does, byte for byte), per pixel or per
/// [`TRILINEAR_RUN_CHUNK`] of a run, read bilinearly with no blend.
impl Fetch for RegionFetch {
    #[inline(always)]
    fn fetch(self, cube: &CubeMap, frame: &Rays, face: Face, d: DVec3) -> u32 {
        let (sx, sy) = (face_axes(face, frame.b), face_axes(face, frame.r1));
        let f = footprint(face_axes(face, d), sx, sy, frame.half_face);
        let (l, _) = cube.level(nearest_level_of(f) as usize);
        let (u, v) = face_uv(face, d, l.face_size() as f64 / 2.0);
        l.bilinear(face, u, v)
    }

    fn span(
        self,
        cube: &CubeMap,
        frame: &Rays,
        face: Face,
        run: &FaceRun,
        out: &mut [u32],
        buf: &mut FaceBuf,
    ) {
        chunked_span(cube, frame, face, run, out, buf, |f| {
            (nearest_level_of(f) as usize, 0)
        })
    }
}

/// A run drawn per [`TRILINEAR_RUN_CHUNK`] on the pyramid levels `level_of` gives each
/// chunk from its middle pixel's footprint: the first level and the second's weight
/// (0..=255; 0 for none), `(0, 0)` at footprints up to √2. The run's chunks that share
/// their first level are drawn on it in one go, then those that share their second
/// level (and blend it in) are blended in one go (`face_rows`, `face_rows_blend`: the
/// positions pass and the row kernels).
fn chunked_span(
    cube: &CubeMap,
    frame: &Rays,
    face: Face,
    run: &FaceRun,
    out: &mut [u32],
    buf: &mut FaceBuf,
    level_of: impl Fn(f64) -> (usize, u32),
) {
    const C: usize = TRILINEAR_RUN_CHUNK;
    let n = out.len();
    // The image's x and y steps on the face's axes (y: −R₁ per row; the sign does not
    // change the footprint).
    let (sx, sy) = (face_axes(face, frame.b), face_axes(face, frame.r1));
    let (mut levels, mut fracs) = (take(&mut buf.levels), take(&mut buf.fracs));
    levels.clear();
    fracs.clear();
    let chunks = n.div_ceil(C);
    levels.reserve(chunks);
    fracs.reserve(chunks);
    // The levels of the last `k` seen (a run's chunks mostly share theirs): the
    // pyramid is looked up when `k` changes, not per chunk.
    let resolve = |k: usize| ChunkLevels {
        first: cube.level(k).1,
        second: cube.level(k + 1).1,
    };
    let (mut last_k, mut last) = (0, resolve(0));
    // Chunk c's middle pixel is c·C + C/2 (the last chunk's: its own middle), a
    // whole number below 2^53 stepped in f64: exact, the same `mid` as
    // `(c * C + C / 2) as f64`.
    let mut off = (C / 2) as f64;
    // Blocks of chunks whose footprint is bounded by √2 (`footprint_bound`) have
    // level of detail 0 at every middle pixel without computing it (a bounded block
    // gets what the exact footprint would give it, so the bytes are the same).
    let mut skip_to = 0;
    for c in 0..chunks {
        if c % LOD_BLOCK == 0 && c + LOD_BLOCK < chunks {
            let ends = (run.dx + off, run.dx + off + ((LOD_BLOCK - 1) * C) as f64);
            let bound = footprint_bound((run.p, run.d), ends, sx, sy, frame.half_face);
            if bound <= LOD0_FOOTPRINT {
                skip_to = c + LOD_BLOCK;
            }
        }
        if c < skip_to {
            off += C as f64;
            if last_k != 0 {
                (last_k, last) = (0, resolve(0));
            }
            levels.push(last);
            fracs.push(0);
            continue;
        }
        let mid = if c + 1 < chunks {
            run.dx + off
        } else {
            run.dx + (c * C + (n - c * C) / 2) as f64
        };
        off += C as f64;
        let at = |i: usize| run.p[i] + mid * run.d[i];
        let (k, frac) = level_of(footprint((at(0), at(1), at(2)), sx, sy, frame.half_face));
        if k != last_k {
            (last_k, last) = (k, resolve(k));
        }
        levels.push(last);
        fracs.push(if last.first == last.second { 0 } else { frac });
    }
    // The run on level `k` from chunk `cs.start` and its pixels.
    let on = |k: usize, cs: &Range<usize>| {
        let (l, _) = cube.level(k);
        let half = l.face_size() as f64 / 2.0;
        let sub = FaceRun {
            half,
            dx: run.dx + (cs.start * C) as f64,
            ..*run
        };
        let px = cs.start * C..(cs.end * C).min(n);
        let t = toward_next(face_texels(l, face), frame, face, &sub, px.len());
        (t, sub, px)
    };
    for (k, cs) in same_runs(levels.len(), |c| Some(levels[c].first)) {
        let (t, sub, px) = on(k, &cs);
        active().face_rows::<true>(&t, &sub, &mut out[px], buf);
    }
    let blended = |c: usize| (fracs[c] != 0).then_some(levels[c].second);
    for (k, cs) in same_runs(levels.len(), blended) {
        let (t, sub, px) = on(k, &cs);
        let w = ChunkWeights {
            chunk: C,
            fracs: &fracs[cs],
        };
        active().face_rows_blend(&t, &sub, &mut out[px], w, buf);
    }
    (buf.levels, buf.fracs) = (levels, fracs);
}

/// A frame of `view` of `cube` with `opts` (the entry is [`crate::Panorama::render`] of a
/// cube): rectilinear views with `opts.cube`, the other output projections per pixel
/// (`projected.rs`).
///
/// # Errors
/// [`ViewError::BadIndexStep`] for an index step not in {1, 2, 4, 8, 16}, as for a map
/// (the step is unused here, but a request is refused alike whatever it draws).
pub(crate) fn cube_frame(
    cube: &CubeMap,
    view: View,
    opts: &RenderOptions,
    frame: &mut Frame<'_>,
    region_lod: bool,
) -> Result<RenderReport, ViewError> {
    check_step(opts.index_step)?;
    let pixels = frame.width() as u64 * frame.height() as u64;
    let path = if view.projection().is_rectilinear() {
        let sampler = match (opts.sampler, region_lod) {
            (Sampler::Bilinear, true) => CubeSampler::Region,
            (s, _) => CubeSampler::Plain(s),
        };
        render_cube(cube, view, sampler, opts.cube, frame, opts.threads);
        RenderPath::Cube(opts.cube)
    } else {
        super::projected::render_cube(cube, view, opts.sampler, frame, opts.threads);
        RenderPath::CubeProjected
    };
    Ok(RenderReport {
        path,
        exact_pixels: 0,
        pixels,
        table_bytes: cube.bytes(),
        max_step: 1,
        min_step: 1,
    })
}

/// Render `view` of `cube` into `frame` with the chosen renderer (the entry is
/// [`cube_frame`]). `threads` splits rows into
/// bands across the rayon pool; the output is identical either way (the renderers differ
/// as [`CubeRenderer`] says; trilinear builds the face pyramid on first use).
pub(crate) fn render_cube(
    cube: &CubeMap,
    view: View,
    sampler: impl Into<CubeSampler>,
    renderer: CubeRenderer,
    frame: &mut Frame<'_>,
    threads: bool,
) {
    let rays = Rays::new(view, frame.width(), frame.height(), cube.face_size());
    let out = frame.pixels_mut();
    match sampler.into() {
        CubeSampler::Plain(Sampler::Nearest) => {
            render_with(cube, &rays, NearestFetch, renderer, out, threads)
        }
        CubeSampler::Plain(Sampler::Bilinear) => {
            render_with(cube, &rays, BilinearFetch, renderer, out, threads)
        }
        CubeSampler::Plain(Sampler::Trilinear) => {
            cube.pyramid(); // built here, not inside a row band
            render_with(cube, &rays, TrilinearFetch, renderer, out, threads)
        }
        CubeSampler::Region => {
            cube.pyramid();
            render_with(cube, &rays, RegionFetch, renderer, out, threads)
        }
    }
}

/// How a cube frame samples: a [`Sampler`], or bilinear on the pyramid level of each
/// region's footprint (`Panorama::set_region_lod`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum CubeSampler {
    Plain(Sampler),
    Region,
}

impl From<Sampler> for CubeSampler {
    fn from(s: Sampler) -> CubeSampler {
        CubeSampler::Plain(s)
    }
}

/// The runs of consecutive items in `0..n` with the same `key` (items whose key is
/// `None` skipped): `(key, items)`.
fn same_runs(
    n: usize,
    key: impl Fn(usize) -> Option<usize>,
) -> impl Iterator<Item = (usize, Range<usize>)> {
    let mut c0 = 0;
    std::iter::from_fn(move || {
        while c0 < n {
            let Some(k) = key(c0) else {
                c0 += 1;
                continue;
            };
            let start = c0;
            c0 += 1;
            while c0 < n && key(c0) == Some(k) {
                c0 += 1;
            }
            return Some((k, start..c0));
        }
        None
    })
}

/// Chunks of a trilinear face run whose level of detail is bounded together
/// (`footprint_bound`) before any is computed.
const LOD_BLOCK: usize = 8;

/// A cube band task's scratch: a scanline's face segments and its runs' position buffers.
type BandScratch = (Vec<Seg>, FaceBuf);

thread_local! {
    /// The scratch a thread's last cube band task gave back (`Loan`).
    static BAND_SCRATCH: std::cell::Cell<Option<Box<BandScratch>>> =
        const { std::cell::Cell::new(None) };
}

fn render_with<S: Fetch>(
    cube: &CubeMap,
    frame: &Rays,
    s: S,
    renderer: CubeRenderer,
    out: &mut [u32],
    threads: bool,
) {
    let w = frame.w as usize;
    // Bands of whole rows, ~16k pixels each so small frames stay on one thread.
    let rows_per_band = rows_per_task(w).clamp(1, frame.h as usize);
    // The scratch (segments, runs' position buffers) is kept by each thread from band to
    // band and frame to frame (`Loan`): made afresh per band, its buffers were allocated
    // and zeroed ~135 times a 1080p frame.
    let scratch = || Loan::take(&BAND_SCRATCH, BandScratch::default);
    let band = |sc: &mut Loan<BandScratch>, (bi, chunk): (usize, &mut [u32])| {
        let (segs, buf) = &mut **sc;
        for (r, line) in chunk.chunks_exact_mut(w).enumerate() {
            let y = bi * rows_per_band + r;
            match renderer {
                CubeRenderer::Basic => basic_row(cube, frame, s, y, line),
                CubeRenderer::Accelerated => accel_row(cube, frame, s, y, line, segs, buf),
            }
        }
    };
    if threads {
        // One band per task, so the threads share the work to the last band
        // (`rows::rows_per_task`).
        out.par_chunks_mut(w * rows_per_band)
            .enumerate()
            .with_max_len(1)
            .for_each_init(scratch, band);
    } else {
        let mut sc = scratch();
        for job in out.chunks_mut(w * rows_per_band).enumerate() {
            band(&mut sc, job);
        }
    }
}

/// The per-pixel kernel over `line[x0..x1]` of row `y`: full ray, face choice, coordinates.
#[inline(always)]
fn per_pixel<S: Fetch>(
    cube: &CubeMap,
    frame: &Rays,
    s: S,
    y: usize,
    line: &mut [u32],
    x0: usize,
    x1: usize,
) {
    let dy = frame.dy(y);
    for (x, px) in line.iter_mut().enumerate().take(x1).skip(x0) {
        // The whole rotation per pixel; bit-identical to the accelerated path's ray.
        let d = ray(frame.row(dy), frame.b, frame.dx(x));
        *px = s.fetch(cube, frame, face_of(d), d);
    }
}

fn basic_row<S: Fetch>(cube: &CubeMap, frame: &Rays, s: S, y: usize, line: &mut [u32]) {
    per_pixel(cube, frame, s, y, line, 0, line.len());
}

/// A run of pixels `[start, end]` (inclusive) guessed to be on one face.
#[derive(Clone, Copy, Debug)]
struct Seg {
    start: usize,
    end: usize,
    face: Face,
}

fn push_seg(segs: &mut Vec<Seg>, start: usize, end: usize, face: Face) {
    if let Some(last) = segs.last_mut() {
        if last.face == face && start <= last.end + 1 {
            last.end = last.end.max(end);
            return;
        }
    }
    segs.push(Seg { start, end, face });
}

/// Binary search for face changes between pixels `lo` and `hi` whose faces are known.
fn split(
    face_at: &impl Fn(usize) -> Face,
    lo: usize,
    hi: usize,
    flo: Face,
    fhi: Face,
    segs: &mut Vec<Seg>,
) {
    if flo == fhi {
        push_seg(segs, lo, hi, flo);
        return;
    }
    if hi <= lo + 1 {
        push_seg(segs, lo, lo, flo);
        push_seg(segs, hi, hi, fhi);
        return;
    }
    let mid = lo + (hi - lo) / 2;
    let fm = face_at(mid);
    split(face_at, lo, mid, flo, fm, segs);
    split(face_at, mid, hi, fm, fhi, segs);
}

/// Concave margin of the face choice (see the module docs): > 0 means strictly this face.
#[inline(always)]
fn margin(face: Face, d: DVec3) -> f64 {
    let (a, b, m) = face_axes(face, d);
    (m - a.abs()).min(m - b.abs())
}

fn accel_row<S: Fetch>(
    cube: &CubeMap,
    frame: &Rays,
    s: S,
    y: usize,
    line: &mut [u32],
    segs: &mut Vec<Seg>,
    buf: &mut FaceBuf,
) {
    let w = line.len();
    let p = frame.row(frame.dy(y));
    let b = frame.b;
    let face_at = |x: usize| face_of(ray(p, b, frame.dx(x)));
    segs.clear();
    split(&face_at, 0, w - 1, face_at(0), face_at(w - 1), segs);
    for seg in segs.iter() {
        let ok = |x: usize| margin(seg.face, ray(p, b, frame.dx(x))) > frame.delta;
        let (mut a, mut e) = (seg.start, seg.end + 1); // half-open [a, e)
                                                       // Peel at most two unproven pixels from each end.
        for _ in 0..2 {
            if a < e && !ok(a) {
                per_pixel(cube, frame, s, y, line, a, a + 1);
                a += 1;
            }
            if a < e && !ok(e - 1) {
                per_pixel(cube, frame, s, y, line, e - 1, e);
                e -= 1;
            }
        }
        if a >= e {
            continue;
        }
        if !(ok(a) && ok(e - 1)) {
            // Degenerate: the scanline runs along an edge. Decide per pixel.
            per_pixel(cube, frame, s, y, line, a, e);
            continue;
        }
        // A verified run: the ray's coordinates on the face's axes are linear in dx,
        // the face coordinates a projective line, evaluated exactly per pixel and drawn
        // by the row kernels (render/kernel/face.rs).
        let (pa, pb, pm) = face_axes(seg.face, p);
        let (ba, bb, bm) = face_axes(seg.face, b);
        let run = FaceRun {
            p: [pa, pb, pm],
            d: [ba, bb, bm],
            dx: frame.dx(a),
            half: frame.half_face,
        };
        s.span(cube, frame, seg.face, &run, &mut line[a..e], buf);
    }
}

/// One run of a row as the accelerated cube renderer splits it ([`scanline_runs`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScanlineRun {
    /// The run's first pixel column.
    pub start: u32,
    /// The column after its last pixel (exclusive).
    pub end: u32,
    /// The cube face its pixels are drawn from.
    pub face: Face,
    /// Whether both ends were proven inside `face` (the run drawn as one face run);
    /// unverified runs (and peeled single pixels) were rendered per pixel.
    pub verified: bool,
}

/// How the accelerated renderer splits row `y` of a `width × height` view: its runs in
/// order. For tests and the docs' statistics.
pub fn scanline_runs(
    view: View,
    width: u32,
    height: u32,
    face_size: u32,
    y: u32,
) -> Vec<ScanlineRun> {
    let frame = Rays::new(view, width, height, face_size);
    let w = width as usize;
    let p = frame.row(frame.dy(y as usize));
    let b = frame.b;
    let face_at = |x: usize| face_of(ray(p, b, frame.dx(x)));
    let mut segs = Vec::new();
    split(&face_at, 0, w - 1, face_at(0), face_at(w - 1), &mut segs);
    let mut out = Vec::new();
    for seg in segs {
        let ok = |x: usize| margin(seg.face, ray(p, b, frame.dx(x))) > frame.delta;
        let (mut a, mut e) = (seg.start, seg.end + 1);
        let mut tail = Vec::new();
        let pixel = |x: usize| ScanlineRun {
            start: x as u32,
            end: x as u32 + 1,
            face: face_at(x),
            verified: false,
        };
        for _ in 0..2 {
            if a < e && !ok(a) {
                out.push(pixel(a));
                a += 1;
            }
            if a < e && !ok(e - 1) {
                tail.push(pixel(e - 1));
                e -= 1;
            }
        }
        if a < e {
            out.push(ScanlineRun {
                start: a as u32,
                end: e as u32,
                face: seg.face,
                verified: ok(a) && ok(e - 1),
            });
        }
        out.extend(tail.into_iter().rev());
    }
    out
}

impl CubeMap {
    /// Render a cube map from a panorama: each face is the exact renderer's hfov-90° view
    /// at the face's yaw/pitch (the definition in `docs/conventions.md`).
    ///
    /// # Errors
    /// [`CubeError::FaceSize`] for a bad `face_size`.
    pub fn from_envmap(
        map: &EnvMap,
        face_size: u32,
        sampler: Sampler,
    ) -> Result<CubeMap, CubeError> {
        check_face_size("cube map", face_size)?;
        let n = face_size as usize;
        let mut faces: [Vec<u32>; 6] = Default::default();
        for (k, face) in Face::ALL.iter().enumerate() {
            let mut buf = vec![0u32; n * n];
            let mut frame = Frame::new(&mut buf, face_size, face_size).map_err(|e| {
                CubeError::Usage(UsageProblem::FaceRender {
                    face: *face,
                    error: e,
                })
            })?;
            render_exact(map, face.view(), sampler, &mut frame, true);
            faces[k] = buf;
        }
        let refs: [&[u32]; 6] = std::array::from_fn(|k| faces[k].as_slice());
        CubeMap::from_faces(face_size, refs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cube of `n`² faces of hashed noise.
    fn noise_cube(n: u32) -> CubeMap {
        let faces: Vec<Vec<u32>> = (0..6u32)
            .map(|k| {
                (0..n * n)
                    .map(|i| {
                        let mut h = (i + 1).wrapping_mul(2_654_435_761) ^ ((k + 7) * 40_503);
                        h ^= h >> 15;
                        h = h.wrapping_mul(2_246_822_519);
                        (h ^ (h >> 13)) & 0x00FF_FFFF
                    })
                    .collect()
            })
            .collect();
        let refs: [&[u32]; 6] = std::array::from_fn(|k| faces[k].as_slice());
        CubeMap::from_faces(n, refs).unwrap()
    }

    #[test]
    fn trilinear_runs_take_each_chunks_exact_level_of_detail() {
        // Every pixel of a scanline trilinear frame is `trilinear_dir` with the level of
        // detail of its chunk's middle pixel computed exactly (verified runs; the
        // per-pixel one elsewhere), whether or not the renderer skipped the chunk's
        // level in a block bounded below √2: the bytes the renderer gave before blocks
        // were skipped. The views mix blocks that are skipped and chunks that blend.
        // The level per region likewise: bilinear on the level nearest that footprint.
        const C: usize = TRILINEAR_RUN_CHUNK;
        let cube = noise_cube(256);
        cube.pyramid();
        let (w, h) = (400u32, 160u32);
        let (mut skipped, mut blended) = (0, 0);
        let views = [
            (37.3, 0.0, 90.0),
            (10.0, 30.0, 120.0),
            (-140.0, -50.0, 100.0),
        ];
        for (yaw, pitch, hfov) in views {
            let view = View::new(yaw, pitch, hfov).unwrap();
            let mut px = vec![0u32; (w * h) as usize];
            let mut frame = Frame::new(&mut px, w, h).unwrap();
            render_cube(
                &cube,
                view,
                Sampler::Trilinear,
                CubeRenderer::Accelerated,
                &mut frame,
                false,
            );
            // The level per region: bilinear on the nearest level of the same footprint.
            let mut region = vec![0u32; (w * h) as usize];
            let mut rf = Frame::new(&mut region, w, h).unwrap();
            let (r, a) = (CubeSampler::Region, CubeRenderer::Accelerated);
            render_cube(&cube, view, r, a, &mut rf, false);
            let rays = Rays::new(view, w, h, cube.face_size());
            let half = rays.half_face;
            for y in 0..h as usize {
                let p = rays.row(rays.dy(y));
                for r in scanline_runs(view, w, h, cube.face_size(), y as u32) {
                    let face = r.face;
                    let (sx, sy) = (face_axes(face, rays.b), face_axes(face, rays.r1));
                    let (s, n) = (r.start as usize, (r.end - r.start) as usize);
                    for x in s..s + n {
                        let d = ray(p, rays.b, rays.dx(x));
                        let f = if r.verified {
                            let c = (x - s) / C;
                            let mid = rays.dx(s) + (c * C + C.min(n - c * C) / 2) as f64;
                            footprint(face_axes(face, ray(p, rays.b, mid)), sx, sy, half)
                        } else {
                            footprint(face_axes(face, d), sx, sy, half)
                        };
                        let lod = lod_q8(f);
                        let want = cube.trilinear_dir(face, d, lod);
                        let got = px[y * w as usize + x];
                        assert_eq!(got, want, "{view:?} ({x}, {y}) lod {lod}");
                        let (l, _) = cube.level(nearest_level_of(f) as usize);
                        let (u, v) = face_uv(face, d, l.face_size() as f64 / 2.0);
                        let want = l.bilinear(face, u, v);
                        let got = region[y * w as usize + x];
                        assert_eq!(got, want, "region {view:?} ({x}, {y}) footprint {f}");
                    }
                    // What the renderer's blocks did on this run.
                    let chunks = n.div_ceil(C);
                    for c0 in (0..chunks).step_by(super::LOD_BLOCK) {
                        if !r.verified || c0 + super::LOD_BLOCK >= chunks {
                            continue;
                        }
                        let mid = |c: usize| rays.dx(s) + (c * C + C / 2) as f64;
                        let (pa, pb, pm) = face_axes(face, p);
                        let (ba, bb, bm) = face_axes(face, rays.b);
                        let ends = (mid(c0), mid(c0 + super::LOD_BLOCK - 1));
                        let run = ([pa, pb, pm], [ba, bb, bm]);
                        if footprint_bound(run, ends, sx, sy, half) <= LOD0_FOOTPRINT {
                            skipped += 1;
                        }
                    }
                    blended += (0..chunks)
                        .filter(|&c| {
                            let mid = rays.dx(s) + (c * C + C.min(n - c * C) / 2) as f64;
                            let at = face_axes(face, ray(p, rays.b, mid));
                            r.verified && lod_q8(footprint(at, sx, sy, half)) > 0
                        })
                        .count();
                }
            }
        }
        assert!(
            skipped > 100 && blended > 100,
            "{skipped} blocks skipped, {blended} chunks blended"
        );
    }

    #[test]
    fn same_runs_groups_consecutive_keys_and_skips_none() {
        let keys = [
            Some(1),
            Some(1),
            None,
            Some(1),
            Some(2),
            Some(2),
            None,
            None,
            Some(0),
        ];
        let runs: Vec<_> = same_runs(keys.len(), |c| keys[c]).collect();
        assert_eq!(runs, vec![(1, 0..2), (1, 3..4), (2, 4..6), (0, 8..9)]);
        assert_eq!(same_runs(0, |_| Some(0)).count(), 0);
        assert_eq!(same_runs(3, |_| None).count(), 0);
    }
}
