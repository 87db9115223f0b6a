//! The exact mapping: output pixel (or image point) → ray (in the view's output
//! projection) → (λ, φ) → map (u, v), in f64. The yardstick of every fast path (`render/exact.rs` samples it; the accuracy
//! metric compares against it).

use crate::geom::camera::{dir_to_lat_long, Camera};
use crate::geom::projection::Projection;

/// Exact map position of the center of output pixel (x, y), or `None` when the map does
/// not cover that direction (or the view's projection has none there).
#[inline]
pub fn exact_uv(
    cam: &Camera,
    projection: Projection,
    map_w: f64,
    map_h: f64,
    x: u32,
    y: u32,
) -> Option<(f64, f64)> {
    exact_uv_at(
        cam,
        projection,
        map_w,
        map_h,
        x as f64 + 0.5,
        y as f64 + 0.5,
    )
}

/// Exact map position of an arbitrary image-plane point (used for supersampling).
#[inline]
pub fn exact_uv_at(
    cam: &Camera,
    projection: Projection,
    map_w: f64,
    map_h: f64,
    px: f64,
    py: f64,
) -> Option<(f64, f64)> {
    let (lambda, phi) = dir_to_lat_long(cam.ray(px, py)?);
    projection.uv(lambda, phi, map_w, map_h)
}

/// atan2(y, x) to within 1e-9 radians of `f64::atan2` (unit test), in about a fifth of
/// its instructions: octant reduction to |z| ≤ tan(π/8) and the Taylor series of atan
/// to z^21 (its remainder is below 0.42^23/23 < 2e-10). For the exact pixels of frames
/// with a level per region that read a level coarser than the map, where 1e-9 rad is
/// below 1e-5 pixels of any map up to 65536 wide (`render/scanline.rs`, `exact_run`).
#[inline]
pub(crate) fn atan2_fast(y: f64, x: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    const TAN_PI_8: f64 = 0.414_213_562_373_095_03;
    let (ax, ay) = (x.abs(), y.abs());
    let swap = ay > ax;
    let (lo, hi) = if swap { (ax, ay) } else { (ay, ax) };
    if hi == 0.0 || hi.is_nan() || hi.is_infinite() || lo.is_nan() {
        return y.atan2(x);
    }
    let a = lo / hi;
    let (z, base) = if a > TAN_PI_8 {
        ((a - 1.0) / (a + 1.0), FRAC_PI_4)
    } else {
        (a, 0.0)
    };
    let z2 = z * z;
    // Σ (−1)^n z^(2n+1) / (2n+1), n = 0..=10, by Horner in z².
    let mut p = -1.0 / 21.0;
    for c in [
        1.0 / 19.0,
        -1.0 / 17.0,
        1.0 / 15.0,
        -1.0 / 13.0,
        1.0 / 11.0,
        -1.0 / 9.0,
        1.0 / 7.0,
        -1.0 / 5.0,
        1.0 / 3.0,
    ] {
        p = p * z2 + c;
    }
    let p = -p * z2 + 1.0;
    let mut r = base + z * p;
    if swap {
        r = FRAC_PI_2 - r;
    }
    if x.is_sign_negative() {
        r = PI - r;
    }
    r.copysign(y)
}

#[cfg(test)]
mod atan2_tests {
    use super::atan2_fast;

    /// Within 1e-9 rad of `f64::atan2` on every octant, the axes, signed zeros and
    /// magnitudes from 1e-12 to 1e12.
    #[test]
    fn atan2_fast_is_atan2() {
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut worst: f64 = 0.0;
        for _ in 0..200_000 {
            let m = 10f64.powf(next() * 24.0 - 12.0);
            let (y, x) = ((next() * 2.0 - 1.0) * m, (next() * 2.0 - 1.0));
            for (y, x) in [(y, x), (x, y), (y, 0.0), (0.0, x), (y, -0.0), (-0.0, x)] {
                let (a, b) = (atan2_fast(y, x), y.atan2(x));
                worst = worst.max((a - b).abs());
                assert!((a - b).abs() <= 1e-9, "atan2({y}, {x}): {a} against {b}");
            }
        }
        for (y, x) in [
            (0.0, 0.0),
            (-0.0, 0.0),
            (0.0, -0.0),
            (-0.0, -0.0),
            (1.0, 1.0),
            (-1.0, -1.0),
        ] {
            assert!((atan2_fast(y, x) - y.atan2(x)).abs() <= 1e-15, "{y} {x}");
            assert_eq!(
                atan2_fast(y, x).is_sign_negative(),
                y.atan2(x).is_sign_negative()
            );
        }
        eprintln!("worst {worst:e}");
    }
}
