//! `viewer ies`: JSON summary and samples of a real fixture, and clean failures.

use std::path::PathBuf;
use std::process::Command;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/ies")
        .join(name)
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
    let out = Command::new(env!("CARGO_BIN_EXE_viewer"))
        .arg("ies")
        .arg(&bad)
        .output()
        .expect("viewer runs");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("bad.ies:3:") && err.contains("number of vertical angles"),
        "{err}"
    );
}
