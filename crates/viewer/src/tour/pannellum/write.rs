//! Writing a [`Tour`] as a Pannellum tour config (the reading is in the parent module).

use crate::tour::{Hotspot, HotspotKind, Source, TargetAngle, Tour};
use serde_json::{json, Map, Value};
use std::path::Path;

/// The tour as the text of a Pannellum tour config (a single-scene tour too: Pannellum
/// opens both), scenes in the tour's order. Marzipano tile scenes have no Pannellum form:
/// they are left out and named in the second value.
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
    let saved = |s: &&crate::tour::TourScene| !matches!(s.source, Source::MarzipanoTiles { .. });
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
            Source::MarzipanoTiles { .. } => {
                left_out.push(s.id.clone());
                continue;
            }
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
        let hs: Vec<Value> = s.hotspots.iter().map(hotspot_json).collect();
        o.insert("hotSpots".into(), Value::Array(hs));
        for (k, v) in &s.extra {
            o.entry(k.clone()).or_insert_with(|| v.clone());
        }
        scenes.push((s.id.clone(), Value::Object(o)));
    }
    (Value::Object(default), scenes, left_out)
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
