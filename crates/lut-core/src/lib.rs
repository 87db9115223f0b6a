//! # lut-core
//!
//! CPU panorama rendering with a **scanline-coherent look-up table** (US 5,748,194), and
//! an exact per-pixel renderer every fast path is measured against. No window code.
//!
//! ## Pipeline
//! 1. An [`EnvMap`] holds the panorama (0RGB `u32`, padded for branch-free bilinear) and
//!    its [`Projection`] (equirectangular, cylindrical, sine, elliptical, diamond).
//! 2. A [`Renderer`] owns two look-up tables on a cylinder whose axis is parallel to the
//!    screen scanlines (the patent's FIGS. 5-7): a wide-FOV one and a high-resolution one,
//!    chosen by hfov (60° threshold) or forced. Each stores only the one-eighth region
//!    (FIG. 6E, region 681) and recovers the rest by sign and reflection.
//! 3. Per frame: pitch picks the table rows of each scanline (two rows blended), zoom is
//!    one scale factor per scanline, yaw is a column offset added to u with wrap-around.
//! 4. Per scanline: the table is read every Nth pixel and map coordinates are interpolated
//!    in fixed point between; the step is chosen per region of each scanline from an
//!    analytic error bound (shorter near a pole, where longitude changes fast, with exact
//!    evaluation in a small zone); the ±180° seam is unwrapped per span, never smeared.
//! 5. Nearest or bilinear sampling (FIG. 10), or trilinear from a pyramid of the map
//!    when zoomed out ([`pyramid`]), writes 0RGB pixels into the caller's buffer,
//!    optionally in row bands across threads (byte-identical to one thread).
//!
//! Loading ([`load`]): a pixel limit checked from the file header before decoding, 8-bit
//! images decoded straight into the map's buffer, progress reports.
//!
//! Partial panoramas ([`coverage`], [`gpano`], [`viewlimit`]): a map may store only the
//! pixels of the area it covers plus their place in the full panorama (GPano XMP or an
//! explicit [`Coverage`]); renderers keep the full geometry and sampling returns the
//! background outside the crop; [`limit_view`] keeps a view inside the covered area.
//!
//! ## Conventions (`conventions.md`, followed exactly)
//! * yaw ψ positive turns right (toward increasing longitude), any real value, reduced
//!   mod 360°; pitch θ positive looks up, clamped to [−90°, 90°]; hfov is the horizontal
//!   field of view of the output, in (0°, 180°). No roll.
//! * Pixel (i, j) covers [i, i+1) × [j, j+1), center (i + ½, j + ½); row 0 is the top.
//! * Camera ray of output pixel (x, y): d = (x + ½ − W/2, H/2 − (y + ½), f),
//!   f = (W/2)/tan(hfov/2), rotated by pitch about X then yaw about Y;
//!   λ = atan2(X', Z'), φ = atan2(Y', √(X'² + Z'²)).
//! * Equirect: u = (λ + π)/2π · W, v = (π/2 − φ)/π · H; other projections in
//!   [`projection`].
//! * Colors are 8-bit sRGB filtered as stored; `u32` pixels are 0RGB.
//!
//! ## Accuracy
//! The LUT renderer's *sampling-position error* is the distance between its (u, v) and
//! the exact (u, v), in source pixels, with the u part scaled by cos φ (so it measures
//! the angular error in units of the map's pixel pitch and stays well defined at the
//! poles, where a whole map row is one direction). The budget is 0.05 px everywhere;
//! see `docs/ARCHITECTURE.md` and the property tests for the bound reached.

#![warn(missing_docs)]

pub mod accuracy;
pub mod camera;
pub mod coverage;
pub mod cube;
pub mod envmap;
pub mod error;
pub mod exact;
pub mod fixed;
pub mod gpano;
pub mod light;
pub mod load;
pub mod lut;
pub mod projection;
pub mod pyramid;
pub mod raster;
mod rows;
mod simd;
pub mod synth;
pub mod viewlimit;

pub use camera::{Camera, View, MAX_OUTPUT_SIDE};
pub use coverage::{Coverage, CoverageError, CoverageSource, Crop};
pub use envmap::{EnvMap, Sampler, Tone, MAX_MAP_PIXELS, MAX_MAP_WIDTH};
pub use error::{MapError, ViewError};
pub use exact::{render_exact, render_exact_supersampled};
pub use load::{LoadOptions, LoadPhase, LoadProgress, DEFAULT_MAX_PIXELS};
pub use projection::Projection;
pub use raster::{
    IndexStep, LutChoice, RenderOptions, RenderPath, RenderReport, Renderer, RendererKind,
};
pub use simd::{
    active_kernel, cpu_features, kernel_from_env, kernel_info, parse_kernel, set_kernel, Kernel,
    KernelError, KernelInfo, KernelSource, SpanJob, Texels, Window, KERNEL_ENV, MAX_JOBS,
    MAX_LEVELS, TRILINEAR_CHUNK,
};
pub use viewlimit::limit_view;
