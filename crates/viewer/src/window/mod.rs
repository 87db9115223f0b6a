//! The interactive window: `viewer [PANORAMA]`.
//!
//! * [`input`]: drag, wheel, keys and held buttons → the view (pure, unit-tested).
//! * [`ui`]: the egui panel (pure immediate-mode drawing from plain data).
//! * [`paint`]: the scene and the panel composed on the CPU into one 0RGB buffer.
//! * `app`: the winit event loop, softbuffer surface and background loading.
//!
//! Every frame's scene is rendered by `lut_core::Renderer::render`, the same call with the
//! same options `viewer render` makes, so the window shows what `viewer render` writes.

mod app;
pub mod input;
pub mod paint;
pub mod ui;

use clap::Args;
use lut_core::Projection;

/// `Option<Projection>` under another name, so clap takes the value parser's result
/// as-is (`auto` parses to `None`).
type ProjectionArg = Option<Projection>;

/// Arguments of the default command: open the window.
#[derive(Args, Debug)]
pub struct OpenArgs {
    /// Panorama to open (the bundled sample when omitted). Any image `viewer render`
    /// reads; drop another file on the window to open it.
    pub panorama: Option<std::path::PathBuf>,
    /// Map projection of the panorama: auto (2:1 images are equirect), equirect,
    /// cylinder, sine, elliptical or diamond.
    #[arg(long, value_name = "NAME", default_value = "auto", value_parser = crate::cli_common::parse_projection)]
    pub projection: ProjectionArg,
    /// Initial window size in logical pixels, WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "1024x640", value_parser = crate::cli_common::parse_size)]
    pub size: (u32, u32),
    /// Print the view of every rendered frame to stdout (for scripts and tests).
    #[arg(long)]
    pub print_view: bool,
}

/// Open the window on the panorama (or the sample) and run until it is closed.
///
/// # Errors
/// A missing panorama file, or no display to open a window on (a clear message; the
/// process exits nonzero, it does not panic).
pub fn run(a: OpenArgs) -> anyhow::Result<()> {
    if let Some(p) = &a.panorama {
        // Fail before opening a window for a path that is not there at all; a file that
        // exists but does not decode is reported in the window instead.
        std::fs::metadata(p).map_err(|e| anyhow::anyhow!("{}: {e}", p.display()))?;
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
    let projection = a.projection;
    app::run(a, projection)
}
