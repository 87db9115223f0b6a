//! The lit panorama: the panorama's texels lit once per lighting change, so a pan of a lit
//! room is an ordinary (unlit) frame of the lit copy (docs/lights.md, "Lighting at frame
//! rate").
//!
//! Neither the illuminance nor the lit colour (albedo · (ambient + exposure · E), or the
//! false-colour blend) depends on the view. [`IlluminanceMap::bake_map`] and
//! [`IlluminanceMap::bake_cube`] light every stored texel of a panorama: its direction by
//! the panorama's own mapping (equirectangular and the other projections of revolution,
//! partial maps in their place in the full panorama, the six faces of a cube map), the
//! ray/box hit and E from the illuminance map — probed at the corners of blocks of
//! [`super::MAP_SHADE_BLOCK`] texels and interpolated, split where a room edge crosses
//! a block or E curves (`map_shade.rs`, the code that lights frames) — then the colour
//! by the shading table's rows (`shade_table.rs`). Bands of rows run in parallel; the
//! bytes do not depend on the number of threads.
//!
//! Only the base level is lit; the lit copy's pyramid (trilinear, and the level a moving
//! window frame reads) is the ordinary 2×2 average of the lit texels, built when the
//! source's pyramid has been built (else on first use), with its levels' own pyramids
//! (`crate::build_frame_levels`: zoomed-out still frames are drawn from a level). That is the box filter of the
//! lit picture itself: a coarse texel straddling a room edge averages each side's own
//! light, where lighting the averaged albedo with E at the texel's centre would put one
//! face's light on both; and averaging costs a fraction of lighting.
//!
//! Memory: the lit copy is as large as the map (4 bytes per texel, padding included)
//! plus its pyramid (a third more). [`BAKE_MAX_BYTES`] bounds it; larger panoramas keep
//! lighting each frame ([`IlluminanceMap::frame_shader`]).

use super::illum::IlluminanceMap;
use super::map_shade::{colour_band, Probe, ProbeGrid, Rays, BLOCK};
use super::room::Room;
use super::shade::ShadeOptions;
use super::shade_table::ShadeRow;
use super::LightError;
use crate::cube::{face_dir, CubeMap, Face};
use crate::geom::camera::lat_long_to_dir;
use crate::geom::projection::Projection;
use crate::map::envmap::EnvMap;
use crate::panorama::Panorama;
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::sync::atomic::{AtomicBool, Ordering};

/// The most memory a lit copy (with its pyramid) may take: 192 MiB, which holds an
/// 8192 × 4096 map (128 MiB) and its pyramid (43 MiB), or a cube of 2048-texel faces
/// (96 MiB + 32 MiB). An 8192 × 4096 panorama is what today's 360° cameras and most
/// stitched panoramas deliver; beyond it the copy would double a memory use that is
/// already over half a gigabyte, and its bake (growing with the texels) would take
/// several hundred milliseconds.
pub const BAKE_MAX_BYTES: usize = 192 << 20;

/// The bytes a lit copy of `map` takes, its pyramids included: about a third more for
/// its pyramid and, for a full panorama, a ninth more for its levels' own pyramids
/// (`crate::build_frame_levels`: still frames drawn from a level); a partial map's levels
/// keep the texels its crop reaches, also about a third of its stored pixels, plus a row
/// or column per level at the edges.
pub fn lit_map_bytes(map: &EnvMap) -> usize {
    let base = map.bytes();
    let levels = if map.crop().is_some() { 0 } else { base / 9 };
    base + base / 3 + levels
}

/// The bytes a lit copy of `cube` takes, its pyramid included.
pub fn lit_cube_bytes(cube: &CubeMap) -> usize {
    let base = cube.bytes();
    base + base / 3
}

/// The bytes a lit copy of `pano` takes, its pyramids included ([`lit_map_bytes`],
/// [`lit_cube_bytes`]).
pub fn lit_panorama_bytes(pano: &Panorama) -> usize {
    pano.with_pixels(lit_map_bytes, lit_cube_bytes)
}

fn check_budget(bytes: usize) -> Result<(), LightError> {
    if bytes > BAKE_MAX_BYTES {
        return Err(LightError::BakeTooLarge {
            bytes,
            max: BAKE_MAX_BYTES,
        });
    }
    Ok(())
}

/// [`LightError::Cancelled`] when `cancel` is set (some bands were then skipped).
fn cancelled(cancel: &AtomicBool) -> Result<(), LightError> {
    if cancel.load(Ordering::Relaxed) {
        return Err(LightError::Cancelled);
    }
    Ok(())
}

/// The texels of a map of revolution: the direction through texel centre (x + ½, y + ½)
/// of the stored pixels, placed at (left, top) in the full panorama.
struct MapTexels {
    room: Room,
    projection: Projection,
    /// The full panorama's size.
    w: f64,
    h: f64,
    /// Where the stored pixels start in it (a partial map's crop).
    left: f64,
    top: f64,
}

impl MapTexels {
    fn new(room: Room, map: &EnvMap) -> MapTexels {
        let (left, top) = map
            .crop()
            .map_or((0.0, 0.0), |c| (c.left() as f64, c.top() as f64));
        MapTexels {
            room,
            projection: map.projection(),
            w: map.width() as f64,
            h: map.height() as f64,
            left,
            top,
        }
    }

    /// The world direction of full-panorama position (u, v). Equirectangular: the
    /// analytic inverse, continued smoothly past the edges (a block's far corner may lie
    /// one texel beyond them). The other projections: positions clamped into the image
    /// and into the row's extent (texels outside an ellipse or diamond take the light of
    /// the row's end, as the samplers read it).
    fn dir(&self, u: f64, v: f64) -> DVec3 {
        let (w, h) = (self.w, self.h);
        if self.projection == Projection::Equirect {
            return lat_long_to_dir(u / w * TAU - PI, FRAC_PI_2 - v / h * PI);
        }
        let p = self.projection;
        let (u, v) = (u.clamp(0.0, w), v.clamp(0.0, h));
        let (lambda, phi) = p.direction(u, v, w, h).unwrap_or_else(|| {
            let half = p.row_scale_at_v(v, h) * w * 0.5;
            let u = u.clamp(w * 0.5 - half, w * 0.5 + half);
            p.direction(u, v, w, h).unwrap_or((0.0, 0.0))
        });
        lat_long_to_dir(lambda, phi)
    }
}

impl ProbeGrid for MapTexels {
    #[inline]
    fn probe(&self, map: &IlluminanceMap, x: usize, y: usize) -> Probe {
        let d = self.dir(self.left + x as f64 + 0.5, self.top + y as f64 + 0.5);
        map.probe(self.room.to_room(d))
    }
}

impl IlluminanceMap {
    /// Light `rows` (whole rows of `stride` pixels, the first `w` of each lit; the
    /// image's row `y0` first) from `src` (the same rows of the unlit image) with the
    /// probes of `grid`: the lux of each block row in `buf`, then the colour.
    #[allow(clippy::too_many_arguments)]
    fn bake_rows<G: ProbeGrid>(
        &self,
        grid: &G,
        colour: ShadeRow,
        opts: &ShadeOptions,
        (w, stride): (usize, usize),
        y0: usize,
        src: &[u32],
        rows: &mut [u32],
        buf: &mut Vec<f32>,
    ) {
        let n = rows.len() / stride;
        buf.resize(w * n, 0.0);
        self.band_lux(grid, w, y0, &mut buf[..w * n]);
        for j in 0..n {
            let dst = &mut rows[j * stride..j * stride + w];
            dst.copy_from_slice(&src[j * stride..j * stride + w]);
            colour_band(colour, opts, dst, &buf[j * w..(j + 1) * w]);
        }
    }

    /// The lit copy of `map` (every stored texel lit as `opts` says, see the module docs):
    /// a map like `map` (size, projection, crop, background) whose ordinary frames are
    /// the lit room. Its pyramid is built here when `map`'s has been.
    ///
    /// # Errors
    /// [`LightError::BadOption`] as [`ShadeOptions::check`];
    /// [`LightError::BakeTooLarge`] when the copy would take more than
    /// [`BAKE_MAX_BYTES`] ([`lit_map_bytes`]).
    pub fn bake_map(&self, map: &EnvMap, opts: &ShadeOptions) -> Result<EnvMap, LightError> {
        self.bake_map_cancellable(map, opts, &AtomicBool::new(false))
    }

    /// [`IlluminanceMap::bake_map`], stopped when `cancel` is set: each band of rows
    /// checks it before it starts, so a cancelled bake ends within one band per thread
    /// (the window cancels a bake whose lighting has changed).
    ///
    /// # Errors
    /// As [`IlluminanceMap::bake_map`]; [`LightError::Cancelled`] when `cancel` was set.
    pub fn bake_map_cancellable(
        &self,
        map: &EnvMap,
        opts: &ShadeOptions,
        cancel: &AtomicBool,
    ) -> Result<EnvMap, LightError> {
        opts.check()?;
        check_budget(lit_map_bytes(map))?;
        let grid = MapTexels::new(*self.room(), map);
        let colour = ShadeRow::active();
        let (src, stride) = map.padded();
        let (w, h) = (map.stored_width() as usize, map.stored_height() as usize);
        let mut data = vec![0u32; src.len()];
        let (body, pad) = data.split_at_mut(stride * h);
        let band = stride * BLOCK.1;
        body.par_chunks_mut(band)
            .enumerate()
            .for_each_init(Vec::new, |buf, (i, rows)| {
                if cancel.load(Ordering::Relaxed) {
                    return;
                }
                let src = &src[i * band..i * band + rows.len()];
                self.bake_rows(
                    &grid,
                    colour,
                    opts,
                    (w, stride),
                    i * BLOCK.1,
                    src,
                    rows,
                    buf,
                );
            });
        // The padding: column w repeats column 0 (360°) or w − 1, row h repeats h − 1.
        let wrap = map.pads_by_wrapping();
        for row in body.chunks_mut(stride) {
            row[w] = if wrap { row[0] } else { row[w - 1] };
        }
        pad.copy_from_slice(&body[(h - 1) * stride..]);
        cancelled(cancel)?;
        let lit = map.with_padded(data);
        if map.pyramid_bytes() > 0 {
            crate::render::build_frame_levels(&lit);
        }
        Ok(lit)
    }

    /// The lit copy of `pano`, a panorama of the same kind and geometry sharing its
    /// tables ([`IlluminanceMap::bake_map`] or [`IlluminanceMap::bake_cube`]), stopped
    /// when `cancel` is set (checked before each band of rows).
    ///
    /// # Errors
    /// As [`IlluminanceMap::bake_map_cancellable`] ([`lit_panorama_bytes`]).
    pub fn bake_panorama(
        &self,
        pano: &Panorama,
        opts: &ShadeOptions,
        cancel: &AtomicBool,
    ) -> Result<Panorama, LightError> {
        pano.try_derive(
            |map| self.bake_map_cancellable(map, opts, cancel),
            |cube| self.bake_cube_cancellable(cube, opts, cancel),
        )
    }

    /// The lit copy of `cube` (every face texel lit as `opts` says, see the module docs;
    /// each face's border from its lit neighbours, as [`CubeMap::from_faces`] makes it).
    /// Its pyramid is built here when `cube`'s has been.
    ///
    /// # Errors
    /// As [`IlluminanceMap::bake_map`] ([`lit_cube_bytes`]).
    pub fn bake_cube(&self, cube: &CubeMap, opts: &ShadeOptions) -> Result<CubeMap, LightError> {
        self.bake_cube_cancellable(cube, opts, &AtomicBool::new(false))
    }

    /// [`IlluminanceMap::bake_cube`], stopped when `cancel` is set (checked before each
    /// band of rows, as [`IlluminanceMap::bake_map_cancellable`] does).
    ///
    /// # Errors
    /// As [`IlluminanceMap::bake_cube`]; [`LightError::Cancelled`] when `cancel` was set.
    pub fn bake_cube_cancellable(
        &self,
        cube: &CubeMap,
        opts: &ShadeOptions,
        cancel: &AtomicBool,
    ) -> Result<CubeMap, LightError> {
        opts.check()?;
        check_budget(lit_cube_bytes(cube))?;
        let colour = ShadeRow::active();
        let n = cube.face_size() as usize;
        let half = n as f64 / 2.0;
        let room = *self.room();
        let mut faces: [Vec<u32>; 6] = std::array::from_fn(|_| vec![0u32; n * n]);
        faces.par_iter_mut().enumerate().for_each(|(k, out)| {
            let face = Face::ALL[k];
            // Texel centre (X, Y) of the face looks along face_dir(face, X/half − 1,
            // 1 − Y/half): linear in both, as a camera's rays are.
            let a = room.to_room(face_dir(face, -1.0, 1.0));
            let grid = Rays::linear(
                a,
                room.to_room(face_dir(face, -1.0 + 1.0 / half, 1.0)) - a,
                room.to_room(face_dir(face, -1.0, 1.0 - 1.0 / half)) - a,
            );
            let src = cube.face_pixels(face);
            let band = n * BLOCK.1;
            out.par_chunks_mut(band)
                .enumerate()
                .for_each_init(Vec::new, |buf, (i, rows)| {
                    if cancel.load(Ordering::Relaxed) {
                        return;
                    }
                    let src = &src[i * band..i * band + rows.len()];
                    self.bake_rows(&grid, colour, opts, (n, n), i * BLOCK.1, src, rows, buf);
                });
        });
        cancelled(cancel)?;
        let refs: [&[u32]; 6] = std::array::from_fn(|k| faces[k].as_slice());
        let lit = CubeMap::from_faces(cube.face_size(), refs).map_err(|e| {
            // Cannot happen: the faces have the source's (valid) size.
            LightError::Inconsistent {
                file: e.to_string(),
                expected: "faces of the source cube's size",
            }
        })?;
        if cube.pyramid_bytes() > 0 {
            lit.pyramid();
        }
        Ok(lit)
    }
}
