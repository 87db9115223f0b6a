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
//! This file builds the table; the row loop that reads it is a kernel
//! (`render/kernel/shade/`: a scalar form, and AVX2 and AVX-512 forms on x86-64, chosen
//! with the other kernels, so `LUTPANO_KERNEL=scalar` reaches it), which also fixes the
//! table's layout (`ShadeTable`: the row of a light factor, the padding).

use super::shade::{decode_lut, encode, encode_lut};
use crate::render::kernel::{active, Light, SelectedKernel, ShadeTable};
use std::sync::OnceLock;

/// The light factor row `r` stands for (see `ShadeTable::factor_of`).
fn factor_of(r: usize) -> f32 {
    ShadeTable::factor_of(r)
}

/// The row of light factor `k` (see `ShadeTable::row_of`).
#[cfg(test)]
fn row_of(k: f32) -> usize {
    ShadeTable::row_of(k)
}

/// Rows of the table.
#[cfg(test)]
const ROWS: usize = ShadeTable::ROWS;

/// The shading table: for each row's light factor and each sRGB byte, the exact path's
/// shaded byte ([`ShadeTable`]'s layout).
pub(crate) fn table() -> ShadeTable<'static> {
    static TABLE: OnceLock<Vec<u8>> = OnceLock::new();
    let bytes = TABLE.get_or_init(|| {
        let (dec, enc) = (decode_lut(), encode_lut());
        let mut t = vec![0u8; ShadeTable::LEN];
        for r in 1..ShadeTable::ROWS {
            let k = factor_of(r);
            for c in 0..256 {
                t[r * 256 + c] = encode(dec[c] * k, enc) as u8;
            }
        }
        t
    });
    ShadeTable::new(bytes).expect("the table has ShadeTable::LEN bytes")
}

/// The shading rows with one kernel (the active one: [`ShadeRow::active`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ShadeRow {
    kernel: SelectedKernel,
}

impl ShadeRow {
    /// The rows with the active kernel (the table is built now, not inside the first
    /// row).
    pub(crate) fn active() -> ShadeRow {
        let _ = table();
        ShadeRow { kernel: active() }
    }

    /// Shade `pixels` (0RGB albedo) in place with light factor ambient + exposure · E
    /// per pixel, E from `lux`.
    #[inline]
    pub(crate) fn run(self, pixels: &mut [u32], lux: &[f32], ambient: f32, exposure: f32) {
        let light = Light { ambient, exposure };
        self.kernel.shade_row(table(), pixels, lux, light);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::shade::shade_pixel;
    use crate::render::kernel::Kernel;

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
        let t = table().bytes();
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
        let scalar = ShadeRow {
            kernel: Kernel::Scalar.selected(),
        };
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
                scalar.run(&mut s, &lux[..len], a, x);
                let mut f = pixels[..len].to_vec();
                ShadeRow::active().run(&mut f, &lux[..len], a, x);
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
        let scalar = ShadeRow {
            kernel: Kernel::Scalar.selected(),
        };
        for k in Kernel::available() {
            let form = ShadeRow {
                kernel: k.selected(),
            };
            for lux in &rows {
                for (a, x) in [(0.15, 1.0 / 300.0), (0.0, 1.0), (1.0, 0.0), (0.0, 1e-4)] {
                    for (start, len) in [(0, n), (3, 1000), (5, 17), (0, 31)] {
                        let mut s = pixels[start..start + len].to_vec();
                        scalar.run(&mut s, &lux[start..start + len], a, x);
                        let mut f = pixels[start..start + len].to_vec();
                        form.run(&mut f, &lux[start..start + len], a, x);
                        assert_eq!(s, f, "{form:?}, a {a}, x {x}, {start}+{len}");
                    }
                }
            }
        }
    }
}
