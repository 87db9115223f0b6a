//! `viewer bench`: speed against error for every renderer configuration, in one run.
//!
//! Two phases over the same fixed view sets (see [`view_sets`]):
//! 1. **error**: per view, the exact map positions and the exact images (nearest and
//!    bilinear) are computed once; every LUT configuration's sampling positions
//!    (`Renderer::positions`, the same kernel as `render`) are compared with them
//!    (`accuracy::position_error`, the angular metric), and every renderer's image is
//!    compared with the exact image of the same sampler (PSNR over R, G, B, pooled over
//!    the set's frames).
//! 2. **speed**: every configuration renders every frame of the set (one warm-up pass,
//!    then `--passes` timed passes); the median milliseconds per frame is reported.
//!
//! Tables are built before timing (their build time is reported separately), so a frame's
//! time is all the per-view work: per-scanline setup plus the kernels.

use crate::cli_common::{parse_size, write_png_atomic};
use anyhow::{anyhow, bail, Context, Result};
use clap::{Args, ValueEnum};
use lut_core::exact_uv;
use lut_core::position_error;
use lut_core::{
    Camera, EnvMap, IndexStep, LutChoice, Projection, RenderOptions, Renderer, RendererKind,
    Sampler, View,
};
use lut_core::{CubeMap, CubeRenderer};
use lut_core::{Frame, Scene};
use lut_core::{Surface, TableKind};
use rayon::prelude::*;
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Which views to measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ViewsArg {
    /// 5 fixed views and an 8-frame pan per set.
    Quick,
    /// 9 fixed views (adds the zenith and near-nadir) and a 24-frame pan per set.
    Full,
}

/// `viewer bench` arguments.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Panorama to measure; without it a generated 8192x4096 equirectangular grid map
    /// (`--map-size` changes the size).
    pub panorama: Option<PathBuf>,
    /// Map projection: equirect, cylinder, sine, elliptical, diamond (omitted: detected
    /// from PANORAMA, equirect for the generated map).
    #[arg(long, value_parser = parse_projection_name)]
    pub projection: Option<Projection>,
    /// Size of the generated map when no PANORAMA is given.
    #[arg(long, default_value = "8192x4096", value_parser = parse_map_size)]
    pub map_size: (u32, u32),
    /// Output size WIDTHxHEIGHT.
    #[arg(long, default_value = "1920x1080", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Worker threads (a rayon pool of this size runs every renderer); default: all cores.
    #[arg(long)]
    pub threads: Option<usize>,
    /// The view sets: quick or full.
    #[arg(long, value_enum, default_value_t = ViewsArg::Quick)]
    pub views: ViewsArg,
    /// Timed passes over each set (after one warm-up pass).
    #[arg(long, default_value_t = 3)]
    pub passes: u32,
    /// Print one JSON array instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Also write the speed-against-error chart to this PNG.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Also export, for the hfov-90 set, the source map (map.rgb, raw RGB24), the exact
    /// sampling maps in OpenCV's convention (mapx_NN.f32 / mapy_NN.f32 = u − ½, v − ½),
    /// the exact renders (exact_{bilinear,nearest}_NN.rgb) and views.json, for
    /// scripts/peers.py.
    #[arg(long)]
    pub export_maps: Option<PathBuf>,
    /// Skip the cube renderers (they convert the map to a cube first, which takes a while).
    #[arg(long)]
    pub no_cube: bool,
    /// Skip the minification set (zoomed out: bilinear and trilinear against the exact
    /// render supersampled 8x8, which takes a while).
    #[arg(long)]
    pub no_minify: bool,
    /// The pixel limit for PANORAMA.
    #[command(flatten)]
    pub limit: crate::max_pixels::MaxPixelsArg,
}

fn parse_projection_name(s: &str) -> Result<Projection, String> {
    s.parse()
}

fn parse_map_size(s: &str) -> Result<(u32, u32), String> {
    let (a, b) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("map size '{s}' must look like WIDTHxHEIGHT, e.g. 8192x4096"))?;
    let w: u32 = a
        .trim()
        .parse()
        .map_err(|_| format!("map size '{s}': bad width"))?;
    let h: u32 = b
        .trim()
        .parse()
        .map_err(|_| format!("map size '{s}': bad height"))?;
    lut_core::check_map_size("generated map", w, h).map_err(|e| e.to_string())?;
    Ok((w, h))
}

/// A set of frames rendered with one table choice.
struct ViewSet {
    /// "wide" or "high": the table the set is natural for.
    table: TableKind,
    hfov: f64,
    views: Vec<View>,
}

/// The fixed, documented view sets. Each has fixed views (center, the ±180° seam, two
/// oblique, near a pole; `full` adds the zenith, near-nadir and two more) and a pan at
/// pitch 10° (yaw advancing by 360°/n, offset 3.7° so no frame is axis-aligned). The wide
/// table's set is at hfov 90°, the high table's at hfov 50° (its natural range, < 60°;
/// forcing the high table at 90° would make the pixels beyond it exact).
fn view_sets(which: ViewsArg) -> Result<Vec<ViewSet>> {
    let mut fixed: Vec<(f64, f64)> = vec![
        (0.0, 0.0),
        (180.0, 0.0),
        (37.5, 25.0),
        (-100.0, -45.0),
        (60.0, 80.0),
    ];
    let pan_frames = match which {
        ViewsArg::Quick => 8,
        ViewsArg::Full => {
            fixed.extend([(0.0, 90.0), (-150.0, -89.9), (123.4, 60.0), (270.2, -10.0)]);
            24
        }
    };
    let pan = (0..pan_frames).map(|k| (3.7 + k as f64 * 360.0 / pan_frames as f64, 10.0));
    let all: Vec<(f64, f64)> = fixed.into_iter().chain(pan).collect();
    [(TableKind::Wide, 90.0), (TableKind::High, 50.0)]
        .into_iter()
        .map(|(table, hfov)| {
            let views = all
                .iter()
                .map(|&(y, p)| View::new(y, p, hfov).map_err(|e| anyhow!("bench view: {e}")))
                .collect::<Result<Vec<_>>>()?;
            Ok(ViewSet { table, hfov, views })
        })
        .collect()
}

/// One renderer configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Config {
    Exact(Sampler),
    Lut(Sampler, IndexStep),
    Cube(Sampler, CubeRenderer),
    /// A plain gather along precomputed (exact, nearest) indices: the floor for any
    /// table-driven renderer.
    Gather,
}

const STEPS: [IndexStep; 6] = [
    IndexStep::Fixed(1),
    IndexStep::Fixed(2),
    IndexStep::Fixed(4),
    IndexStep::Fixed(8),
    IndexStep::Fixed(16),
    IndexStep::Adaptive,
];
const SAMPLERS: [Sampler; 2] = [Sampler::Nearest, Sampler::Bilinear];

fn configs(cube: bool) -> Vec<Config> {
    let mut v: Vec<Config> = SAMPLERS.iter().map(|&s| Config::Exact(s)).collect();
    for s in SAMPLERS {
        for st in STEPS {
            v.push(Config::Lut(s, st));
        }
    }
    if cube {
        for s in SAMPLERS {
            for r in [CubeRenderer::Basic, CubeRenderer::Accelerated] {
                v.push(Config::Cube(s, r));
            }
        }
    }
    v.push(Config::Gather);
    v
}

/// One line of the report (one element of the `--json` array).
#[derive(Debug, Clone, Serialize)]
struct Row {
    renderer: &'static str,
    sampler: &'static str,
    /// A number, "adaptive", or null (not a LUT renderer).
    index_step: serde_json::Value,
    /// "wide", "high" or null.
    lut: Option<&'static str>,
    width: u32,
    height: u32,
    threads: usize,
    map_width: u32,
    map_height: u32,
    projection: String,
    hfov: f64,
    frames: usize,
    ms_median: f64,
    ms_min: f64,
    ms_max: f64,
    /// Max sampling-position error over all frames, source pixels (null: not measured,
    /// e.g. a cube renderer samples cube faces, not the map).
    max_err_px: Option<f64>,
    mean_err_px: Option<f64>,
    /// PSNR against the exact render with the same sampler (null: identical images).
    psnr_db: Option<f64>,
    /// PSNR against the exact render supersampled 8×8 per pixel (the minification set).
    #[serde(skip_serializing_if = "Option::is_none")]
    psnr_ss_db: Option<f64>,
    /// Fraction of pixels the LUT renderer evaluated exactly (pole zones, beyond a table).
    exact_fraction: Option<f64>,
    table_bytes: Option<usize>,
    table_build_ms: Option<f64>,
}

/// Run `viewer bench`.
pub fn run(a: BenchArgs) -> Result<()> {
    if a.passes == 0 {
        bail!("--passes must be at least 1");
    }
    let threads = a.threads.unwrap_or_else(rayon::current_num_threads);
    if threads == 0 {
        bail!("--threads must be at least 1");
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("cannot start the thread pool")?;
    pool.install(|| run_in_pool(&a, threads))
}

fn run_in_pool(a: &BenchArgs, threads: usize) -> Result<()> {
    let t0 = Instant::now();
    let map = match &a.panorama {
        Some(p) => crate::cli_common::load_panorama_opts(
            Some(p),
            &a.limit.options(a.projection, lut_core::Tone::default()),
        )?,
        None => lut_core::grid_map(
            a.map_size.0,
            a.map_size.1,
            a.projection.unwrap_or(Projection::Equirect),
        )
        .map_err(|e| anyhow!("cannot generate the benchmark map: {e}"))?,
    };
    progress(
        a,
        &format!(
            "map {}x{} {:?} ready in {:.1} s; {} threads",
            map.width(),
            map.height(),
            map.projection(),
            t0.elapsed().as_secs_f64(),
            threads
        ),
    );
    let (w, h) = a.size;
    let sets = view_sets(a.views)?;
    let mut renderer = Renderer::new(&map);

    // Tables: built once, timed, before any frame.
    let mut build_ms = [0.0f64; 2];
    let mut table_bytes = [0usize; 2];
    let mut unfolded_bytes = [0usize; 2];
    for (i, kind) in [TableKind::Wide, TableKind::High].into_iter().enumerate() {
        let t = Instant::now();
        let table = renderer.table(Surface::Cylinder, kind);
        build_ms[i] = t.elapsed().as_secs_f64() * 1e3;
        table_bytes[i] = table.bytes();
        unfolded_bytes[i] = table.unfolded_bytes();
    }

    let cube_map = if a.no_cube {
        None
    } else {
        let size = (map.width() / 4).clamp(16, 4096);
        let t = Instant::now();
        let c = CubeMap::from_envmap(&map, size, Sampler::Bilinear)
            .map_err(|e| anyhow!("cannot convert the map to a cube: {e}"))?;
        progress(
            a,
            &format!(
                "cube {size}² faces converted in {:.1} s",
                t.elapsed().as_secs_f64()
            ),
        );
        Some(c)
    };
    let src: Vec<u32> = gather_source(&map);

    let mut rows = Vec::new();
    for set in &sets {
        let export = match (&a.export_maps, set.table) {
            (Some(d), TableKind::Wide) => Some(d.as_path()),
            _ => None,
        };
        let cfgs = configs(cube_map.is_some());
        let ctx = Ctx {
            map: &map,
            cube: cube_map.as_ref(),
            src: &src,
            set,
            w,
            h,
        };
        let errs = measure_errors(&ctx, &mut renderer, &cfgs, export, a)?;
        for (ci, cfg) in cfgs.iter().enumerate() {
            let times = time_config(&ctx, &mut renderer, *cfg, &errs.gather_idx, a.passes)?;
            let e = &errs.per_config[ci];
            let (renderer_name, sampler, step, lut) = describe(*cfg, set.table);
            let is_lut = matches!(cfg, Config::Lut(..));
            let ti = if set.table == TableKind::Wide { 0 } else { 1 };
            let row = Row {
                renderer: renderer_name,
                sampler,
                index_step: step,
                lut,
                width: w,
                height: h,
                threads,
                map_width: map.width(),
                map_height: map.height(),
                projection: format!("{:?}", map.projection()).to_lowercase(),
                hfov: set.hfov,
                frames: set.views.len(),
                ms_median: median(&times),
                ms_min: times.iter().cloned().fold(f64::INFINITY, f64::min),
                ms_max: times.iter().cloned().fold(0.0, f64::max),
                max_err_px: e.pos_count.map(|_| e.max),
                mean_err_px: e
                    .pos_count
                    .map(|n| if n > 0 { e.sum / n as f64 } else { 0.0 }),
                psnr_db: psnr(e.sse, e.samples),
                psnr_ss_db: None,
                exact_fraction: is_lut.then(|| e.exact_px as f64 / e.px.max(1) as f64),
                table_bytes: is_lut.then_some(table_bytes[ti]),
                table_build_ms: is_lut.then_some(build_ms[ti]),
            };
            progress(a, &row_line(&row));
            rows.push(row);
        }
    }

    let mut minify_note = None;
    if !a.no_minify {
        let (mut mrows, note) = minify_set(a, &map, &mut renderer, threads)?;
        rows.append(&mut mrows);
        minify_note = Some(note);
    }

    if let Some(p) = &a.plot {
        plot(p, &rows).with_context(|| format!("{}: cannot draw the chart", p.display()))?;
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        print_table(&rows, build_ms, table_bytes, unfolded_bytes);
        if let Some(n) = minify_note {
            println!("{n}");
        }
    }
    Ok(())
}

/// The minification set: zoomed out (hfov 120 at a third of the output size, so one
/// screen pixel covers several map pixels), the five fixed views; bilinear and trilinear,
/// LUT (adaptive step) and exact, timed and compared by PSNR with the exact render
/// supersampled 8×8 per pixel (box filter, bilinear sub-samples).
fn minify_set(
    a: &BenchArgs,
    map: &EnvMap,
    renderer: &mut Renderer,
    threads: usize,
) -> Result<(Vec<Row>, String)> {
    let (w, h) = ((a.size.0 / 3).max(1), (a.size.1 / 3).max(1));
    let hfov = 120.0;
    let views = [
        (0.0, 0.0),
        (180.0, 0.0),
        (37.5, 25.0),
        (-100.0, -45.0),
        (60.0, 80.0),
    ]
    .iter()
    .map(|&(y, p)| View::new(y, p, hfov).map_err(|e| anyhow!("bench view: {e}")))
    .collect::<Result<Vec<_>>>()?;
    let t = Instant::now();
    map.pyramid();
    let pyr_ms = t.elapsed().as_secs_f64() * 1e3;
    let n = w as usize * h as usize;
    let mut truths = Vec::new();
    for (i, v) in views.iter().enumerate() {
        let mut t = vec![0u32; n];
        lut_core::render_exact_supersampled(
            map,
            *v,
            Sampler::Bilinear,
            8,
            &mut Frame::new(&mut t, w, h)?,
            true,
        );
        truths.push(t);
        progress(a, &format!("minify: 8x8 truth {}/{}", i + 1, views.len()));
    }
    let cfgs = [
        (RendererKind::Lut, Sampler::Nearest),
        (RendererKind::Lut, Sampler::Bilinear),
        (RendererKind::Lut, Sampler::Trilinear),
        (RendererKind::Exact, Sampler::Bilinear),
        (RendererKind::Exact, Sampler::Trilinear),
    ];
    let mut rows = Vec::new();
    let mut out = vec![0u32; n];
    for (kind, sampler) in cfgs {
        let opts = RenderOptions {
            renderer: kind,
            sampler,
            index_step: IndexStep::Adaptive,
            lut: LutChoice::Wide,
            ..RenderOptions::default()
        };
        let (mut err, mut times) = (0u64, Vec::new());
        for (v, truth) in views.iter().zip(&truths) {
            renderer.render(Scene::Map(map), *v, &opts, &mut Frame::new(&mut out, w, h)?)?;
            err += sse(&out, truth);
        }
        for _ in 0..a.passes {
            for v in &views {
                let t = Instant::now();
                renderer.render(Scene::Map(map), *v, &opts, &mut Frame::new(&mut out, w, h)?)?;
                times.push(t.elapsed().as_secs_f64() * 1e3);
            }
        }
        let is_lut = kind == RendererKind::Lut;
        let row = Row {
            renderer: if is_lut { "lut" } else { "exact" },
            sampler: sampler.name(),
            index_step: if is_lut {
                serde_json::json!("adaptive")
            } else {
                serde_json::Value::Null
            },
            lut: is_lut.then_some("wide"),
            width: w,
            height: h,
            threads,
            map_width: map.width(),
            map_height: map.height(),
            projection: format!("{:?}", map.projection()).to_lowercase(),
            hfov,
            frames: views.len(),
            ms_median: median(&times),
            ms_min: times.iter().cloned().fold(f64::INFINITY, f64::min),
            ms_max: times.iter().cloned().fold(0.0, f64::max),
            max_err_px: None,
            mean_err_px: None,
            psnr_db: None,
            psnr_ss_db: psnr(err, (n * views.len() * 3) as u64),
            exact_fraction: None,
            table_bytes: None,
            table_build_ms: None,
        };
        progress(a, &row_line(&row));
        rows.push(row);
    }
    let mut note = format!(
        "minification set: {w}x{h} at hfov {hfov}, {} views; pyramid built in {pyr_ms:.0} ms, \
         {:.1} MiB ({:.0} % of the map); PSNR against the exact render supersampled 8x8:",
        views.len(),
        map.pyramid_bytes() as f64 / 1048576.0,
        100.0 * map.pyramid_bytes() as f64 / map.bytes() as f64
    );
    for r in &rows {
        note.push_str(&format!(
            "\n  {:<6} {:<9} {:>7.2} ms  {:>5.1} dB",
            r.renderer,
            r.sampler,
            r.ms_median,
            r.psnr_ss_db.unwrap_or(f64::INFINITY)
        ));
    }
    Ok((rows, note))
}

/// Progress goes to stderr (with --json, stdout is only the JSON array).
fn progress(_a: &BenchArgs, msg: &str) {
    eprintln!("bench: {msg}");
}

struct Ctx<'a> {
    map: &'a EnvMap,
    cube: Option<&'a CubeMap>,
    src: &'a [u32],
    set: &'a ViewSet,
    w: u32,
    h: u32,
}

fn lut_opts(sampler: Sampler, step: IndexStep, table: TableKind) -> RenderOptions {
    RenderOptions {
        renderer: RendererKind::Lut,
        sampler,
        index_step: step,
        lut: match table {
            TableKind::Wide => LutChoice::Wide,
            _ => LutChoice::High,
        },
        surface: Surface::Cylinder,
        threads: true,
        ..RenderOptions::default()
    }
}

fn describe(
    cfg: Config,
    table: TableKind,
) -> (
    &'static str,
    &'static str,
    serde_json::Value,
    Option<&'static str>,
) {
    let lut = match table {
        TableKind::Wide => "wide",
        _ => "high",
    };
    match cfg {
        Config::Exact(s) => ("exact", s.name(), serde_json::Value::Null, None),
        Config::Lut(s, st) => (
            "lut",
            s.name(),
            match st {
                IndexStep::Fixed(n) => serde_json::json!(n),
                IndexStep::Adaptive => serde_json::json!("adaptive"),
            },
            Some(lut),
        ),
        Config::Cube(s, CubeRenderer::Basic) => {
            ("cube-basic", s.name(), serde_json::Value::Null, None)
        }
        Config::Cube(s, CubeRenderer::Accelerated) => {
            ("cube-scanline", s.name(), serde_json::Value::Null, None)
        }
        Config::Gather => ("gather", "nearest", serde_json::Value::Null, None),
    }
}

/// The map's pixels, unpadded, row-major: the source of the plain gather.
fn gather_source(map: &EnvMap) -> Vec<u32> {
    let (mw, mh) = (map.width(), map.height());
    let mut v = vec![0u32; mw as usize * mh as usize];
    v.par_chunks_mut(mw as usize)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, p) in row.iter_mut().enumerate() {
                *p = map.pixel(x as u32, y as u32);
            }
        });
    v
}

#[derive(Debug, Clone, Copy, Default)]
struct ErrAcc {
    /// Some(pixels compared) when positions are measured.
    pos_count: Option<u64>,
    max: f64,
    sum: f64,
    sse: u64,
    samples: u64,
    exact_px: u64,
    px: u64,
}

struct Errors {
    per_config: Vec<ErrAcc>,
    /// Per view: the map index of each output pixel's exact nearest sample (u32::MAX =
    /// background).
    gather_idx: Vec<Vec<u32>>,
}

fn measure_errors(
    ctx: &Ctx,
    renderer: &mut Renderer,
    cfgs: &[Config],
    export: Option<&Path>,
    a: &BenchArgs,
) -> Result<Errors> {
    let (w, h) = (ctx.w, ctx.h);
    let n = w as usize * h as usize;
    let map = ctx.map;
    let (mw, mh, proj) = (map.width(), map.height(), map.projection());
    let mut acc = vec![ErrAcc::default(); cfgs.len()];
    let mut gather_idx = Vec::with_capacity(ctx.set.views.len());
    let mut manifest = Vec::new();
    if let Some(dir) = export {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create the export folder", dir.display()))?;
        write_rgb(&dir.join("map.rgb"), ctx.src)?;
    }
    let mut img = vec![0u32; n];
    let mut exact_img = [vec![0u32; n], vec![0u32; n]];
    for (vi, &view) in ctx.set.views.iter().enumerate() {
        let cam = Camera::new(view, w, h);
        // Exact positions and latitudes, once per view.
        let mut exact: Vec<(Option<(f64, f64)>, f64)> = vec![(None, 0.0); n];
        exact
            .par_chunks_mut(w as usize)
            .enumerate()
            .for_each(|(y, row)| {
                for (x, e) in row.iter_mut().enumerate() {
                    let uv = exact_uv(&cam, proj, mw as f64, mh as f64, x as u32, y as u32);
                    *e = (uv, cam.pixel_lat_long(x as u32, y as u32).1);
                }
            });
        for (si, s) in SAMPLERS.iter().enumerate() {
            lut_core::render_exact(
                map,
                view,
                *s,
                &mut Frame::new(&mut exact_img[si], w, h)?,
                true,
            );
        }
        let idx: Vec<u32> = exact
            .par_iter()
            .map(|(uv, _)| match uv {
                Some((u, v)) => {
                    let x = (u.floor() as i64).rem_euclid(mw as i64) as u32;
                    let y = (v.floor() as i64).clamp(0, mh as i64 - 1) as u32;
                    y * mw + x
                }
                None => u32::MAX,
            })
            .collect();
        if let Some(dir) = export {
            export_view(dir, vi, &exact, &exact_img)?;
            manifest.push(serde_json::json!({
                "yaw": view.yaw_deg(), "pitch": view.pitch_deg(), "hfov": view.hfov_deg(),
                "mapx": format!("mapx_{vi:02}.f32"), "mapy": format!("mapy_{vi:02}.f32"),
                "exact_bilinear": format!("exact_bilinear_{vi:02}.rgb"),
                "exact_nearest": format!("exact_nearest_{vi:02}.rgb"),
            }));
        }
        for (ci, cfg) in cfgs.iter().enumerate() {
            let e = &mut acc[ci];
            match *cfg {
                Config::Exact(_) => {
                    e.pos_count = Some(e.pos_count.unwrap_or(0) + n as u64);
                }
                Config::Lut(s, st) => {
                    let opts = lut_opts(s, st, ctx.set.table);
                    // Positions do not depend on the sampler: measure them once (nearest).
                    if s == Sampler::Nearest {
                        let (pos, rep) = renderer.positions(mw, mh, proj, view, &opts, w, h)?;
                        let (max, sum, cnt) = compare(&pos, &exact, proj, mw, mh);
                        e.max = e.max.max(max);
                        e.sum += sum;
                        e.pos_count = Some(e.pos_count.unwrap_or(0) + cnt);
                        e.exact_px += rep.exact_pixels;
                        e.px += rep.pixels;
                    }
                    renderer.render(
                        Scene::Map(map),
                        view,
                        &opts,
                        &mut Frame::new(&mut img, w, h)?,
                    )?;
                }
                Config::Cube(s, r) => {
                    let c = ctx.cube.expect("cube configs only with a cube");
                    render_cube(c, view, s, r, &mut img, w, h)?;
                }
                Config::Gather => gather(ctx.src, &idx, &mut img, w as usize, map.background()),
            }
            let si = match *cfg {
                Config::Exact(s) | Config::Lut(s, _) | Config::Cube(s, _) => s,
                Config::Gather => Sampler::Nearest,
            };
            let reference = &exact_img[if si == Sampler::Nearest { 0 } else { 1 }];
            if let Config::Exact(_) = cfg {
                e.samples += 3 * n as u64; // identical by definition
            } else {
                e.sse += sse(&img, reference);
                e.samples += 3 * n as u64;
            }
        }
        // Share the sampler-independent position stats with the bilinear LUT rows.
        for ci in 0..cfgs.len() {
            if let Config::Lut(Sampler::Bilinear, st) = cfgs[ci] {
                if let Some(nj) = cfgs
                    .iter()
                    .position(|c| *c == Config::Lut(Sampler::Nearest, st))
                {
                    let src = acc[nj];
                    let e = &mut acc[ci];
                    e.pos_count = src.pos_count;
                    e.max = src.max;
                    e.sum = src.sum;
                    e.exact_px = src.exact_px;
                    e.px = src.px;
                }
            }
        }
        gather_idx.push(idx);
        progress(
            a,
            &format!(
                "hfov {} view {}/{} (yaw {:.1}, pitch {:.1}) measured",
                ctx.set.hfov,
                vi + 1,
                ctx.set.views.len(),
                view.yaw_deg(),
                view.pitch_deg()
            ),
        );
    }
    if let Some(dir) = export {
        let doc = serde_json::json!({
            "map": "map.rgb", "map_width": mw, "map_height": mh,
            "width": w, "height": h, "threads": rayon::current_num_threads(),
            "convention": "mapx/mapy: float32, row-major, OpenCV pixel centers (u - 0.5, v - 0.5); NaN = background",
            "views": manifest,
        });
        std::fs::write(dir.join("views.json"), serde_json::to_string_pretty(&doc)?)
            .with_context(|| format!("{}: cannot write views.json", dir.display()))?;
    }
    Ok(Errors {
        per_config: acc,
        gather_idx,
    })
}

/// (max, sum, count) of the angular-metric position error over pixels both sides cover.
fn compare(
    pos: &[Option<(f64, f64)>],
    exact: &[(Option<(f64, f64)>, f64)],
    proj: Projection,
    mw: u32,
    mh: u32,
) -> (f64, f64, u64) {
    pos.par_iter()
        .zip(exact.par_iter())
        .fold(
            || (0.0f64, 0.0f64, 0u64),
            |(mx, sum, cnt), (got, (ex, phi))| match (got, ex) {
                (Some(g), Some(e)) => {
                    let d = position_error(proj, mw as f64, mh as f64, *phi, *e, *g);
                    let d = if d.is_finite() { d } else { f64::INFINITY };
                    (mx.max(d), sum + d, cnt + 1)
                }
                _ => (mx, sum, cnt),
            },
        )
        .reduce(
            || (0.0, 0.0, 0),
            |a, b| (a.0.max(b.0), a.1 + b.1, a.2 + b.2),
        )
}

fn gather(src: &[u32], idx: &[u32], out: &mut [u32], w: usize, background: u32) {
    out.par_chunks_mut(w)
        .zip(idx.par_chunks(w))
        .with_min_len((16384 / w.max(1)).max(1))
        .for_each(|(o, i)| {
            for (p, &k) in o.iter_mut().zip(i) {
                *p = src.get(k as usize).copied().unwrap_or(background);
            }
        });
}

fn sse(a: &[u32], b: &[u32]) -> u64 {
    a.par_iter()
        .zip(b.par_iter())
        .map(|(&x, &y)| {
            let mut s = 0u64;
            for sh in [0, 8, 16] {
                let d = ((x >> sh) & 0xFF) as i64 - ((y >> sh) & 0xFF) as i64;
                s += (d * d) as u64;
            }
            s
        })
        .sum()
}

fn psnr(sse: u64, samples: u64) -> Option<f64> {
    if sse == 0 || samples == 0 {
        return None;
    }
    let mse = sse as f64 / samples as f64;
    Some(10.0 * (255.0f64 * 255.0 / mse).log10())
}

fn time_config(
    ctx: &Ctx,
    renderer: &mut Renderer,
    cfg: Config,
    gather_idx: &[Vec<u32>],
    passes: u32,
) -> Result<Vec<f64>> {
    let (w, h) = (ctx.w, ctx.h);
    let mut out = vec![0u32; w as usize * h as usize];
    let mut times = Vec::new();
    // Exact renders are slow and vary little: one timed pass, no warm-up.
    let exact = matches!(cfg, Config::Exact(_));
    let warm = u32::from(!exact);
    let passes = if exact { 1 } else { passes };
    for pass in 0..passes + warm {
        for (vi, &view) in ctx.set.views.iter().enumerate() {
            let t = Instant::now();
            match cfg {
                Config::Exact(s) => {
                    lut_core::render_exact(ctx.map, view, s, &mut Frame::new(&mut out, w, h)?, true)
                }
                Config::Lut(s, st) => {
                    renderer.render(
                        Scene::Map(ctx.map),
                        view,
                        &lut_opts(s, st, ctx.set.table),
                        &mut Frame::new(&mut out, w, h)?,
                    )?;
                }
                Config::Cube(s, r) => {
                    let c = ctx.cube.expect("cube configs only with a cube");
                    render_cube(c, view, s, r, &mut out, w, h)?;
                }
                Config::Gather => gather(
                    ctx.src,
                    &gather_idx[vi],
                    &mut out,
                    w as usize,
                    ctx.map.background(),
                ),
            }
            std::hint::black_box(&out);
            if pass >= warm {
                times.push(t.elapsed().as_secs_f64() * 1e3);
            }
        }
    }
    Ok(times)
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(|a, b| a.total_cmp(b));
    let n = s.len();
    if n == 0 {
        0.0
    } else if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

fn write_rgb(path: &Path, px: &[u32]) -> Result<()> {
    let mut buf = Vec::with_capacity(px.len() * 3);
    for p in px {
        buf.extend_from_slice(&[(p >> 16) as u8, (p >> 8) as u8, *p as u8]);
    }
    std::fs::write(path, buf).with_context(|| format!("{}: cannot write", path.display()))
}

fn export_view(
    dir: &Path,
    vi: usize,
    exact: &[(Option<(f64, f64)>, f64)],
    imgs: &[Vec<u32>; 2],
) -> Result<()> {
    let mut mx = Vec::with_capacity(exact.len() * 4);
    let mut my = Vec::with_capacity(exact.len() * 4);
    for (uv, _) in exact {
        let (u, v) = uv.map_or((f32::NAN, f32::NAN), |(u, v)| {
            ((u - 0.5) as f32, (v - 0.5) as f32)
        });
        mx.extend_from_slice(&u.to_le_bytes());
        my.extend_from_slice(&v.to_le_bytes());
    }
    let p = dir.join(format!("mapx_{vi:02}.f32"));
    std::fs::write(&p, mx).with_context(|| format!("{}: cannot write", p.display()))?;
    let p = dir.join(format!("mapy_{vi:02}.f32"));
    std::fs::write(&p, my).with_context(|| format!("{}: cannot write", p.display()))?;
    write_rgb(&dir.join(format!("exact_nearest_{vi:02}.rgb")), &imgs[0])?;
    write_rgb(&dir.join(format!("exact_bilinear_{vi:02}.rgb")), &imgs[1])
}

fn fmt_opt(v: Option<f64>, prec: usize) -> String {
    v.map_or("-".to_string(), |x| format!("{x:.prec$}"))
}

fn step_str(v: &serde_json::Value) -> String {
    match v {
        serde_json::Value::Null => "-".into(),
        serde_json::Value::String(s) => s.clone(),
        o => o.to_string(),
    }
}

fn row_line(r: &Row) -> String {
    format!(
        "{:<13} {:<8} {:>8} {:<4} {:>5} {:>9.2} {:>9.2} {:>10} {:>10} {:>7} {:>7}",
        r.renderer,
        r.sampler,
        step_str(&r.index_step),
        r.lut.unwrap_or("-"),
        r.hfov,
        r.ms_median,
        r.ms_min,
        fmt_opt(r.max_err_px, 4),
        fmt_opt(r.mean_err_px, 5),
        fmt_opt(r.psnr_db, 1),
        r.exact_fraction
            .map_or("-".into(), |f| format!("{:.2}%", f * 100.0)),
    )
}

fn print_table(rows: &[Row], build_ms: [f64; 2], bytes: [usize; 2], unfolded: [usize; 2]) {
    let mut o = std::io::stdout().lock();
    if let Some(r) = rows.first() {
        let _ = writeln!(
            o,
            "map {}x{} {}, output {}x{}, {} threads, {} frames per set",
            r.map_width, r.map_height, r.projection, r.width, r.height, r.threads, r.frames
        );
    }
    let _ = writeln!(
        o,
        "tables: wide {:.1} ms, {} KiB (unfolded {} KiB, 1/{:.2}); high {:.1} ms, {} KiB (unfolded {} KiB, 1/{:.2})",
        build_ms[0],
        bytes[0] / 1024,
        unfolded[0] / 1024,
        unfolded[0] as f64 / bytes[0].max(1) as f64,
        build_ms[1],
        bytes[1] / 1024,
        unfolded[1] / 1024,
        unfolded[1] as f64 / bytes[1].max(1) as f64
    );
    let _ = writeln!(
        o,
        "{:<13} {:<8} {:>8} {:<4} {:>5} {:>9} {:>9} {:>10} {:>10} {:>7} {:>7}",
        "renderer",
        "sampler",
        "step",
        "lut",
        "hfov",
        "ms_med",
        "ms_min",
        "max_err",
        "mean_err",
        "PSNR",
        "exact"
    );
    for r in rows {
        let _ = writeln!(o, "{}", row_line(r));
    }
    let _ = writeln!(
        o,
        "errors in source pixels (angular metric); PSNR in dB against the exact render with the same sampler ('-' = identical)"
    );
}

/// Draw the speed-against-error chart: one point per LUT configuration (x: median ms per
/// frame, y: max sampling-position error), one series per (table, sampler), vertical
/// lines for the other renderers at hfov 90, and the 0.05 px budget.
fn plot(path: &Path, rows: &[Row]) -> Result<()> {
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
                    r0.width, r0.height, r0.map_width, r0.map_height, r0.threads
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
        let series = [
            ("wide", "bilinear", BLUE, "LUT wide (hfov 90), bilinear"),
            ("wide", "nearest", CYAN, "LUT wide (hfov 90), nearest"),
            ("high", "bilinear", GREEN, "LUT high (hfov 50), bilinear"),
            ("high", "nearest", MAGENTA, "LUT high (hfov 50), nearest"),
        ];
        for (lut, sampler, color, label) in series {
            let sel: Vec<&Row> = rows
                .iter()
                .filter(|r| {
                    r.renderer == "lut"
                        && r.lut == Some(lut)
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

/// One frame of a cube map through lut-core's render entry (all threads).
fn render_cube(
    cube: &CubeMap,
    view: View,
    sampler: Sampler,
    renderer: CubeRenderer,
    out: &mut [u32],
    w: u32,
    h: u32,
) -> Result<()> {
    let opts = RenderOptions {
        sampler,
        cube: renderer,
        threads: true,
        ..RenderOptions::default()
    };
    Renderer::default().render(Scene::Cube(cube), view, &opts, &mut Frame::new(out, w, h)?)?;
    Ok(())
}
