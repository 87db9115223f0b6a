//! The light table, whatever the file format: constant ranges left out in both directions
//! (EP 0613099 claim 8) with lookups identical to the uncut table, and the interpolation
//! between measured angles (linear or Catmull-Rom).

use lut_core::{Interpolation, LdtFile, LightTable, Named, Photometry, Symmetry, TableOptions};
use std::path::PathBuf;
use test_support::light_fixtures::{sphere, synth};

fn ldt(name: &str) -> Photometry {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/ldt")
        .join(name);
    Photometry::from_ldt(&LdtFile::load(&p).unwrap())
}

fn ies(name: &str) -> Photometry {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/ies")
        .join(name);
    Photometry::load(&p).unwrap()
}

fn build(p: &Photometry, interpolation: Interpolation, cut: bool) -> LightTable {
    let o = TableOptions {
        interpolation,
        cut_constant_ranges: cut,
        ..TableOptions::default()
    };
    LightTable::from_photometry(p, &o).unwrap()
}

/// The cut and the uncut table give the same bits: over the sphere at distances across
/// the whole series, at every level, at the measured angles and just beside them.
fn assert_identical(p: &Photometry, interp: Interpolation) -> (LightTable, LightTable) {
    let (cut, full) = (build(p, interp, true), build(p, interp, false));
    assert_eq!(cut.level_count(), full.level_count());
    for d in sphere(20_000) {
        assert_eq!(
            cut.candela_dir(d).to_bits(),
            full.candela_dir(d).to_bits(),
            "{d}"
        );
        for dist in [1.0, 4.0, 6.0, 11.0, 50.0] {
            let (a, b) = (
                cut.illuminance_normal(d, dist),
                full.illuminance_normal(d, dist),
            );
            assert_eq!(a.to_bits(), b.to_bits(), "{d} at {dist} m: {a} vs {b}");
        }
    }
    let eps = [0.0, 1e-9, -1e-9, 0.4];
    for k in 0..cut.level_count() {
        for &h in &p.horizontal_angles {
            for &v in &p.vertical_angles {
                for (dh, dv) in eps.iter().flat_map(|&a| eps.iter().map(move |&b| (a, b))) {
                    let (a, b) = (
                        cut.level_candela(k, v + dv, h + dh).unwrap(),
                        full.level_candela(k, v + dv, h + dh).unwrap(),
                    );
                    assert_eq!(a.to_bits(), b.to_bits(), "level {k} ({v}, {h}): {a} vs {b}");
                }
            }
        }
    }
    (cut, full)
}

// ---------------------------------------------------------------- claim 8

#[test]
fn constant_planes_and_rows_of_a_wall_washer_are_not_stored() {
    // Dark behind (the planes C90 to C180 are all zero) and above the horizontal.
    let p = ldt("wallwasher_c0_c180.ldt");
    assert_eq!(p.symmetry, Symmetry::Bilateral0To180);
    // (planes, rows) stored: linear keeps the boundary entry; Catmull-Rom reads one more.
    for (interp, want) in [
        (Interpolation::Linear, (7, 19)),
        (Interpolation::CatmullRom, (8, 20)),
    ] {
        let (cut, full) = assert_identical(&p, interp);
        assert_eq!(full.level_size(0), Some((13, 37)));
        assert_eq!(cut.level_size(0), Some(want), "{interp:?}");
        for k in 0..cut.level_count() {
            let (c, f) = (
                cut.stored_values(k).unwrap(),
                full.stored_values(k).unwrap(),
            );
            assert!(
                c < f || (k > 0 && c == f),
                "{interp:?} level {k}: {c} vs {f}"
            );
        }
        assert!(cut.stored_values(0).unwrap() * 2 < full.stored_values(0).unwrap());
        // Behind the washer and above it: nothing, from the substituted constants.
        assert_eq!(cut.candela(30.0, 120.0), 0.0);
        assert_eq!(cut.candela(100.0, 10.0), 0.0);
        assert!(cut.candela(30.0, 40.0) > 0.0);
    }
}

#[test]
fn leading_and_trailing_planes_of_a_floodlight_are_not_stored() {
    // Type B, H from −90 to 90 (no symmetry): a constant 12 cd beyond ±40°, both sides.
    let v: Vec<f64> = (0..=18).map(|i| -90.0 + 10.0 * i as f64).collect();
    let f = synth(
        2,
        &v,
        &v,
        |h, vv| {
            if h.abs() > 40.0 {
                12.0
            } else {
                900.0 - 10.0 * h.abs() - 3.0 * vv.abs() + h
            }
        },
        1.0,
    );
    let p = Photometry::from_ies(&f).unwrap();
    assert_eq!(p.symmetry, Symmetry::None);
    let (cut, _) = assert_identical(&p, Interpolation::Linear);
    // H −50 ..= 50: the boundary planes stay.
    assert_eq!(cut.level_size(0), Some((11, 19)));
    let (cut, _) = assert_identical(&p, Interpolation::CatmullRom);
    assert_eq!(cut.level_size(0), Some((13, 19)));
}

#[test]
fn a_dark_range_across_c0_is_cut_at_both_ends_of_a_full_circle() {
    // Type C, C 0..345 (no symmetry; the table closes the circle with a plane at 360°):
    // a constant glow of 50 cd from C300 through C0 to C30 (a constant other than zero,
    // so a neighbour read wrongly across the seam would show: Catmull-Rom would dip below
    // 50 rather than be clamped at 0).
    let v: Vec<f64> = (0..=18).map(|i| 10.0 * i as f64).collect();
    let h: Vec<f64> = (0..24).map(|i| 15.0 * i as f64).collect();
    let f = synth(
        1,
        &v,
        &h,
        |c, g| {
            if !(45.0..300.0).contains(&c) {
                50.0
            } else {
                400.0 + c - g
            }
        },
        1.0,
    );
    let p = Photometry::from_ies(&f).unwrap();
    assert_eq!(p.symmetry, Symmetry::None);
    let (cut, full) = assert_identical(&p, Interpolation::Linear);
    assert_eq!(full.level_size(0), Some((25, 19)));
    // Stored C30 ..= C300: the boundary planes stay.
    assert_eq!(cut.level_size(0), Some((19, 19)));
    // Catmull-Rom reads one more plane each side (wrapping round 360°): C15 ..= C315.
    let (cut, _) = assert_identical(&p, Interpolation::CatmullRom);
    assert_eq!(cut.level_size(0), Some((21, 19)));
    // Constant only at the start, lit just before 360°: the first cell reads the lit C345
    // plane across the seam, so Catmull-Rom cuts nothing; linear cuts C0 to C45.
    let f = synth(
        1,
        &v,
        &h,
        |c, g| if c <= 45.0 { 50.0 } else { 400.0 + c - g },
        1.0,
    );
    let p = Photometry::from_ies(&f).unwrap();
    let (cut, _) = assert_identical(&p, Interpolation::CatmullRom);
    assert_eq!(cut.level_size(0), Some((25, 19)));
    assert!(cut.candela(50.0, 7.5) < 50.0);
    let (cut, _) = assert_identical(&p, Interpolation::Linear);
    assert_eq!(cut.level_size(0), Some((22, 19))); // C45 ..= C360
}

#[test]
fn every_sample_file_looks_up_the_same_with_and_without_the_cut() {
    let files = [
        ldt("office_louvre_2x28w.ldt"),
        ldt("no_symmetry.ldt"),
        ldt("bilateral_c90_c270.ldt"),
        ldt("quadrant_tilt_include.ldt"),
        ies("type_b_full.ies"),
        ies("label_lines.ies"),
    ];
    for p in &files {
        for interp in Interpolation::ALL {
            assert_identical(p, *interp);
        }
    }
}

// ---------------------------------------------------------------- interpolation

/// Uniform Catmull-Rom, the textbook form (Cycles' `cubic_interp`), written here
/// independently of the library's.
fn cr(a: f64, b: f64, c: f64, d: f64, t: f64) -> f64 {
    0.5 * (2.0 * b
        + (c - a) * t
        + (2.0 * a - 5.0 * b + 4.0 * c - d) * t * t
        + (3.0 * b - a - 3.0 * c + d) * t * t * t)
}

#[test]
fn catmull_rom_is_exact_at_the_measured_angles() {
    let p = ldt("no_symmetry.ldt");
    let t = build(&p, Interpolation::CatmullRom, true);
    let nv = p.vertical_angles.len();
    for (ih, &c) in p.horizontal_angles.iter().enumerate() {
        for (iv, &g) in p.vertical_angles.iter().enumerate() {
            let want = p.candela[ih * nv + iv];
            let got = t.candela(g, c);
            assert!(
                (got - want).abs() <= 1e-9 * want.max(1.0),
                "({g}, {c}): {got} vs {want}"
            );
        }
    }
}

#[test]
fn catmull_rom_reads_four_neighbours_mirrored_at_the_pole_and_repeated_at_the_end() {
    // Rotational, γ 0 to 90 every 2.5°: γ 0 is the pole (row −1 mirrors row 1), 90 is the
    // end of the measured range (the row past it repeats the last).
    let p = ies("label_lines.ies");
    let t = build(&p, Interpolation::CatmullRom, true);
    let i = &p.candela;
    let want = cr(i[1], i[0], i[1], i[2], 0.4);
    assert!(
        (t.candela(1.0, 77.0) - want).abs() < 1e-9,
        "{}",
        t.candela(1.0, 77.0)
    );
    let want = cr(i[10], i[11], i[12], i[13], 0.3);
    assert!((t.candela(28.25, 0.0) - want).abs() < 1e-9);
    let want = cr(i[34], i[35], i[36], i[36], 0.2).max(0.0);
    assert!((t.candela(88.0, 0.0) - want).abs() < 1e-9);
    // Linear between the same values.
    let l = build(&p, Interpolation::Linear, true);
    assert!((l.candela(28.25, 0.0) - (i[11] + (i[12] - i[11]) * 0.3)).abs() < 1e-9);
}

#[test]
fn interpolation_is_continuous_across_nodes_seams_and_symmetry_planes() {
    for (p, name) in [
        (ldt("no_symmetry.ldt"), "no symmetry"),
        (ldt("bilateral_c0_c180.ldt"), "bilateral"),
        (ldt("office_louvre_2x28w.ldt"), "quadrant"),
    ] {
        for interp in Interpolation::ALL {
            let t = build(&p, *interp, true);
            let max = p.max_candela();
            let jump = |a: f64, b: f64| (a - b).abs() <= 1e-5 * max;
            for &c in &p.horizontal_angles {
                for &g in &p.vertical_angles {
                    // Across every node in both directions, and across the mirror planes
                    // (C 0, 90, 180, 270) and the 0/360 seam.
                    let e = 1e-7;
                    let (gl, gh) = ((g - e).max(0.0), (g + e).min(180.0));
                    assert!(
                        jump(t.candela(gl, c), t.candela(gh, c)),
                        "{name} {interp:?} γ {g}"
                    );
                    assert!(
                        jump(t.candela(g, c - e), t.candela(g, c + e)),
                        "{name} {interp:?} C {c}"
                    );
                }
            }
            // Catmull-Rom on these evenly spaced angles also has a continuous slope at
            // every node inside the range (where it is not clamped at zero): one-sided
            // differences agree.
            if *interp == Interpolation::CatmullRom {
                let h = 1e-4;
                for &c in &[17.0, 100.0, 200.0] {
                    for &g in &p.vertical_angles[1..p.vertical_angles.len() - 1] {
                        if t.candela(g - h, c) == 0.0 || t.candela(g + h, c) == 0.0 {
                            continue;
                        }
                        let left = (t.candela(g, c) - t.candela(g - h, c)) / h;
                        let right = (t.candela(g + h, c) - t.candela(g, c)) / h;
                        assert!(
                            (left - right).abs() <= 1e-3 * max,
                            "{name} γ {g} C {c}: slope {left} vs {right}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn catmull_rom_never_goes_below_zero_and_may_overshoot_above() {
    // A hard cut-off: 1000 cd to 10°, then nothing.
    let v: Vec<f64> = (0..=18).map(|i| 5.0 * i as f64).collect();
    let f = synth(
        1,
        &v,
        &[0.0],
        |_, g| if g <= 10.0 { 1000.0 } else { 0.0 },
        1.0,
    );
    let p = Photometry::from_ies(&f).unwrap();
    let t = build(&p, Interpolation::CatmullRom, true);
    let mut lo = f64::INFINITY;
    let mut hi = 0.0f64;
    for i in 0..=9000 {
        let c = t.candela(i as f64 * 0.01, 0.0);
        lo = lo.min(c);
        hi = hi.max(c);
    }
    assert_eq!(lo, 0.0);
    // Between 15° and 20° the cubic is −500 t (1 − t)² (< 0): clamped to 0.
    assert!(cr(1000.0, 0.0, 0.0, 0.0, 0.5) < 0.0);
    assert_eq!(t.candela(17.5, 0.0), 0.0);
    // Between 5° and 10° it rises above 1000 by up to 500 · 4/27 (documented).
    let peak = 1000.0 + 500.0 * 4.0 / 27.0;
    assert!(hi > 1000.0 && hi <= peak + 1e-6, "{hi}");
    // Linear neither undershoots nor overshoots.
    let l = build(&p, Interpolation::Linear, true);
    for i in 0..=900 {
        let c = l.candela(i as f64 * 0.1, 0.0);
        assert!((0.0..=1000.0).contains(&c));
    }
}

#[test]
fn both_interpolations_keep_the_flux_of_the_realistic_file() {
    let p = ldt("office_louvre_2x28w.ldt");
    let lin = build(&p, Interpolation::Linear, true).luminous_flux();
    let cub = build(&p, Interpolation::CatmullRom, true).luminous_flux();
    assert!((lin - 3879.2).abs() / 3879.2 < 5e-3, "{lin}");
    assert!((cub - lin).abs() / lin < 5e-3, "{cub} vs {lin}");
}
