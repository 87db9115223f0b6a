//! Command-line arguments the commands share, and the parsers of their values.
//!
//! * [`mod@named`]: the one clap value parser of every option enum (`lut_core::Named`).
//! * [`values`]: sizes "WxH", angles, stops.
//! * [`input`]: how a panorama is read (`--projection`, `--layout`, `--naming`, …).
//! * [`max_pixels`]: the pixel limit.

pub mod input;
pub mod max_pixels;
pub mod named;
pub mod values;

pub use input::{CubeArgs, InputArgs, ProjectionArg, ProjectionOpt};
pub use max_pixels::MaxPixelsArg;
pub use named::{named, named_or_parse};
pub use values::{parse_angle, parse_map_size, parse_size, parse_stops};
