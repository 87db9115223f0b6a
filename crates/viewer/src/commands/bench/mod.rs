//! `viewer bench`: speed against error for every renderer configuration, in one run.
//!
//! Two phases over the same fixed view sets (see [`configs::view_sets`]):
//! 1. **error**: per view, the exact map positions and the exact images (nearest and
//!    bilinear) are computed once; every LUT (cylinder by step, plane and diamond
//!    adaptive) and grid configuration's sampling positions (`Renderer::positions`, the
//!    same kernels as `render`) are compared with them
//!    (`accuracy::position_error`, the angular metric), and every renderer's image is
//!    compared with the exact image of the same sampler (PSNR over R, G, B, pooled over
//!    the set's frames).
//! 2. **speed**: every configuration renders every frame of the set, `--passes` times
//!    (each a warm-up pass, then a timed pass; the configurations take turns, pass by
//!    pass, so that a drifting machine's speed weighs on all alike: `time_configs`); the
//!    median milliseconds per frame is reported.
//!
//! Tables are built before timing (their build time is reported separately), so a frame's
//! time is all the per-view work: per-scanline setup plus the kernels. The grid renderer
//! has no table: its per-view build is inside every frame, and is also timed alone
//! (`Renderer::build_grid`; the grid rows' `table_build_ms`). A third set, the
//! minification set, compares samplers zoomed out with a supersampled truth.
//!
//! * [`mod@configs`]: the view sets and the renderer configurations;
//! * [`measure`]: the thread pool, errors, PSNR, timing;
//! * [`report`]: the rows (`--json`) and the text table;
//! * [`plot`]: `--plot` (and `--replot`: the chart again from a `--json` file, with the
//!   peers of `scripts/peers.py`); [`export`]: `--export-maps`.

pub mod configs;
pub mod export;
pub mod measure;
pub mod plot;
pub mod report;

use crate::args::{named, parse_map_size, parse_size, MaxPixelsArg, ProjectionOpt};
use anyhow::{anyhow, Context, Result};
use clap::Args;
use configs::{configs, given_view_sets, view_sets, ViewArg, ViewsArg};
use export::Export;
use lut_core::CubeMap;
use lut_core::{IndexStep, TableKind};
use lut_core::{Kernel, Projection, Renderer, Sampler, Surface};
use measure::{gather_source, in_pool, measure_errors, time_config, Ctx};
use report::{row_line, Row, RunInfo, Tables};
use std::path::PathBuf;
use std::time::Instant;

/// `viewer bench` arguments.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Panorama to measure; without it a generated 8192x4096 equirectangular grid map
    /// (`--map-size` changes the size).
    pub panorama: Option<PathBuf>,
    /// The map's projection (auto: detected from PANORAMA; equirect for the generated
    /// map).
    #[command(flatten)]
    pub projection: ProjectionOpt,
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
    #[arg(long, default_value = "quick", value_parser = named::<ViewsArg>())]
    pub views: ViewsArg,
    /// Time exactly this view instead of the view sets: YAW,PITCH,HFOV in degrees
    /// (repeatable; each view is its own set of one frame, on the table the renderer picks
    /// for its hfov, and every row carries `view` [yaw, pitch, hfov]; no minification set).
    #[arg(long = "view", value_name = "YAW,PITCH,HFOV", value_parser = configs::parse_view,
          conflicts_with = "views")]
    pub view: Vec<ViewArg>,
    /// Timed passes over each set, each after a warm-up pass (the configurations take
    /// turns, pass by pass).
    #[arg(long, default_value_t = 3)]
    pub passes: u32,
    /// Print one JSON array instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Also write the speed-against-error chart to this PNG.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Measure nothing: redraw the chart (`--plot`, required) from the rows a
    /// `viewer bench --json` run wrote to this file.
    #[arg(long, value_name = "OURS_JSON", requires = "plot", conflicts_with_all = ["json", "export_maps", "panorama"])]
    pub replot: Option<PathBuf>,
    /// With --replot: also draw the peers `scripts/peers.py` measured in the same run (its
    /// peers.json), as dashed lines with their PSNR against the exact render.
    #[arg(long, value_name = "PEERS_JSON", requires = "replot")]
    pub peers: Option<PathBuf>,
    /// Also export, for the hfov-90 set, the source map (map.rgb, raw RGB24), the exact
    /// sampling maps in OpenCV's convention (mapx_NN.f32 / mapy_NN.f32 = u − ½, v − ½),
    /// the exact renders (exact_{bilinear,nearest}_NN.rgb) and views.json, for
    /// scripts/peers.py.
    #[arg(long)]
    pub export_maps: Option<PathBuf>,
    /// Skip the cube renderers (they convert the map to a cube first, which takes a while).
    #[arg(long)]
    pub no_cube: bool,
    /// Measure only the configurations the peers are compared with (LUT, wide table,
    /// adaptive index step, nearest and bilinear) on the hfov-90 set: no cube, no
    /// minification set. `scripts/peers.py --rounds` runs this between its rounds of
    /// OpenCV timings, so that ours and theirs are timed in turns.
    #[arg(long, conflicts_with_all = ["export_maps", "plot"])]
    pub only_default: bool,
    /// Skip the minification set (zoomed out: bilinear and trilinear against the exact
    /// render supersampled 8x8, which takes a while).
    #[arg(long)]
    pub no_minify: bool,
    /// The span kernel: auto (the best this CPU runs), scalar, sse41, avx2 or avx512 (default:
    /// LUTPANO_KERNEL, else auto). The kernel that ran and the CPU features detected are
    /// printed with the results.
    #[arg(long, value_parser = parse_kernel_choice)]
    pub kernel: Option<KernelChoice>,
    /// The pixel limit for PANORAMA.
    #[command(flatten)]
    pub limit: MaxPixelsArg,
}

/// `--kernel`: a kernel, or `auto` (`None`: the best the CPU runs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KernelChoice(pub Option<Kernel>);

/// Parse `--kernel` (`auto` or a kernel name; whether the CPU runs it is checked when
/// the bench starts).
fn parse_kernel_choice(s: &str) -> Result<KernelChoice, String> {
    if s.eq_ignore_ascii_case("auto") {
        return Ok(KernelChoice(None));
    }
    lut_core::parse_name::<Kernel>(s)
        .map(|k| KernelChoice(Some(k)))
        .ok_or_else(|| {
            format!(
                "unknown kernel '{s}' (expected auto, {})",
                lut_core::name_list::<Kernel>()
            )
        })
}

/// Milliseconds per frame of every configuration of `cfgs` over the set, the passes
/// taking turns: each [`time_config`] call is one warm-up pass and one timed pass, and
/// pass p of every configuration runs before pass p + 1 of any (exact renders: pass 1
/// only, as `time_config` times them once).
///
/// Why: timed one after the other, each configuration's passes fell in one window of a
/// few seconds, and on a VM whose speed drifts by 20–30 % over seconds the ratios
/// between configurations (the cube scanline frame against the LUT's measured 0.64x and
/// 1.11x in two runs of the same code) followed the drift more than the code. Taking
/// turns puts every configuration's samples across the whole measurement.
fn time_configs(
    ctx: &Ctx,
    renderer: &mut Renderer,
    cfgs: &[configs::Config],
    gather_idx: &[Vec<u32>],
    passes: u32,
) -> Result<Vec<Vec<f64>>> {
    let mut times = vec![Vec::new(); cfgs.len()];
    for pass in 0..passes {
        for (cfg, t) in cfgs.iter().zip(&mut times) {
            if pass > 0 && matches!(cfg, configs::Config::Exact(_)) {
                continue;
            }
            t.extend(time_config(ctx, renderer, *cfg, gather_idx, 1)?);
        }
    }
    Ok(times)
}

/// Run `viewer bench`.
pub fn run(a: BenchArgs) -> Result<()> {
    if a.passes == 0 {
        return Err(crate::usage!("--passes must be at least 1"));
    }
    if let Some(ours) = &a.replot {
        return replot(ours, a.peers.as_deref(), a.plot.as_deref());
    }
    if let Some(KernelChoice(k)) = a.kernel {
        lut_core::set_kernel(k).map_err(|e| anyhow!("--kernel: {e}"))?;
    }
    in_pool(a.threads, |threads| run_in_pool(&a, threads))
}

/// `--replot`: the chart from the rows in `ours` and the peers in `peers`; both files
/// are read before anything is drawn, so a bad one leaves no PNG.
fn replot(
    ours: &std::path::Path,
    peers: Option<&std::path::Path>,
    png: Option<&std::path::Path>,
) -> Result<()> {
    let png = png.ok_or_else(|| crate::usage!("--replot needs --plot PNG"))?;
    let rows = plot::read_rows(ours)?;
    let peers = match peers {
        Some(p) => plot::read_peers(p)?,
        None => Vec::new(),
    };
    plot::plot(png, &rows, &peers)
        .with_context(|| format!("{}: cannot draw the chart", png.display()))
}

/// Progress goes to stderr (with --json, stdout is only the JSON array).
pub fn progress(msg: &str) {
    crate::errln!("bench: {msg}");
}

fn run_in_pool(a: &BenchArgs, threads: usize) -> Result<()> {
    let t0 = Instant::now();
    let projection = a.projection.value.map_only("bench")?;
    let map = match &a.panorama {
        Some(p) => crate::panorama::load_panorama(
            Some(p),
            &a.limit.options(projection, lut_core::Tone::default()),
        )?,
        None => lut_core::grid_map(
            a.map_size.0,
            a.map_size.1,
            projection.unwrap_or(Projection::Equirect),
        )
        .map_err(|e| anyhow!("cannot generate the benchmark map: {e}"))?,
    };
    progress(&format!(
        "map {}x{} {:?} ready in {:.1} s; {} threads",
        map.width(),
        map.height(),
        map.projection(),
        t0.elapsed().as_secs_f64(),
        threads
    ));
    let kernel = lut_core::kernel_info();
    progress(&kernel.to_string());
    let (w, h) = a.size;
    let run = RunInfo {
        width: w,
        height: h,
        threads,
        map_width: map.width(),
        map_height: map.height(),
        projection: map.projection().name().into(),
        kernel: kernel.active.name().into(),
    };
    let mut sets = if a.view.is_empty() {
        view_sets(a.views)?
    } else {
        given_view_sets(&a.view)?
    };
    if a.only_default && a.view.is_empty() {
        sets.retain(|s| s.table == TableKind::Wide && s.hfov == 90.0);
    }
    let mut renderer = Renderer::new(&map);

    // Tables: built once, timed, before any frame (the cylinder's, then the other
    // surfaces').
    let mut build = |surface: Surface| {
        let mut tables = Tables::default();
        for (i, kind) in [TableKind::Wide, TableKind::High].into_iter().enumerate() {
            let t = Instant::now();
            // (`Renderer::new` gave the renderer the map's geometry: the table is built.)
            if let Some(table) = renderer.table(surface, kind) {
                tables.build_ms[i] = t.elapsed().as_secs_f64() * 1e3;
                tables.bytes[i] = table.bytes();
                tables.unfolded[i] = table.unfolded_bytes();
            }
        }
        tables
    };
    let tables = build(Surface::Cylinder);
    // (`--only-default` reports neither the other surfaces nor the gather.)
    let others: Vec<(&str, Tables)> = configs::OTHER_SURFACES
        .iter()
        .filter(|_| !a.only_default)
        .map(|&sf| (sf.name(), build(sf)))
        .collect();

    let cube_map = if a.no_cube || a.only_default {
        None
    } else {
        // Faces of a quarter of the map's width: as many texels per degree along the
        // equator and the meridians through the face centres as the map has there (the
        // same texel density: the comparison with the LUT frames is fair; wider faces,
        // e.g. width / π, read up to 1.6x the texels, docs/performance.md, "Cube against
        // the LUT per view").
        let size = (map.width() / 4).clamp(16, 4096);
        let t = Instant::now();
        let c = CubeMap::from_envmap(&map, size, Sampler::Bilinear)
            .map_err(|e| anyhow!("cannot convert the map to a cube: {e}"))?;
        progress(&format!(
            "cube {size}² faces converted in {:.1} s",
            t.elapsed().as_secs_f64()
        ));
        Some(lut_core::Panorama::cube(c))
    };
    let src: Vec<u32> = if a.only_default {
        Vec::new()
    } else {
        gather_source(&map)
    };

    let mut rows = Vec::new();
    // The export: the hfov-90 set's views, or every `--view`.
    let mut export = match &a.export_maps {
        Some(d) => Some(Export::start(d, &src)?),
        None => None,
    };
    for set in &sets {
        let export = match &mut export {
            Some(ex) if set.given.is_some() || set.table == TableKind::Wide => Some(ex),
            _ => None,
        };
        let mut cfgs = configs(cube_map.is_some());
        if a.only_default {
            cfgs.retain(|c| matches!(c, configs::Config::Lut(_, IndexStep::Adaptive)));
        }
        let ctx = Ctx {
            map: &map,
            cube: cube_map.as_ref(),
            src: &src,
            set,
            w,
            h,
        };
        let errs = measure_errors(&ctx, &mut renderer, &cfgs, export)?;
        let ti = if set.table == TableKind::Wide { 0 } else { 1 };
        let times = time_configs(&ctx, &mut renderer, &cfgs, &errs.gather_idx, a.passes)?;
        for ((cfg, e), times) in cfgs.iter().zip(&errs.per_config).zip(times) {
            let (index_step, lut) = cfg.lut_fields(set.table);
            let mut row = Row {
                index_step,
                lut: lut.map(Into::into),
                ..Row::timed(
                    &run,
                    cfg.renderer_name(),
                    cfg.sampler(),
                    set.hfov,
                    set.views.len(),
                    &times,
                )
            };
            e.fill(&mut row);
            row.view = set.given;
            row.surface = cfg.surface().map(Into::into);
            match cfg {
                configs::Config::Lut(..) => {
                    row.exact_fraction = Some(e.exact_fraction());
                    row.table_bytes = Some(tables.bytes[ti]);
                    row.table_build_ms = Some(tables.build_ms[ti]);
                }
                configs::Config::LutSurface(_, sf) => {
                    let t = &others
                        .iter()
                        .find(|(n, _)| *n == sf.name())
                        .ok_or_else(|| anyhow!("internal: no {} tables", sf.name()))?
                        .1;
                    row.exact_fraction = Some(e.exact_fraction());
                    row.table_bytes = Some(t.bytes[ti]);
                    row.table_build_ms = Some(t.build_ms[ti]);
                }
                configs::Config::Grid(_) => {
                    row.exact_fraction = Some(e.exact_fraction());
                    let build = measure::time_grid_build(&ctx, &mut renderer, a.passes)?;
                    row.table_build_ms = Some(measure::median(&build));
                }
                _ => {}
            }
            progress(&row_line(&row));
            rows.push(row);
        }
    }

    if let Some(ex) = export {
        ex.finish((map.width(), map.height()), (w, h))?;
    }

    let mut minify_note = None;
    if !a.no_minify && !a.only_default && a.view.is_empty() {
        let (mut mrows, note) = measure::minify_set(&run, a.size, a.passes, &map, &mut renderer)?;
        rows.append(&mut mrows);
        minify_note = Some(note);
    }

    if let Some(p) = &a.plot {
        plot::plot(p, &rows, &[])
            .with_context(|| format!("{}: cannot draw the chart", p.display()))?;
    }
    if a.json {
        crate::outln!("{}", serde_json::to_string_pretty(&rows)?)?;
    } else {
        report::write_table(
            &mut std::io::stdout().lock(),
            &rows,
            &tables,
            &others,
            &kernel.to_string(),
        )?;
        if let Some(n) = minify_note {
            crate::outln!("{n}")?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::cli::{Cli, Command};
    use clap::Parser;

    fn bench_args(extra: &[&str]) -> Result<super::BenchArgs, clap::Error> {
        let mut argv = vec!["viewer", "bench"];
        argv.extend_from_slice(extra);
        match Cli::try_parse_from(argv)?.command {
            Some(Command::Bench(a)) => Ok(a),
            other => panic!("not bench: {other:?}"),
        }
    }

    #[test]
    fn arguments_parse_with_their_defaults() {
        let a = bench_args(&[]).unwrap();
        assert_eq!(
            (a.map_size, a.size, a.passes),
            ((8192, 4096), (1920, 1080), 3)
        );
        assert_eq!(a.views, super::ViewsArg::Quick);
        assert_eq!(a.projection.value.map_only("bench").unwrap(), None);
        let a = bench_args(&[
            "--views",
            "full",
            "--map-size",
            "512x256",
            "--projection",
            "sine",
            "--threads",
            "2",
            "--json",
            "--no-cube",
            "--no-minify",
        ])
        .unwrap();
        assert_eq!(a.views, super::ViewsArg::Full);
        assert_eq!(a.map_size, (512, 256));
        assert_eq!(
            a.projection.value.map_only("bench").unwrap(),
            Some(lut_core::Projection::Sine)
        );
        assert!(a.json && a.no_cube && a.no_minify && a.threads == Some(2));
        assert_eq!(a.kernel, None);
        for (k, want) in [("auto", None), ("scalar", Some(lut_core::Kernel::Scalar))] {
            let a = bench_args(&["--kernel", k]).unwrap();
            assert_eq!(a.kernel, Some(super::KernelChoice(want)));
        }
        for (flag, bad) in [
            ("--views", "all"),
            ("--map-size", "big"),
            ("--size", "1x0"),
            ("--kernel", "neon9"),
        ] {
            let e = bench_args(&[flag, bad]).unwrap_err().to_string();
            assert!(e.contains(bad), "{e}");
        }
    }

    #[test]
    fn views_given_on_the_command_line() {
        let a = bench_args(&["--view", "30,90,90", "--view", "0,0,150"]).unwrap();
        assert_eq!(
            a.view,
            [
                super::ViewArg([30.0, 90.0, 90.0]),
                super::ViewArg([0.0, 0.0, 150.0])
            ]
        );
        assert!(bench_args(&[]).unwrap().view.is_empty());
        for bad in ["30,90", "x,0,90", "0,100,90", "0,0,200"] {
            let e = bench_args(&["--view", bad]).unwrap_err().to_string();
            assert!(e.contains(bad), "{e}");
        }
        let e = bench_args(&["--view", "0,0,90", "--views", "full"]).unwrap_err();
        assert_eq!(e.kind(), clap::error::ErrorKind::ArgumentConflict);
    }

    #[test]
    fn replot_needs_plot_and_writes_nothing_from_a_bad_file() {
        let e = bench_args(&["--replot", "ours.json"]).unwrap_err();
        assert_eq!(e.kind(), clap::error::ErrorKind::MissingRequiredArgument);
        assert!(e.to_string().contains("--plot"), "{e}");
        let e = bench_args(&["--peers", "p.json", "--plot", "a.png"]).unwrap_err();
        assert!(e.to_string().contains("--replot"), "{e}");
        let tmp = tempfile::tempdir().unwrap();
        let ours = tmp.path().join("ours.json");
        let peers = tmp.path().join("peers.json");
        std::fs::write(&ours, "[]").unwrap();
        std::fs::write(&peers, r#"{"rows": [{"peer": "x"}]}"#).unwrap();
        let png = tmp.path().join("chart.png");
        let (o, p, g) = (
            ours.to_str().unwrap(),
            peers.to_str().unwrap(),
            png.to_str().unwrap(),
        );
        for args in [
            vec!["--replot", o, "--plot", g],
            vec!["--replot", p, "--plot", g],
        ] {
            let e = super::run(bench_args(&args).unwrap()).unwrap_err();
            assert!(format!("{e:#}").contains(args[1]), "{e:#}");
            assert!(!png.exists());
        }
    }
}
