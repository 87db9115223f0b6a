//! Cube renderers: accelerated (per-scanline face runs) against basic (per pixel), on a
//! horizontal panning sequence, single thread, at 1280×720 and 1920×1080.
//!
//! Run: `cargo bench -p lut-core --bench cube`
//!
//! Each iteration renders the next frame of a pan: yaw advances 7.3° per frame (so
//! frames sweep all four side faces and cross every vertical edge) at a fixed pitch, the
//! paper's "horizontal look-around at constant pitch".

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use lut_core::cube::{self, CubeMap, CubeRenderer};
use lut_core::{EnvMap, Projection, Sampler, View};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

fn cube_map() -> CubeMap {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/courtyard.jpg");
    let map = EnvMap::load(&path, Some(Projection::Equirect)).expect("assets/courtyard.jpg");
    // 1024² faces: a realistically large cube (6 × 4 MiB), upsampled from the photograph.
    CubeMap::from_envmap(&map, 1024, Sampler::Bilinear).expect("cube")
}

fn pan(c: &mut Criterion) {
    let cube = cube_map();
    for (pitch, label) in [(0.0, "pitch0"), (30.0, "pitch30")] {
        for sampler in [Sampler::Bilinear, Sampler::Nearest] {
            let mut g = c.benchmark_group(format!("cube_pan_{label}_{}", sampler.name()));
            g.sample_size(20);
            g.warm_up_time(Duration::from_millis(500));
            g.measurement_time(Duration::from_secs(3));
            for (w, h) in [(1280u32, 720u32), (1920, 1080)] {
                g.throughput(Throughput::Elements(w as u64 * h as u64));
                let mut out = vec![0u32; (w * h) as usize];
                for r in [CubeRenderer::Basic, CubeRenderer::Accelerated] {
                    let mut frame = 0u32;
                    g.bench_function(BenchmarkId::new(r.name(), format!("{w}x{h}")), |b| {
                        b.iter(|| {
                            frame = frame.wrapping_add(1);
                            let yaw = (frame as f64 * 7.3) % 360.0;
                            let view = View::new(yaw, pitch, 90.0).unwrap();
                            cube::render(&cube, view, sampler, r, &mut out, w, h, false).unwrap();
                            black_box(&out);
                        })
                    });
                }
            }
            g.finish();
        }
    }
}

criterion_group!(benches, pan);
criterion_main!(benches);
