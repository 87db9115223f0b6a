//! `viewer report --png`: the work plane's plan in false colours with isolux lines and
//! the luminaires' positions, and the lit view of the panorama beside it.
//!
//! The plan covers the whole room at the work plane's height, seen from above (X to the
//! right, Z up the image: the room's front wall at the top); the calculation area (inside
//! the border band) is outlined with a dashed line and its grid points are dots. Each
//! pixel's direct illuminance is exact (the per-pixel arithmetic); the indirect, which
//! varies slowly, is read exactly on a 0.25 m grid and interpolated between. The colours
//! are the window's false colours ([`lut_core::false_color`], three decades below the
//! scale's top, a round number above the plan's maximum); isolux lines are drawn at a
//! round step (1, 2, 2.5 or 5 × 10ⁿ lx, about eight lines over the plan's range).

use super::{lux, Report, ReportArgs};
use anyhow::{anyhow, Context, Result};
use clap::Parser;
use glam::DVec3;
use lut_core::{false_color, false_color_position, LightScene};
use rayon::prelude::*;

/// Pixels per metre of the plan at most, and its largest side in pixels.
const PLAN_MAX: f64 = 460.0;
/// The lit view's size.
const VIEW: (u32, u32) = (560, 420);
/// Margins and the title band, pixels.
const MARGIN: u32 = 16;
const TITLE: u32 = 44;
const LEGEND: u32 = 120;

/// A 0RGB image.
pub struct Image {
    /// Width in pixels.
    pub w: u32,
    /// Height in pixels.
    pub h: u32,
    /// Pixels, row-major.
    pub px: Vec<u32>,
}

/// A round step for about `n` isolux lines over `range` lux.
fn isolux_step(range: f64, n: f64) -> f64 {
    let raw = (range / n).max(1e-9);
    let k = 10f64.powf(raw.log10().floor());
    for m in [1.0, 2.0, 2.5, 5.0, 10.0] {
        if m * k >= raw {
            return m * k;
        }
    }
    10.0 * k
}

/// A round scale top at or above `max` lux (1, 2 or 5 × 10ⁿ).
fn scale_top(max: f64) -> f64 {
    let max = max.max(1.0);
    let k = 10f64.powf(max.log10().floor());
    for m in [1.0, 2.0, 5.0, 10.0] {
        if m * k >= max {
            return m * k;
        }
    }
    10.0 * k
}

/// The plan: illuminance over the room at the work plane's height, `pw × ph` pixels.
fn plan_values(r: &Report, scene: &LightScene, pw: u32, ph: u32) -> Vec<f64> {
    let room = scene.room();
    let (lo, hi) = room.bounds();
    let h = r.height;
    // The indirect part on a coarse grid of nodes (corners included).
    let nx = ((hi.x - lo.x) / 0.25).ceil().max(1.0) as usize + 1;
    let nz = ((hi.z - lo.z) / 0.25).ceil().max(1.0) as usize + 1;
    let nodes: Vec<f64> = (0..nx * nz)
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k % nx, k / nx);
            let p = DVec3::new(
                lo.x + (hi.x - lo.x) * i as f64 / (nx - 1) as f64,
                h,
                lo.z + (hi.z - lo.z) * j as f64 / (nz - 1) as f64,
            );
            scene.indirect(p, DVec3::Y)
        })
        .collect();
    (0..(pw * ph) as usize)
        .into_par_iter()
        .map(|k| {
            let (px, py) = ((k % pw as usize) as f64, (k / pw as usize) as f64);
            let x = lo.x + (px + 0.5) / pw as f64 * (hi.x - lo.x);
            // Row 0 is the front (high Z).
            let z = hi.z - (py + 0.5) / ph as f64 * (hi.z - lo.z);
            let fx = (x - lo.x) / (hi.x - lo.x) * (nx - 1) as f64;
            let fz = (z - lo.z) / (hi.z - lo.z) * (nz - 1) as f64;
            let (i, j) = ((fx as usize).min(nx - 2), (fz as usize).min(nz - 2));
            let (i1, j1) = ((i + 1).min(nx - 1), (j + 1).min(nz - 1));
            let (tx, tz) = (fx - i as f64, fz - j as f64);
            let at = |i: usize, j: usize| nodes[j * nx + i];
            let a = at(i, j) + (at(i1, j) - at(i, j)) * tx;
            let b = at(i, j1) + (at(i1, j1) - at(i, j1)) * tx;
            scene.direct(DVec3::new(x, h, z), DVec3::Y) + a + (b - a) * tz
        })
        .collect()
}

/// Draw the report's image: the plan (with its legend) and the lit view.
///
/// # Errors
/// The panorama cannot be loaded or rendered, or text cannot be drawn.
pub fn render(a: &ReportArgs, r: &Report, scene: &LightScene) -> Result<Image> {
    let view = lit_view(a, r)?;
    render_with(r, scene, &view)
}

/// The lit view's size in pixels.
pub const VIEW_SIZE: (u32, u32) = VIEW;

/// [`render`] with the lit view given ([`VIEW_SIZE`] pixels, 0RGB): the window renders
/// it from the panorama it shows.
///
/// # Errors
/// Text cannot be drawn, or `view` is not [`VIEW_SIZE`].
pub fn render_with(r: &Report, scene: &LightScene, view: &[u32]) -> Result<Image> {
    anyhow::ensure!(
        view.len() == (VIEW.0 * VIEW.1) as usize,
        "the lit view has {} pixels, not {}x{}",
        view.len(),
        VIEW.0,
        VIEW.1
    );
    let (w_m, d_m) = (r.room[0], r.room[1]);
    let scale = (PLAN_MAX / w_m.max(d_m)).min(200.0);
    let pw = ((w_m * scale).round() as u32).max(40);
    let ph = ((d_m * scale).round() as u32).max(40);
    let values = plan_values(r, scene, pw, ph);
    let emax = values.iter().copied().fold(0.0, f64::max);
    let emin = values.iter().copied().fold(f64::INFINITY, f64::min);
    let top = scale_top(emax);
    let step = isolux_step(emax - emin.min(emax), 8.0);
    let mut plan: Vec<u32> = values
        .iter()
        .map(|&e| false_color(false_color_position(e, top)))
        .collect();
    // Isolux lines: where the level changes between neighbours.
    let level = |e: f64| (e / step).floor() as i64;
    for y in 0..ph as usize {
        for x in 0..pw as usize {
            let k = y * pw as usize + x;
            let l = level(values[k]);
            let right = x + 1 < pw as usize && level(values[k + 1]) != l;
            let down = y + 1 < ph as usize && level(values[k + pw as usize]) != l;
            if right || down {
                plan[k] = 0x202020;
            }
        }
    }
    let room = scene.room();
    let (lo, hi) = room.bounds();
    let to_px = |x: f64, z: f64| -> (f64, f64) {
        (
            (x - lo.x) / (hi.x - lo.x) * pw as f64,
            (hi.z - z) / (hi.z - lo.z) * ph as f64,
        )
    };
    // The calculation area, dashed, and its points.
    let wp = &r.areas[0].grid;
    let (x0, y0) = to_px(wp.u[0], wp.v[1]);
    let (x1, y1) = to_px(wp.u[1], wp.v[0]);
    let mut put = |x: i64, y: i64, c: u32| {
        if x >= 0 && y >= 0 && (x as u32) < pw && (y as u32) < ph {
            plan[y as usize * pw as usize + x as usize] = c;
        }
    };
    for t in 0..((x1 - x0) as i64) {
        if (t / 5) % 2 == 0 {
            put(x0 as i64 + t, y0 as i64, 0xffffff);
            put(x0 as i64 + t, y1 as i64, 0xffffff);
        }
    }
    for t in 0..((y1 - y0) as i64) {
        if (t / 5) % 2 == 0 {
            put(x0 as i64, y0 as i64 + t, 0xffffff);
            put(x1 as i64, y0 as i64 + t, 0xffffff);
        }
    }
    for p in &wp.points {
        let (x, y) = to_px(p.x, p.z);
        put(x as i64, y as i64, 0x000000);
    }
    // The luminaires: white discs ringed in black.
    let mut markers = Vec::new();
    for l in &r.luminaires {
        let (cx, cy) = to_px(l.position[0], l.position[2]);
        for dy in -7i64..=7 {
            for dx in -7i64..=7 {
                let d2 = dx * dx + dy * dy;
                if d2 <= 49 {
                    put(
                        cx as i64 + dx,
                        cy as i64 + dy,
                        if d2 <= 25 { 0xffffff } else { 0x000000 },
                    );
                }
            }
        }
        markers.push((cx as i32, cy as i32));
    }
    // The plan panel with the legend at its right.
    let (lw, lh) = (pw + LEGEND, ph.max(300));
    let mut panel = vec![0x303030u32; (lw * lh) as usize];
    for y in 0..ph {
        let row = (y * pw) as usize;
        panel[(y * lw) as usize..(y * lw + pw) as usize]
            .copy_from_slice(&plan[row..row + pw as usize]);
    }
    crate::lighting::legend::draw_legend(&mut panel, lw, lh, top).map_err(|e| anyhow!(e))?;
    // The lit view.
    let w = MARGIN * 3 + lw + VIEW.0;
    let h = TITLE + MARGIN + lh.max(VIEW.1) + MARGIN + 24;
    let mut px = vec![0xffffffu32; (w * h) as usize];
    let blit = |px: &mut [u32], src: &[u32], sw: u32, sh: u32, ox: u32, oy: u32| {
        for y in 0..sh {
            let d = ((oy + y) * w + ox) as usize;
            px[d..d + sw as usize]
                .copy_from_slice(&src[(y * sw) as usize..((y + 1) * sw) as usize]);
        }
    };
    blit(&mut px, &panel, lw, lh, MARGIN, TITLE + MARGIN);
    blit(
        &mut px,
        view,
        VIEW.0,
        VIEW.1,
        MARGIN * 2 + lw,
        TITLE + MARGIN,
    );
    let wpl = &r.areas[0];
    let title = format!(
        "Work plane {:.2} m: Em {} lx, Emin {} lx, U0 {:.2} ({} {} lx, U0 {:.2}: {})",
        r.height,
        lux(wpl.stats.em),
        lux(wpl.stats.emin),
        wpl.stats.u0,
        r.task.name,
        r.task.em,
        r.task.u0,
        if wpl.pass == Some(true) {
            "pass"
        } else {
            "FAIL"
        }
    );
    let caption = format!(
        "Plan from above (front wall at the top), isolux lines every {} lx, {} luminaires; lit view yaw {:.0} pitch {:.0}",
        lux(step),
        r.luminaires.len(),
        r.view[0],
        r.view[1]
    );
    let labels: Vec<(String, i32, i32)> = markers
        .iter()
        .enumerate()
        .map(|(i, &(x, y))| {
            (
                (i + 1).to_string(),
                x + MARGIN as i32 + 9,
                y + (TITLE + MARGIN) as i32 - 16,
            )
        })
        .collect();
    draw_text(&mut px, w, h, &title, &caption, &labels, h as i32 - 22)?;
    Ok(Image { w, h, px })
}

/// The title at the top, the caption at `caption_y` and small labels, in black.
fn draw_text(
    px: &mut [u32],
    w: u32,
    h: u32,
    title: &str,
    caption: &str,
    labels: &[(String, i32, i32)],
    caption_y: i32,
) -> Result<()> {
    use plotters::prelude::*;
    plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        epaint_default_fonts::UBUNTU_LIGHT,
    )
    .map_err(|_| anyhow!("cannot load the report's font"))?;
    let mut buf: Vec<u8> = px
        .iter()
        .flat_map(|p| [(p >> 16) as u8, (p >> 8) as u8, *p as u8])
        .collect();
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        let err = |e: DrawingAreaErrorKind<_>| anyhow!("cannot draw the report's text: {e}");
        let big = ("sans-serif", 20.0).into_font().color(&BLACK);
        let small = ("sans-serif", 14.0).into_font().color(&BLACK);
        root.draw(&Text::new(title.to_string(), (MARGIN as i32, 12), big))
            .map_err(err)?;
        root.draw(&Text::new(
            caption.to_string(),
            (MARGIN as i32, caption_y),
            small.clone(),
        ))
        .map_err(err)?;
        for (t, x, y) in labels {
            root.draw(&Text::new(t.clone(), (*x, *y), small.clone()))
                .map_err(err)?;
        }
        root.present().map_err(err)?;
    }
    for (p, c) in px.iter_mut().zip(buf.chunks_exact(3)) {
        *p = (c[0] as u32) << 16 | (c[1] as u32) << 8 | c[2] as u32;
    }
    Ok(())
}

/// The lit view: `viewer render`'s frame of the panorama with these luminaires, exposed
/// so that the work plane's Em looks like the photograph.
fn lit_view(a: &ReportArgs, r: &Report) -> Result<Vec<u32>> {
    #[derive(Parser)]
    struct Wrap {
        #[command(flatten)]
        r: crate::commands::render::RenderArgs,
    }
    let mut argv: Vec<String> = vec!["render".into()];
    argv.extend(a.panorama.iter().map(|p| p.display().to_string()));
    argv.extend([
        "-o".to_string(),
        "report-view.png".into(),
        "--size".into(),
        format!("{}x{}", VIEW.0, VIEW.1),
        format!("--yaw={}", r.view[0]),
        format!("--pitch={}", r.view[1]),
        format!("--hfov={}", r.view[2]),
    ]);
    let mut ra = Wrap::try_parse_from(&argv)
        .map_err(|e| {
            crate::usage!(
                "the lit view: {}",
                e.to_string().lines().next().unwrap_or("")
            )
        })?
        .r;
    ra.lights.room = a.room.clone();
    ra.lights.exposure_lux = Some(r.areas[0].stats.em.max(1.0));
    crate::commands::render::frame(&ra).context("the lit view")
}

/// The image as PNG bytes.
///
/// # Errors
/// An encoding failure.
pub fn encode(img: &Image) -> Result<Vec<u8>> {
    let rgb = crate::output::rgb24(&img.px);
    let mut out = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut out),
        &rgb,
        img.w,
        img.h,
        image::ExtendedColorType::Rgb8,
    )
    .map_err(|e| anyhow!("cannot encode the report's image: {e}"))?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_steps() {
        assert_eq!(isolux_step(800.0, 8.0), 100.0);
        assert_eq!(isolux_step(170.0, 8.0), 25.0);
        assert_eq!(scale_top(640.0), 1000.0);
        assert_eq!(scale_top(180.0), 200.0);
    }
}
