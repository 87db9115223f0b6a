//! The interactive window: `viewer [PANORAMA]`.
//!
//! * [`input`]: drag, wheel, double-click, held buttons, auto-rotation, zoom range →
//!   the view (pure, unit-tested).
//! * [`keys`]: the one table of key bindings (input and the help read it) and the
//!   routing of shortcut keys past egui's focus.
//! * [`quality`]: render settings, anti-aliasing modes and the adaptive quality rule.
//! * [`document`]: what is shown, loading, the last error, drops, start views (pure
//!   state machine, unit-tested); [`loader`]: what is opened and the loading thread's
//!   work; [`folder`]: the next and previous panorama in a folder.
//! * [`ui`]: the engineering panel in sections ([`lights_panel`]: its "Lights" section); [`overlay`]: the viewing UI over the
//!   scene (toolbar, compass, notices, help); [`notices`]: the messages' state;
//!   [`dialogs`]: the Open and Save dialogs.
//! * [`prefs`]: settings kept between runs in the user's config folder.
//! * [`paint`]: the scene and the UI composed on the CPU into one 0RGB buffer; the
//!   upscaling of degraded frames; the window icon.
//! * [`export`]: HDR exposure steps and the "Save view…" size and file name (pure).
//! * [`tour`]: a tour's hotspots over the scene, links followed with a glide and a
//!   crossfade, back and forward, the scene list.
//! * [`heap`]: freed heap memory given back to the system when the window settles, so
//!   that a long session's resident memory does not creep up (glibc).
//! * `app`: the winit event loop and softbuffer surface; it runs the document's effects.
//!
//! The luminaires the panel edits are [`crate::lighting::LightsState`].
//!
//! Every frame's scene is rendered by [`crate::scene::render_scene`], the same call with
//! the same options `viewer render` makes, so the window shows what `viewer render` writes.

mod app;
pub mod dialogs;
pub mod document;
pub mod export;
pub mod folder;
pub mod heap;
pub mod input;
pub mod keys;
pub mod lights_panel;
pub mod loader;
pub mod notices;
pub mod overlay;
pub mod paint;
pub mod prefs;
pub mod quality;
pub mod tour;
pub mod ui;

use crate::args::{parse_angle, parse_size, InputArgs, MaxPixelsArg, ProjectionArg};
use crate::lighting::LightArgs;
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
    pub input: InputArgs,
    /// Start yaw in degrees (default: the file's GPano start view, else 0).
    #[arg(long, value_parser = parse_angle, allow_hyphen_values = true)]
    pub yaw: Option<f64>,
    /// Start pitch in degrees, clamped to [-90, 90] (default: the file's, else 0).
    #[arg(long, value_parser = parse_angle, allow_hyphen_values = true)]
    pub pitch: Option<f64>,
    /// Start horizontal field of view in degrees, in (0, 180) (default: the file's, else
    /// 90; the zoom limit may widen it).
    #[arg(long, value_parser = parse_hfov, allow_hyphen_values = true)]
    pub hfov: Option<f64>,
    /// Initial window size in logical pixels, WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "1024x640", value_parser = parse_size)]
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
    pub limit: MaxPixelsArg,
    /// Decoded tiles of tiled pyramids kept in memory (MiB); kept in the settings for the
    /// next runs (default: the settings', else 1024).
    #[arg(long, value_parser = clap::value_parser!(u64).range(16..=1 << 20))]
    pub cache_mib: Option<u64>,
    /// Luminaires lighting the scene (also added, moved and removed in the panel).
    #[command(flatten)]
    pub lights: LightArgs,
}

/// A start hfov: a finite angle in (0, 180).
fn parse_hfov(s: &str) -> Result<f64, String> {
    let v = parse_angle(s)?;
    if v > 0.0 && v < 180.0 {
        Ok(v)
    } else {
        Err(format!("hfov '{s}' must be in (0, 180) degrees"))
    }
}

/// Open the window on the panorama (or the sample) and run until it is closed.
///
/// # Errors
/// A missing panorama file, or no display to open a window on (a clear message; the
/// process exits nonzero, it does not panic).
pub fn run(mut a: OpenArgs) -> anyhow::Result<()> {
    // A scene file names the panorama and view when the command line does not.
    let (scene_pano, scene_view) = a.lights.room.scene_panorama()?;
    if a.panorama.is_empty() {
        a.panorama.extend(scene_pano);
    }
    if let Some(v) = scene_view {
        a.yaw = a.yaw.or(Some(v.yaw));
        a.pitch = a.pitch.or(Some(v.pitch));
        a.hfov = a.hfov.or(Some(v.hfov));
    }
    // A panorama that cannot be opened, missing or damaged alike, is the loader's error:
    // the window opens with the bundled sample and shows the error (one behaviour for
    // both; docs/reliability.md, class 8), as when a bad file is dropped or opened later.
    if a.panorama.len() > 1 && matches!(a.input.projection.value, ProjectionArg::Map(_)) {
        return Err(crate::usage!(
            "{} files given: a single panorama takes one file (six faces are a cube map)",
            a.panorama.len()
        ));
    }
    // Lights given on the command line: loaded now, so a bad file or position is
    // reported before any window opens (as `viewer render` reports it).
    let mut lights = a.lights.state()?;
    if a.lights.exposure_lux.is_none() && a.lights.room.scene.is_none() {
        // The window's default: the exposure follows the lights, so a light added or
        // dropped brightens the room without blowing it out.
        lights.auto_exposure = true;
    }
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
