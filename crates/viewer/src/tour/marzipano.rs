//! Marzipano tool exports: `data.js` (`var APP_DATA = {...};`, a JavaScript object
//! literal: scenes with `id`, `name`, `levels`, `faceSize`, `initialViewParameters`,
//! `linkHotspots` {yaw, pitch, rotation, target}, `infoHotspots` {yaw, pitch, title, text})
//! beside `tiles/<id>/<z>/<face>/<y>/<x>.jpg`.
//!
//! Marzipano's angles are radians, yaw positive to the right (as here) and pitch
//! positive *down* (its `coordinatesToScreen` puts pitch > 0 below the horizon): pitch is
//! negated on reading. Its `fov` is the vertical field of view; the start view's
//! horizontal one is taken for a 16:9 window ([`VFOV_ASPECT`]).

use super::literal::{self, Lit, LitKind};
use super::pannellum::Report;
use super::{
    path_problem, Angles, Horizon, Hotspot, HotspotKind, Loaded, Source, Target, Tour, TourScene,
    DEFAULT_START, MAX_HOTSPOTS, MAX_SCENES,
};
use serde_json::{json, Map};
use std::path::Path;

/// The aspect ratio Marzipano's vertical `fov` is turned into a horizontal one at.
pub const VFOV_ASPECT: f64 = 16.0 / 9.0;

/// A hotspot's `title` and `text` joined into one hover text.
fn info_text(title: Option<&str>, text: Option<&str>) -> String {
    match (
        title.filter(|t| !t.is_empty()),
        text.filter(|t| !t.is_empty()),
    ) {
        (Some(a), Some(b)) => format!("{a}: {b}"),
        (Some(a), None) | (None, Some(a)) => a.to_string(),
        (None, None) => String::new(),
    }
}

/// Read a Marzipano `data.js` (`text`, from `file`, tiles relative to `dir`).
///
/// # Errors
/// No `APP_DATA`, a syntax error, or no `scenes` array: nothing opens.
pub fn read(text: &str, file: &Path, dir: &Path) -> anyhow::Result<Loaded> {
    let root = literal::parse_app_data(text)
        .map_err(|e| anyhow::anyhow!("{}:{}: {}", file.display(), e.line, e.message))?;
    let Some(LitKind::Arr(list)) = root.get("scenes").map(|s| &s.kind) else {
        anyhow::bail!(
            "{}:{}: APP_DATA has no scenes array: not a Marzipano tour",
            file.display(),
            root.line
        );
    };
    let mut r = Report {
        file,
        problems: Vec::new(),
    };
    let mut tour = Tour::new(dir.to_path_buf());
    tour.title = root.get("name").and_then(Lit::as_str).map(str::to_string);
    if let Some(s) = root.get("settings") {
        tour.default_extra
            .insert("marzipanoSettings".into(), s.to_json());
    }
    for (i, s) in list.iter().enumerate() {
        let place = format!("scenes[{i}]");
        if i >= MAX_SCENES {
            r.add(
                s.line,
                &place,
                format!("more than {MAX_SCENES} scenes: the rest are left out"),
            );
            break;
        }
        if let Some(scene) = read_scene(&mut r, s, &place) {
            if tour.scene(&scene.id).is_some() {
                r.add(
                    s.line,
                    &format!("{place}.id"),
                    format!("scene id \"{}\" is repeated: left out", scene.id),
                );
                continue;
            }
            tour.scenes.push(scene);
        }
    }
    // A link's hover text: its target's name.
    let names: Vec<(String, String)> = tour
        .scenes
        .iter()
        .map(|s| {
            (
                s.id.clone(),
                s.title.clone().unwrap_or_else(|| s.id.clone()),
            )
        })
        .collect();
    for s in &mut tour.scenes {
        for h in &mut s.hotspots {
            if let HotspotKind::Scene { scene_id, .. } = &h.kind {
                if let Some((_, n)) = names.iter().find(|(id, _)| id == scene_id) {
                    h.text = n.clone();
                }
            }
        }
    }
    if let Some(first) = tour.scenes.first() {
        tour.first_scene = first.id.clone();
    } else {
        r.add(0, "", "no scene of the tour opens");
    }
    for s in &tour.scenes {
        for h in &s.hotspots {
            if let HotspotKind::Scene { scene_id, .. } = &h.kind {
                if tour.scene(scene_id).is_none() {
                    r.add(
                        h.line,
                        &format!("{}.target", h.place),
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

fn radians(
    r: &mut Report,
    v: Option<&Lit>,
    line: usize,
    place: &str,
    lo: f64,
    hi: f64,
) -> Option<f64> {
    match v {
        None => {
            r.add(line, place, "missing");
            None
        }
        Some(v) => match v.as_f64() {
            Some(x) if (lo..=hi).contains(&x) => Some(x),
            Some(x) => {
                r.add(
                    v.line,
                    place,
                    format!("{} is not in [{lo}, {hi}] (radians)", super::num_text(x)),
                );
                None
            }
            None => {
                r.add(v.line, place, format!("is {}, not a number", v.what()));
                None
            }
        },
    }
}

const TURN: f64 = 100.0 * std::f64::consts::TAU;
const HALF_PI: f64 = std::f64::consts::FRAC_PI_2;

fn read_scene(r: &mut Report, s: &Lit, place: &str) -> Option<TourScene> {
    if !matches!(s.kind, LitKind::Obj(_)) {
        r.add(
            s.line,
            place,
            format!("is {}, not a scene object: left out", s.what()),
        );
        return None;
    }
    let Some(id) = s.get("id").and_then(Lit::as_str).filter(|i| !i.is_empty()) else {
        r.add(
            s.line,
            &format!("{place}.id"),
            "missing or not a string: scene left out",
        );
        return None;
    };
    let dir = format!("tiles/{id}");
    if let Some(why) = path_problem(&dir) {
        r.add(
            s.get("id").map_or(s.line, |v| v.line),
            &format!("{place}.id"),
            format!("the tile folder {why}: scene left out"),
        );
        return None;
    }
    let mut levels = Vec::new();
    match s.get("levels").map(|l| &l.kind) {
        Some(LitKind::Arr(ls)) => {
            for (i, l) in ls.iter().enumerate() {
                let size = l.get("size").and_then(Lit::as_f64);
                let tile = l.get("tileSize").and_then(Lit::as_f64);
                let ok =
                    |v: Option<f64>| v.filter(|v| v.fract() == 0.0 && (1.0..=65536.0).contains(v));
                match (ok(tile), ok(size)) {
                    (Some(t), Some(sz)) => levels.push((
                        t as u32,
                        sz as u32,
                        matches!(
                            l.get("fallbackOnly").map(|f| &f.kind),
                            Some(LitKind::Bool(true))
                        ),
                    )),
                    _ => r.add(
                        l.line,
                        &format!("{place}.levels[{i}]"),
                        "needs whole tileSize and size in 1..=65536: level left out",
                    ),
                }
            }
        }
        _ => r.add(
            s.line,
            &format!("{place}.levels"),
            "missing or not an array: the scene has no tiles",
        ),
    }
    let face_size = match s.get("faceSize").and_then(Lit::as_f64) {
        Some(f) if f.fract() == 0.0 && (1.0..=65536.0).contains(&f) => f as u32,
        _ => {
            r.add(
                s.line,
                &format!("{place}.faceSize"),
                "missing or not a whole number in 1..=65536: taken from the levels",
            );
            levels.iter().map(|l| l.1).max().unwrap_or(0)
        }
    };
    let ivp = s.get("initialViewParameters");
    let vp = format!("{place}.initialViewParameters");
    let start = match ivp {
        Some(v) if matches!(v.kind, LitKind::Obj(_)) => {
            let yaw = radians(r, v.get("yaw"), v.line, &format!("{vp}.yaw"), -TURN, TURN);
            let pitch = radians(
                r,
                v.get("pitch"),
                v.line,
                &format!("{vp}.pitch"),
                -HALF_PI,
                HALF_PI,
            );
            let fov = radians(
                r,
                v.get("fov"),
                v.line,
                &format!("{vp}.fov"),
                1e-5,
                std::f64::consts::PI - 1e-3,
            );
            Angles {
                yaw: yaw.map_or(DEFAULT_START.yaw, |y| wrap180(y.to_degrees())),
                pitch: pitch.map_or(DEFAULT_START.pitch, |p| -p.to_degrees()),
                hfov: fov.map_or(DEFAULT_START.hfov, |f| {
                    (2.0 * ((f / 2.0).tan() * VFOV_ASPECT).atan())
                        .to_degrees()
                        .min(179.0)
                }),
            }
        }
        _ => DEFAULT_START,
    };
    let mut hotspots = Vec::new();
    let mut total = 0usize;
    for (key, link) in [("linkHotspots", true), ("infoHotspots", false)] {
        let Some(list) = s.get(key) else { continue };
        let LitKind::Arr(list) = &list.kind else {
            r.add(
                list.line,
                &format!("{place}.{key}"),
                format!("is {}, not an array: ignored", list.what()),
            );
            continue;
        };
        for (i, h) in list.iter().enumerate() {
            let hp = format!("{place}.{key}[{i}]");
            total += 1;
            if total > MAX_HOTSPOTS {
                r.add(
                    h.line,
                    &hp,
                    format!(
                        "more than {MAX_HOTSPOTS} hotspots in one scene: the rest are left out"
                    ),
                );
                break;
            }
            let yaw = radians(r, h.get("yaw"), h.line, &format!("{hp}.yaw"), -TURN, TURN);
            let pitch = radians(
                r,
                h.get("pitch"),
                h.line,
                &format!("{hp}.pitch"),
                -HALF_PI,
                HALF_PI,
            );
            let (Some(yaw), Some(pitch)) = (yaw, pitch) else {
                r.add(h.line, &hp, "hotspot left out");
                continue;
            };
            let mut extra = Map::new();
            let kind = if link {
                let Some(t) = h.get("target").and_then(Lit::as_str) else {
                    r.add(
                        h.line,
                        &format!("{hp}.target"),
                        "missing or not a scene id: hotspot left out",
                    );
                    continue;
                };
                if let Some(rot) = h.get("rotation").and_then(Lit::as_f64) {
                    extra.insert("marzipanoRotation".into(), json!(rot));
                }
                HotspotKind::Scene {
                    scene_id: t.to_string(),
                    target: Target::default(),
                }
            } else {
                HotspotKind::Info { url: None }
            };
            let text = if link {
                String::new()
            } else {
                info_text(
                    h.get("title").and_then(Lit::as_str),
                    h.get("text").and_then(Lit::as_str),
                )
            };
            hotspots.push(Hotspot {
                yaw: wrap180(yaw.to_degrees()),
                pitch: -pitch.to_degrees(),
                text,
                kind,
                line: h.line,
                place: hp.clone(),
                extra,
            });
        }
    }
    Some(TourScene {
        id: id.to_string(),
        title: s.get("name").and_then(Lit::as_str).map(str::to_string),
        source: Source::MarzipanoTiles {
            dir,
            levels,
            face_size,
        },
        start,
        north_offset: 0.0,
        horizon: Horizon::default(),
        hotspots,
        line: s.line,
        source_line: s.get("levels").map_or(s.line, |l| l.line),
        extra: Map::new(),
    })
}

fn wrap180(a: f64) -> f64 {
    (a + 180.0).rem_euclid(360.0) - 180.0
}
