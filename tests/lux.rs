//! Lux against the closed-form point-source cases of CIE 171:2006 ("Test cases to assess
//! the accuracy of lighting computer programs"): a point source of intensity I gives
//! E = I · cos θ / d² on a surface at distance d whose normal makes the angle θ with the
//! direction to the source. The reference case: an isotropic 10 000 lm source
//! (I = 10 000 / 4π cd) 3 m above a point gives 88.42 lx.
//!
//! Checked within 0.5 % (most much closer), for several sources, aims, faces and
//! distances on both sides of the distance series' reference distance (4 m by default:
//! beyond it the illuminance is read from the pre-filtered tables the series keeps, each
//! within 0.4 % of the measured one, see docs/lights.md). The error a peaked distribution
//! would get from the plain (unchecked) series is measured and stated.

use glam::DVec3;
use lut_core::{LightScene, LightTable, Luminaire, Room, TableOptions};
use std::f64::consts::PI;
use std::sync::Arc;
use test_support::light_fixtures::synth;

/// An isotropic source of `lumens`, type C, measured at 0, 90 and 180°.
fn isotropic(lumens: f64) -> Arc<LightTable> {
    let i = lumens / (4.0 * PI);
    let f = synth(1, &[0.0, 90.0, 180.0], &[0.0], |_, _| i, 1.0);
    Arc::new(LightTable::from_ies(&f, &TableOptions::default()).unwrap())
}

/// A rotational distribution I(γ) measured every `step` degrees over the whole sphere.
fn rotational(step: f64, i: impl Fn(f64) -> f64) -> Arc<LightTable> {
    let n = (180.0 / step).round() as usize;
    let v: Vec<f64> = (0..=n).map(|k| k as f64 * step).collect();
    let f = synth(1, &v, &[0.0], |_, g| i(g), 1.0);
    Arc::new(LightTable::from_ies(&f, &TableOptions::default()).unwrap())
}

fn placed(table: &Arc<LightTable>, p: DVec3, yaw: f64, pitch: f64) -> Luminaire {
    let mut l = Luminaire::new(table.clone(), p);
    l.yaw_deg = yaw;
    l.pitch_deg = pitch;
    l
}

/// A hall large enough for the far cases: 80 × 80 m, 12 m high, camera 1.6 m.
fn hall() -> Room {
    Room::new(80.0, 80.0, 12.0, 1.6).unwrap()
}

/// E = I(γ) cos θ / d² for a source at `l` aimed along `aim` (unit), at point `p` with
/// inward normal `n`: the closed form, computed here.
fn closed_form(i: &dyn Fn(f64) -> f64, l: DVec3, aim: DVec3, p: DVec3, n: DVec3) -> f64 {
    let to = l - p;
    let d = to.length();
    let cos_t = n.dot(to) / d;
    if cos_t <= 0.0 {
        return 0.0;
    }
    let gamma = aim.dot(-to / d).clamp(-1.0, 1.0).acos().to_degrees();
    i(gamma) * cos_t / (d * d)
}

/// A distribution, a position, an aim (yaw, pitch).
type Source<'a> = (&'a dyn Fn(f64) -> f64, DVec3, f64, f64);

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-12)
}

#[test]
fn cie_171_reference_case_88_42_lux() {
    // Isotropic 10 000 lm, 3 m above a floor point.
    let scene = LightScene::new(
        hall(),
        vec![placed(
            &isotropic(10_000.0),
            DVec3::new(1.0, 3.0, -2.0),
            0.0,
            -90.0,
        )],
    )
    .unwrap();
    let e = scene.illuminance(DVec3::new(1.0, 0.0, -2.0), DVec3::Y);
    assert!((e - 88.42).abs() < 0.005, "{e} lx");
    assert!(rel(e, 10_000.0 / (4.0 * PI) / 9.0) < 1e-12);
}

#[test]
fn isotropic_source_on_every_face_and_distance() {
    // Oblique points: E = I cos θ / d², on the floor, the walls and the ceiling, from
    // 0.5 m to 40 m (the series' levels serve 4, 8, 16, 32 m): a constant survives the
    // pre-filter exactly, so every distance is within rounding.
    let room = hall();
    let lumens = 10_000.0;
    let i = lumens / (4.0 * PI);
    let l = DVec3::new(2.0, 6.0, -3.0);
    let scene = LightScene::new(room, vec![placed(&isotropic(lumens), l, 30.0, -40.0)]).unwrap();
    let mut checked = 0;
    for k in 0..200 {
        // Points spread over the six faces at growing distances.
        let t = k as f64 / 200.0;
        let r = 0.5 + 39.5 * t * t;
        let a = k as f64 * 2.399_963;
        let (lo, hi) = room.bounds();
        let face = k % 6;
        let p = match face {
            0 => DVec3::new(l.x + r * a.cos(), 0.0, l.z + r * a.sin()),
            1 => DVec3::new(l.x + r * a.cos(), 12.0, l.z + r * a.sin()),
            2 => DVec3::new(lo.x, 6.0 + 5.0 * a.sin(), l.z + r * a.cos()),
            3 => DVec3::new(hi.x, 6.0 + 5.0 * a.sin(), l.z + r * a.cos()),
            4 => DVec3::new(l.x + r * a.cos(), 6.0 + 5.0 * a.sin(), lo.z),
            _ => DVec3::new(l.x + r * a.cos(), 6.0 + 5.0 * a.sin(), hi.z),
        };
        if !room.contains(p) {
            continue;
        }
        let n = room.surface_normal(p, 1e-9).unwrap();
        let want = closed_form(&|_| i, l, DVec3::NEG_Y, p, n);
        let got = scene.illuminance(p, n);
        assert!(rel(got, want) < 1e-9, "face {face} p {p}: {got} vs {want}");
        checked += 1;
    }
    assert!(checked > 150);
}

#[test]
fn aimed_smooth_sources_near_and_beyond_the_reference_distance() {
    // Three sources with smooth distributions, each aimed its own way, measured every
    // 2.5° (as manufacturers publish); points on the floor, a wall and the ceiling at 1
    // to 40 m. The closed form uses the continuous I(γ); the table interpolates it
    // linearly between measured angles (≤ 0.15 % here) and, beyond 4 m, reads the
    // pre-filtered tables the series kept (each within 0.4 % of the measured one):
    // within 0.5 %.
    let room = hall();
    let i_a = |g: f64| 1200.0 + 800.0 * g.to_radians().cos();
    let i_b = |g: f64| 900.0 * (1.0 + g.to_radians().cos()) / 2.0 + 100.0;
    let i_c = |g: f64| 500.0 + 300.0 * (2.0 * g.to_radians()).cos();
    let sources: [Source; 3] = [
        (&i_a, DVec3::new(0.0, 8.0, 0.0), 0.0, -90.0),
        (&i_b, DVec3::new(-10.0, 4.0, 6.0), 45.0, -30.0),
        (&i_c, DVec3::new(12.0, 10.0, -15.0), -120.0, 10.0),
    ];
    let lights: Vec<Luminaire> = sources
        .iter()
        .map(|(f, p, yaw, pitch)| placed(&rotational(2.5, f), *p, *yaw, *pitch))
        .collect();
    let aims: Vec<DVec3> = lights.iter().map(|l| l.frame().2).collect();
    let scene = LightScene::new(room, lights.clone()).unwrap();
    let (lo, hi) = room.bounds();
    let mut worst: f64 = 0.0;
    let mut far = 0;
    for k in 0..300 {
        let a = k as f64 * 0.618_034 * 2.0 * PI;
        let r = 1.0 + 39.0 * (k as f64 / 300.0);
        let p = match k % 3 {
            0 => DVec3::new(
                (r * a.cos()).clamp(lo.x, hi.x),
                0.0,
                (r * a.sin()).clamp(lo.z, hi.z),
            ),
            1 => DVec3::new(
                hi.x,
                1.0 + 10.0 * (k as f64 * 0.37).sin().abs(),
                (r * a.sin()).clamp(lo.z, hi.z),
            ),
            _ => DVec3::new(
                (r * a.cos()).clamp(lo.x, hi.x),
                12.0,
                (r * a.sin()).clamp(lo.z, hi.z),
            ),
        };
        let n = room.surface_normal(p, 1e-9).unwrap();
        // Each source alone, then all together (the sum).
        let mut total = 0.0;
        for (j, (f, l, _, _)) in sources.iter().enumerate() {
            let want = closed_form(*f, *l, aims[j], p, n);
            let one = LightScene::new(room, vec![lights[j].clone()]).unwrap();
            let got = one.illuminance(p, n);
            if want > 1e-6 {
                worst = worst.max(rel(got, want));
                assert!(rel(got, want) < 5e-3, "source {j} at {p}: {got} vs {want}");
                far += ((p - *l).length() > 8.0) as usize;
            } else {
                assert!(got.abs() < 1e-9);
            }
            total += want;
        }
        let got = scene.illuminance(p, n);
        assert!(
            rel(got, total) < 5e-3 || total < 1e-9,
            "sum at {p}: {got} vs {total}"
        );
    }
    assert!(
        far > 100,
        "too few points beyond the reference distance ({far})"
    );
    eprintln!("smooth sources: worst {:.3} %", worst * 100.0);
}

#[test]
fn many_sources_add_up() {
    // Nine isotropic sources of different flux on a grid above a floor point and the
    // four walls: E = Σ I_k cos θ_k / d_k².
    let room = Room::new(12.0, 9.0, 4.0, 1.5).unwrap();
    let mut lights = Vec::new();
    let mut parts = Vec::new();
    for gx in -1..=1 {
        for gz in -1..=1 {
            let lm = 2000.0 + 1000.0 * (gx + 1) as f64 + 300.0 * (gz + 1) as f64;
            let p = DVec3::new(3.5 * gx as f64, 3.6, 2.5 * gz as f64);
            lights.push(placed(&isotropic(lm), p, 10.0 * gx as f64, -90.0));
            parts.push((lm / (4.0 * PI), p));
        }
    }
    let scene = LightScene::new(room, lights).unwrap();
    for p in [
        DVec3::new(0.3, 0.0, -0.4),
        DVec3::new(-6.0, 1.0, 2.0),
        DVec3::new(6.0, 2.5, -4.0),
        DVec3::new(1.0, 0.8, 4.5),
        DVec3::new(-2.0, 3.0, -4.5),
        DVec3::new(5.0, 4.0, 1.0),
    ] {
        let n = room.surface_normal(p, 1e-9).unwrap();
        let want: f64 = parts
            .iter()
            .map(|(i, l)| closed_form(&|_| *i, *l, DVec3::NEG_Y, p, n))
            .sum();
        let got = scene.illuminance(p, n);
        assert!(rel(got, want) < 1e-9, "{p}: {got} vs {want}");
    }
}

#[test]
fn peaked_distribution_error_is_stated() {
    // A narrow spot, I = 20 000 cos^40 γ cd (half the peak at 10.7°), measured every
    // 2.5°, aimed straight down, its beam centre read at 2 to 32 m.
    let i = |g: f64| 20_000.0 * g.to_radians().cos().max(0.0).powi(40);
    let n = 72;
    let v: Vec<f64> = (0..=n).map(|k| k as f64 * 2.5).collect();
    let file = synth(1, &v, &[0.0], |_, g| i(g), 1.0);
    let room = Room::new(10.0, 10.0, 40.0, 1.5).unwrap();
    let errors = |opts: &TableOptions| -> Vec<f64> {
        let table = Arc::new(LightTable::from_ies(&file, opts).unwrap());
        [2.0, 4.0, 8.0, 16.0, 32.0]
            .iter()
            .map(|&h| {
                let l = DVec3::new(0.0, h, 0.0);
                let scene = LightScene::new(room, vec![placed(&table, l, 0.0, -90.0)]).unwrap();
                let got = scene.illuminance(DVec3::ZERO, DVec3::Y);
                let want = i(0.0) / (h * h);
                (got - want) / want
            })
            .collect()
    };
    // The default series refuses every pre-filtered table (each strays by more than
    // 0.4 %), so the measured table serves every distance: exact.
    let checked = errors(&TableOptions::default());
    assert!(checked.iter().all(|e| e.abs() < 1e-9), "{checked:?}");
    // The plain series (every table halving, the patent's claim 7 as such) rounds the
    // peak off beyond the reference distance: the [¼ ½ ¼] filter of level k spans
    // 2.5°·2^k on each side. Measured, and stated in docs/lights.md: −1.9 % at 8 m
    // (level 1), −8.6 % at 16 m (level 2), −27 % at 32 m (level 3).
    let plain = errors(&TableOptions {
        series_tolerance: None,
        ..TableOptions::default()
    });
    eprintln!("plain series at 2, 4, 8, 16, 32 m: {plain:?}");
    assert!(plain[0].abs() < 1e-9 && plain[1].abs() < 1e-9, "{plain:?}");
    assert!((-0.022..=-0.016).contains(&plain[2]), "{plain:?}");
    assert!((-0.095..=-0.075).contains(&plain[3]), "{plain:?}");
    assert!((-0.30..=-0.24).contains(&plain[4]), "{plain:?}");
    // Off the centre, inside the measured table: between measured angles the table
    // interpolates, and a beam this narrow curves within a step (I''/I = −40 at the
    // centre: linear interpolation is off by up to about (2.5°)²/8 · 40 ≈ 1 %, measured
    // 1.3 %); Catmull-Rom
    // follows the curve closer. Where I is above a tenth of its peak:
    let l = DVec3::new(0.0, 3.0, 0.0);
    for (interpolation, bound) in [
        (lut_core::Interpolation::Linear, 0.015),
        (lut_core::Interpolation::CatmullRom, 0.003),
    ] {
        let opts = TableOptions {
            interpolation,
            ..TableOptions::default()
        };
        let table = Arc::new(LightTable::from_ies(&file, &opts).unwrap());
        let scene = LightScene::new(room, vec![placed(&table, l, 0.0, -90.0)]).unwrap();
        let mut worst: f64 = 0.0;
        for k in 0..80 {
            let p = DVec3::new(k as f64 * 0.01, 0.0, 0.0);
            let want = closed_form(&i, l, DVec3::NEG_Y, p, DVec3::Y);
            if want > 0.1 * i(0.0) / 9.0 {
                worst = worst.max(rel(scene.illuminance(p, DVec3::Y), want));
            }
        }
        eprintln!("{interpolation:?}: worst {:.3} %", worst * 100.0);
        assert!(worst < bound, "{interpolation:?}: {worst}");
    }
}
