//! Lighting a frame from the [`IlluminanceMap`]: what the window does every frame.
//!
//! The camera ray is linear in the pixel coordinates, so the illuminance over the image
//! is evaluated at the corners of blocks of [`BLOCK`] pixels (exact ray/box intersection,
//! then the map's bilinear value) and interpolated bilinearly between them. A block is
//! split in four (two when it is one pixel wide or high), recursively, when its corners
//! lie on different faces (a room edge crosses it: the recursion follows the edge down
//! to single pixels, each taking the face its own ray hits, exactly as the per-pixel path
//! does) or further apart on the face than the map allows there (`Tile::max_len`: E
//! curves too much for a straight line over that distance, near a light or a cut-off, or
//! the view grazes the face). So a frame costs a few map lookups per block, whatever the
//! number of lights, plus one table read per channel (`shade_table`: within a level of
//! the exact path's linear-light multiply).
//!
//! The same blocks light the texels of a panorama once per lighting change (`bake.rs`):
//! the block corners are then texels, whose directions come from the panorama's mapping
//! instead of a camera ([`ProbeGrid`]).

use super::illum::IlluminanceMap;
use super::shade::{
    blend, check_frame, decode_lut, encode_lut, false_color, false_color_position, shade_pixel,
    ShadeOptions,
};
use super::shade_table::ShadeRow;
use super::LightError;
use crate::geom::camera::Camera;
use glam::DVec3;
use rayon::prelude::*;

/// The illuminance seen at one pixel.
#[derive(Clone, Copy)]
pub(crate) struct Probe {
    face: usize,
    /// The hit point relative to the camera.
    p: DVec3,
    e: f32,
    /// The tile's [`super::illum::Tile::max_len`].
    max_len: f32,
}

/// 0, 1, 2, … as f32, for filling a block (vectorizes, unlike a counter converted per
/// pixel).
const RAMP: [f32; BLOCK.0] = {
    let mut r = [0f32; BLOCK.0];
    let mut i = 0;
    while i < BLOCK.0 {
        r[i] = i as f32;
        i += 1;
    }
    r
};

/// Block size (columns, rows) between evaluations of the map, before splitting.
pub const BLOCK: (usize, usize) = (32, 16);

/// Where the pixels of an image (a frame, or a panorama's texels) look: the map's probe
/// at pixel (x, y), through its centre (x + ½, y + ½); x and y may be one past the image
/// (a block's far corner). [`IlluminanceMap::fill`] interpolates between these.
pub(crate) trait ProbeGrid {
    /// The probe at pixel (x, y).
    fn probe(&self, map: &IlluminanceMap, x: usize, y: usize) -> Probe;
}

/// The camera rays of one frame in the room's frame: the ray through pixel centre
/// (x + ½, y + ½) is `a + b·(x + ½) + c·(y + ½)` (linear in both, as the camera's is, and
/// as a cube face's texels are).
pub(crate) struct Rays {
    a: DVec3,
    b: DVec3,
    c: DVec3,
}

impl Rays {
    fn new(map: &IlluminanceMap, cam: &Camera) -> Rays {
        let room = map.room();
        let a = room.to_room(cam.world_ray(0.0, 0.0));
        Rays {
            a,
            b: room.to_room(cam.world_ray(1.0, 0.0)) - a,
            c: room.to_room(cam.world_ray(0.0, 1.0)) - a,
        }
    }

    /// The rays `a + b·x + c·y` at image point (x, y) (room frame).
    pub(crate) fn linear(a: DVec3, b: DVec3, c: DVec3) -> Rays {
        Rays { a, b, c }
    }
}

impl ProbeGrid for Rays {
    #[inline]
    fn probe(&self, map: &IlluminanceMap, x: usize, y: usize) -> Probe {
        map.probe(self.a + self.b * (x as f64 + 0.5) + self.c * (y as f64 + 0.5))
    }
}

/// [`super::RoomFace::index`] of the face on axis `a` at its low (0) or high (1) end.
const FACE_ON_AXIS: [[usize; 2]; 3] = [[2, 3], [0, 1], [4, 5]];

impl IlluminanceMap {
    /// The map's illuminance along the camera ray `d` (room frame): the exact ray/box
    /// intersection of [`super::Room::hit_face`] (same arithmetic, same ties), then the
    /// face's bilinear value.
    #[inline]
    pub(crate) fn probe(&self, d: DVec3) -> Probe {
        // Per axis, the plane ahead: the high one for a positive (or +0) component. The
        // camera is strictly inside, so a zero component gives +∞, never NaN.
        let pick = |c: f64, lo: f64, hi: f64| {
            if c.is_sign_positive() {
                (hi / c, 1)
            } else {
                (lo / c, 0)
            }
        };
        let (tx, hx) = pick(d.x, self.rel_lo.x, self.rel_hi.x);
        let (ty, hy) = pick(d.y, self.rel_lo.y, self.rel_hi.y);
        let (tz, hz) = pick(d.z, self.rel_lo.z, self.rel_hi.z);
        let (t, face) = if tx <= ty && tx <= tz {
            (tx, FACE_ON_AXIS[0][hx])
        } else if ty <= tz {
            (ty, FACE_ON_AXIS[1][hy])
        } else {
            (tz, FACE_ON_AXIS[2][hz])
        };
        let f = &self.faces[face];
        let p = d * t;
        let (e, max_len) = f.sample(&self.values, p[f.u_axis] - f.u0_rel, p[f.v_axis] - f.v0_rel);
        Probe {
            face,
            p,
            e,
            max_len,
        }
    }

    /// Fill the block of columns x0 .. x1 − 1 and rows y0 .. y1 − 1 of `out` given the
    /// probes at its
    /// corners (x1, y1 may be one past the image): bilinear between them when all four lie
    /// on one face within the tiles' `max_len` of each other, else split in four (or two),
    /// down to single pixels, which take their own probe.
    fn fill<G: ProbeGrid>(
        &self,
        rays: &G,
        (x0, y0, x1, y1): (usize, usize, usize, usize),
        [tl, tr, bl, br]: [Probe; 4],
        out: &mut Lux<'_>,
    ) {
        let (nx, ny) = (x1 - x0, y1 - y0);
        if nx == 1 && ny == 1 {
            let at = out.at(x0, y0);
            out.es[at] = tl.e;
            return;
        }
        let len = tl.max_len.min(tr.max_len).min(bl.max_len).min(br.max_len) as f64;
        let same = tl.face == tr.face && tl.face == bl.face && tl.face == br.face;
        if same
            && (tl.p - br.p).length_squared() <= len * len
            && (tr.p - bl.p).length_squared() <= len * len
        {
            // Bilinear: each row linear between its two ends.
            let (dl, dr) = ((bl.e - tl.e) / ny as f32, (br.e - tr.e) / ny as f32);
            for (j, &fj) in RAMP[..ny].iter().enumerate() {
                let (l, r) = (tl.e + dl * fj, tr.e + dr * fj);
                let step = (r - l) / nx as f32;
                let at = out.at(x0, y0 + j);
                let row = &mut out.es[at..][..nx];
                for (e, &i) in row.iter_mut().zip(RAMP.iter()) {
                    *e = l + step * i;
                }
            }
            return;
        }
        if nx <= 2 && ny <= 2 {
            // Pixels of their own: one probe each (the top-left one is known).
            for j in 0..ny {
                for i in 0..nx {
                    let e = match (i, j) {
                        (0, 0) => tl.e,
                        _ => rays.probe(self, x0 + i, y0 + j).e,
                    };
                    let k = out.at(x0 + i, y0 + j);
                    out.es[k] = e;
                }
            }
            return;
        }
        let (xm, ym) = (x0 + nx / 2, y0 + ny / 2);
        if ny == 1 {
            let (t, b) = (rays.probe(self, xm, y0), rays.probe(self, xm, y1));
            self.fill(rays, (x0, y0, xm, y1), [tl, t, bl, b], out);
            self.fill(rays, (xm, y0, x1, y1), [t, tr, b, br], out);
        } else if nx == 1 {
            let (l, r) = (rays.probe(self, x0, ym), rays.probe(self, x1, ym));
            self.fill(rays, (x0, y0, x1, ym), [tl, tr, l, r], out);
            self.fill(rays, (x0, ym, x1, y1), [l, r, bl, br], out);
        } else {
            let t = rays.probe(self, xm, y0);
            let b = rays.probe(self, xm, y1);
            let l = rays.probe(self, x0, ym);
            let r = rays.probe(self, x1, ym);
            let m = rays.probe(self, xm, ym);
            self.fill(rays, (x0, y0, xm, ym), [tl, t, l, m], out);
            self.fill(rays, (xm, y0, x1, ym), [t, tr, m, r], out);
            self.fill(rays, (x0, ym, xm, y1), [l, m, bl, b], out);
            self.fill(rays, (xm, ym, x1, y1), [m, r, b, br], out);
        }
    }

    /// The illuminance of the band of rows starting at `band_y` (`es` holds whole rows of
    /// `w` values, at most [`BLOCK`]`.1` of them), block by block.
    pub(crate) fn band_lux<G: ProbeGrid>(&self, rays: &G, w: usize, band_y: usize, es: &mut [f32]) {
        let rows = es.len() / w;
        debug_assert!(rows <= BLOCK.1);
        let y1 = band_y + rows;
        let mut x0 = 0;
        let mut l = [rays.probe(self, 0, band_y), rays.probe(self, 0, y1)];
        let mut out = Lux {
            es,
            stride: w,
            y0: band_y,
        };
        while x0 < w {
            let x1 = (x0 + BLOCK.0).min(w);
            let r = [rays.probe(self, x1, band_y), rays.probe(self, x1, y1)];
            self.fill(
                rays,
                (x0, band_y, x1, y1),
                [l[0], r[0], l[1], r[1]],
                &mut out,
            );
            (x0, l) = (x1, r);
        }
    }

    /// The map's illuminance at pixel (x, y) of `cam`'s image through its own ray (any
    /// view projection); `None` where the projection has no direction.
    #[inline]
    fn pixel_lux(&self, cam: &Camera, x: usize, y: usize) -> Option<f32> {
        let d = cam.ray(x as f64 + 0.5, y as f64 + 0.5)?;
        Some(self.probe(self.room().to_room(d)).e)
    }

    /// The illuminance in lux (lights only) the map gives each pixel of `cam`'s image,
    /// row by row, as [`IlluminanceMap::shade_frame`] uses it (for tests, and exports).
    /// Rectilinear views interpolate it over blocks (see the module docs); the other view
    /// projections (not linear in the pixel coordinates) probe the map at every pixel,
    /// NaN where the projection has no direction (outside a fisheye's disc).
    ///
    /// # Errors
    /// [`LightError::BufferSize`] when `out` does not hold the camera's pixels.
    pub fn lux_frame(&self, cam: &Camera, out: &mut [f32]) -> Result<(), LightError> {
        let (w, h) = (cam.width as usize, cam.height as usize);
        if out.len() != w * h {
            return Err(LightError::BufferSize {
                len: out.len(),
                width: cam.width,
                height: cam.height,
                needed: w * h,
            });
        }
        if w == 0 {
            return Ok(());
        }
        if !cam.projection().is_rectilinear() {
            out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
                for (x, e) in row.iter_mut().enumerate() {
                    *e = self.pixel_lux(cam, x, y).unwrap_or(f32::NAN);
                }
            });
            return Ok(());
        }
        let rays = Rays::new(self, cam);
        out.par_chunks_mut(w * BLOCK.1)
            .enumerate()
            .for_each(|(band, es)| self.band_lux(&rays, w, band * BLOCK.1, es));
        Ok(())
    }

    /// A shader of `cam`'s frames (`cam.width × cam.height` pixels) lit from this map with
    /// `opts`, band by band ([`FrameShader::shade_band`]): what
    /// [`IlluminanceMap::shade_frame`] runs over a rendered frame, and what a renderer's
    /// [`crate::BandHook`] runs on each band as soon as it is drawn
    /// ([`crate::Renderer::render_with`]).
    ///
    /// # Errors
    /// [`LightError::BadOption`] as [`ShadeOptions::check`].
    pub fn frame_shader<'a>(
        &'a self,
        cam: &'a Camera,
        opts: &ShadeOptions,
    ) -> Result<FrameShader<'a>, LightError> {
        opts.check()?;
        Ok(FrameShader {
            map: self,
            cam,
            rays: cam
                .projection()
                .is_rectilinear()
                .then(|| Rays::new(self, cam)),
            opts: *opts,
            colour: ShadeRow::active(),
        })
    }

    /// Light a rendered frame in place from the map, as [`super::shade_frame`] does from
    /// the luminaires: each pixel's colour is the albedo of the room surface its camera ray
    /// hits, times ambient + exposure · E, in linear light. Rows run in parallel; the
    /// result does not depend on the number of threads. The same as rendering with
    /// [`IlluminanceMap::frame_shader`]'s [`FrameShader::shade_band`] as the band hook,
    /// which saves this second pass over the frame.
    ///
    /// # Errors
    /// As [`super::shade_frame`].
    pub fn shade_frame(
        &self,
        cam: &Camera,
        frame: &mut [u32],
        w: u32,
        h: u32,
        opts: &ShadeOptions,
    ) -> Result<(), LightError> {
        check_frame(cam, frame, w, h)?;
        let shader = self.frame_shader(cam, opts)?;
        if frame.is_empty() {
            return Ok(());
        }
        frame
            .par_chunks_mut(w as usize * BLOCK.1)
            .enumerate()
            .for_each(|(band, pixels)| shader.shade_band(band * BLOCK.1, pixels));
        Ok(())
    }
}

/// Lights the bands of one camera's frames from an [`IlluminanceMap`]
/// ([`IlluminanceMap::frame_shader`]).
pub struct FrameShader<'a> {
    map: &'a IlluminanceMap,
    cam: &'a Camera,
    /// The camera rays (rectilinear views only: the others probe every pixel).
    rays: Option<Rays>,
    opts: ShadeOptions,
    colour: ShadeRow,
}

impl FrameShader<'_> {
    /// The frame size (width, height) it lights: its camera's.
    pub fn size(&self) -> (u32, u32) {
        (self.cam.width, self.cam.height)
    }

    /// Light the rows `y0 ..` of the frame held in `rows` (whole rows of the camera's
    /// width; rows past the camera's height are left alone), in place, exactly as
    /// [`IlluminanceMap::shade_frame`] lights them when `y0` is a multiple of
    /// [`BLOCK`]`.1` (the map's blocks start there; any `y0` is lit correctly, a band
    /// starting elsewhere interpolates over blocks cut at its edge).
    pub fn shade_band(&self, y0: usize, rows: &mut [u32]) {
        let (w, h) = (self.cam.width as usize, self.cam.height as usize);
        if w == 0 || y0 >= h {
            return;
        }
        let n = (rows.len() / w).min(h - y0);
        let rows = &mut rows[..n * w];
        let map = self.map;
        let Some(rays) = &self.rays else {
            // Each pixel through its own ray; pixels with no direction stay as rendered.
            let o = &self.opts;
            let (ambient, exposure) = (o.ambient as f32, o.exposure as f32);
            let (dec, enc) = (decode_lut(), encode_lut());
            for (j, row) in rows.chunks_mut(w).enumerate() {
                for (x, px) in row.iter_mut().enumerate() {
                    let Some(e) = map.pixel_lux(self.cam, x, y0 + j) else {
                        continue;
                    };
                    if o.false_color {
                        colour_band(self.colour, o, std::slice::from_mut(px), &[e]);
                    } else {
                        *px = shade_pixel(*px, ambient + exposure * e, dec, enc);
                    }
                }
            }
            return;
        };
        // The map's blocks: BLOCK.1 rows from each multiple of BLOCK.1 (cut at the band),
        // their lux in this thread's buffer (a block row: in L2), then the colour.
        thread_local! {
            static LUX: std::cell::RefCell<Vec<f32>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        LUX.with_borrow_mut(|buf| {
            let mut y = y0;
            while y < y0 + n {
                let y1 = ((y / BLOCK.1 + 1) * BLOCK.1).min(y0 + n);
                let band = &mut rows[(y - y0) * w..(y1 - y0) * w];
                buf.resize(band.len(), 0.0);
                let es = &mut buf[..band.len()];
                map.band_lux(rays, w, y, es);
                colour_band(self.colour, &self.opts, band, es);
                y = y1;
            }
        });
    }
}

/// Colour `pixels` (albedo) in place from their illuminance `es` (lux, lights only) with
/// `o` (checked): the shading table's rows ([`ShadeRow`]), or the false-colour blend.
/// What a frame's band and a baked panorama's texels both get.
pub(crate) fn colour_band(colour: ShadeRow, o: &ShadeOptions, pixels: &mut [u32], es: &[f32]) {
    let (ambient, exposure) = (o.ambient as f32, o.exposure as f32);
    if !o.false_color {
        colour.run(pixels, es, ambient, exposure);
        return;
    }
    let (dec, enc) = (decode_lut(), encode_lut());
    for (px, &e) in pixels.iter_mut().zip(es) {
        let shaded = shade_pixel(*px, ambient + exposure * e, dec, enc);
        let c = false_color(false_color_position(e as f64, o.false_color_max_lux));
        *px = blend(c, shaded, 0.65);
    }
}

/// Where [`IlluminanceMap::fill`] writes: whole rows of `stride` values, the first one
/// row `y0`.
struct Lux<'a> {
    es: &'a mut [f32],
    stride: usize,
    y0: usize,
}

impl Lux<'_> {
    /// The index of pixel (x, y).
    #[inline]
    fn at(&self, x: usize, y: usize) -> usize {
        (y - self.y0) * self.stride + x
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::RoomFace;

    #[test]
    fn face_table_matches_the_faces() {
        for (axis, ends) in FACE_ON_AXIS.iter().enumerate() {
            for (high, &i) in ends.iter().enumerate() {
                assert_eq!(RoomFace::on_axis(axis, high == 1).index(), i);
            }
        }
    }
}
