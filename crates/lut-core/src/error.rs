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
    /// hfov is outside the open interval (0, 180).
    #[error("hfov must be in the open interval (0, 180) degrees, got {0}")]
    HfovOutOfRange(f64),
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

/// Why a coverage, a crop or GPano metadata cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CoverageError {
    /// A coverage text that does not follow the grammar `HFOVxVFOV[±YAW±PITCH]`.
    #[error("coverage '{text}': {reason}")]
    Syntax {
        /// The text as given.
        text: String,
        /// What is wrong with it.
        reason: String,
    },
    /// Metadata or a coverage that does not describe a usable part of a panorama.
    #[error("{what}: {reason}")]
    Invalid {
        /// The file, metadata field or value concerned.
        what: String,
        /// Why.
        reason: String,
    },
    /// The image itself cannot be read or used.
    #[error(transparent)]
    Map(#[from] MapError),
}
