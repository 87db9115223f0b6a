//! `viewer bench --plot FILE.png`: the speed-against-error chart (bitmap only; text via
//! ab_glyph with egui's bundled font, so no system fonts are needed).
//!
//! Made to read at a glance: one point per configuration (x: median ms per frame, y: its
//! mean sampling-position error, both log) with a whisker up to its max error (the max is
//! set by the table, so it is the same for most configurations, and the 0.05 px budget
//! applies to it), one colour per series of configurations (renderer, table, sampler,
//! hfov: however many the rows hold), the budget, the Pareto front (the configurations
//! no other one beats on both time and mean error), the renderers without a position
//! error (exact, cube, gather) as vertical lines, step labels placed where they overlap
//! neither each other nor a point (dropped when there is no room), plain decimal ticks,
//! and the legend in its own panel beside the plot.

use super::report::{step_str, Row};
use crate::output::write_png_atomic;
use anyhow::{anyhow, Context, Result};
use plotters::prelude::*;
use std::path::Path;

/// Image size.
const SIZE: (u32, u32) = (1400, 800);
/// Width of the plot; the legend panel takes the rest.
const PLOT_W: u32 = 1020;
/// Lowest error drawn (log scale).
const FLOOR: f64 = 1e-5;
/// The error budget, source pixels.
const BUDGET: f64 = 0.05;

/// Colours of the series, in order (distinct on white, the first a clear blue).
const PALETTE: [RGBColor; 12] = [
    RGBColor(0, 90, 230),
    RGBColor(0, 170, 200),
    RGBColor(30, 150, 40),
    RGBColor(200, 0, 170),
    RGBColor(230, 120, 0),
    RGBColor(120, 60, 200),
    RGBColor(150, 110, 40),
    RGBColor(90, 90, 90),
    RGBColor(190, 160, 0),
    RGBColor(0, 110, 110),
    RGBColor(230, 70, 70),
    RGBColor(0, 0, 0),
];

/// One series: the rows of one renderer, table, sampler and hfov with a measured error.
struct Series<'a> {
    label: String,
    rows: Vec<&'a Row>,
}

/// The series of `rows` (minification rows left out), in the order they first appear.
fn series(rows: &[Row]) -> Vec<Series<'_>> {
    let mut out: Vec<Series> = Vec::new();
    for r in rows.iter().filter(|r| r.psnr_ss_db.is_none()) {
        if !r.max_err_px.is_some_and(|e| e > 0.0) || r.ms_median <= 0.0 {
            continue;
        }
        // The table's surface when it is not the default cylinder (e.g. diamond).
        let surface = r
            .surface
            .filter(|s| *s != "cylinder")
            .map_or(String::new(), |s| format!(" {s}"));
        let label = match r.lut {
            Some(lut) => format!(
                "{}{surface} {lut} (hfov {}), {}",
                r.renderer, r.hfov, r.sampler
            ),
            None => format!("{}{surface} (hfov {}), {}", r.renderer, r.hfov, r.sampler),
        };
        match out.iter_mut().find(|s| s.label == label) {
            Some(s) => s.rows.push(r),
            None => out.push(Series {
                label,
                rows: vec![r],
            }),
        }
    }
    out
}

/// Renderers drawn as vertical lines (no position error: exact, cube, gather), at the
/// first set's hfov.
fn references(rows: &[Row]) -> Vec<&Row> {
    let Some(hfov) = rows.first().map(|r| r.hfov) else {
        return Vec::new();
    };
    rows.iter()
        .filter(|r| {
            r.psnr_ss_db.is_none()
                && r.hfov == hfov
                && r.ms_median > 0.0
                && !r.max_err_px.is_some_and(|e| e > 0.0)
        })
        .collect()
}

/// The Pareto front of (time, error) points: those no other point beats on both, by
/// increasing time (errors then strictly decrease).
pub fn pareto(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut p: Vec<(f64, f64)> = points.to_vec();
    p.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut front: Vec<(f64, f64)> = Vec::new();
    for q in p {
        if front.last().is_none_or(|l| q.1 < l.1) {
            front.push(q);
        }
    }
    front
}

/// A rectangle in pixels: x, y (top left), width, height.
pub type Rect = (i32, i32, i32, i32);

fn overlaps(a: Rect, b: Rect) -> bool {
    a.0 < b.0 + b.2 && b.0 < a.0 + a.2 && a.1 < b.1 + b.3 && b.1 < a.1 + a.3
}

/// Places a label of `size` (w, h) near each point (pixels) without covering another
/// label, any point's marker (`marker` pixels square) or leaving `area`; a label with no
/// free place is dropped (`None`).
pub fn place_labels(
    points: &[(i32, i32)],
    sizes: &[(i32, i32)],
    marker: i32,
    area: Rect,
) -> Vec<Option<Rect>> {
    let m = marker;
    let marks: Vec<Rect> = points
        .iter()
        .map(|&(x, y)| (x - m / 2, y - m / 2, m, m))
        .collect();
    let mut placed: Vec<Rect> = Vec::new();
    points
        .iter()
        .zip(sizes)
        .map(|(&(x, y), &(w, h))| {
            let g = m / 2 + 2;
            let spots = [
                (x + g, y - h - 1),
                (x + g, y + 1),
                (x - g - w, y - h - 1),
                (x - g - w, y + 1),
                (x - w / 2, y - g - h),
                (x - w / 2, y + g),
                (x + g, y - h / 2),
                (x - g - w, y - h / 2),
            ];
            let inside = |r: Rect| {
                r.0 >= area.0
                    && r.1 >= area.1
                    && r.0 + r.2 <= area.0 + area.2
                    && r.1 + r.3 <= area.1 + area.3
            };
            let free = spots.iter().map(|&(lx, ly)| (lx, ly, w, h)).find(|&r| {
                inside(r)
                    && !placed.iter().any(|&p| overlaps(p, r))
                    && !marks.iter().any(|&p| overlaps(p, r))
            });
            if let Some(r) = free {
                placed.push(r);
            }
            free
        })
        .collect()
}

/// A tick value in plain decimals (0.001, 0.5, 20), not exponents.
pub fn tick(v: f64) -> String {
    if !(v.is_finite() && v > 0.0) {
        return format!("{v}");
    }
    let digits = (-v.log10().floor()).max(0.0) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A row's mean and max error as drawn (at least [`FLOOR`]).
fn mean_of(r: &Row) -> f64 {
    r.mean_err_px.or(r.max_err_px).unwrap_or(FLOOR).max(FLOOR)
}

fn max_of(r: &Row) -> f64 {
    r.max_err_px.unwrap_or(FLOOR).max(FLOOR)
}

fn err<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("{e}")
}

/// Draw the chart into `path` (see the module doc).
pub fn plot(path: &Path, rows: &[Row]) -> Result<()> {
    plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        epaint_default_fonts::UBUNTU_LIGHT,
    )
    .map_err(|_| anyhow!("cannot load the chart font"))?;
    let (pw, ph) = SIZE;
    let mut buf = vec![255u8; (pw * ph * 3) as usize];
    let all = series(rows);
    let refs = references(rows);
    {
        let root = BitMapBackend::with_buffer(&mut buf, (pw, ph)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let (left, right) = root.split_horizontally(PLOT_W);
        let times = all
            .iter()
            .flat_map(|s| s.rows.iter().map(|r| r.ms_median))
            .chain(refs.iter().map(|r| r.ms_median));
        let (tmin, tmax) = times.fold((f64::INFINITY, 0.0f64), |(a, b), t| (a.min(t), b.max(t)));
        let (xmin, xmax) = if tmax > 0.0 {
            (tmin / 1.4, tmax * 1.4)
        } else {
            (0.1, 100.0)
        };
        let ymax = all
            .iter()
            .flat_map(|s| s.rows.iter().filter_map(|r| r.max_err_px))
            .fold(0.1, f64::max)
            * 2.0;
        let caption = rows.first().map_or(String::new(), |r| {
            format!(
                "speed against error: {}x{} from {}x{}, {} threads, kernel {}",
                r.run.width,
                r.run.height,
                r.run.map_width,
                r.run.map_height,
                r.run.threads,
                r.run.kernel
            )
        });
        let mut chart = ChartBuilder::on(&left)
            .caption(caption, ("sans-serif", 24))
            .margin(16)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d((xmin..xmax).log_scale(), (FLOOR..ymax).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("median ms per frame (log)")
            .y_desc("sampling-position error, source px (log): point = mean, whisker = max")
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .label_style(("sans-serif", 16))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(err)?;
        // The budget, the reference renderers, the Pareto front, then the points on top.
        chart
            .draw_series(LineSeries::new(
                [(xmin, BUDGET), (xmax, BUDGET)],
                RED.stroke_width(2),
            ))
            .map_err(err)?;
        let ref_colour = |i: usize| PALETTE[(all.len() + i) % PALETTE.len()];
        for (i, r) in refs.iter().enumerate() {
            chart
                .draw_series(LineSeries::new(
                    [(r.ms_median, FLOOR), (r.ms_median, ymax)],
                    ref_colour(i).stroke_width(2),
                ))
                .map_err(err)?;
        }
        let points: Vec<(f64, f64)> = all
            .iter()
            .flat_map(|s| s.rows.iter())
            .map(|r| (r.ms_median, mean_of(r)))
            .collect();
        let front = pareto(&points);
        let mut steps = Vec::new();
        for (i, &(x, y)) in front.iter().enumerate() {
            if i > 0 {
                steps.push((x, front[i - 1].1));
            }
            steps.push((x, y));
        }
        if let Some(&(_, y)) = front.last() {
            steps.push((xmax, y));
        }
        chart
            .draw_series(LineSeries::new(steps, BLACK.mix(0.45).stroke_width(2)))
            .map_err(err)?;
        for (si, s) in all.iter().enumerate() {
            let c = PALETTE[si % PALETTE.len()];
            for r in &s.rows {
                let (x, lo, hi) = (r.ms_median, mean_of(r), max_of(r));
                chart
                    .draw_series(LineSeries::new([(x, lo), (x, hi)], c.mix(0.5)))
                    .map_err(err)?;
                let (px, py) = chart.backend_coord(&(x, hi));
                root.draw(&PathElement::new(
                    [(px - 4, py), (px + 4, py)],
                    c.stroke_width(2),
                ))
                .map_err(err)?;
            }
            chart
                .draw_series(
                    s.rows
                        .iter()
                        .map(|r| Circle::new((r.ms_median, mean_of(r)), 5, c.filled())),
                )
                .map_err(err)?;
        }
        // Step labels where they fit.
        let mut at = Vec::new();
        let mut texts = Vec::new();
        for (si, s) in all.iter().enumerate() {
            for r in &s.rows {
                let p = chart.backend_coord(&(r.ms_median, mean_of(r)));
                let t = match step_str(&r.index_step).as_str() {
                    "adaptive" => "A".to_string(),
                    "-" => String::new(),
                    o => o.to_string(),
                };
                at.push(p);
                texts.push((t, si));
            }
        }
        let sizes: Vec<(i32, i32)> = texts
            .iter()
            .map(|(t, _)| (8 * t.chars().count() as i32 + 2, 14))
            .collect();
        let (ax, ay) = chart.plotting_area().get_base_pixel();
        let (aw, ah) = chart.plotting_area().dim_in_pixel();
        let area = (ax, ay, aw as i32, ah as i32);
        for (spot, (t, si)) in place_labels(&at, &sizes, 10, area).iter().zip(&texts) {
            if let (Some(r), false) = (spot, t.is_empty()) {
                root.draw(&Text::new(
                    t.clone(),
                    (r.0 + 1, r.1),
                    ("sans-serif", 14)
                        .into_font()
                        .color(&PALETTE[si % PALETTE.len()]),
                ))
                .map_err(err)?;
            }
        }
        // The legend panel.
        let font = ("sans-serif", 15).into_font();
        let mut y = 60;
        let line = |y: i32, c: RGBColor| PathElement::new([(12, y), (36, y)], c.stroke_width(2));
        right
            .draw(&Text::new(
                "legend",
                (12, 30),
                ("sans-serif", 18).into_font(),
            ))
            .map_err(err)?;
        for (si, s) in all.iter().enumerate() {
            let c = PALETTE[si % PALETTE.len()];
            right
                .draw(&Circle::new((24, y), 5, c.filled()))
                .map_err(err)?;
            right
                .draw(&Text::new(s.label.clone(), (44, y - 8), font.clone()))
                .map_err(err)?;
            y += 24;
        }
        for (i, r) in refs.iter().enumerate() {
            right.draw(&line(y, ref_colour(i))).map_err(err)?;
            let label = format!("{}, {} (no position error)", r.renderer, r.sampler);
            right
                .draw(&Text::new(label, (44, y - 8), font.clone()))
                .map_err(err)?;
            y += 24;
        }
        right.draw(&line(y, RED)).map_err(err)?;
        right
            .draw(&Text::new("budget 0.05 px", (44, y - 8), font.clone()))
            .map_err(err)?;
        y += 24;
        right.draw(&line(y, RGBColor(140, 140, 140))).map_err(err)?;
        right
            .draw(&Text::new(
                "Pareto front (time, mean error)",
                (44, y - 8),
                font.clone(),
            ))
            .map_err(err)?;
        y += 36;
        for note in [
            "point: mean error; whisker top: max",
            "error (the table sets it: the same",
            "for most configurations)",
            "labels: index step (A = adaptive);",
            "where labels would overlap,",
            "they are left out",
        ] {
            right
                .draw(&Text::new(note, (12, y), font.clone()))
                .map_err(err)?;
            y += 20;
        }
        root.present().map_err(err)?;
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

    fn run() -> RunInfo {
        RunInfo {
            width: 64,
            height: 32,
            threads: 1,
            map_width: 256,
            map_height: 128,
            projection: "equirect",
            kernel: "scalar",
        }
    }

    fn lut(ms: f64, err: f64, step: i64, table: &'static str) -> Row {
        Row {
            index_step: serde_json::json!(step),
            lut: Some(table),
            surface: Some("cylinder"),
            max_err_px: Some(err),
            mean_err_px: Some(err / 4.0),
            ..Row::timed(&run(), "lut", Sampler::Bilinear, 90.0, 1, &[ms])
        }
    }

    #[test]
    fn draws_a_chart_into_a_new_folder() {
        let rows = [
            lut(1.0, 0.01, 4, "wide"),
            lut(0.5, 0.04, 8, "wide"),
            Row::timed(&run(), "exact", Sampler::Bilinear, 90.0, 1, &[20.0]),
        ];
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("charts/speed.png");
        plot(&path, &rows).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), SIZE);
        let white = image::Rgb([255u8, 255, 255]);
        let ink = img.pixels().filter(|p| **p != white).count();
        assert!(ink > 10_000, "{ink} pixels drawn");
        assert!(
            img.pixels().any(|p| p[2] > 200 && p[0] < 80),
            "no blue series"
        );
    }

    /// Any number of configurations: 40 series of 6 points each still draw (colours
    /// repeat), and every series appears in the legend panel (ink right of the plot).
    #[test]
    fn many_configurations() {
        let tables = ["wide", "high"];
        let mut rows = Vec::new();
        for s in 0..40 {
            for k in 0..6 {
                let mut r = lut(
                    1.0 + k as f64 + s as f64 * 0.1,
                    0.001 * (k + 1) as f64,
                    k,
                    tables[s % 2],
                );
                r.hfov = 30.0 + s as f64;
                rows.push(r);
            }
        }
        assert_eq!(series(&rows).len(), 40);
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("many.png");
        plot(&path, &rows).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        let legend_ink = (PLOT_W..SIZE.0)
            .flat_map(|x| (0..SIZE.1).map(move |y| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y)[0] < 200)
            .count();
        assert!(legend_ink > 2_000, "{legend_ink}");
    }

    #[test]
    fn pareto_front_keeps_the_unbeaten() {
        let pts = [
            (1.0, 0.04),
            (2.0, 0.01),
            (1.5, 0.05),
            (3.0, 0.01),
            (0.5, 0.1),
            (4.0, 0.001),
        ];
        assert_eq!(
            pareto(&pts),
            vec![(0.5, 0.1), (1.0, 0.04), (2.0, 0.01), (4.0, 0.001)]
        );
        assert!(pareto(&[]).is_empty());
    }

    #[test]
    fn labels_do_not_overlap_each_other_or_points() {
        // A cluster of 30 points a few pixels apart, and a lone point.
        let mut pts: Vec<(i32, i32)> = (0..30)
            .map(|i| (100 + 3 * (i % 6), 100 + 4 * (i / 6)))
            .collect();
        pts.push((400, 300));
        let sizes = vec![(18, 14); pts.len()];
        let area = (0, 0, 600, 400);
        let got = place_labels(&pts, &sizes, 10, area);
        let rects: Vec<Rect> = got.iter().flatten().copied().collect();
        assert!(got[30].is_some(), "the lone point is labelled");
        assert!(rects.len() < pts.len(), "a crowded cluster drops labels");
        for (i, a) in rects.iter().enumerate() {
            for b in &rects[i + 1..] {
                assert!(!overlaps(*a, *b), "{a:?} {b:?}");
            }
            for &(x, y) in &pts {
                assert!(
                    !overlaps(*a, (x - 5, y - 5, 10, 10)),
                    "{a:?} covers ({x}, {y})"
                );
            }
            assert!(a.0 >= 0 && a.1 >= 0 && a.0 + a.2 <= 600 && a.1 + a.3 <= 400);
        }
    }

    #[test]
    fn ticks_are_plain_decimals() {
        assert_eq!(tick(0.001), "0.001");
        assert_eq!(tick(0.05), "0.05");
        assert_eq!(tick(2.0), "2");
        assert_eq!(tick(20.0), "20");
        assert_eq!(tick(0.00001), "0.00001");
        assert_eq!(tick(0.3), "0.3");
    }
}
