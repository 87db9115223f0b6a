//! Goniometric luminaires (EP 0613099): IES parsing, the light table (symmetry folding,
//! constant ranges, interpolation, distance series) and room lighting.

use glam::DVec3;
use lut_core::{
    lux_at, shade_frame, IesError, IesFile, IesFormat, LightError, LightScene, LightTable,
    Luminaire, PhotometricType, Room, ShadeOptions, Symmetry, TableOptions, Tilt,
};
use lut_core::{Camera, View};
use std::path::PathBuf;
use std::sync::Arc;
use test_support::geometry::room_hit;

use test_support::light_fixtures::synth;

fn data(name: &str) -> PathBuf {
    test_support::test_data("ies").join(name)
}

fn table(f: &IesFile) -> LightTable {
    LightTable::from_ies(f, &TableOptions::default()).unwrap()
}

/// Relative closeness: |a − b| ≤ tol · max(|b|, 1).
fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1.0)
}

// ---------------------------------------------------------------- sample files

#[test]
fn sample_files_parse_with_the_right_counts() {
    let f = IesFile::load(&data("label_lines.ies")).unwrap();
    assert_eq!(f.format, IesFormat::Lm63_1995);
    assert_eq!(f.photometric_type, PhotometricType::C);
    assert_eq!(
        (f.vertical_angles.len(), f.horizontal_angles.len()),
        (37, 1)
    );
    assert_eq!(f.candela.len(), 37);
    assert_eq!(f.keyword("LUMCAT"), Some("BD0150"));
    assert_eq!(f.max_candela(), 2200.0);
    assert_eq!(table(&f).symmetry(), Symmetry::Rotational);

    let f = IesFile::load(&data("relative_photometry_with_multiplier.ies")).unwrap();
    assert_eq!(f.rated_lumens(), Some(500.0));
    assert_eq!(f.candela_multiplier, 1.5);
    assert!(close(f.max_candela(), 3300.0, 1e-12));

    let f = IesFile::load(&data("absolute_photometry.ies")).unwrap();
    assert_eq!(f.rated_lumens(), None);

    let f = IesFile::load(&data("type_b_full.ies")).unwrap();
    assert_eq!(f.format, IesFormat::Lm63_2019);
    assert_eq!(f.photometric_type, PhotometricType::B);
    assert_eq!((f.vertical_angles.len(), f.horizontal_angles.len()), (5, 5));
    assert_eq!(f.max_candela(), 25000.0);
    assert_eq!(f.input_watts, 200.0);
    assert_eq!(table(&f).symmetry(), Symmetry::Lateral);

    let f = IesFile::load(&data("tilt_include_v19.ies")).unwrap();
    assert_eq!(f.format, IesFormat::Lm63_2019);
    assert_eq!((f.vertical_angles.len(), f.horizontal_angles.len()), (5, 3));
    match &f.tilt {
        Tilt::Include(t) => {
            assert_eq!((t.geometry, t.angles.len(), t.factors.len()), (1, 7, 7));
            assert_eq!(t.factor_at(45.0), 0.90);
        }
        Tilt::None => panic!("tilt block not read"),
    }
    assert_eq!(table(&f).symmetry(), Symmetry::Quadrant);
}

#[test]
fn rotational_lumens_match_a_hand_integration() {
    // Integrate the rotational label_lines distribution by the trapezoid rule over its
    // 2.5° steps: Φ = 2π ∫ I(γ) sin γ dγ. The table's 0.25° midpoint rule on linear
    // interpolation agrees within 0.5% (the difference is the quadrature, not the table).
    let f = IesFile::load(&data("label_lines.ies")).unwrap();
    let t = table(&f);
    let v = &f.vertical_angles;
    let mut hand = 0.0;
    for i in 0..v.len() - 1 {
        let (a, b) = (v[i].to_radians(), v[i + 1].to_radians());
        let ya = f.candela[i] * a.sin();
        let yb = f.candela[i + 1] * b.sin();
        hand += 0.5 * (ya + yb) * (b - a);
    }
    hand *= 2.0 * std::f64::consts::PI;
    let flux = t.luminous_flux();
    assert!(close(flux, hand, 5e-3), "flux {flux} vs hand {hand}");
}

// ---------------------------------------------------------------- malformed files

const GOOD: &str = "IESNA:LM-63-2002\n[TEST] t\nTILT=NONE\n1 -1 1 3 2 1 2 0 0 0\n1 1 10\n0 45 90\n0 90\n100 50 0\n90 40 0\n";

fn err(text: &str) -> IesError {
    IesFile::parse(text, "bad.ies").expect_err("must fail")
}

fn line_of(e: &IesError) -> usize {
    match e {
        IesError::Syntax { line, .. } | IesError::Truncated { line, .. } => *line,
        IesError::TiltFileUnsupported { line, .. } => *line,
        other => panic!("unexpected error {other:?}"),
    }
}

#[test]
fn good_fixture_parses() {
    let f = IesFile::parse(GOOD, "good.ies").unwrap();
    assert_eq!(f.candela, vec![100.0, 50.0, 0.0, 90.0, 40.0, 0.0]);
}

#[test]
fn truncated_value_list_errors_at_the_last_line() {
    let e = err(GOOD.trim_end().strip_suffix(" 0").unwrap());
    assert!(matches!(e, IesError::Truncated { .. }), "{e:?}");
    assert_eq!(line_of(&e), 9);
    let msg = e.to_string();
    assert!(
        msg.starts_with("bad.ies:9:") && msg.contains("candela value 3 of 3"),
        "{msg}"
    );
    // Truncated in the angle lists.
    let e = err("TILT=NONE\n1 -1 1 3 2 1 2 0 0 0\n1 1 10\n0 45\n");
    assert!(e.to_string().contains("vertical angle 3 of 3"), "{e}");
}

#[test]
fn bad_tilt_blocks_error_cleanly() {
    let e = err(&GOOD.replace("TILT=NONE", "TILT=lamp.tlt"));
    assert_eq!(
        e,
        IesError::TiltFileUnsupported {
            file: "bad.ies".into(),
            line: 3,
            name: "lamp.tlt".into()
        }
    );
    assert!(e.to_string().contains("not supported"));
    let e = err(&GOOD.replace("TILT=NONE", "TILT="));
    assert_eq!(line_of(&e), 3);
    // INCLUDE with a geometry out of range.
    let e = err(&GOOD.replace("TILT=NONE", "TILT=INCLUDE\n7\n2\n0 90\n1 0.5"));
    assert!(
        e.to_string()
            .contains("bad.ies:4: expected the TILT=INCLUDE lamp-to-luminaire geometry"),
        "{e}"
    );
    // INCLUDE with a non-number factor.
    let e = err(&GOOD.replace("TILT=NONE", "TILT=INCLUDE\n1\n2\n0 90\n1 half"));
    assert_eq!(line_of(&e), 7);
    assert!(e.to_string().contains("tilt factor 2 of 2"), "{e}");
    // INCLUDE whose factors run into the lamp data: the counts then fail somewhere later,
    // still with a line number and no panic.
    let e = err(&GOOD.replace("TILT=NONE", "TILT=INCLUDE\n1\n3\n0 45 90\n1 1"));
    assert!(line_of(&e) > 0);
    // No TILT line at all.
    let e = err("IESNA:LM-63-2002\n[TEST] t\n");
    assert!(e.to_string().contains("TILT="), "{e}");
}

#[test]
fn negative_or_fractional_counts_error_with_the_line() {
    let e = err(&GOOD.replace("1 -1 1 3 2", "1 -1 1 -3 2"));
    assert_eq!(line_of(&e), 4);
    assert!(e.to_string().contains("number of vertical angles"), "{e}");
    assert!(e.to_string().contains("'-3'"), "{e}");
    let e = err(&GOOD.replace("1 -1 1 3 2", "1 -1 1 3 2.5"));
    assert!(e.to_string().contains("number of horizontal angles"), "{e}");
    let e = err(&GOOD.replace("1 -1 1 3 2 1", "1 -1 1 3 2 4"));
    assert!(e.to_string().contains("photometric type"), "{e}");
    let e = err(&GOOD.replace("1 -1 1 3", "1 -7 1 3"));
    assert!(e.to_string().contains("lumens per lamp"), "{e}");
}

#[test]
fn non_numbers_and_bad_angles_error_with_the_line() {
    let e = err(&GOOD.replace("90 40 0", "90 forty 0"));
    assert_eq!(line_of(&e), 9);
    assert!(e.to_string().contains("'forty'"), "{e}");
    let e = err(&GOOD.replace("0 45 90\n", "0 45 nan\n"));
    assert_eq!(line_of(&e), 6);
    let e = err(&GOOD.replace("0 45 90\n", "0 90 45\n"));
    assert!(e.to_string().contains("larger than the previous"), "{e}");
    let e = err(&GOOD.replace("0 45 90\n", "0 45 200\n"));
    assert!(e.to_string().contains("in [0, 180]"), "{e}");
    let e = err(&format!("{GOOD}7\n"));
    assert_eq!(line_of(&e), 10);
    assert!(e.to_string().contains("end of the data"), "{e}");
}

#[test]
fn error_messages_escape_control_characters_from_the_file() {
    // An escape sequence in a value: the message shows it escaped, never raw.
    let e = err(&GOOD.replace("90 40 0", "90 \x1b[2J\x1b[31mred 0"));
    let msg = e.to_string();
    assert!(!msg.chars().any(|c| c.is_control()), "{msg:?}");
    assert!(msg.contains("'\\u{1b}[2J\\u{1b}[31mred'"), "{msg}");
    assert_eq!(line_of(&e), 9);
    // In a TILT= file name and in trailing data; bidi overrides too; long text is cut.
    let e = err(&GOOD.replace("TILT=NONE", "TILT=\x07lamp\u{202e}.tlt"));
    let msg = e.to_string();
    assert!(
        !msg.chars().any(|c| c.is_control() || c == '\u{202e}'),
        "{msg:?}"
    );
    assert!(msg.contains("TILT=\\u{7}lamp\\u{202e}.tlt"), "{msg}");
    let e = err(&format!("{GOOD}\x1b{}\n", "z".repeat(200)));
    let msg = e.to_string();
    assert!(!msg.chars().any(|c| c.is_control()), "{msg:?}");
    assert!(msg.contains('…') && msg.len() < 200, "{msg}");
}

#[test]
fn undeclared_symmetry_is_an_error_naming_the_angle_line() {
    let f = IesFile::parse(&GOOD.replace("\n0 90\n", "\n0 120\n"), "odd.ies").unwrap();
    let e = LightTable::from_ies(&f, &TableOptions::default()).unwrap_err();
    assert!(e.to_string().starts_with("odd.ies:7:"), "{e}");
}

// ---------------------------------------------------------------- symmetry folding

/// A value that differs at every (h, v) pair.
fn pattern(h: f64, v: f64) -> f64 {
    1000.0 + 7.0 * h + 3.0 * v + ((h * 13.0 + v * 5.0) % 17.0)
}

/// Folded lookups at mirrored horizontal angles equal the stored value (× multiplier).
fn check_mirrors(t: &LightTable, f: &IesFile, mirrors: &dyn Fn(f64) -> Vec<f64>) {
    let nv = f.vertical_angles.len();
    for (ih, &h) in f.horizontal_angles.iter().enumerate() {
        for (iv, &v) in f.vertical_angles.iter().enumerate() {
            let stored = f.candela[ih * nv + iv] * f.candela_multiplier;
            for m in mirrors(h) {
                let got = t.candela(v, m);
                // f64 storage, normalized by 1/d_ref² and back: 1e-12 relative.
                assert!(
                    close(got, stored, 1e-12),
                    "h {h} mirrored {m} v {v}: {got} vs {stored}"
                );
            }
        }
    }
}

#[test]
fn quadrant_symmetry_folds_all_four_quadrants() {
    let f = synth(
        1,
        &[0.0, 30.0, 60.0, 90.0],
        &[0.0, 30.0, 60.0, 90.0],
        pattern,
        1.5,
    );
    let t = table(&f);
    assert_eq!(t.symmetry(), Symmetry::Quadrant);
    assert_eq!(t.level_size(0), Some((4, 4)));
    check_mirrors(&t, &f, &|c| {
        vec![c, 180.0 - c, 180.0 + c, 360.0 - c, c - 360.0, c + 720.0]
    });
}

#[test]
fn bilateral_0_180_symmetry_folds() {
    let h: Vec<f64> = (0..=4).map(|i| i as f64 * 45.0).collect();
    let f = synth(1, &[0.0, 45.0, 90.0, 135.0, 180.0], &h, pattern, 1.0);
    let t = table(&f);
    assert_eq!(t.symmetry(), Symmetry::Bilateral0To180);
    check_mirrors(&t, &f, &|c| vec![c, 360.0 - c, -c]);
}

#[test]
fn bilateral_90_270_symmetry_folds() {
    let h: Vec<f64> = (0..=4).map(|i| 90.0 + i as f64 * 45.0).collect();
    let f = synth(1, &[0.0, 45.0, 90.0], &h, pattern, 1.0);
    let t = table(&f);
    assert_eq!(t.symmetry(), Symmetry::Bilateral90To270);
    check_mirrors(&t, &f, &|c| {
        vec![c, (180.0 - c).rem_euclid(360.0), 180.0 - c]
    });
}

#[test]
fn rotational_symmetry_ignores_the_horizontal_angle() {
    let f = synth(1, &[0.0, 45.0, 90.0], &[0.0], pattern, 1.0);
    let t = table(&f);
    assert_eq!(t.symmetry(), Symmetry::Rotational);
    check_mirrors(&t, &f, &|_| vec![0.0, 17.0, 123.0, 271.5, -40.0]);
}

#[test]
fn no_symmetry_wraps_around_360() {
    let h: Vec<f64> = (0..12).map(|i| i as f64 * 30.0).collect(); // 0..330
    let f = synth(1, &[0.0, 90.0, 180.0], &h, pattern, 1.0);
    let t = table(&f);
    assert_eq!(t.symmetry(), Symmetry::None);
    check_mirrors(&t, &f, &|c| vec![c, c + 360.0, c - 360.0]);
    // Between 330 and 360 (= 0) the value interpolates linearly across the wrap.
    let (a, b) = (pattern(330.0, 90.0), pattern(0.0, 90.0));
    assert!(close(t.candela(90.0, 340.0), a + (b - a) / 3.0, 1e-12));
}

#[test]
fn lateral_symmetry_of_type_b_mirrors_left_and_right() {
    let f = IesFile::load(&data("type_b_full.ies")).unwrap();
    let t = table(&f);
    check_mirrors(&t, &f, &|h| vec![h, -h]);
    // Outside the measured horizontal range (behind the floodlight) there is no light.
    assert_eq!(t.candela(0.0, 120.0), 0.0);
}

#[test]
fn direction_angles_follow_the_documented_frames() {
    // Type C: the aim is γ = 0; C = 0 toward the light's up axis, C = 90 toward its left.
    let f = synth(
        1,
        &[0.0, 90.0, 180.0],
        &[0.0, 90.0, 180.0, 270.0, 360.0],
        pattern,
        1.0,
    );
    let t = table(&f);
    let (g, c) = t.angles_of(DVec3::new(0.0, 1.0, 0.0));
    assert!(close(g, 90.0, 1e-12) && close(c, 0.0, 1e-12));
    let (g, c) = t.angles_of(DVec3::new(-1.0, 0.0, 0.0));
    assert!(close(g, 90.0, 1e-12) && close(c, 90.0, 1e-12));
    assert!(close(t.angles_of(DVec3::Z).0, 0.0, 1e-12));
    assert!(close(
        t.candela_dir(DVec3::new(1.0, 0.0, 0.0)),
        pattern(270.0, 90.0),
        1e-12
    ));
    // Type B: H is left-right (asin x), V is up-down (plane angle about the lateral axis).
    let b = table(&IesFile::load(&data("type_b_full.ies")).unwrap());
    let s = 0.5f64.sqrt();
    let (v, h) = b.angles_of(DVec3::new(s, 0.0, s));
    assert!(close(v, 0.0, 1e-12) && close(h, 45.0, 1e-12));
    let (v, h) = b.angles_of(DVec3::new(0.0, s, s));
    assert!(close(v, 45.0, 1e-12) && close(h, 0.0, 1e-12));
}

// ---------------------------------------------------------------- interpolation

#[test]
fn interpolation_is_exact_at_measured_angles_and_linear_between() {
    // Uneven vertical angles (bisection path) and even horizontal angles (multiply path).
    let v = [0.0, 10.0, 35.0, 90.0];
    let h = [0.0, 45.0, 90.0];
    let f = synth(1, &v, &h, pattern, 1.0);
    let t = table(&f);
    for &hh in &h {
        for &vv in &v {
            assert!(close(t.candela(vv, hh), pattern(hh, vv), 1e-12));
        }
    }
    for (i, j, fv, fh) in [(0, 0, 0.5, 0.0), (1, 0, 0.2, 0.7), (2, 1, 0.9, 0.25)] {
        let vv = v[i] + (v[i + 1] - v[i]) * fv;
        let hh = h[j] + (h[j + 1] - h[j]) * fh;
        let c00 = pattern(h[j], v[i]);
        let c01 = pattern(h[j], v[i + 1]);
        let c10 = pattern(h[j + 1], v[i]);
        let c11 = pattern(h[j + 1], v[i + 1]);
        let a = c00 + (c01 - c00) * fv;
        let b = c10 + (c11 - c10) * fv;
        let want = a + (b - a) * fh;
        assert!(close(t.candela(vv, hh), want, 1e-12), "({vv}, {hh})");
    }
}

#[test]
fn sample_file_interpolates_between_measured_angles() {
    let f = IesFile::load(&data("relative_photometry_with_multiplier.ies")).unwrap();
    let t = table(&f);
    // γ = 3.75 lies halfway between 2.5 (2000.2) and 5 (1950.0); × 1.5.
    assert!(close(
        t.candela(3.75, 0.0),
        1.5 * (2000.2 + 1950.0) / 2.0,
        1e-12
    ));
    // Zero outside the measured vertical range 0..90.
    assert_eq!(t.candela(95.0, 0.0), 0.0);
    assert_eq!(t.candela(-1.0, 0.0), 0.0);
}

// ---------------------------------------------------------------- constant ranges

#[test]
fn constant_ranges_are_not_stored_and_are_substituted() {
    // 5 cd up to 20°, varying to 60°, zero from 70° to 180° (a cut-off).
    let v: Vec<f64> = (0..=18).map(|i| i as f64 * 10.0).collect();
    let h = [0.0, 90.0];
    let val = |hh: f64, vv: f64| {
        if vv <= 20.0 {
            5.0
        } else if vv >= 70.0 {
            0.0
        } else {
            100.0 + hh + vv
        }
    };
    let f = synth(1, &v, &h, val, 1.0);
    let t = table(&f);
    let (_, stored) = t.level_size(0).unwrap();
    // Rows 20..=70 are stored (the boundary rows stay for interpolation): 6 of 19.
    assert_eq!(stored, 6);
    for vv in [0.0f64, 5.0, 20.0, 65.0, 70.0, 75.0, 120.0, 180.0] {
        for hh in [0.0f64, 45.0, 90.0, 200.0] {
            let hf = if hh > 90.0 { 180.0 - hh } else { hh };
            let hf = hf.abs();
            // Exact values where constant; linear elsewhere (check vs the pattern).
            let want = if vv <= 20.0 {
                5.0
            } else if vv >= 70.0 {
                0.0
            } else {
                let lo = (vv / 10.0).floor() * 10.0;
                let a = val(0.0, lo) + (val(90.0, lo) - val(0.0, lo)) * hf / 90.0;
                let b =
                    val(0.0, lo + 10.0) + (val(90.0, lo + 10.0) - val(0.0, lo + 10.0)) * hf / 90.0;
                a + (b - a) * (vv - lo) / 10.0
            };
            assert!(close(t.candela(vv, hh), want, 1e-12), "({vv}, {hh})");
        }
    }
}

// ---------------------------------------------------------------- distance series

#[test]
fn distance_series_halves_and_interpolates_by_log_distance() {
    let v: Vec<f64> = (0..=36).map(|i| i as f64 * 5.0).collect();
    let h: Vec<f64> = (0..=8).map(|i| i as f64 * 22.5).collect();
    let f = synth(
        1,
        &v,
        &h,
        |hh, vv| 100.0 + (vv * 0.7).sin().abs() * 900.0 + hh,
        1.0,
    );
    // The plain series (the patent's halving, not checked against the measured table).
    let opts = TableOptions {
        reference_distance: 2.0,
        max_levels: 4,
        series_tolerance: None,
        ..TableOptions::default()
    };
    let t = LightTable::from_ies(&f, &opts).unwrap();
    assert_eq!(t.level_count(), 4);
    let sizes: Vec<_> = (0..4).map(|k| t.level_size(k).unwrap()).collect();
    assert_eq!(sizes, vec![(9, 37), (5, 19), (3, 10), (2, 6)]);
    let dir = DVec3::new(0.3, -0.4, 0.8).normalize();
    let (vv, hh) = t.angles_of(dir);
    let lvl = |k: usize| t.level_candela(k, vv, hh).unwrap();
    // d ≤ d_ref: the full table with inverse square.
    for d in [0.5, 1.0, 2.0] {
        assert!(close(t.illuminance_normal(dir, d) * d * d, lvl(0), 1e-9));
    }
    // d = d_ref·2^k: table k exactly; between: linear in D = log2(d / d_ref).
    for k in 0..4 {
        let d = 2.0 * 2f64.powi(k as i32);
        assert!(
            close(t.illuminance_normal(dir, d) * d * d, lvl(k), 1e-9),
            "level {k}"
        );
    }
    let d = 2.0 * 2f64.powf(1.25);
    let want = lvl(1) + (lvl(2) - lvl(1)) * 0.25;
    assert!(close(t.illuminance_normal(dir, d) * d * d, want, 1e-9));
    // Far beyond the series: the coarsest table, still with inverse square.
    for d in [1e3, 1e6] {
        assert!(close(t.illuminance_normal(dir, d) * d * d, lvl(3), 1e-9));
    }
}

#[test]
fn distance_series_tends_to_the_far_field_table_for_smooth_light() {
    // I(γ) = 1000 + 500 cos γ sampled every 5°. The [¼ ½ ¼] pre-filter maps cos γ to
    // cos γ · (1 + cos s)/2 at step s, exactly, also at the mirrored poles (cos is even
    // about 0° and 180°). So level k holds, at its own angles,
    //     1000 + 500 cos γ · Π_{j<k} (1 + cos s_j)/2,   s_j = 5°, 10°, 20°,
    // and as the steps shrink the product tends to 1: the series tends to the far-field
    // (measured) table.
    let v: Vec<f64> = (0..=36).map(|i| i as f64 * 5.0).collect();
    let far = |g: f64| 1000.0 + 500.0 * g.to_radians().cos();
    let f = synth(1, &v, &[0.0], |_, g| far(g), 1.0);
    let plain = TableOptions {
        series_tolerance: None,
        ..TableOptions::default()
    };
    let t = LightTable::from_ies(&f, &plain).unwrap();
    assert_eq!(t.level_count(), 4);
    let level_angles: [Vec<f64>; 4] = [
        v.clone(),
        (0..=18).map(|i| i as f64 * 10.0).collect(),
        (0..=9).map(|i| i as f64 * 20.0).collect(),
        vec![0.0, 40.0, 80.0, 120.0, 160.0, 180.0],
    ];
    let mut damp = 1.0;
    for (k, angles) in level_angles.iter().enumerate() {
        for &g in angles {
            let want = 1000.0 + 500.0 * g.to_radians().cos() * damp;
            let got = t.level_candela(k, g, 0.0).unwrap();
            // f64 storage, normalized by 1/d_ref² and back: 1e-12 relative.
            assert!(close(got, want, 1e-12), "level {k} γ {g}: {got} vs {want}");
        }
        if k < 3 {
            damp *= (1.0 + (5.0 * 2f64.powi(k as i32)).to_radians().cos()) / 2.0;
        }
    }
    // Measured every 1°, every level stays within 0.5% of the far-field values at any angle
    // (damping ≤ 0.2% plus linear interpolation ≤ 0.15% at the coarsest 8° step).
    let v1: Vec<f64> = (0..=180).map(|i| i as f64).collect();
    let t1 = LightTable::from_ies(&synth(1, &v1, &[0.0], |_, g| far(g), 1.0), &plain).unwrap();
    assert_eq!(t1.level_count(), 4);
    for k in 0..t1.level_count() {
        for i in 0..=360 {
            let g = i as f64 * 0.5;
            let got = t1.level_candela(k, g, 0.0).unwrap();
            assert!(
                close(got, far(g), 5e-3),
                "level {k} γ {g}: {got} vs {}",
                far(g)
            );
        }
    }
    // A constant table is the same at every level (the filter preserves constants).
    let iso = synth(1, &v, &[0.0], |_, _| 300.0, 1.0);
    let ti = table(&iso);
    assert_eq!(ti.level_count(), 4);
    for k in 0..ti.level_count() {
        assert_eq!(ti.level_candela(k, 77.0, 0.0), Some(300.0));
    }
}

#[test]
fn checked_series_keeps_only_faithful_tables() {
    // The default series stops at the first table that strays more than 0.4 % from the
    // measured one (below 5 % of the peak, 0.4 % of 5 % of the peak).
    let fine: Vec<f64> = (0..=180).map(|i| i as f64).collect();
    let five: Vec<f64> = (0..=36).map(|i| i as f64 * 5.0).collect();
    let smooth = |g: f64| 1000.0 + 500.0 * g.to_radians().cos();
    let spot = |g: f64| 20_000.0 * g.to_radians().cos().max(0.0).powi(40);
    let counts: Vec<usize> = [
        (&fine, &smooth as &dyn Fn(f64) -> f64),
        (&five, &smooth),
        (&five, &spot),
    ]
    .iter()
    .map(|(v, f)| {
        let t = table(&synth(1, v, &[0.0], |_, g| f(g), 1.0));
        // Whatever is kept is faithful, at any angle.
        for k in 0..t.level_count() {
            for i in 0..=1800 {
                let g = i as f64 * 0.1;
                let (a, b) = (t.level_candela(k, g, 0.0).unwrap(), t.candela(g, 0.0));
                let peak = f(0.0).max(f(180.0));
                assert!(
                    (a - b).abs() <= 0.004 * b.max(0.05 * peak) + 1e-9,
                    "level {k} γ {g}"
                );
            }
        }
        t.level_count()
    })
    .collect();
    // Measured every 1°, a broad distribution keeps the whole series; every 5°, the
    // second table (10° steps) already strays; a narrow spot keeps its measured table.
    assert_eq!(counts[0], 4, "{counts:?}");
    assert!(counts[1] < 4, "{counts:?}");
    assert_eq!(counts[2], 1, "{counts:?}");
    // A tolerance must be a finite number ≥ 0.
    let bad = TableOptions {
        series_tolerance: Some(f64::NAN),
        ..TableOptions::default()
    };
    assert!(LightTable::from_ies(&synth(1, &five, &[0.0], |_, g| smooth(g), 1.0), &bad).is_err());
}

// ---------------------------------------------------------------- lighting

fn isotropic(candela: f64) -> Arc<LightTable> {
    let f = synth(1, &[0.0, 90.0, 180.0], &[0.0], |_, _| candela, 1.0);
    Arc::new(table(&f))
}

#[test]
fn isotropic_source_gives_i_cos_over_d_squared() {
    let (w, dep, ht, cam_h) = (6.0, 16.0, 3.0, 1.5);
    let room = Room::new(w, dep, ht, cam_h).unwrap();
    let light_pos = DVec3::new(0.5, 2.9, -1.0);
    let i = 1000.0;
    let mut l = Luminaire::new(isotropic(i), light_pos);
    l.yaw_deg = 30.0; // aim does not matter for an isotropic source
    l.pitch_deg = -60.0;
    let scene = LightScene::new(room, vec![l]).unwrap();
    let origin = DVec3::new(0.0, cam_h, 0.0);
    let mut checked = 0;
    for (yaw, pitch) in [
        (0.0, -90.0),
        (0.0, 0.0),
        (90.0, 20.0),
        (180.0, -30.0),
        (-135.0, 60.0),
    ] {
        let cam = Camera::new(View::new(yaw, pitch, 100.0).unwrap(), 64, 48);
        for py in (0..48).step_by(5) {
            for px in (0..64).step_by(7) {
                let (x, y) = (px as f64 + 0.5, py as f64 + 0.5);
                let (p, n) = room_hit(origin, cam.world_ray(x, y), w, dep, ht);
                let to = light_pos - p;
                let d = to.length();
                let cos = (n.dot(to) / d).max(0.0);
                let want = i * cos / (d * d);
                let got = lux_at(&scene, &cam, x, y);
                // f64 geometry and an exactly representable table value: 1e-9 relative.
                assert!(
                    (got - want).abs() <= 1e-9 * want.max(1e-3),
                    "view ({yaw},{pitch}) pixel ({px},{py}): {got} vs {want} (d = {d})"
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 300);
}

#[test]
fn downlight_distribution_is_read_through_the_aim() {
    // A rotational downlight aimed straight down: the floor point below it gets I(0)/h².
    let f = IesFile::load(&data("relative_photometry_with_multiplier.ies")).unwrap();
    let t = Arc::new(table(&f));
    let room = Room::new(5.0, 5.0, 2.7, 1.6).unwrap();
    let scene = LightScene::new(
        room,
        vec![Luminaire::new(t.clone(), DVec3::new(0.0, 2.7, 0.0))],
    )
    .unwrap();
    let cam = Camera::new(View::new(0.0, -90.0, 90.0).unwrap(), 101, 101);
    let e = lux_at(&scene, &cam, 50.5, 50.5);
    assert!(close(e, 3300.0 / (2.7 * 2.7), 1e-12), "{e}");
    // The upper hemisphere gets nothing: the ceiling is dark.
    let up = Camera::new(View::new(0.0, 90.0, 90.0).unwrap(), 11, 11);
    assert_eq!(lux_at(&scene, &up, 5.5, 5.5), 0.0);
    // Aimed up instead, the floor below gets nothing and the ceiling is lit.
    let mut l = Luminaire::new(t, DVec3::new(0.0, 2.0, 0.0));
    l.pitch_deg = 90.0;
    let scene = LightScene::new(room, vec![l]).unwrap();
    assert_eq!(lux_at(&scene, &cam, 50.5, 50.5), 0.0);
    let e = lux_at(&scene, &up, 5.5, 5.5);
    assert!(close(e, 3300.0 / (0.7 * 0.7), 1e-12), "{e}");
}

#[test]
fn tilt_factor_scales_a_tilted_luminaire() {
    let f = IesFile::load(&data("tilt_include_v19.ies")).unwrap();
    let t = Arc::new(table(&f));
    let room = Room::new(8.0, 8.0, 3.0, 1.5).unwrap();
    let mut l = Luminaire::new(t, DVec3::new(0.0, 2.5, 0.0));
    l.pitch_deg = -45.0; // 45° from nadir: factor 0.90
    assert!(close(l.tilt_deg(), 45.0, 1e-9));
    let lit = LightScene::new(room, vec![l.clone()]).unwrap();
    l.table = Arc::new(table(
        &IesFile::parse(
            &std::fs::read_to_string(data("tilt_include_v19.ies"))
                .unwrap()
                .replace("\r\n", "\n")
                .replace(
                    "TILT=INCLUDE\n1\n7\n0 15 30 45 60 75 90\n1.0 0.98 0.95 0.90 0.85 0.80 0.75\n",
                    "TILT=NONE\n",
                ),
            "notilt.ies",
        )
        .unwrap(),
    ));
    let plain = LightScene::new(room, vec![l]).unwrap();
    let p = DVec3::new(0.0, 0.0, 2.0);
    let (a, b) = (lit.illuminance(p, DVec3::Y), plain.illuminance(p, DVec3::Y));
    assert!(b > 0.0 && close(a, 0.9 * b, 1e-9), "{a} vs {b}");
}

#[test]
fn scene_rejects_bad_input() {
    let room = Room::new(4.0, 4.0, 2.5, 1.5).unwrap();
    let e = LightScene::new(
        room,
        vec![Luminaire::new(isotropic(1.0), DVec3::new(0.0, 3.0, 0.0))],
    );
    assert!(matches!(
        e,
        Err(LightError::LightOutsideRoom { index: 0, .. })
    ));
    assert!(Room::new(4.0, 0.0, 2.5, 1.0).is_err());
    assert!(Room::new(4.0, 4.0, 2.5, 2.5).is_err());
    assert!(Room::new(f64::NAN, 4.0, 2.5, 1.0).is_err());
    let scene = LightScene::new(room, vec![]).unwrap();
    let cam = Camera::new(View::default(), 4, 4);
    let mut small = vec![0u32; 15];
    let r = shade_frame(&scene, &cam, &mut small, 4, 4, &ShadeOptions::default());
    assert!(matches!(r, Err(LightError::BufferSize { len: 15, .. })));
    let bad = ShadeOptions {
        exposure: f64::NAN,
        ..Default::default()
    };
    let mut ok = vec![0u32; 16];
    assert!(shade_frame(&scene, &cam, &mut ok, 4, 4, &bad).is_err());
}

#[test]
fn shading_multiplies_albedo_by_the_light_factor() {
    let room = Room::new(5.0, 5.0, 2.7, 1.6).unwrap();
    let cam = Camera::new(View::new(0.0, -90.0, 90.0).unwrap(), 9, 9);
    let albedo = 0x80_40_c0u32;
    // No lights, ambient 1: the frame is unchanged (sRGB → linear → sRGB round trip).
    let scene = LightScene::new(room, vec![]).unwrap();
    let mut f = vec![albedo; 81];
    let opts = ShadeOptions {
        ambient: 1.0,
        ..Default::default()
    };
    shade_frame(&scene, &cam, &mut f, 9, 9, &opts).unwrap();
    assert!(f.iter().all(|&p| p == albedo));
    // Ambient 0 and an isotropic light of I cd at height h over the floor centre, with
    // exposure 1/E: the centre pixel (lit at exactly E = I/h²) keeps its albedo.
    let (i, h) = (500.0, 2.0);
    let scene = LightScene::new(
        room,
        vec![Luminaire::new(isotropic(i), DVec3::new(0.0, h, 0.0))],
    )
    .unwrap();
    let mut f = vec![albedo; 81];
    let opts = ShadeOptions {
        ambient: 0.0,
        exposure: h * h / i,
        ..Default::default()
    };
    shade_frame(&scene, &cam, &mut f, 9, 9, &opts).unwrap();
    assert_eq!(f[4 * 9 + 4], albedo);
    // Off-centre floor pixels get less light (cos θ / d²): darker, never brighter.
    assert!(f.iter().all(|&p| ((p >> 16) & 0xff) <= 0x80));
    assert!(((f[0] >> 16) & 0xff) < 0x80);
}

#[test]
fn shading_is_identical_on_one_and_many_threads() {
    let f = IesFile::load(&data("tilt_include_v19.ies")).unwrap();
    let t = Arc::new(table(&f));
    let room = Room::new(6.0, 5.0, 3.0, 1.5).unwrap();
    let mut a = Luminaire::new(t.clone(), DVec3::new(1.0, 2.8, 1.0));
    a.yaw_deg = 20.0;
    let mut b = Luminaire::new(t, DVec3::new(-2.0, 2.0, -1.0));
    b.pitch_deg = -30.0;
    let scene = LightScene::new(room, vec![a, b]).unwrap();
    let cam = Camera::new(View::new(40.0, -20.0, 110.0).unwrap(), 96, 64);
    let base: Vec<u32> = (0..96 * 64)
        .map(|i| (i as u32).wrapping_mul(2_654_435_761) & 0xff_ffff)
        .collect();
    let run = |threads: usize, false_color: bool| {
        let mut fr = base.clone();
        let opts = ShadeOptions {
            false_color,
            ..Default::default()
        };
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| shade_frame(&scene, &cam, &mut fr, 96, 64, &opts).unwrap());
        fr
    };
    assert_eq!(run(1, false), run(3, false));
    assert_eq!(run(1, true), run(3, true));
    assert_ne!(run(1, false), run(1, true));
}

#[test]
fn series_lookup_matches_the_tables_inside_and_outside_constant_ranges() {
    // A cut-off at 60° (zero beyond, not stored) and a measured range ending at 150°:
    // the series lookup, which skips the horizontal angle in constant ranges, must equal
    // the blend of the two tables' own lookups everywhere.
    let v: Vec<f64> = (0..=30).map(|i| i as f64 * 5.0).collect();
    let h: Vec<f64> = (0..=8).map(|i| i as f64 * 45.0).collect();
    let f = synth(
        1,
        &v,
        &h,
        |hh, g| {
            if g >= 60.0 {
                0.0
            } else {
                500.0 + 3.0 * hh - 4.0 * g
            }
        },
        1.0,
    );
    let t = LightTable::from_ies(
        &f,
        &TableOptions {
            reference_distance: 1.0,
            max_levels: 3,
            series_tolerance: None,
            ..TableOptions::default()
        },
    )
    .unwrap();
    assert!(t.level_size(0).unwrap().1 < v.len());
    let mut n = 0;
    for i in 0..40 {
        let th = (i as f64 * 4.7).to_radians();
        let ph = (i as f64 * 37.0).to_radians();
        let dir = DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
        let (vv, hh) = t.angles_of(dir);
        for d in [0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 9.0] {
            let big_d = f64::log2(f64::max(d, 1.0)).min(2.0);
            let k = big_d.floor() as usize;
            let frac = big_d - k as f64;
            let a = t.level_candela(k, vv, hh).unwrap();
            let b = t.level_candela((k + 1).min(2), vv, hh).unwrap();
            let want = (a + (b - a) * frac) / (d * d);
            let got = t.illuminance_normal(dir, d);
            assert!(
                close(got, want, 1e-12),
                "γ {vv} C {hh} d {d}: {got} vs {want}"
            );
            n += (vv > 150.0 || a == 0.0) as usize;
        }
    }
    assert!(n > 0, "no direction fell in a constant range");
}
