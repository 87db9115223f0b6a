//! `viewer ies`: JSON summary and samples of IES and EULUMDAT fixtures (chosen by content),
//! and clean failures.

use std::path::PathBuf;
use std::process::Command;

fn fixture(name: &str) -> PathBuf {
    test_support::test_data("ies").join(name)
}

#[test]
fn json_summary_and_samples() {
    let out = Command::new(env!("CARGO_BIN_EXE_viewer"))
        .arg("ies")
        .arg(fixture("relative_photometry_with_multiplier.ies"))
        .args([
            "--sample", "0,0", "--sample", "3.75,123", "--sample", "95,0", "--json",
        ])
        .output()
        .expect("viewer runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(v["format"], "LM-63-1995");
    assert_eq!(v["photometric_type"], "C");
    assert_eq!(v["symmetry"], "rotational");
    assert_eq!(v["vertical_angles"], 37);
    assert_eq!(v["horizontal_angles"], 1);
    assert_eq!(v["rated_lumens"], 500.0);
    let max = v["max_candela"].as_f64().unwrap();
    assert!((max - 3300.0).abs() < 1e-9, "{max}");
    assert!(v["lumens"].as_f64().unwrap() > 0.0);
    let s = v["samples"].as_array().unwrap();
    assert_eq!(s.len(), 3);
    assert_eq!(s[1]["vertical"], 3.75);
    assert_eq!(s[1]["horizontal"], 123.0);
    // file candela × multiplier 1.5; 3.75° lies halfway between 2.5° and 5°.
    let c0 = s[0]["candela"].as_f64().unwrap();
    let c1 = s[1]["candela"].as_f64().unwrap();
    assert!((c0 - 3300.0).abs() < 1e-3, "{c0}");
    assert!((c1 - 1.5 * (2000.2 + 1950.0) / 2.0).abs() < 1e-3, "{c1}");
    // Outside the measured vertical range 0..90.
    assert_eq!(s[2]["candela"].as_f64().unwrap(), 0.0);
}

#[test]
fn malformed_file_fails_with_one_line_naming_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.ies");
    std::fs::write(
        &bad,
        "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 -3 1 1 2 0 0 0\n1 1 10\n0 45 90\n0\n1 2 3\n",
    )
    .unwrap();
    let err = failure(&bad);
    assert!(
        err.contains("bad.ies:3:") && err.contains("number of vertical angles"),
        "{err}"
    );
}

/// `viewer ies FILE` fails with exactly one line on stderr; that line.
fn failure(file: &std::path::Path) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_viewer"))
        .arg("ies")
        .arg(file)
        .output()
        .expect("viewer runs");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    err
}

fn ldt_fixture(name: &str) -> PathBuf {
    test_support::test_data("ldt").join(name)
}

/// `viewer ies FILE --json` with samples, parsed.
fn summary(file: &std::path::Path, samples: &[&str]) -> serde_json::Value {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_viewer"));
    cmd.arg("ies").arg(file).arg("--json");
    for s in samples {
        cmd.args(["--sample", s]);
    }
    let out = cmd.output().expect("viewer runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object")
}

#[test]
fn eulumdat_files_are_read_by_content_whatever_their_name() {
    let samples = ["0,0", "37.5,100", "100,200", "12.5,345"];
    let ldt = summary(&ldt_fixture("bilateral_c90_c270.ldt"), &samples);
    assert_eq!(ldt["format"], "EULUMDAT");
    assert_eq!(ldt["symmetry"], "bilateral 90-270");
    assert_eq!(ldt["eulumdat"]["symmetry_indicator"], 3);
    assert_eq!(ldt["rated_lumens"], 2000.0);
    // The same candela as the IES twin at every sample.
    let ies = summary(&ldt_fixture("bilateral_c90_c270.ies"), &samples);
    assert_eq!(ies["format"], "LM-63-2002");
    for i in 0..samples.len() {
        let a = ldt["samples"][i]["candela"].as_f64().unwrap();
        let b = ies["samples"][i]["candela"].as_f64().unwrap();
        assert!(
            (a - b).abs() < 1e-9 * b.max(1.0),
            "{}: {a} vs {b}",
            samples[i]
        );
    }
    assert!(ldt["samples"][0]["candela"].as_f64().unwrap() > 0.0);
    // Misnamed both ways: the content decides.
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("downlight.ies");
    std::fs::copy(ldt_fixture("absolute_led.ldt"), &a).unwrap();
    let v = summary(&a, &[]);
    assert_eq!(v["format"], "EULUMDAT");
    assert_eq!(v["rated_lumens"], serde_json::Value::Null);
    assert_eq!(v["eulumdat"]["absolute_photometry"], true);
    let b = dir.path().join("downlight.ldt");
    std::fs::copy(fixture("absolute_photometry.ies"), &b).unwrap();
    let w = summary(&b, &[]);
    assert_eq!(w["format"], "LM-63-1995");
    assert_eq!(v["max_candela"], w["max_candela"]);
}

#[test]
fn malformed_eulumdat_file_fails_with_one_line_naming_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.ldt");
    let text = std::fs::read_to_string(ldt_fixture("bilateral_c0_c180.ldt")).unwrap();
    let text = text.replacen("\n3\n2\n24\n", "\n3\n9\n24\n", 1);
    std::fs::write(&bad, text).unwrap();
    let err = failure(&bad);
    assert!(
        err.contains("bad.ldt:3:") && err.contains("symmetry indicator Isym"),
        "{err}"
    );
}
