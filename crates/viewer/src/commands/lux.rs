//! `viewer lux`: the illuminance at points of the room, computed per point (the per-pixel
//! path's arithmetic: E = Σ I(direction) · cos(incidence) / d² through each luminaire's
//! table, plus the light the room's surfaces reflect, from the radiosity solve by exact
//! point-to-patch form factors), for checking numbers against a standard's test cases or
//! a planner's calculation.

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
    /// Print JSON: {"points": [{"at": [x, y, z], "normal": [nx, ny, nz], "lux": E,
    /// "direct": Ed, "indirect": Ei}]} (E = Ed + Ei).
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
    /// Illuminance in lux: `direct` + `indirect`.
    pub lux: f64,
    /// The luminaires' light, lux.
    pub direct: f64,
    /// The light reflected by the room's surfaces (inter-reflections), lux; 0 with
    /// `--direct-only`.
    pub indirect: f64,
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
            // Scaled by its largest component first: a normal of denormal numbers (whose
            // squared length underflows to 0) has a direction all the same.
            Some(n) if room.contains(at) => {
                let n = DVec3::from(n);
                (n / n.abs().max_element()).normalize()
            }
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
        let (direct, indirect) = (scene.direct(at, normal), scene.indirect(at, normal));
        let lux = direct + indirect;
        if !lux.is_finite() {
            return Err(crate::usage!(
                "{arg}: the illuminance is not a finite number ({lux}): the luminaires' \
                 intensities times the multipliers are out of range"
            ));
        }
        out.push(Reading {
            at: p.at,
            normal: normal.to_array(),
            lux,
            direct,
            indirect,
        });
    }
    Ok(out)
}

/// The readings as text: one line per point.
pub fn text(readings: &[Reading]) -> String {
    let mut s = String::from(
        "point  at (x, y, z) m                  normal                    lux        direct     indirect\n",
    );
    for (i, r) in readings.iter().enumerate() {
        let v = |a: [f64; 3]| format!("({:.3}, {:.3}, {:.3})", a[0], a[1], a[2]);
        s += &format!(
            "{:<6} {:<30} {:<24} {:<10} {:<10} {}\n",
            i + 1,
            v(r.at),
            v(r.normal),
            lux_text(r.lux),
            lux_text(r.direct),
            lux_text(r.indirect)
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
///
/// # Errors
/// A number that is not finite ([`crate::exit::finite_json`]).
pub fn json(readings: &[Reading]) -> Result<String> {
    crate::exit::finite_json(&Report { points: readings }, false)
}

/// Run `viewer lux`.
pub fn run(a: LuxArgs) -> Result<()> {
    let r = readings(&a)?;
    if a.json {
        crate::outln!("{}", json(&r)?)?;
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
            lux: 100.0,
            direct: 88.42,
            indirect: 11.58,
        }];
        let v: serde_json::Value = serde_json::from_str(&json(&r).unwrap()).unwrap();
        assert_eq!(
            v,
            serde_json::json!({"points": [{"at": [1.0, 0.0, 2.0], "normal": [0.0, 1.0, 0.0],
                "lux": 100.0, "direct": 88.42, "indirect": 11.58}]})
        );
    }
}
