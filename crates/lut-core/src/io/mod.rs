//! Input at the edge: image files and bytes into maps (with the pixel limit checked from
//! the header, progress reports, HDR tone mapping), partial panoramas placed by GPano XMP
//! or an explicit coverage, and cube maps from face files or layout images. Depends on
//! everything below it; nothing in the crate depends on it.

pub(crate) mod cube;
pub(crate) mod exr;
pub(crate) mod gpano;
pub(crate) mod load;
pub(crate) mod partial;
