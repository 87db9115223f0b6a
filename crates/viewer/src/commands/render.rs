//! `viewer render`: one view of a panorama to a PNG, headless.

use crate::args::{
    named, named_or_parse, parse_angle, parse_size, parse_stops, InputArgs, MaxPixelsArg,
};
use crate::heatmap::{summary, write_error_map};
use crate::lighting::{LightArgs, LitRenderError};
use crate::output::{check_not_input, output_kind, write_image};
use crate::panorama::{coverage_text, heading_text, load_cube, load_panorama_partial};
use crate::scene::measure_errors;
use crate::usage;
use anyhow::{anyhow, Context, Result};
use clap::Args;
use lut_core::Panorama;
use lut_core::{
    IndexStep, LutChoice, RenderOptions, RenderReport, RendererKind, Sampler, Surface, View,
    ViewProjection, PANNINI_D_DEFAULT,
};
use std::path::{Path, PathBuf};

/// Arguments of `viewer render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Panorama image (JPEG, PNG, ...), or a cube map: a folder, six face files, or one
    /// layout image with --projection cube. When omitted, the --scene file's panorama,
    /// else the bundled sample.
    pub panorama: Vec<PathBuf>,
    /// Decoded tiles kept in memory when the panorama is a tiled pyramid (MiB).
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u64).range(16..=1 << 20))]
    pub cache_mib: u64,
    /// Output image: .png or .jpg/.jpeg (by the name), written atomically; a device or
    /// FIFO (e.g. /dev/stdout) is written into as PNG.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Yaw in degrees (any value, taken modulo 360; positive turns right). Default 0, or
    /// the --scene file's view.
    #[arg(long, value_parser = parse_angle, allow_hyphen_values = true)]
    pub yaw: Option<f64>,
    /// Pitch in degrees (positive looks up; clamped to [-90, 90]). Default 0, or the
    /// --scene file's view.
    #[arg(long, value_parser = parse_angle, allow_hyphen_values = true)]
    pub pitch: Option<f64>,
    /// Horizontal field of view in degrees: in (0, 180) for the rectilinear view
    /// projection, up to 360 for the others (see --view-projection). Default 90, or the
    /// --scene file's view.
    #[arg(long, value_parser = parse_angle, allow_hyphen_values = true)]
    pub hfov: Option<f64>,
    /// How output pixels map to directions. Stereographic at --pitch -90 and a wide
    /// --hfov (e.g. 300) is the little planet.
    #[arg(long, default_value = "rectilinear", value_parser = named_or_parse::<ViewProjection>())]
    pub view_projection: ViewProjection,
    /// Pannini's parameter d >= 0 (0: rectilinear, 1: classic; default 1), with
    /// --view-projection pannini.
    #[arg(long, value_parser = parse_pannini_d, allow_hyphen_values = true)]
    pub pannini_d: Option<f64>,
    /// Output size WIDTHxHEIGHT (each side 1..=16384).
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// How to read the panorama (shared with the window).
    #[command(flatten)]
    pub input: InputArgs,
    /// Renderer.
    #[arg(long, default_value = "lut", value_parser = named::<RendererKind>())]
    pub renderer: RendererKind,
    /// Pixel interpolation.
    #[arg(long, default_value = "bilinear", value_parser = named::<Sampler>())]
    pub sampler: Sampler,
    /// Index interpolation step.
    #[arg(long, default_value = "adaptive", value_parser = named::<IndexStep>())]
    pub index_step: IndexStep,
    /// Which look-up table.
    #[arg(long, default_value = "auto", value_parser = named::<LutChoice>())]
    pub lut: LutChoice,
    /// Surface the look-up table is built on.
    #[arg(long, default_value = "cylinder", value_parser = named::<Surface>())]
    pub lut_surface: Surface,
    /// Exposure in stops for HDR maps (.hdr, .exr): values times 2^EV, then the tone
    /// curve x/(1+x) and sRGB. 8-bit images are shown as stored.
    #[arg(long, default_value = "0", value_parser = parse_stops, allow_hyphen_values = true)]
    pub exposure: f64,
    /// Keep the view inside the covered area of a partial panorama: reduce hfov if the
    /// view is larger than the coverage, then clamp pitch and yaw.
    #[arg(long)]
    pub view_limit: bool,
    /// Draw a zoomed-out bilinear or trilinear frame from the pyramid level on which no
    /// pixel is magnified by more than √2, as the window draws its still frames (less
    /// aliasing, and a huge map costs what its level costs). Without it, frames read the
    /// map itself at every zoom. Views that are not zoomed out are the same either way.
    #[arg(long)]
    pub still_level: bool,
    /// Render on one thread.
    #[arg(long)]
    pub single_thread: bool,
    /// The pixel limit.
    #[command(flatten)]
    pub limit: MaxPixelsArg,
    /// Draw the false colours' legend (a bar with its lux scale) at the right edge; needs
    /// --false-color (or a scene file with false colours on).
    #[arg(long)]
    pub legend: bool,
    /// Print which path rendered, the table size and the sampling-position error against
    /// the exact map (max and mean, source pixels).
    #[arg(long, short)]
    pub verbose: bool,
    /// Also write the error heat map of this view to this PNG: per pixel the
    /// sampling-position error of the renderer in use against the exact map, on a log
    /// scale from 0.001 to 1 source pixel, with a legend.
    #[arg(long, value_name = "OUT.png")]
    pub error_map: Option<PathBuf>,
    /// Luminaires lighting the scene.
    #[command(flatten)]
    pub lights: LightArgs,
    /// A level horizon: the pitch of the panorama's horizon in degrees (Pannellum's
    /// horizonPitch, GPano's PosePitchDegrees), rotated away before projection
    /// (equirectangular and cube maps, re-levelled once at load, docs/tours.md).
    #[arg(long, value_parser = parse_angle, allow_hyphen_values = true)]
    pub horizon_pitch: Option<f64>,
    /// A level horizon: the roll of the panorama's horizon in degrees (Pannellum's
    /// horizonRoll, GPano's PoseRollDegrees).
    #[arg(long, value_parser = parse_angle, allow_hyphen_values = true)]
    pub horizon_roll: Option<f64>,
    /// A tour (Pannellum config or Marzipano data.js): render its scene named by --scene
    /// (default: its first scene) at the scene's start view and horizon, with its hotspot
    /// markers (the options given override the view).
    #[arg(long, value_name = "T.json")]
    pub tour: Option<PathBuf>,
}

/// Pannini's d: a finite number (the range is checked with the view).
fn parse_pannini_d(s: &str) -> Result<f64, String> {
    crate::args::values::finite(s).ok_or_else(|| format!("'{s}' is not a finite number"))
}

impl RenderArgs {
    /// Yaw, pitch and hfov: the options given, else the scene file's view, else 0, 0, 90.
    pub fn angles(&self, scene: Option<crate::lighting::SceneView>) -> (f64, f64, f64) {
        (
            self.yaw.or(scene.map(|v| v.yaw)).unwrap_or(0.0),
            self.pitch.or(scene.map(|v| v.pitch)).unwrap_or(0.0),
            self.hfov.or(scene.map(|v| v.hfov)).unwrap_or(90.0),
        )
    }

    /// The view at a file's start view `start` for the angles not given on the command
    /// line, in `projection`; `None` when the file's angles make no valid view (the
    /// command line's or the default view is kept).
    pub fn file_view(
        &self,
        start: lut_core::StartView,
        projection: ViewProjection,
    ) -> Option<View> {
        let yaw = self.yaw.unwrap_or(start.yaw_deg);
        let pitch = self.pitch.unwrap_or(start.pitch_deg);
        let hfov = self.hfov.or(start.hfov_deg).unwrap_or(90.0);
        View::with_projection(yaw, pitch, hfov, projection).ok()
    }

    /// The output projection these arguments select (Pannini with its d).
    ///
    /// # Errors
    /// `--pannini-d` with another projection.
    pub fn view_projection(&self) -> Result<ViewProjection> {
        match (self.view_projection, self.pannini_d) {
            (ViewProjection::Pannini(_), d) => {
                Ok(ViewProjection::Pannini(d.unwrap_or(PANNINI_D_DEFAULT)))
            }
            (p, Some(_)) => Err(usage!(
                "--pannini-d applies to --view-projection pannini, not {}",
                p.name()
            )),
            (p, None) => Ok(p),
        }
    }

    /// The view these arguments select (angles not given: those of the scene file's view,
    /// `scene`: the file and its view).
    ///
    /// # Errors
    /// Bad angles, an hfov outside the projection's range, a bad Pannini d: a usage error
    /// (exit 2), unless the scene file's angles are to blame (the command line's own and
    /// the defaults make a valid view): then a problem of that file (exit 1), named.
    pub fn view(&self, scene: Option<(&Path, crate::lighting::SceneView)>) -> Result<View> {
        let p = self.view_projection()?;
        let at = |s: Option<crate::lighting::SceneView>| {
            let (yaw, pitch, hfov) = self.angles(s);
            View::with_projection(yaw, pitch, hfov, p)
        };
        at(scene.map(|s| s.1)).map_err(|e| {
            let hint = match e {
                lut_core::ViewError::HfovOutOfRange(h) if h >= 180.0 => {
                    " (wider views: --view-projection stereographic, fisheye, equisolid or pannini)"
                }
                _ => "",
            };
            match scene {
                Some((path, _)) if at(None).is_ok() => {
                    anyhow!("{}: \"view\": {e}{hint}", path.display())
                }
                _ => usage!("invalid view: {e}{hint}"),
            }
        })
    }

    /// The render options these arguments select.
    pub fn options(&self) -> RenderOptions {
        RenderOptions {
            renderer: self.renderer,
            sampler: self.sampler,
            index_step: self.index_step,
            lut: self.lut,
            surface: self.lut_surface,
            threads: !self.single_thread,
            cube: self.input.cube_renderer,
        }
    }

    /// The panorama these arguments name: a cube map, or a map placed by `--coverage` or
    /// its GPano XMP.
    fn load(&self, scene_pano: Vec<PathBuf>) -> Result<Panorama> {
        let input = &self.input;
        let panorama = if self.panorama.is_empty() {
            &scene_pano
        } else {
            &self.panorama
        };
        if let [one] = panorama.as_slice() {
            if crate::panorama::is_tiled(one) {
                if input.coverage.is_some() {
                    return Err(usage!(
                        "--coverage applies to equirectangular panoramas, not tiled pyramids"
                    ));
                }
                // The CLI waits for every tile a frame reads: the same bytes every run.
                let pano = crate::panorama::open_tiled(one, self.cache_mib)?;
                return Ok(Panorama::tiled(pano, true));
            }
        }
        if input.projection.value.reads_cube(panorama) {
            if input.coverage.is_some() {
                return Err(usage!(
                    "--coverage applies to equirectangular panoramas, not cube maps"
                ));
            }
            let cube = load_cube(panorama, input.cube)?;
            // A level horizon: the faces re-levelled once, as a map is.
            let (p, r) = (
                self.horizon_pitch.unwrap_or(0.0),
                self.horizon_roll.unwrap_or(0.0),
            );
            if p != 0.0 || r != 0.0 {
                return Ok(Panorama::cube(lut_core::level_cube_horizon(&cube, p, r)?));
            }
            return Ok(Panorama::cube(cube));
        }
        if panorama.len() > 1 {
            return Err(usage!(
                "{} files given: a single panorama takes one file (use --projection cube for six faces)",
                panorama.len()
            ));
        }
        let tone = lut_core::Tone {
            exposure_ev: self.exposure,
        };
        let (map, _) = load_panorama_partial(
            panorama.first().map(|p| p.as_path()),
            &self.limit.options(input.projection.value.map(), tone),
            input.coverage,
            &mut |_| {},
        )?;
        Ok(Panorama::map(crate::tour::render::level(
            map,
            self.horizon_pitch,
            self.horizon_roll,
        )?))
    }
}

/// Run `viewer render`.
pub fn run(mut a: RenderArgs) -> Result<()> {
    // --tour: --scene names the tour's scene (its panorama, view, horizon, markers).
    let tour_scene = match a.tour.clone() {
        Some(t) => Some(crate::tour::render::prepare(&mut a, &t)?),
        None => None,
    };
    let out = frame_with(&a, tour_scene.as_ref())?;
    write_image(&a.output, &out, a.size.0, a.size.1)
}

/// The frame `viewer render` writes (rendered, lit, with the overlays asked for), 0RGB,
/// `a.size`; the output's name is checked but nothing is written.
///
/// # Errors
/// As [`run`].
pub fn frame(a: &RenderArgs) -> Result<Vec<u32>> {
    frame_with(a, None)
}

/// [`frame`], with a tour scene's hotspot markers drawn over it.
fn frame_with(a: &RenderArgs, tour_scene: Option<&crate::tour::TourScene>) -> Result<Vec<u32>> {
    let (scene_pano, scene_view) = a.lights.room.scene_panorama()?;
    let mut view = a.view(a.lights.room.scene.as_deref().zip(scene_view))?;
    if a.view_limit && !view.projection().is_rectilinear() {
        return Err(usage!(
            "--view-limit applies to rectilinear views, not --view-projection {}",
            view.projection().name()
        ));
    }
    let (w, h) = a.size;
    // The output is checked before anything is loaded: its format, and that it is not
    // one of the files read.
    let mut outputs = vec![a.output.clone()];
    outputs.extend(a.error_map.iter().cloned());
    for o in &outputs {
        output_kind(o)?;
    }
    let mut inputs = a.panorama.clone();
    inputs.extend(scene_pano.iter().cloned());
    inputs.extend(a.lights.room.scene.iter().cloned());
    inputs.extend(a.lights.room.lights.iter().map(|l| l.file.clone()));
    check_not_input(&outputs, &inputs)?;
    // The lights first: a bad luminaire or room is reported before the panorama loads.
    let mut lights = a.lights.state()?;
    if a.legend && !lights.false_color {
        return Err(usage!(
            "--legend draws the false colours' scale: give --false-color too"
        ));
    }
    let mut scene = a.load(scene_pano)?;
    scene.set_still_level(a.still_level);
    // The file's own start view (GPano), as the window opens it, for the angles neither
    // the command line nor a scene file gives.
    if let (None, Some(start)) = (scene_view, scene.as_map().and_then(|m| m.start_view())) {
        if let Some(v) = a.file_view(start, view.projection()) {
            view = v;
        }
    }
    if let (true, Some(map)) = (a.view_limit, scene.as_map()) {
        view = lut_core::limit_view(view, w, h, &map.coverage());
    }
    let mut out = vec![0u32; w as usize * h as usize];
    // Rendered and lit in one pass (each band of rows lit as it is drawn).
    let mut lit = crate::lighting::LitCache::default();
    let t0 = std::time::Instant::now();
    let report = lights
        .render_lit(
            &mut lit,
            false,
            &mut scene,
            view,
            &a.options(),
            &mut out,
            (w, h),
        )
        .map_err(|e| match e {
            LitRenderError::Render(e) => anyhow::Error::new(e),
            LitRenderError::Lights(e) => anyhow::Error::msg(e),
        })?;
    let lit_ms = t0.elapsed().as_secs_f64() * 1e3;
    // A tiled pyramid's tiles that could not be read or decoded (each drawn from a
    // coarser level): a warning naming each, never silence (docs/reliability.md, class 3).
    if let Some((_, _, notices)) = scene.tiles_status() {
        for n in notices {
            crate::errln!("warning: {}", lut_core::one_line(&n));
        }
    }
    let error_map = if a.verbose || a.error_map.is_some() {
        Some(
            measure_errors(&mut scene, view, &a.options(), w, h)
                .context("cannot measure the sampling-position error")?,
        )
    } else {
        None
    };
    if a.verbose {
        print_report(a, &scene, &report, view);
        if let Some(em) = &error_map {
            crate::errln!("{}", summary(em));
        }
    }
    if let (Some(path), Some(em)) = (&a.error_map, &error_map) {
        write_error_map(path, em)?;
    }
    if error_map.is_some() {
        if let Some(note) = crate::heatmap::exact_note(scene.kind()) {
            crate::errln!("note: the sampling-position error is {note}");
        }
    }
    if a.verbose && !lights.lights.is_empty() {
        crate::errln!(
            "lit from an illuminance map of {:.1} KiB ({} luminaires, map, render and shading {:.0} ms, exposure {:.0} lx)",
            lit.bytes() as f64 / 1024.0,
            lights.lights.len(),
            lit_ms,
            lights.exposure_lux
        );
    }
    if lights.show_room {
        crate::lighting::overlay::draw_room_and_lights(&lights, view, &mut out, w, h)
            .map_err(anyhow::Error::msg)?;
    }
    if a.legend {
        crate::lighting::legend::draw_legend(&mut out, w, h, lights.false_color_max)
            .map_err(anyhow::Error::msg)?;
    }
    if let Some(ts) = tour_scene {
        crate::tour::markers::draw(ts, view, &mut out, w, h);
    }
    Ok(out)
}

/// `-v`: what rendered the frame, on stderr.
fn print_report(a: &RenderArgs, scene: &Panorama, report: &RenderReport, view: View) {
    let (w, h) = a.size;
    match scene.as_map() {
        Some(map) => {
            let steps = if report.path == lut_core::RenderPath::Grid {
                format!("grid cells {}..{} px", report.min_step, report.max_step)
            } else {
                format!("index step {}..{}", report.min_step, report.max_step)
            };
            crate::errln!(
                "rendered {}x{} from {}x{} {} map: path {}, table {} bytes, {} of {} pixels exact, {steps}",
                w,
                h,
                map.width(),
                map.height(),
                map.projection(),
                report.path.name(),
                report.table_bytes,
                report.exact_pixels,
                report.pixels,
            );
            if !view.projection().is_rectilinear() {
                crate::errln!(
                    "view projection {} (hfov {} degrees)",
                    view.projection(),
                    view.hfov_deg()
                );
            }
            if let Some(c) = coverage_text(map) {
                crate::errln!("partial panorama: {c}");
            }
            if a.view_limit {
                crate::errln!(
                    "view (limited): yaw {:.4} pitch {:.4} hfov {:.4}",
                    view.yaw_deg(),
                    view.pitch_deg(),
                    view.hfov_deg()
                );
            }
            if let Some(hd) = heading_text(map, view.yaw_deg()) {
                crate::errln!("view centre {hd}");
            }
        }
        None => crate::errln!(
            "rendered {w}x{h} from a {} map of {}px faces",
            scene.kind().name(),
            scene.size().0
        ),
    }
}

#[cfg(test)]
mod tests {
    use crate::cli::{Cli, Command};
    use clap::Parser;
    use lut_core::{CubeRenderer, IndexStep, LutChoice, Naming, RendererKind, Sampler, Surface};

    fn render_args(extra: &[&str]) -> Result<super::RenderArgs, clap::Error> {
        let mut argv = vec!["viewer", "render", "-o", "x.png"];
        argv.extend_from_slice(extra);
        match Cli::try_parse_from(argv)?.command {
            Some(Command::Render(a)) => Ok(*a),
            other => panic!("not render: {other:?}"),
        }
    }

    #[test]
    fn defaults_are_the_documented_ones() {
        let a = render_args(&[]).unwrap();
        assert_eq!(a.options(), lut_core::RenderOptions::default());
        assert_eq!(a.options().cube, CubeRenderer::Accelerated);
        assert_eq!(a.size, (1280, 720));
        assert_eq!(a.angles(None), (0.0, 0.0, 90.0));
        let saved = crate::lighting::SceneView {
            yaw: 10.0,
            pitch: -20.0,
            hfov: 70.0,
        };
        assert_eq!(a.angles(Some(saved)), (10.0, -20.0, 70.0));
        assert_eq!(a.input.cube_renderer, CubeRenderer::Accelerated);
        assert_eq!(a.input.projection.value, crate::args::ProjectionArg::Auto);
    }

    #[test]
    fn every_option_value_parses_by_its_name() {
        let a = render_args(&[
            "--renderer",
            "exact",
            "--sampler",
            "trilinear",
            "--index-step",
            "16",
            "--lut",
            "high",
            "--lut-surface",
            "plane",
            "--cube-renderer",
            "basic",
            "--naming",
            "sauerbraten",
            "--layout",
            "3x2",
            "--projection",
            "sinusoidal",
            "--yaw",
            "-30",
            "--single-thread",
        ])
        .unwrap();
        let o = a.options();
        assert_eq!(o.renderer, RendererKind::Exact);
        assert_eq!(o.sampler, Sampler::Trilinear);
        assert_eq!(o.index_step, IndexStep::Fixed(16));
        assert_eq!(o.lut, LutChoice::High);
        assert_eq!(o.surface, Surface::Plane);
        assert!(!o.threads);
        assert_eq!(a.input.cube_renderer, CubeRenderer::Basic);
        assert_eq!(a.input.cube.naming, Some(Naming::Cube2));
        assert_eq!(a.input.cube.layout, Some(lut_core::Layout::Grid3x2));
        assert_eq!(
            a.input.projection.value.map(),
            Some(lut_core::Projection::Elliptical)
        );
        assert_eq!(a.yaw, Some(-30.0));
    }

    #[test]
    fn view_projections_and_their_parameter() {
        use lut_core::ViewProjection;
        let a = render_args(&[]).unwrap();
        assert_eq!(
            a.view(None).unwrap(),
            lut_core::View::new(0.0, 0.0, 90.0).unwrap()
        );
        assert!(a.error_map.is_none());
        let a = render_args(&["--view-projection", "pannini", "--hfov", "200"]).unwrap();
        assert_eq!(
            a.view(None).unwrap().projection(),
            ViewProjection::Pannini(1.0)
        );
        let a = render_args(&["--view-projection", "pannini", "--pannini-d", "0.25"]).unwrap();
        assert_eq!(a.view_projection().unwrap(), ViewProjection::Pannini(0.25));
        let a = render_args(&["--view-projection", "little-planet", "--hfov", "330"]).unwrap();
        assert_eq!(
            a.view(None).unwrap().projection(),
            ViewProjection::Stereographic
        );
        let a = render_args(&["--renderer", "grid", "--lut-surface", "diamond"]).unwrap();
        assert_eq!(a.options().renderer, RendererKind::Grid);
        assert_eq!(a.options().surface, Surface::Diamond);
        let a = render_args(&["--view-projection", "fisheye", "--pannini-d", "1"]).unwrap();
        assert!(a
            .view(None)
            .unwrap_err()
            .to_string()
            .contains("--pannini-d applies"));
        let a = render_args(&["--hfov", "250"]).unwrap();
        let e = a.view(None).unwrap_err().to_string();
        assert!(
            e.contains("got 250") && e.contains("--view-projection"),
            "{e}"
        );
    }

    #[test]
    fn bad_values_are_refused_naming_them() {
        for (flag, bad) in [
            ("--index-step", "3"),
            ("--sampler", "cubic"),
            ("--lut", "medium"),
            ("--cube-renderer", "accelerated"),
            ("--layout", "hex"),
            ("--naming", "opengl3"),
            ("--projection", "mercator"),
            ("--size", "0x10"),
            ("--yaw", "nan"),
            ("--view-projection", "mercator"),
            ("--pannini-d", "inf"),
            ("--renderer", "table"),
        ] {
            let e = render_args(&[flag, bad]).unwrap_err().to_string();
            assert!(e.contains(bad), "{flag} {bad}: {e}");
        }
    }
}
