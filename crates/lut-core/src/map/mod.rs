//! Maps: [`EnvMap`] (pixels and projection, no files), partial maps and the cropped
//! samplers, the per-pixel samplers, the minification pyramid, HDR tone mapping and the
//! synthetic grid maps. Depends on `geom` only.

pub(crate) mod crop;
pub(crate) mod envmap;
pub(crate) mod level;
pub(crate) mod pyramid;
pub(crate) mod sample;
pub(crate) mod synth;
pub(crate) mod tone;

#[cfg(doc)]
use envmap::EnvMap;
