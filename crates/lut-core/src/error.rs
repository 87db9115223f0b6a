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

/// An environment map that cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MapError {
    /// The file could not be read or decoded.
    #[error("{path}: cannot read image: {reason}")]
    Decode {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// The image is empty or larger than the supported limit.
    #[error("{what}: map size {width}x{height} is not supported: {reason}")]
    Size {
        /// The file or a description of the source.
        what: String,
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// Why.
        reason: String,
    },
    /// The image has more pixels than the configured limit (read from the file header,
    /// before any pixel buffer is allocated: a defence against decompression bombs).
    #[error(
        "{what}: the image is {width}x{height} = {pixels} pixels, above the limit of {limit} \
         pixels, so it was not decoded (a defence against decompression bombs); raise the \
         limit with --max-pixels"
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
    /// A non-2:1 image given (or detected) as equirectangular, or an unknown projection.
    #[error("{what}: {reason}")]
    Projection {
        /// The file or a description of the source.
        what: String,
        /// Why.
        reason: String,
    },
}
