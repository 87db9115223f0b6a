//! `viewer render --tour T.json --scene ID`: a tour scene's panorama at its start view
//! and horizon, with its hotspot markers; and the horizon levelling `render` applies.

use super::{Source, TourScene};
use crate::commands::render::RenderArgs;
use crate::usage;
use anyhow::{anyhow, Result};
use lut_core::EnvMap;
use std::path::Path;

/// `map` re-levelled by the horizon pitch and roll given (none or zero: unchanged).
///
/// # Errors
/// A partial or non-equirectangular map with a horizon to level (usage: exit 2).
pub fn level(map: EnvMap, pitch: Option<f64>, roll: Option<f64>) -> Result<EnvMap> {
    let (p, r) = (pitch.unwrap_or(0.0), roll.unwrap_or(0.0));
    if p == 0.0 && r == 0.0 {
        return Ok(map);
    }
    lut_core::level_horizon(&map, p, r).ok_or_else(|| {
        usage!(
            "--horizon-pitch and --horizon-roll apply to full equirectangular panoramas, not {}",
            if map.crop().is_some() {
                "partial ones".to_string()
            } else {
                format!("{} maps", map.projection())
            }
        )
    })
}

/// Set `a` up to render the tour scene `--scene` names (its panorama, start view for the
/// angles not given, horizon unless given), and return the scene (for its markers). The
/// tour's problems are printed on stderr; the scene must open.
///
/// # Errors
/// The tour does not open, the scene is not in it, or its panorama cannot be found (a
/// multires scene whose basePath holds no tiled pyramid), or --tour with --panorama files.
pub fn prepare(a: &mut RenderArgs, tour: &Path) -> Result<TourScene> {
    if !a.panorama.is_empty() {
        return Err(usage!(
            "--tour renders a scene of the tour: give no panorama files"
        ));
    }
    let loaded = super::load(tour)?;
    for p in &loaded.problems {
        crate::errln!("{p}");
    }
    let t = loaded.tour;
    let id = match a.lights.room.scene.take() {
        Some(p) => p.to_string_lossy().into_owned(),
        None => t.first().map(|s| s.id.clone()).unwrap_or_default(),
    };
    let Some(scene) = t.scene(&id) else {
        let ids: Vec<_> = t.scenes.iter().map(|s| s.id.as_str()).collect();
        return Err(anyhow!(
            "{}: no scene \"{id}\" opens in the tour (scenes: {})",
            tour.display(),
            ids.join(", ")
        ));
    };
    let files = |rel: &str| {
        t.resolve(rel)
            .map_err(|why| anyhow!("{}: scene \"{id}\": {why}", tour.display()))
    };
    match &scene.source {
        Source::Equirect(p) => a.panorama = vec![files(p)?],
        Source::Cube(faces) => {
            let mut list = Vec::new();
            for f in faces {
                let Some(f) = f else {
                    return Err(anyhow!(
                        "{}: scene \"{id}\": a cube face is missing (null): render needs all six",
                        tour.display()
                    ));
                };
                list.push(files(f)?);
            }
            a.panorama = list;
        }
        Source::MarzipanoTiles { dir, .. } => {
            // Opened as a tiled pyramid through the data.js beside tiles/.
            let d = files(dir)?;
            if crate::panorama::marzipano_data_js(&d).is_none() {
                return Err(anyhow!(
                    "{}: scene \"{id}\": its tiles open from a Marzipano export's data.js beside tiles/<id> ({} is not such a folder)",
                    tour.display(),
                    d.display()
                ));
            }
            a.panorama = vec![d];
        }
        Source::Multires(m) => {
            // Opened as the tiled pyramid in its basePath (the window's rule).
            let d = t
                .multires_dir(&id, m)
                .map_err(|why| anyhow!("{}: {why}", tour.display()))?;
            a.panorama = vec![d];
        }
    }
    a.yaw = a.yaw.or(Some(scene.start.yaw));
    a.pitch = a.pitch.or(Some(scene.start.pitch));
    a.hfov = a.hfov.or(Some(scene.start.hfov));
    a.horizon_pitch = a.horizon_pitch.or(Some(scene.horizon.pitch));
    a.horizon_roll = a.horizon_roll.or(Some(scene.horizon.roll));
    Ok(scene.clone())
}
