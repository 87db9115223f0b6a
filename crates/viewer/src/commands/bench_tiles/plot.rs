//! `viewer bench-tiles --plot FILE.png` (and `--replot JSON --plot FILE.png`): the chart of
//! the bench against the panorama's width. Left, times (ms, log): process start to first
//! picture, view stop to sharp, and the pan's median and p99 frame, over resident tiles
//! and with tiles arriving, each with its issue target dashed in its colour (250 ms,
//! 300 ms, 16.7 ms for the p99s). Right, the peak resident memory (MiB) with the cache's
//! budget and the target, budget + 200 MiB. Widths on a log axis (16k, 64k, 256k …);
//! every sample drawn as a point, the line through each width's median. The plotting
//! helpers (ticks, font) are `viewer bench`'s.

use super::TilesSample;
use crate::commands::bench::plot::{log_key_points, tick};
use crate::output::write_png_atomic;
use anyhow::{anyhow, bail, Context, Result};
use plotters::prelude::*;
use std::path::Path;

/// Image size.
pub const SIZE: (u32, u32) = (1500, 760);
/// Width of the times panel (the memory panel takes the rest).
const TIMES_W: u32 = 900;

/// One drawn quantity: its name, colour, whether dashed-line p99, how to read it, and
/// its target (ms) if it has one.
struct Series {
    name: &'static str,
    colour: RGBColor,
    get: fn(&TilesSample) -> Option<f64>,
    target: Option<f64>,
}

const BLUE_: RGBColor = RGBColor(0, 90, 230);
const GREEN_: RGBColor = RGBColor(30, 150, 40);
const ORANGE_: RGBColor = RGBColor(230, 120, 0);
const PURPLE_: RGBColor = RGBColor(150, 40, 190);
const GREY_: RGBColor = RGBColor(120, 120, 120);

fn times() -> Vec<Series> {
    vec![
        Series {
            name: "first picture (process start)",
            colour: BLUE_,
            get: |s| Some(s.first_picture_ms),
            target: Some(250.0),
        },
        Series {
            name: "view stop to sharp",
            colour: GREEN_,
            get: |s| s.sharp_ms,
            target: Some(300.0),
        },
        Series {
            name: "pan, resident tiles: median",
            colour: ORANGE_,
            get: |s| Some(s.pan_resident_ms_median),
            target: None,
        },
        Series {
            name: "pan, resident tiles: p99",
            colour: RGBColor(170, 80, 0),
            get: |s| Some(s.pan_resident_ms_p99),
            target: Some(16.7),
        },
        Series {
            name: "pan, tiles arriving: median",
            colour: PURPLE_,
            get: |s| Some(s.pan_arriving_ms_median),
            target: None,
        },
        Series {
            name: "pan, tiles arriving: p99",
            colour: RGBColor(90, 20, 120),
            get: |s| Some(s.pan_arriving_ms_p99),
            target: None,
        },
    ]
}

fn err<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("drawing the chart: {e}")
}

/// `16k` for 16384, else the number.
fn width_label(w: f64) -> String {
    let w = w.round() as u64;
    if w.is_multiple_of(1024) {
        format!("{}k", w / 1024)
    } else {
        w.to_string()
    }
}

/// The median of each width's values, by increasing width.
fn medians(rows: &[TilesSample], get: impl Fn(&TilesSample) -> Option<f64>) -> Vec<(f64, f64)> {
    let mut widths: Vec<u64> = rows.iter().map(|r| r.width).collect();
    widths.sort_unstable();
    widths.dedup();
    widths
        .into_iter()
        .filter_map(|w| {
            let mut v: Vec<f64> = rows
                .iter()
                .filter(|r| r.width == w)
                .filter_map(&get)
                .filter(|v| v.is_finite() && *v > 0.0)
                .collect();
            if v.is_empty() {
                return None;
            }
            v.sort_by(f64::total_cmp);
            Some((w as f64, v[v.len() / 2]))
        })
        .collect()
}

/// Read the rows of a `viewer bench-tiles --json` file.
///
/// # Errors
/// The file cannot be read or is not that JSON (one line naming the file).
pub fn read_rows(path: &Path) -> Result<Vec<TilesSample>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    let rows: Vec<TilesSample> = serde_json::from_str(&text).map_err(|e| {
        anyhow!(
            "{}: not the JSON of viewer bench-tiles --json ({e})",
            path.display()
        )
    })?;
    if rows.is_empty() {
        bail!("{}: no measurements in the file", path.display());
    }
    Ok(rows)
}

/// Draw the chart of `rows` into `path` (a PNG, written atomically).
///
/// # Errors
/// No rows; drawing or writing failed.
pub fn plot(path: &Path, rows: &[TilesSample]) -> Result<()> {
    if rows.is_empty() {
        bail!("no measurements to draw");
    }
    plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        epaint_default_fonts::UBUNTU_LIGHT,
    )
    .map_err(|_| anyhow!("cannot load the chart font"))?;
    let (pw, ph) = SIZE;
    let mut buf = vec![255u8; (pw * ph * 3) as usize];
    let wmin = rows.iter().map(|r| r.width).min().unwrap_or(1) as f64;
    let wmax = rows.iter().map(|r| r.width).max().unwrap_or(1) as f64;
    let (xmin, xmax) = (wmin / 1.5, wmax * 1.5);
    let mut key_widths: Vec<f64> = rows.iter().map(|r| r.width as f64).collect();
    key_widths.sort_by(f64::total_cmp);
    key_widths.dedup();
    let series = times();
    {
        let root = BitMapBackend::with_buffer(&mut buf, (pw, ph)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let (top, legend) = root.split_vertically(ph - 150);
        let (left, right) = top.split_horizontally(TIMES_W);
        let caption = {
            let r = &rows[0];
            format!(
                "bench-tiles: {}x{} frames, tiles of {}, {} decoding threads, cache {} MiB",
                r.frame_width,
                r.frame_height,
                r.tile,
                r.threads,
                r.cache_budget_bytes >> 20
            )
        };
        root.draw(&Text::new(caption, (16, 8), ("sans-serif", 22).into_font()))
            .map_err(err)?;

        // Times.
        let values = rows
            .iter()
            .flat_map(|r| series.iter().filter_map(move |s| (s.get)(r)))
            .chain(series.iter().filter_map(|s| s.target))
            .filter(|v| v.is_finite() && *v > 0.0);
        let (tmin, tmax) = values.fold((f64::INFINITY, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
        let (ylo, yhi) = (tmin / 1.6, tmax * 1.6);
        let mut chart = ChartBuilder::on(&left)
            .margin(16)
            .margin_top(40)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(
                (xmin..xmax).log_scale().with_key_points(key_widths.clone()),
                (ylo..yhi)
                    .log_scale()
                    .with_key_points(log_key_points(ylo, yhi, 14)),
            )
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("panorama width, px (log)")
            .y_desc("ms (log)")
            .x_label_formatter(&|v| width_label(*v))
            .y_label_formatter(&|v| tick(*v))
            .label_style(("sans-serif", 16))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(err)?;
        for s in &series {
            if let Some(t) = s.target {
                chart
                    .draw_series(DashedLineSeries::new(
                        [(xmin, t), (xmax, t)],
                        8,
                        6,
                        s.colour.mix(0.7).stroke_width(2),
                    ))
                    .map_err(err)?;
            }
            chart
                .draw_series(LineSeries::new(
                    medians(rows, s.get),
                    s.colour.stroke_width(2),
                ))
                .map_err(err)?;
            chart
                .draw_series(rows.iter().filter_map(|r| {
                    (s.get)(r)
                        .filter(|v| v.is_finite() && *v > 0.0)
                        .map(|v| Circle::new((r.width as f64, v), 5, s.colour.filled()))
                }))
                .map_err(err)?;
        }

        // Memory.
        let mib = |b: u64| b as f64 / 1048576.0;
        let budget = rows
            .iter()
            .map(|r| mib(r.cache_budget_bytes))
            .fold(0.0, f64::max);
        let peak = rows
            .iter()
            .map(|r| mib(r.peak_rss_bytes))
            .fold(0.0, f64::max);
        let ytop = (budget + 200.0).max(peak) * 1.15;
        let mut mem = ChartBuilder::on(&right)
            .margin(16)
            .margin_top(40)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(
                (xmin..xmax).log_scale().with_key_points(key_widths.clone()),
                0.0..ytop,
            )
            .map_err(err)?;
        mem.configure_mesh()
            .x_desc("panorama width, px (log)")
            .y_desc("peak resident memory, MiB")
            .x_label_formatter(&|v| width_label(*v))
            .y_label_formatter(&|v| format!("{v:.0}"))
            .label_style(("sans-serif", 16))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(err)?;
        mem.draw_series(DashedLineSeries::new(
            [(xmin, budget + 200.0), (xmax, budget + 200.0)],
            8,
            6,
            RED.stroke_width(2),
        ))
        .map_err(err)?;
        mem.draw_series(LineSeries::new(
            [(xmin, budget), (xmax, budget)],
            GREY_.stroke_width(1),
        ))
        .map_err(err)?;
        mem.draw_series(LineSeries::new(
            medians(rows, |r| Some(mib(r.peak_rss_bytes))),
            BLACK.stroke_width(2),
        ))
        .map_err(err)?;
        mem.draw_series(
            rows.iter()
                .map(|r| Circle::new((r.width as f64, mib(r.peak_rss_bytes)), 5, BLACK.filled())),
        )
        .map_err(err)?;

        // Legend: two columns under the panels.
        let mut entries: Vec<(RGBColor, bool, String)> = Vec::new();
        for s in &series {
            entries.push((s.colour, false, s.name.to_string()));
            if let Some(t) = s.target {
                entries.push((s.colour, true, format!("target: {} ≤ {t} ms", s.name)));
            }
        }
        entries.push((BLACK, false, "peak RSS (VmHWM)".into()));
        entries.push((GREY_, false, format!("cache budget {budget:.0} MiB")));
        entries.push((
            RED,
            true,
            format!(
                "target: peak RSS ≤ budget + 200 MiB ({:.0})",
                budget + 200.0
            ),
        ));
        let per_col = entries.len().div_ceil(2);
        for (i, (c, dashed, text)) in entries.iter().enumerate() {
            let (x, y) = (
                24 + (i / per_col) as i32 * 720,
                10 + (i % per_col) as i32 * 20,
            );
            let style = c.stroke_width(2);
            if *dashed {
                legend
                    .draw(&PathElement::new([(x, y + 8), (x + 10, y + 8)], style))
                    .map_err(err)?;
                legend
                    .draw(&PathElement::new([(x + 16, y + 8), (x + 26, y + 8)], style))
                    .map_err(err)?;
            } else {
                legend
                    .draw(&PathElement::new([(x, y + 8), (x + 26, y + 8)], style))
                    .map_err(err)?;
                legend
                    .draw(&Circle::new((x + 13, y + 8), 4, c.filled()))
                    .map_err(err)?;
            }
            legend
                .draw(&Text::new(
                    text.clone(),
                    (x + 36, y),
                    ("sans-serif", 15).into_font(),
                ))
                .map_err(err)?;
        }
        root.present().map_err(err)?;
    }
    let px: Vec<u32> = buf
        .chunks_exact(3)
        .map(|c| (c[0] as u32) << 16 | (c[1] as u32) << 8 | c[2] as u32)
        .collect();
    write_png_atomic(path, &px, pw, ph)
        .with_context(|| format!("{}: cannot write the chart", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(width: u64, first: f64, rss_mib: u64) -> TilesSample {
        TilesSample {
            width,
            cube: 8 * (width as f64 / std::f64::consts::PI / 8.0) as u32,
            max_level: 5,
            tile: 512,
            cold: true,
            frame_width: 1920,
            frame_height: 1080,
            first_picture_ms: first,
            open_ms: first / 2.0,
            sharp_ms: Some(90.0),
            sharp_level: 4,
            sharp_tiles_decoded: 30,
            sharp_view_tiles: 37,
            sharp_frames: 6,
            pan_resident_ms_median: 4.6,
            pan_resident_ms_p99: 8.0,
            pan_resident_coarser: 0,
            pan_arriving_ms_median: 10.0,
            pan_arriving_ms_p99: 20.0,
            pan_arriving_coarser: 40,
            pan_arriving_levels: (2, 5),
            peak_rss_bytes: rss_mib << 20,
            cache_budget_bytes: 1 << 30,
            cache_bytes: 300 << 20,
            threads: 2,
            tiles_decoded: 400,
            tiles_per_s_per_thread: 360.0,
            mpixel_per_s_per_thread: 80.0,
        }
    }

    fn has_colour(img: &image::RgbImage, x: std::ops::Range<u32>, c: RGBColor) -> bool {
        x.flat_map(|x| (0..img.height()).map(move |y| (x, y)))
            .any(|(x, y)| img.get_pixel(x, y).0 == [c.0, c.1, c.2])
    }

    #[test]
    fn the_chart_draws_times_left_and_memory_right() {
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("c.png");
        let rows = vec![
            sample(16384, 20.0, 400),
            sample(65536, 26.0, 520),
            sample(16384, 23.0, 380),
        ];
        plot(&png, &rows).unwrap();
        let img = image::open(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), SIZE);
        // the first picture's blue points in the times panel, the peak RSS's black and
        // the target's red in the memory panel
        assert!(has_colour(&img, 0..TIMES_W, BLUE_));
        assert!(has_colour(&img, 0..TIMES_W, GREEN_));
        assert!(!has_colour(&img, TIMES_W..SIZE.0, BLUE_));
        assert!(has_colour(&img, TIMES_W..SIZE.0, RED));
        // medians by width
        assert_eq!(
            medians(&rows, |r| Some(r.first_picture_ms)),
            vec![(16384.0, 23.0), (65536.0, 26.0)]
        );
        assert_eq!(width_label(262144.0), "256k");
        assert_eq!(width_label(2000.0), "2000");
    }

    #[test]
    fn a_bad_json_is_one_line_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let bad = dir.path().join("bad.json");
        std::fs::write(&bad, "{\"not\": \"rows\"}").unwrap();
        let e = format!("{:#}", read_rows(&bad).unwrap_err());
        assert!(e.contains("bad.json") && !e.contains('\n'), "{e}");
        std::fs::write(&bad, "[]").unwrap();
        assert!(format!("{:#}", read_rows(&bad).unwrap_err()).contains("no measurements"));
    }
}
