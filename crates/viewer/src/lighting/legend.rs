//! The legend of the false colours: a bar from `max / 1000` lux (bottom) to `max` lux
//! (top) with a tick and label at each decade, in the colours the shading uses
//! ([`lut_core::false_color`] of [`lut_core::false_color_position`]). The window draws it
//! with egui from [`ticks`] and [`bar_color`]; `viewer render --legend` draws it into the
//! frame with [`draw_legend`].

use lut_core::{false_color, false_color_position};

/// How many decades the false-colour scale spans (see [`lut_core::false_color_position`]).
pub const DECADES: i32 = 3;

/// One labelled tick of the legend.
#[derive(Debug, Clone, PartialEq)]
pub struct Tick {
    /// Position along the bar: 0 at the bottom, 1 at the top.
    pub pos: f64,
    /// The illuminance the tick marks, in lux.
    pub lux: f64,
    /// Its label ("1000 lx").
    pub label: String,
}

/// The illuminance at position `pos` (0 bottom, 1 top) of a scale topping at `max_lux`:
/// the inverse of [`lut_core::false_color_position`] inside the scale.
pub fn lux_at_position(pos: f64, max_lux: f64) -> f64 {
    max_lux * 10f64.powf(DECADES as f64 * (pos.clamp(0.0, 1.0) - 1.0))
}

/// The colour (0RGB) of the bar at position `pos` (0 bottom, 1 top).
pub fn bar_color(pos: f64, max_lux: f64) -> u32 {
    false_color(false_color_position(lux_at_position(pos, max_lux), max_lux))
}

/// A short label for `lux`: no more digits than the scale needs.
pub fn label(lux: f64) -> String {
    if lux >= 10.0 {
        format!("{lux:.0} lx")
    } else if lux >= 1.0 {
        format!("{lux:.1} lx")
    } else if lux >= 0.01 {
        format!("{lux:.2} lx")
    } else {
        format!("{lux:.1e} lx")
    }
}

/// The legend's ticks, one per decade from `max_lux / 1000` (pos 0) to `max_lux` (pos 1).
pub fn ticks(max_lux: f64) -> Vec<Tick> {
    (0..=DECADES)
        .map(|k| {
            let pos = k as f64 / DECADES as f64;
            let lux = lux_at_position(pos, max_lux);
            Tick {
                pos,
                lux,
                label: label(lux),
            }
        })
        .collect()
}

/// Where the legend sits in a `w × h` frame: (x, y, width, height) of its box, at the
/// right edge, vertically centred; `None` when the frame is too small to hold it.
pub fn legend_box(w: u32, h: u32) -> Option<(u32, u32, u32, u32)> {
    let scale = (w.max(h) as f64 / 800.0).max(1.0);
    let bw = (96.0 * scale).round() as u32;
    let bh = ((h as f64 * 0.6).min(300.0 * scale)).round() as u32;
    let margin = (10.0 * scale).round() as u32;
    if w < bw + 2 * margin || bh < (80.0 * scale) as u32 {
        return None;
    }
    Some((w - bw - margin, (h - bh) / 2, bw, bh))
}

/// Draw the legend into a `w × h` 0RGB frame (over a darkened box at the right edge).
/// Frames too small to hold it are left as they are.
///
/// # Errors
/// The label font cannot be loaded, or text drawing fails.
pub fn draw_legend(frame: &mut [u32], w: u32, h: u32, max_lux: f64) -> Result<(), String> {
    use plotters::prelude::*;
    let Some((bx, by, bw, bh)) = legend_box(w, h) else {
        return Ok(());
    };
    plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        epaint_default_fonts::UBUNTU_LIGHT,
    )
    .map_err(|_| "cannot load the legend font".to_string())?;
    let scale = (w.max(h) as f64 / 800.0).max(1.0);
    let px = |v: f64| (v * scale).round() as i32;
    // The box, darkened, as RGB bytes for the bitmap backend.
    let mut buf = Vec::with_capacity((bw * bh * 3) as usize);
    for y in by..by + bh {
        for x in bx..bx + bw {
            let p = frame[(y * w + x) as usize];
            for s in [16, 8, 0] {
                buf.push((((p >> s) & 0xff) as f64 * 0.35) as u8);
            }
        }
    }
    {
        let root = BitMapBackend::with_buffer(&mut buf, (bw, bh)).into_drawing_area();
        let (pad, bar_w) = (px(8.0), px(14.0));
        let top = px(26.0);
        let bottom = bh as i32 - px(12.0);
        let err = |e: DrawingAreaErrorKind<_>| format!("cannot draw the legend: {e}");
        let text = ("sans-serif", px(13.0) as f64).into_font().color(&WHITE);
        root.draw(&Text::new("illuminance", (pad, px(6.0)), text.clone()))
            .map_err(err)?;
        let span = (bottom - top).max(1);
        for row in top..bottom {
            let pos = 1.0 - (row - top) as f64 / span as f64;
            let c = bar_color(pos, max_lux);
            let rgb = RGBColor((c >> 16) as u8, (c >> 8) as u8, c as u8);
            root.draw(&PathElement::new(
                vec![(pad, row), (pad + bar_w - 1, row)],
                rgb,
            ))
            .map_err(err)?;
        }
        for t in ticks(max_lux) {
            let y = bottom - (t.pos * span as f64).round() as i32;
            root.draw(&PathElement::new(
                vec![(pad + bar_w, y), (pad + bar_w + px(4.0), y)],
                WHITE,
            ))
            .map_err(err)?;
            root.draw(&Text::new(
                t.label,
                (pad + bar_w + px(7.0), y - px(10.0)),
                text.clone(),
            ))
            .map_err(err)?;
        }
        root.present().map_err(err)?;
    }
    for (i, rgb) in buf.chunks_exact(3).enumerate() {
        let (x, y) = (bx + i as u32 % bw, by + i as u32 / bw);
        frame[(y * w + x) as usize] =
            ((rgb[0] as u32) << 16) | ((rgb[1] as u32) << 8) | rgb[2] as u32;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_invert_the_shading_scale() {
        for max in [1000.0, 300.0, 50.0] {
            for k in 0..=30 {
                let pos = k as f64 / 30.0;
                let lux = lux_at_position(pos, max);
                assert!((false_color_position(lux, max) - pos).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn ticks_are_the_decades() {
        let t = ticks(1000.0);
        let labels: Vec<&str> = t.iter().map(|t| t.label.as_str()).collect();
        assert_eq!(labels, ["1.0 lx", "10 lx", "100 lx", "1000 lx"]);
        assert!((t[0].lux - 1.0).abs() < 1e-9 && (t[3].lux - 1000.0).abs() < 1e-9);
        assert_eq!(ticks(300.0)[0].label, "0.30 lx");
    }

    #[test]
    fn drawn_bar_has_the_shading_colours() {
        let (w, h) = (800u32, 600u32);
        let mut f = vec![0x808080u32; (w * h) as usize];
        draw_legend(&mut f, w, h, 1000.0).unwrap();
        let (bx, by, _, bh) = legend_box(w, h).unwrap();
        // The middle of the bar: its row's colour is the ramp's colour at that row.
        let (top, bottom) = (by + 26, by + bh - 12);
        let x = bx + 8 + 7;
        for row in [top + 1, (top + bottom) / 2, bottom - 2] {
            let pos = 1.0 - (row - top) as f64 / (bottom - top) as f64;
            assert_eq!(
                f[(row * w + x) as usize],
                bar_color(pos, 1000.0),
                "row {row}"
            );
        }
        // Red at the top, dark blue at the bottom; outside the box the frame is untouched.
        assert_eq!(bar_color(1.0, 1000.0), false_color(1.0));
        assert_eq!(bar_color(0.0, 1000.0), false_color(0.0));
        assert_eq!(f[0], 0x808080);
        assert_eq!(f[(by * w + bx - 1) as usize], 0x808080);
        // Labels were drawn: some near-white pixels right of the bar.
        let lit = (by..by + bh)
            .flat_map(|y| (x + 20..bx + 90).map(move |x| (y, x)))
            .filter(|&(y, x)| f[(y * w + x) as usize] & 0xff > 0xc0)
            .count();
        assert!(lit > 50, "{lit}");
    }

    #[test]
    fn tiny_frames_get_no_legend() {
        let mut f = vec![7u32; 60 * 40];
        draw_legend(&mut f, 60, 40, 1000.0).unwrap();
        assert!(f.iter().all(|&p| p == 7));
    }
}
