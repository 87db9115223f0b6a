//! Writing a [`Tour`] as a Pannellum tour config (the reading is in the parent module).

use crate::tour::{Hotspot, HotspotKind, Source, TargetAngle, Tour};
use serde_json::{json, Map, Value};
use std::path::Path;

/// The tour as the text of a Pannellum tour config (a single-scene tour too: Pannellum
/// opens both), scenes in the tour's order. A Marzipano tile scene is written as a
/// multires scene reading its tiles unchanged when its levels fit Pannellum's multires
/// ([`marzipano_multires`]); one that does not fit is left out and named with the reason
/// in the second value (`id: why`), and the links to it with it.
pub fn to_text(tour: &Tour) -> (String, Vec<String>) {
    let (default, scenes, left_out) = parts(tour);
    let indent = |v: &Value, by: &str| {
        serde_json::to_string_pretty(v)
            .unwrap_or_default()
            .replace('\n', &format!("\n{by}"))
    };
    let mut t = String::from("{\n");
    for (k, v) in &tour.root_extra {
        if k != "default" && k != "scenes" {
            let key = serde_json::to_string(k).unwrap_or_default();
            t += &format!("  {key}: {},\n", indent(v, "  "));
        }
    }
    t += &format!(
        "  \"default\": {},\n  \"scenes\": {{",
        indent(&default, "  ")
    );
    for (i, (id, v)) in scenes.iter().enumerate() {
        let key = serde_json::to_string(id).unwrap_or_default();
        t += if i == 0 { "\n" } else { ",\n" };
        t += &format!("    {key}: {}", indent(v, "    "));
    }
    t += if scenes.is_empty() {
        "}\n}\n"
    } else {
        "\n  }\n}\n"
    };
    (t, left_out)
}

type Parts = (Value, Vec<(String, Value)>, Vec<String>);

fn parts(tour: &Tour) -> Parts {
    let mut left_out = Vec::new();
    let mut default = Map::new();
    // The first scene as saved: the tour's, unless it is left out (Marzipano tiles), then
    // the first scene that is saved (a config must not start in a scene it lacks).
    let saved = |s: &&crate::tour::TourScene| match &s.source {
        Source::MarzipanoTiles { dir, levels, .. } => marzipano_multires(dir, levels).is_ok(),
        _ => true,
    };
    let unsaved: Vec<String> = tour
        .scenes
        .iter()
        .filter(|s| !saved(s))
        .map(|s| s.id.clone())
        .collect();
    let first = tour
        .first()
        .filter(saved)
        .or_else(|| tour.scenes.iter().find(saved));
    default.insert(
        "firstScene".into(),
        json!(first.map_or("", |s| s.id.as_str())),
    );
    if let Some(f) = tour.fade_ms {
        default.insert("sceneFadeDuration".into(), json!(f));
    }
    if let Some(t) = &tour.title {
        if !tour.single {
            default.insert("title".into(), json!(t));
        }
    }
    for (k, v) in &tour.default_extra {
        default.entry(k.clone()).or_insert_with(|| v.clone());
    }
    let mut scenes = Vec::new();
    for s in &tour.scenes {
        let mut o = Map::new();
        if let Some(t) = &s.title {
            o.insert("title".into(), json!(t));
        }
        match &s.source {
            Source::Equirect(p) => {
                o.insert("type".into(), json!("equirectangular"));
                o.insert("panorama".into(), json!(p));
            }
            Source::Cube(faces) => {
                o.insert("type".into(), json!("cubemap"));
                o.insert("cubeMap".into(), json!(faces));
            }
            Source::Multires(m) => {
                o.insert("type".into(), json!("multires"));
                o.insert("multiRes".into(), m.clone());
            }
            Source::MarzipanoTiles { dir, levels, .. } => match marzipano_multires(dir, levels) {
                Ok(m) => {
                    o.insert("type".into(), json!("multires"));
                    o.insert("multiRes".into(), m);
                }
                Err(why) => {
                    left_out.push(format!("{}: {why}", s.id));
                    continue;
                }
            },
        }
        o.insert("yaw".into(), json!(s.start.yaw));
        o.insert("pitch".into(), json!(s.start.pitch));
        o.insert("hfov".into(), json!(s.start.hfov));
        if s.north_offset != 0.0 {
            o.insert("northOffset".into(), json!(s.north_offset));
        }
        if s.horizon.pitch != 0.0 {
            o.insert("horizonPitch".into(), json!(s.horizon.pitch));
        }
        if s.horizon.roll != 0.0 {
            o.insert("horizonRoll".into(), json!(s.horizon.roll));
        }
        // Links to a scene left out would go nowhere: left out with it.
        let hs: Vec<Value> = s
            .hotspots
            .iter()
            .filter(|h| match &h.kind {
                HotspotKind::Scene { scene_id, .. } => !unsaved.contains(scene_id),
                HotspotKind::Info { .. } => true,
            })
            .map(hotspot_json)
            .collect();
        o.insert("hotSpots".into(), Value::Array(hs));
        for (k, v) in &s.extra {
            o.entry(k.clone()).or_insert_with(|| v.clone());
        }
        scenes.push((s.id.clone(), Value::Object(o)));
    }
    (Value::Object(default), scenes, left_out)
}

/// A Marzipano scene (tiles in `dir`, `tiles/<id>/{z}/{f}/{y}/{x}.jpg`; `levels` as
/// its `data.js` lists them: tileSize, size, fallbackOnly) as Pannellum's `multiRes`
/// block reading the same tiles: `basePath` the tile folder, `path` `/%l/%s/%y/%x` or
/// `/%l0/%s/%y/%x`, `extension` `jpg`, `tileResolution`, `maxLevel`, `cubeResolution`.
///
/// Pannellum's levels are 1..=maxLevel, each twice the one below, of one tile size,
/// level 1 one tile a face; its path names a level as `%l` (from 1) or `%l0` (from 0).
/// Marzipano's `z` is the level's index in size order, from 0. So the levels fit when,
/// sorted by size, the first drawn one (not `fallbackOnly`) is `z` 0 (then `%l0`) or 1
/// (after a `fallbackOnly` preview level, Marzipano's usual export: then `%l`), every level
/// from it has the same tile size, doubles the one before and is drawn, and it is one
/// tile a face. Face letters and their orientation are the same in both (docs/huge.md,
/// "Marzipano's tile layout"; tests/tours.rs renders a scene through both).
///
/// # Errors
/// Why the levels do not fit (one line).
pub fn marzipano_multires(dir: &str, levels: &[(u32, u32, bool)]) -> Result<Value, String> {
    let mut ls = levels.to_vec();
    // Marzipano's makeLevelList: sorted by size (stable); `z` the sorted index.
    ls.sort_by_key(|l| l.1);
    let k = ls
        .iter()
        .position(|l| !l.2)
        .ok_or("every level is fallbackOnly")?;
    if k > 1 {
        return Err(format!(
            "its first drawn level is z={k} (after {k} fallbackOnly levels), and a Pannellum \
             path numbers levels from 1 (%l) or 0 (%l0) only"
        ));
    }
    let used = &ls[k..];
    let tile = used[0].0;
    if let Some(l) = used.iter().find(|l| l.2) {
        return Err(format!(
            "its level of {} px is fallbackOnly above a drawn level: Pannellum draws every level",
            l.1
        ));
    }
    if let Some(l) = used.iter().find(|l| l.0 != tile) {
        return Err(format!(
            "its levels have tiles of {tile} and {} px: Pannellum's multires has one tileResolution",
            l.0
        ));
    }
    if let Some(w) = used.windows(2).find(|w| w[1].1 != 2 * w[0].1) {
        return Err(format!(
            "its level of {} px follows one of {} px: Pannellum's levels double",
            w[1].1, w[0].1
        ));
    }
    if used[0].1 > tile {
        return Err(format!(
            "its smallest drawn level ({} px) is more than one tile of {tile}: Pannellum's level 1 is one tile a face",
            used[0].1
        ));
    }
    let path = if k == 1 {
        "/%l/%s/%y/%x"
    } else {
        "/%l0/%s/%y/%x"
    };
    Ok(json!({
        "basePath": dir,
        "path": path,
        "extension": "jpg",
        "tileResolution": tile,
        "maxLevel": used.len(),
        "cubeResolution": used[used.len() - 1].1,
    }))
}

fn hotspot_json(h: &Hotspot) -> Value {
    let mut o = Map::new();
    o.insert("pitch".into(), json!(h.pitch));
    o.insert("yaw".into(), json!(h.yaw));
    match &h.kind {
        HotspotKind::Scene { scene_id, target } => {
            o.insert("type".into(), json!("scene"));
            o.insert("text".into(), json!(h.text));
            o.insert("sceneId".into(), json!(scene_id));
            let put = |o: &mut Map<String, Value>, k: &str, t: TargetAngle| match t {
                TargetAngle::Scene => {}
                TargetAngle::Value(v) => {
                    o.insert(k.into(), json!(v));
                }
                TargetAngle::Same => {
                    o.insert(k.into(), json!("same"));
                }
                TargetAngle::SameAzimuth => {
                    o.insert(k.into(), json!("sameAzimuth"));
                }
            };
            put(&mut o, "targetYaw", target.yaw);
            put(&mut o, "targetPitch", target.pitch);
            put(&mut o, "targetHfov", target.hfov);
        }
        HotspotKind::Info { url } => {
            o.insert("type".into(), json!("info"));
            o.insert("text".into(), json!(h.text));
            if let Some(u) = url {
                o.insert("URL".into(), json!(u));
            }
        }
    }
    for (k, v) in &h.extra {
        o.entry(k.clone()).or_insert_with(|| v.clone());
    }
    Value::Object(o)
}

/// Write the tour to `path` as a Pannellum config through the one output writer
/// ([`crate::output::write_image_atomic`]: a temporary file in the same folder, renamed,
/// removed on an error or a signal; an ordinary file's permissions). Returns the ids of
/// scenes that have no Pannellum form (left out).
///
/// # Errors
/// The file cannot be written.
pub fn save(tour: &Tour, path: &Path) -> anyhow::Result<Vec<String>> {
    let (text, left_out) = to_text(tour);
    crate::output::write_image_atomic(path, |w| Ok(w.write_all(text.as_bytes())?))?;
    Ok(left_out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marzipano_levels_that_fit_pannellums_multires_and_those_that_do_not() {
        // The tool's usual export: a fallbackOnly preview level, then doubling levels of
        // one tile size from one tile a face: Pannellum's %l is Marzipano's z.
        let m = marzipano_multires(
            "tiles/0-a",
            &[
                (512, 2048, false),
                (256, 256, true),
                (512, 512, false),
                (512, 1024, false),
            ],
        )
        .unwrap();
        assert_eq!(
            m,
            json!({"basePath": "tiles/0-a", "path": "/%l/%s/%y/%x", "extension": "jpg",
                   "tileResolution": 512, "maxLevel": 3, "cubeResolution": 2048})
        );
        // Without the preview level, z counts from the first drawn level: %l0.
        let m = marzipano_multires("tiles/1-b", &[(32, 32, false), (32, 64, false)]).unwrap();
        assert_eq!(m["path"], "/%l0/%s/%y/%x");
        assert_eq!(
            (m["maxLevel"].as_u64(), m["cubeResolution"].as_u64()),
            (Some(2), Some(64))
        );
        type Levels<'a> = &'a [(u32, u32, bool)];
        let bad: &[(Levels, &str)] = &[
            (
                &[(16, 16, true), (16, 32, false), (48, 96, false)],
                "tiles of 16 and 48 px",
            ),
            (&[(64, 64, false), (64, 192, false)], "follows one of 64 px"),
            (&[(16, 16, true), (32, 32, true), (64, 64, false)], "z=2"),
            (&[(64, 64, true)], "every level is fallbackOnly"),
            (&[(64, 128, false), (64, 256, false)], "more than one tile"),
            (&[(64, 64, false), (64, 128, true)], "fallbackOnly above"),
        ];
        for (levels, why) in bad {
            let e = marzipano_multires("tiles/x", levels).unwrap_err();
            assert!(e.contains(why) && !e.contains('\n'), "{levels:?}: {e}");
        }
    }
}
