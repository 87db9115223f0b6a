//! The x86-64 forms of the shading row: 8 pixels per step with AVX2 (the table read
//! with gathers) and 16 with AVX-512 (F, BW, VBMI): k changes slowly across a frame, so
//! many runs of 16 pixels use one table row (all of them with no light in view, about a
//! third next to eight lights in the benchmark's view); that row is held in four
//! registers and read with byte permutes (`vpermi2b`: 64 bytes, 16 pixels, per
//! instruction and 128 table entries), no memory access per pixel; the other runs take
//! 16-lane gathers. Both write what `scalar.rs` writes (`kernel/tests/`).
//!
//! `unsafe` is confined to the intrinsics' pointer arguments and the call of a
//! `target_feature` function, each justified where it is used.

#![allow(unsafe_code)]

use super::{scalar, Light, ShadeTable, BASE_BITS, ROWS, SHIFT};
use crate::render::kernel::select::{Kernel, SelectedKernel};
use std::arch::x86_64::*;

/// The shading row with a SIMD form of kernel `k`; `false` (nothing written) where it
/// has none (SSE4.1 and scalar run the scalar form; AVX-512 without VBMI the AVX2 one).
#[inline]
pub(super) fn shade_row(
    k: SelectedKernel,
    t: ShadeTable,
    row: &mut [u32],
    lux: &[f32],
    l: Light,
) -> bool {
    match k.0 {
        Kernel::Avx512 if std::arch::is_x86_feature_detected!("avx512vbmi") => {
            // SAFETY: `k` is a `SelectedKernel`, made only when the CPU runs the kernel:
            // `Kernel::Avx512` has AVX2, AVX-512 F and BW; VBMI was checked above.
            unsafe { shade_row_avx512_impl(t.bytes, row, lux, l.ambient, l.exposure) }
        }
        // SAFETY: as above (an AVX-512 CPU runs AVX2).
        Kernel::Avx2 | Kernel::Avx512 => unsafe {
            shade_row_avx2_impl(t.bytes, row, lux, l.ambient, l.exposure)
        },
        Kernel::Sse41 | Kernel::Scalar => return false,
    }
    true
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
fn shade_row_avx512_impl(t: &[u8], pixels: &mut [u32], lux: &[f32], ambient: f32, exposure: f32) {
    let n = pixels.len().min(lux.len());
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
                let c =
                    _mm512_and_si512(_mm512_srlv_epi32(px, _mm512_set1_epi32(shift as i32)), byte);
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
    shade_row_avx2_impl(t, tail, lux_tail, ambient, exposure);
}

#[target_feature(enable = "avx2")]
fn shade_row_avx2_impl(t: &[u8], pixels: &mut [u32], lux: &[f32], ambient: f32, exposure: f32) {
    let n = pixels.len().min(lux.len());
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
    scalar::shade_row(ShadeTable { bytes: t }, tail, lux_tail, ambient, exposure);
    debug_assert!(ROWS * 256 + 3 <= t.len() && ShadeTable::row_of(0.0) == 0);
}
