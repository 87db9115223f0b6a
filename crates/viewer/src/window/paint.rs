//! Composing a frame on the CPU: the rendered scene, then the egui panel painted over it
//! by `egui_software_backend`, all into one 0RGB `u32` buffer (softbuffer's format).

use egui_software_backend::{BufferMutRef, ColorFieldOrder, EguiSoftwareRender};

/// Color of the window outside the scene (behind the panel), 0RGB.
pub const BACKGROUND: u32 = 0x0010_1010;

/// The scene's place in the window, in physical pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SceneRect {
    /// Left edge.
    pub x: u32,
    /// Top edge.
    pub y: u32,
    /// Width (≥ 1).
    pub w: u32,
    /// Height (≥ 1).
    pub h: u32,
}

impl SceneRect {
    /// The pixel rectangle of an egui rectangle (points) in a `win_w × win_h` window at
    /// `pixels_per_point`, rounded to whole pixels and clipped; `None` when empty.
    pub fn from_points(
        r: egui::Rect,
        pixels_per_point: f32,
        win_w: u32,
        win_h: u32,
    ) -> Option<Self> {
        let to_px = |v: f32, max: u32| -> u32 {
            let p = (v * pixels_per_point).round();
            if p.is_finite() && p > 0.0 {
                (p as u32).min(max)
            } else {
                0
            }
        };
        let (x0, y0) = (to_px(r.min.x, win_w), to_px(r.min.y, win_h));
        let (x1, y1) = (to_px(r.max.x, win_w), to_px(r.max.y, win_h));
        (x1 > x0 && y1 > y0).then_some(SceneRect {
            x: x0,
            y: y0,
            w: x1 - x0,
            h: y1 - y0,
        })
    }
}

/// Paints frames: scene copy + egui on top.
pub struct Compositor {
    egui: EguiSoftwareRender,
}

impl Default for Compositor {
    fn default() -> Self {
        Compositor::new()
    }
}

impl Compositor {
    /// A compositor for 0RGB buffers (little-endian bytes B, G, R, 0).
    pub fn new() -> Compositor {
        Compositor {
            egui: EguiSoftwareRender::new(ColorFieldOrder::Bgra),
        }
    }

    /// Fill `frame` (`w × h`) with the scene at `rect` (its pixels `scene`, `rect.w ×
    /// rect.h`) and [`BACKGROUND`] elsewhere, then paint egui's primitives over it.
    /// Texture deltas are always applied, even when the frame is empty.
    #[allow(clippy::too_many_arguments)]
    pub fn compose(
        &mut self,
        frame: &mut [u32],
        w: u32,
        h: u32,
        scene: Option<(&[u32], SceneRect)>,
        prims: &[egui::ClippedPrimitive],
        textures: &egui::TexturesDelta,
        pixels_per_point: f32,
    ) {
        let (wu, hu) = (w as usize, h as usize);
        if wu == 0 || hu == 0 || frame.len() != wu * hu {
            return;
        }
        frame.fill(BACKGROUND);
        if let Some((pixels, r)) = scene {
            let (rx, ry, rw, rh) = (r.x as usize, r.y as usize, r.w as usize, r.h as usize);
            if pixels.len() == rw * rh && rx + rw <= wu && ry + rh <= hu {
                for (dst, src) in frame
                    .chunks_exact_mut(wu)
                    .skip(ry)
                    .zip(pixels.chunks_exact(rw))
                {
                    dst[rx..rx + rw].copy_from_slice(src);
                }
            }
        }
        let bytes: &mut [[u8; 4]] = bytemuck::cast_slice_mut(frame);
        let mut target = BufferMutRef::new(bytes, wu, hu);
        self.egui
            .render(&mut target, prims, textures, pixels_per_point);
        // egui leaves coverage in the top byte; softbuffer wants 0RGB.
        for p in frame.iter_mut() {
            *p &= 0x00FF_FFFF;
        }
    }
}

/// `a` and `b` mixed with `b`'s weight `f` in 1/256, two channels per multiply
/// (products stay below 2^16 per channel, so none carries into the next).
/// `f` ≤ 256 (the callers' weights), so the sums are at most 0xFF80_FF80: the wrapping
/// operations never wrap; they only spare the overflow checks of the test profile, which
/// would stop the loops from vectorizing.
#[inline(always)]
fn mix(a: u32, b: u32, f: u32) -> u32 {
    let g = 256u32.wrapping_sub(f);
    let lerp = |mask: u32, round: u32| {
        ((a & mask)
            .wrapping_mul(g)
            .wrapping_add((b & mask).wrapping_mul(f))
            .wrapping_add(round)
            >> 8)
            & mask
    };
    lerp(0x00FF_00FF, 0x0080_0080) | lerp(0x0000_FF00, 0x0000_8000)
}

/// Fill `dst` (`dw × dh`) with `src` (`sw × sh`) scaled bilinearly, pixel centres
/// aligned (a degraded frame rendered at a lower resolution, shown at the scene's size).
/// Edges clamp. Each source row is interpolated across once and kept while the
/// destination rows between it and the next use it. Nothing happens when a buffer does
/// not match its size.
pub fn upscale_bilinear(src: &[u32], sw: u32, sh: u32, dst: &mut [u32], dw: u32, dh: u32) {
    let (sw, sh, dw, dh) = (sw as usize, sh as usize, dw as usize, dh as usize);
    if sw == 0 || sh == 0 || src.len() != sw * sh || dst.len() != dw * dh {
        return;
    }
    // For each destination column (row): the two source taps and the weight of the
    // second in 1/256.
    let taps = |dn: usize, sn: usize| -> Vec<(usize, usize, u32)> {
        (0..dn)
            .map(|i| {
                let s =
                    ((i as f64 + 0.5) * sn as f64 / dn as f64 - 0.5).clamp(0.0, (sn - 1) as f64);
                let i0 = s.floor() as usize;
                let f = ((s - i0 as f64) * 256.0).round() as u32;
                (i0, (i0 + 1).min(sn - 1), f.min(256))
            })
            .collect()
    };
    let xs = taps(dw, sw);
    let ys = taps(dh, sh);
    let across = |y: usize, out: &mut [u32]| {
        let r = &src[y * sw..][..sw];
        for (o, &(x0, x1, f)) in out.iter_mut().zip(&xs) {
            *o = mix(r[x0], r[x1], f);
        }
    };
    let (mut top, mut bottom) = (vec![0; dw], vec![0; dw]);
    let (mut have_top, mut have_bottom) = (usize::MAX, usize::MAX);
    for (row, &(y0, y1, fy)) in dst.chunks_exact_mut(dw).zip(&ys) {
        if have_top != y0 {
            if have_bottom == y0 {
                std::mem::swap(&mut top, &mut bottom);
                std::mem::swap(&mut have_top, &mut have_bottom);
            } else {
                across(y0, &mut top);
                have_top = y0;
            }
        }
        if have_bottom != y1 {
            across(y1, &mut bottom);
            have_bottom = y1;
        }
        for ((d, &a), &b) in row.iter_mut().zip(&top).zip(&bottom) {
            *d = mix(a, b, fy);
        }
    }
}

/// The window icon: a globe with a latitude/longitude grid, `ICON_SIZE`² RGBA, drawn
/// here so no image file is needed.
pub const ICON_SIZE: u32 = 64;

/// RGBA bytes of the window icon (transparent outside the globe).
pub fn icon_rgba() -> Vec<u8> {
    let n = ICON_SIZE as usize;
    let r = n as f64 / 2.0 - 1.0;
    let mut px = vec![0u8; n * n * 4];
    for (i, p) in px.chunks_exact_mut(4).enumerate() {
        let x = ((i % n) as f64 + 0.5 - n as f64 / 2.0) / r;
        let y = (n as f64 / 2.0 - (i / n) as f64 - 0.5) / r;
        let d2 = x * x + y * y;
        if d2 > 1.0 {
            continue;
        }
        // The sphere seen from the front, turned a little so meridians curve.
        let z = (1.0 - d2).sqrt();
        let lon = x.atan2(z) + 0.4;
        let lat = y.asin();
        let grid = |a: f64, step: f64| ((a / step).fract().abs() - 0.5).abs() > 0.42;
        let on_line = grid(lon.to_degrees() + 360.0, 30.0) || grid(lat.to_degrees() + 90.0, 30.0);
        let shade = 0.55 + 0.45 * z;
        let (cr, cg, cb) = if on_line {
            (235.0, 240.0, 250.0)
        } else {
            (40.0, 110.0, 200.0)
        };
        let edge = ((1.0 - d2.sqrt()) * r).clamp(0.0, 1.0);
        p.copy_from_slice(&[
            (cr * shade) as u8,
            (cg * shade) as u8,
            (cb * shade) as u8,
            (255.0 * edge) as u8,
        ]);
    }
    px
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn upscale_keeps_flat_areas_and_interpolates_between() {
        // 2×1 → 4×2: the outer pixels keep the source colours, the inner ones mix them.
        let src = [0x0000_0000, 0x00FF_FFFF];
        let mut dst = vec![0; 8];
        upscale_bilinear(&src, 2, 1, &mut dst, 4, 2);
        assert_eq!(dst[0], 0);
        assert_eq!(dst[3], 0x00FF_FFFF);
        assert_eq!(dst[1], 0x0040_4040);
        assert_eq!(dst[2], 0x00BF_BFBF);
        assert_eq!(&dst[..4], &dst[4..]);
        // A flat image stays flat at any size; mismatched buffers are left alone.
        let flat = vec![0x0012_3456; 3 * 2];
        let mut big = vec![0; 10 * 7];
        upscale_bilinear(&flat, 3, 2, &mut big, 10, 7);
        assert!(big.iter().all(|&p| p == 0x0012_3456));
        let mut untouched = vec![7; 4];
        upscale_bilinear(&flat, 3, 3, &mut untouched, 2, 2);
        assert_eq!(untouched, [7; 4]);
    }

    /// A half-resolution frame of the window's size: every output pixel lies between
    /// its four source neighbours, channel by channel, and a linear ramp stays linear.
    #[test]
    fn upscale_a_half_resolution_frame() {
        let (sw, sh, dw, dh) = (400u32, 250u32, 800u32, 500u32);
        let src: Vec<u32> = (0..sw * sh)
            .map(|i| {
                let (x, y) = (i % sw, i / sw);
                ((x * 255 / (sw - 1)) << 16) | ((y * 255 / (sh - 1)) << 8) | ((x * 7 + y * 3) % 256)
            })
            .collect();
        let mut dst = vec![0; (dw * dh) as usize];
        upscale_bilinear(&src, sw, sh, &mut dst, dw, dh);
        let ch = |p: u32, s: u32| (p >> s) & 255;
        for y in 0..dh {
            for x in 0..dw {
                let p = dst[(y * dw + x) as usize];
                // Its taps are among the 3×3 source pixels around (x/2, y/2).
                let (sx, sy) = (x / 2, y / 2);
                let n: Vec<u32> = (sy.saturating_sub(1)..=(sy + 1).min(sh - 1))
                    .flat_map(|b| {
                        (sx.saturating_sub(1)..=(sx + 1).min(sw - 1)).map(move |a| (a, b))
                    })
                    .map(|(a, b)| src[(b * sw + a) as usize])
                    .collect();
                for s in [16, 8, 0] {
                    let lo = n.iter().map(|&q| ch(q, s)).min().unwrap();
                    let hi = n.iter().map(|&q| ch(q, s)).max().unwrap();
                    assert!((lo..=hi).contains(&ch(p, s)), "({x},{y}) channel {s}");
                }
            }
        }
        // Red is a horizontal ramp: monotone along every row.
        for row in dst.chunks_exact(dw as usize) {
            assert!(row.windows(2).all(|w| ch(w[0], 16) <= ch(w[1], 16)));
        }
    }

    #[test]
    fn the_icon_is_a_globe_on_transparency() {
        let px = icon_rgba();
        assert_eq!(px.len(), (ICON_SIZE * ICON_SIZE * 4) as usize);
        let alpha = |x: u32, y: u32| px[((y * ICON_SIZE + x) * 4 + 3) as usize];
        assert_eq!(alpha(0, 0), 0, "corners transparent");
        assert_eq!(alpha(ICON_SIZE / 2, ICON_SIZE / 2), 255, "centre opaque");
        let lines = px
            .chunks_exact(4)
            .filter(|p| p[3] == 255 && p[0] > 150)
            .count();
        let sea = px
            .chunks_exact(4)
            .filter(|p| p[3] == 255 && u16::from(p[2]) > u16::from(p[0]) + 60)
            .count();
        assert!(lines > 100 && sea > 1000, "grid {lines}, globe {sea}");
    }
}
