//! Pannellum configs (doc/json-config-parameters.md of mpetroff/pannellum): a tour
//! (`default` with `firstScene`, `scenes` by id) or a single-scene config; read into a
//! [`Tour`], written back as a tour config Pannellum opens.
//!
//! As Pannellum does, `default`'s members apply to every scene that does not set them
//! (its start view, `northOffset`, `horizonPitch`/`horizonRoll`, `type`, `basePath`).
//! Members this viewer does not use (`author`, `autoLoad`, a hotspot's `cssClass`, ...)
//! are kept and written back.

use super::literal::{self, Lit, LitKind};
use super::{
    num_text, path_problem, Angles, Horizon, Hotspot, HotspotKind, Loaded, Problem, Source, Target,
    TargetAngle, Tour, TourScene, DEFAULT_START, MAX_HOTSPOTS, MAX_SCENES,
};
use serde_json::{Map, Value};
use std::path::Path;

mod write;
pub use write::{marzipano_multires, save, to_text};

/// Members of a scene this module interprets (the rest are kept in `extra`).
const SCENE_KEYS: [&str; 14] = [
    "title",
    "type",
    "panorama",
    "cubeMap",
    "multiRes",
    "basePath",
    "yaw",
    "pitch",
    "hfov",
    "northOffset",
    "horizonPitch",
    "horizonRoll",
    "hotSpots",
    "firstScene",
];

/// Members of a hotspot this module interprets.
const HOTSPOT_KEYS: [&str; 9] = [
    "pitch",
    "yaw",
    "type",
    "text",
    "URL",
    "sceneId",
    "targetYaw",
    "targetPitch",
    "targetHfov",
];

/// Collects problems of one file.
pub(crate) struct Report<'a> {
    pub(crate) file: &'a Path,
    pub(crate) problems: Vec<Problem>,
}

impl Report<'_> {
    pub(crate) fn add(&mut self, line: usize, place: &str, message: impl Into<String>) {
        self.problems.push(Problem {
            file: self.file.to_path_buf(),
            line,
            place: place.to_string(),
            message: message.into(),
        });
    }
}

/// Read a Pannellum config (`text`, from `file`, paths relative to `dir`).
///
/// # Errors
/// A syntax error, or a root that is not an object: nothing opens.
pub fn read(text: &str, file: &Path, dir: &Path) -> anyhow::Result<Loaded> {
    let root = literal::parse(text)
        .map_err(|e| anyhow::anyhow!("{}:{}: {}", file.display(), e.line, e.message))?;
    let LitKind::Obj(members) = &root.kind else {
        anyhow::bail!(
            "{}:{}: the config is {}, not an object: not a Pannellum config",
            file.display(),
            root.line,
            root.what()
        );
    };
    let mut r = Report {
        file,
        problems: Vec::new(),
    };
    let mut tour = Tour::new(dir.to_path_buf());
    let default = root.get("default");
    if let Some(d) = default {
        if !matches!(d.kind, LitKind::Obj(_)) {
            r.add(
                d.line,
                "default",
                format!("is {}, not an object: ignored", d.what()),
            );
        }
    }
    let default = default.filter(|d| matches!(d.kind, LitKind::Obj(_)));
    match root.get("scenes") {
        Some(scenes) => {
            // Members of the root other than default and scenes: Pannellum merges them
            // over every scene; kept at the root, as they were.
            for (k, v) in members {
                if k != "default" && k != "scenes" {
                    tour.root_extra.insert(k.clone(), v.to_json());
                }
            }
            if let Some(LitKind::Obj(dm)) = default.map(|d| &d.kind) {
                for (k, v) in dm {
                    match k.as_str() {
                        "firstScene" | "sceneFadeDuration" => {}
                        k2 if SCENE_KEYS.contains(&k2) => {}
                        _ => {
                            tour.default_extra.insert(k.clone(), v.to_json());
                        }
                    }
                }
            }
            if let Some(t) = default.and_then(|d| d.get("title")).and_then(Lit::as_str) {
                tour.title = Some(t.to_string());
            }
            tour.fade_ms = default
                .and_then(|d| d.get("sceneFadeDuration"))
                .and_then(|v| number(&mut r, v, "default.sceneFadeDuration", 0.0, 60_000.0));
            let LitKind::Obj(list) = &scenes.kind else {
                anyhow::bail!(
                    "{}:{}: scenes: is {}, not an object of scenes by id",
                    file.display(),
                    scenes.line,
                    scenes.what()
                );
            };
            for (n, (id, s)) in list.iter().enumerate() {
                let place = format!("scenes.{id}");
                if n >= MAX_SCENES {
                    r.add(
                        s.line,
                        &place,
                        format!("more than {MAX_SCENES} scenes: the rest are left out"),
                    );
                    break;
                }
                if let Some(prev) = tour.index(id) {
                    r.add(
                        s.line,
                        &place,
                        "the scene id is repeated: the last one is used (as in Pannellum)",
                    );
                    tour.scenes.remove(prev);
                }
                if let Some(scene) = read_scene(&mut r, s, default, id, &place) {
                    tour.scenes.push(scene);
                }
            }
            match default.and_then(|d| d.get("firstScene")) {
                Some(f) => {
                    match f.as_str() {
                        Some(id) if tour.scene(id).is_some() => tour.first_scene = id.to_string(),
                        Some(id) => {
                            r.add(f.line, "default.firstScene", format!("scene \"{id}\" is not in the tour: starting in the first scene"));
                            tour.first_scene = id.to_string();
                        }
                        None => r.add(
                            f.line,
                            "default.firstScene",
                            format!("is {}, not a scene id", f.what()),
                        ),
                    }
                }
                None => r.add(
                    root.line,
                    "default.firstScene",
                    "missing: starting in the first scene",
                ),
            }
            if tour.first_scene.is_empty() || tour.scene(&tour.first_scene).is_none() {
                // Saved with the scene it really starts in.
                if let Some(s) = tour.scenes.first() {
                    tour.first_scene = s.id.clone();
                }
            }
        }
        None => {
            // A single-scene config: the root is the scene.
            let id = file
                .file_stem()
                .and_then(|s| s.to_str())
                .filter(|s| !s.is_empty())
                .unwrap_or("scene")
                .to_string();
            tour.single = true;
            if let Some(scene) = read_scene(&mut r, &root, None, &id, "") {
                tour.title = scene.title.clone();
                tour.first_scene = id;
                tour.scenes.push(scene);
            }
        }
    }
    if tour.scenes.is_empty() {
        r.add(0, "", "no scene of the tour opens");
    }
    // Links to scenes that are not in the tour.
    for s in &tour.scenes {
        for h in &s.hotspots {
            if let HotspotKind::Scene { scene_id, .. } = &h.kind {
                if tour.scene(scene_id).is_none() {
                    r.add(
                        h.line,
                        &join(&h.place, "sceneId"),
                        format!("links to scene \"{scene_id}\", which is not in the tour"),
                    );
                }
            }
        }
    }
    Ok(Loaded {
        tour,
        problems: r.problems,
    })
}

fn join(place: &str, key: &str) -> String {
    if place.is_empty() {
        key.to_string()
    } else {
        format!("{place}.{key}")
    }
}

/// A number member in `[lo, hi]`; a problem (and `None`) otherwise.
fn number(r: &mut Report, v: &Lit, place: &str, lo: f64, hi: f64) -> Option<f64> {
    match v.as_f64() {
        Some(x) if (lo..=hi).contains(&x) => Some(x),
        Some(x) => {
            r.add(
                v.line,
                place,
                format!("{} is not in [{lo}, {hi}]: ignored", num_text(x)),
            );
            None
        }
        None => {
            r.add(
                v.line,
                place,
                format!("is {}, not a number: ignored", v.what()),
            );
            None
        }
    }
}

/// Angles that wrap may take any value, but not absurd ones.
const MAX_TURN: f64 = 36_000.0;

/// A member of the scene or, when the scene does not set it, of `default`.
fn member<'a>(s: &'a Lit, default: Option<&'a Lit>, key: &str) -> Option<(&'a Lit, bool)> {
    s.get(key)
        .map(|v| (v, false))
        .or_else(|| default.and_then(|d| d.get(key)).map(|v| (v, true)))
}

fn read_scene(
    r: &mut Report,
    s: &Lit,
    default: Option<&Lit>,
    id: &str,
    place: &str,
) -> Option<TourScene> {
    let LitKind::Obj(members) = &s.kind else {
        r.add(
            s.line,
            place,
            format!("is {}, not a scene object: left out", s.what()),
        );
        return None;
    };
    let at = |key: &str| join(place, key);
    // The scene's value, else (missing or bad) default's.
    let num = |r: &mut Report, key: &str, lo: f64, hi: f64| -> Option<f64> {
        let own = s.get(key).and_then(|v| number(r, v, &at(key), lo, hi));
        own.or_else(|| {
            let v = default?.get(key)?;
            number(r, v, &format!("default.{key}"), lo, hi)
        })
    };
    let text = |r: &mut Report, key: &str| -> Option<String> {
        let (v, from_default) = member(s, default, key)?;
        match v.as_str() {
            Some(t) => Some(t.to_string()),
            None => {
                let p = if from_default {
                    format!("default.{key}")
                } else {
                    at(key)
                };
                r.add(
                    v.line,
                    &p,
                    format!("is {}, not a string: ignored", v.what()),
                );
                None
            }
        }
    };
    let base = text(r, "basePath").unwrap_or_default();
    let with_base = |p: &str| -> String {
        if base.is_empty() {
            p.to_string()
        } else {
            format!(
                "{}/{}",
                base.trim_end_matches('/'),
                p.trim_start_matches("./")
            )
        }
    };
    let kind = text(r, "type").unwrap_or_else(|| "equirectangular".into());
    let source_line = ["panorama", "cubeMap", "multiRes"]
        .iter()
        .find_map(|k| s.get(k))
        .map_or(s.line, |v| v.line);
    let source = match kind.as_str() {
        "equirectangular" => {
            let Some(p) = s.get("panorama") else {
                r.add(
                    s.line,
                    &at("panorama"),
                    "missing (an equirectangular scene needs its image): scene left out",
                );
                return None;
            };
            let Some(p) = p.as_str() else {
                r.add(
                    p.line,
                    &at("panorama"),
                    format!("is {}, not a path: scene left out", p.what()),
                );
                return None;
            };
            let full = with_base(p);
            if let Some(why) = path_problem(&full) {
                r.add(
                    s.get("panorama").map_or(s.line, |v| v.line),
                    &at("panorama"),
                    format!("{why}: scene left out"),
                );
                return None;
            }
            Source::Equirect(full)
        }
        "cubemap" => {
            let Some(c) = s.get("cubeMap") else {
                r.add(
                    s.line,
                    &at("cubeMap"),
                    "missing (a cubemap scene needs six faces): scene left out",
                );
                return None;
            };
            let faces = match &c.kind {
                LitKind::Arr(a) if a.len() == 6 => a,
                _ => {
                    r.add(c.line, &at("cubeMap"), "is not an array of six faces (front, right, back, left, up, down): scene left out");
                    return None;
                }
            };
            let mut out = Vec::with_capacity(6);
            for (i, f) in faces.iter().enumerate() {
                match &f.kind {
                    LitKind::Null => out.push(None),
                    LitKind::Str(p) => {
                        let full = with_base(p);
                        if let Some(why) = path_problem(&full) {
                            r.add(
                                f.line,
                                &format!("{}[{i}]", at("cubeMap")),
                                format!("{why}: scene left out"),
                            );
                            return None;
                        }
                        out.push(Some(full));
                    }
                    _ => {
                        r.add(
                            f.line,
                            &format!("{}[{i}]", at("cubeMap")),
                            format!("is {}, not a path or null: scene left out", f.what()),
                        );
                        return None;
                    }
                }
            }
            Source::Cube(out)
        }
        "multires" => {
            let Some(m) = s
                .get("multiRes")
                .filter(|m| matches!(m.kind, LitKind::Obj(_)))
            else {
                r.add(
                    s.line,
                    &at("multiRes"),
                    "missing or not an object (a multires scene needs it): scene left out",
                );
                return None;
            };
            let mut j = m.to_json();
            if !base.is_empty() {
                // Kept explicit so the scene saves the same without the default.
                let mb = j.get("basePath").and_then(Value::as_str).unwrap_or("");
                j["basePath"] = Value::String(with_base(mb));
            }
            if let Some(bp) = j.get("basePath").and_then(Value::as_str) {
                if let Some(why) =
                    path_problem(bp.trim_start_matches("./")).filter(|_| bp != "." && bp != "./")
                {
                    r.add(
                        m.line,
                        &join(&at("multiRes"), "basePath"),
                        format!("{why}: scene left out"),
                    );
                    return None;
                }
            }
            Source::Multires(j)
        }
        other => {
            let line = member(s, default, "type").map_or(s.line, |(v, _)| v.line);
            r.add(line, &at("type"), format!("unknown type \"{other}\" (equirectangular, cubemap or multires): scene left out"));
            return None;
        }
    };
    let start = Angles {
        yaw: num(r, "yaw", -MAX_TURN, MAX_TURN).map_or(DEFAULT_START.yaw, wrap180),
        pitch: num(r, "pitch", -90.0, 90.0).unwrap_or(DEFAULT_START.pitch),
        hfov: num(r, "hfov", 1e-3, 179.0).unwrap_or(DEFAULT_START.hfov),
    };
    let north_offset = num(r, "northOffset", -MAX_TURN, MAX_TURN).unwrap_or(0.0);
    let horizon = Horizon {
        pitch: num(r, "horizonPitch", -90.0, 90.0).unwrap_or(0.0),
        roll: num(r, "horizonRoll", -180.0, 180.0).unwrap_or(0.0),
    };
    let mut hotspots = Vec::new();
    if let Some((hs, from_default)) = member(s, default, "hotSpots") {
        let hp = if from_default {
            "default.hotSpots".to_string()
        } else {
            at("hotSpots")
        };
        match &hs.kind {
            LitKind::Arr(list) => {
                if list.len() > MAX_HOTSPOTS {
                    r.add(hs.line, &hp, format!("{} hotspots: more than {MAX_HOTSPOTS} in one scene; the first {MAX_HOTSPOTS} are kept", list.len()));
                }
                for (i, h) in list.iter().take(MAX_HOTSPOTS).enumerate() {
                    if let Some(h) = read_hotspot(r, h, &format!("{hp}[{i}]")) {
                        hotspots.push(h);
                    }
                }
            }
            _ => r.add(
                hs.line,
                &hp,
                format!("is {}, not an array: no hotspots", hs.what()),
            ),
        }
    }
    let mut extra = Map::new();
    for (k, v) in members {
        if !SCENE_KEYS.contains(&k.as_str()) {
            extra.insert(k.clone(), v.to_json());
        }
    }
    Some(TourScene {
        id: id.to_string(),
        title: s.get("title").and_then(Lit::as_str).map(str::to_string),
        source,
        start,
        north_offset,
        horizon,
        hotspots,
        line: s.line,
        source_line,
        extra,
    })
}

fn wrap180(a: f64) -> f64 {
    (a + 180.0).rem_euclid(360.0) - 180.0
}

fn read_hotspot(r: &mut Report, h: &Lit, place: &str) -> Option<Hotspot> {
    let LitKind::Obj(members) = &h.kind else {
        r.add(
            h.line,
            place,
            format!("is {}, not a hotspot object: left out", h.what()),
        );
        return None;
    };
    let at = |k: &str| join(place, k);
    let mut need = |k: &str, lo: f64, hi: f64| -> Option<f64> {
        match h.get(k) {
            None => {
                r.add(h.line, &at(k), "missing: hotspot left out");
                None
            }
            Some(v) => match v.as_f64() {
                Some(x) if (lo..=hi).contains(&x) => Some(x),
                Some(x) => {
                    r.add(
                        v.line,
                        &at(k),
                        format!("{} is not in [{lo}, {hi}]: hotspot left out", num_text(x)),
                    );
                    None
                }
                None => {
                    r.add(
                        v.line,
                        &at(k),
                        format!("is {}, not a number: hotspot left out", v.what()),
                    );
                    None
                }
            },
        }
    };
    let pitch = need("pitch", -90.0, 90.0);
    let yaw = need("yaw", -MAX_TURN, MAX_TURN);
    let (pitch, yaw) = (pitch?, wrap180(yaw?));
    let text = match h.get("text") {
        None => String::new(),
        Some(t) => match t.as_str() {
            Some(s) => s.to_string(),
            None => {
                r.add(
                    t.line,
                    &at("text"),
                    format!("is {}, not a string: ignored", t.what()),
                );
                String::new()
            }
        },
    };
    let scene_id = h.get("sceneId");
    let ty = match h.get("type") {
        None => None,
        Some(t) => match t.as_str() {
            Some(s) => Some((s, t.line)),
            None => {
                r.add(
                    t.line,
                    &at("type"),
                    format!(
                        "is {}, not \"scene\" or \"info\": hotspot left out",
                        t.what()
                    ),
                );
                return None;
            }
        },
    };
    let is_scene = match ty {
        Some(("scene", _)) => true,
        Some(("info", _)) => false,
        None => scene_id.is_some(),
        Some((other, line)) => {
            r.add(
                line,
                &at("type"),
                format!("unknown hotspot type \"{other}\" (scene or info): hotspot left out"),
            );
            return None;
        }
    };
    let kind = if is_scene {
        let Some(sid) = scene_id else {
            r.add(
                h.line,
                &at("sceneId"),
                "missing (a scene hotspot needs it): hotspot left out",
            );
            return None;
        };
        let Some(sid) = sid.as_str() else {
            r.add(
                sid.line,
                &at("sceneId"),
                format!("is {}, not a scene id: hotspot left out", sid.what()),
            );
            return None;
        };
        let mut target = |k: &str, azimuth: bool, lo: f64, hi: f64| -> TargetAngle {
            let Some(v) = h.get(k) else {
                return TargetAngle::Scene;
            };
            match &v.kind {
                LitKind::Num(x) if (lo..=hi).contains(x) => {
                    TargetAngle::Value(if azimuth { wrap180(*x) } else { *x })
                }
                LitKind::Str(s) if s == "same" => TargetAngle::Same,
                LitKind::Str(s) if s == "sameAzimuth" && azimuth => TargetAngle::SameAzimuth,
                LitKind::Num(x) => {
                    r.add(
                        v.line,
                        &at(k),
                        format!(
                            "{} is not in [{lo}, {hi}]: the target scene's own is used",
                            num_text(*x)
                        ),
                    );
                    TargetAngle::Scene
                }
                _ => {
                    let allowed = if azimuth {
                        "a number, \"same\" or \"sameAzimuth\""
                    } else {
                        "a number or \"same\""
                    };
                    r.add(
                        v.line,
                        &at(k),
                        format!("is not {allowed}: the target scene's own is used"),
                    );
                    TargetAngle::Scene
                }
            }
        };
        let t = Target {
            yaw: target("targetYaw", true, -MAX_TURN, MAX_TURN),
            pitch: target("targetPitch", false, -90.0, 90.0),
            hfov: target("targetHfov", false, 1e-3, 179.0),
        };
        HotspotKind::Scene {
            scene_id: sid.to_string(),
            target: t,
        }
    } else {
        HotspotKind::Info {
            url: h.get("URL").and_then(Lit::as_str).map(str::to_string),
        }
    };
    let mut extra = Map::new();
    for (k, v) in members {
        if !HOTSPOT_KEYS.contains(&k.as_str()) {
            extra.insert(k.clone(), v.to_json());
        }
    }
    Some(Hotspot {
        yaw,
        pitch,
        text,
        kind,
        line: h.line,
        place: place.to_string(),
        extra,
    })
}
