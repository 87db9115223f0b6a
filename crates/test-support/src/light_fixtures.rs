//! Shared by the light tests: synthetic IES files (any angles, candela from a function)
//! and directions spread over the sphere.

use glam::DVec3;
use lut_core::{IesFile, LightScene, LightTable, Luminaire, Room, TableOptions, View};
use std::sync::Arc;

/// Directions spread evenly over the whole sphere (a Fibonacci spiral).
pub fn sphere(n: usize) -> Vec<DVec3> {
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let ph = i as f64 * 2.399_963_229_728_653;
            DVec3::new(r * ph.cos(), r * ph.sin(), z)
        })
        .collect()
}

/// A type-C (or A/B) file with the given angles and values f(h, v) (horizontal-major).
pub fn synth(ptype: u32, v: &[f64], h: &[f64], f: impl Fn(f64, f64) -> f64, mult: f64) -> IesFile {
    let mut s = String::from("IESNA:LM-63-2002\n[TEST] synthetic\nTILT=NONE\n");
    s += &format!(
        "1 -1 {mult} {} {} {ptype} 2 0 0 0\n1 1 10\n",
        v.len(),
        h.len()
    );
    s += &v
        .iter()
        .map(|a| a.to_string())
        .collect::<Vec<_>>()
        .join(" ");
    s += "\n";
    s += &h
        .iter()
        .map(|a| a.to_string())
        .collect::<Vec<_>>()
        .join(" ");
    s += "\n";
    for &hh in h {
        s += &v
            .iter()
            .map(|&vv| f(hh, vv).to_string())
            .collect::<Vec<_>>()
            .join(" ");
        s += "\n";
    }
    IesFile::parse(&s, "synthetic.ies").expect("synthetic file parses")
}

/// The benchmark's luminaire: type C, bilateral, 5° steps, cut off at 80° (its planes
/// agree at the nadir, as a measured luminaire's do).
pub fn bench_table() -> Arc<LightTable> {
    let v: Vec<f64> = (0..=36).map(|i| i as f64 * 5.0).collect();
    let h: Vec<f64> = (0..=12).map(|i| i as f64 * 15.0).collect();
    let f = synth(
        1,
        &v,
        &h,
        |hh, g| {
            let (sg, cg) = g.to_radians().sin_cos();
            if g >= 80.0 {
                0.0
            } else {
                2000.0 * cg * cg * (1.0 + 0.2 * hh.to_radians().cos() * sg)
            }
        },
        1.0,
    );
    Arc::new(LightTable::from_ies(&f, &TableOptions::default()).expect("bench table builds"))
}

/// A luminaire of `t` at `p` (room coordinates) aimed at (yaw, pitch) degrees.
pub fn lum(t: &Arc<LightTable>, p: [f64; 3], yaw: f64, pitch: f64) -> Luminaire {
    let mut l = Luminaire::new(t.clone(), DVec3::from(p));
    l.yaw_deg = yaw;
    l.pitch_deg = pitch;
    l
}

/// Eight of `table` on a ring 10 cm below the ceiling of a 6 × 5 × 2.8 m room, camera at
/// 1.5 m, each turned 37° from the last (the benchmark's room).
pub fn ring(table: &Arc<LightTable>) -> LightScene {
    let lights: Vec<Luminaire> = (0..8)
        .map(|i| {
            let a = i as f64 / 8.0 * std::f64::consts::TAU;
            lum(
                table,
                [2.0 * a.cos(), 2.7, 1.8 * a.sin()],
                i as f64 * 37.0,
                -90.0,
            )
        })
        .collect();
    LightScene::new(Room::new(6.0, 5.0, 2.8, 1.5).expect("room"), lights).expect("ring scene")
}

/// Views for comparing lit frames: down at the floor, steep, wide, up at the ceiling,
/// straight down (the nadir), narrow.
pub fn views() -> Vec<View> {
    [
        (0.0, -30.0, 100.0),
        (90.0, -60.0, 90.0),
        (200.0, 10.0, 120.0),
        (-45.0, 45.0, 80.0),
        (33.0, -89.0, 100.0),
        (140.0, -5.0, 40.0),
    ]
    .iter()
    .map(|&(y, p, f)| View::new(y, p, f).expect("view"))
    .collect()
}
