//! Goniometric luminaires (EP 0613099) lighting a room panorama.
//!
//! * [`ies`]: the IES LM-63 parser (1986/1991/1995/2002/2019; types A, B, C; TILT).
//! * [`table`]: the patent's light table: a 2-D table indexed by the pair of polar angles
//!   of the direction relative to the light's aim, with fractional-index interpolation,
//!   symmetry folded at lookup (only the measured subset is stored), constant ranges left
//!   out and substituted at lookup, and a series of pre-filtered tables by distance, each
//!   about half the size of the previous, normalized to a reference distance and scaled by
//!   the inverse square.
//! * [`shade`]: a room box around the camera, luminaires placed in it, and per-pixel
//!   shading of a rendered frame: scene point = ray ∩ room, E = I(direction)·cos(incidence)/d²,
//!   colour = albedo · (ambient + exposure · ΣE), with a false-colour illuminance overlay.
//!
//! World frame (docs/conventions.md): X right, Y up, Z forward at yaw 0; metres. The origin is
//! the floor point below the camera, so the camera sits at (0, camera height, 0).
//! See `docs/lights.md` for the design.

pub mod ies;
pub mod shade;
pub mod table;

pub use ies::{IesError, IesFile, IesFormat, PhotometricType, Tilt, TiltData};
pub use shade::{lux_at, shade_frame, LightScene, Luminaire, Room, ShadeOptions};
pub use table::{LightTable, Symmetry, TableOptions};

/// Why a light table, a scene or a shading request cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LightError {
    /// The IES file is unreadable or malformed.
    #[error(transparent)]
    Ies(#[from] IesError),
    /// An [`IesFile`] assembled by hand whose fields do not agree.
    #[error("{file}: inconsistent photometric data: expected {expected}")]
    Inconsistent {
        /// The file's name.
        file: String,
        /// What was expected.
        expected: &'static str,
    },
    /// A numeric option is out of its range.
    #[error("{name} must be {expected}, got {value}")]
    BadOption {
        /// Which option.
        name: &'static str,
        /// The accepted range, in words.
        expected: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// A luminaire lies outside the room box (the walls would shadow it entirely).
    #[error(
        "light {index} at ({x}, {y}, {z}) m is outside the room \
         (x in ±{half_width}, y in 0..{height}, z in ±{half_depth})"
    )]
    LightOutsideRoom {
        /// Index of the luminaire in the scene.
        index: usize,
        /// Position X.
        x: f64,
        /// Position Y.
        y: f64,
        /// Position Z.
        z: f64,
        /// Half the room width.
        half_width: f64,
        /// Room height.
        height: f64,
        /// Half the room depth.
        half_depth: f64,
    },
    /// The frame buffer does not hold width × height pixels.
    #[error("frame holds {len} pixels but {width}x{height} needs {needed}")]
    BufferSize {
        /// Buffer length.
        len: usize,
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// width × height.
        needed: usize,
    },
}
