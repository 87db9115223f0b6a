//! `viewer bench-load`: huge panoramas. For generated equirectangular maps of 8192×4096,
//! 16384×8192 and 32768×16384 (JPEG, made once and cached), each measured in a fresh
//! child process so the peak memory is that size's alone: file size, load time
//! (decode + convert, with the phase split), table build time, the median frame time of a
//! 1920×1080 pan (LUT, bilinear and nearest) and the peak resident memory (`VmHWM`).

use super::bench::measure::median;
use crate::args::{parse_size, MaxPixelsArg};
use crate::output::write_image_atomic;
use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use lut_core::Frame;
use lut_core::TableKind;
use lut_core::{LoadPhase, Projection, RenderOptions, Renderer, Sampler, Tone, View};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `viewer bench-load`.
#[derive(Args, Debug)]
pub struct BenchLoadArgs {
    /// Map widths (equirectangular, height = width / 2), comma-separated; a K suffix
    /// means ×1024 (8k = 8192).
    #[arg(long, value_delimiter = ',', default_value = "8k,16k,32k", value_parser = parse_width)]
    pub widths: Vec<u32>,
    /// Folder for the generated JPEGs, made once and reused (default:
    /// $TMPDIR/viewer-bench-load). Nothing is written into the repository.
    #[arg(long)]
    pub cache: Option<PathBuf>,
    /// JPEG quality of the generated maps.
    #[arg(long, default_value_t = 90, value_parser = clap::value_parser!(u8).range(1..=100))]
    pub quality: u8,
    /// Output size of the pan.
    #[arg(long, default_value = "1920x1080", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Frames per pan (yaw steps over a full turn, pitch 10°, hfov --hfov).
    #[arg(long, default_value_t = 36)]
    pub frames: u32,
    /// Horizontal field of view of the pan, degrees.
    #[arg(long, default_value_t = 90.0)]
    pub hfov: f64,
    /// Measure every map this many times, the maps taking turns (8k, 32k, 8k, 32k, …),
    /// each time in a fresh process, and report each frame time as the median over the
    /// passes (the load, table and pyramid times and the memory are the first pass's).
    /// On a machine whose speed drifts, one pass per map measures the maps at different
    /// moments; taking turns and the median make their ratios steadier.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=20))]
    pub passes: u32,
    /// Print one JSON array instead of the table.
    #[arg(long)]
    pub json: bool,
    /// The pixel limit for loading the maps.
    #[command(flatten)]
    pub limit: MaxPixelsArg,
    /// Internal: measure this one file in this process and print one JSON line.
    #[arg(long, hide = true)]
    pub child: Option<PathBuf>,
}

/// Parse a map width: 8192 or 8k.
fn parse_width(s: &str) -> Result<u32, String> {
    let t = s.trim();
    let (num, mult) = match t.strip_suffix(['k', 'K']) {
        Some(n) => (n, 1024),
        None => (t, 1),
    };
    let w = num
        .parse::<u32>()
        .ok()
        .and_then(|n| n.checked_mul(mult))
        .ok_or_else(|| format!("map width '{s}' must be a whole number, e.g. 8192 or 8k"))?;
    if w < 4 || w % 2 != 0 {
        return Err(format!("map width '{s}' must be even and at least 4"));
    }
    lut_core::check_map_size("map", w, w / 2).map_err(|e| e.to_string())?;
    Ok(w)
}

/// One size's measurements (one child process).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Sample {
    /// Map width.
    pub width: u32,
    /// Map height.
    pub height: u32,
    /// JPEG file size.
    pub file_bytes: u64,
    /// The map's padded 0RGB buffer.
    pub map_bytes: u64,
    /// Load: open to map ready (read + decode + convert).
    pub load_s: f64,
    /// Reading the file (the JPEG decoder reads it whole first).
    pub read_s: f64,
    /// Decoding.
    pub decode_s: f64,
    /// Converting into the map.
    pub convert_s: f64,
    /// Building both look-up tables.
    pub tables_s: f64,
    /// Bytes of both tables.
    pub table_bytes: u64,
    /// Median frame of the pan, bilinear as the window draws a still frame: on the
    /// deepest pyramid level on which no pixel is magnified by more than √2
    /// (`Renderer::set_still_level`; the map itself unless the view is zoomed
    /// out; the pyramid built before the pan).
    pub frame_ms_bilinear: f64,
    /// Median frame of the pan, bilinear on the map itself at every zoom (the library's
    /// default, what `frame_ms_bilinear` measured before still frames read a level).
    #[serde(default)]
    pub frame_ms_bilinear_map: f64,
    /// Median frame of the pan, nearest.
    pub frame_ms_nearest: f64,
    /// Median frame of the pan, trilinear as the window draws a still frame (its default
    /// sampler): from the same level as `frame_ms_bilinear` (`Renderer::set_still_level`;
    /// the pyramids built before the pan).
    pub frame_ms_trilinear: f64,
    /// Median frame of the pan, trilinear on the map itself at every zoom (the library's
    /// default, what `frame_ms_trilinear` measured before still frames read a level).
    #[serde(default)]
    pub frame_ms_trilinear_map: f64,
    /// Median frame of the pan, bilinear on the pyramid level matching the footprint
    /// (`Renderer::set_bilinear_level`, what the window uses while moving).
    #[serde(default)]
    pub frame_ms_bilinear_level: f64,
    /// The pan's horizontal field of view.
    #[serde(default)]
    pub hfov: f64,
    /// Time to build the pyramid (trilinear's levels) and the own pyramids of the levels
    /// still frames are drawn from (`lut_core::build_frame_levels`, what the window does
    /// while loading).
    pub pyramid_s: f64,
    /// Bytes of those pyramids.
    pub pyramid_bytes: u64,
    /// Peak resident memory after loading (VmHWM).
    pub peak_after_load_bytes: u64,
    /// Peak resident memory of the whole child (VmHWM at the end).
    pub peak_bytes: u64,
}

/// Run `viewer bench-load`.
pub fn run(a: BenchLoadArgs) -> Result<()> {
    if let Some(p) = &a.child {
        let s = measure(p, &a)?;
        crate::outln!("{}", serde_json::to_string(&s)?)?;
        return Ok(());
    }
    let cache = a
        .cache
        .clone()
        .unwrap_or_else(|| std::env::temp_dir().join("viewer-bench-load"));
    std::fs::create_dir_all(&cache)
        .with_context(|| format!("{}: cannot create the cache folder", cache.display()))?;
    let exe = std::env::current_exe().context("cannot find the viewer executable")?;
    let mut paths = Vec::new();
    for &w in &a.widths {
        let path = cache.join(format!("grid_{w}x{}_q{}.jpg", w / 2, a.quality));
        if !path.exists() {
            crate::errln!("generating {} ...", path.display());
            let t = Instant::now();
            generate_jpeg(&path, w, w / 2, a.quality)?;
            crate::errln!("  done in {:.1} s", t.elapsed().as_secs_f64());
        }
        paths.push((w, path));
    }
    let mut passes: Vec<Vec<Sample>> = vec![Vec::new(); paths.len()];
    for pass in 0..a.passes {
        for ((w, path), samples) in paths.iter().zip(&mut passes) {
            crate::errln!(
                "measuring {}x{} in a child process (pass {} of {}) ...",
                w,
                w / 2,
                pass + 1,
                a.passes
            );
            samples.push(measure_child(&exe, path, &a)?);
        }
    }
    let rows: Vec<Sample> = passes.iter().map(|s| combine(s)).collect();
    if a.json {
        crate::outln!("{}", serde_json::to_string_pretty(&rows)?)?;
    } else {
        print_table(&rows, &a)?;
    }
    Ok(())
}

/// The first pass's sample with each frame time replaced by its median over `passes`.
fn combine(passes: &[Sample]) -> Sample {
    let m = |f: fn(&Sample) -> f64| median(&passes.iter().map(f).collect::<Vec<_>>());
    Sample {
        frame_ms_bilinear: m(|s| s.frame_ms_bilinear),
        frame_ms_bilinear_map: m(|s| s.frame_ms_bilinear_map),
        frame_ms_nearest: m(|s| s.frame_ms_nearest),
        frame_ms_trilinear: m(|s| s.frame_ms_trilinear),
        frame_ms_trilinear_map: m(|s| s.frame_ms_trilinear_map),
        frame_ms_bilinear_level: m(|s| s.frame_ms_bilinear_level),
        ..passes[0].clone()
    }
}

/// Measure `path` in a child process (`viewer bench-load --child`).
fn measure_child(exe: &Path, path: &Path, a: &BenchLoadArgs) -> Result<Sample> {
    let out = std::process::Command::new(exe)
        .arg("bench-load")
        .arg("--child")
        .arg(path)
        .args(["--size", &format!("{}x{}", a.size.0, a.size.1)])
        .args(["--frames", &a.frames.to_string()])
        .args(["--hfov", &a.hfov.to_string()])
        .args(["--max-pixels", &a.limit.max_pixels.to_string()])
        .stderr(std::process::Stdio::inherit())
        .output()
        .context("cannot run the measuring child process")?;
    if !out.status.success() {
        bail!("measuring {} failed", path.display());
    }
    let line = String::from_utf8_lossy(&out.stdout);
    serde_json::from_str(line.trim())
        .map_err(|e| anyhow!("child output is not a measurement ({e}): {line}"))
}

fn gib(b: u64) -> f64 {
    b as f64 / f64::from(1u32 << 30)
}

fn print_table(rows: &[Sample], a: &BenchLoadArgs) -> Result<()> {
    // The children inherit LUTPANO_KERNEL, so they run the kernel named here.
    crate::outln!("{}", lut_core::kernel_info())?;
    crate::outln!(
        "{} threads; pan {}x{}, {} frames, LUT renderer (pitch 10°, hfov {}°); {} pass{}",
        rayon::current_num_threads(),
        a.size.0,
        a.size.1,
        a.frames,
        a.hfov,
        a.passes,
        if a.passes == 1 {
            ""
        } else {
            "es (frame times: medians)"
        }
    )?;
    crate::outln!(
        "| map | JPEG | load s (read + decode + convert) | tables s | frame ms bilinear | frame ms nearest | pyramid s | frame ms trilinear | frame ms bilinear on the level | frame ms bilinear on the map | frame ms trilinear on the map | map GiB | pyramid GiB | peak RSS after load GiB | peak RSS GiB |"
    )?;
    crate::outln!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")?;
    for s in rows {
        crate::outln!(
            "| {}x{} | {:.1} MB | {:.2} ({:.2} + {:.2} + {:.2}) | {:.3} | {:.1} | {:.1} | {:.2} | {:.1} | {:.1} | {:.1} | {:.1} | {:.2} | {:.2} | {:.2} | {:.2} |",
            s.width,
            s.height,
            s.file_bytes as f64 / 1e6,
            s.load_s,
            s.read_s,
            s.decode_s,
            s.convert_s,
            s.tables_s,
            s.frame_ms_bilinear,
            s.frame_ms_nearest,
            s.pyramid_s,
            s.frame_ms_trilinear,
            s.frame_ms_bilinear_level,
            s.frame_ms_bilinear_map,
            s.frame_ms_trilinear_map,
            gib(s.map_bytes),
            gib(s.pyramid_bytes),
            gib(s.peak_after_load_bytes),
            gib(s.peak_bytes),
        )?;
    }
    Ok(())
}

/// Write the benchmark scene (`lut_core::scene_color`, a latitude/longitude grid
/// on a colour field) as a `w × h` equirectangular JPEG, atomically. The RGB buffer is
/// filled row-parallel; the map type is not used, so only the RGB buffer and the encoder
/// are in memory.
fn generate_jpeg(path: &Path, w: u32, h: u32, quality: u8) -> Result<()> {
    let (wu, hu) = (w as usize, h as usize);
    let mut rgb = vec![0u8; wu * hu * 3];
    let (wf, hf) = (f64::from(w), f64::from(h));
    rgb.par_chunks_mut(wu * 3).enumerate().for_each(|(y, row)| {
        for (x, p) in row.chunks_exact_mut(3).enumerate() {
            let c = match Projection::Equirect.direction(x as f64 + 0.5, y as f64 + 0.5, wf, hf) {
                Some((l, ph)) => lut_core::scene_color(l, ph),
                None => 0,
            };
            p.copy_from_slice(&[(c >> 16) as u8, (c >> 8) as u8, c as u8]);
        }
    });
    write_image_atomic(path, |f| {
        image::codecs::jpeg::JpegEncoder::new_with_quality(f, quality)
            .encode(&rgb, w, h, image::ExtendedColorType::Rgb8)
            .map_err(|e| anyhow!("{}: cannot encode: {e}", path.display()))
    })
}

/// A field of `/proc/self/status` in bytes (Linux; `None` elsewhere).
pub(crate) fn proc_status_bytes(field: &str) -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with(field))?;
    let kb: u64 = line[field.len()..]
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kb * 1024)
}

/// The child's work: load one file, build the tables, pan, report.
fn measure(path: &Path, a: &BenchLoadArgs) -> Result<Sample> {
    let file_bytes = std::fs::metadata(path)
        .with_context(|| format!("{}: cannot read", path.display()))?
        .len();
    let opts = a.limit.options(None, Tone::default());
    let t0 = Instant::now();
    let mut marks: Vec<(LoadPhase, f64)> = Vec::new();
    let map = lut_core::load_map(path, &opts, &mut |p| {
        if marks.last().map(|m| m.0) != Some(p.phase) {
            marks.push((p.phase, t0.elapsed().as_secs_f64()));
        }
    })
    .map_err(crate::panorama::map_error)?;
    let load_s = t0.elapsed().as_secs_f64();
    let peak_after_load = proc_status_bytes("VmHWM:").unwrap_or(0);
    // Phase durations from the first report of each phase to the next one's.
    let span = |ph: LoadPhase| -> f64 {
        let Some(i) = marks.iter().position(|m| m.0 == ph) else {
            return 0.0;
        };
        let end = marks.get(i + 1).map_or(load_s, |m| m.1);
        end - marks[i].1
    };
    let (read_s, decode_s, convert_s) = (
        span(LoadPhase::Reading),
        span(LoadPhase::Decoding),
        span(LoadPhase::Converting),
    );

    let t1 = Instant::now();
    let mut renderer = Renderer::new(&map);
    let surface = RenderOptions::default().surface;
    // (`Renderer::new` gave the renderer the map's geometry: the tables are built.)
    let mut table_bytes = 0u64;
    for kind in [TableKind::Wide, TableKind::High] {
        table_bytes += renderer.table(surface, kind).map_or(0, |t| t.bytes()) as u64;
    }
    let tables_s = t1.elapsed().as_secs_f64();

    let (w, h) = a.size;
    let mut out = vec![0u32; w as usize * h as usize];
    // `still`: still frames on a level (`set_still_level`); `moving`: bilinear
    // on the level of the view's centre (`set_bilinear_level`).
    let mut pan = |sampler: Sampler, still: bool, moving: bool| -> Result<f64> {
        renderer.set_still_level(still);
        renderer.set_bilinear_level(moving);
        let o = RenderOptions {
            sampler,
            ..RenderOptions::default()
        };
        let n = a.frames.max(1);
        let mut ms = Vec::with_capacity(n as usize);
        for i in 0..=n {
            let view = View::new(f64::from(i) * 360.0 / f64::from(n), 10.0, a.hfov)?;
            let t = Instant::now();
            renderer.render(&map, view, &o, &mut Frame::new(&mut out, w, h)?)?;
            if i > 0 {
                // frame 0 warms the caches
                ms.push(t.elapsed().as_secs_f64() * 1e3);
            }
        }
        Ok(median(&ms))
    };
    let frame_ms_bilinear_map = pan(Sampler::Bilinear, false, false)?;
    let frame_ms_nearest = pan(Sampler::Nearest, false, false)?;
    let t = Instant::now();
    lut_core::build_frame_levels(&map);
    let pyramid_s = t.elapsed().as_secs_f64();
    let pyramid_bytes = map.pyramid_bytes()
        + map
            .pyramid()
            .iter()
            .map(lut_core::EnvMap::pyramid_bytes)
            .sum::<usize>();
    let frame_ms_trilinear_map = pan(Sampler::Trilinear, false, false)?;
    let frame_ms_trilinear = pan(Sampler::Trilinear, true, false)?;
    let frame_ms_bilinear = pan(Sampler::Bilinear, true, false)?;
    let frame_ms_bilinear_level = pan(Sampler::Bilinear, false, true)?;
    Ok(Sample {
        width: map.width(),
        height: map.height(),
        file_bytes,
        map_bytes: map.bytes() as u64,
        load_s,
        read_s,
        decode_s,
        convert_s,
        tables_s,
        table_bytes,
        frame_ms_bilinear,
        frame_ms_bilinear_map,
        frame_ms_nearest,
        frame_ms_trilinear,
        frame_ms_trilinear_map,
        frame_ms_bilinear_level,
        hfov: a.hfov,
        pyramid_s,
        pyramid_bytes: pyramid_bytes as u64,
        peak_after_load_bytes: peak_after_load,
        peak_bytes: proc_status_bytes("VmHWM:").unwrap_or(0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widths_parse() {
        assert_eq!(parse_width("8k"), Ok(8192));
        assert_eq!(parse_width("32K"), Ok(32768));
        assert_eq!(parse_width("1000"), Ok(1000));
        assert!(parse_width("7").is_err());
        assert!(parse_width("128k").is_err()); // above the map limits
        assert!(parse_width("x").is_err());
    }

    /// Passes combine into the first pass's sample with the median of each frame time.
    #[test]
    fn passes_combine_into_median_frame_times() {
        let sample = |k: f64| Sample {
            width: 8192,
            height: 4096,
            file_bytes: 1,
            map_bytes: 2,
            load_s: k,
            read_s: 0.0,
            decode_s: 0.0,
            convert_s: 0.0,
            tables_s: 0.0,
            table_bytes: 3,
            frame_ms_bilinear: k,
            frame_ms_bilinear_map: 2.0 * k,
            frame_ms_nearest: 3.0 * k,
            frame_ms_trilinear: 4.0 * k,
            frame_ms_trilinear_map: 5.0 * k,
            frame_ms_bilinear_level: 6.0 * k,
            hfov: 90.0,
            pyramid_s: 0.0,
            pyramid_bytes: 4,
            peak_after_load_bytes: 5,
            peak_bytes: 6,
        };
        let c = combine(&[sample(5.0), sample(1.0), sample(2.0)]);
        assert_eq!(c.load_s, 5.0, "the first pass's");
        let frames = [
            c.frame_ms_bilinear,
            c.frame_ms_bilinear_map,
            c.frame_ms_nearest,
            c.frame_ms_trilinear,
            c.frame_ms_trilinear_map,
            c.frame_ms_bilinear_level,
        ];
        assert_eq!(frames, [2.0, 4.0, 6.0, 8.0, 10.0, 12.0]);
    }
}
