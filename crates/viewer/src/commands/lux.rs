//! `viewer lux`: the illuminance at points of the room, computed per point (the per-pixel
//! path's arithmetic: E = Σ I(direction) · cos(incidence) / d² through each luminaire's
//! table), for checking numbers against a standard's test cases or a planner's
//! calculation.

use crate::args::values::finite;
use crate::lighting::RoomArgs;
use anyhow::{Context, Result};
use clap::Args;
use glam::DVec3;
use lut_core::LightError;
use serde::Serialize;

/// How far from a face a point may be and still count as on it, metres (1 mm).
pub const ON_SURFACE: f64 = 1e-3;

/// Arguments of `viewer lux`.
// The field docs are the command-line help: `[:NX,NY,NZ]` there is not a link.
#[allow(rustdoc::broken_intra_doc_links)]
#[derive(Args, Debug)]
pub struct LuxArgs {
    /// The room and its luminaires (at least one --light, or a --scene with lights).
    #[command(flatten)]
    pub room: RoomArgs,
    /// A point to read: X,Y,Z[:NX,NY,NZ] in metres, room coordinates (repeatable). The
    /// surface normal defaults to the inward normal of the wall, floor or ceiling the point
    /// lies on (within 1 mm); give it for any other point (a work plane: ...:0,1,0).
    #[arg(long = "at", value_parser = parse_point, allow_hyphen_values = true, required = true)]
    pub at: Vec<PointSpec>,
    /// Print JSON: {"points": [{"at": [x, y, z], "normal": [nx, ny, nz], "lux": E}]}.
    #[arg(long)]
    pub json: bool,
}

/// One `--at X,Y,Z[:NX,NY,NZ]`.
#[derive(Debug, Clone, PartialEq)]
pub struct PointSpec {
    /// The point, metres, room coordinates.
    pub at: [f64; 3],
    /// The surface normal (any length but zero), if given.
    pub normal: Option<[f64; 3]>,
}

fn parse_point(s: &str) -> Result<PointSpec, String> {
    let three = |t: &str, what: &str| -> Result<[f64; 3], String> {
        match t
            .split(',')
            .map(finite)
            .collect::<Option<Vec<f64>>>()
            .as_deref()
        {
            Some(&[x, y, z]) => Ok([x, y, z]),
            _ => Err(format!("point '{s}': {what} '{t}' must be 3 numbers")),
        }
    };
    let (at, normal) = match s.split_once(':') {
        Some((a, n)) => (
            three(a, "position X,Y,Z")?,
            Some(three(n, "normal NX,NY,NZ")?),
        ),
        None => (three(s, "position X,Y,Z")?, None),
    };
    if let Some(n) = normal {
        if n.iter().all(|&c| c == 0.0) {
            return Err(format!("point '{s}': the normal must not be 0,0,0"));
        }
    }
    Ok(PointSpec { at, normal })
}

/// One reading, as printed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reading {
    /// The point.
    pub at: [f64; 3],
    /// The unit normal used.
    pub normal: [f64; 3],
    /// Illuminance in lux.
    pub lux: f64,
}

#[derive(Serialize)]
struct Report<'a> {
    points: &'a [Reading],
}

/// The readings these arguments ask for.
///
/// # Errors
/// A bad room, luminaire file or position; no luminaire; a point outside the room, or
/// off every face (or on an edge) without a normal.
pub fn readings(a: &LuxArgs) -> Result<Vec<Reading>> {
    let st = a.room.state()?;
    if st.lights.is_empty() {
        return Err(crate::usage!(
            "no luminaire: give --light FILE@X,Y,Z[:YAW,PITCH] (or a --scene with lights)"
        ));
    }
    let scene = st
        .scene()
        .map_err(anyhow::Error::msg)?
        .context("no luminaire")?;
    let room = *scene.room();
    let mut out = Vec::with_capacity(a.at.len());
    for p in &a.at {
        let at = DVec3::from(p.at);
        let arg = format!("--at {},{},{}", p.at[0], p.at[1], p.at[2]);
        let normal = match p.normal {
            Some(n) if room.contains(at) => DVec3::from(n).normalize(),
            // Outside: the same error as without a normal.
            Some(_) => {
                let (lo, hi) = room.bounds();
                let e = LightError::PointOutsideRoom {
                    point: p.at,
                    low: lo.to_array(),
                    high: hi.to_array(),
                };
                return Err(crate::usage!("{arg}: {e}"));
            }
            None => room.surface_normal(at, ON_SURFACE).map_err(|e| match e {
                LightError::PointOffSurface { .. } | LightError::PointOnEdge { .. } => {
                    crate::usage!("{arg}: {e} (give it: X,Y,Z:NX,NY,NZ)")
                }
                e => crate::usage!("{arg}: {e}"),
            })?,
        };
        out.push(Reading {
            at: p.at,
            normal: normal.to_array(),
            lux: scene.illuminance(at, normal),
        });
    }
    Ok(out)
}

/// The readings as text: one line per point.
pub fn text(readings: &[Reading]) -> String {
    let mut s =
        String::from("point  at (x, y, z) m                  normal                    lux\n");
    for (i, r) in readings.iter().enumerate() {
        let v = |a: [f64; 3]| format!("({:.3}, {:.3}, {:.3})", a[0], a[1], a[2]);
        s += &format!(
            "{:<6} {:<30} {:<24} {}\n",
            i + 1,
            v(r.at),
            v(r.normal),
            lux_text(r.lux)
        );
    }
    s
}

/// Lux with four significant digits (88.42, 1234, 0.03518).
fn lux_text(lux: f64) -> String {
    if lux == 0.0 {
        return "0".into();
    }
    let digits = (3 - lux.abs().log10().floor() as i32).clamp(0, 12) as usize;
    format!("{lux:.digits$}")
}

/// The readings as JSON on one line: `{"points": [{"at": [...], "normal": [...],
/// "lux": E}]}`.
pub fn json(readings: &[Reading]) -> String {
    serde_json::to_string(&Report { points: readings }).expect("readings serialize")
}

/// Run `viewer lux`.
pub fn run(a: LuxArgs) -> Result<()> {
    let r = readings(&a)?;
    if a.json {
        crate::outln!("{}", json(&r))?;
    } else {
        crate::outln!("{}", text(&r).trim_end_matches('\n'))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_parse() {
        assert_eq!(
            parse_point("1,0,-2.5").unwrap(),
            PointSpec {
                at: [1.0, 0.0, -2.5],
                normal: None
            }
        );
        assert_eq!(
            parse_point("0,0.85,0:0,1,0").unwrap().normal,
            Some([0.0, 1.0, 0.0])
        );
        for bad in ["1,2", "1,2,x", "1,2,3:0,0,0", "1,2,3:1,2", "1,2,nan", ""] {
            assert!(parse_point(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn lux_has_four_significant_digits() {
        assert_eq!(lux_text(88.419_412), "88.42");
        assert_eq!(lux_text(1234.4), "1234");
        assert_eq!(lux_text(0.035_184), "0.03518");
        assert_eq!(lux_text(0.0), "0");
    }

    #[test]
    fn json_has_exactly_the_documented_shape() {
        let r = [Reading {
            at: [1.0, 0.0, 2.0],
            normal: [0.0, 1.0, 0.0],
            lux: 88.42,
        }];
        let v: serde_json::Value = serde_json::from_str(&json(&r)).unwrap();
        assert_eq!(
            v,
            serde_json::json!({"points": [{"at": [1.0, 0.0, 2.0], "normal": [0.0, 1.0, 0.0], "lux": 88.42}]})
        );
    }
}
