//! Minification anti-aliasing: a pyramid of the map and the trilinear sampler.
//!
//! Zoomed out on a large map, one screen pixel covers several map pixels and bilinear
//! sampling (four texels) aliases: moiré on fine patterns, sparkle while panning. The
//! pyramid stores the map again at half, quarter, ... size (a 2×2 box filter per level,
//! averaged in 8-bit sRGB like the supersampled exact renderer), the same idea as
//! EP 0613099's series of tables halving in size. The sampler picks the two levels around
//! the pixel footprint and blends bilinear samples of both (trilinear).
//!
//! Geometry: level k pixel j covers level-0 pixels [j·2^k, (j+1)·2^k), so a level-0
//! position u (pixel i spans [i, i + 1)) is u / 2^k on level k — a shift of the Q.16
//! coordinate. Every map gets levels down to a side of 2, odd sides included: a level of
//! an odd side has ⌈side / 2⌉ pixels, its last pixel averaging the previous level's last
//! column (or row) with the one beyond it — column 0 for a 360° map (the seam), the last
//! column again otherwise, the last row again at the bottom — so the relation above stays
//! exact for every position inside the map. A 6000×3000 map gets 3000×1500, 1500×750,
//! 750×375, 375×188, … 6×3, 3×2. (Where a level's width is not W / 2^k, a 360° map's seam
//! falls inside its last column instead of on a column boundary: within a level texel of
//! the seam the level blends the two sides a little early, which a minifying filter
//! tolerates; levels of maps whose sides stay even are unchanged by this.)
//!
//! The level of detail is `log2(footprint) − ½` in Q.8 ([`lod_q8`]), where the footprint is
//! the larger side of the pixel's extent in level-0 map pixels. The LUT renderer takes the
//! horizontal extent from each span's index-interpolation step and the vertical one per
//! scanline from its angular row spacing (the LUT's per-scanline scale); the exact
//! renderer differentiates the exact mapping per pixel. Memory: at most one third of the
//! map more, built on first use. Partial (cropped) maps get no pyramid: they sample
//! bilinearly.

use crate::geom::fixed::Fx;
use crate::map::envmap::EnvMap;
use crate::map::sample::lerp_px;
use rayon::prelude::*;

/// Smallest level side built.
const MIN_LEVEL_SIDE: u32 = 2;

/// Level-of-detail bias in levels: blending towards level 1 starts at a footprint of
/// √2 map pixels instead of 1. Between 1 and √2 bilinear barely aliases, and a frame at
/// the common zoom (about one map pixel per screen pixel) then costs one bilinear sample
/// per pixel instead of two.
pub const LOD_BIAS: f32 = -0.5;

/// Footprints up to this have level of detail 0 ([`lod_q8`] skips the log2 there):
/// up to 2^0.5, where log2 + [`LOD_BIAS`] ≤ 0 (and just above it, or after the f32
/// rounding of the footprint, the Q.8 value truncates below 1/256 to 0 anyway). The LUT
/// renderer's spans at the common zoom have footprints between 1 and 1.414.
const LOD0_FOOTPRINT: f64 = std::f64::consts::SQRT_2;

/// Level of detail in Q.8 (256 = one level) for a footprint of `footprint` level-0 map
/// pixels per screen pixel: log2 of it plus [`LOD_BIAS`], and 0 (level 0, plain bilinear)
/// below that.
#[inline]
pub fn lod_q8(footprint: f64) -> i32 {
    // Up to LOD0_FOOTPRINT the answer is 0 (log2 + bias < 1/256): no log2.
    if footprint > LOD0_FOOTPRINT {
        // f32 log2 is plenty: the blend weight has 8 bits.
        (((footprint as f32).log2() + LOD_BIAS) * 256.0).clamp(0.0, i32::MAX as f32 / 2.0) as i32
    } else {
        0
    }
}

impl EnvMap {
    /// The pyramid levels 1, 2, ... (level 0 is the map itself), built on first use
    /// (rayon) and kept, down to a side of 2 (odd sides included). Empty for partial
    /// maps.
    pub fn pyramid(&self) -> &[EnvMap] {
        self.levels.get_or_init(|| build_levels(self))
    }

    /// Bytes the pyramid holds (0 until built).
    pub fn pyramid_bytes(&self) -> usize {
        self.levels
            .get()
            .map_or(0, |l| l.iter().map(EnvMap::bytes).sum())
    }

    /// Level `k` of the pyramid (0 = this map); clamped to the last level built.
    pub(crate) fn level(&self, k: usize) -> (&EnvMap, u32) {
        let (level, k) = pick_level(self, k, EnvMap::pyramid);
        (level, k as u32)
    }

    /// Trilinear sample at level-0 position (u, v) (Q.16; u in [0, W) for 360° maps) with
    /// level of detail `lod` (Q.8, see [`lod_q8`]): bilinear on the two levels around it,
    /// blended. `lod` ≤ 0 is plain bilinear.
    pub fn trilinear(&self, u: Fx, v: Fx, lod: i32) -> u32 {
        if lod <= 0 || self.crop.is_some() {
            return self.bilinear_any(u, v);
        }
        let k = (lod >> 8) as usize;
        let frac = (lod & 0xFF) as u32;
        let (a_map, ka) = self.level(k);
        let a = a_map.bilinear(u >> ka, v >> ka);
        let (b_map, kb) = self.level(k + 1);
        if frac == 0 || kb == ka {
            return a;
        }
        lerp_px(a, b_map.bilinear(u >> kb, v >> kb), frac)
    }

    fn bilinear_any(&self, u: Fx, v: Fx) -> u32 {
        if self.crop.is_some() {
            self.bilinear_cropped(u, v)
        } else {
            self.bilinear(u, v)
        }
    }
}

/// Levels 1.. of `map` (empty for partial maps).
/// Level `k` of `base`'s pyramid (0 = `base`; `levels` gives levels 1, 2, ..., built on
/// first use) clamped to the last level, and its index. Shared by maps and cubes; level 0
/// never builds the pyramid.
pub(crate) fn pick_level<'a, T>(
    base: &'a T,
    k: usize,
    levels: impl FnOnce(&'a T) -> &'a [T],
) -> (&'a T, usize) {
    if k == 0 {
        return (base, 0);
    }
    let levels = levels(base);
    match levels.len() {
        0 => (base, 0),
        n => {
            let k = k.min(n);
            (&levels[k - 1], k)
        }
    }
}

fn build_levels(map: &EnvMap) -> Vec<EnvMap> {
    let mut levels: Vec<EnvMap> = Vec::new();
    if map.crop.is_some() {
        return levels;
    }
    loop {
        let prev = levels.last().unwrap_or(map);
        let (w, h) = (prev.width, prev.height);
        let (nw, nh) = (w.div_ceil(2), h.div_ceil(2));
        if nw < MIN_LEVEL_SIDE || nh < MIN_LEVEL_SIDE {
            return levels;
        }
        // The column right of the last one (odd widths): column 0 across a 360° seam,
        // else the last column again; the row below the last: the last row again.
        let wraps = prev.projection.wraps();
        let right = |x: u32| match (x + 1 < w, wraps) {
            (true, _) => x + 1,
            (false, true) => 0,
            (false, false) => x,
        };
        let below = |y: u32| (y + 1).min(h - 1);
        let (nw, nh) = (nw as usize, nh as usize);
        let mut px = vec![0u32; nw * nh];
        px.par_chunks_mut(nw).enumerate().for_each(|(j, row)| {
            for (i, p) in row.iter_mut().enumerate() {
                let (x, y) = (2 * i as u32, 2 * j as u32);
                let (x1, y1) = (right(x), below(y));
                // (Elliptical and diamond maps: pixels on the sphere only.)
                *p = average4(
                    prev.pixel_on_sphere(x, y),
                    prev.pixel_on_sphere(x1, y),
                    prev.pixel_on_sphere(x, y1),
                    prev.pixel_on_sphere(x1, y1),
                );
            }
        });
        match EnvMap::from_pixels(nw as u32, nh as u32, &px, prev.projection) {
            Ok(mut level) => {
                level.background = map.background;
                levels.push(level);
            }
            // Cannot happen (sides ≥ 2 and below the map's); stop rather than panic.
            Err(_) => return levels,
        }
    }
}

/// Rounded average of four 0RGB pixels, per channel.
#[inline]
fn average4(a: u32, b: u32, c: u32, d: u32) -> u32 {
    let ch = |s: u32| {
        let sum = (a >> s & 0xFF) + (b >> s & 0xFF) + (c >> s & 0xFF) + (d >> s & 0xFF);
        ((sum + 2) / 4) << s
    };
    ch(16) | ch(8) | ch(0)
}

/// Level-0 Q.16 → level-k Q.16 (documentation helper for tests).
#[cfg(test)]
fn to_level(x: Fx, k: u32) -> Fx {
    x >> k
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::fixed::to_fx;
    use crate::geom::projection::Projection;

    /// The log2-free range of `lod_q8` gives what the formula gives there (a sweep of
    /// footprints from 1 to 1.5 in steps of 2⁻²⁰, and the first lod above 0).
    #[test]
    fn lod_without_log2_equals_the_formula() {
        let formula = |f: f64| {
            (((f as f32).log2() + LOD_BIAS) * 256.0).clamp(0.0, i32::MAX as f32 / 2.0) as i32
        };
        let mut first = None;
        for i in 0..=(1 << 19) {
            let f = 1.0 + i as f64 / (1 << 20) as f64;
            assert_eq!(lod_q8(f), formula(f), "footprint {f}");
            if first.is_none() && formula(f) > 0 {
                first = Some(f);
            }
        }
        assert!(first.is_some_and(|f| f > LOD0_FOOTPRINT), "{first:?}");
    }

    fn checker(w: u32, h: u32) -> EnvMap {
        let px: Vec<u32> = (0..h)
            .flat_map(|y| (0..w).map(move |x| if (x + y) % 2 == 0 { 0xFFFFFF } else { 0 }))
            .collect();
        EnvMap::from_pixels(w, h, &px, Projection::Equirect).unwrap()
    }

    #[test]
    fn levels_halve_and_average() {
        let m = checker(48, 24);
        let l = m.pyramid();
        let sides: Vec<_> = l.iter().map(|m| (m.width(), m.height())).collect();
        assert_eq!(sides, vec![(24, 12), (12, 6), (6, 3), (3, 2)]);
        // A one-pixel checker averages to mid grey on every level.
        for lv in l {
            for y in 0..lv.height() {
                for x in 0..lv.width() {
                    assert_eq!(
                        lv.pixel(x, y),
                        0x808080,
                        "level {}x{}",
                        lv.width(),
                        lv.height()
                    );
                }
            }
        }
        assert_eq!(
            m.pyramid_bytes(),
            l.iter().map(EnvMap::bytes).sum::<usize>()
        );
        assert!(m.pyramid_bytes() * 3 <= m.bytes() + 3 * 4 * 64);
    }

    #[test]
    fn lod_zero_is_bilinear_and_levels_line_up() {
        let px: Vec<u32> = (0..64 * 32)
            .map(|i: u32| i.wrapping_mul(2654435761) & 0xFFFFFF)
            .collect();
        let m = EnvMap::from_pixels(64, 32, &px, Projection::Equirect).unwrap();
        for &(u, v) in &[(0.3, 0.7), (13.5, 9.25), (63.9, 31.9)] {
            let (u, v) = (to_fx(u), to_fx(v));
            assert_eq!(m.trilinear(u, v, 0), m.bilinear(u, v));
            assert_eq!(m.trilinear(u, v, -40), m.bilinear(u, v));
            // Whole levels: exactly the bilinear sample of that level.
            let l1 = &m.pyramid()[0];
            assert_eq!(
                m.trilinear(u, v, 256),
                l1.bilinear(to_level(u, 1), to_level(v, 1))
            );
        }
        // The centre of level-1 pixel (3, 2) is the corner shared by level-0 pixels
        // (6..8, 4..6): both give the average of those four.
        let (u, v) = (to_fx(7.0), to_fx(5.0));
        assert_eq!(m.trilinear(u, v, 256), m.pyramid()[0].pixel(3, 2));
    }

    /// Odd sides get levels too (⌈side / 2⌉): the last column of a 360° map's level
    /// averages across the seam, the last row repeats; a clamped map repeats its last
    /// column. Even levels are the plain 2×2 averages.
    #[test]
    fn odd_sides_get_levels() {
        let px: Vec<u32> = (0..30 * 15)
            .map(|i: u32| i.wrapping_mul(2654435761) & 0xFFFFFF)
            .collect();
        for proj in [Projection::Equirect, Projection::Elliptical] {
            let m = EnvMap::from_pixels(30, 15, &px, proj).unwrap();
            let sides: Vec<_> = m
                .pyramid()
                .iter()
                .map(|l| (l.width(), l.height()))
                .collect();
            assert_eq!(sides, [(15, 8), (8, 4), (4, 2)], "{proj}");
            let l1 = &m.pyramid()[0];
            let l2 = &m.pyramid()[1];
            // (Elliptical maps average the pixels on the sphere: `pixel_on_sphere`.)
            let p = |x: u32, y: u32| m.pixel_on_sphere(x, y);
            // Level 1: 30 is even, 15 rows are odd: the last row repeats row 14.
            assert_eq!(l1.pixel(3, 2), average4(p(6, 4), p(7, 4), p(6, 5), p(7, 5)));
            assert_eq!(
                l1.pixel(3, 7),
                average4(p(6, 14), p(7, 14), p(6, 14), p(7, 14))
            );
            // Level 2: 15 columns are odd: the last column wraps (360°) or repeats.
            let q = |x: u32, y: u32| l1.pixel_on_sphere(x, y);
            let beyond = if proj.wraps() { 0 } else { 14 };
            assert_eq!(
                l2.pixel(7, 1),
                average4(q(14, 2), q(beyond, 2), q(14, 3), q(beyond, 3)),
                "{proj}"
            );
            // Level-0 positions inside the map are inside every level (u >> k).
            let (u, v) = (to_fx(29.9), to_fx(14.9));
            for (k, l) in m.pyramid().iter().enumerate() {
                let k = k as u32 + 1;
                assert!(to_level(u, k) < (l.width() as i64) << 16);
                assert!(to_level(v, k) < (l.height() as i64) << 16);
            }
        }
        // The map of the module doc.
        let m = EnvMap::from_pixels(
            6000,
            3000,
            &vec![0x123456; 6000 * 3000],
            Projection::Equirect,
        )
        .unwrap();
        let sides: Vec<_> = m
            .pyramid()
            .iter()
            .map(|l| (l.width(), l.height()))
            .collect();
        assert_eq!(
            sides[..4],
            [(3000, 1500), (1500, 750), (750, 375), (375, 188)]
        );
        assert_eq!(sides.last(), Some(&(3, 2)));
        assert!(m
            .pyramid()
            .iter()
            .all(|l| l.pixel(l.width() - 1, 0) == 0x123456));
    }

    #[test]
    fn lod_of_footprints() {
        assert_eq!(lod_q8(0.5), 0);
        assert_eq!(lod_q8(1.0), 0);
        assert_eq!(lod_q8(1.4), 0);
        assert_eq!(lod_q8(2.0), 128);
        assert_eq!(lod_q8(8.0), 640);
        assert!((lod_q8(3.0) - 277).abs() <= 1);
    }
}
