//! Shared by the light tests: synthetic IES files (any angles, candela from a function)
//! and directions spread over the sphere.

use glam::DVec3;
use lut_core::IesFile;

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
