//! The AVX2 node blend (see `nodes/mod.rs`; `Kernel::Avx512` runs it too): 4 values
//! (2 nodes of Λ, V) per step in `f64` lanes. Every step is exact there: the values are
//! `i32`, so bot − top has at most 33 bits, (bot − top)·wa/2^16 at most 50 significant
//! bits (wa ≤ 2^16; the division only moves the exponent), its floor is the arithmetic
//! shift `>> 16`, and top plus it (between top and bot) converts back to `i32` exactly.
//! (The same in `i64` lanes, with `_mm256_mul_epi32`, was rewritten by the compiler into
//! a general 64-bit multiply: 10 instructions a node against about 5 here.)

#![allow(unsafe_code)]

use super::NodeRows;
use crate::render::kernel::select::{Kernel, SelectedKernel};
use std::arch::x86_64::*;

/// Blend with a SIMD kernel; `false` (nothing written) for the others.
#[inline(always)]
pub(super) fn blend(k: SelectedKernel, rows: NodeRows<'_>, out: &mut [[i32; 2]]) -> bool {
    match k.0 {
        // SAFETY: `k` is a `SelectedKernel`, made only when the CPU runs the kernel (an
        // AVX-512 CPU runs AVX2).
        Kernel::Avx2 | Kernel::Avx512 => unsafe { avx2(rows, out) },
        Kernel::Sse41 | Kernel::Scalar => return false,
    }
    true
}

#[target_feature(enable = "avx2")]
fn avx2(rows: NodeRows<'_>, out: &mut [[i32; 2]]) {
    let NodeRows { top, bot, wa } = rows;
    let n = out.len();
    let (top, bot) = (&top[..n], &bot[..n]);
    // wa/2^16, exact (wa ≤ 2^16).
    let w = _mm256_set1_pd(wa as f64 / 65536.0);
    let mut j = 0;
    while j + 2 <= n {
        // SAFETY: nodes j..j + 2 of each slice exist (j + 2 ≤ n = every length): 16
        // bytes, unaligned loads and store.
        unsafe {
            let t = _mm256_cvtepi32_pd(_mm_loadu_si128(top.as_ptr().add(j).cast()));
            let b = _mm256_cvtepi32_pd(_mm_loadu_si128(bot.as_ptr().add(j).cast()));
            let d = _mm256_floor_pd(_mm256_mul_pd(_mm256_sub_pd(b, t), w));
            let r = _mm256_cvttpd_epi32(_mm256_add_pd(t, d));
            _mm_storeu_si128(out.as_mut_ptr().add(j).cast(), r);
        }
        j += 2;
    }
    for ((o, a), c) in out[j..].iter_mut().zip(&top[j..]).zip(&bot[j..]) {
        *o = [blend1(a[0], c[0], wa), blend1(a[1], c[1], wa)];
    }
}

/// One value, as `lut::Band::blend_nodes` blends it.
#[inline(always)]
fn blend1(top: i32, bot: i32, wa: i64) -> i32 {
    (top as i64 + (((bot as i64 - top as i64) * wa) >> 16)) as i32
}
