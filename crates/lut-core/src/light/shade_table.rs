//! The colour arithmetic of the interactive path as one table: light factor × sRGB byte →
//! sRGB byte.
//!
//! The exact path ([`super::shade`]) multiplies in linear light per channel: decode the
//! sRGB byte, multiply by the light factor k, encode — about 25 instructions per channel.
//! Here k is quantized on a logarithmic scale, 64 steps per octave from 2⁻¹² to 2¹² (the
//! f32 exponent and the top 6 bits of its mantissa: the step is 0.8–1.6 %, so the
//! quantized factor is within ±0.8 % of k), and the table holds, for each step and each
//! byte, the exact path's result at the step's centre; a channel is then one load. ±0.8 %
//! of k moves an sRGB value by at most ±0.33 %, under a level, so a shaded channel is
//! within one level of the exact path's (tested for every byte over the whole range).
//! k below 2⁻¹² gives black, above 2¹² the last step (every byte but 0 already saturates).
//!
//! The row loop has a scalar form and, on x86-64 with AVX2 (detected at run time), an
//! 8-pixel form that reads the table with gathers; both write the same bytes (tested).

use super::shade::{decode_lut, encode, encode_lut};
use std::sync::OnceLock;

/// Table rows per octave of k = 2^(23 − SHIFT).
const SHIFT: u32 = 17;
/// The smallest and largest k (as powers of two) the table spans.
const K_MIN_EXP: i32 = -12;
const K_MAX_EXP: i32 = 12;
/// The f32 bits of 2^K_MIN_EXP.
const BASE_BITS: i32 = (127 + K_MIN_EXP) << 23;
/// Row 0 is black (k below the range); then 64 rows per octave.
pub(crate) const ROWS: usize = 1 + (((K_MAX_EXP - K_MIN_EXP) as usize) << (23 - SHIFT));

/// The row of light factor `k` (≥ 0; anything not above 0 is row 0, black).
#[inline]
pub(crate) fn row_of(k: f32) -> usize {
    let bits = k.to_bits() as i32;
    // Negative k has the sign bit set: row 0 (before the subtraction could wrap).
    if bits < 0 {
        return 0;
    }
    let i = ((bits - BASE_BITS) >> SHIFT) + 1;
    i.clamp(0, ROWS as i32 - 1) as usize
}

/// The light factor row `r` stands for (the centre of its range of f32 bit patterns).
fn factor_of(r: usize) -> f32 {
    if r == 0 {
        return 0.0;
    }
    f32::from_bits((BASE_BITS + (((r - 1) as i32) << SHIFT) + (1 << (SHIFT - 1))) as u32)
}

/// ROWS × 256 shaded bytes, plus 3 bytes of padding so a 4-byte gather at the last byte
/// stays inside.
pub(crate) fn table() -> &'static [u8] {
    static TABLE: OnceLock<Vec<u8>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let (dec, enc) = (decode_lut(), encode_lut());
        let mut t = vec![0u8; ROWS * 256 + 3];
        for r in 1..ROWS {
            let k = factor_of(r);
            for c in 0..256 {
                t[r * 256 + c] = encode(dec[c] * k, enc) as u8;
            }
        }
        t
    })
}

/// The form of the row loop this CPU runs (detected once, see [`ShadeRow::detect`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ShadeRow {
    avx2: bool,
}

impl ShadeRow {
    /// The fastest form this CPU runs.
    pub(crate) fn detect() -> ShadeRow {
        #[cfg(target_arch = "x86_64")]
        let avx2 = std::arch::is_x86_feature_detected!("avx2");
        #[cfg(not(target_arch = "x86_64"))]
        let avx2 = false;
        // Build the table now, not inside the first row.
        let _ = table();
        ShadeRow { avx2 }
    }

    /// Shade `pixels` (0RGB albedo) in place with light factor ambient + exposure · E
    /// per pixel, E from `lux`.
    #[inline]
    pub(crate) fn run(self, pixels: &mut [u32], lux: &[f32], ambient: f32, exposure: f32) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            simd::shade_row_avx2(pixels, lux, ambient, exposure);
            return;
        }
        shade_row_scalar(pixels, lux, ambient, exposure);
    }
}

/// Shade `pixels` (0RGB albedo) in place with light factor ambient + exposure · E per
/// pixel, E from `lux`; the fastest form this CPU runs.
#[cfg(test)]
pub(crate) fn shade_row(pixels: &mut [u32], lux: &[f32], ambient: f32, exposure: f32) {
    ShadeRow::detect().run(pixels, lux, ambient, exposure);
}

/// The portable form of [`shade_row`].
pub(crate) fn shade_row_scalar(pixels: &mut [u32], lux: &[f32], ambient: f32, exposure: f32) {
    let t = table();
    for (p, &e) in pixels.iter_mut().zip(lux) {
        let row: &[u8; 256] = t[row_of(ambient + exposure * e) * 256..][..256]
            .try_into()
            .expect("a table row has 256 entries");
        let [b, g, r, _] = p.to_le_bytes();
        *p =
            (row[r as usize] as u32) << 16 | (row[g as usize] as u32) << 8 | row[b as usize] as u32;
    }
}

#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod simd {
    //! The AVX2 form of the row loop: 8 pixels per step, the table read by gathers.
    //! `unsafe` is confined to the intrinsics' pointer arguments and the call of a
    //! `target_feature` function, each justified where it is used.

    use super::{row_of, shade_row_scalar, table, BASE_BITS, ROWS, SHIFT};
    use std::arch::x86_64::*;

    /// [`super::shade_row_scalar`] with AVX2; the caller has checked that the CPU has it
    /// ([`super::ShadeRow::detect`]).
    pub(super) fn shade_row_avx2(pixels: &mut [u32], lux: &[f32], ambient: f32, exposure: f32) {
        // SAFETY: only called after `is_x86_feature_detected!("avx2")` returned true.
        unsafe { shade_row_avx2_impl(pixels, lux, ambient, exposure) }
    }

    #[target_feature(enable = "avx2")]
    fn shade_row_avx2_impl(pixels: &mut [u32], lux: &[f32], ambient: f32, exposure: f32) {
        let n = pixels.len().min(lux.len());
        let t = table();
        let (head, tail) = pixels[..n].split_at_mut(n - n % 8);
        let (lux_head, lux_tail) = lux[..n].split_at(n - n % 8);
        let a = _mm256_set1_ps(ambient);
        let x = _mm256_set1_ps(exposure);
        let base = _mm256_set1_epi32(BASE_BITS);
        let one = _mm256_set1_epi32(1);
        let zero = _mm256_setzero_si256();
        let top = _mm256_set1_epi32(ROWS as i32 - 1);
        let byte = _mm256_set1_epi32(0xff);
        for (p8, e8) in head.chunks_exact_mut(8).zip(lux_head.chunks_exact(8)) {
            // SAFETY: `e8` and `p8` hold exactly 8 f32 / u32 (chunks_exact); loadu/storeu
            // take unaligned pointers.
            let e = unsafe { _mm256_loadu_ps(e8.as_ptr()) };
            // SAFETY: as above.
            let px = unsafe { _mm256_loadu_si256(p8.as_ptr().cast()) };
            let k = _mm256_add_ps(a, _mm256_mul_ps(x, e));
            let bits = _mm256_castps_si256(k);
            // row_of: ((bits − BASE) >> SHIFT) + 1 clamped to [0, ROWS − 1]; k < 0 (sign
            // bit set) → row 0, like the scalar form.
            let mut row = _mm256_add_epi32(
                _mm256_srai_epi32::<{ SHIFT as i32 }>(_mm256_sub_epi32(bits, base)),
                one,
            );
            row = _mm256_min_epi32(_mm256_max_epi32(row, zero), top);
            let negative = _mm256_cmpgt_epi32(zero, bits);
            row = _mm256_andnot_si256(negative, row);
            let off = _mm256_slli_epi32::<8>(row);
            let r = _mm256_and_si256(_mm256_srli_epi32::<16>(px), byte);
            let g = _mm256_and_si256(_mm256_srli_epi32::<8>(px), byte);
            let b = _mm256_and_si256(px, byte);
            // SAFETY: every index is row·256 + byte ≤ (ROWS − 1)·256 + 255, and the table
            // has 3 bytes of padding after that, so each 4-byte read is inside it.
            let (gr, gg, gb) = unsafe {
                let p = t.as_ptr().cast::<i32>();
                (
                    _mm256_i32gather_epi32::<1>(p, _mm256_add_epi32(off, r)),
                    _mm256_i32gather_epi32::<1>(p, _mm256_add_epi32(off, g)),
                    _mm256_i32gather_epi32::<1>(p, _mm256_add_epi32(off, b)),
                )
            };
            let out = _mm256_or_si256(
                _mm256_or_si256(
                    _mm256_slli_epi32::<16>(_mm256_and_si256(gr, byte)),
                    _mm256_slli_epi32::<8>(_mm256_and_si256(gg, byte)),
                ),
                _mm256_and_si256(gb, byte),
            );
            // SAFETY: as for the load above.
            unsafe { _mm256_storeu_si256(p8.as_mut_ptr().cast(), out) };
        }
        shade_row_scalar(tail, lux_tail, ambient, exposure);
        debug_assert!(ROWS * 256 + 3 <= t.len() && row_of(0.0) == 0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::shade::shade_pixel;

    #[test]
    fn rows_cover_the_range_monotonically() {
        assert_eq!(row_of(0.0), 0);
        assert_eq!(row_of(-1.0), 0);
        assert_eq!(row_of(2f32.powi(-13)), 0);
        assert_eq!(row_of(1e30), ROWS - 1);
        let mut last = 0;
        for i in 0..20000 {
            let k = 2f32.powf(-13.0 + i as f32 * 26.0 / 20000.0);
            let r = row_of(k);
            assert!(r >= last);
            last = r;
            if r > 0 && r < ROWS - 1 {
                let c = factor_of(r);
                assert!((c / k - 1.0).abs() <= 0.0079, "k {k} row {r} centre {c}");
            }
        }
    }

    #[test]
    fn table_is_within_one_level_of_the_exact_arithmetic() {
        let (dec, enc) = (decode_lut(), encode_lut());
        let t = table();
        for i in 0..4000 {
            let k = 2f32.powf(-11.9 + i as f32 * 23.8 / 4000.0);
            let row = row_of(k);
            for c in 0..=255u32 {
                let exact = shade_pixel(c, k, dec, enc);
                let got = t[row * 256 + c as usize] as u32;
                assert!(exact.abs_diff(got) <= 1, "k {k} byte {c}: {got} vs {exact}");
            }
        }
    }

    #[test]
    fn simd_and_scalar_rows_agree() {
        // Every byte in every channel, light factors over the whole range and beyond, and
        // rows of every length (the SIMD form's tail).
        let pixels: Vec<u32> = (0..1000u32)
            .map(|i| i.wrapping_mul(2_654_435_761) & 0xff_ffff)
            .collect();
        let lux: Vec<f32> = (0..1000)
            .map(|i| match i % 7 {
                0 => 0.0,
                1 => 1e9,
                _ => 2f32.powf((i as f32 * 0.37) % 30.0 - 15.0) * 300.0,
            })
            .collect();
        for len in [0, 1, 7, 8, 9, 63, 1000] {
            for (a, x) in [(0.15, 1.0 / 300.0), (0.0, 1.0), (1.0, 0.0)] {
                let mut s = pixels[..len].to_vec();
                shade_row_scalar(&mut s, &lux[..len], a, x);
                let mut f = pixels[..len].to_vec();
                shade_row(&mut f, &lux[..len], a, x);
                assert_eq!(s, f, "len {len}");
            }
        }
    }
}
