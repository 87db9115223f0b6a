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
