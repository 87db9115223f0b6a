//! `viewer lux`: the JSON interface exactly as documented, the CIE 171:2006 reference case
//! through the command line, aims and several sources against the closed form (with
//! `--direct-only`, and the same with every reflectance 0), the inter-reflections added on
//! top, and clean one-line failures.

mod common;

use common::viewer;
use std::f64::consts::PI;

fn iso() -> String {
    test_support::test_data("ies/isotropic_10000lm.ies")
        .to_str()
        .unwrap()
        .to_string()
}

/// `viewer lux --json` with the direct light only (the closed forms' case).
fn run_json(args: &[&str]) -> serde_json::Value {
    let direct = run_json_with(&[&["--direct-only"], args].concat());
    // Black surfaces give exactly the same numbers.
    let black = run_json_with(&[&["--reflectances", "0,0,0"], args].concat());
    assert_eq!(direct, black);
    direct
}

fn run_json_with(args: &[&str]) -> serde_json::Value {
    let mut a = vec!["lux", "--json"];
    a.extend_from_slice(args);
    let out = viewer(&a);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object")
}

/// A point, the normal given on the command line (if any), the normal expected.
type Point = ([f64; 3], Option<[f64; 3]>, [f64; 3]);

fn fails(args: &[&str]) -> String {
    let mut a = vec!["lux"];
    a.extend_from_slice(args);
    let out = viewer(&a);
    assert!(!out.status.success(), "{args:?} should fail");
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    // One line (clap adds its "For more information" hint to a bad value).
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| !l.is_empty() && !l.starts_with("For more information"))
        .collect();
    assert_eq!(lines.len(), 1, "one line: {err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

#[test]
fn json_is_exactly_the_documented_interface() {
    let light = format!("{}@0,3,0", iso());
    let v = run_json(&["--room", "10x10x4", "--light", &light, "--at", "0,0,0"]);
    let obj = v.as_object().unwrap();
    assert_eq!(obj.keys().collect::<Vec<_>>(), ["points"]);
    let p = &v["points"][0];
    let keys: Vec<&String> = p.as_object().unwrap().keys().collect();
    assert_eq!(keys, ["at", "direct", "indirect", "lux", "normal"]);
    assert_eq!(p["indirect"], serde_json::json!(0.0));
    assert_eq!(p["direct"], p["lux"]);
    assert_eq!(p["at"], serde_json::json!([0.0, 0.0, 0.0]));
    assert_eq!(p["normal"], serde_json::json!([0.0, 1.0, 0.0]));
    // CIE 171:2006: isotropic 10 000 lm, 3 m above the point: 88.42 lx.
    let e = p["lux"].as_f64().unwrap();
    assert!((e - 88.42).abs() < 0.005, "{e}");
}

#[test]
fn oblique_points_on_every_face_near_and_far() {
    // I cos θ / d² for the isotropic source at (1, 2.5, -2) of a 30 × 40 × 6 m hall
    // (camera 1.6 m), on the floor, the walls and the ceiling, 1 to 20 m away, with and
    // without the default normals, a work-plane point with its normal given.
    let i = 10_000.0 / (4.0 * PI);
    let l = [1.0, 2.5, -2.0];
    let light = format!("{}@1,2.5,-2:40,-30", iso());
    let points: [Point; 7] = [
        ([1.0, 0.0, -2.0], None, [0.0, 1.0, 0.0]),
        ([8.0, 0.0, 9.0], None, [0.0, 1.0, 0.0]),
        ([15.0, 3.0, 4.0], None, [-1.0, 0.0, 0.0]),
        ([-15.0, 1.0, -12.0], None, [1.0, 0.0, 0.0]),
        ([3.0, 5.0, 20.0], None, [0.0, 0.0, -1.0]),
        ([-4.0, 6.0, 1.0], None, [0.0, -1.0, 0.0]),
        ([2.0, 0.85, -1.0], Some([0.0, 2.0, 0.0]), [0.0, 1.0, 0.0]),
    ];
    let mut args = vec![
        "--room".to_string(),
        "30x40x6".into(),
        "--light".into(),
        light,
    ];
    for (p, n, _) in &points {
        args.push("--at".into());
        let mut a = format!("{},{},{}", p[0], p[1], p[2]);
        if let Some(n) = n {
            a += &format!(":{},{},{}", n[0], n[1], n[2]);
        }
        args.push(a);
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let v = run_json(&args);
    for (k, (p, _, n)) in points.iter().enumerate() {
        let got = &v["points"][k];
        assert_eq!(got["normal"], serde_json::json!(n), "point {k}");
        let to = [l[0] - p[0], l[1] - p[1], l[2] - p[2]];
        let d2 = to.iter().map(|c| c * c).sum::<f64>();
        let cos = (to[0] * n[0] + to[1] * n[1] + to[2] * n[2]) / d2.sqrt();
        let want = i * cos.max(0.0) / d2;
        let e = got["lux"].as_f64().unwrap();
        assert!((e - want).abs() <= 5e-3 * want, "point {k}: {e} vs {want}");
    }
}

#[test]
fn several_sources_and_a_multiplier_add_up() {
    let a = format!("{}@-1,2.8,0", iso());
    let b = format!("{}@2,2.8,1", iso());
    let one = |args: &[&str]| run_json(args)["points"][0]["lux"].as_f64().unwrap();
    let base = ["--room", "6x6x3", "--at", "0.5,0,0.5"];
    let ea = one(&[&base[..], &["--light", &a]].concat());
    let eb = one(&[&base[..], &["--light", &b]].concat());
    let both = one(&[&base[..], &["--light", &a, "--light", &b]].concat());
    assert!((both - (ea + eb)).abs() < 1e-9 * both);
    let doubled = one(&[
        &base[..],
        &["--light", &a, "--light", &b, "--light-multiplier", "2"],
    ]
    .concat());
    assert!((doubled - 2.0 * both).abs() < 1e-9 * both);
    // An LDT file, aimed, read with Catmull-Rom: it runs, and differs from linear only
    // by the interpolation (a fraction of a percent on a 5° file).
    let ldt = test_support::test_data("ldt/office_louvre_2x28w.ldt");
    let l = format!("{}@0,2.9,0:30,-70", ldt.display());
    let lin = one(&["--room", "6x6x3", "--light", &l, "--at", "0.5,0,0.5"]);
    let cr = one(&[
        "--room",
        "6x6x3",
        "--light",
        &l,
        "--light-interpolation",
        "catmull-rom",
        "--at",
        "0.5,0,0.5",
    ]);
    assert!(lin > 0.0 && (cr - lin).abs() < 0.02 * lin, "{lin} {cr}");
}

#[test]
fn inter_reflections_add_to_the_direct_light() {
    // The default reflectances (0.2, 0.5, 0.7): the direct part is unchanged, the
    // indirect is positive and lux is their sum; a point under the light reads more.
    let light = format!("{}@0,2.5,0", iso());
    let args = [
        "--room",
        "6x5x2.8",
        "--light",
        &light,
        "--at",
        "0,0,0",
        "--at",
        "1,0.75,0.5:0,1,0",
    ];
    let direct = run_json(&args);
    let lit = run_json_with(&args);
    for k in 0..2 {
        let (d, p) = (&direct["points"][k], &lit["points"][k]);
        let (ed, dd, di, e) = (
            d["lux"].as_f64().unwrap(),
            p["direct"].as_f64().unwrap(),
            p["indirect"].as_f64().unwrap(),
            p["lux"].as_f64().unwrap(),
        );
        assert_eq!(dd, ed);
        assert!(
            di > 1.0 && (e - (dd + di)).abs() < 1e-9 * e && e > ed,
            "{p}"
        );
    }
    // Reflectances outside [0, 1) are refused.
    for bad in ["1,0.5,0.7", "0.2,-0.1,0.7", "0.2,0.5", "a,b,c"] {
        let e = fails(&[&args[..], &["--reflectances", bad]].concat());
        assert!(e.contains("reflectance"), "{e}");
    }
}

#[test]
fn text_output_lists_each_point() {
    let light = format!("{}@0,3,0", iso());
    let out = viewer(&[
        "lux",
        "--direct-only",
        "--room",
        "10x10x4",
        "--light",
        &light,
        "--at",
        "0,0,0",
        "--at",
        "5,2,0",
    ]);
    assert!(out.status.success());
    let t = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = t.lines().collect();
    assert_eq!(lines.len(), 3, "{t}");
    assert!(lines[1].contains(" 88.42 "), "{t}");
    assert!(lines[1].ends_with(" 0"), "no indirect light: {t}");
    assert!(lines[2].contains("(-1.000, 0.000, 0.000)"), "{t}");
}

#[test]
fn bad_points_and_missing_lights_fail_cleanly() {
    let light = format!("{}@0,3,0", iso());
    let base = ["--room", "10x10x4", "--light", light.as_str()];
    let e = fails(&[&base[..], &["--at", "0,1,0"]].concat());
    assert!(
        e.contains("--at 0,1,0") && e.contains("X,Y,Z:NX,NY,NZ"),
        "{e}"
    );
    let e = fails(&[&base[..], &["--at", "5,0,0"]].concat());
    assert!(e.contains("floor") && e.contains("right wall"), "{e}");
    let e = fails(&[&base[..], &["--at", "6,0,0"]].concat());
    assert!(e.contains("outside the room"), "{e}");
    let e = fails(&[&base[..], &["--at", "6,0,0:0,1,0"]].concat());
    assert!(e.contains("outside the room"), "{e}");
    let e = fails(&[&base[..], &["--at", "1,2,3:0,0,0"]].concat());
    assert!(e.contains("0,0,0"), "{e}");
    let e = fails(&["--room", "10x10x4", "--at", "0,0,0"]);
    assert!(e.contains("no luminaire"), "{e}");
    let e = fails(&[
        "--room",
        "10x10x4",
        "--light",
        &format!("{}@0,9,0", iso()),
        "--at",
        "0,0,0",
    ]);
    assert!(e.contains("outside the room"), "{e}");
    let e = fails(&["--light", "/no/such.ies@0,2,0", "--at", "0,0,0"]);
    assert!(e.contains("/no/such.ies"), "{e}");
}
