//! `viewer bench-tiles`: gigapixel panoramas from tiles. For synthetic Pannellum pyramids
//! of 16k, 64k and 256k width (`viewer tile --synthetic`, written once into a cache folder
//! and reused), each measured in a fresh child process with the pyramid's files dropped
//! from the page cache (cold): process start to first picture, view stop to sharp, the
//! frame times of a pan with tiles arriving (across levels: zooming in and out) and of a
//! pan over resident tiles (median and p99), the peak resident memory (`VmHWM`) and the
//! decoding pool's tiles and Mpixel per second per thread. `--plot` draws the chart
//! (`plot.rs`), `--replot JSON` draws it again from a `--json` run. -> docs/huge.md.

pub mod plot;

use super::bench::measure::median;
use super::bench_load::proc_status_bytes;
use crate::args::parse_size;
use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use lut_core::{Sampler, TiledPanorama, View};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// Arguments of `viewer bench-tiles`.
#[derive(Args, Debug)]
pub struct BenchTilesArgs {
    /// Panorama widths of the synthetic pyramids (equirectangular width; the cube face is
    /// about width / π), comma-separated; a k suffix means ×1024 (16k = 16384).
    #[arg(long, value_delimiter = ',', default_value = "16k,64k,256k", value_parser = parse_width)]
    pub widths: Vec<u64>,
    /// Folder for the generated pyramids, made once and reused (default:
    /// $TMPDIR/viewer-bench-tiles). Nothing is written into the repository.
    #[arg(long)]
    pub cache: Option<PathBuf>,
    /// Tile size of the generated pyramids.
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(16..=8192))]
    pub tile_size: u32,
    /// Output size of the frames.
    #[arg(long, default_value = "1920x1080", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Frames of each pan.
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(2..=100_000))]
    pub frames: u32,
    /// Horizontal field of view where the view stops and of the resident pan, degrees.
    #[arg(long, default_value_t = 90.0)]
    pub hfov: f64,
    /// The tile cache's budget, MiB.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u64).range(16..=1 << 20))]
    pub cache_mib: u64,
    /// Decoding threads (default: the cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=256))]
    pub threads: Option<u32>,
    /// Print one JSON array instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Also draw the chart (times and peak memory against the panorama's width) into
    /// this PNG.
    #[arg(long, value_name = "PNG")]
    pub plot: Option<PathBuf>,
    /// Measure nothing: draw the chart (`--plot`, required) from the JSON an earlier
    /// `--json` run printed.
    #[arg(long, value_name = "JSON", requires = "plot", conflicts_with_all = ["json", "child"])]
    pub replot: Option<PathBuf>,
    /// Internal: measure this pyramid in this process and print one JSON line.
    #[arg(long, hide = true)]
    pub child: Option<PathBuf>,
    /// Internal: the parent's clock (ns since the Unix epoch) when it started the child.
    #[arg(long, hide = true)]
    pub started_ns: Option<u64>,
    /// Internal: whether the pyramid's files were dropped from the page cache.
    #[arg(long, hide = true)]
    pub cold: bool,
}

/// Parse a panorama width: 16384 or 16k (even, at least 26: a face of 8 pixels).
fn parse_width(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (num, mult) = match t.strip_suffix(['k', 'K']) {
        Some(n) => (n, 1024),
        None => (t, 1),
    };
    let w = num
        .parse::<u64>()
        .ok()
        .and_then(|n| n.checked_mul(mult))
        .ok_or_else(|| format!("panorama width '{s}' must be a whole number, e.g. 16384 or 16k"))?;
    if !(26..=1_600_000).contains(&w) || w % 2 != 0 {
        return Err(format!(
            "panorama width '{s}' must be even, from 26 to 1600000"
        ));
    }
    Ok(w)
}

/// One pyramid's measurements (one child process).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct TilesSample {
    /// The synthetic panorama's width (its height is half).
    pub width: u64,
    /// The pyramid's cube face (`cubeResolution`).
    pub cube: u32,
    /// Its levels (`maxLevel`).
    pub max_level: u32,
    /// Its tile size (`tileResolution`).
    pub tile: u32,
    /// The pyramid's files were dropped from the page cache before the child started.
    pub cold: bool,
    /// Output size of the frames.
    pub frame_width: u32,
    /// Output height.
    pub frame_height: u32,
    /// Process start (the parent spawning the child) to the first picture drawn.
    pub first_picture_ms: f64,
    /// Of that, opening the pyramid (config, level 1 decoded).
    pub open_ms: f64,
    /// The view stopped (after the pan with tiles arriving) to every tile of the view
    /// at the wanted level drawn; `null` when not sharp within 60 s.
    pub sharp_ms: Option<f64>,
    /// The level the stopped view wants (still: no pixel magnified by more than √2).
    #[serde(default)]
    pub sharp_level: u32,
    /// Tiles decoded from the stop until sharp (the view's missing tiles, their
    /// ancestors and whatever prefetch was already queued).
    #[serde(default)]
    pub sharp_tiles_decoded: u64,
    /// Tiles of that level the stopped view reads.
    #[serde(default)]
    pub sharp_view_tiles: u32,
    /// Frames drawn from the stop until sharp.
    #[serde(default)]
    pub sharp_frames: u32,
    /// Pan over resident tiles: median frame time.
    pub pan_resident_ms_median: f64,
    /// Pan over resident tiles: 99th percentile frame time.
    pub pan_resident_ms_p99: f64,
    /// Frames of the resident pan drawn coarser than wanted (0 when the cache holds them).
    pub pan_resident_coarser: u32,
    /// Pan with tiles arriving (new ground, zooming in and out across levels): median.
    pub pan_arriving_ms_median: f64,
    /// Pan with tiles arriving: 99th percentile.
    pub pan_arriving_ms_p99: f64,
    /// Frames of that pan drawn coarser than wanted (tiles still decoding).
    pub pan_arriving_coarser: u32,
    /// Levels that pan drew from (lowest, highest).
    pub pan_arriving_levels: (u32, u32),
    /// Peak resident memory of the child (VmHWM).
    pub peak_rss_bytes: u64,
    /// The cache's budget.
    pub cache_budget_bytes: u64,
    /// Bytes of decoded tiles held at the end.
    pub cache_bytes: u64,
    /// Decoding threads.
    pub threads: u32,
    /// Tiles decoded in the child.
    pub tiles_decoded: u64,
    /// Tiles decoded per second of a thread's decoding time (file read included).
    pub tiles_per_s_per_thread: f64,
    /// Mpixel decoded per second of a thread's decoding time.
    pub mpixel_per_s_per_thread: f64,
}

/// Run `viewer bench-tiles`.
pub fn run(a: BenchTilesArgs) -> Result<()> {
    if let Some(p) = &a.child {
        let s = measure(p, &a)?;
        crate::outln!("{}", serde_json::to_string(&s)?)?;
        return Ok(());
    }
    if let (Some(json), Some(png)) = (&a.replot, &a.plot) {
        // Both read before anything is drawn: a bad file leaves no PNG.
        let rows = plot::read_rows(json)?;
        return plot::plot(png, &rows);
    }
    let cache = a
        .cache
        .clone()
        .unwrap_or_else(|| std::env::temp_dir().join("viewer-bench-tiles"));
    std::fs::create_dir_all(&cache)
        .with_context(|| format!("{}: cannot create the cache folder", cache.display()))?;
    let exe = std::env::current_exe().context("cannot find the viewer executable")?;
    let mut rows = Vec::new();
    for &w in &a.widths {
        let dir = cache.join(format!("synthetic_{w}x{}_t{}", w / 2, a.tile_size));
        if !dir.join("config.json").is_file() {
            crate::errln!("generating {} ...", dir.display());
            let t = Instant::now();
            let st = std::process::Command::new(&exe)
                .arg("tile")
                .args(["--synthetic", &format!("{w}x{}", w / 2)])
                .args(["--tile-size", &a.tile_size.to_string()])
                .arg("-q")
                .arg("-o")
                .arg(&dir)
                // Its summary line would spoil the JSON on standard output.
                .stdout(std::process::Stdio::null())
                .status()
                .context("cannot run viewer tile")?;
            if !st.success() {
                bail!("viewer tile --synthetic {w}x{} failed", w / 2);
            }
            crate::errln!("  done in {:.1} s", t.elapsed().as_secs_f64());
        }
        let cold = drop_from_page_cache(&dir)?;
        crate::errln!(
            "measuring {} in a child process{} ...",
            dir.display(),
            if cold { " (cold)" } else { "" }
        );
        let mut s = measure_child(&exe, &dir, &a, cold)?;
        s.width = w;
        rows.push(s);
    }
    if a.json {
        crate::outln!("{}", serde_json::to_string_pretty(&rows)?)?;
    } else {
        print_table(&rows, &a)?;
    }
    if let Some(png) = &a.plot {
        plot::plot(png, &rows)?;
    }
    Ok(())
}

/// Drop every file under `dir` from the page cache (flushed first, so freshly written
/// files go too): `posix_fadvise(POSIX_FADV_DONTNEED)`. Returns whether it could
/// (Linux); elsewhere the first picture is measured warm.
fn drop_from_page_cache(dir: &Path) -> Result<bool> {
    #[cfg(target_os = "linux")]
    {
        let mut stack = vec![dir.to_path_buf()];
        while let Some(d) = stack.pop() {
            let rd =
                std::fs::read_dir(&d).with_context(|| format!("{}: cannot list", d.display()))?;
            for e in rd {
                let e = e.with_context(|| format!("{}: cannot list", d.display()))?;
                let t = e.file_type()?;
                if t.is_dir() {
                    stack.push(e.path());
                } else if t.is_file() {
                    let f = std::fs::File::open(e.path())
                        .with_context(|| format!("{}: cannot open", e.path().display()))?;
                    f.sync_data().ok();
                    rustix::fs::fadvise(&f, 0, None, rustix::fs::Advice::DontNeed).with_context(
                        || format!("{}: cannot drop from the page cache", e.path().display()),
                    )?;
                }
            }
        }
        Ok(true)
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = dir;
        Ok(false)
    }
}

/// Measure the pyramid `dir` in a child process (`viewer bench-tiles --child`).
fn measure_child(exe: &Path, dir: &Path, a: &BenchTilesArgs, cold: bool) -> Result<TilesSample> {
    let mut cmd = std::process::Command::new(exe);
    cmd.arg("bench-tiles")
        .arg("--child")
        .arg(dir)
        .args(["--size", &format!("{}x{}", a.size.0, a.size.1)])
        .args(["--frames", &a.frames.to_string()])
        .args(["--hfov", &a.hfov.to_string()])
        .args(["--cache-mib", &a.cache_mib.to_string()])
        .stderr(std::process::Stdio::inherit());
    if let Some(t) = a.threads {
        cmd.args(["--threads", &t.to_string()]);
    }
    if cold {
        cmd.arg("--cold");
    }
    let now = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .unwrap_or_default()
        .as_nanos();
    cmd.args(["--started-ns", &now.to_string()]);
    let out = cmd
        .output()
        .context("cannot run the measuring child process")?;
    if !out.status.success() {
        bail!("measuring {} failed", dir.display());
    }
    let line = String::from_utf8_lossy(&out.stdout);
    serde_json::from_str(line.trim())
        .map_err(|e| anyhow!("child output is not a measurement ({e}): {line}"))
}

/// The `q`-quantile (0..=1) of `v` by the nearest rank (0 for none).
fn quantile(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let rank = (q * s.len() as f64).ceil() as usize;
    s[rank.clamp(1, s.len()) - 1]
}

/// The child's work: open, first picture, a pan with tiles arriving, the stop until
/// sharp, a pan over resident tiles; report.
fn measure(dir: &Path, a: &BenchTilesArgs) -> Result<TilesSample> {
    // Process start as the parent saw it (the same wall clock), else this process's.
    let since_start = {
        let started = a.started_ns.map(|ns| UNIX_EPOCH + Duration::from_nanos(ns));
        let local = Instant::now();
        move || -> f64 {
            match started {
                Some(s) => SystemTime::now()
                    .duration_since(s)
                    .unwrap_or_default()
                    .as_secs_f64(),
                None => local.elapsed().as_secs_f64(),
            }
        }
    };
    let threads = a.threads.unwrap_or_else(|| {
        std::thread::available_parallelism().map_or(1, |n| n.get().min(256) as u32)
    });
    let (w, h) = a.size;
    let t_open = Instant::now();
    let budget = (a.cache_mib as usize).saturating_mul(1 << 20);
    let mut pano = TiledPanorama::open(dir, budget, threads as usize)?;
    let open_ms = t_open.elapsed().as_secs_f64() * 1e3;
    let mut px = vec![0u32; w as usize * h as usize];
    let start = View::new(0.0, 0.0, a.hfov)?;
    let level = |p: &TiledPanorama, v: View, still: bool| {
        lut_core::tile_frame_level(p.store(), v, w, h, still)
    };
    let l0 = level(&pano, start, true);
    pano.render(start, Sampler::Bilinear, l0, &mut px, w, h, true);
    let first_picture_ms = since_start() * 1e3;

    // Pan with tiles arriving: new ground (yaw 0 → 180°, pitch 0 → 30°), zooming in to a
    // fifth of the field of view and out again, each frame on its centre's level.
    let n = a.frames;
    let mut arriving = Vec::with_capacity(n as usize);
    let (mut coarser, mut lo, mut hi) = (0u32, u32::MAX, 0u32);
    let pose = |i: u32| -> Result<View> {
        let t = f64::from(i) / f64::from(n - 1);
        let zoom = 1.0 - 0.8 * (std::f64::consts::PI * t).sin();
        Ok(View::new(180.0 * t, 30.0 * t, a.hfov * zoom)?)
    };
    for i in 0..n {
        let v = pose(i)?;
        let t = Instant::now();
        let l = level(&pano, v, false);
        let f = pano.render(v, Sampler::Bilinear, l, &mut px, w, h, true);
        arriving.push(t.elapsed().as_secs_f64() * 1e3);
        coarser += u32::from(f.coarser());
        lo = lo.min(f.level);
        hi = hi.max(f.level);
    }

    // The view stops: still frames until every tile at the wanted level is drawn.
    let stop = pose(n - 1)?;
    let t_stop = Instant::now();
    let mut sharp_ms = None;
    let decoded_at_stop = pano.decode_stats().tiles;
    let sharp_level = level(&pano, stop, true);
    let mut sharp_frames = 0u32;
    let mut sharp_view_tiles = 0u32;
    while t_stop.elapsed() < Duration::from_secs(60) {
        let l = level(&pano, stop, true);
        let f = pano.render(stop, Sampler::Bilinear, l, &mut px, w, h, true);
        sharp_frames += 1;
        sharp_view_tiles = u32::try_from(f.touched.len()).unwrap_or(u32::MAX);
        if !f.coarser() {
            sharp_ms = Some(t_stop.elapsed().as_secs_f64() * 1e3);
            break;
        }
        if pano.pending() == 0 {
            // Nothing left to wait for: the missing tiles failed (a notice each).
            break;
        }
        std::thread::sleep(Duration::from_millis(1));
    }

    let sharp_tiles_decoded = pano.decode_stats().tiles - decoded_at_stop;

    // Pan over resident tiles: a slow pan around the stop, its tiles loaded first.
    let resident_pose = |i: u32| -> Result<View> {
        let t = f64::from(i) / f64::from(n - 1);
        Ok(View::new(
            stop.yaw_deg() - 10.0 + 20.0 * t,
            stop.pitch_deg(),
            a.hfov,
        )?)
    };
    for i in 0..n {
        let v = resident_pose(i)?;
        let l = level(&pano, v, false);
        pano.render_wait(v, Sampler::Bilinear, l, &mut px, w, h);
    }
    let mut resident = Vec::with_capacity(n as usize);
    let mut resident_coarser = 0u32;
    for i in 0..n {
        let v = resident_pose(i)?;
        let t = Instant::now();
        let l = level(&pano, v, false);
        let f = pano.render(v, Sampler::Bilinear, l, &mut px, w, h, true);
        resident.push(t.elapsed().as_secs_f64() * 1e3);
        resident_coarser += u32::from(f.coarser());
    }

    let cfg = pano.config();
    let d = pano.decode_stats();
    let stats = pano.store().stats();
    let per_thread = |x: f64| if d.busy_s > 0.0 { x / d.busy_s } else { 0.0 };
    Ok(TilesSample {
        width: 0,
        cube: cfg.cube,
        max_level: cfg.max_level,
        tile: cfg.tile,
        cold: a.cold,
        frame_width: w,
        frame_height: h,
        first_picture_ms,
        open_ms,
        sharp_ms,
        sharp_level,
        sharp_tiles_decoded,
        sharp_view_tiles,
        sharp_frames,
        pan_resident_ms_median: median(&resident),
        pan_resident_ms_p99: quantile(&resident, 0.99),
        pan_resident_coarser: resident_coarser,
        pan_arriving_ms_median: median(&arriving),
        pan_arriving_ms_p99: quantile(&arriving, 0.99),
        pan_arriving_coarser: coarser,
        pan_arriving_levels: (lo, hi),
        peak_rss_bytes: proc_status_bytes("VmHWM:").unwrap_or(0),
        cache_budget_bytes: stats.budget as u64,
        cache_bytes: stats.bytes as u64,
        threads,
        tiles_decoded: d.tiles,
        tiles_per_s_per_thread: per_thread(d.tiles as f64),
        mpixel_per_s_per_thread: per_thread(d.texels as f64 * 1e-6),
    })
}

fn mib(b: u64) -> f64 {
    b as f64 / 1048576.0
}

fn print_table(rows: &[TilesSample], a: &BenchTilesArgs) -> Result<()> {
    crate::outln!("{}", lut_core::kernel_info())?;
    crate::outln!(
        "frames {}x{}, bilinear; stop and resident pan at hfov {}°; {} frames a pan; cache {} MiB",
        a.size.0,
        a.size.1,
        a.hfov,
        a.frames,
        a.cache_mib
    )?;
    crate::outln!(
        "| panorama | cube face | levels | cold | first picture ms (open) | sharp ms (level, view's tiles, tiles decoded, frames) | pan resident ms median / p99 | pan arriving ms median / p99 (coarser frames) | peak RSS MiB | tiles decoded | tiles/s/thread | Mpx/s/thread |"
    )?;
    crate::outln!("|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|")?;
    for s in rows {
        crate::outln!(
            "| {}x{} | {} | {} | {} | {:.0} ({:.0}) | {} ({}, {}, {}, {}) | {:.1} / {:.1} | {:.1} / {:.1} ({}) | {:.0} | {} | {:.0} | {:.1} |",
            s.width,
            s.width / 2,
            s.cube,
            s.max_level,
            if s.cold { "yes" } else { "no" },
            s.first_picture_ms,
            s.open_ms,
            s.sharp_ms.map_or("not sharp".into(), |m| format!("{m:.0}")),
            s.sharp_level,
            s.sharp_view_tiles,
            s.sharp_tiles_decoded,
            s.sharp_frames,
            s.pan_resident_ms_median,
            s.pan_resident_ms_p99,
            s.pan_arriving_ms_median,
            s.pan_arriving_ms_p99,
            s.pan_arriving_coarser,
            mib(s.peak_rss_bytes),
            s.tiles_decoded,
            s.tiles_per_s_per_thread,
            s.mpixel_per_s_per_thread,
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widths_parse() {
        assert_eq!(parse_width("16k"), Ok(16384));
        assert_eq!(parse_width("256K"), Ok(262144));
        assert_eq!(parse_width("2048"), Ok(2048));
        assert!(parse_width("24").is_err());
        assert!(parse_width("2049").is_err());
        assert!(parse_width("x").is_err());
    }

    #[test]
    fn quantiles_by_nearest_rank() {
        let v: Vec<f64> = (1..=100).rev().map(f64::from).collect();
        assert_eq!(quantile(&v, 0.99), 99.0);
        assert_eq!(quantile(&v, 1.0), 100.0);
        assert_eq!(quantile(&v[..10], 0.99), 100.0);
        assert_eq!(quantile(&[], 0.5), 0.0);
    }
}
