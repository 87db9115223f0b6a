//! Inter-reflections (docs/lights.md, "Inter-reflections"): the flux balance of a closed
//! box, exact for any luminaire. With every reflectance 0 the area-weighted mean of the
//! surfaces' illuminance is Φ / S (Φ the luminaires' flux, S the box's surface: every
//! lumen lands once); with one reflectance ρ everywhere it is Φ / (S (1 − ρ)) (each lumen
//! lands 1 + ρ + ρ² + … times). The surfaces' mean is measured here independently of the
//! solve's own sums: the direct illuminance on a fine midpoint grid of every face
//! ([`LightScene::direct`], the per-pixel arithmetic), the indirect at points of a coarser
//! grid ([`LightScene::indirect`], the exact point-to-patch form factors), and Φ from the
//! luminaire's table integrated over the sphere ([`LightTable::luminous_flux`]). Both
//! within 0.5 %, for several rooms, luminaire files, positions and aims.

use glam::DVec3;
use lut_core::{LightScene, LightTable, Luminaire, Reflectances, Room, RoomFace, TableOptions};
use std::f64::consts::PI;
use std::sync::Arc;
use test_support::light_fixtures::synth;

fn file(rel: &str) -> Arc<LightTable> {
    Arc::new(LightTable::load(&test_support::test_data(rel)).unwrap())
}

fn isotropic(lumens: f64) -> Arc<LightTable> {
    let i = lumens / (4.0 * PI);
    let f = synth(1, &[0.0, 90.0, 180.0], &[0.0], |_, _| i, 1.0);
    Arc::new(LightTable::from_ies(&f, &TableOptions::default()).unwrap())
}

fn placed(table: &Arc<LightTable>, p: [f64; 3], yaw: f64, pitch: f64) -> Luminaire {
    let mut l = Luminaire::new(table.clone(), DVec3::from(p));
    l.yaw_deg = yaw;
    l.pitch_deg = pitch;
    l
}

/// The area-weighted mean over the six faces of `f(point, inward normal)` by the
/// midpoint rule on cells of about `h` metres.
fn surface_mean(room: &Room, h: f64, f: &(dyn Fn(DVec3, DVec3) -> f64 + Sync)) -> f64 {
    let (lo, hi) = room.bounds();
    let mut total = 0.0;
    let mut area = 0.0;
    for face in RoomFace::ALL {
        let (ua, va) = face.plane_axes();
        let (su, sv) = (hi[ua] - lo[ua], hi[va] - lo[va]);
        let (nu, nv) = ((su / h).ceil() as usize, (sv / h).ceil() as usize);
        let (hu, hv) = (su / nu as f64, sv / nv as f64);
        let n = face.inward_normal();
        let mut s = 0.0;
        for j in 0..nv {
            for i in 0..nu {
                let mut p = DVec3::ZERO;
                p[face.axis()] = room.plane(face);
                p[ua] = lo[ua] + (i as f64 + 0.5) * hu;
                p[va] = lo[va] + (j as f64 + 0.5) * hv;
                s += f(p, n);
            }
        }
        total += s * hu * hv;
        area += su * sv;
    }
    total / area
}

fn surface(room: &Room) -> f64 {
    let (w, d, h) = (room.width(), room.depth(), room.height());
    2.0 * (w * d + w * h + d * h)
}

struct Case {
    room: Room,
    lights: Vec<Luminaire>,
}

fn cases() -> Vec<Case> {
    let iso = isotropic(10_000.0);
    let louvre = file("ldt/office_louvre_2x28w.ldt");
    let washer = file("ldt/wallwasher_c0_c180.ldt");
    let type_b = file("ies/type_b_full.ies");
    let nosym = file("ldt/no_symmetry.ldt");
    vec![
        Case {
            room: Room::new(4.0, 3.0, 2.5, 1.2).unwrap(),
            lights: vec![placed(&iso, [0.3, 1.6, -0.2], 0.0, -90.0)],
        },
        Case {
            room: Room::new(6.0, 5.0, 2.8, 1.6).unwrap(),
            lights: vec![
                placed(&louvre, [-1.5, 2.4, -1.2], 0.0, -90.0),
                placed(&louvre, [1.5, 2.4, 1.2], 30.0, -90.0),
            ],
        },
        Case {
            room: Room::new(3.0, 3.5, 3.0, 1.5)
                .unwrap()
                .with_center(0.4, -0.3)
                .unwrap(),
            lights: vec![placed(&washer, [0.0, 2.3, 0.5], -90.0, -60.0)],
        },
        Case {
            room: Room::new(5.0, 4.0, 2.7, 1.4).unwrap(),
            lights: vec![
                placed(&type_b, [-1.0, 1.8, 0.5], 20.0, -10.0),
                placed(&nosym, [1.2, 2.0, -0.8], 45.0, -70.0),
            ],
        },
    ]
}

fn flux(lights: &[Luminaire]) -> f64 {
    lights
        .iter()
        .map(|l| l.multiplier * l.table.luminous_flux())
        .sum()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn flux_balance_with_black_surfaces_is_phi_over_s() {
    for (k, c) in cases().into_iter().enumerate() {
        let scene = LightScene::new(c.room, c.lights.clone())
            .unwrap()
            .with_reflectances(Reflectances::ZERO)
            .unwrap();
        assert!(scene.radiosity().is_none());
        let want = flux(&c.lights) / surface(&c.room);
        let got = surface_mean(&c.room, 0.02, &|p, n| scene.illuminance(p, n));
        assert!(
            rel(got, want) < 0.005,
            "case {k}: {got} lx vs Φ/S {want} lx"
        );
    }
}

#[test]
fn flux_balance_with_one_reflectance_is_phi_over_s_one_minus_rho() {
    for (k, c) in cases().into_iter().enumerate() {
        for rho in [0.3, 0.7] {
            let scene = LightScene::new(c.room, c.lights.clone())
                .unwrap()
                .with_reflectances(Reflectances::uniform(rho))
                .unwrap();
            let r = scene.radiosity().unwrap();
            let phi = flux(&c.lights);
            // The solve's own direct flux (patches) against Φ.
            assert!(
                rel(r.direct_flux(), phi) < 0.005,
                "case {k}: patches get {} lm of {phi}",
                r.direct_flux()
            );
            let want = phi / (surface(&c.room) * (1.0 - rho));
            let direct = surface_mean(&c.room, 0.02, &|p, n| scene.direct(p, n));
            let indirect = surface_mean(&c.room, 0.25, &|p, n| scene.indirect(p, n));
            let got = direct + indirect;
            assert!(
                rel(got, want) < 0.005,
                "case {k} ρ {rho}: {got} lx ({direct} direct + {indirect} indirect) vs {want}"
            );
            // The map's fast path (patch means interpolated on the faces) keeps the mean.
            let fast = surface_mean(&c.room, 0.1, &|p, n| {
                scene.illuminance(p, n) - scene.direct(p, n)
            });
            assert!(
                rel(fast, indirect) < 0.005,
                "case {k} ρ {rho}: fast {fast} vs {indirect}"
            );
        }
    }
}

#[test]
fn default_reflectances_brighten_the_point_under_a_light() {
    let room = Room::new(6.0, 5.0, 2.8, 1.6).unwrap();
    let l = vec![placed(
        &file("ldt/office_louvre_2x28w.ldt"),
        [0.0, 2.7, 0.0],
        0.0,
        -90.0,
    )];
    let direct = LightScene::new(room, l.clone()).unwrap();
    let lit = LightScene::new(room, l)
        .unwrap()
        .with_reflectances(Reflectances::default())
        .unwrap();
    for (p, n) in [
        (DVec3::new(0.0, 0.0, 0.0), DVec3::Y),
        (DVec3::new(0.0, 0.75, 0.0), DVec3::Y),
    ] {
        let (e0, e1) = (direct.illuminance(p, n), lit.illuminance(p, n));
        assert_eq!(lit.direct(p, n), e0);
        let ind = lit.indirect(p, n);
        assert!(
            ind > 5.0 && e1 > e0,
            "{p}: {e0} direct, {e1} with ρ (indirect {ind})"
        );
        // On the floor the fast (interpolated) and exact indirect agree closely.
        if p.y == 0.0 {
            assert!(rel(e1 - e0, ind) < 0.03, "{} vs {ind}", e1 - e0);
        }
    }
    // The ceiling above downlights is no longer black.
    let c = DVec3::new(1.0, 2.8, 1.0);
    assert_eq!(direct.illuminance(c, DVec3::NEG_Y), 0.0);
    assert!(lit.illuminance(c, DVec3::NEG_Y) > 1.0);
}

#[test]
fn black_surfaces_change_nothing() {
    let room = Room::new(6.0, 5.0, 2.8, 1.6).unwrap();
    let l = vec![placed(&isotropic(5000.0), [0.5, 2.5, -0.4], 0.0, -90.0)];
    let a = LightScene::new(room, l.clone()).unwrap();
    let b = LightScene::new(room, l)
        .unwrap()
        .with_reflectances(Reflectances::ZERO)
        .unwrap();
    for p in [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(3.0, 1.0, 0.5),
        DVec3::new(1.0, 2.8, 2.0),
    ] {
        let n = room.surface_normal(p, 1e-3).unwrap();
        assert_eq!(a.illuminance(p, n).to_bits(), b.illuminance(p, n).to_bits());
        assert_eq!(b.indirect(p, n), 0.0);
    }
}

#[test]
fn reflectance_of_one_is_refused() {
    let room = Room::new(4.0, 4.0, 2.5, 1.2).unwrap();
    let s = LightScene::new(
        room,
        vec![placed(&isotropic(1000.0), [0.0, 2.0, 0.0], 0.0, -90.0)],
    )
    .unwrap();
    let e = s.with_reflectances(Reflectances::uniform(1.0)).unwrap_err();
    assert!(e.to_string().contains("[0, 1)"), "{e}");
}
