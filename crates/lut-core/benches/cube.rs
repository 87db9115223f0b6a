//! Cube renderers: accelerated (per-scanline face runs) against basic (per pixel), on a
//! horizontal panning sequence, single thread, at 1280×720 and 1920×1080.
//!
//! Run: `cargo bench -p lut-core --bench cube` (criterion), or
//! `CUBE_PAN_MIN=1 cargo bench -p lut-core --bench cube` (interleaved, minimum per frame).
//!
//! Each iteration renders the next frame of a pan: yaw advances 7.3° per frame (so
//! frames sweep all four side faces and cross every vertical edge) at a fixed pitch, the
//! paper's "horizontal look-around at constant pitch".

use criterion::{criterion_group, BenchmarkId, Criterion, Throughput};
use lut_core::LoadOptions;
use lut_core::{CubeMap, CubeRenderer};
use lut_core::{Frame, Panorama, RenderOptions};
use lut_core::{Projection, Sampler, View};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

fn cube_map() -> CubeMap {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/courtyard.jpg");
    let map = lut_core::load_map(
        &path,
        &LoadOptions {
            projection: Some(Projection::Equirect),
            ..LoadOptions::default()
        },
        &mut |_| {},
    )
    .expect("assets/courtyard.jpg");
    // 1024² faces: a realistically large cube (6 × 4 MiB), upsampled from the photograph.
    CubeMap::from_envmap(&map, 1024, Sampler::Bilinear).expect("cube")
}

fn pan(c: &mut Criterion) {
    let mut cube = Panorama::cube(cube_map());
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
                            render_cube(&mut cube, view, sampler, r, &mut out, w, h);
                            black_box(&out);
                        })
                    });
                }
            }
            g.finish();
        }
    }
}

/// `CUBE_PAN_MIN=1`: the same pans, the two renderers interleaved frame by frame, and the
/// *minimum* time per frame over the sequence reported for each. On a shared, loaded
/// machine the minimum is the stable statistic; criterion's means are kept as the default.
fn interleaved_min() {
    let mut cube = Panorama::cube(cube_map());
    println!("frame time, min over 72 interleaved frames (yaw += 5 deg), one thread:");
    for pitch in [0.0, 30.0] {
        for sampler in [Sampler::Bilinear, Sampler::Nearest] {
            for (w, h) in [(1280u32, 720u32), (1920, 1080)] {
                let mut out = vec![0u32; (w * h) as usize];
                let mut best = [f64::INFINITY; 2];
                for frame in 0..72 {
                    let view = View::new(frame as f64 * 5.0, pitch, 90.0).unwrap();
                    for (k, r) in [CubeRenderer::Basic, CubeRenderer::Accelerated]
                        .into_iter()
                        .enumerate()
                    {
                        let t = std::time::Instant::now();
                        render_cube(&mut cube, view, sampler, r, &mut out, w, h);
                        black_box(&out);
                        best[k] = best[k].min(t.elapsed().as_secs_f64() * 1e3);
                    }
                }
                println!(
                    "pitch {pitch:>2} {:<8} {w}x{h}: basic {:.2} ms, accelerated {:.2} ms, accelerated saves {:.0} %",
                    sampler.name(),
                    best[0],
                    best[1],
                    100.0 * (1.0 - best[1] / best[0])
                );
            }
        }
    }
}

criterion_group!(benches, pan);

fn main() {
    if std::env::var_os("CUBE_PAN_MIN").is_some() {
        interleaved_min();
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}

/// One frame of `cube` on one thread through the render entry.
fn render_cube(
    cube: &mut Panorama,
    view: View,
    sampler: Sampler,
    renderer: CubeRenderer,
    out: &mut [u32],
    w: u32,
    h: u32,
) {
    let opts = RenderOptions {
        sampler,
        cube: renderer,
        threads: false,
        ..RenderOptions::default()
    };
    cube.render(view, &opts, &mut Frame::new(out, w, h).unwrap())
        .unwrap();
}
