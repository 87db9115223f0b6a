//! Goniometric luminaires (EP 0613099) lighting a room panorama.
//!
//! * [`ies`]: the IES LM-63 parser (1986/1991/1995/2002/2019; types A, B, C; TILT).
//! * [`ldt`]: the EULUMDAT (.ldt) parser (symmetry indicators 0-4, type indicators 0-3,
//!   relative and absolute photometry).
//! * [`photometry`]: one photometric model for both formats ([`Photometry`]), loaded by
//!   content, not by file name.
//! * [`table`]: the patent's light table: a 2-D table indexed by the pair of polar angles
//!   of the direction relative to the light's aim, with fractional-index interpolation,
//!   symmetry folded at lookup (only the measured subset is stored), constant ranges left
//!   out and substituted at lookup, and a series of pre-filtered tables by distance, each
//!   about half the size of the previous, normalized to a reference distance and scaled by
//!   the inverse square.
//! * [`room`]: the room box around the camera, turned and shifted to fit the photograph;
//!   room coordinates.
//! * [`shade`]: luminaires placed in the room, and per-pixel shading of a rendered frame:
//!   scene point = ray ∩ room, E = I(direction)·cos(incidence)/d², colour = albedo ·
//!   (ambient + exposure · ΣE), with a false-colour illuminance overlay. The exact path.
//! * [`illum`]: the illuminance map, E computed once per lighting change over the room's
//!   faces, which frames sample (`map_shade`): the interactive path.
//! * [`radiosity`]: inter-reflections: the faces' reflectances, patches, closed-form
//!   form factors and the radiosity solve; the indirect illuminance at any point.
//! * [`grid`]: EN 12464-1 calculation grids and their figures (Em, Emin, Emax, U0, Ud).
//! * [`ugr`]: CIE 117's Unified Glare Rating from the files' luminous areas.
//! * [`bake`]: the lit panorama, every texel lit once from the illuminance map, so a pan
//!   of the lit room is an unlit frame of the lit copy.
//!
//! World frame (docs/conventions.md): X right, Y up, Z forward at yaw 0; metres. The origin is
//! the floor point below the camera, so the camera sits at (0, camera height, 0).
//! See `docs/lights.md` for the design.

pub mod bake;
pub mod grid;
pub mod ies;
pub mod illum;
pub mod ldt;
mod level;
mod map_shade;
pub mod photometry;
pub mod radiosity;
pub mod room;
pub mod shade;
mod shade_table;
pub mod table;
pub mod ugr;

pub use bake::{lit_cube_bytes, lit_map_bytes, lit_panorama_bytes, BAKE_MAX_BYTES};
pub use grid::{border_band, en12464_spacing, AreaStats, CalcGrid, MAX_GRID_POINTS};
pub use ies::{IesError, IesFile, IesFormat, PhotometricType, Tilt, TiltData};
pub use illum::{IlluminanceMap, MapOptions};
pub use ldt::{LampSet, LdtError, LdtFile, LdtSymmetry, LdtType};
pub use map_shade::{FrameShader, BLOCK as MAP_SHADE_BLOCK};
pub use photometry::{detect_format, LightFileFormat, Photometry, PhotometrySource};
pub use radiosity::{
    DirectLight, FormFactors, Patch, Radiosity, Reflectances, DEFAULT_PATCHES, MAX_PATCHES,
};
pub use room::{Room, RoomFace};
pub use shade::{
    false_color, false_color_position, lux_at, shade_frame, LightScene, Luminaire, ShadeOptions,
};
pub use table::{Interpolation, LightTable, Symmetry, TableOptions};
pub use ugr::{ugr, GlareTerm, LuminousArea, Ugr};

/// Largest photometric file read, in bytes. Real IES and EULUMDAT files are well under
/// 1 MB; the largest table the parsers accept (4 M values) fits in this.
pub const MAX_FILE_BYTES: u64 = 64 << 20;

/// Read a photometric file as text, refusing files over [`MAX_FILE_BYTES`] before reading
/// them. UTF-8 when valid, else ISO-8859-1 (what EULUMDAT prescribes and what old IES
/// files use): every byte becomes the character of the same number, so header text keeps
/// its accents and the numbers are unchanged. The `Err` is the reason, for the caller's
/// error type.
/// A parser or table builder that panicked on a file: the file's [`LightError::Io`].
impl From<crate::guard::DecoderPanic> for LightError {
    fn from(p: crate::guard::DecoderPanic) -> LightError {
        LightError::Io {
            file: p.path.display().to_string(),
            reason: format!(
                "the file is damaged or of a kind the reader cannot handle (it failed on it: {})",
                p.message
            ),
        }
    }
}

pub(crate) fn read_text(path: &std::path::Path) -> Result<String, String> {
    use std::io::Read;
    let f = crate::file::open_regular(path).map_err(|e| e.to_string())?;
    let mut bytes = Vec::new();
    f.take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| e.to_string())?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(format!(
            "larger than {} MiB, far more than any photometric file needs",
            MAX_FILE_BYTES >> 20
        ));
    }
    Ok(match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => e.into_bytes().iter().map(|&b| char::from(b)).collect(),
    })
}

/// Text from a file made safe to print in a one-line message: control characters
/// (escape sequences, carriage returns, ...) and invisible format characters (bidi
/// overrides, zero-width spaces, byte-order marks) are written as `\u{..}` escapes, and
/// anything past 40 characters is cut and marked with `…`.
pub(crate) fn sanitize(text: &str) -> String {
    const MAX: usize = 40;
    let mut out = String::new();
    for (i, c) in text.chars().enumerate() {
        if i == MAX {
            out.push('…');
            break;
        }
        let invisible = matches!(
            c,
            '\u{200b}'..='\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}' | '\u{feff}'
        );
        if c.is_control() || invisible {
            out.push_str(&format!("\\u{{{:x}}}", c as u32));
        } else {
            out.push(c);
        }
    }
    out
}

/// [`sanitize`]d text in single quotes, for the "found ..." part of an error.
pub(crate) fn quoted(text: &str) -> String {
    format!("'{}'", sanitize(text))
}

/// Why a light table, a scene or a shading request cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LightError {
    /// The IES file is unreadable or malformed.
    #[error(transparent)]
    Ies(#[from] IesError),
    /// The EULUMDAT file is unreadable or malformed.
    #[error(transparent)]
    Ldt(#[from] LdtError),
    /// A number that sizes work or memory is beyond its limit
    /// ([`crate::limits`]): room sides, luminaires, multipliers.
    #[error(transparent)]
    Limit(#[from] crate::guard::LimitError),
    /// The file could not be read.
    #[error("{file}: cannot read: {reason}")]
    Io {
        /// The file.
        file: String,
        /// Why.
        reason: String,
    },
    /// The file is neither an IES nor an EULUMDAT file (judged by content, then by its
    /// extension).
    #[error(
        "{file}: not a photometric file: neither IES LM-63 (no IESNA/IES: format line, no \
         TILT= line) nor EULUMDAT (lines 2 to 7 are not the type and symmetry indicators, \
         the C-plane and gamma counts and steps)"
    )]
    UnknownFormat {
        /// The file.
        file: String,
    },
    /// A [`Photometry`] (or an [`IesFile`]) assembled by hand whose fields do not agree.
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
        "light {} at ({}, {}, {}) m is outside the room \
         (x in {}..{}, y in {}..{}, z in {}..{})",
        index + 1, position[0], position[1], position[2],
        low[0], high[0], low[1], high[1], low[2], high[2]
    )]
    LightOutsideRoom {
        /// Index of the luminaire in the scene (0-based; the message counts from 1).
        index: usize,
        /// Its position in room coordinates.
        position: [f64; 3],
        /// The room's low corner.
        low: [f64; 3],
        /// The room's high corner.
        high: [f64; 3],
    },
    /// A point (for a lux reading) lies outside the room box.
    #[error(
        "point ({}, {}, {}) m is outside the room (x in {}..{}, y in {}..{}, z in {}..{})",
        point[0], point[1], point[2], low[0], high[0], low[1], high[1], low[2], high[2]
    )]
    PointOutsideRoom {
        /// The point, room coordinates.
        point: [f64; 3],
        /// The room's low corner.
        low: [f64; 3],
        /// The room's high corner.
        high: [f64; 3],
    },
    /// A point lies on no face of the room, so the surface normal is not known.
    #[error(
        "point ({}, {}, {}) m is not on a wall, the floor or the ceiling (none within {} m): \
         the surface's normal is needed",
        point[0], point[1], point[2], tol
    )]
    PointOffSurface {
        /// The point, room coordinates.
        point: [f64; 3],
        /// How close to a face it had to be, in metres.
        tol: f64,
    },
    /// A point lies on an edge or corner of the room, where faces with different normals
    /// meet.
    #[error(
        "point ({}, {}, {}) m lies where the {} and the {} meet: the surface's normal is needed",
        point[0], point[1], point[2], faces.0, faces.1
    )]
    PointOnEdge {
        /// The point, room coordinates.
        point: [f64; 3],
        /// Two of the faces meeting there.
        faces: (&'static str, &'static str),
    },
    /// A lit copy of the panorama would take more memory than a bake may use.
    #[error(
        "the lit panorama would take {} MiB, more than the {} MiB a bake may use: \
         frames are lit one by one instead",
        bytes.div_ceil(1 << 20), max >> 20
    )]
    BakeTooLarge {
        /// The bytes the lit copy (and its pyramid) would take.
        bytes: usize,
        /// [`BAKE_MAX_BYTES`].
        max: usize,
    },
    /// A bake was cancelled (its lighting changed while it ran): nothing was made.
    #[error("the bake was cancelled")]
    Cancelled,
    /// A computation would need more of something than its budget allows.
    #[error("{what}: {count} needed, more than the limit of {max}")]
    TooMany {
        /// What ("radiosity patches", "grid points").
        what: &'static str,
        /// How many were needed.
        count: usize,
        /// The limit.
        max: usize,
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
