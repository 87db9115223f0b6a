//! `viewer report --json`: the report's fields (docs/lights.md, "Reports"). Every number
//! is finite (an unlit area has U0 and Ud 0); a value the files do not give (a
//! luminaire's power, its luminous area, a UGR that cannot be rated) is left out rather
//! than written as null.

use super::Report;
use serde_json::{json, Map, Value};

/// The report as pretty JSON, through the one JSON writer ([`crate::exit::finite_json`]).
///
/// # Errors
/// A number that is not finite (a usage error naming the field), never `null`.
pub fn json(r: &Report) -> anyhow::Result<String> {
    Ok(crate::exit::finite_json(&value(r), true)? + "\n")
}

/// The report as a JSON value.
pub fn value(r: &Report) -> Value {
    let areas: Vec<Value> = r
        .areas
        .iter()
        .map(|l| {
            let mut a = json!({
                "name": l.grid.name,
                "area_m2": l.grid.area_m2(),
                "grid": { "spacing_m": l.grid.spacing_m(), "points": l.grid.points.len(),
                          "columns": l.grid.nu, "rows": l.grid.nv },
                "em": l.stats.em,
                "emin": l.stats.emin,
                "emax": l.stats.emax,
                "u0": l.stats.u0,
                "ud": l.stats.ud,
            });
            if let (Some((em, u0)), Some(pass)) = (l.required, l.pass) {
                a["required"] = json!({ "em": em, "u0": u0 });
                a["pass"] = json!(pass);
            }
            a
        })
        .collect();
    let luminaires: Vec<Value> = r
        .luminaires
        .iter()
        .map(|l| {
            let mut m = Map::new();
            m.insert("file".into(), json!(l.file));
            m.insert("position".into(), json!(l.position));
            m.insert("aim".into(), json!(l.aim));
            m.insert("multiplier".into(), json!(l.multiplier));
            m.insert("flux_lm".into(), json!(l.flux_lm));
            if let Some(w) = l.power_w {
                m.insert("power_w".into(), json!(w));
            }
            if let Some(a) = l.luminous_area {
                m.insert(
                    "luminous_area".into(),
                    json!({ "width_m": a.width, "length_m": a.length, "height_m": a.height,
                            "round": a.round }),
                );
            }
            Value::Object(m)
        })
        .collect();
    let mut ugr = Map::new();
    if let Some(v) = r.ugr.value {
        ugr.insert("value".into(), json!(v));
    }
    if let Some(n) = r.ugr.note {
        ugr.insert("note".into(), json!(n));
    }
    ugr.insert("observer".into(), json!(r.observer.0.to_array()));
    ugr.insert("line_of_sight".into(), json!(r.observer.1.to_array()));
    ugr.insert(
        "background_luminance".into(),
        json!(r.ugr.background_luminance),
    );
    ugr.insert(
        "luminaires".into(),
        Value::Array(
            r.ugr
                .terms
                .iter()
                .map(|t| {
                    let mut m = Map::new();
                    m.insert("index".into(), json!(t.index + 1));
                    match t.excluded {
                        Some(why) => {
                            m.insert("excluded".into(), json!(why));
                        }
                        None => {
                            m.insert("luminance".into(), json!(t.luminance));
                            m.insert("solid_angle".into(), json!(t.solid_angle));
                            m.insert("position_index".into(), json!(t.position_index));
                        }
                    }
                    Value::Object(m)
                })
                .collect(),
        ),
    );
    json!({
        "room": { "width": r.room[0], "depth": r.room[1], "height": r.room[2] },
        "work_plane": { "height_m": r.height, "border_band_m": r.band },
        "areas": areas,
        "task": {
            "name": r.task.name,
            "description": r.task.description,
            "em": r.task.em,
            "u0": r.task.u0,
            "walls_em": r.task.walls_em,
            "ceiling_em": r.task.ceiling_em,
            "surfaces_u0": super::SURFACE_U0,
            "pass": r.pass,
        },
        "luminaires": luminaires,
        "total_flux_lm": r.total_flux_lm,
        "reflectances": { "floor": r.reflectances.floor, "walls": r.reflectances.walls,
                          "ceiling": r.reflectances.ceiling },
        "indirect": r.indirect,
        "ugr": Value::Object(ugr),
    })
}
