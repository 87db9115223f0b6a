//! Geometry: map projections, output (view) projections, the camera, Q.16 fixed point, coverage and crops, the view
//! limit, the exact mapping from an output pixel to map coordinates, and the error metric.
//! Depends on nothing else in the crate (but the error types).

pub(crate) mod accuracy;
pub(crate) mod camera;
pub(crate) mod coverage;
pub(crate) mod fixed;
pub(crate) mod limits;
pub(crate) mod mapping;
pub(crate) mod projection;
pub(crate) mod view_projection;
pub(crate) mod viewlimit;
