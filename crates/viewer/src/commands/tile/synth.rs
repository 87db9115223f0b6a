//! The synthetic pyramid's pixels, fast: the test scene (`lut_core::scene_color`) computed
//! from the direction vector with no library trigonometry, plus a fine grain, so a
//! 262144-wide pyramid (42 Gpixel of faces) is written in minutes.
//!
//! # The scene from the direction
//! `scene_color(λ, φ)` needs λ and φ in degrees for its grid lines and φ for its brightness
//! ramp, and cos(λ + π), cos(λ + π/3), cos(λ − π/3) for its hue. The cosines come from the
//! direction itself (cos λ = z / ρ, sin λ = x / ρ, ρ = √(x² + z²)), and λ, φ from
//! [`atan2`] below: a table of atan(k/32) plus a six-term series, within a few units in
//! the last place of the library's (its per-pixel `atan2` and three `cos` were 80 % of
//! `viewer tile --synthetic`'s time). The colours equal `scene_color`'s but where a value
//! lies within about 1e-13 of a line's edge or of a rounding tie (the unit test checks
//! a million directions).
//!
//! # Interpolated where it cannot be seen
//! Along a face row the angles are exact every 8 pixels (32 on faces of 8192 and more)
//! and linear in between, except near the poles and across the seam ([`step_for`]); a
//! segment whose ends are both in the colour field and which spans less than a line's
//! width has its colour interpolated too. [`render`] is thus `scene_color` within one
//! level but at a few pixels on line edges (tested on faces of 648 to 83440 px).
//!
//! # The grain
//! The scene alone is smooth at a large pyramid's finest levels (a 512-px tile of a
//! 262144-wide panorama spans half a degree), so its JPEG tiles were a few KB where a
//! photograph's are tens of KB, and cheap to decode: not what a bench of a gigapixel
//! photograph should decode. Each top-level pixel gets a luminance grain, the sum of
//! `octaves` layers of value noise, layer k constant over 2^k × 2^k pixel blocks, each
//! uniform in ±[`GRAIN`] (a hash of face, layer and block: every tile differs). The
//! levels are box-filtered from the top, so at every level the layers at least as coarse
//! as a level pixel survive as pixel-scale grain: every level's tiles have detail.

use lut_core::Face;

/// Half the range of one grain layer (levels of 0..255).
pub const GRAIN: i32 = 5;

/// atan(k / 32) for k = 0..=32.
fn atan_table() -> &'static [f64; 33] {
    static T: std::sync::OnceLock<[f64; 33]> = std::sync::OnceLock::new();
    T.get_or_init(|| std::array::from_fn(|k| (k as f64 / 32.0).atan()))
}

/// atan(t) for t in [0, 1]: atan(c) + atan((t − c) / (1 + t·c)) with c = k/32 the
/// nearest table point, the second by its series (|u| ≤ 1/64: six terms leave < 1e-23).
#[inline]
fn atan01(t: f64, table: &[f64; 33]) -> f64 {
    // round half up (t ≥ 0): no library call (`f64::round` is one without SSE4.1)
    let k = (t * 32.0 + 0.5) as usize;
    let c = k as f64 / 32.0;
    let u = (t - c) / (1.0 + t * c);
    let u2 = u * u;
    let s = u
        * (1.0
            + u2 * (-1.0 / 3.0
                + u2 * (1.0 / 5.0 + u2 * (-1.0 / 7.0 + u2 * (1.0 / 9.0 + u2 * (-1.0 / 11.0))))));
    table[k.min(32)] + s
}

/// `y.atan2(x)` (the angle of (x, y)), 0 for (0, 0).
#[inline]
pub fn atan2(y: f64, x: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI};
    let (ay, ax) = (y.abs(), x.abs());
    let (lo, hi) = if ay <= ax { (ay, ax) } else { (ax, ay) };
    if hi == 0.0 {
        return 0.0;
    }
    let mut r = atan01(lo / hi, atan_table());
    if ay > ax {
        r = FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    if y < 0.0 {
        -r
    } else {
        r
    }
}

/// What `scene_color` needs of a direction: λ and φ in degrees, cos λ and sin λ.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Angles {
    l: f64,
    p: f64,
    cl: f64,
    sl: f64,
}

/// The angles of the direction `(x, y, z)` (not necessarily unit).
#[inline]
fn angles(x: f64, y: f64, z: f64) -> Angles {
    let rho = (x * x + z * z).sqrt();
    // λ = atan2(x, z): cos λ = z / ρ, sin λ = x / ρ (λ = 0 on the axis, as atan2(0, 0)).
    let (cl, sl) = if rho > 0.0 {
        (z / rho, x / rho)
    } else {
        (1.0, 0.0)
    };
    Angles {
        l: atan2(x, z).to_degrees(),
        p: atan2(y, rho).to_degrees(),
        cl,
        sl,
    }
}

/// `a + (b − a) · f` of every field.
#[inline]
fn lerp(a: &Angles, b: &Angles, f: f64) -> Angles {
    Angles {
        l: a.l + (b.l - a.l) * f,
        p: a.p + (b.p - a.p) * f,
        cl: a.cl + (b.cl - a.cl) * f,
        sl: a.sl + (b.sl - a.sl) * f,
    }
}

/// The colour field's channels (0..=255, before rounding) at `a` when no line is there.
#[inline]
fn field(a: &Angles) -> Option<[f64; 3]> {
    match color(a) {
        0xFFFFFF | 0xFF2020 | 0x202020 if on_line(a) => None,
        _ => {
            const HALF_SQRT3: f64 = 0.866_025_403_784_438_6;
            let bright = 0.55 + 0.45 * (a.p / 180.0 + 0.5);
            let c = |v: f64| (v * bright).clamp(0.0, 1.0) * 255.0;
            Some([
                c(0.5 - 0.5 * a.cl),
                c(0.5 + 0.5 * (0.5 * a.cl - HALF_SQRT3 * a.sl)),
                c(0.5 + 0.5 * (0.5 * a.cl + HALF_SQRT3 * a.sl)),
            ])
        }
    }
}

/// Whether `a` is on one of the scene's lines (the meridian, the seam, the grid).
#[inline]
fn on_line(a: &Angles) -> bool {
    let (l, p) = (a.l, a.p);
    let line = |v: f64, every: f64, width: f64| {
        let n = ((v / every + 64.5) as i64 - 64) as f64;
        (v - n * every).abs() < width
    };
    l.abs() < 0.4
        || l.abs() > 179.6
        || (p.abs() <= 80.0 && line(l, 15.0, 0.4))
        || line(p, 10.0, 0.3)
}

/// `scene_color`'s colour from the angles.
#[inline]
fn color(a: &Angles) -> u32 {
    let (l, p) = (a.l, a.p);
    // scene_color's `v.rem_euclid(every) < width || > every − width`: v within `width`
    // of the nearest multiple of `every` (|v| ≤ 180; no library call for the rounding)
    let line = |v: f64, every: f64, width: f64| {
        let n = ((v / every + 64.5) as i64 - 64) as f64;
        (v - n * every).abs() < width
    };
    if l.abs() < 0.4 {
        return 0xFFFFFF;
    }
    if l.abs() > 179.6 {
        return 0xFF2020;
    }
    let near_pole = p.abs() > 80.0;
    if (!near_pole && line(l, 15.0, 0.4)) || line(p, 10.0, 0.3) {
        return 0x202020;
    }
    const HALF_SQRT3: f64 = 0.866_025_403_784_438_6;
    // 0.55 + 0.45 (φ / π + 0.5), φ in degrees
    let bright = 0.55 + 0.45 * (p / 180.0 + 0.5);
    // scene_color: 0.5 + 0.5·cos(λ + π), cos(λ + π/3), cos(λ − π/3)
    let r = 0.5 - 0.5 * a.cl;
    let g = 0.5 + 0.5 * (0.5 * a.cl - HALF_SQRT3 * a.sl);
    let b = 0.5 + 0.5 * (0.5 * a.cl + HALF_SQRT3 * a.sl);
    let c = |v: f64| ((v * bright).clamp(0.0, 1.0) * 255.0 + 0.5) as u32;
    c(r) << 16 | c(g) << 8 | c(b)
}

/// `lut_core::scene_color(λ, φ)` of the direction `(x, y, z)` (not necessarily unit).
#[cfg(test)]
fn scene_color_dir(x: f64, y: f64, z: f64) -> u32 {
    color(&angles(x, y, z))
}

/// A 32-bit mix of the grain's block coordinates.
#[inline]
fn mix(seed: u32, bx: u32, by: u32) -> u32 {
    let mut h = bx.wrapping_mul(0x9E37_79B1) ^ by.wrapping_mul(0x85EB_CA77) ^ seed;
    h ^= h >> 15;
    h = h.wrapping_mul(0x2C1B_3C6D);
    h ^ (h >> 13)
}

/// A grain layer's value: uniform in −GRAIN..=GRAIN.
#[inline]
fn grain_value(h: u32) -> i32 {
    (((h >> 16) * (2 * GRAIN as u32 + 1)) >> 16) as i32 - GRAIN
}

/// The grain of pixels `x0..x0 + out.len()` of row `y` of `face` (top level), `octaves`
/// layers, added into `out`: layers 0 to 2 a block at a time, the coarser ones (constant
/// over 8-pixel blocks) summed once for each 8-pixel block.
pub fn grain_row(face: Face, x0: u32, y: u32, octaves: u32, out: &mut [i32]) {
    let w = out.len() as u32;
    let octaves = octaves.min(31);
    let seed = |k: u32| ((face as u32) << 8 | k).wrapping_mul(0xC2B2_AE3D);
    let mut layer = |k: u32| {
        let mut x = x0;
        while x < x0 + w {
            let bx = x >> k;
            let end = ((bx + 1) << k).min(x0 + w);
            let v = grain_value(mix(seed(k), bx, y >> k));
            for g in &mut out[(x - x0) as usize..(end - x0) as usize] {
                *g += v;
            }
            x = end;
        }
    };
    for k in 0..octaves.min(3) {
        layer(k);
    }
    // Layers 3.. are constant over 8-pixel blocks: their sum for each block, each
    // layer's value recomputed only where its block changes.
    if octaves > 3 {
        let mut value = [0i32; 32];
        let mut block = [u32::MAX; 32];
        let mut sum = 0;
        let mut x = x0;
        while x < x0 + w {
            let end = (((x >> 3) + 1) << 3).min(x0 + w);
            for j in 3..octaves {
                let b = x >> j;
                if b != block[j as usize] {
                    let v = grain_value(mix(seed(j), b, y >> j));
                    sum += v - value[j as usize];
                    value[j as usize] = v;
                    block[j as usize] = b;
                }
            }
            for g in &mut out[(x - x0) as usize..(end - x0) as usize] {
                *g += sum;
            }
            x = end;
        }
    }
}

/// Pixels between two exact samples `step` apart (8, or 32 on faces of 8192 and more)
/// have their angles interpolated linearly: the error is about 0.08 · (2·step / n)²
/// radians, under 3 % of a pixel for either. Near the poles (|φ| > 85°) and across the
/// ±180° seam, where λ is not smooth, every pixel is exact.
fn step_for(n: u32) -> usize {
    if n >= 8192 {
        32
    } else {
        8
    }
}

/// Columns `x0..x0 + w`, rows from `y0` (as many as `out` holds) of `face` (side `n`) of
/// the synthetic scene with `octaves` layers of grain, as RGB8 rows into `out`.
pub fn render(face: Face, n: u32, (x0, y0, w): (u32, u32, u32), octaves: u32, out: &mut [u8]) {
    if w == 0 {
        return;
    }
    let w = w as usize;
    let step = step_for(n);
    let half = f64::from(n) / 2.0;
    let inv = 1.0 / half;
    let mut grain = vec![0i32; w];
    let mut samples: Vec<(usize, Angles)> = Vec::with_capacity(w / step + 2);
    for (j, row) in out.chunks_exact_mut(3 * w).enumerate() {
        let y = y0 + j as u32;
        let t = 1.0 - (f64::from(y) + 0.5) * inv;
        let at = |i: usize| {
            let s = (f64::from(x0 + i as u32) + 0.5) * inv - 1.0;
            let d = lut_core::face_dir(face, s, t);
            angles(d.x, d.y, d.z)
        };
        samples.clear();
        samples.extend((0..w).step_by(step).map(|i| (i, at(i))));
        if samples.last().is_some_and(|&(i, _)| i != w - 1) {
            samples.push((w - 1, at(w - 1)));
        }
        grain.fill(0);
        grain_row(face, x0, y, octaves, &mut grain);
        for pair in samples.windows(2) {
            let ((i, a), (e, b)) = (pair[0], pair[1]);
            let smooth = (b.l - a.l).abs() < 10.0 && a.p.abs().max(b.p.abs()) < 85.0;
            // Both ends in the colour field and a span under any line's width (0.6°):
            // no line inside, the colour is interpolated too.
            let narrow = smooth && (b.l - a.l).abs() < 0.3 && (b.p - a.p).abs() < 0.3;
            let fields = if narrow {
                field(&a).zip(field(&b))
            } else {
                None
            };
            let inv_len = 1.0 / (e - i) as f64;
            if let Some((ca, cb)) = fields {
                // 16.16 fixed point, rounded half up (the channels are in 0..=255)
                let start = ca.map(|c| ((c + 0.5) * 65536.0) as i32);
                let delta: [i32; 3] =
                    std::array::from_fn(|c| ((cb[c] - ca[c]) * inv_len * 65536.0) as i32);
                let mut v = start;
                for (px, &g) in row[3 * i..3 * e].chunks_exact_mut(3).zip(&grain[i..e]) {
                    for c in 0..3 {
                        px[c] = ((v[c] >> 16) + g).clamp(0, 255) as u8;
                        v[c] += delta[c];
                    }
                }
            } else {
                for k in i..e {
                    let ang = if k == i {
                        a
                    } else if smooth {
                        lerp(&a, &b, (k - i) as f64 * inv_len)
                    } else {
                        at(k)
                    };
                    put(&mut row[3 * k..3 * k + 3], color(&ang), grain[k]);
                }
            }
        }
        if let Some(&(e, b)) = samples.last() {
            put(&mut row[3 * e..3 * e + 3], color(&b), grain[e]);
        }
    }
}

/// Pixel `c` (0RGB) plus grain `g`, as RGB8 into `px`.
#[inline]
fn put(px: &mut [u8], c: u32, g: i32) {
    let add = |v: u32| (v as i32 + g).clamp(0, 255) as u8;
    px.copy_from_slice(&[add(c >> 16 & 255), add(c >> 8 & 255), add(c & 255)]);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rng(s: &mut u64) -> f64 {
        *s ^= *s << 13;
        *s ^= *s >> 7;
        *s ^= *s << 17;
        (*s >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn atan2_matches_the_library() {
        let mut s = 0x1234_5678_9abc_def1u64;
        let mut worst = 0f64;
        for i in 0..1_000_000 {
            let (y, x) = (rng(&mut s) * 2.0 - 1.0, rng(&mut s) * 2.0 - 1.0);
            let (y, x) = if i % 3 == 0 { (y * 1e-6, x) } else { (y, x) };
            worst = worst.max((atan2(y, x) - y.atan2(x)).abs());
        }
        assert!(worst < 1e-15, "worst {worst:e}");
        for (y, x) in [
            (0.0, 1.0),
            (1.0, 0.0),
            (0.0, -1.0),
            (-1.0, 0.0),
            (1.0, 1.0),
            (-2.0, -2.0),
        ] {
            assert!((atan2(y, x) - f64::atan2(y, x)).abs() < 1e-15, "{y} {x}");
        }
        assert_eq!(atan2(0.0, 0.0), 0.0);
    }

    #[test]
    fn the_scene_from_the_direction_is_scene_color() {
        let mut s = 0x0bad_cafe_1234_5677u64;
        let mut differ = 0;
        let n = 1_000_000;
        for i in 0..n {
            let (x, y, z) = (
                rng(&mut s) * 2.0 - 1.0,
                rng(&mut s) * 2.0 - 1.0,
                rng(&mut s) * 2.0 - 1.0,
            );
            // some near the poles, some on the seam
            let (x, z) = match i % 10 {
                0 => (x * 1e-4, z * 1e-4),
                1 => (x * 1e-3, -z.abs()),
                _ => (x, z),
            };
            let d = glam::DVec3::new(x, y, z);
            let (l, p) = lut_core::dir_to_lat_long(d);
            if scene_color_dir(x, y, z) != lut_core::scene_color(l, p) {
                differ += 1;
            }
        }
        assert!(differ <= n / 100_000, "{differ} of {n} differ");
        // the exact poles and axes
        for (x, y, z) in [
            (0.0, 1.0, 0.0),
            (0.0, -1.0, 0.0),
            (0.0, 0.0, 1.0),
            (0.0, 0.0, -1.0),
            (1.0, 0.0, 0.0),
        ] {
            let (l, p) = lut_core::dir_to_lat_long(glam::DVec3::new(x, y, z));
            assert_eq!(
                scene_color_dir(x, y, z),
                lut_core::scene_color(l, p),
                "{x} {y} {z}"
            );
        }
    }

    #[test]
    fn grain_is_bounded_varied_and_constant_over_its_blocks() {
        let mut row = vec![0i32; 64];
        grain_row(Face::Front, 0, 0, 1, &mut row);
        assert!(row.iter().all(|g| g.abs() <= GRAIN));
        let distinct: std::collections::HashSet<i32> = row.iter().copied().collect();
        assert!(distinct.len() > GRAIN as usize, "{row:?}");
        // layers 3 and 4 alone (all five minus the first three): constant over 8-pixel
        // blocks, and the same whatever the row's first column
        let layers = |x0: u32, y: u32, n: u32| {
            let mut v = vec![0i32; 40];
            grain_row(Face::Up, x0, y, n, &mut v);
            v
        };
        let coarse: Vec<i32> = layers(8, 16, 5)
            .iter()
            .zip(layers(8, 16, 3))
            .map(|(a, b)| a - b)
            .collect();
        for b in coarse.chunks(8) {
            assert!(b.iter().all(|&v| v == b[0]), "{coarse:?}");
        }
        assert_eq!(layers(8, 16, 5)[5..], layers(13, 16, 5)[..35]);
        // rows in one 8-row block share layer 3 and above
        let c2: Vec<i32> = layers(8, 23, 5)
            .iter()
            .zip(layers(8, 23, 3))
            .map(|(a, b)| a - b)
            .collect();
        assert_eq!(coarse, c2);
        // other faces: other grain
        let mut c = vec![0i32; 64];
        grain_row(Face::Back, 0, 0, 1, &mut c);
        assert_ne!(row, c);
    }

    /// Without grain, rendered tiles are the scene pixel by pixel: within one level but
    /// where an interpolated position crosses a line's edge (a few pixels in a thousand).
    #[test]
    fn rendered_faces_are_the_scene() {
        for (face, n, x0, y0) in [
            (Face::Front, 648, 0, 0),
            (Face::Up, 648, 100, 200),
            (Face::Back, 2600, 1000, 1000),
            (Face::Right, 83440, 40000, 512),
            (Face::Down, 83440, 41000, 41000),
            (Face::Back, 83440, 41500, 30000),
        ] {
            let (w, h) = (300u32, 40u32);
            let mut out = vec![0u8; (3 * w * h) as usize];
            render(face, n, (x0, y0, w), 0, &mut out);
            let mut far = 0;
            for (k, p) in out.chunks_exact(3).enumerate() {
                let (x, y) = (x0 + k as u32 % w, y0 + k as u32 / w);
                let d = super::super::source::pixel_dir(face, n, x, y);
                let (l, ph) = lut_core::dir_to_lat_long(d);
                let c = lut_core::scene_color(l, ph);
                let want = [(c >> 16) as u8, (c >> 8) as u8, c as u8];
                if p.iter().zip(want).any(|(a, b)| a.abs_diff(b) > 1) {
                    far += 1;
                }
            }
            assert!(
                far * 200 <= w * h,
                "{face:?} {n}: {far} pixels differ by more than 1"
            );
        }
    }
}
