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
//! map more, built on first use.
//!
//! Partial maps (a crop of the panorama, `map/crop.rs`) get the pyramid of the full map
//! padded with the background, kept only where the crop reaches: level k stores the
//! texels of the full map's level k whose level-0 texels (by the rule above, odd sides
//! and the seam included) hold a stored pixel — a rectangle of that level, taken round
//! the seam like the crop, at least 2 × 2 — each the value the padded map's level has
//! there. So a level texel wholly inside the crop averages stored pixels only, and one
//! partly inside averages its stored pixels with the background, as the padded map's
//! does (a minified crop edge blends into the background instead of ending in a hard
//! step). The levels are read as the padded map reads them ([`EnvMap::bilinear_padded`]:
//! a texel off the rectangle is the background), level 0 as the partial map always is
//! ([`EnvMap::bilinear_cropped`]: background where the pixel is not covered, the edge
//! texels clamped inside). Trilinear on a partial map is therefore trilinear on the
//! padded full map, byte for byte, except where the level-0 sample is within half a
//! pixel of the crop's edge and weighs in (`tests/partial.rs`). The crop's rectangles
//! cost about a third of the stored pixels, plus a texel row or column on each side
//! per level; a new background colour rebuilds them (`EnvMap::set_background`).

use crate::geom::coverage::Crop;
use crate::geom::fixed::Fx;
use crate::geom::projection::Projection;
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
pub(crate) const LOD0_FOOTPRINT: f64 = std::f64::consts::SQRT_2;

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

/// `render::sink::nearest_level` of a footprint `f` (level-0 map pixels per screen pixel) without a
/// logarithm: 0 up to √2 (and for NaN), else ⌊log2(f) + ½⌋ = the binary exponent of
/// f·√2, at most 30 (the readers clamp it to their last level). It equals
/// `nearest_level(lod_q8(f))` (the level of [`lod_q8`]'s level of detail) except within 1/256 of a level above a boundary, where
/// `lod_q8`'s truncation to Q.8 still says the level below (unit test).
#[inline(always)]
pub(crate) fn nearest_level_of(f: f64) -> u32 {
    // (NaN compares false.)
    if f.partial_cmp(&std::f64::consts::SQRT_2) != Some(std::cmp::Ordering::Greater) {
        return 0;
    }
    let e = ((f * std::f64::consts::SQRT_2).to_bits() >> 52) as i64 - 1023;
    e.clamp(1, 30) as u32
}

impl EnvMap {
    /// The pyramid levels 1, 2, ... (level 0 is the map itself), built on first use
    /// (rayon) and kept, down to a side of 2 (odd sides included). For a partial map, the
    /// padded full map's levels where its crop reaches (see the module docs); their
    /// [`EnvMap::width`] and [`EnvMap::height`] are those of the full map's levels.
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
    /// blended. `lod` ≤ 0 is plain bilinear. For a partial map (u, v) are
    /// full-panorama coordinates; its level 0 is [`EnvMap::bilinear_cropped`], its other
    /// levels the padded full map's (see the module docs).
    pub fn trilinear(&self, u: Fx, v: Fx, lod: i32) -> u32 {
        if lod <= 0 {
            return self.level_bilinear(0, u, v);
        }
        let k = (lod >> 8) as usize;
        let frac = (lod & 0xFF) as u32;
        let ka = self.level(k).1;
        let a = self.level_bilinear(ka, u, v);
        let kb = self.level(k + 1).1;
        if frac == 0 || kb == ka {
            return a;
        }
        lerp_px(a, self.level_bilinear(kb, u, v), frac)
    }

    /// The bilinear sample of pyramid level `k` (0 = this map; a level that is built) at
    /// level-0 position (u, v) (Q.16), as [`EnvMap::trilinear`] reads its levels: level k
    /// at (u >> k, v >> k). On a partial map level 0 is [`EnvMap::bilinear_cropped`] and
    /// the other levels [`EnvMap::bilinear_padded`]: what the full map padded with the
    /// background reads there.
    #[inline]
    pub(crate) fn level_bilinear(&self, k: u32, u: Fx, v: Fx) -> u32 {
        if k == 0 {
            return if self.crop.is_some() {
                self.bilinear_cropped(u, v)
            } else {
                self.bilinear(u, v)
            };
        }
        let level = &self.pyramid()[k as usize - 1];
        if level.crop.is_some() {
            level.bilinear_padded(u >> k, v >> k)
        } else {
            level.bilinear(u >> k, v >> k)
        }
    }
}

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

/// Levels 1.. of `map`.
fn build_levels(map: &EnvMap) -> Vec<EnvMap> {
    if let Some(crop) = map.crop {
        return build_partial_levels(map, crop);
    }
    let mut levels: Vec<EnvMap> = Vec::new();
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

/// Levels 1.. of a partial map (see the module docs): level k stores the texels of the
/// full map's level k that its crop touches, each the value the full map padded with
/// the background has there, so a level texel partly inside the crop is the average of
/// its stored texels and the background (exactly the padded map's texel).
fn build_partial_levels(map: &EnvMap, crop: Crop) -> Vec<EnvMap> {
    let mut levels: Vec<EnvMap> = Vec::new();
    let bg = map.background;
    let mut rect = Rect::of(&crop);
    loop {
        let prev = levels.last().unwrap_or(map);
        let (fw, fh) = (rect.fw, rect.fh);
        if fw.div_ceil(2) < MIN_LEVEL_SIDE || fh.div_ceil(2) < MIN_LEVEL_SIDE {
            return levels;
        }
        let next = rect.next();
        // Texel (x, y) of the padded full map's previous level: stored, or background.
        let at = |x: u32, y: u32| rect.holds(x, y).map_or(bg, |(sx, sy)| prev.pixel(sx, sy));
        // `build_levels`' neighbours: across the seam, and the last row again.
        let right = |x: u32| if x + 1 < fw { x + 1 } else { 0 };
        let below = |y: u32| (y + 1).min(fh - 1);
        let (nw, nh) = (next.w as usize, next.h as usize);
        let mut px = vec![0u32; nw * nh];
        px.par_chunks_mut(nw).enumerate().for_each(|(j, row)| {
            let y = 2 * (next.top + j as u32);
            for (i, p) in row.iter_mut().enumerate() {
                let x = 2 * ((next.left + i as u32) % next.fw);
                let (x1, y1) = (right(x), below(y));
                *p = average4(at(x, y), at(x1, y), at(x, y1), at(x1, y1));
            }
        });
        // (The padding column repeats column 0 only when the level's texels span 360°.)
        let pad_as = if next.w == next.fw {
            Projection::Equirect
        } else {
            Projection::Elliptical
        };
        let level = Crop::new(next.fw, next.fh, next.left, next.top, next.w, next.h)
            .ok()
            .and_then(|c| {
                let m = EnvMap::from_pixels(next.w, next.h, &px, pad_as).ok()?;
                m.into_partial(c).ok()
            });
        match level {
            Some(mut level) => {
                level.background = bg;
                levels.push(level);
                rect = next;
            }
            // Cannot happen (sides ≥ 2 and at most the panorama's); stop rather than panic.
            None => return levels,
        }
    }
}

/// The stored texels of a partial map's level in the padded full map's level: its sides
/// `fw × fh` and the stored rectangle (`w × h` from column `left`, row `top`; the columns
/// continue at 0 past the seam), as `Crop` has them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Rect {
    fw: u32,
    fh: u32,
    left: u32,
    top: u32,
    w: u32,
    h: u32,
}

impl Rect {
    fn of(c: &Crop) -> Rect {
        Rect {
            fw: c.full_width(),
            fh: c.full_height(),
            left: c.left(),
            top: c.top(),
            w: c.width(),
            h: c.height(),
        }
    }

    /// The stored texel holding full-level texel (x, y) (`x < fw`), if any.
    fn holds(&self, x: u32, y: u32) -> Option<(u32, u32)> {
        let sx = (x + self.fw - self.left) % self.fw;
        let sy = y.wrapping_sub(self.top);
        (sx < self.w && sy < self.h).then_some((sx, sy))
    }

    /// The next level's rectangle: every texel whose 2×2 block (`build_levels`' rule:
    /// the column after an odd side's last is column 0, the row below the last row is
    /// the last row again) holds a stored texel of this level, and at least 2 × 2 (a
    /// texel added to make up the size is the padded map's too: background, or the
    /// average of what it covers). Full width starts at column 0.
    fn next(&self) -> Rect {
        let (fw, fh) = (self.fw.div_ceil(2), self.fh.div_ceil(2));
        let right = |x: u32| if x + 1 < self.fw { x + 1 } else { 0 };
        let col = |x: u32| (x + self.fw - self.left) % self.fw < self.w;
        let mask: Vec<bool> = (0..fw).map(|i| col(2 * i) || col(right(2 * i))).collect();
        let (mut left, mut w) = cyclic_hull(&mask);
        w = w.max(2);
        if w >= fw {
            (left, w) = (0, fw);
        }
        let mut top = self.top / 2;
        let h = ((self.top + self.h - 1) / 2 + 1 - top).max(2);
        top = top.min(fh - h);
        Rect {
            fw,
            fh,
            left,
            top,
            w,
            h,
        }
    }
}

/// The shortest run of columns round the circle `mask` holding every set one: (first
/// column, length); (0, n) when all are set. (`mask` has one set.)
fn cyclic_hull(mask: &[bool]) -> (u32, u32) {
    let n = mask.len();
    let Some(first) = mask.iter().position(|&b| b) else {
        return (0, n as u32);
    };
    // The longest run of unset columns ends just before the hull's first column.
    let (mut gap, mut start, mut run) = (0, 0, 0);
    for s in 1..=n {
        let i = (first + s) % n;
        if mask[i] {
            if run > gap {
                (gap, start) = (run, i);
            }
            run = 0;
        } else {
            run += 1;
        }
    }
    if gap == 0 {
        (0, n as u32)
    } else {
        (start as u32, (n - gap) as u32)
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

    const BG: u32 = 0x3366CC;

    /// Crops (full sides, left, top, width, height) with odd and even sides and origins,
    /// across the seam, 360° wide, at the corners, and tiny.
    const CROPS: [(u32, u32, u32, u32, u32, u32); 10] = [
        (30, 15, 7, 3, 11, 9),
        (30, 15, 25, 0, 9, 15),
        (37, 19, 36, 17, 2, 2),
        (37, 19, 0, 5, 37, 7),
        (37, 19, 0, 0, 3, 2),
        (37, 19, 35, 4, 2, 3),
        (64, 32, 1, 1, 62, 30),
        (64, 32, 60, 10, 8, 4),
        (301, 151, 150, 40, 77, 61),
        (301, 151, 290, 149, 40, 2),
    ];

    /// The full map of random pixels inside `crop` and [`BG`] elsewhere (an ordinary
    /// map: the padded reference), and the partial map of its crop.
    fn padded_and_partial(c: (u32, u32, u32, u32, u32, u32)) -> (EnvMap, EnvMap) {
        let crop = Crop::new(c.0, c.1, c.2, c.3, c.4, c.5).unwrap();
        let (fw, fh) = (crop.full_width(), crop.full_height());
        let inside = |x: u32, y: u32| {
            (x + fw - crop.left()) % fw < crop.width() && y.wrapping_sub(crop.top()) < crop.height()
        };
        let px: Vec<u32> = (0..fw * fh)
            .map(|i| match inside(i % fw, i / fw) {
                true => (i ^ 0x5A5A).wrapping_mul(2_654_435_761) & 0xFF_FFFF,
                false => BG,
            })
            .collect();
        let mut full = EnvMap::from_pixels(fw, fh, &px, Projection::Equirect).unwrap();
        full.set_background(BG);
        let stored: Vec<u32> = (0..crop.height())
            .flat_map(|y| (0..crop.width()).map(move |x| ((crop.left() + x) % fw, crop.top() + y)))
            .map(|(x, y)| px[(y * fw + x) as usize])
            .collect();
        let m = EnvMap::from_pixels(crop.width(), crop.height(), &stored, Projection::Equirect);
        let mut part = m.unwrap().into_partial(crop).unwrap();
        part.set_background(BG);
        assert!(part.crop().is_some());
        (full, part)
    }

    /// A partial map's levels are the padded full map's levels where its crop reaches:
    /// the same sides, every stored texel the padded level's texel (byte for byte, those
    /// partly inside the crop included: their background share is the padded map's), and
    /// every texel not stored the background in the padded level (nothing the crop
    /// reaches is left out, odd sides and the seam included). The memory is the stored
    /// texels'.
    #[test]
    fn partial_levels_are_the_padded_maps() {
        for c in CROPS {
            let (full, part) = padded_and_partial(c);
            assert_eq!(part.pyramid_bytes(), 0, "built on first use");
            let (fl, pl) = (full.pyramid(), part.pyramid());
            assert_eq!(fl.len(), pl.len(), "{c:?}");
            for (k, (f, p)) in fl.iter().zip(pl).enumerate() {
                assert_eq!((p.width(), p.height()), (f.width(), f.height()), "{c:?}");
                let r = p.crop().map_or(
                    Rect {
                        fw: f.width(),
                        fh: f.height(),
                        left: 0,
                        top: 0,
                        w: f.width(),
                        h: f.height(),
                    },
                    |c| Rect::of(&c),
                );
                assert_eq!((p.stored_width(), p.stored_height()), (r.w, r.h));
                for y in 0..f.height() {
                    for x in 0..f.width() {
                        let want = f.pixel(x, y);
                        match r.holds(x, y) {
                            Some((sx, sy)) => assert_eq!(
                                p.pixel(sx, sy),
                                want,
                                "{c:?} level {} texel ({x}, {y})",
                                k + 1
                            ),
                            None => assert_eq!(want, BG, "{c:?} level {} ({x}, {y})", k + 1),
                        }
                    }
                }
            }
            let bytes: usize = pl.iter().map(EnvMap::bytes).sum();
            assert_eq!(part.pyramid_bytes(), bytes);
            assert!(bytes <= full.pyramid_bytes(), "{c:?}");
        }
    }

    /// Trilinear on a partial map is trilinear on the padded full map: byte for byte
    /// from level of detail 256 on (levels ≥ 1 only), and below it (level 0 blended with
    /// level 1) the partial map's own level 0 (`bilinear_cropped`) blended with the
    /// padded map's level 1 — so equal to the padded map's trilinear wherever the
    /// level-0 samples agree (at least one pixel inside the crop, or outside it).
    #[test]
    fn partial_trilinear_is_the_padded_maps() {
        for c in CROPS {
            let (full, part) = padded_and_partial(c);
            let crop = part.crop().unwrap();
            let l1 = &full.pyramid()[0];
            let (fw, fh) = (c.0 as i64, c.1 as i64);
            let mut deep = 0;
            for i in 0..fw * 3 {
                for j in -2..fh * 3 + 2 {
                    // Positions a third of a pixel apart, off the pixel grid.
                    let (u, v) = (((i << 16) + 0x5432) / 3, ((j << 16) + 0x1234) / 3);
                    for lod in [-5, 0, 1, 100, 255, 256, 300, 512, 700, 1000, 2000] {
                        let got = part.trilinear(u, v, lod);
                        let at = format!("{c:?} at ({u:#x}, {v:#x}) lod {lod}");
                        if lod <= 0 {
                            assert_eq!(got, part.bilinear_cropped(u, v), "{at}");
                        } else if lod < 256 {
                            let want = lerp_px(
                                part.bilinear_cropped(u, v),
                                l1.bilinear(u >> 1, v >> 1),
                                lod as u32,
                            );
                            assert_eq!(got, want, "{at}");
                        } else {
                            assert_eq!(got, full.trilinear(u, v, lod), "{at}");
                        }
                        // At least a pixel inside the crop or outside it: the padded map's.
                        let (su, sv) = (
                            (u - ((crop.left() as i64) << 16)).rem_euclid(fw << 16),
                            v - ((crop.top() as i64) << 16),
                        );
                        let d = |s: i64, n: u32| s.min(((n as i64) << 16) - s);
                        let (du, dv) = (d(su, crop.width()), d(sv, crop.height()));
                        let wrapped = crop.width() == crop.full_width();
                        let du = if wrapped { i64::MAX } else { du };
                        if du.min(dv) >= 1 << 16 {
                            deep += 1;
                            assert_eq!(got, full.trilinear(u, v, lod), "inside: {at}");
                        }
                    }
                }
            }
            assert!(deep > 0 || c.4 <= 2 || c.5 <= 2, "{c:?}");
        }
    }

    /// A new background colour rebuilds a partial map's pyramid (its edge texels hold
    /// the background); a full map's is kept.
    #[test]
    fn new_background_rebuilds_a_partial_pyramid() {
        let (mut full, mut part) = padded_and_partial(CROPS[0]);
        let first = part.pyramid()[0].pixel(0, 0);
        full.pyramid();
        part.set_background(BG);
        assert!(part.pyramid_bytes() > 0, "the same colour keeps it");
        part.set_background(0xFFFFFF);
        full.set_background(0xFFFFFF);
        assert_eq!(part.pyramid_bytes(), 0);
        assert!(full.pyramid_bytes() > 0);
        // Crop column 7 (odd) and row 3 (odd): level-1 texel (0, 0) of the stored ones
        // covers one stored pixel and three of the background.
        assert_ne!(part.pyramid()[0].pixel(0, 0), first);
        assert_eq!(part.pyramid()[0].background(), 0xFFFFFF);
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
