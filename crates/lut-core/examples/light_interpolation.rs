//! Linear against Catmull-Rom interpolation of the light tables, on the sample files.
//!
//! `cargo run -p lut-core --release --example light_interpolation` prints the two Markdown
//! tables of docs/lights.md: per file, the difference in candela over the sphere and in
//! illuminance on the floor of a room lit by the luminaire, and the integrated flux; and
//! the values stored with and without the constant ranges (claim 8).
//!
//! `… --example light_interpolation -- lookups linear|catmull-rom N` only does N
//! illuminance lookups (a fixed workload), to compare the two by instruction counts:
//! `valgrind --tool=callgrind target/release/examples/light_interpolation lookups linear 1000000`.

use glam::DVec3;
use lut_core::{Interpolation, LightTable, Named, Photometry, TableOptions};
use std::path::PathBuf;

const FILES: &[&str] = &[
    "ies/label_lines.ies",
    "ies/tilt_include_v19.ies",
    "ies/type_b_full.ies",
    "ldt/office_louvre_2x28w.ldt",
    "ldt/no_symmetry.ldt",
    "ldt/bilateral_c90_c270.ldt",
    "ldt/wallwasher_c0_c180.ldt",
];

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data")
        .join(name)
}

fn table(p: &Photometry, interpolation: Interpolation) -> LightTable {
    let o = TableOptions {
        interpolation,
        ..TableOptions::default()
    };
    LightTable::from_photometry(p, &o).expect("sample file builds")
}

/// Directions spread evenly over the sphere (a Fibonacci spiral).
fn sphere(n: usize) -> impl Iterator<Item = DVec3> {
    (0..n).map(move |i| {
        let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
        let r = (1.0 - z * z).sqrt();
        let ph = i as f64 * 2.399_963_229_728_653;
        DVec3::new(r * ph.cos(), r * ph.sin(), z)
    })
}

/// Illuminance on the floor of a 6 × 6 m room from the luminaire 2.8 m above its centre,
/// aimed straight down, every 5 cm (a light aimed down has its right along world +X, its
/// up along world +Z: local = (x, z, −y)).
fn floor(t: &LightTable) -> Vec<f64> {
    let light = DVec3::new(0.0, 2.8, 0.0);
    let mut e = Vec::new();
    for i in 0..120 {
        for j in 0..120 {
            let p = DVec3::new(
                -3.0 + 0.025 + 0.05 * i as f64,
                0.0,
                -3.0 + 0.025 + 0.05 * j as f64,
            );
            let w = p - light;
            let d = w.length();
            let local = DVec3::new(w.x, w.z, -w.y) / d;
            e.push(t.illuminance_normal(local, d) * (light.y - p.y) / d);
        }
    }
    e
}

/// (max |a − b| / max |b|, mean |a − b| / mean |b|) in percent.
fn diff(a: &[f64], b: &[f64]) -> (f64, f64) {
    let max_b = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mean_b = b.iter().map(|x| x.abs()).sum::<f64>() / b.len() as f64;
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| (x - y).abs()).collect();
    let max_d = d.iter().fold(0.0f64, |m, &x| m.max(x));
    let mean_d = d.iter().sum::<f64>() / d.len() as f64;
    (100.0 * max_d / max_b, 100.0 * mean_d / mean_b)
}

fn compare() {
    println!("| file | symmetry | angles (h × v) | ΔI max | ΔI mean | ΔE floor max | ΔE floor mean | E max (lx) | flux linear → Catmull-Rom (lm) |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for name in FILES {
        let p = Photometry::load(&data(name)).expect("sample file loads");
        let (lin, cub) = (
            table(&p, Interpolation::Linear),
            table(&p, Interpolation::CatmullRom),
        );
        let il: Vec<f64> = sphere(200_000).map(|d| lin.candela_dir(d)).collect();
        let ic: Vec<f64> = sphere(200_000).map(|d| cub.candela_dir(d)).collect();
        let (el, ec) = (floor(&lin), floor(&cub));
        let (imax, imean) = diff(&ic, &il);
        let (emax, emean) = diff(&ec, &el);
        let e_top = el.iter().fold(0.0f64, |m, &x| m.max(x));
        println!(
            "| `{name}` | {} | {} × {} | {imax:.2} % | {imean:.2} % | {emax:.2} % | {emean:.2} % | {e_top:.0} | {:.1} → {:.1} |",
            p.symmetry.name(),
            p.horizontal_angles.len(),
            p.vertical_angles.len(),
            lin.luminous_flux(),
            cub.luminous_flux()
        );
    }
    println!();
    println!("ΔI: |I_catmull-rom − I_linear| over 200 000 directions evenly spread on the sphere, max relative to the largest candela, mean relative to the mean candela. ΔE: the same for the illuminance on a 6 × 6 m floor 2.8 m below the luminaire (aimed down), every 5 cm.");
}

/// Values stored with and without the constant ranges (claim 8), all levels.
fn storage() {
    println!("| file | level 0 stored (planes × rows), uncut → cut | values, all levels, uncut → cut (linear) | (Catmull-Rom) |");
    println!("|---|---|---|---|");
    for name in FILES {
        let p = Photometry::load(&data(name)).expect("sample file loads");
        let build = |interpolation, cut_constant_ranges| {
            let o = TableOptions {
                interpolation,
                cut_constant_ranges,
                ..TableOptions::default()
            };
            LightTable::from_photometry(&p, &o).expect("sample file builds")
        };
        let total = |t: &LightTable| {
            (0..t.level_count())
                .filter_map(|k| t.stored_values(k))
                .sum::<usize>()
        };
        let (full, cut) = (
            build(Interpolation::Linear, false),
            build(Interpolation::Linear, true),
        );
        let (cfull, ccut) = (
            build(Interpolation::CatmullRom, false),
            build(Interpolation::CatmullRom, true),
        );
        let (a, b) = (full.level_size(0).unwrap(), cut.level_size(0).unwrap());
        println!(
            "| `{name}` | {} × {} → {} × {} | {} → {} | {} → {} |",
            a.0,
            a.1,
            b.0,
            b.1,
            total(&full),
            total(&cut),
            total(&cfull),
            total(&ccut)
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        None => {
            compare();
            println!();
            storage();
        }
        Some("lookups") => {
            let interp = match args.get(1).map(String::as_str) {
                Some("catmull-rom") => Interpolation::CatmullRom,
                _ => Interpolation::Linear,
            };
            let n: usize = args
                .get(2)
                .and_then(|s| s.parse().ok())
                .unwrap_or(1_000_000);
            let p = Photometry::load(&data("ldt/office_louvre_2x28w.ldt")).expect("loads");
            let t = table(&p, interp);
            // Downward hemisphere (where the luminaire shines), 1 to 3 m.
            let sum: f64 = sphere(n)
                .enumerate()
                .map(|(i, d)| {
                    t.illuminance_normal(DVec3::new(d.x, d.y, d.z.abs()), 1.0 + (i % 3) as f64)
                })
                .sum();
            println!("{} lookups ({}), sum {sum:.6}", n, interp.name());
        }
        Some(other) => {
            eprintln!(
                "unknown mode '{other}': run without arguments, or `lookups linear|catmull-rom N`"
            );
            std::process::exit(2);
        }
    }
}
