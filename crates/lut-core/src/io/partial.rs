//! Partial panoramas at load time: decide how an image is placed in its full panorama
//! (an explicit [`Coverage`], GPano XMP found in the file, or the whole sphere), decode
//! it, and crop it into place (`map/crop.rs`).

use crate::error::{CoverageError, MapError};
use crate::geom::coverage::Coverage;
use crate::geom::projection::Projection;
use crate::io::gpano::GPano;
use crate::io::load::{decode_map, load_map, LoadOptions, LoadProgress};
use crate::map::envmap::EnvMap;
use std::path::Path;

/// `error` about the file `what`.
fn in_file(what: &str, error: CoverageError) -> CoverageError {
    CoverageError::InFile {
        what: what.to_string(),
        error: Box::new(error),
    }
}

/// What a decoded panorama turned out to cover.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CoverageSource {
    /// The whole sphere (no metadata, or metadata describing the whole panorama).
    Full,
    /// GPano XMP metadata in the file.
    Xmp,
    /// An explicit [`Coverage`] given by the caller.
    Explicit,
}

/// Decode an image file's bytes as a possibly partial panorama, with the pixel limit,
/// projection and tone of `opts` and progress reports (see [`decode_map`]):
///
/// * `coverage` given: the image covers that area (equirectangular); any GPano metadata
///   is ignored.
/// * otherwise, for JPEGs with GPano XMP and an `auto` or equirectangular projection: the
///   metadata places the image in the full panorama and supplies the compass heading;
/// * otherwise: as [`decode_map`], a full panorama.
///
/// # Errors
/// [`CoverageError`] naming `what` for bad metadata or coverage (an explicit coverage
/// overrides bad metadata), or the image's [`MapError`].
pub fn decode_partial(
    bytes: &[u8],
    what: &str,
    opts: &LoadOptions,
    coverage: Option<Coverage>,
    progress: &mut dyn FnMut(LoadProgress),
) -> Result<(EnvMap, CoverageSource), CoverageError> {
    place_partial(bytes, what, opts, coverage, |o| {
        decode_map(bytes, what, o, progress)
    })
}

/// As [`decode_partial`], streamed from a file (see [`load_map`]): only the file's first
/// 256 KiB are read for the metadata (an XMP packet sits in an APP1 segment of at most
/// 64 KiB before the image data).
///
/// # Errors
/// As [`decode_partial`]; unreadable files are [`MapError::Decode`].
pub fn load_partial(
    path: &Path,
    opts: &LoadOptions,
    coverage: Option<Coverage>,
    progress: &mut dyn FnMut(LoadProgress),
) -> Result<(EnvMap, CoverageSource), CoverageError> {
    use std::io::Read;
    let what = path.display().to_string();
    let io_err = |e: std::io::Error| MapError::Decode {
        path: path.to_path_buf(),
        reason: e.to_string(),
    };
    let mut head = Vec::new();
    crate::file::open_regular(path)
        .map_err(io_err)?
        .take(256 * 1024)
        .read_to_end(&mut head)
        .map_err(io_err)?;
    place_partial(&head, &what, opts, coverage, |o| {
        load_map(path, o, progress)
    })
}

/// Decide how a panorama is placed (explicit coverage, GPano metadata found in `head`, or
/// full), decode it with `decode`, and crop it into place.
fn place_partial(
    head: &[u8],
    what: &str,
    opts: &LoadOptions,
    coverage: Option<Coverage>,
    decode: impl FnOnce(&LoadOptions) -> Result<EnvMap, MapError>,
) -> Result<(EnvMap, CoverageSource), CoverageError> {
    let projection = opts.projection;
    let equirect = matches!(projection, None | Some(Projection::Equirect));
    if coverage.is_some() && !equirect {
        return Err(CoverageError::NotEquirect {
            what: what.to_string(),
        });
    }
    let meta = if coverage.is_none() && equirect {
        crate::io::gpano::read_gpano(head).map_err(|e| in_file(what, CoverageError::Metadata(e)))?
    } else {
        None
    };
    let heading = meta.as_ref().and_then(|g| g.pose_heading_degrees);
    let start = meta.as_ref().and_then(GPano::start_view);
    let has_crop = coverage.is_some() || meta.as_ref().is_some_and(|g| g.has_crop());
    if !has_crop {
        let mut m = decode(opts)?;
        m.set_pose_heading_deg(heading);
        m.set_start_view(start);
        // A camera held tilted (GPano PosePitchDegrees/PoseRollDegrees): the map is
        // re-levelled once here (map/level.rs), so it opens level.
        let pose = meta.as_ref().map(|g| {
            (
                g.pose_pitch_degrees.unwrap_or(0.0),
                g.pose_roll_degrees.unwrap_or(0.0),
            )
        });
        if let Some((p, r)) = pose.filter(|&(p, r)| p != 0.0 || r != 0.0) {
            if let Some(level) = crate::map::level::level_horizon(&m, p, r) {
                m = level;
            }
        }
        return Ok((m, CoverageSource::Full));
    }
    // Decoded as "elliptical" only so that any aspect ratio is accepted and the padding
    // column repeats the last column (no wrap); `into_partial` makes it the crop of an
    // equirect (re-padded if the crop spans 360°).
    let mut m = decode(&LoadOptions {
        projection: Some(Projection::Elliptical),
        ..*opts
    })?;
    let (iw, ih) = (m.width(), m.height());
    let (crop, source) = match (coverage, &meta) {
        (Some(c), _) => (c.crop_for_image(iw, ih), CoverageSource::Explicit),
        (None, Some(g)) => (g.crop_for_image(iw, ih), CoverageSource::Xmp),
        // Not reached (`has_crop` needs one of them); the whole sphere is harmless.
        (None, None) => (Coverage::FULL.crop_for_image(iw, ih), CoverageSource::Full),
    };
    let crop = crop.map_err(|e| in_file(what, e))?;
    m.set_pose_heading_deg(heading);
    m.set_start_view(start);
    let m = m.into_partial(crop)?;
    let source = if m.crop().is_none() {
        CoverageSource::Full
    } else {
        source
    };
    Ok((m, source))
}
