//! The shading row's portable form: one pixel at a time, the reference the SIMD forms
//! (`x86.rs`) equal.

use super::ShadeTable;

/// Shade `pixels` in place with light factor `ambient + exposure · lux[i]` per pixel
/// (see `SelectedKernel::shade_row`).
pub(super) fn shade_row(
    t: ShadeTable,
    pixels: &mut [u32],
    lux: &[f32],
    ambient: f32,
    exposure: f32,
) {
    for (p, &e) in pixels.iter_mut().zip(lux) {
        let row = t.row(ShadeTable::row_of(ambient + exposure * e));
        let [b, g, r, _] = p.to_le_bytes();
        *p =
            (row[r as usize] as u32) << 16 | (row[g as usize] as u32) << 8 | row[b as usize] as u32;
    }
}
