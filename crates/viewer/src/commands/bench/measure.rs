//! `viewer bench`'s measuring: the thread pool, sampling-position error against the
//! exact mapping, PSNR against the exact images, and frame times.

use super::configs::{
    minify_opts, minify_size, minify_views, position_opts, Config, ViewSet, MINIFY_CONFIGS,
    MINIFY_HFOV, SAMPLERS,
};
use super::export::Export;
use super::progress;
use super::report::{Row, RunInfo};
use crate::scene::render_scene;
use anyhow::{bail, Context, Result};
use lut_core::exact_uv;
use lut_core::position_error;
use lut_core::{
    Camera, EnvMap, Frame, MapGeometry, Named, Panorama, Projection, Renderer, RendererKind,
    Sampler, View,
};
use rayon::prelude::*;
use std::time::Instant;

/// Run `f` on a rayon pool of `threads` workers (default: all cores), which every
/// renderer then runs on; `f` gets the pool's size.
///
/// # Errors
/// Zero threads, a pool that cannot start, or `f`'s error.
pub fn in_pool<R: Send>(
    threads: Option<usize>,
    f: impl FnOnce(usize) -> Result<R> + Send,
) -> Result<R> {
    let threads = threads.unwrap_or_else(rayon::current_num_threads);
    if threads == 0 {
        return Err(crate::usage!("--threads must be at least 1"));
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("cannot start the thread pool")?;
    pool.install(|| f(threads))
}

/// What one set's measurements read.
pub struct Ctx<'a> {
    /// The map.
    pub map: &'a EnvMap,
    /// The map converted to a cube (when the cube renderers are measured).
    pub cube: Option<&'a Panorama>,
    /// The map's pixels unpadded ([`gather_source`]).
    pub src: &'a [u32],
    /// The set.
    pub set: &'a ViewSet,
    /// Output width.
    pub w: u32,
    /// Output height.
    pub h: u32,
}

/// The map's pixels, unpadded, row-major: the source of the plain gather.
pub fn gather_source(map: &EnvMap) -> Vec<u32> {
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

/// Errors of one configuration, accumulated over a set's frames.
#[derive(Debug, Clone, Copy, Default)]
pub struct ErrAcc {
    /// Some(pixels compared) when positions are measured.
    pub pos_count: Option<u64>,
    /// Largest position error, source pixels.
    pub max: f64,
    /// Sum of the position errors.
    pub sum: f64,
    /// Sum of squared channel differences against the exact image.
    pub sse: u64,
    /// Channel samples compared.
    pub samples: u64,
    /// Pixels the LUT renderer evaluated exactly.
    pub exact_px: u64,
    /// Pixels rendered.
    pub px: u64,
}

impl ErrAcc {
    /// The report's error fields: max and mean position error, PSNR.
    pub fn fill(&self, row: &mut Row) {
        row.max_err_px = self.pos_count.map(|_| self.max);
        row.mean_err_px = self
            .pos_count
            .map(|n| if n > 0 { self.sum / n as f64 } else { 0.0 });
        row.psnr_db = psnr(self.sse, self.samples);
    }

    /// The fraction of pixels evaluated exactly.
    pub fn exact_fraction(&self) -> f64 {
        self.exact_px as f64 / self.px.max(1) as f64
    }
}

/// A set's errors: per configuration, and the gather's indices per view.
pub struct Errors {
    /// In the order of the configurations measured.
    pub per_config: Vec<ErrAcc>,
    /// Per view: the map index of each output pixel's exact nearest sample (u32::MAX =
    /// background).
    pub gather_idx: Vec<Vec<u32>>,
}

/// Render `view` with `cfg` into `out`: the exact renderer, the scene (map or cube) or
/// the gather along `idx`. The LUT renderer's report for LUT configurations.
fn render_config(
    ctx: &Ctx,
    renderer: &mut Renderer,
    cfg: Config,
    view: View,
    idx: &[u32],
    out: &mut [u32],
) -> Result<()> {
    let (w, h) = (ctx.w, ctx.h);
    match cfg {
        Config::Exact(s) => {
            lut_core::render_exact(ctx.map, view, s, &mut Frame::new(out, w, h)?, true);
        }
        Config::Gather => gather(ctx.src, idx, out, w as usize, ctx.map.background()),
        Config::Lut(..) | Config::LutSurface(..) | Config::Grid(_) => {
            let Some(opts) = position_opts(cfg, ctx.set.table) else {
                bail!("internal: no options for {cfg:?}");
            };
            renderer.render(ctx.map, view, &opts, &mut Frame::new(out, w, h)?)?;
        }
        Config::Cube(s, r) => {
            let Some(cube) = ctx.cube else {
                bail!("internal: a cube configuration without a cube");
            };
            let opts = lut_core::RenderOptions {
                sampler: s,
                cube: r,
                threads: true,
                ..lut_core::RenderOptions::default()
            };
            // A handle on the same faces (an `Arc`): nothing is copied.
            render_scene(&mut cube.share(), view, &opts, out, w, h)?;
        }
    }
    Ok(())
}

/// Per view: the exact positions and images once, then every configuration's positions
/// (LUT) and image compared with them. With `export`, the set's exact data is written
/// for `scripts/peers.py`, its views numbered from `export.len()`.
pub fn measure_errors(
    ctx: &Ctx,
    renderer: &mut Renderer,
    cfgs: &[Config],
    mut export: Option<&mut Export>,
) -> Result<Errors> {
    let (w, h) = (ctx.w, ctx.h);
    let n = w as usize * h as usize;
    let map = ctx.map;
    let (mw, mh, proj) = (map.width(), map.height(), map.projection());
    let geometry = MapGeometry::of(map);
    let mut acc = vec![ErrAcc::default(); cfgs.len()];
    let mut gather_idx = Vec::with_capacity(ctx.set.views.len());
    let first = export.as_ref().map_or(0, |ex| ex.len());
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
                    let phi = cam.pixel_lat_long(x as u32, y as u32).map_or(0.0, |d| d.1);
                    *e = (uv, phi);
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
        if let Some(ex) = export.as_deref_mut() {
            ex.view(first + vi, view, &exact, &exact_img)?;
        }
        for (ci, cfg) in cfgs.iter().enumerate() {
            let e = &mut acc[ci];
            // Positions do not depend on the sampler: measured once (nearest), shared
            // with the bilinear rows below.
            if let (Sampler::Nearest, Some(opts)) =
                (cfg.sampler(), position_opts(*cfg, ctx.set.table))
            {
                let (pos, rep) = renderer.positions(geometry, view, &opts, w, h)?;
                let (max, sum, cnt) = compare(&pos, &exact, proj, mw, mh);
                e.max = e.max.max(max);
                e.sum += sum;
                e.pos_count = Some(e.pos_count.unwrap_or(0) + cnt);
                e.exact_px += rep.exact_pixels;
                e.px += rep.pixels;
            }
            e.samples += 3 * n as u64;
            if let Config::Exact(_) = cfg {
                // Identical to the reference by definition.
                e.pos_count = Some(e.pos_count.unwrap_or(0) + n as u64);
                continue;
            }
            render_config(ctx, renderer, *cfg, view, &idx, &mut img)?;
            let reference = &exact_img[if cfg.sampler() == Sampler::Nearest {
                0
            } else {
                1
            }];
            e.sse += sse(&img, reference);
        }
        // Share the sampler-independent position stats with the bilinear rows.
        for ci in 0..cfgs.len() {
            let twin = cfgs[ci].nearest_twin();
            if cfgs[ci].sampler() == Sampler::Bilinear && twin != cfgs[ci] {
                if let Some(nj) = cfgs.iter().position(|c| *c == twin) {
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
        progress(&format!(
            "hfov {} view {}/{} (yaw {:.1}, pitch {:.1}) measured",
            ctx.set.hfov,
            vi + 1,
            ctx.set.views.len(),
            view.yaw_deg(),
            view.pitch_deg()
        ));
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

/// Rows of `w` pixels read from `src` at `idx` (out of range: `background`).
fn gather(src: &[u32], idx: &[u32], out: &mut [u32], w: usize, background: u32) {
    out.par_chunks_mut(w)
        .zip(idx.par_chunks(w))
        .with_min_len((16384 / w.max(1)).max(1))
        // Tasks of one size, as the renderer's (`lut_core` `rows_per_task`): rayon's
        // default pieces left one thread finishing a quarter frame alone.
        .with_max_len((16384 / w.max(1)).max(1))
        .for_each(|(o, i)| {
            for (p, &k) in o.iter_mut().zip(i) {
                *p = src.get(k as usize).copied().unwrap_or(background);
            }
        });
}

/// Sum of squared differences over R, G and B.
pub fn sse(a: &[u32], b: &[u32]) -> u64 {
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

/// PSNR in dB of a summed squared error over `samples` 8-bit channel samples; `None` for
/// identical images (or nothing compared).
pub fn psnr(sse: u64, samples: u64) -> Option<f64> {
    if sse == 0 || samples == 0 {
        return None;
    }
    let mse = sse as f64 / samples as f64;
    Some(10.0 * (255.0f64 * 255.0 / mse).log10())
}

/// Milliseconds per frame of `cfg` over the set: one warm-up pass, then `passes` timed
/// passes (exact renders: one timed pass, no warm-up: they are slow and vary little).
pub fn time_config(
    ctx: &Ctx,
    renderer: &mut Renderer,
    cfg: Config,
    gather_idx: &[Vec<u32>],
    passes: u32,
) -> Result<Vec<f64>> {
    let mut out = vec![0u32; ctx.w as usize * ctx.h as usize];
    let mut times = Vec::new();
    let exact = matches!(cfg, Config::Exact(_));
    let warm = u32::from(!exact);
    let passes = if exact { 1 } else { passes };
    for pass in 0..passes + warm {
        for (vi, &view) in ctx.set.views.iter().enumerate() {
            let t = Instant::now();
            render_config(ctx, renderer, cfg, view, &gather_idx[vi], &mut out)?;
            std::hint::black_box(&out);
            if pass >= warm {
                times.push(t.elapsed().as_secs_f64() * 1e3);
            }
        }
    }
    Ok(times)
}

/// Milliseconds of the grid's per-view build alone (`Renderer::build_grid`, no drawing)
/// for each frame of the set: one warm-up pass, then `passes` timed passes.
pub fn time_grid_build(ctx: &Ctx, renderer: &mut Renderer, passes: u32) -> Result<Vec<f64>> {
    let geometry = MapGeometry::of(ctx.map);
    let mut times = Vec::new();
    for pass in 0..=passes {
        for &view in &ctx.set.views {
            let t = Instant::now();
            let rep = renderer.build_grid(geometry, view, ctx.w, ctx.h, true)?;
            std::hint::black_box(rep);
            if pass > 0 {
                times.push(t.elapsed().as_secs_f64() * 1e3);
            }
        }
    }
    Ok(times)
}

/// The median (0 for no values).
pub fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    match s.len() {
        0 => 0.0,
        n if n % 2 == 1 => s[n / 2],
        n => 0.5 * (s[n / 2 - 1] + s[n / 2]),
    }
}

/// The minification set (see [`super::configs::minify_views`]): every configuration of
/// [`MINIFY_CONFIGS`] timed and compared by PSNR with the exact render supersampled 8×8
/// per pixel (box filter, bilinear sub-samples). The rows, and the note that sums them up.
pub fn minify_set(
    run: &RunInfo,
    size: (u32, u32),
    passes: u32,
    map: &EnvMap,
    renderer: &mut Renderer,
) -> Result<(Vec<Row>, String)> {
    let (w, h) = minify_size(size);
    let views = minify_views()?;
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
        progress(&format!("minify: 8x8 truth {}/{}", i + 1, views.len()));
    }
    let run = RunInfo {
        width: w,
        height: h,
        ..run.clone()
    };
    let mut rows = Vec::new();
    let mut out = vec![0u32; n];
    for (kind, sampler) in MINIFY_CONFIGS {
        let opts = minify_opts(kind, sampler);
        let (mut err, mut times) = (0u64, Vec::new());
        for (v, truth) in views.iter().zip(&truths) {
            renderer.render(map, *v, &opts, &mut Frame::new(&mut out, w, h)?)?;
            err += sse(&out, truth);
        }
        for _ in 0..passes {
            for v in &views {
                let t = Instant::now();
                renderer.render(map, *v, &opts, &mut Frame::new(&mut out, w, h)?)?;
                times.push(t.elapsed().as_secs_f64() * 1e3);
            }
        }
        let is_lut = kind == RendererKind::Lut;
        let mut row = Row::timed(&run, kind.name(), sampler, MINIFY_HFOV, views.len(), &times);
        if is_lut {
            row.index_step = super::configs::step_json(opts.index_step);
            row.lut = Some(opts.lut.name().into());
        }
        row.psnr_ss_db = psnr(err, (n * views.len() * 3) as u64);
        progress(&super::report::row_line(&row));
        rows.push(row);
    }
    let note = super::report::minify_note(
        (w, h),
        views.len(),
        pyr_ms,
        map.pyramid_bytes(),
        map.bytes(),
        &rows,
    );
    Ok((rows, note))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn psnr_of_known_errors() {
        assert_eq!(psnr(0, 300), None);
        assert_eq!(psnr(5, 0), None);
        // MSE 1 → 20·log10(255) = 48.13 dB; MSE 255² → 0 dB.
        assert!((psnr(300, 300).unwrap() - 48.1308).abs() < 1e-4);
        assert!(psnr(255 * 255 * 3, 3).unwrap().abs() < 1e-12);
        assert_eq!(sse(&[0x000A_0B0C], &[0x000A_0B0C]), 0);
        assert_eq!(
            sse(&[0x00FF_0000, 0x0000_0003], &[0, 0x0000_0001]),
            255 * 255 + 4
        );
        // The top byte is not a channel.
        assert_eq!(sse(&[0xFF00_0000], &[0]), 0);
    }

    #[test]
    fn medians() {
        assert_eq!(median(&[]), 0.0);
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
    }

    #[test]
    fn gather_reads_indices_and_background() {
        let src = [10, 11, 12, 13];
        let mut out = [0u32; 4];
        gather(&src, &[3, 0, u32::MAX, 4], &mut out, 2, 99);
        assert_eq!(out, [13, 10, 99, 99]);
    }

    #[test]
    fn pool_of_the_size_asked() {
        assert_eq!(
            in_pool(Some(3), |n| Ok((n, rayon::current_num_threads()))).unwrap(),
            (3, 3)
        );
        assert!(in_pool(Some(0), |_| Ok(())).is_err());
    }

    /// On a small generated map: the exact renderer measures no error, the gather is the
    /// exact nearest image, the LUT positions are within the 0.05 px budget, every
    /// configuration renders, and the bilinear LUT rows share the nearest rows' positions.
    #[test]
    fn errors_of_a_small_set() {
        let map = lut_core::grid_map(256, 128, Projection::Equirect).unwrap();
        let cube =
            Panorama::cube(lut_core::CubeMap::from_envmap(&map, 32, Sampler::Bilinear).unwrap());
        let src = gather_source(&map);
        let set = ViewSet {
            table: lut_core::TableKind::Wide,
            hfov: 90.0,
            views: vec![
                View::new(20.0, 10.0, 90.0).unwrap(),
                View::new(180.0, 80.0, 90.0).unwrap(),
            ],
            given: None,
        };
        let ctx = Ctx {
            map: &map,
            cube: Some(&cube),
            src: &src,
            set: &set,
            w: 48,
            h: 32,
        };
        let cfgs = super::super::configs::configs(true);
        let mut renderer = Renderer::new(&map);
        let errs = measure_errors(&ctx, &mut renderer, &cfgs, None).unwrap();
        assert_eq!(errs.gather_idx.len(), 2);
        for (cfg, e) in cfgs.iter().zip(&errs.per_config) {
            assert_eq!(e.samples, 2 * 3 * 48 * 32, "{cfg:?}");
            match cfg {
                Config::Exact(_) => assert_eq!((e.sse, e.max), (0, 0.0)),
                Config::Gather => assert_eq!(e.sse, 0, "the gather is the exact nearest image"),
                Config::Lut(..) | Config::LutSurface(..) | Config::Grid(_) => {
                    assert!(
                        e.pos_count.unwrap() > 0 && e.max < 0.05,
                        "{cfg:?} {}",
                        e.max
                    );
                    let twin = cfgs.iter().position(|c| *c == cfg.nearest_twin()).unwrap();
                    assert_eq!(e.max, errs.per_config[twin].max, "{cfg:?}");
                    assert!(e.px > 0 && e.sse < e.samples * 16, "{cfg:?}");
                }
                Config::Cube(..) => assert!(e.pos_count.is_none()),
            }
            // One timed pass over the two views (after a warm-up, except exact).
            let times = time_config(&ctx, &mut renderer, *cfg, &errs.gather_idx, 1).unwrap();
            assert_eq!(times.len(), 2, "{cfg:?}");
        }
    }
}
