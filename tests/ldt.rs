//! EULUMDAT (.ldt): parsing, the same candela as the equivalent IES file for every
//! symmetry indicator, relative and absolute photometry, malformed files, choosing the
//! format by content.

use lut_core::{
    detect_format, IesFile, Interpolation, LdtError, LdtFile, LdtSymmetry, LdtType, LightError,
    LightFileFormat, LightTable, Named, Photometry, PhotometrySource, Symmetry, TableOptions,
};
use std::path::PathBuf;

use test_support::light_fixtures::sphere;

fn ldt_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/ldt")
        .join(name)
}

fn ies_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/ies")
        .join(name)
}

fn read(p: &PathBuf) -> String {
    std::fs::read_to_string(p).unwrap()
}

fn opts(interpolation: Interpolation) -> TableOptions {
    TableOptions {
        interpolation,
        ..TableOptions::default()
    }
}

/// Relative closeness: |a − b| ≤ tol · max(|b|, 1).
fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1.0)
}

// ---------------------------------------------------------------- the fixtures

#[test]
fn every_symmetry_indicator_parses_with_its_stored_planes() {
    let cases = [
        (
            "rotational_label_lines.ldt",
            LdtSymmetry::VerticalAxis,
            1,
            1,
            37,
        ),
        ("no_symmetry.ldt", LdtSymmetry::None, 24, 24, 37),
        (
            "bilateral_c0_c180.ldt",
            LdtSymmetry::PlaneC0C180,
            24,
            13,
            37,
        ),
        (
            "bilateral_c90_c270.ldt",
            LdtSymmetry::PlaneC90C270,
            24,
            13,
            37,
        ),
        (
            "quadrant_tilt_include.ldt",
            LdtSymmetry::BothPlanes,
            8,
            3,
            5,
        ),
        (
            "office_louvre_2x28w.ldt",
            LdtSymmetry::BothPlanes,
            24,
            7,
            37,
        ),
    ];
    for (name, sym, mc, stored, ng) in cases {
        let f = LdtFile::load(&ldt_path(name)).unwrap();
        assert_eq!(f.symmetry, sym, "{name}");
        assert_eq!(f.c_plane_count(), mc, "{name}");
        assert_eq!(f.stored_c_angles().len(), stored, "{name}");
        assert_eq!(f.gamma_angles.len(), ng, "{name}");
        assert_eq!(f.intensities.len(), stored * ng, "{name}");
    }
    // Isym 3 stores C270 through C0 to C90.
    let f = LdtFile::load(&ldt_path("bilateral_c90_c270.ldt")).unwrap();
    let s = f.stored_c_angles();
    assert_eq!((s[0], s[5], s[6], s[12]), (270.0, 345.0, 0.0, 90.0));
}

#[test]
fn realistic_file_reads_its_header_lamp_sets_and_flux() {
    // CR LF line ends, ISO-8859-1 text, Ityp 2, two lamp sets.
    let f = LdtFile::load(&ldt_path("office_louvre_2x28w.ldt")).unwrap();
    assert_eq!(f.type_indicator, LdtType::Linear);
    assert_eq!(f.luminaire_name, "Einbauleuchte Büro 2x28W T5 Raster");
    assert_eq!(f.luminaire_mm, [597.0, 597.0, 80.0]);
    assert_eq!(f.light_output_ratio, 74.6);
    assert_eq!(f.lamp_sets.len(), 2);
    assert_eq!(f.lamp_sets[0].count, 2);
    assert_eq!(f.lamp_sets[0].total_flux, 5200.0);
    assert_eq!(f.lamp_sets[1].lamp_type, "T5 35W/840 (alternative)");
    assert_eq!(f.direct_ratios[9], 0.96);
    assert!(!f.is_absolute());
    // The intensities refer to the first set; the second scales by its own flux.
    assert_eq!(f.candela_scale(), 5.2);
    assert!(close(f.candela_scale_for(1).unwrap(), 6.6, 1e-15));
    assert_eq!(f.candela_scale_for(2), None);
    // Integrated, the distribution gives LORL % of the first set's lamp flux (the file
    // rounds intensities to 0.1 cd/klm; the table integrates on a 0.25° grid).
    let t = LightTable::from_ldt(&f, &TableOptions::default()).unwrap();
    assert_eq!(t.symmetry(), Symmetry::Quadrant);
    let flux = t.luminous_flux();
    assert!(
        close(flux, f.luminaire_flux(), 5e-3),
        "{flux} vs {}",
        f.luminaire_flux()
    );
    assert!(close(f.luminaire_flux(), 3879.2, 1e-12));
    // No light above the horizontal: those rows are a cut constant range.
    assert!(t.level_size(0).unwrap().1 < 37);
    assert_eq!(t.candela(120.0, 33.0), 0.0);
}

#[test]
fn relative_and_absolute_photometry_scale_by_the_flux() {
    // Relative: 1 lamp of 2000 lm, cd/klm × 2.
    let rel = LdtFile::load(&ldt_path("rotational_label_lines.ldt")).unwrap();
    assert!(!rel.is_absolute());
    assert_eq!(rel.intensities[0], 1100.0);
    assert_eq!(rel.candela_at(0, 0), Some(2200.0));
    let p = Photometry::from_ldt(&rel);
    assert_eq!(p.rated_lumens(), Some(2000.0));
    assert_eq!(p.max_candela(), 2200.0);
    // Absolute: a negative lamp count, the luminaire's 4000 lm; still cd per klm of it.
    let abs = LdtFile::load(&ldt_path("absolute_led.ldt")).unwrap();
    assert!(abs.is_absolute());
    assert_eq!(abs.lamp_sets[0].count, -1);
    assert_eq!(abs.intensities[0], 550.0);
    let p = Photometry::from_ldt(&abs);
    assert_eq!(p.rated_lumens(), None);
    assert_eq!(p.max_candela(), 2200.0);
    // The conversion factor multiplies: 500 lm × 1.5 / 1000 on cd/klm = 2 × cd.
    let conv = LdtFile::load(&ldt_path("relative_conversion.ldt")).unwrap();
    assert_eq!(conv.conversion_factor, 1.5);
    assert_eq!(conv.candela_scale(), 0.75);
    let ies = IesFile::load(&ies_path("relative_photometry_with_multiplier.ies")).unwrap();
    let pl = Photometry::from_ldt(&conv);
    let pi = Photometry::from_ies(&ies).unwrap();
    assert_eq!(pl.candela.len(), pi.candela.len());
    for (a, b) in pl.candela.iter().zip(&pi.candela) {
        assert!(close(*a, *b, 1e-12), "{a} vs {b}");
    }
}

// ---------------------------------------------------------------- LDT = IES

/// The LDT file and its IES twin give the same candela everywhere: at the measured
/// angles, between them, at mirrored C angles, over the whole sphere, and through the
/// distance series; with both interpolations.
fn same_as_ies(ldt: &str, ies: PathBuf, symmetry: Symmetry) {
    let lf = LdtFile::load(&ldt_path(ldt)).unwrap();
    let f = IesFile::load(&ies).unwrap();
    for interp in Interpolation::ALL {
        let tl = LightTable::from_ldt(&lf, &opts(*interp)).unwrap();
        let ti = LightTable::from_ies(&f, &opts(*interp)).unwrap();
        assert_eq!(tl.symmetry(), symmetry, "{ldt}");
        assert_eq!(ti.symmetry(), symmetry, "{ldt}");
        assert_eq!(tl.level_count(), ti.level_count());
        // At every measured angle pair, exactly the file's value (mirrored around).
        let nv = f.vertical_angles.len();
        for (ih, &c) in f.horizontal_angles.iter().enumerate() {
            for (iv, &g) in f.vertical_angles.iter().enumerate() {
                let want = f.candela[ih * nv + iv] * f.candela_multiplier;
                for cc in [c, -c, 180.0 - c, 180.0 + c, c + 360.0] {
                    let mirrored_ok = match symmetry {
                        Symmetry::Quadrant | Symmetry::Rotational => true,
                        Symmetry::Bilateral0To180 => cc == c || cc == -c || cc == c + 360.0,
                        Symmetry::Bilateral90To270 => cc == c || cc == 180.0 - c,
                        _ => cc == c || cc == c + 360.0,
                    };
                    if mirrored_ok {
                        let got = tl.candela(g, cc);
                        assert!(
                            close(got, want, 1e-9),
                            "{ldt} γ {g} C {cc}: {got} vs {want}"
                        );
                    }
                }
            }
        }
        // Between the measured angles and over the sphere, the same to rounding.
        for d in sphere(4000) {
            let (a, b) = (tl.candela_dir(d), ti.candela_dir(d));
            assert!(close(a, b, 1e-9), "{ldt} {interp:?} {d}: {a} vs {b}");
            for dist in [2.0, 9.0, 40.0] {
                let (a, b) = (
                    tl.illuminance_normal(d, dist),
                    ti.illuminance_normal(d, dist),
                );
                assert!(close(a, b, 1e-9), "{ldt} {d} at {dist} m: {a} vs {b}");
            }
        }
    }
}

#[test]
fn isym_1_matches_the_ies_file() {
    same_as_ies(
        "rotational_label_lines.ldt",
        ies_path("label_lines.ies"),
        Symmetry::Rotational,
    );
    same_as_ies(
        "absolute_led.ldt",
        ies_path("absolute_photometry.ies"),
        Symmetry::Rotational,
    );
}

#[test]
fn isym_0_matches_the_ies_file() {
    same_as_ies(
        "no_symmetry.ldt",
        ldt_path("no_symmetry.ies"),
        Symmetry::None,
    );
}

#[test]
fn isym_2_matches_the_ies_file() {
    same_as_ies(
        "bilateral_c0_c180.ldt",
        ldt_path("bilateral_c0_c180.ies"),
        Symmetry::Bilateral0To180,
    );
    same_as_ies(
        "wallwasher_c0_c180.ldt",
        ldt_path("wallwasher_c0_c180.ies"),
        Symmetry::Bilateral0To180,
    );
}

#[test]
fn isym_3_matches_the_ies_file() {
    same_as_ies(
        "bilateral_c90_c270.ldt",
        ldt_path("bilateral_c90_c270.ies"),
        Symmetry::Bilateral90To270,
    );
    // The stored C0 plane (file order: the 7th) is the IES file's C180 plane, and C345
    // reads C195: I(C) = I(180° − C).
    let lf = LdtFile::load(&ldt_path("bilateral_c90_c270.ldt")).unwrap();
    let t = LightTable::from_ldt(&lf, &TableOptions::default()).unwrap();
    let ng = lf.gamma_angles.len();
    for j in 0..ng {
        let g = lf.gamma_angles[j];
        assert!(close(
            t.candela(g, 0.0),
            lf.candela_at(6, j).unwrap(),
            1e-12
        ));
        assert!(close(
            t.candela(g, 180.0),
            lf.candela_at(6, j).unwrap(),
            1e-12
        ));
        assert!(close(
            t.candela(g, 345.0),
            lf.candela_at(5, j).unwrap(),
            1e-12
        ));
        assert!(close(
            t.candela(g, 195.0),
            lf.candela_at(5, j).unwrap(),
            1e-12
        ));
    }
}

#[test]
fn isym_4_matches_the_ies_file() {
    same_as_ies(
        "quadrant_tilt_include.ldt",
        ies_path("tilt_include_v19.ies"),
        Symmetry::Quadrant,
    );
}

#[test]
fn a_decimal_comma_reads_as_a_point() {
    let text = read(&ldt_path("bilateral_c0_c180.ldt"));
    let comma: String = text
        .lines()
        .map(|l| {
            if l.parse::<f64>().is_ok() {
                l.replace('.', ",")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    assert!(comma.contains("0,55"));
    let a = LdtFile::parse(&text, "a.ldt").unwrap();
    let b = LdtFile::parse(&comma, "b.ldt").unwrap();
    assert_eq!(a.intensities, b.intensities);
    assert_eq!(a.direct_ratios, b.direct_ratios);
}

// ---------------------------------------------------------------- malformed files

fn good() -> String {
    read(&ldt_path("bilateral_c0_c180.ldt"))
}

/// The good file with lines (1-based) replaced.
fn with_lines(edits: &[(usize, &str)]) -> String {
    let mut lines: Vec<String> = good().lines().map(String::from).collect();
    for &(n, text) in edits {
        lines[n - 1] = text.to_string();
    }
    lines.join("\n") + "\n"
}

fn with_line(n: usize, text: &str) -> String {
    with_lines(&[(n, text)])
}

fn err(text: &str) -> LdtError {
    LdtFile::parse(text, "bad.ldt").expect_err("must fail")
}

fn line_of(e: &LdtError) -> usize {
    match e {
        LdtError::Syntax { line, .. } | LdtError::Truncated { line, .. } => *line,
        other => panic!("unexpected error {other:?}"),
    }
}

#[test]
fn good_fixture_line_numbers() {
    // The tests below count on this layout: 1 lamp set, so the direct ratios are lines
    // 33-42, the 24 C angles 43-66, the 37 γ angles 67-103, the intensities from 104.
    let g = good();
    let lines: Vec<&str> = g.lines().collect();
    assert_eq!(lines[25], "1");
    assert_eq!(
        (lines[42], lines[43], lines[66], lines[103]),
        ("0", "15", "0", "540")
    );
    assert_eq!(lines.len(), 103 + 13 * 37);
}

#[test]
fn truncated_files_error_at_the_last_line() {
    let g = good();
    let lines: Vec<&str> = g.lines().collect();
    let cut = |n: usize| lines[..n].join("\n") + "\n";
    let e = err(&cut(lines.len() - 1));
    assert!(matches!(e, LdtError::Truncated { .. }), "{e:?}");
    assert_eq!(line_of(&e), lines.len() - 1);
    assert!(e.to_string().contains("intensity 37 of 37"), "{e}");
    assert!(
        e.to_string().starts_with("bad.ldt:583: file ends early"),
        "{e}"
    );
    // In the header and in the lamp set.
    let e = err(&cut(5));
    assert_eq!(line_of(&e), 5);
    assert!(e.to_string().contains("number Ng of intensities"), "{e}");
    let e = err(&cut(28));
    assert!(
        e.to_string().contains("total luminous flux of set 1"),
        "{e}"
    );
    let e = err("");
    assert!(e.to_string().contains("company identification"), "{e}");
}

#[test]
fn bad_counts_error_with_the_line() {
    for (n, text, what) in [
        (4, "-24", "number of C planes Mc"),
        (4, "0", "number of C planes Mc"),
        (4, "2.5", "number of C planes Mc"),
        (6, "x", "number Ng of intensities"),
        (26, "0", "number n of lamp sets"),
        (27, "0", "non-zero number of lamps"),
        (29, "-5", "positive total luminous flux"),
    ] {
        let e = err(&with_line(n, text));
        assert_eq!(line_of(&e), n, "{e}");
        assert!(e.to_string().contains(what), "{e}");
    }
    // Isym 2 stores half the planes: Mc must be even (Isym 4: a multiple of 4).
    let e = err(&with_line(4, "23"));
    assert_eq!(line_of(&e), 4);
    assert!(e.to_string().contains("divisible by 2"), "{e}");
    // Isym 4 on data with a half of the planes: the counts disagree with the data.
    let e = err(&with_line(3, "4"));
    assert_eq!(line_of(&e), 104 + 7 * 37);
    assert!(
        e.to_string()
            .contains("end of the data after 259 intensities"),
        "{e}"
    );
}

#[test]
fn bad_numbers_error_with_the_line_and_the_text() {
    let e = err(&with_line(5, "fifteen"));
    assert_eq!(line_of(&e), 5);
    assert!(e.to_string().contains("'fifteen'"), "{e}");
    let e = err(&with_line(200, "12,3,4"));
    assert_eq!(line_of(&e), 200);
    assert!(e.to_string().contains("intensity"), "{e}");
    let e = err(&with_line(24, "inf"));
    assert!(e.to_string().contains("conversion factor"), "{e}");
    let e = err(&with_line(24, "0"));
    assert!(e.to_string().contains("positive conversion factor"), "{e}");
    let e = err(&with_line(36, "n/a"));
    assert_eq!(line_of(&e), 36);
    assert!(e.to_string().contains("direct ratio 4 of 10"), "{e}");
    // An empty numeric header line.
    let e = err(&with_line(13, ""));
    assert!(e.to_string().contains("found an empty line"), "{e}");
}

#[test]
fn out_of_range_indicators_error_with_the_line() {
    let e = err(&with_line(2, "7"));
    assert_eq!(line_of(&e), 2);
    assert!(e.to_string().contains("type indicator Ityp"), "{e}");
    assert!(e.to_string().contains("0..=3"), "{e}");
    let e = err(&with_line(3, "5"));
    assert_eq!(line_of(&e), 3);
    assert!(e.to_string().contains("symmetry indicator Isym"), "{e}");
    let e = err(&with_line(3, "-1"));
    assert_eq!(line_of(&e), 3);
}

#[test]
fn inconsistent_angles_error_with_the_line() {
    // Dc says 15° but the 3rd C angle is 31°.
    let e = err(&with_line(45, "31"));
    assert_eq!(line_of(&e), 45);
    assert!(
        e.to_string().contains("C angle 3 of 24 (degrees) = 30"),
        "{e}"
    );
    // C planes must start at C0.
    let mut t = with_line(5, "0");
    t = t.replacen("\n0\n15\n30\n", "\n5\n15\n30\n", 1);
    let e = err(&t);
    assert_eq!(line_of(&e), 43);
    assert!(e.to_string().contains("start at C0"), "{e}");
    // Isym 2 with an uneven list (Dc = 0) whose middle plane is not C180.
    let mut t = with_line(5, "0");
    t = t.replacen("\n180\n195\n", "\n181\n195\n", 1);
    let e = err(&t);
    assert_eq!(line_of(&e), 55);
    assert!(e.to_string().contains("C angle 13 = 180"), "{e}");
    // Dg says 5° but a γ angle is off.
    let e = err(&with_line(70, "16"));
    assert_eq!(line_of(&e), 70);
    assert!(e.to_string().contains("Dg = 5"), "{e}");
}

#[test]
fn non_increasing_or_out_of_range_angles_error() {
    let e = err(&with_line(46, "30"));
    assert_eq!(line_of(&e), 46);
    assert!(
        e.to_string().contains("larger than the previous angle 30"),
        "{e}"
    );
    let e = err(&with_line(5, "0").replacen("\n0\n5\n10\n", "\n0\n5\n5\n", 1));
    assert!(e.to_string().contains("larger than the previous"), "{e}");
    let e = err(&with_lines(&[(7, "0"), (103, "190")]));
    assert_eq!(line_of(&e), 103);
    assert!(e.to_string().contains("in [0, 180]"), "{e}");
}

#[test]
fn huge_counts_fail_before_allocating() {
    // Mc past the cap.
    let e = err(&with_line(4, "4000000000"));
    assert_eq!(line_of(&e), 4);
    // Within the caps one by one but not together: 10 000 × 10 000 intensities.
    let e = err(&with_line(3, "0")
        .replacen("\n24\n", "\n10000\n", 1)
        .replacen("\n37\n", "\n10000\n", 1));
    assert_eq!(line_of(&e), 6);
    assert!(e.to_string().contains("at most 4000000 intensities"), "{e}");
    // A lamp-set count past the cap.
    let e = err(&with_line(26, "99999999"));
    assert_eq!(line_of(&e), 26);
}

#[test]
fn trailing_data_is_an_error() {
    let e = err(&format!("{}7\n", good()));
    assert_eq!(line_of(&e), 585);
    assert!(
        e.to_string()
            .contains("end of the data after 481 intensities"),
        "{e}"
    );
    // Trailing blank lines are fine.
    LdtFile::parse(&format!("{}\n\n  \n", good()), "ok.ldt").unwrap();
}

#[test]
fn error_messages_escape_control_characters_from_the_file() {
    let e = err(&with_line(2, "\x1b]0;pwned\x07"));
    let msg = e.to_string();
    assert!(!msg.chars().any(|c| c.is_control()), "{msg:?}");
    assert!(msg.contains("\\u{1b}]0;pwned\\u{7}"), "{msg}");
    let e = err(&with_line(300, &format!("1{}", "\u{202e}9".repeat(50))));
    let msg = e.to_string();
    assert!(!msg.contains('\u{202e}') && msg.contains('…'), "{msg}");
}

// ---------------------------------------------------------------- by content

#[test]
fn the_format_is_chosen_by_content() {
    let ldt = read(&ldt_path("no_symmetry.ldt"));
    let ies = read(&ldt_path("no_symmetry.ies"));
    assert_eq!(detect_format(&ldt), Some(LightFileFormat::Eulumdat));
    assert_eq!(detect_format(&ies), Some(LightFileFormat::Ies));
    // LM-63-1986 has no format line: the TILT= line tells.
    let old = read(&ies_path("label_lines.ies")).replacen("IESNA:LM-63-1995\n", "", 1);
    assert_eq!(detect_format(&old), Some(LightFileFormat::Ies));
    assert_eq!(detect_format("hello\nworld\n"), None);
    // A damaged EULUMDAT file (bad Dc) is still recognized by its two indicators.
    assert_eq!(
        detect_format(&with_line(5, "fifteen")),
        Some(LightFileFormat::Eulumdat)
    );
}

#[test]
fn misnamed_files_load_by_content_both_ways() {
    let dir = tempfile::tempdir().unwrap();
    let as_ies = dir.path().join("really_ldt.ies");
    std::fs::copy(ldt_path("no_symmetry.ldt"), &as_ies).unwrap();
    let as_ldt = dir.path().join("really_ies.ldt");
    std::fs::copy(ldt_path("no_symmetry.ies"), &as_ldt).unwrap();
    let a = Photometry::load(&as_ies).unwrap();
    assert!(matches!(a.source, PhotometrySource::Ldt(_)));
    assert_eq!(a.format_name(), "EULUMDAT");
    let b = Photometry::load(&as_ldt).unwrap();
    assert!(matches!(b.source, PhotometrySource::Ies(_)));
    assert_eq!(b.format_name(), "LM-63-2002");
    // Same distribution, whatever the name.
    let (ta, tb) = (
        LightTable::load(&as_ies).unwrap(),
        LightTable::load(&as_ldt).unwrap(),
    );
    for d in sphere(500) {
        assert!(close(ta.candela_dir(d), tb.candela_dir(d), 1e-9));
    }
    // A damaged EULUMDAT file named .ies gets the EULUMDAT error with its line.
    let bad = dir.path().join("bad.ies");
    std::fs::write(&bad, with_line(6, "lots")).unwrap();
    let e = Photometry::load(&bad).unwrap_err();
    assert!(matches!(e, LightError::Ldt(_)), "{e:?}");
    assert!(e.to_string().contains("bad.ies:6:"), "{e}");
    // Content that is neither: by extension, else a clear error.
    let junk = dir.path().join("notes.txt");
    std::fs::write(&junk, "just\nsome\ntext\n").unwrap();
    let e = Photometry::load(&junk).unwrap_err();
    assert!(matches!(e, LightError::UnknownFormat { .. }), "{e:?}");
    assert!(
        e.to_string().starts_with(&format!("{}:", junk.display())),
        "{e}"
    );
    let junk_ldt = dir.path().join("notes.ldt");
    std::fs::write(&junk_ldt, "just\nsome\ntext\n").unwrap();
    let e = Photometry::load(&junk_ldt).unwrap_err();
    assert!(
        e.to_string()
            .contains("notes.ldt:2: expected the type indicator"),
        "{e}"
    );
    let e = Photometry::load(&dir.path().join("missing.ldt")).unwrap_err();
    assert!(matches!(e, LightError::Io { .. }), "{e:?}");
}

// ---------------------------------------------------------------- measurement tilt

/// The fixture's text with its tilt during measurement (line 25) set to `deg`.
fn with_tilt(name: &str, deg: f64) -> String {
    let text = read(&ldt_path(name));
    let mut lines: Vec<&str> = text.split('\n').collect();
    assert_eq!(lines[24].trim(), "0", "{name}: line 25 is the tilt");
    let t = format!("{deg}");
    lines[24] = &t;
    lines.join("\n")
}

/// One table per tilt from the same fixture: the full-resolution table only, so
/// `LightScene::direct` reads exactly `candela` (no distance series).
fn tilted_table(name: &str, deg: f64) -> std::sync::Arc<LightTable> {
    let f = LdtFile::parse(&with_tilt(name, deg), name).unwrap();
    assert_eq!(f.measurement_tilt, deg);
    let o = TableOptions {
        max_levels: 1,
        ..TableOptions::default()
    };
    std::sync::Arc::new(LightTable::from_ldt(&f, &o).unwrap())
}

/// A file measured tilted by θ, placed with some aim, lights every point as the same
/// file measured level would if its table were turned by θ about the C0-C180 axis: the
/// direction from the light in its own frame (x right, y up, z aim), rotated by hand
/// into the goniometer's frame, m = (x cos θ − z sin θ, y, x sin θ + z cos θ), gives
/// γ = acos m_z and C = atan2(−m_x, m_y) (the table's convention), and E = I(γ, C) ·
/// cos(incidence) / d². Checked on a file without symmetry and a bilateral one, tilts of
/// both signs, aims down and sideways, at points on every face of the room.
#[test]
fn the_measurement_tilt_turns_the_table_about_the_c0_c180_axis() {
    use glam::DVec3;
    use lut_core::{LightScene, Luminaire, Room};
    let room = Room::new(6.0, 5.0, 3.0, 1.5).unwrap();
    let (lo, hi) = room.bounds();
    for name in ["no_symmetry.ldt", "bilateral_c0_c180.ldt"] {
        let level = tilted_table(name, 0.0);
        assert_eq!(level.measurement_tilt_deg(), 0.0);
        for theta in [15.0f64, -30.0] {
            let t = tilted_table(name, theta);
            assert_eq!(t.measurement_tilt_deg(), theta);
            for (yaw, pitch) in [(0.0, -90.0), (40.0, -60.0), (-120.0, -20.0)] {
                let mut l = Luminaire::new(t.clone(), DVec3::new(0.4, 2.6, -0.3));
                l.yaw_deg = yaw;
                l.pitch_deg = pitch;
                let (r, u, a) = l.mount_frame();
                let scene = LightScene::new(room, vec![l.clone()]).unwrap();
                let (st, ct) = theta.to_radians().sin_cos();
                let mut lit = 0;
                for k in 0..400 {
                    // Points spread over the six faces.
                    let s = (k as f64 * 0.618_034).fract();
                    let q = (k as f64 * 0.414_214).fract();
                    let (p, n) = match k % 6 {
                        0 => (DVec3::new(lo.x + s * 6.0, lo.y, lo.z + q * 5.0), DVec3::Y),
                        1 => (DVec3::new(lo.x + s * 6.0, hi.y, lo.z + q * 5.0), -DVec3::Y),
                        2 => (DVec3::new(lo.x, lo.y + s * 3.0, lo.z + q * 5.0), DVec3::X),
                        3 => (DVec3::new(hi.x, lo.y + s * 3.0, lo.z + q * 5.0), -DVec3::X),
                        4 => (DVec3::new(lo.x + s * 6.0, lo.y + q * 3.0, lo.z), DVec3::Z),
                        _ => (DVec3::new(lo.x + s * 6.0, lo.y + q * 3.0, hi.z), -DVec3::Z),
                    };
                    let to = p - l.position;
                    let d = to.length();
                    if d > 3.9 {
                        continue; // within the reference distance: the table as measured
                    }
                    let w = to / d;
                    let (x, y, z) = (w.dot(r), w.dot(u), w.dot(a));
                    let m = DVec3::new(x * ct - z * st, y, x * st + z * ct);
                    let gamma = m.z.clamp(-1.0, 1.0).acos().to_degrees();
                    let c = (-m.x).atan2(m.y).to_degrees().rem_euclid(360.0);
                    let cos_i = (-w).dot(n).max(0.0);
                    let want = level.candela(gamma, c) * cos_i / (d * d);
                    let got = scene.direct(p, n);
                    assert!(
                        (got - want).abs() <= 1e-9 * want.max(1.0),
                        "{name} θ {theta} aim ({yaw}, {pitch}) at {p}: {got} vs {want}"
                    );
                    lit += usize::from(want > 0.0);
                }
                assert!(lit > 50, "{name} θ {theta}: only {lit} lit points compared");
            }
        }
    }
}

/// The sense, on a rotationally symmetric file: measured tilted by θ and hung aimed
/// straight down (yaw 0), its beam axis (the table's nadir) leans θ toward +X (the
/// luminaire's C270 side), so it lights the room exactly as the level file aimed there:
/// yaw 90 (toward +X), pitch θ − 90.
#[test]
fn a_tilted_rotational_file_hung_level_lights_as_the_level_file_aimed_over() {
    use glam::DVec3;
    use lut_core::{LightScene, Luminaire, Room};
    let room = Room::new(6.0, 6.0, 3.0, 1.5).unwrap();
    let name = "rotational_label_lines.ldt";
    let theta = 20.0;
    let pos = DVec3::new(0.0, 2.9, 0.0);
    let tilted =
        LightScene::new(room, vec![Luminaire::new(tilted_table(name, theta), pos)]).unwrap();
    let mut aimed = Luminaire::new(tilted_table(name, 0.0), pos);
    aimed.yaw_deg = 90.0;
    aimed.pitch_deg = theta - 90.0;
    let aimed = LightScene::new(room, vec![aimed]).unwrap();
    let level = LightScene::new(room, vec![Luminaire::new(tilted_table(name, 0.0), pos)]).unwrap();
    let mut differs = 0;
    for i in 0..=24 {
        for j in 0..=24 {
            let p = DVec3::new(-2.9 + 0.2417 * i as f64, 0.0, -2.9 + 0.2417 * j as f64);
            let (a, b) = (tilted.direct(p, DVec3::Y), aimed.direct(p, DVec3::Y));
            assert!((a - b).abs() <= 1e-9 * b.max(1.0), "{p}: {a} vs {b}");
            let c = level.direct(p, DVec3::Y);
            differs += usize::from((a - c).abs() > 1e-3 * c.max(1.0));
        }
    }
    // And the tilt changes the light (the test would pass vacuously otherwise).
    assert!(differs > 100, "{differs}");
    // The brightest floor point moves toward +X: the beam axis meets the floor at
    // x = h tan θ.
    let peak = |s: &LightScene| {
        (0..=580)
            .map(|i| -2.9 + 0.01 * i as f64)
            .max_by(|&x, &y| {
                let e = |x: f64| s.direct(DVec3::new(x, 0.0, 0.0), DVec3::Y);
                e(x).total_cmp(&e(y))
            })
            .unwrap()
    };
    let (xl, xt) = (peak(&level), peak(&tilted));
    assert!(xl.abs() < 0.05, "{xl}");
    assert!(xt > 0.2, "the tilted file's peak is at x = {xt}");
}
