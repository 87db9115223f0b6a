//! Fixed-point formats.
//!
//! * [`Fx`]: map coordinates in **Q.16** (16 fractional bits) held in `i64`. Per-pixel
//!   index interpolation steps these by an integer increment; `i64` means no overflow for
//!   any supported map width, and on x86-64 an `i64` add costs what an `i32` add does.
//! * Table entries are `i32` in **Q15.16** (see [`crate::LutTable`]): ±32767 map pixels, enough
//!   for the folded one-eighth region of maps up to 131 068 pixels wide.
//! * Bilinear weights are 8-bit (`0..=255` out of 256), so two colour channels blend in
//!   one `u32` (see [`crate::EnvMap`]). Weight quantization moves a sample by at most
//!   1/512 pixel and is the same for every renderer, exact included.

/// Fractional bits of [`Fx`].
pub const FX_BITS: u32 = 16;
/// 1.0 in [`Fx`].
pub const FX_ONE: i64 = 1 << FX_BITS;
/// 0.5 in [`Fx`].
pub const FX_HALF: i64 = 1 << (FX_BITS - 1);

/// A map coordinate in Q.16 fixed point.
pub type Fx = i64;

/// f64 → Q.16, rounded to nearest. Saturates (never overflows) for huge inputs.
#[inline]
pub fn to_fx(x: f64) -> Fx {
    let s = x * FX_ONE as f64;
    // `as` saturates on overflow and maps NaN to 0; callers never pass NaN.
    s.round() as i64
}

/// Q.16 → f64.
#[inline]
pub fn from_fx(x: Fx) -> f64 {
    x as f64 / FX_ONE as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn round_trip() {
        for v in [0.0, 0.5, -0.25, 65535.75, -1e-6, 131071.0] {
            assert!((from_fx(to_fx(v)) - v).abs() <= 0.5 / FX_ONE as f64);
        }
        assert_eq!(to_fx(-0.5), -FX_HALF);
    }
}
