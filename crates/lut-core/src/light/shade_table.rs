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
//! The row loop has a scalar form and, on x86-64 (detected at run time), an 8-pixel AVX2
//! form that reads the table with gathers and a 16-pixel AVX-512 form (F, BW, VBMI): k
//! changes slowly across a frame, so many runs of 16 pixels use one table row (all of
//! them with no light in view, about a third next to eight lights in the benchmark's
//! view); that row is held in four registers and read with byte permutes (`vpermi2b`:
//! 64 bytes, 16 pixels, per instruction and 128 table entries), no memory access per
//! pixel; the other runs take 16-lane gathers. All forms write the same bytes (tested).

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
/// (Off x86-64 both flags are false and read only by the tests.)
#[derive(Debug, Clone, Copy)]
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
pub(crate) struct ShadeRow {
    avx2: bool,
    avx512: bool,
}

impl ShadeRow {
    /// The fastest form this CPU runs.
    pub(crate) fn detect() -> ShadeRow {
        #[cfg(target_arch = "x86_64")]
        let (avx2, avx512) = {
            use std::arch::is_x86_feature_detected as has;
            let avx2 = has!("avx2");
            (
                avx2,
                avx2 && has!("avx512f") && has!("avx512bw") && has!("avx512vbmi"),
            )
        };
        #[cfg(not(target_arch = "x86_64"))]
        let (avx2, avx512) = (false, false);
        // Build the table now, not inside the first row.
        let _ = table();
        ShadeRow { avx2, avx512 }
    }

    /// The forms this CPU runs, the fastest first (for tests: each is checked against
    /// the scalar form).
    #[cfg(test)]
    pub(crate) fn all() -> Vec<ShadeRow> {
        let best = ShadeRow::detect();
        let mut v = vec![best];
        if best.avx512 {
            v.push(ShadeRow {
                avx512: false,
                ..best
            });
        }
        if best.avx2 {
            v.push(ShadeRow {
                avx2: false,
                avx512: false,
            });
        }
        v
    }

    /// Shade `pixels` (0RGB albedo) in place with light factor ambient + exposure · E
    /// per pixel, E from `lux`.
    #[inline]
    pub(crate) fn run(self, pixels: &mut [u32], lux: &[f32], ambient: f32, exposure: f32) {
        #[cfg(target_arch = "x86_64")]
        if self.avx512 {
            simd::shade_row_avx512(pixels, lux, ambient, exposure);
            return;
        }
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

    /// [`super::shade_row_scalar`] with AVX-512 (F, BW, VBMI) and AVX2; the caller has
    /// checked that the CPU has them ([`super::ShadeRow::detect`]).
    pub(super) fn shade_row_avx512(pixels: &mut [u32], lux: &[f32], ambient: f32, exposure: f32) {
        // SAFETY: only called after `is_x86_feature_detected!` returned true for avx2,
        // avx512f, avx512bw and avx512vbmi.
        unsafe { shade_row_avx512_impl(pixels, lux, ambient, exposure) }
    }

    /// The 256 entries of table row `r` (≤ ROWS − 1) as four registers.
    #[target_feature(enable = "avx512f")]
    fn load_row(t: &[u8], r: usize) -> [__m512i; 4] {
        let row = &t[r * 256..r * 256 + 256];
        // SAFETY: `row` holds 256 bytes: four unaligned 64-byte loads inside it.
        unsafe {
            let p = row.as_ptr();
            [
                _mm512_loadu_si512(p.cast()),
                _mm512_loadu_si512(p.add(64).cast()),
                _mm512_loadu_si512(p.add(128).cast()),
                _mm512_loadu_si512(p.add(192).cast()),
            ]
        }
    }

    /// Each byte `i` of `idx` replaced by entry `i` of the table row `row`.
    #[target_feature(enable = "avx512f,avx512bw,avx512vbmi")]
    fn lookup(row: &[__m512i; 4], idx: __m512i) -> __m512i {
        let lo = _mm512_permutex2var_epi8(row[0], idx, row[1]);
        let hi = _mm512_permutex2var_epi8(row[2], idx, row[3]);
        _mm512_mask_blend_epi8(_mm512_movepi8_mask(idx), lo, hi)
    }

    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vbmi")]
    fn shade_row_avx512_impl(pixels: &mut [u32], lux: &[f32], ambient: f32, exposure: f32) {
        let n = pixels.len().min(lux.len());
        let t = table();
        let (head, tail) = pixels[..n].split_at_mut(n - n % 16);
        let (lux_head, lux_tail) = lux[..n].split_at(n - n % 16);
        let a = _mm512_set1_ps(ambient);
        let x = _mm512_set1_ps(exposure);
        let base = _mm512_set1_epi32(BASE_BITS);
        let one = _mm512_set1_epi32(1);
        let zero = _mm512_setzero_si512();
        let top = _mm512_set1_epi32(ROWS as i32 - 1);
        let rgb = _mm512_set1_epi32(0xff_ffff);
        let byte = _mm512_set1_epi32(0xff);
        // The table row held in registers, and its number.
        let mut first = usize::MAX;
        let mut held = [zero; 4];
        for (p16, e16) in head.chunks_exact_mut(16).zip(lux_head.chunks_exact(16)) {
            // SAFETY: `e16` and `p16` hold exactly 16 f32 / u32 (chunks_exact); loadu
            // takes unaligned pointers.
            let e = unsafe { _mm512_loadu_ps(e16.as_ptr()) };
            // The rows as in `row_of` (k < 0, sign bit set, → row 0).
            let bits = _mm512_castps_si512(_mm512_add_ps(a, _mm512_mul_ps(x, e)));
            let mut row = _mm512_add_epi32(
                _mm512_srai_epi32::<{ SHIFT }>(_mm512_sub_epi32(bits, base)),
                one,
            );
            row = _mm512_min_epi32(_mm512_max_epi32(row, zero), top);
            let negative = _mm512_cmplt_epi32_mask(bits, zero);
            row = _mm512_maskz_mov_epi32(!negative, row);
            // SAFETY: as for the load above.
            let px = unsafe { _mm512_loadu_si512(p16.as_ptr().cast()) };
            let r0 = _mm_cvtsi128_si32(_mm512_castsi512_si128(row));
            let out = if _mm512_cmpneq_epi32_mask(row, _mm512_set1_epi32(r0)) == 0 {
                // One table row for all 16 pixels: read it with byte permutes.
                let r0 = r0 as usize;
                if r0 != first {
                    first = r0;
                    held = load_row(t, r0);
                }
                lookup(&held, px)
            } else {
                // Rows differ: one gather per channel.
                let off = _mm512_slli_epi32::<8>(row);
                let p = t.as_ptr().cast::<i32>();
                let ch = |shift: u32| {
                    let c = _mm512_and_si512(
                        _mm512_srlv_epi32(px, _mm512_set1_epi32(shift as i32)),
                        byte,
                    );
                    // SAFETY: every index is row·256 + byte ≤ (ROWS − 1)·256 + 255 and the
                    // table has 3 bytes of padding after that: each 4-byte read is inside.
                    let g = unsafe { _mm512_i32gather_epi32::<1>(_mm512_add_epi32(off, c), p) };
                    _mm512_sllv_epi32(_mm512_and_si512(g, byte), _mm512_set1_epi32(shift as i32))
                };
                _mm512_or_si512(_mm512_or_si512(ch(16), ch(8)), ch(0))
            };
            // SAFETY: as for the loads above.
            unsafe { _mm512_storeu_si512(p16.as_mut_ptr().cast(), _mm512_and_si512(out, rgb)) };
        }
        shade_row_avx2_impl(tail, lux_tail, ambient, exposure);
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
        for len in [0, 1, 7, 8, 9, 15, 16, 17, 63, 1000] {
            for (a, x) in [(0.15, 1.0 / 300.0), (0.0, 1.0), (1.0, 0.0)] {
                let mut s = pixels[..len].to_vec();
                shade_row_scalar(&mut s, &lux[..len], a, x);
                let mut f = pixels[..len].to_vec();
                shade_row(&mut f, &lux[..len], a, x);
                assert_eq!(s, f, "len {len}");
            }
        }
    }

    #[test]
    fn every_form_agrees_with_the_scalar_one_on_smooth_and_rough_rows() {
        // Smooth ramps of E (runs of 16 on one table row, on two adjacent rows, and on
        // more: every path of the AVX-512 form), steps, the ends of the table (rows 0 and
        // ROWS − 1, where the second row is clamped), negative and huge k; pixels with
        // every byte value in every channel, and a top byte that must not leak through.
        let n = 4096;
        let pixels: Vec<u32> = (0..n as u32)
            .map(|i| i.wrapping_mul(2_654_435_761) ^ (i << 24))
            .collect();
        let mut rows: Vec<Vec<f32>> = Vec::new();
        for slope in [0.0f32, 1e-4, 1e-3, 3e-3, 1e-2, 0.1] {
            rows.push((0..n).map(|i| 300.0 * (1.0 + slope * i as f32)).collect());
        }
        rows.push(
            (0..n)
                .map(|i| if i % 40 < 20 { 10.0 } else { 5000.0 })
                .collect(),
        );
        rows.push((0..n).map(|i| (i as f32 - 2000.0) * 0.5).collect());
        rows.push(vec![1e30; n]);
        rows.push(vec![0.0; n]);
        rows.push(
            (0..n)
                .map(|i| 2f32.powf(-13.0 + i as f32 * 30.0 / n as f32))
                .collect(),
        );
        for form in ShadeRow::all() {
            for lux in &rows {
                for (a, x) in [(0.15, 1.0 / 300.0), (0.0, 1.0), (1.0, 0.0), (0.0, 1e-4)] {
                    for (start, len) in [(0, n), (3, 1000), (5, 17), (0, 31)] {
                        let mut s = pixels[start..start + len].to_vec();
                        shade_row_scalar(&mut s, &lux[start..start + len], a, x);
                        let mut f = pixels[start..start + len].to_vec();
                        form.run(&mut f, &lux[start..start + len], a, x);
                        assert_eq!(s, f, "{form:?}, a {a}, x {x}, {start}+{len}");
                    }
                }
            }
        }
    }
}
