//! Per-frame cost of lighting a 1920×1080 frame with 1 and 8 goniometric luminaires
//! (linear interpolation, the default), and with 8 using Catmull-Rom.
//!
//! Run: `cargo bench -p lut-core --bench lights`.
//! The luminaire is a synthetic type C, bilateral (0-180) distribution with 5° steps and
//! a cut-off at 80° (so the constant range is exercised), in a 6 × 5 × 2.8 m room.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::DVec3;
use lut_core::{
    shade_frame, IesFile, Interpolation, LightScene, LightTable, Luminaire, Room, ShadeOptions,
    TableOptions,
};
use lut_core::{Camera, View};
use std::hint::black_box;
use std::sync::Arc;

fn synthetic_table(interpolation: Interpolation) -> LightTable {
    let v: Vec<f64> = (0..=36).map(|i| i as f64 * 5.0).collect();
    let h: Vec<f64> = (0..=12).map(|i| i as f64 * 15.0).collect();
    let mut s = format!(
        "IESNA:LM-63-2002\n[TEST] bench\nTILT=NONE\n1 -1 1 {} {} 1 2 0 0 0\n1 1 50\n",
        v.len(),
        h.len()
    );
    let join = |a: &[f64]| {
        a.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    };
    s += &format!("{}\n{}\n", join(&v), join(&h));
    for &hh in &h {
        let row: Vec<f64> = v
            .iter()
            .map(|&g| {
                if g >= 80.0 {
                    0.0
                } else {
                    2000.0 * g.to_radians().cos().powi(2) * (1.0 + 0.2 * hh.to_radians().cos())
                }
            })
            .collect();
        s += &join(&row);
        s += "\n";
    }
    let f = IesFile::parse(&s, "bench.ies").expect("bench file parses");
    let opts = TableOptions {
        interpolation,
        ..TableOptions::default()
    };
    LightTable::from_ies(&f, &opts).expect("bench table builds")
}

fn bench_lights(c: &mut Criterion) {
    let linear = Arc::new(synthetic_table(Interpolation::Linear));
    let cubic = Arc::new(synthetic_table(Interpolation::CatmullRom));
    let room = Room::new(6.0, 5.0, 2.8, 1.5).expect("room");
    let (w, h) = (1920u32, 1080u32);
    let cam = Camera::new(View::new(30.0, -15.0, 100.0).expect("view"), w, h);
    let base: Vec<u32> = (0..w * h)
        .map(|i| (i.wrapping_mul(2_654_435_761)) & 0xff_ffff)
        .collect();
    let mut frame = base.clone();
    let mut group = c.benchmark_group("lights_1920x1080");
    group.throughput(Throughput::Elements(u64::from(w * h)));
    group.sample_size(10);
    // 0, 1 and 8 lights with linear interpolation (the default), 8 with Catmull-Rom.
    let cases = [
        ("lights", 0usize, &linear),
        ("lights", 1, &linear),
        ("lights", 8, &linear),
        ("lights_catmull_rom", 8, &cubic),
    ];
    for (name, n, table) in cases {
        let lights: Vec<Luminaire> = (0..n)
            .map(|i| {
                let a = i as f64 / n as f64 * std::f64::consts::TAU;
                let mut l = Luminaire::new(
                    Arc::clone(table),
                    DVec3::new(2.0 * a.cos(), 2.7, 1.8 * a.sin()),
                );
                l.yaw_deg = i as f64 * 37.0;
                l
            })
            .collect();
        let scene = LightScene::new(room, lights).expect("scene");
        let opts = ShadeOptions::default();
        group.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
            b.iter(|| {
                frame.copy_from_slice(&base);
                shade_frame(black_box(&scene), &cam, &mut frame, w, h, &opts).expect("shade");
                black_box(&frame);
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_lights);
criterion_main!(benches);
