//! Cube-face pyramids: trilinear (minifying) sampling on cube maps, as the map's pyramid
//! (`map/pyramid.rs`) gives it to equirects.
//!
//! Level k + 1 has faces of side ⌈s / 2⌉ where level k's side is s, down to 1. Each level
//! covers the whole face, so a direction's face coordinates on level k are
//! [`face_uv`] with half that level's side (the renderers' face runs simply take that
//! half). A level texel is the area average of the previous level over the texel's
//! square of the face (exactly the 2×2 box of the map's pyramid for even sides; for odd
//! sides each level texel covers s / ⌈s / 2⌉ < 2 texels, weighted by overlap), averaged in
//! 8-bit sRGB like the map's pyramid, and each level gets its one-texel border from its
//! neighbouring faces of the same level ([`CubeMap::from_faces`]), so bilinear reads on a
//! level cross face edges without a seam.
//!
//! The level of detail is [`lod_q8`] of the footprint: the larger of `|∂u|`, `|∂v|` (face
//! texels of level 0) for one output pixel right and one down, from the analytic
//! derivatives of `u = h + h·a/m`, `v = h − h·b/m` ([`footprint`]). The per-pixel (basic)
//! renderer takes it per pixel; the scanline renderer per chunk of
//! [`TRILINEAR_RUN_CHUNK`] pixels of a face run, at the chunk's middle pixel (as the
//! map's LUT renderer takes one per span).

use super::{face_axes, face_uv, CubeMap, Face};
use crate::map::pyramid::{lod_q8, pick_level};
use crate::map::sample::lerp_px;
use glam::DVec3;
use rayon::prelude::*;

/// Pixels of a scanline renderer's face run that share one level of detail.
pub(crate) const TRILINEAR_RUN_CHUNK: usize = 16;

impl CubeMap {
    /// The pyramid levels 1, 2, ... (level 0 is this cube), built on first use (rayon)
    /// and kept: faces of side ⌈s / 2⌉ down to 1 (see the module docs).
    pub fn pyramid(&self) -> &[CubeMap] {
        self.levels.get_or_init(|| build_levels(self))
    }

    /// Bytes the pyramid holds (0 until built).
    pub fn pyramid_bytes(&self) -> usize {
        self.levels
            .get()
            .map_or(0, |l| l.iter().map(CubeMap::bytes).sum())
    }

    /// Level `k` (0 = this cube), clamped to the last level, and its index.
    pub(crate) fn level(&self, k: usize) -> (&CubeMap, usize) {
        pick_level(self, k, CubeMap::pyramid)
    }

    /// Trilinear sample of direction `d` on `face` (the face of `d`) with level of detail
    /// `lod` (Q.8, [`lod_q8`]): bilinear on the two levels around it at the direction's
    /// face coordinates on each, blended by `lod & 0xFF`; `lod` ≤ 0 is
    /// [`CubeMap::bilinear`] at [`face_uv`].
    pub fn trilinear_dir(&self, face: Face, d: DVec3, lod: i32) -> u32 {
        let sample = |c: &CubeMap| {
            let (u, v) = face_uv(face, d, c.face_size() as f64 / 2.0);
            c.bilinear(face, u, v)
        };
        if lod <= 0 {
            return sample(self);
        }
        let k = (lod >> 8) as usize;
        let frac = (lod & 0xFF) as u32;
        let (a, ka) = self.level(k);
        let (b, kb) = self.level(k + 1);
        let s = sample(a);
        if frac == 0 || ka == kb {
            return s;
        }
        lerp_px(s, sample(b), frac)
    }
}

/// Level-0 face texels per output pixel at the ray with face axes `(a, b, m)` (see
/// [`face_axes`]), the image's x and y steps per pixel being `sx`, `sy` on the same axes:
/// the larger of `|∂u|`, `|∂v|` over both steps, for faces of side `2 · half`.
#[inline]
pub(crate) fn footprint(
    (a, b, m): (f64, f64, f64),
    sx: (f64, f64, f64),
    sy: (f64, f64, f64),
    half: f64,
) -> f64 {
    let k = half / (m * m);
    let mut f: f64 = 0.0;
    for (sa, sb, sm) in [sx, sy] {
        let du = (sa * m - a * sm) * k;
        let dv = (sb * m - b * sm) * k;
        f = f.max(du.abs()).max(dv.abs());
    }
    f
}

/// An upper bound of [`footprint`] over the pixels `dx` in `[x0, x1]` of a face run whose
/// axes are `(a, b, m) = p + dx · d` (`m` > 0 at both ends), with generous room for the
/// rounding of [`footprint`] as computed at any of them; infinite unless both ends are
/// finite with `m` > 0. Each `|∂u|`, `|∂v|` is `|s·m − c·s_m| · half / m²` with `c`
/// the ray's `a` or `b` and `s` a step's: the numerator is linear in `dx` (its largest
/// magnitude at an end) and `1 / m²` is largest at the end where `m` is smallest (`m` is
/// linear and positive between), so the product of the two is an upper bound.
#[inline]
pub(crate) fn footprint_bound(
    (p, d): ([f64; 3], [f64; 3]),
    (x0, x1): (f64, f64),
    sx: (f64, f64, f64),
    sy: (f64, f64, f64),
    half: f64,
) -> f64 {
    let at = |x: f64| (p[0] + x * d[0], p[1] + x * d[1], p[2] + x * d[2]);
    let ends = [at(x0), at(x1)];
    // (NaN or infinite ends, or m ≤ 0 at one: no bound.)
    let usable = ends
        .iter()
        .all(|e| e.0.is_finite() && e.1.is_finite() && e.2.is_finite() && e.2 > 0.0);
    if !usable {
        return f64::INFINITY;
    }
    let m = ends[0].2.min(ends[1].2);
    let mut num: f64 = 0.0;
    for (sa, sb, sm) in [sx, sy] {
        for (a, b, mm) in ends {
            for (s, c) in [(sa, a), (sb, b)] {
                // The magnitude plus a bound of its rounding (relative 1e-12 of its
                // terms, some thousand times f64's).
                let t = s * mm - c * sm;
                num = num.max(t.abs() + 1e-12 * ((s * mm).abs() + (c * sm).abs()));
            }
        }
    }
    num * (half / (m * m)) * (1.0 + 1e-9)
}

/// The level of detail (Q.8) of the ray `d` on `face` with image steps `sx`, `sy` (world).
#[inline]
pub(crate) fn lod_of(face: Face, d: DVec3, sx: DVec3, sy: DVec3, half: f64) -> i32 {
    lod_q8(footprint(
        face_axes(face, d),
        face_axes(face, sx),
        face_axes(face, sy),
        half,
    ))
}

/// Per output texel `j` of a side-`m2` level: the source texels of the side-`m` level it
/// covers and their weights (overlap / texel width, summing to 1).
fn area_weights(m: u32, m2: u32) -> Vec<Vec<(usize, f32)>> {
    let s = m as f64 / m2 as f64;
    (0..m2)
        .map(|j| {
            let (lo, hi) = (j as f64 * s, (j + 1) as f64 * s);
            let first = lo.floor() as usize;
            let last = (hi.ceil() as usize).min(m as usize);
            (first..last)
                .map(|i| {
                    let w = hi.min(i as f64 + 1.0) - lo.max(i as f64);
                    (i, (w / s) as f32)
                })
                .filter(|&(_, w)| w > 0.0)
                .collect()
        })
        .collect()
}

/// One face (`m × m`, row-major, no border) area-averaged to `m2 × m2`.
fn downsample(px: &[u32], m: usize, m2: usize, w: &[Vec<(usize, f32)>]) -> Vec<u32> {
    let ch = |p: u32, s: u32| ((p >> s) & 0xFF) as f32;
    // Horizontal pass: m rows of m2 texels, three channels.
    let mut rows = vec![[0f32; 3]; m * m2];
    for y in 0..m {
        for (j, wj) in w.iter().enumerate() {
            let mut acc = [0f32; 3];
            for &(i, k) in wj {
                let p = px[y * m + i];
                for (c, s) in acc.iter_mut().zip([16, 8, 0]) {
                    *c += k * ch(p, s);
                }
            }
            rows[y * m2 + j] = acc;
        }
    }
    let mut out = vec![0u32; m2 * m2];
    for (j2, wj) in w.iter().enumerate() {
        for j in 0..m2 {
            let mut acc = [0f32; 3];
            for &(y, k) in wj {
                for (c, r) in acc.iter_mut().zip(rows[y * m2 + j]) {
                    *c += k * r;
                }
            }
            let q = |x: f32| ((x + 0.5).floor() as u32).min(255);
            out[j2 * m2 + j] = q(acc[0]) << 16 | q(acc[1]) << 8 | q(acc[2]);
        }
    }
    out
}

/// Levels 1.. of `cube`.
fn build_levels(cube: &CubeMap) -> Vec<CubeMap> {
    let mut levels: Vec<CubeMap> = Vec::new();
    loop {
        let prev = levels.last().unwrap_or(cube);
        let m = prev.face_size();
        if m <= 1 {
            return levels;
        }
        let m2 = m.div_ceil(2);
        let w = area_weights(m, m2);
        let faces: Vec<Vec<u32>> = Face::ALL
            .par_iter()
            .map(|&f| downsample(&prev.face_pixels(f), m as usize, m2 as usize, &w))
            .collect();
        let refs: [&[u32]; 6] = std::array::from_fn(|k| faces[k].as_slice());
        match CubeMap::from_faces(m2, refs) {
            Ok(l) => levels.push(l),
            // Cannot happen (1 ≤ m2 < m); stop rather than panic.
            Err(_) => return levels,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn footprint_bound_is_above_every_pixels_footprint() {
        // Random view runs on random faces: the bound over [x0, x1] is at least the
        // footprint at every whole and half pixel between (as the scanline renderer
        // computes it); over a single pixel, that pixel's footprint.
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut checked = 0;
        for _ in 0..400 {
            let (yaw, pitch) = (rnd() * 360.0 - 180.0, rnd() * 180.0 - 90.0);
            let (sp, cp) = pitch.to_radians().sin_cos();
            let (sy, cy) = yaw.to_radians().sin_cos();
            let b = DVec3::new(cy, 0.0, -sy);
            let r1 = DVec3::new(-sp * sy, cp, -sp * cy);
            let r2 = DVec3::new(cp * sy, sp, cp * cy);
            let focal = 100.0 + rnd() * 2000.0;
            let dy = rnd() * 1000.0 - 500.0;
            let p = r1 * dy + r2 * focal;
            let face = Face::ALL[(rnd() * 6.0) as usize % 6];
            let (pa, pb, pm) = face_axes(face, p);
            let (ba, bb, bm) = face_axes(face, b);
            let (sx, sy) = (face_axes(face, b), face_axes(face, r1));
            let half = 1.0 + rnd() * 4000.0;
            let x0 = (rnd() * 2000.0 - 1000.0).floor() + 0.5;
            let x1 = x0 + (rnd() * 300.0).floor();
            let run = ([pa, pb, pm], [ba, bb, bm]);
            let bound = footprint_bound(run, (x0, x1), sx, sy, half);
            let at = |x: f64| (pa + x * ba, pb + x * bb, pm + x * bm);
            if !(at(x0).2 > 0.0 && at(x1).2 > 0.0) {
                assert_eq!(bound, f64::INFINITY);
                continue;
            }
            let mut most: f64 = 0.0;
            let mut x = x0;
            while x <= x1 {
                let f = footprint(at(x), sx, sy, half);
                assert!(f <= bound, "{face:?} {x}: {f} > {bound}");
                most = most.max(f);
                x += 0.5;
            }
            // Over one pixel the bound is that pixel's footprint, to rounding.
            let one = footprint_bound(run, (x0, x0), sx, sy, half);
            let f0 = footprint(at(x0), sx, sy, half);
            assert!(f0 < 0.1 || one <= f0 * (1.0 + 1e-6), "{one} far above {f0}");
            assert!(most <= bound);
            checked += 1;
        }
        assert!(checked > 100, "{checked} runs checked");
    }

    #[test]
    fn levels_halve_and_average() {
        // Even side: the 2×2 box, rounded half up; odd: overlap weights summing to 1.
        let n = 6u32;
        let faces: Vec<Vec<u32>> = (0..6u32)
            .map(|k| (0..n * n).map(|i| (i * 7 + k * 40) % 256).collect())
            .collect();
        let refs: [&[u32]; 6] = std::array::from_fn(|k| faces[k].as_slice());
        let cube = CubeMap::from_faces(n, refs).unwrap();
        let sides: Vec<u32> = cube.pyramid().iter().map(|l| l.face_size()).collect();
        assert_eq!(sides, [3, 2, 1]);
        let l1 = &cube.pyramid()[0];
        for f in Face::ALL {
            let src = &faces[f.index()];
            for (j, i) in [(0u32, 0u32), (2, 1), (1, 2)] {
                let s = |x: u32, y: u32| src[(y * n + x) as usize];
                let sum = s(2 * i, 2 * j)
                    + s(2 * i + 1, 2 * j)
                    + s(2 * i, 2 * j + 1)
                    + s(2 * i + 1, 2 * j + 1);
                assert_eq!(l1.pixel(f, i, j), (sum + 2) / 4, "{f:?} ({i},{j})");
            }
        }
        for (m, m2) in [(3u32, 2u32), (5, 3), (7, 4), (2049, 1025)] {
            for wj in area_weights(m, m2) {
                let t: f32 = wj.iter().map(|w| w.1).sum();
                assert!((t - 1.0).abs() < 1e-5, "{m}->{m2}: {t}");
            }
        }
        // A flat face stays flat on every level, and the pyramid ends at side 1.
        let flat = CubeMap::from_faces(5, [&[0x40_80_C0u32; 25][..]; 6]).unwrap();
        for l in flat.pyramid() {
            assert!(Face::ALL
                .iter()
                .all(|&f| l.face_pixels(f).iter().all(|&p| p == 0x40_80_C0)));
        }
        assert_eq!(flat.pyramid().last().unwrap().face_size(), 1);
    }

    #[test]
    fn footprint_of_a_face_camera() {
        // The face's own camera at the face's resolution (focal = half): one texel per
        // pixel at the center.
        let half = 32.0;
        let d = DVec3::new(0.0, 0.0, half);
        let sx = DVec3::new(1.0, 0.0, 0.0);
        let sy = DVec3::new(0.0, -1.0, 0.0);
        let f0 = footprint(
            face_axes(Face::Front, d),
            face_axes(Face::Front, sx),
            face_axes(Face::Front, sy),
            half,
        );
        assert!((f0 - 1.0).abs() < 1e-12, "{f0}");
        assert_eq!(lod_of(Face::Front, d, sx, sy, half), 0);
        // Twice as far out (half the pixel density): two texels per pixel, lod 0.5.
        let lod = lod_of(Face::Front, d, 2.0 * sx, 2.0 * sy, half);
        assert_eq!(lod, 128);
    }
}
