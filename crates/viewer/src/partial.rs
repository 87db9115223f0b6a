//! Partial panoramas in the viewer: `--coverage`, loading with GPano XMP, and the texts
//! the panel and `viewer render -v` show (coverage, compass heading).

use anyhow::Result;
use lut_core::{compass_heading, compass_point};
use lut_core::{Coverage, CoverageSource, EnvMap, LoadOptions};
use std::path::Path;

/// Parse `--coverage HFOVxVFOV[±YAW±PITCH]` (see `lut_core::Coverage`).
pub fn parse_coverage(s: &str) -> Result<Coverage, String> {
    s.parse::<Coverage>().map_err(|e| e.to_string())
}

/// Turn a placement error into one line that says how to override bad metadata (or, for
/// an image that cannot be read, the hint of [`crate::cli_common::map_error`]).
pub fn coverage_error(e: lut_core::CoverageError, coverage: Option<Coverage>) -> anyhow::Error {
    if let lut_core::CoverageError::Map(m) = e {
        return crate::cli_common::map_error(m);
    }
    let hint = match (&e, coverage) {
        (lut_core::CoverageError::Syntax { .. }, _) | (_, Some(_)) => "",
        // Bad metadata or a placement that does not fit, and no coverage given.
        (_, None) => {
            " (give --coverage HFOVxVFOV±YAW±PITCH to place the image yourself, e.g. \
             --coverage 360x180 to show it as a full panorama)"
        }
    };
    anyhow::anyhow!("{e}{hint}")
}

/// Load a panorama (`None`: the bundled sample) with the pixel limit, projection and tone
/// of `opts`, placed by `coverage` when given, else by the GPano XMP in the file (JPEG),
/// else as a full panorama; `progress` as in `lut_core::load_map`. Bad metadata is an
/// error that says how to override it.
pub fn load_panorama_partial(
    path: Option<&Path>,
    opts: &LoadOptions,
    coverage: Option<Coverage>,
    progress: &mut dyn FnMut(lut_core::LoadProgress),
) -> Result<(EnvMap, CoverageSource)> {
    match path {
        Some(p) => lut_core::load_partial(p, opts, coverage, progress),
        None => lut_core::decode_partial(
            crate::assets::SAMPLE_JPEG,
            crate::assets::SAMPLE_NAME,
            opts,
            coverage,
            progress,
        ),
    }
    .map_err(|e| coverage_error(e, coverage))
}

/// "covers 120°×60° around yaw 30°, pitch −10° (stored 2000×1000 of 6000×3000)" for a
/// partial map, `None` for a full one.
pub fn coverage_text(map: &EnvMap) -> Option<String> {
    let crop = map.crop()?;
    let c = crop.coverage();
    Some(format!(
        "covers {:.1}°×{:.1}° around yaw {:.1}°, pitch {:.1}° (stored {}×{} of {}×{})",
        c.hfov(),
        c.vfov(),
        c.yaw(),
        c.pitch(),
        crop.width(),
        crop.height(),
        crop.full_width(),
        crop.full_height()
    ))
}

/// "heading 213° (SW)" for the view centre, when the map knows its heading.
pub fn heading_text(map: &EnvMap, yaw: f64) -> Option<String> {
    let h = compass_heading(map.pose_heading_deg()?, yaw);
    Some(format!("heading {h:.0}° ({})", compass_point(h)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coverage_flag_errors_name_the_text() {
        assert!(parse_coverage("120x60+30-10").is_ok());
        let e = parse_coverage("120x60+30").unwrap_err();
        assert!(e.contains("120x60+30"), "{e}");
    }
}
