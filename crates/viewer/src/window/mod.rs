//! The interactive window: `viewer [PANORAMA]`.
//!
//! * [`input`]: drag, wheel, keys and held buttons → the view (pure, unit-tested).
//! * [`ui`]: the egui panel (pure immediate-mode drawing from plain data).
//! * [`paint`]: the scene and the panel composed on the CPU into one 0RGB buffer.
//! * [`export`]: HDR exposure steps and the "Save view…" size and file name (pure).
//! * `app`: the winit event loop, softbuffer surface and background loading.
//!
//! Every frame's scene is rendered by `lut_core::Renderer::render`, the same call with the
//! same options `viewer render` makes, so the window shows what `viewer render` writes.

mod app;
pub mod export;
pub mod input;
pub mod lights;
pub mod paint;
pub mod ui;

use crate::render_cmd::ProjectionArg;
use clap::Args;
use std::path::PathBuf;

/// Arguments of the default command: open the window.
#[derive(Args, Debug)]
pub struct OpenArgs {
    /// Panorama to open (the bundled sample when omitted): any image `viewer render`
    /// reads, or a cube map (a folder, six face files, or one layout image with
    /// --projection cube). Drop another file or folder on the window to open it.
    pub panorama: Vec<PathBuf>,
    /// How to read the panorama (the same options as `viewer render`).
    #[command(flatten)]
    pub input: crate::render_cmd::InputArgs,
    /// Initial window size in logical pixels, WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "1024x640", value_parser = crate::cli_common::parse_size)]
    pub size: (u32, u32),
    /// Print the view of every rendered frame to stdout (for scripts and tests).
    #[arg(long)]
    pub print_view: bool,
    /// Start with the view limit off (partial panoramas; the panel's "Keep the view
    /// inside" switches it).
    #[arg(long)]
    pub no_view_limit: bool,
    /// The pixel limit for panoramas opened or dropped.
    #[command(flatten)]
    pub limit: crate::max_pixels::MaxPixelsArg,
    /// Luminaires lighting the scene (also added, moved and removed in the panel).
    #[command(flatten)]
    pub lights: crate::ies_cmd::LightArgs,
}

/// Open the window on the panorama (or the sample) and run until it is closed.
///
/// # Errors
/// A missing panorama file, or no display to open a window on (a clear message; the
/// process exits nonzero, it does not panic).
pub fn run(a: OpenArgs) -> anyhow::Result<()> {
    for p in &a.panorama {
        // Fail before opening a window for a path that is not there at all; a file that
        // exists but does not decode is reported in the window instead.
        std::fs::metadata(p).map_err(|e| anyhow::anyhow!("{}: {e}", p.display()))?;
    }
    if a.panorama.len() > 1 && matches!(a.input.projection, ProjectionArg::Map(_)) {
        anyhow::bail!(
            "{} files given: a single panorama takes one file (six faces are a cube map)",
            a.panorama.len()
        );
    }
    // Lights given on the command line: loaded now, so a bad file or position is
    // reported before any window opens (as `viewer render` reports it).
    let lights = lights_from_args(&a.lights)?;
    let has_display = ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()));
    if cfg!(all(unix, not(target_os = "macos"))) && !has_display {
        anyhow::bail!(
            "cannot open a window: no display (neither DISPLAY nor WAYLAND_DISPLAY is set); \
             `viewer render` draws a view to a PNG without one"
        );
    }
    app::run(a, lights)
}

/// The panel's light state for `--light ...` and the other light options.
///
/// # Errors
/// As `ies_cmd::build_scene`: an unreadable IES file, a light outside the room.
fn lights_from_args(a: &crate::ies_cmd::LightArgs) -> anyhow::Result<lights::LightsState> {
    let opts = crate::ies_cmd::shade_options(a)?;
    let scene = crate::ies_cmd::build_scene(a)?;
    let mut st = lights::LightsState {
        room: a.room.unwrap_or(lights::DEFAULT_ROOM),
        camera_height: a.camera_height.unwrap_or(lights::DEFAULT_CAMERA_HEIGHT),
        multiplier: a.light_multiplier.unwrap_or(1.0),
        exposure_lux: a.exposure_lux.unwrap_or(lights::DEFAULT_EXPOSURE_LUX),
        ambient: opts.ambient,
        false_color: opts.false_color,
        false_color_max: opts.false_color_max_lux,
        ..lights::LightsState::default()
    };
    if let Some(scene) = scene {
        for (spec, l) in a.lights.iter().zip(scene.luminaires()) {
            st.lights.push(lights::LightEntry {
                path: spec.file.clone(),
                table: l.table.clone(),
                position: spec.position,
                yaw: spec.aim.0,
                pitch: spec.aim.1,
            });
        }
    }
    Ok(st)
}
