//! `viewer bench --plot FILE.png`: the speed-against-error chart (bitmap only; text via
//! ab_glyph with egui's bundled font, so no system fonts are needed).

use super::report::{step_str, Row};
use crate::output::write_png_atomic;
use anyhow::{anyhow, Context, Result};
use std::path::Path;

/// Draw the speed-against-error chart: one point per LUT configuration (x: median ms per
/// frame, y: max sampling-position error), one series per (table, sampler), vertical
/// lines for the other renderers at hfov 90, and the 0.05 px budget.
pub fn plot(path: &Path, rows: &[Row]) -> Result<()> {
    use plotters::prelude::*;
    plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        epaint_default_fonts::UBUNTU_LIGHT,
    )
    .map_err(|_| anyhow!("cannot load the chart font"))?;
    let (pw, ph) = (1200u32, 760u32);
    let mut buf = vec![255u8; (pw * ph * 3) as usize];
    let floor = 1e-5;
    {
        let root = BitMapBackend::with_buffer(&mut buf, (pw, ph)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let xmax = rows.iter().map(|r| r.ms_median).fold(1.0, f64::max) * 1.5;
        let xmin = rows
            .iter()
            .map(|r| r.ms_median)
            .fold(f64::INFINITY, f64::min)
            .max(0.01)
            / 1.5;
        let ymax = rows.iter().filter_map(|r| r.max_err_px).fold(0.1, f64::max) * 2.0;
        let r0 = &rows[0];
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!(
                    "speed against error: {}x{} from {}x{}, {} threads",
                    r0.run.width,
                    r0.run.height,
                    r0.run.map_width,
                    r0.run.map_height,
                    r0.run.threads
                ),
                ("sans-serif", 26),
            )
            .margin(16)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d((xmin..xmax).log_scale(), (floor..ymax).log_scale())
            .map_err(|e| anyhow!("{e}"))?;
        chart
            .configure_mesh()
            .x_desc("median ms per frame (log)")
            .y_desc("sampling-position error, source px: filled = max, hollow = mean (log)")
            .label_style(("sans-serif", 16))
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        chart
            .draw_series(LineSeries::new(
                [(xmin, 0.05), (xmax, 0.05)],
                RED.stroke_width(1),
            ))
            .map_err(|e| anyhow!("{e}"))?
            .label("budget 0.05 px")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED));
        // (renderer, surface, set hfov, sampler): LUT series are the cylinder's by step;
        // the grid and the diamond table are one point per set (issue 12).
        let series = [
            (
                "lut",
                Some("cylinder"),
                90.0,
                "bilinear",
                BLUE,
                "LUT wide (hfov 90), bilinear",
            ),
            (
                "lut",
                Some("cylinder"),
                90.0,
                "nearest",
                CYAN,
                "LUT wide (hfov 90), nearest",
            ),
            (
                "lut",
                Some("cylinder"),
                50.0,
                "bilinear",
                GREEN,
                "LUT high (hfov 50), bilinear",
            ),
            (
                "lut",
                Some("cylinder"),
                50.0,
                "nearest",
                MAGENTA,
                "LUT high (hfov 50), nearest",
            ),
            (
                "grid",
                None,
                90.0,
                "bilinear",
                RGBColor(170, 0, 0),
                "grid (hfov 90), bilinear",
            ),
            (
                "grid",
                None,
                50.0,
                "bilinear",
                RGBColor(110, 60, 0),
                "grid (hfov 50), bilinear",
            ),
            (
                "lut",
                Some("diamond"),
                90.0,
                "bilinear",
                RGBColor(90, 0, 160),
                "LUT diamond wide (hfov 90), bilinear",
            ),
        ];
        for (renderer, surface, hfov, sampler, color, label) in series {
            let sel: Vec<&Row> = rows
                .iter()
                .filter(|r| {
                    r.renderer == renderer
                        && r.surface == surface
                        && r.hfov == hfov
                        && r.psnr_ss_db.is_none()
                        && r.sampler == sampler
                        && r.max_err_px.is_some()
                })
                .collect();
            let pts: Vec<(f64, f64, String)> = sel
                .iter()
                .map(|r| {
                    (
                        r.ms_median,
                        r.max_err_px.unwrap_or(0.0).max(floor),
                        step_str(&r.index_step),
                    )
                })
                .collect();
            // Mean errors: hollow markers of the same color.
            chart
                .draw_series(sel.iter().map(|r| {
                    Circle::new(
                        (r.ms_median, r.mean_err_px.unwrap_or(0.0).max(floor)),
                        5,
                        color.stroke_width(2),
                    )
                }))
                .map_err(|e| anyhow!("{e}"))?;
            chart
                .draw_series(
                    pts.iter()
                        .map(|(x, y, _)| Circle::new((*x, *y), 5, color.filled())),
                )
                .map_err(|e| anyhow!("{e}"))?
                .label(label)
                .legend(move |(x, y)| Circle::new((x + 10, y), 5, color.filled()));
            chart
                .draw_series(pts.iter().map(|(x, y, s)| {
                    Text::new(
                        if s == "adaptive" {
                            "A".to_string()
                        } else {
                            s.clone()
                        },
                        (*x, *y * 1.12),
                        ("sans-serif", 14).into_font().color(&color),
                    )
                }))
                .map_err(|e| anyhow!("{e}"))?;
        }
        let others = [
            ("exact", "bilinear", BLACK, "exact, bilinear (hfov 90)"),
            (
                "cube-scanline",
                "bilinear",
                RGBColor(200, 120, 0),
                "cube scanline, bilinear (hfov 90)",
            ),
            (
                "gather",
                "nearest",
                RGBColor(120, 120, 120),
                "plain gather of precomputed indices (hfov 90)",
            ),
        ];
        for (name, sampler, color, label) in others {
            if let Some(r) = rows
                .iter()
                .find(|r| r.renderer == name && r.sampler == sampler && r.hfov == 90.0)
            {
                let x = r.ms_median;
                chart
                    .draw_series(LineSeries::new(
                        [(x, floor), (x, ymax)],
                        color.stroke_width(2),
                    ))
                    .map_err(|e| anyhow!("{e}"))?
                    .label(label)
                    .legend(move |(lx, ly)| PathElement::new([(lx, ly), (lx + 20, ly)], color));
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    let px: Vec<u32> = buf
        .chunks_exact(3)
        .map(|c| (c[0] as u32) << 16 | (c[1] as u32) << 8 | c[2] as u32)
        .collect();
    if let Some(d) = path.parent() {
        if !d.as_os_str().is_empty() {
            std::fs::create_dir_all(d)
                .with_context(|| format!("{}: cannot create", d.display()))?;
        }
    }
    write_png_atomic(path, &px, pw, ph)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::commands::bench::report::RunInfo;
    use lut_core::Sampler;

    #[test]
    fn draws_a_chart_into_a_new_folder() {
        let run = RunInfo {
            width: 64,
            height: 32,
            threads: 1,
            map_width: 256,
            map_height: 128,
            projection: "equirect",
        };
        let lut = |ms: f64, err: f64| Row {
            index_step: serde_json::json!(4),
            lut: Some("wide"),
            surface: Some("cylinder"),
            max_err_px: Some(err),
            mean_err_px: Some(err / 4.0),
            ..Row::timed(&run, "lut", Sampler::Bilinear, 90.0, 1, &[ms])
        };
        let rows = [
            lut(1.0, 0.01),
            lut(0.5, 0.04),
            Row::timed(&run, "exact", Sampler::Bilinear, 90.0, 1, &[20.0]),
        ];
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("charts/speed.png");
        plot(&path, &rows).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (1200, 760));
        let white = image::Rgb([255u8, 255, 255]);
        let ink = img.pixels().filter(|p| **p != white).count();
        assert!(ink > 10_000, "{ink} pixels drawn");
        assert!(
            img.pixels().any(|p| p[2] > 200 && p[0] < 80),
            "no blue series"
        );
    }
}
