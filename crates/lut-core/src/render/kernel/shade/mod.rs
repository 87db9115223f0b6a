//! The shading rows of the lighting (`light/`): each pixel's three sRGB bytes replaced
//! through the shading table's row for its light factor `ambient + exposure · E`, E the
//! pixel's illuminance. The table itself (what each entry holds: the exact linear-light
//! arithmetic, within a level) is built by `light/shade_table.rs`; this operation owns
//! its layout: the row of a light factor ([`ShadeTable::row_of`]: 64 rows per octave of k from
//! 2⁻¹² to 2¹², the f32 exponent and the top 6 bits of its mantissa; row 0 black) and
//! `ROWS × 256` bytes plus 3 of padding ([`ShadeTable`]).
//!
//! This file holds the types and the dispatch ([`SelectedKernel::shade_row`]);
//! `scalar.rs` the portable form (the reference), `x86.rs` the AVX2 and AVX-512 (F, BW,
//! VBMI) forms. `Kernel::Sse41` runs the scalar form, `Kernel::Avx512` on a CPU without
//! VBMI the AVX2 one. Every form writes the same bytes (`kernel/tests/`: random tables,
//! pixels and illuminances, every kernel the CPU has).

use super::select::SelectedKernel;

mod scalar;
#[cfg(target_arch = "x86_64")]
mod x86;

/// Table rows per octave of k = 2^(23 − SHIFT).
const SHIFT: u32 = 17;
/// The smallest and largest k (as powers of two) the table spans.
const K_MIN_EXP: i32 = -12;
const K_MAX_EXP: i32 = 12;
/// The f32 bits of 2^K_MIN_EXP.
const BASE_BITS: i32 = (127 + K_MIN_EXP) << 23;
/// Row 0 is black (k below the range); then 64 rows per octave.
const ROWS: usize = 1 + (((K_MAX_EXP - K_MIN_EXP) as usize) << (23 - SHIFT));

/// A shading table as the kernels read it: [`ShadeTable::ROWS`] rows of 256 bytes (row `r`, entry
/// `c`: the shaded value of sRGB byte `c` under the light factor of row `r`), then 3
/// bytes of padding so a 4-byte gather at the last entry stays inside.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ShadeTable<'a> {
    bytes: &'a [u8],
}

impl<'a> ShadeTable<'a> {
    /// Bytes of a table.
    pub(crate) const LEN: usize = ROWS * 256 + 3;

    /// `None` unless `bytes` holds [`ShadeTable::LEN`] bytes.
    pub(crate) fn new(bytes: &'a [u8]) -> Option<ShadeTable<'a>> {
        (bytes.len() == Self::LEN).then_some(ShadeTable { bytes })
    }

    /// Rows of a table.
    pub(crate) const ROWS: usize = ROWS;

    /// The row of light factor `k` (≥ 0; anything not above 0 is row 0, black; above the
    /// range, the last row).
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

    /// The light factor row `r` (≥ 1) stands for: the centre of its range of f32 bit
    /// patterns (row 0 stands for 0).
    pub(crate) fn factor_of(r: usize) -> f32 {
        if r == 0 {
            return 0.0;
        }
        f32::from_bits((BASE_BITS + (((r - 1) as i32) << SHIFT) + (1 << (SHIFT - 1))) as u32)
    }

    /// The table's bytes.
    #[cfg(test)]
    pub(crate) fn bytes(&self) -> &'a [u8] {
        self.bytes
    }

    /// Row `r` (< [`ShadeTable::ROWS`]).
    #[inline(always)]
    fn row(&self, r: usize) -> &'a [u8; 256] {
        self.bytes[r * 256..][..256]
            .try_into()
            .expect("a table row has 256 entries")
    }
}

/// The light factor of a pixel: `ambient + exposure · E`, E its illuminance (lux).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Light {
    /// The factor with no light (E = 0).
    pub(crate) ambient: f32,
    /// The factor per lux.
    pub(crate) exposure: f32,
}

impl SelectedKernel {
    /// Shade `pixels` (0RGB albedo) in place through `t`: each channel byte `c` becomes
    /// entry `c` of the row of light factor `l.ambient + l.exposure · lux[i]`
    /// ([`ShadeTable::row_of`]); the top byte becomes 0. Pixels past the end of `lux` are left as
    /// they are.
    #[inline]
    pub(crate) fn shade_row(self, t: ShadeTable, pixels: &mut [u32], lux: &[f32], l: Light) {
        #[cfg(target_arch = "x86_64")]
        if x86::shade_row(self, t, pixels, lux, l) {
            return;
        }
        scalar::shade_row(t, pixels, lux, l.ambient, l.exposure);
    }
}
