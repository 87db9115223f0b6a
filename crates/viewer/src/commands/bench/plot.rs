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
//! neither each other nor a point (dropped when there is no room), plain decimal ticks at
//! 1, 2 and 5 times each power of ten, and the legend in its own panel beside the plot
//! (its lines spaced to fit). `viewer bench --replot` draws it again from a `--json`
//! file, with the peers of `scripts/peers.py` (no position error either: they remap along
//! our exact maps) as dashed vertical lines numbered at the top, listed with their PSNR
//! against the exact render.

use super::report::{step_str, Row};
use crate::output::write_png_atomic;
use anyhow::{anyhow, Context, Result};
use plotters::prelude::*;
use serde::Deserialize;
use std::path::Path;

/// Image size.
const SIZE: (u32, u32) = (1600, 900);
/// Width of the plot; the legend panel takes the rest.
const PLOT_W: u32 = 1060;
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

/// The marker shapes of the series: the colours repeat after [`PALETTE`]'s twelve, each
/// round with the next shape, so every series has its own colour-and-shape pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Marker {
    Circle,
    Square,
    Triangle,
    Diamond,
}

const MARKERS: [Marker; 4] = [
    Marker::Circle,
    Marker::Square,
    Marker::Triangle,
    Marker::Diamond,
];

/// Series `si`'s colour and marker (distinct pairs for the first 48 series).
fn series_style(si: usize) -> (RGBColor, Marker) {
    (
        PALETTE[si % PALETTE.len()],
        MARKERS[(si / PALETTE.len()) % MARKERS.len()],
    )
}

/// Draw `m` of radius `r` filled with `c` at pixel `(x, y)` of `area`.
fn draw_marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    (x, y): (i32, i32),
    r: i32,
    m: Marker,
    c: RGBColor,
) -> Result<()> {
    let style = c.filled();
    let res = match m {
        Marker::Circle => area.draw(&Circle::new((x, y), r, style)),
        Marker::Square => area.draw(&Rectangle::new([(x - r, y - r), (x + r, y + r)], style)),
        Marker::Triangle => area.draw(&Polygon::new(
            vec![(x, y - r - 1), (x - r - 1, y + r), (x + r + 1, y + r)],
            style,
        )),
        Marker::Diamond => area.draw(&Polygon::new(
            vec![
                (x, y - r - 1),
                (x + r + 1, y),
                (x, y + r + 1),
                (x - r - 1, y),
            ],
            style,
        )),
    };
    res.map_err(|e| anyhow!("drawing the chart: {e}"))
}

/// Colours of the peers' dashed lines: a dark family, apart from the series'.
const PEER_PALETTE: [RGBColor; 6] = [
    RGBColor(0, 0, 0),
    RGBColor(110, 110, 110),
    RGBColor(140, 70, 20),
    RGBColor(90, 40, 130),
    RGBColor(0, 90, 70),
    RGBColor(150, 0, 50),
];

/// A peer of `scripts/peers.py` (one row of its `peers.json`): its name, median ms per
/// frame on the same views, and its PSNR against our exact render (none: it makes no
/// image, e.g. map building alone). Peers remap along our exact maps, so they have no
/// sampling-position error: the chart draws them as dashed vertical lines.
#[derive(Debug, Clone, PartialEq)]
pub struct Peer {
    /// The peer's name as `peers.py` writes it.
    pub name: String,
    /// Median milliseconds per frame.
    pub ms: f64,
    /// PSNR against the exact render, dB.
    pub psnr_db: Option<f64>,
}

#[derive(Deserialize)]
struct PeersFile {
    rows: Vec<PeerRow>,
}

#[derive(Deserialize)]
struct PeerRow {
    peer: String,
    key: String,
    ms_median: Option<f64>,
    psnr_db_vs_exact: Option<f64>,
    /// The peer's images equal our exact render (an infinite PSNR, which JSON cannot
    /// hold: `psnr_db_vs_exact` is null then).
    #[serde(default)]
    identical: bool,
}

fn read_text(path: &Path) -> Result<String> {
    // Regular files only (a FIFO never blocks), at most 256 MiB.
    let bytes = lut_core::read_regular(path, 256 << 20)
        .map_err(|e| anyhow!("{}: cannot read: {e}", path.display()))?;
    String::from_utf8(bytes)
        .map_err(|e| anyhow!("{}: cannot read: not UTF-8 text ({e})", path.display()))
}

/// The rows a `viewer bench --json` run wrote to `path`.
///
/// # Errors
/// A file that cannot be read, is not such an array, or holds no row (one line naming
/// the file and the reason).
pub fn read_rows(path: &Path) -> Result<Vec<Row>> {
    let text = read_text(path)?;
    let rows: Vec<Row> = serde_json::from_str(&text).map_err(|e| {
        anyhow!(
            "{}: not the rows of `viewer bench --json`: {e}",
            path.display()
        )
    })?;
    if rows.is_empty() {
        return Err(anyhow!("{}: no rows", path.display()));
    }
    Ok(rows)
}

/// The peers `scripts/peers.py` wrote to `path` (`peers.json`), once per key (its last
/// row repeats a peer against our gather), those without a time left out.
///
/// # Errors
/// A file that cannot be read or is not such a file (one line naming the file and the
/// reason).
pub fn read_peers(path: &Path) -> Result<Vec<Peer>> {
    let f: PeersFile = serde_json::from_str(&read_text(path)?).map_err(|e| {
        anyhow!(
            "{}: not a peers.json of scripts/peers.py: {e}",
            path.display()
        )
    })?;
    let mut keys: Vec<&str> = Vec::new();
    let mut out = Vec::new();
    for r in &f.rows {
        if keys.contains(&r.key.as_str()) {
            continue;
        }
        keys.push(&r.key);
        if let Some(ms) = r.ms_median.filter(|m| m.is_finite() && *m > 0.0) {
            out.push(Peer {
                name: r.peer.clone(),
                ms,
                psnr_db: if r.identical {
                    Some(f64::INFINITY)
                } else {
                    r.psnr_db_vs_exact
                },
            });
        }
    }
    Ok(out)
}

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
            .as_deref()
            .filter(|s| *s != "cylinder")
            .map_or(String::new(), |s| format!(" {s}"));
        let label = match r.lut.as_deref() {
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

/// A vertical line's legend: the renderer and sampler, and for a row whose positions are
/// stepped within a bound rather than exact (`position_bound_texels`: none `viewer
/// bench` writes today; the cube scanline renderer's bilinear rows of JSON files written
/// before 2026-12-02), that bound.
fn reference_label(r: &Row) -> String {
    let label = format!("{}, {}", r.renderer, r.sampler);
    match r.position_bound_texels {
        Some(b) => format!("{label} (stepped: max error <= {b:.4} face texel, bound)"),
        None => label,
    }
}

/// Renderers drawn as vertical lines (no position error measured: exact, cube, gather;
/// a row stepped within a bound names it, [`reference_label`]), at the first set's hfov.
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

/// The key points (labelled ticks) of a log axis over `lo..=hi`: 1, 2 and 5 times each
/// power of ten inside the range; 1 to 9 times when fewer than two of those fall inside;
/// powers of ten alone (every second, third … one) when more than `max` would.
pub fn log_key_points(lo: f64, hi: f64, max: usize) -> Vec<f64> {
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi >= lo) {
        return Vec::new();
    }
    let (d0, d1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let seq = |mults: &[u32], every: i32| -> Vec<f64> {
        let mut out = Vec::new();
        for d in (d0..=d1).filter(|d| d.rem_euclid(every) == 0) {
            for m in mults {
                // Parsed from decimal, so 2e-5 is the double nearest 0.00002.
                let v: f64 = format!("{m}e{d}").parse().unwrap_or(f64::NAN);
                if v >= lo && v <= hi {
                    out.push(v);
                }
            }
        }
        out
    };
    let main = seq(&[1, 2, 5], 1);
    if main.len() < 2 {
        let all = seq(&[1, 2, 3, 4, 5, 6, 7, 8, 9], 1);
        if all.len() <= max.max(2) {
            return all;
        }
    }
    if main.len() <= max {
        return main;
    }
    let mut every = 1;
    loop {
        let p = seq(&[1], every);
        if p.len() <= max.max(1) || every > 64 {
            return p;
        }
        every += 1;
    }
}

/// The light mesh lines of a log axis: 1 to 9 times each power of ten inside the range.
fn log_light_points(lo: f64, hi: f64) -> Vec<f64> {
    (lo.log10().floor() as i32..=hi.log10().ceil() as i32)
        .flat_map(|d| (1..10).map(move |m| format!("{m}e{d}").parse::<f64>().unwrap_or(f64::NAN)))
        .filter(|v| *v >= lo && *v <= hi)
        .collect()
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

/// One line of the legend.
enum Entry {
    /// A group's heading.
    Head(String),
    /// A series: its point's colour and marker.
    Point(RGBColor, Marker, String),
    /// A solid line (references, budget, front).
    Line(RGBColor, String),
    /// A dashed line (peers).
    Dashed(RGBColor, String),
    /// A line of text.
    Note(String),
}

/// Draw the chart into `path` (see the module doc), with `peers` (from `peers.json`,
/// none when the bench draws the chart itself) as dashed vertical lines.
pub fn plot(path: &Path, rows: &[Row], peers: &[Peer]) -> Result<()> {
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
            .chain(refs.iter().map(|r| r.ms_median))
            .chain(peers.iter().map(|p| p.ms));
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
        // The bottom: a quarter of the lowest mean error drawn (at least [`FLOOR`]), so
        // the points fill the height.
        let ylo = all
            .iter()
            .flat_map(|s| s.rows.iter().map(|r| mean_of(r)))
            .fold(ymax, f64::min)
            .min(0.01)
            / 4.0;
        let ylo = ylo.max(FLOOR);
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
            .build_cartesian_2d(
                (xmin..xmax)
                    .log_scale()
                    .with_key_points(log_key_points(xmin, xmax, (PLOT_W / 80) as usize))
                    .with_light_points(log_light_points(xmin, xmax)),
                (ylo..ymax)
                    .log_scale()
                    .with_key_points(log_key_points(ylo, ymax, (SIZE.1 / 36) as usize))
                    .with_light_points(log_light_points(ylo, ymax)),
            )
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
                    [(r.ms_median, ylo), (r.ms_median, ymax)],
                    ref_colour(i).stroke_width(2),
                ))
                .map_err(err)?;
        }
        // The peers: dashed, numbered at the top (a tag that would overlap the one
        // beside it moves a row down).
        let peer_colour = |i: usize| PEER_PALETTE[i % PEER_PALETTE.len()];
        let (ax, ay) = chart.plotting_area().get_base_pixel();
        let mut tags: Vec<Rect> = Vec::new();
        for (i, p) in peers.iter().enumerate() {
            chart
                .draw_series(DashedLineSeries::new(
                    [(p.ms, ylo), (p.ms, ymax)],
                    8,
                    5,
                    peer_colour(i).stroke_width(2),
                ))
                .map_err(err)?;
            let (px, _) = chart.backend_coord(&(p.ms, ymax));
            let t = format!("{}", i + 1);
            let w = 8 * t.len() as i32 + 2;
            let mut r = (px + 2, ay + 2, w, 14);
            while tags.iter().any(|&q| overlaps(q, r)) {
                r.1 += 15;
            }
            tags.push(r);
            root.draw(&Text::new(
                t,
                (r.0, r.1),
                ("sans-serif", 14).into_font().color(&peer_colour(i)),
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
            let (c, marker) = series_style(si);
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
            for r in &s.rows {
                let p = chart.backend_coord(&(r.ms_median, mean_of(r)));
                draw_marker(&root, p, 5, marker, c)?;
            }
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
        // The legend panel: as many lines as there are, spaced to fit the panel (down
        // to 12 px a line; series beyond that are counted, not listed).
        let mut entries = vec![Entry::Head(
            "configurations (point: mean error; whisker top: max)".into(),
        )];
        let fixed = refs.len() + peers.len() + 12;
        let room = ((SIZE.1 as usize - 60) / 12).saturating_sub(fixed);
        let listed = if all.len() > room {
            room.saturating_sub(1)
        } else {
            all.len()
        };
        for (si, s) in all.iter().enumerate().take(listed) {
            let (c, m) = series_style(si);
            entries.push(Entry::Point(c, m, s.label.clone()));
        }
        if listed < all.len() {
            entries.push(Entry::Note(format!(
                "... and {} more series",
                all.len() - listed
            )));
        }
        entries.push(Entry::Line(RED, "budget 0.05 px (max error)".into()));
        entries.push(Entry::Line(
            RGBColor(140, 140, 140),
            "Pareto front (time, mean error)".into(),
        ));
        if !refs.is_empty() {
            entries.push(Entry::Head(
                "no position error measured (solid lines)".into(),
            ));
        }
        for (i, r) in refs.iter().enumerate() {
            entries.push(Entry::Line(ref_colour(i), reference_label(r)));
        }
        if !peers.is_empty() {
            entries.push(Entry::Head(
                "peers, same run and views (dashed; PSNR vs exact render)".into(),
            ));
        }
        for (i, p) in peers.iter().enumerate() {
            let psnr = p.psnr_db.map_or("no image".to_string(), |d| {
                if d.is_infinite() {
                    "identical images".to_string()
                } else {
                    format!("{d:.1} dB")
                }
            });
            entries.push(Entry::Dashed(
                peer_colour(i),
                format!("{} {}: {psnr}", i + 1, p.name),
            ));
        }
        entries.push(Entry::Note(
            "labels: index step (A = adaptive), where they fit".into(),
        ));
        let step = ((SIZE.1 as i32 - 60) / entries.len().max(1) as i32).clamp(12, 24);
        let size = (step - 3).min(15);
        let font = ("sans-serif", size).into_font();
        let bold = ("sans-serif", size + 1).into_font().color(&BLACK);
        right
            .draw(&Text::new(
                "legend",
                (12, 16),
                ("sans-serif", 18).into_font(),
            ))
            .map_err(err)?;
        let mut y = 44 + step / 2;
        let mid = size / 2;
        for e in &entries {
            match e {
                Entry::Head(t) => {
                    right
                        .draw(&Text::new(t.clone(), (12, y - mid), bold.clone()))
                        .map_err(err)?;
                }
                Entry::Note(t) => {
                    right
                        .draw(&Text::new(t.clone(), (12, y - mid), font.clone()))
                        .map_err(err)?;
                }
                Entry::Point(c, _, t) | Entry::Line(c, t) | Entry::Dashed(c, t) => {
                    match e {
                        Entry::Point(_, m, _) => draw_marker(&right, (24, y), 4, *m, *c)?,
                        Entry::Line(..) => right
                            .draw(&PathElement::new([(12, y), (36, y)], c.stroke_width(2)))
                            .map_err(err)?,
                        _ => {
                            for x in [12, 22, 32] {
                                right
                                    .draw(&PathElement::new(
                                        [(x, y), (x + 6, y)],
                                        c.stroke_width(2),
                                    ))
                                    .map_err(err)?;
                            }
                        }
                    }
                    right
                        .draw(&Text::new(t.clone(), (44, y - mid), font.clone()))
                        .map_err(err)?;
                }
            }
            y += step;
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
            projection: "equirect".into(),
            kernel: "scalar".into(),
        }
    }

    fn lut(ms: f64, err: f64, step: i64, table: &'static str) -> Row {
        Row {
            index_step: serde_json::json!(step),
            lut: Some(table.into()),
            surface: Some("cylinder".into()),
            max_err_px: Some(err),
            mean_err_px: Some(err / 4.0),
            ..Row::timed(&run(), "lut", Sampler::Bilinear, 90.0, 1, &[ms])
        }
    }

    #[test]
    fn every_series_has_its_own_colour_and_marker() {
        // Issue 33 (11): "lut wide nearest" (series 0) and "lut plane high bilinear"
        // (series 12) shared a colour; now their markers differ.
        let styles: Vec<_> = (0..48).map(series_style).collect();
        for (i, a) in styles.iter().enumerate() {
            for (j, b) in styles.iter().enumerate().skip(i + 1) {
                assert_ne!(a, b, "series {i} and {j}");
            }
        }
        assert_eq!(styles[0].0, styles[12].0);
        assert_ne!(styles[0].1, styles[12].1);
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
        plot(&path, &rows, &[]).unwrap();
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
        plot(&path, &rows, &[]).unwrap();
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
    fn log_axes_have_a_one_two_five_key_point_in_every_decade() {
        assert_eq!(
            log_key_points(1.9, 160.0, 20),
            vec![2.0, 5.0, 10.0, 20.0, 50.0, 100.0]
        );
        // Nothing outside the range.
        assert_eq!(
            log_key_points(2.1, 160.0, 20),
            vec![5.0, 10.0, 20.0, 50.0, 100.0]
        );
        let y = log_key_points(1e-5, 0.2, 20);
        assert_eq!(y.first(), Some(&0.00001));
        assert_eq!(y.last(), Some(&0.2));
        assert_eq!(y.len(), 14);
        assert!(y.iter().map(|v| tick(*v)).all(|t| !t.contains('e')));
        // A narrow range: 1 to 9 times; a crowded one: powers of ten, thinned.
        assert_eq!(log_key_points(2.6, 4.5, 20), vec![3.0, 4.0]);
        assert_eq!(
            log_key_points(1e-6, 1e3, 5),
            vec![1e-6, 1e-4, 0.01, 1.0, 100.0]
        );
        assert!(log_key_points(0.0, 1.0, 5).is_empty());
    }

    fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    const PEERS: &str = r#"{"threads": 1, "rows": [
        {"peer": "OpenCV remap, float maps, bilinear", "key": "cv_float_bil", "ms_median": 0.8,
         "ours_ms": 1.0, "ours": "lut bilinear adaptive", "ratio_ours_over_theirs": 1.25,
         "psnr_db_vs_exact": 71.7},
        {"peer": "OpenCV convertMaps (map building only)", "key": "cv_convert", "ms_median": 0.3,
         "ours_ms": null, "ours": "-", "ratio_ours_over_theirs": null, "psnr_db_vs_exact": null},
        {"peer": "again", "key": "cv_float_bil", "ms_median": 0.8, "psnr_db_vs_exact": 71.7},
        {"peer": "OpenCV remap, float maps, nearest", "key": "cv_float_nn", "ms_median": 0.2,
         "ours_ms": 0.3, "ours": "lut nearest adaptive", "ratio_ours_over_theirs": 1.5,
         "psnr_db_vs_exact": null, "identical": true}
    ]}"#;

    /// A reference line's legend names a stepped row's bound (as rows of older JSON files
    /// carry it for the cube scanline renderer's bilinear runs), and the bound survives
    /// the JSON round trip of `--replot`; exact rows carry none, which is every row
    /// `viewer bench` writes now.
    #[test]
    fn stepped_rows_name_their_bound() {
        let mut stepped = Row::timed(&run(), "cube-scanline", Sampler::Bilinear, 90.0, 1, &[5.0]);
        stepped.position_bound_texels = Some(0.0207);
        let exact = Row::timed(&run(), "cube-scanline", Sampler::Nearest, 90.0, 1, &[5.0]);
        assert_eq!(
            reference_label(&stepped),
            "cube-scanline, bilinear (stepped: max error <= 0.0207 face texel, bound)"
        );
        assert_eq!(reference_label(&exact), "cube-scanline, nearest");
        let json = serde_json::to_string(&[&stepped, &exact]).unwrap();
        assert_eq!(json.matches("position_bound_texels").count(), 1);
        let back: Vec<Row> = serde_json::from_str(&json).unwrap();
        assert_eq!(back, vec![stepped, exact]);
    }

    /// `--replot`: the rows of a `--json` run read back (the same rows), the peers read
    /// once per key, and the chart drawn with them.
    #[test]
    fn replot_reads_the_json_files_and_draws_the_peers() {
        let rows = vec![
            lut(1.0, 0.01, 4, "wide"),
            lut(0.5, 0.04, 8, "wide"),
            Row::timed(&run(), "exact", Sampler::Bilinear, 90.0, 1, &[20.0]),
        ];
        let tmp = tempfile::tempdir().unwrap();
        let ours = write(
            tmp.path(),
            "ours.json",
            &serde_json::to_string(&rows).unwrap(),
        );
        assert_eq!(read_rows(&ours).unwrap(), rows);
        let peers = read_peers(&write(tmp.path(), "peers.json", PEERS)).unwrap();
        assert_eq!(
            peers,
            vec![
                Peer {
                    name: "OpenCV remap, float maps, bilinear".into(),
                    ms: 0.8,
                    psnr_db: Some(71.7)
                },
                Peer {
                    name: "OpenCV convertMaps (map building only)".into(),
                    ms: 0.3,
                    psnr_db: None
                },
                Peer {
                    name: "OpenCV remap, float maps, nearest".into(),
                    ms: 0.2,
                    psnr_db: Some(f64::INFINITY)
                },
            ]
        );
        let png = tmp.path().join("replot.png");
        plot(&png, &rows, &peers).unwrap();
        let img = image::open(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), SIZE);
        // The first peer's dashed line is black, left of the plot's right edge.
        let black = (0..PLOT_W)
            .flat_map(|x| (0..SIZE.1).map(move |y| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0 == [0, 0, 0])
            .count();
        assert!(black > 200, "{black}");
    }

    #[test]
    fn bad_json_files_are_named_in_one_line() {
        let tmp = tempfile::tempdir().unwrap();
        let bad_row = PEERS.replace(r#""ms_median": 0.3"#, r#""ms_median": "slow""#);
        let peers = write(tmp.path(), "peers.json", &bad_row);
        let e = read_peers(&peers).unwrap_err().to_string();
        assert!(e.starts_with(&peers.display().to_string()), "{e}");
        assert!(!e.contains('\n'), "{e}");
        let missing = tmp.path().join("none.json");
        let e = read_rows(&missing).unwrap_err().to_string();
        assert!(e.contains("none.json: cannot read"), "{e}");
        for (name, text) in [
            ("a.json", "[{\"renderer\": 3}]"),
            ("b.json", "[]"),
            ("c.json", "{"),
        ] {
            let p = write(tmp.path(), name, text);
            let e = read_rows(&p).unwrap_err().to_string();
            assert!(e.starts_with(&p.display().to_string()), "{e}");
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
