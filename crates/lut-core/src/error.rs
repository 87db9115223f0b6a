//! Error types. One small enum per concern; the library never panics on caller input.

use std::path::PathBuf;

/// An invalid view or output request (angles, sizes, options).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ViewError {
    /// The named angle is NaN or infinite.
    #[error("{name} must be a finite number of degrees, got {value}")]
    NonFinite {
        /// Which parameter ("yaw", "pitch", "hfov").
        name: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// hfov is outside the open interval (0, 180) (the rectilinear projection's range).
    #[error("hfov must be in the open interval (0, 180) degrees, got {0}")]
    HfovOutOfRange(f64),
    /// hfov is outside the range of an output projection other than rectilinear.
    #[error(
        "hfov must be in (0, {max}{} degrees for the {projection} view projection, got {hfov}",
        if *.inclusive { "]" } else { ")" }
    )]
    HfovForProjection {
        /// The rejected hfov.
        hfov: f64,
        /// The projection's name.
        projection: &'static str,
        /// Its largest hfov.
        max: f64,
        /// Whether `max` itself is allowed.
        inclusive: bool,
    },
    /// Pannini's parameter d is negative, not finite or above the limit.
    #[error("the Pannini parameter d must be a number in [0, {max}], got {d}")]
    BadPanniniD {
        /// The rejected value.
        d: f64,
        /// The largest accepted.
        max: f64,
    },
    /// The output size is zero or above [`crate::MAX_OUTPUT_SIDE`].
    #[error("output size {width}x{height} is invalid: each side must be in 1..={max}")]
    BadSize {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
        /// The limit.
        max: u32,
    },
    /// The output buffer does not hold width × height pixels.
    #[error("output buffer holds {len} pixels but {width}x{height} needs {needed}")]
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
    /// Index step not in {1, 2, 4, 8, 16}.
    #[error("index step must be one of 1, 2, 4, 8, 16, got {0}")]
    BadIndexStep(u32),
}

/// Why a map size cannot be used (see [`MapError::Size`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum SizeProblem {
    /// A side is zero.
    #[error("the image is empty")]
    Empty,
    /// A side is above the supported limit.
    #[error("sides above {max_width}x{max_height} are not supported")]
    SidesAbove {
        /// Largest width.
        max_width: u32,
        /// Largest height.
        max_height: u32,
    },
    /// More pixels than the supported limit.
    #[error("more than {max} pixels")]
    PixelsAbove {
        /// Largest pixel count.
        max: u64,
    },
    /// A side below 2 pixels.
    #[error("a map needs at least 2x2 pixels")]
    TooSmall,
    /// A pixel buffer whose length is not width × height.
    #[error("buffer holds {len} pixels")]
    BufferLength {
        /// The buffer's length.
        len: usize,
    },
    /// The memory for the map could not be had.
    #[error("not enough memory for the map ({:.2} GiB)", *bytes as f64 / f64::from(1u32 << 30))]
    OutOfMemory {
        /// Bytes asked for.
        bytes: u64,
    },
}

/// An environment map that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MapError {
    /// The file could not be read or decoded (`reason` is the reader's or decoder's own
    /// message).
    #[error("{path}: cannot read image: {reason}")]
    Decode {
        /// The file (or the name given to in-memory bytes).
        path: PathBuf,
        /// The reader's or decoder's message.
        reason: String,
    },
    /// The image is empty, too small or larger than the supported limit.
    #[error("{what}: map size {width}x{height} is not supported: {problem}")]
    Size {
        /// The file or a description of the source.
        what: String,
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// What is wrong with it.
        problem: SizeProblem,
    },
    /// The image has more pixels than the configured limit (read from the file header,
    /// before any pixel buffer is allocated: a defence against decompression bombs).
    #[error(
        "{what}: the image is {width}x{height} = {pixels} pixels, above the limit of {limit} \
         pixels, so it was not decoded (a defence against decompression bombs)"
    )]
    TooManyPixels {
        /// The file or a description of the source.
        what: String,
        /// Width from the header.
        width: u64,
        /// Height from the header.
        height: u64,
        /// width × height.
        pixels: u64,
        /// The limit in force.
        limit: u64,
    },
    /// No projection was given and the image is not 2:1, so it is not taken as
    /// equirectangular.
    #[error("{what}: image is {width}x{height}, not 2:1, so it is not taken as equirectangular")]
    UnknownProjection {
        /// The file or a description of the source.
        what: String,
        /// Width.
        width: u32,
        /// Height.
        height: u32,
    },
    /// An image given as equirectangular that is not 2:1.
    #[error("{what}: an equirectangular map must be 2:1, this image is {width}x{height}")]
    EquirectNotTwoToOne {
        /// The file or a description of the source.
        what: String,
        /// Width.
        width: u32,
        /// Height.
        height: u32,
    },
}

/// Why GPano metadata cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GPanoError {
    /// The XMP packet mentions GPano but is not well-formed XML.
    #[error("XMP metadata is not well-formed XML: {0}")]
    Xml(String),
    /// A field's value is not a usable number.
    #[error("GPano:{field} = '{value}' is not {expected}")]
    Value {
        /// Field name without prefix.
        field: &'static str,
        /// The text found.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// Some crop fields are present and others are missing.
    #[error("GPano metadata is incomplete: {0} is missing")]
    Missing(&'static str),
    /// The fields do not describe a crop of the full panorama.
    #[error("GPano metadata is inconsistent: {0}")]
    Inconsistent(String),
}

/// What is wrong with a coverage's angles (see [`CoverageError::Angles`]).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AngleProblem {
    /// An angle is NaN or infinite.
    #[error("angles must be finite, got {hfov}x{vfov} at {yaw}, {pitch}")]
    NonFinite {
        /// Horizontal extent.
        hfov: f64,
        /// Vertical extent.
        vfov: f64,
        /// Centre longitude.
        yaw: f64,
        /// Centre latitude.
        pitch: f64,
    },
    /// The horizontal extent is not in (0, 360].
    #[error("horizontal extent {0} is not in (0, 360] degrees")]
    Hfov(f64),
    /// The vertical extent is not in (0, 180].
    #[error("vertical extent {0} is not in (0, 180] degrees")]
    Vfov(f64),
    /// `pitch ± vfov/2` leaves [−90, 90].
    #[error(
        "{vfov} degrees high centred on pitch {pitch} reaches past a pole \
         (pitch ± vfov/2 must stay in [-90, 90])"
    )]
    PastPole {
        /// Vertical extent.
        vfov: f64,
        /// Centre latitude.
        pitch: f64,
    },
}

/// What is wrong with a coverage text (see [`CoverageError::Syntax`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SyntaxProblem {
    /// No `x` between the extents.
    #[error("no 'x' between the horizontal and vertical extent; {GRAMMAR}")]
    NoX,
    /// A part that is not a plain decimal number.
    #[error("{part} '{text}' is not a decimal number; {GRAMMAR}")]
    NotDecimal {
        /// Which part: "HFOV", "VFOV", "YAW" or "PITCH".
        part: &'static str,
        /// Its text.
        text: String,
    },
    /// YAW without PITCH (or the other way round).
    #[error("YAW and PITCH must both be given, each with a sign; {GRAMMAR}")]
    YawPitchPair,
    /// Well-formed, but the angles are out of range.
    #[error("{0}")]
    Angles(AngleProblem),
}

/// The grammar, for messages.
const GRAMMAR: &str = "expected HFOVxVFOV or HFOVxVFOV±YAW±PITCH, e.g. 120x60+30-10";

/// What is wrong with a crop (see [`CoverageError::Crop`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum CropProblem {
    /// A side below 2 pixels.
    #[error("every size must be at least 2 pixels")]
    TooSmall,
    /// A full-panorama side above the supported map side.
    #[error("full panorama sides above {max} are not supported")]
    FullSidesAbove {
        /// The largest side.
        max: u32,
    },
    /// The crop is wider than the full panorama.
    #[error("the crop is wider than the full panorama")]
    Wider,
    /// The crop runs below the full panorama.
    #[error("the crop runs below the full panorama")]
    Below,
}

/// Why a coverage, a crop or GPano metadata cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CoverageError {
    /// A coverage text that does not follow the grammar `HFOVxVFOV[±YAW±PITCH]`.
    #[error("coverage '{text}': {problem}")]
    Syntax {
        /// The text as given.
        text: String,
        /// What is wrong with it.
        problem: SyntaxProblem,
    },
    /// Coverage angles out of range.
    #[error("coverage: {0}")]
    Angles(AngleProblem),
    /// A coverage whose full panorama, for an image of this size, would be larger than
    /// the supported map.
    #[error(
        "coverage {coverage}: a {image_width}x{image_height} image covering it makes a \
         {full_width}x{full_height} full panorama; sides above {max} are not supported"
    )]
    FullTooLarge {
        /// The coverage, as text.
        coverage: String,
        /// Image width.
        image_width: u32,
        /// Image height.
        image_height: u32,
        /// Full panorama width it would need.
        full_width: f64,
        /// Full panorama height it would need.
        full_height: f64,
        /// The largest supported side.
        max: u32,
    },
    /// A crop that does not fit its full panorama.
    #[error("{what}: {problem}")]
    Crop {
        /// The crop (its numbers, or the coverage it was made for).
        what: String,
        /// What is wrong with it.
        problem: CropProblem,
    },
    /// A map whose stored size is not the crop's.
    #[error("crop {crop_width}x{crop_height} of a {full_width}x{full_height} panorama: the image is {width}x{height}")]
    StoredSize {
        /// Crop width.
        crop_width: u32,
        /// Crop height.
        crop_height: u32,
        /// Full panorama width.
        full_width: u32,
        /// Full panorama height.
        full_height: u32,
        /// The map's stored width.
        width: u32,
        /// The map's stored height.
        height: u32,
    },
    /// A coverage given for a projection other than equirectangular.
    #[error("{what}: a coverage applies to equirectangular panoramas only")]
    NotEquirect {
        /// The file.
        what: String,
    },
    /// GPano metadata that cannot be read.
    #[error("{0}")]
    Metadata(GPanoError),
    /// GPano metadata that does not place the image.
    #[error("GPano XMP: {0}")]
    GPanoCrop(GPanoError),
    /// One of the other errors, about a file.
    #[error("{what}: {error}")]
    InFile {
        /// The file.
        what: String,
        /// The error.
        error: Box<CoverageError>,
    },
    /// The image itself cannot be read or used.
    #[error(transparent)]
    Map(#[from] MapError),
}
