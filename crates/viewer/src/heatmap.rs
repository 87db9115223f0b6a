//! The error heat map as an image: `lut_core::ErrorMap`'s colours (the sampling-position
//! error of the renderer in use against the exact map, per pixel, on a logarithmic scale
//! from 0.001 to 1 source pixel) with a legend band below: the colour bar with its
//! ticks, the 0.05 px budget, the max and the mean. `viewer render --error-map` writes
//! it; the window shows the same colours (its panel draws the legend).

use crate::output::write_image;
use anyhow::{anyhow, Result};
use lut_core::{heat_color, heat_scale, ErrorMap, HEAT_MAX, HEAT_MIN};
use std::path::Path;

/// Height of the legend band, pixels.
pub const LEGEND_HEIGHT: u32 = 64;
/// The narrowest legend (a narrower frame is padded to it).
pub const LEGEND_MIN_WIDTH: u32 = 420;

/// The ticks of the legend, source pixels.
pub const TICKS: [f64; 4] = [0.001, 0.01, 0.1, 1.0];

/// The product's sampling-position budget, marked on the legend.
pub const BUDGET_PX: f64 = 0.05;

/// Why the heat map of a panorama of `kind` is 0 everywhere, when it is by construction:
/// cube maps and tiled pyramids are drawn by the cube renderer, which computes every
/// pixel's sampling position exactly (no look-up table to interpolate, docs/cube.md), so
/// there is no position error to show. Said wherever the map is shown (the window's panel
/// and notice, `viewer render --error-map`), so an all-zero map is never silent.
pub fn exact_note(kind: lut_core::PanoramaKind) -> Option<&'static str> {
    match kind {
        lut_core::PanoramaKind::Cube => Some(
            "0 everywhere by construction: a cube map's renderer computes every pixel's \
             sampling position exactly (no look-up table)",
        ),
        lut_core::PanoramaKind::Tiled => Some(
            "0 everywhere by construction: tiles are drawn by the cube renderer, which \
             computes every pixel's sampling position exactly on the level drawn (no \
             look-up table); a frame drawn from a coarser level than wanted shows as \
             \"coarser than wanted\", not here",
        ),
        _ => None,
    }
}

/// One line summing up a heat map: max and mean error, and the pixels compared.
pub fn summary(em: &ErrorMap) -> String {
    let mut s = format!(
        "sampling-position error against the exact map: max {:.4} px, mean {:.5} px over {} pixels",
        em.stats.max, em.stats.mean, em.stats.count
    );
    if em.stats.coverage_mismatch > 0 {
        s.push_str(&format!(
            ", {} pixels where only one side shows the background",
            em.stats.coverage_mismatch
        ));
    }
    s
}

/// The heat map with its legend below: `(pixels, width, height)`, 0RGB. The frame is at
/// the top left, `em.width × em.height`; the image is at least [`LEGEND_MIN_WIDTH`] wide.
///
/// # Errors
/// When the legend's font cannot be loaded or drawn.
pub fn heat_image(em: &ErrorMap) -> Result<(Vec<u32>, u32, u32)> {
    use plotters::prelude::*;
    let w = em.width.max(LEGEND_MIN_WIDTH);
    let h = em.height + LEGEND_HEIGHT;
    let colors = em.colors();
    let mut buf = vec![255u8; (w * h * 3) as usize];
    for y in 0..em.height {
        for x in 0..em.width {
            let c = colors[(y * em.width + x) as usize];
            let i = ((y * w + x) * 3) as usize;
            buf[i..i + 3].copy_from_slice(&[(c >> 16) as u8, (c >> 8) as u8, c as u8]);
        }
    }
    plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        epaint_default_fonts::UBUNTU_LIGHT,
    )
    .map_err(|_| anyhow!("cannot load the legend font"))?;
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        let err = |e: DrawingAreaErrorKind<_>| anyhow!("cannot draw the legend: {e}");
        let top = em.height as i32;
        let (x0, x1) = (12i32, w as i32 - 12);
        let bar = (top + 8, top + 24);
        let at = |e: f64| x0 + ((x1 - x0) as f64 * heat_scale(e)).round() as i32;
        for x in x0..=x1 {
            let t = (x - x0) as f64 / (x1 - x0) as f64;
            let e = 10f64.powf(HEAT_MIN.log10() + t * (HEAT_MAX.log10() - HEAT_MIN.log10()));
            let c = heat_color(e);
            let color = RGBColor((c >> 16) as u8, (c >> 8) as u8, c as u8);
            root.draw(&PathElement::new([(x, bar.0), (x, bar.1)], color))
                .map_err(err)?;
        }
        let font = ("sans-serif", 13).into_font().color(&BLACK);
        for t in TICKS {
            let x = at(t);
            root.draw(&PathElement::new([(x, bar.1), (x, bar.1 + 4)], BLACK))
                .map_err(err)?;
            let label = if t == 1.0 {
                "1 px".to_string()
            } else {
                format!("{t}")
            };
            let dx = if t == 1.0 { -30 } else { -6 };
            root.draw(&Text::new(label, (x + dx, bar.1 + 6), font.clone()))
                .map_err(err)?;
        }
        let b = at(BUDGET_PX);
        root.draw(&PathElement::new(
            [(b, bar.0 - 4), (b, bar.1 + 4)],
            BLACK.stroke_width(2),
        ))
        .map_err(err)?;
        root.draw(&Text::new("0.05 budget", (b - 30, bar.1 + 6), font.clone()))
            .map_err(err)?;
        let stats = format!(
            "max {:.4} px   mean {:.5} px   (log scale, grey: background)",
            em.stats.max, em.stats.mean
        );
        root.draw(&Text::new(stats, (x0, top + 44), font))
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    let px = buf
        .chunks_exact(3)
        .map(|c| (c[0] as u32) << 16 | (c[1] as u32) << 8 | c[2] as u32)
        .collect();
    Ok((px, w, h))
}

/// Write [`heat_image`] of `em` to `path` (PNG or JPEG by its extension, atomically).
///
/// # Errors
/// As [`heat_image`], or when the file cannot be written.
pub fn write_error_map(path: &Path, em: &ErrorMap) -> Result<()> {
    let (px, w, h) = heat_image(em)?;
    write_image(path, &px, w, h)
}

#[cfg(test)]
mod tests {
    use super::*;
    use lut_core::{ErrorStats, HEAT_BACKGROUND};

    fn map() -> ErrorMap {
        let (w, h) = (30u32, 10u32);
        let errors: Vec<Option<f64>> = (0..w * h)
            .map(|i| match i % 3 {
                0 => None,
                1 => Some(0.002),
                _ => Some(0.3),
            })
            .collect();
        ErrorMap {
            width: w,
            height: h,
            errors,
            stats: ErrorStats {
                count: 300,
                max: 0.3,
                mean: 0.1,
                ..ErrorStats::default()
            },
        }
    }

    #[test]
    fn the_frame_is_at_the_top_left_and_the_legend_below() {
        let em = map();
        let (px, w, h) = heat_image(&em).unwrap();
        assert_eq!((w, h), (LEGEND_MIN_WIDTH, 10 + LEGEND_HEIGHT));
        for y in 0..10 {
            for x in 0..30 {
                assert_eq!(px[(y * w + x) as usize], em.colors()[(y * 30 + x) as usize]);
            }
        }
        assert_eq!(px[0], HEAT_BACKGROUND);
        // The bar runs from the scale's first colour to its last.
        let bar_y = 10 + 16;
        assert_eq!(px[(bar_y * w + 12) as usize], heat_color(HEAT_MIN));
        assert_eq!(px[(bar_y * w + w - 12) as usize], heat_color(HEAT_MAX));
        // Text was drawn (dark pixels in the band below the bar).
        let ink = (bar_y + 12..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .filter(|&(x, y)| px[(y * w + x) as usize] & 0xFF < 100)
            .count();
        assert!(ink > 100, "{ink}");
        assert_eq!(
            summary(&em),
            "sampling-position error against the exact map: max 0.3000 px, mean 0.10000 px over 300 pixels"
        );
    }
}
