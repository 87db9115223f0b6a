//! `viewer render`: one view of a panorama to a PNG, headless.

use crate::cli_common::{parse_angle, parse_size, write_png_atomic};
use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use lut_core::Surface;
use lut_core::{Frame, Scene};
use lut_core::{
    IndexStep, LutChoice, Projection, RenderOptions, Renderer, RendererKind, Sampler, View,
};
use std::path::PathBuf;

/// Which renderer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RendererArg {
    /// The scanline-coherent LUT renderer.
    Lut,
    /// The exact per-pixel renderer.
    Exact,
}

/// Pixel interpolation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SamplerArg {
    /// Nearest source pixel.
    Nearest,
    /// Bilinear.
    Bilinear,
    /// Trilinear: bilinear on the two pyramid levels around the pixel footprint
    /// (anti-aliased when zoomed out; the pyramid takes up to 1/3 more memory).
    Trilinear,
}

/// Table choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum LutArg {
    /// Wide above 60 degrees hfov, high-resolution at or below.
    Auto,
    /// The wide-FOV table.
    Wide,
    /// The high-resolution table.
    High,
}

/// Table surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SurfaceArg {
    /// Cylinder (FIGS. 5-7).
    Cylinder,
    /// Plane (FIG. 8A).
    Plane,
}

/// The `--projection` choice: auto, one of the map projections, or a cube map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProjectionArg {
    /// 2:1 images are equirectangular; a folder or several files are a cube map.
    Auto,
    /// A map on a surface of revolution.
    Map(Projection),
    /// A cube map (six faces or one layout image).
    Cube,
}

/// Parse `--projection`.
pub fn parse_projection_arg(s: &str) -> Result<ProjectionArg, String> {
    match s {
        "auto" => Ok(ProjectionArg::Auto),
        "cube" => Ok(ProjectionArg::Cube),
        other => other
            .parse()
            .map(ProjectionArg::Map)
            .map_err(|e: String| format!("{e}, or cube")),
    }
}

/// Cube renderer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CubeRendererArg {
    /// Per pixel: face by the largest coordinate.
    Basic,
    /// Per scanline: face segments split by binary search.
    Scanline,
}

/// How to read a panorama: the options `viewer render` and the window share.
#[derive(Args, Debug, Clone)]
pub struct InputArgs {
    /// Map projection: auto (2:1 is equirect; a folder or several files are a cube),
    /// equirect, cylinder, sine, elliptical, diamond, cube.
    #[arg(long, value_name = "NAME", default_value = "auto", value_parser = parse_projection_arg)]
    pub projection: ProjectionArg,
    /// Cube input layout: files, cross, strip, 3x2 (detected when omitted).
    #[arg(long)]
    pub layout: Option<String>,
    /// Cube face naming/orientation: conventions, cube2, irrlicht (see docs/cube.md).
    #[arg(long)]
    pub naming: Option<String>,
    /// Cube renderer (per pixel, or per scanline with face segments).
    #[arg(long, value_enum, default_value_t = CubeRendererArg::Scanline)]
    pub cube_renderer: CubeRendererArg,
    /// The area the image covers, for partial panoramas: HFOVxVFOV[±YAW±PITCH] in
    /// degrees (e.g. 120x60+30-10: 120 x 60 centred on yaw 30, pitch -10). Overrides
    /// GPano XMP metadata in the file. Equirectangular images only (in the window: the
    /// panorama named on the command line only).
    #[arg(long, value_name = "HFOVxVFOV[±YAW±PITCH]", value_parser = crate::partial::parse_coverage, allow_hyphen_values = true)]
    pub coverage: Option<lut_core::Coverage>,
}

/// Arguments of `viewer render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Panorama image (JPEG, PNG, ...), or a cube map: a folder, six face files, or one
    /// layout image with --projection cube. The bundled sample when omitted.
    pub panorama: Vec<PathBuf>,
    /// Output PNG, written atomically.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Yaw in degrees (any value, taken modulo 360; positive turns right).
    #[arg(long, default_value = "0", value_parser = parse_angle, allow_hyphen_values = true)]
    pub yaw: f64,
    /// Pitch in degrees (positive looks up; clamped to [-90, 90]).
    #[arg(long, default_value = "0", value_parser = parse_angle, allow_hyphen_values = true)]
    pub pitch: f64,
    /// Horizontal field of view in degrees, in (0, 180).
    #[arg(long, default_value = "90", value_parser = parse_angle, allow_hyphen_values = true)]
    pub hfov: f64,
    /// Output size WIDTHxHEIGHT (each side 1..=16384).
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// How to read the panorama (shared with the window).
    #[command(flatten)]
    pub input: InputArgs,
    /// Renderer.
    #[arg(long, value_enum, default_value_t = RendererArg::Lut)]
    pub renderer: RendererArg,
    /// Pixel interpolation.
    #[arg(long, value_enum, default_value_t = SamplerArg::Bilinear)]
    pub sampler: SamplerArg,
    /// Index interpolation step: 1, 2, 4, 8, 16, or "adaptive".
    #[arg(long, default_value = "adaptive", value_parser = parse_step)]
    pub index_step: IndexStep,
    /// Which look-up table.
    #[arg(long, value_enum, default_value_t = LutArg::Auto)]
    pub lut: LutArg,
    /// Surface the look-up table is built on.
    #[arg(long, value_enum, default_value_t = SurfaceArg::Cylinder)]
    pub lut_surface: SurfaceArg,
    /// Exposure in stops for HDR maps (.hdr, .exr): values times 2^EV, then the tone
    /// curve x/(1+x) and sRGB. 8-bit images are shown as stored.
    #[arg(long, default_value = "0", value_parser = parse_stops, allow_hyphen_values = true)]
    pub exposure: f64,
    /// Keep the view inside the covered area of a partial panorama: reduce hfov if the
    /// view is larger than the coverage, then clamp pitch and yaw.
    #[arg(long)]
    pub view_limit: bool,
    /// Render on one thread.
    #[arg(long)]
    pub single_thread: bool,
    /// The pixel limit.
    #[command(flatten)]
    pub limit: crate::max_pixels::MaxPixelsArg,
    /// Print which path rendered and the table size.
    #[arg(long, short)]
    pub verbose: bool,
    /// Luminaires lighting the scene.
    #[command(flatten)]
    pub lights: crate::ies_cmd::LightArgs,
}

/// Parse an exposure in stops (a finite number).
pub fn parse_stops(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("exposure '{s}' is not a finite number of stops")),
    }
}

/// Parse an index step.
pub fn parse_step(s: &str) -> Result<IndexStep, String> {
    if s == "adaptive" {
        return Ok(IndexStep::Adaptive);
    }
    match s.parse::<u32>() {
        Ok(n @ (1 | 2 | 4 | 8 | 16)) => Ok(IndexStep::Fixed(n)),
        _ => Err(format!(
            "index step '{s}' must be 1, 2, 4, 8, 16 or adaptive"
        )),
    }
}

impl RenderArgs {
    /// The render options these arguments select.
    pub fn options(&self) -> RenderOptions {
        RenderOptions {
            renderer: match self.renderer {
                RendererArg::Lut => RendererKind::Lut,
                RendererArg::Exact => RendererKind::Exact,
            },
            sampler: match self.sampler {
                SamplerArg::Nearest => Sampler::Nearest,
                SamplerArg::Bilinear => Sampler::Bilinear,
                SamplerArg::Trilinear => Sampler::Trilinear,
            },
            index_step: self.index_step,
            lut: match self.lut {
                LutArg::Auto => LutChoice::Auto,
                LutArg::Wide => LutChoice::Wide,
                LutArg::High => LutChoice::High,
            },
            surface: match self.lut_surface {
                SurfaceArg::Cylinder => Surface::Cylinder,
                SurfaceArg::Plane => Surface::Plane,
            },
            threads: !self.single_thread,
            cube: match self.input.cube_renderer {
                CubeRendererArg::Basic => lut_core::CubeRenderer::Basic,
                CubeRendererArg::Scanline => lut_core::CubeRenderer::Accelerated,
            },
        }
    }
}

/// Run `viewer render`.
pub fn run(a: RenderArgs) -> Result<()> {
    let mut view = View::new(a.yaw, a.pitch, a.hfov).context("invalid view")?;
    let (w, h) = a.size;
    let cube = match a.input.projection {
        ProjectionArg::Cube => true,
        ProjectionArg::Auto => {
            a.panorama.len() > 1 || a.panorama.first().is_some_and(|p| p.is_dir())
        }
        ProjectionArg::Map(_) => false,
    };
    let mut out = vec![0u32; w as usize * h as usize];
    if cube {
        if a.input.coverage.is_some() {
            anyhow::bail!("--coverage applies to equirectangular panoramas, not cube maps");
        }
        let cube = crate::cube_cmd::load_cube(
            &a.panorama,
            a.input.layout.as_deref(),
            a.input.naming.as_deref(),
        )?;
        Renderer::default().render(
            Scene::Cube(&cube),
            view,
            &a.options(),
            &mut Frame::new(&mut out, w, h)?,
        )?;
        if a.verbose {
            eprintln!(
                "rendered {w}x{h} from a cube map of {}px faces",
                cube.face_size()
            );
        }
    } else {
        if a.panorama.len() > 1 {
            anyhow::bail!(
                "{} files given: a single panorama takes one file (use --projection cube for six faces)",
                a.panorama.len()
            );
        }
        let projection = match a.input.projection {
            ProjectionArg::Map(p) => Some(p),
            _ => None,
        };
        let tone = lut_core::Tone {
            exposure_ev: a.exposure,
        };
        let (map, _) = crate::partial::load_panorama_partial(
            a.panorama.first().map(|p| p.as_path()),
            &a.limit.options(projection, tone),
            a.input.coverage,
            &mut |_| {},
        )?;
        if a.view_limit {
            view = lut_core::limit_view(view, w, h, &map.coverage());
        }
        let opts = a.options();
        let mut renderer = Renderer::new(&map);
        let report = renderer.render(
            Scene::Map(&map),
            view,
            &opts,
            &mut Frame::new(&mut out, w, h)?,
        )?;
        if a.verbose {
            eprintln!(
                "rendered {}x{} from {}x{} {} map: path {}, table {} bytes, {} of {} pixels exact, index step {}..{}",
                w,
                h,
                map.width(),
                map.height(),
                map.projection(),
                report.path.name(),
                report.table_bytes,
                report.exact_pixels,
                report.pixels,
                report.min_step,
                report.max_step
            );
            if let Some(c) = crate::partial::coverage_text(&map) {
                eprintln!("partial panorama: {c}");
            }
            if a.view_limit {
                eprintln!(
                    "view (limited): yaw {:.4} pitch {:.4} hfov {:.4}",
                    view.yaw_deg(),
                    view.pitch_deg(),
                    view.hfov_deg()
                );
            }
            if let Some(hd) = crate::partial::heading_text(&map, view.yaw_deg()) {
                eprintln!("view centre {hd}");
            }
        }
    }
    crate::ies_cmd::apply_lights(&a.lights, view, &mut out, w, h)?;
    write_png_atomic(&a.output, &out, w, h)?;
    Ok(())
}
