//! The span kernels alone, every kernel this CPU runs (scalar, SSE4.1, AVX2): nearest,
//! bilinear and trilinear over the spans of a 1920×1080 frame-like pattern (rows 0.9 map
//! pixels apart, about one map pixel per output pixel with a slow drift, as at hfov 90)
//! on an 8192×4096 map, in spans of 8, 16 and 64 pixels. No table reads, no per-frame
//! setup: the renderer's whole-frame cost is `benches/render.rs` and
//! `examples/frame_cost.rs`.
//!
//! Run: `cargo bench -p lut-core --bench kernels` (filter: `-- kernels/bilinear`).
//! Throughput is in output pixels.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use lut_core::grid_map;
use lut_core::{Kernel, Projection, SpanJob, Texels, MAX_JOBS};
use std::hint::black_box;
use std::time::Duration;

const W: u32 = 1920;
const H: u32 = 1080;
const ONE: i64 = 1 << 16;

/// The spans of one frame, row by row, `n` pixels each (Q.16 positions on a map
/// `mw × mh`).
fn frame_spans(n: u32, mw: u32, mh: u32) -> Vec<Vec<SpanJob>> {
    (0..H)
        .map(|y| {
            let v0 = (mh as i64 / 2 - 486) * ONE + (y as i64 * ONE * 9) / 10;
            let u0 = (mw as i64 / 3) * ONE;
            (0..W / n)
                .map(|s| {
                    let x = s * n;
                    // about one map pixel per output pixel, drifting (1 ± 0.1)
                    let t = x as f64 / W as f64 - 0.5;
                    let du = ((1.0 + 0.1 * t) * ONE as f64) as i64;
                    let dv = (0.05 * t * ONE as f64) as i64;
                    let u = u0 + (x as i64) * ONE + (x as i64 * x as i64 * ONE) / (40 * W as i64);
                    SpanJob {
                        x,
                        len: n,
                        u,
                        v: v0 + (t * t * 200.0 * ONE as f64) as i64,
                        du,
                        dv,
                    }
                })
                .collect()
        })
        .collect()
}

fn kernels(c: &mut Criterion) {
    let map = grid_map(8192, 4096, Projection::Equirect).expect("map");
    // The padded pixels and the first pyramid level, as the renderer reads them.
    let pad = |m: &lut_core::EnvMap| -> Vec<u32> {
        (0..=m.height())
            .flat_map(|y| (0..=m.width()).map(move |x| (x, y)))
            .map(|(x, y)| {
                let xx = if x == m.width() { 0 } else { x };
                m.pixel(xx, y.min(m.height() - 1))
            })
            .collect()
    };
    let px0 = pad(&map);
    let l1 = &map.pyramid()[0];
    let px1 = pad(l1);
    let t0 = Texels::new(&px0, 8192, 4096, true).expect("texels");
    let t1 = Texels::new(&px1, l1.width(), l1.height(), true).expect("texels");
    let levels = [t0, t1];
    let mut out = vec![0u32; W as usize];
    for sampler in ["nearest", "bilinear", "trilinear"] {
        let mut g = c.benchmark_group(format!("kernels/{sampler}"));
        g.sample_size(10);
        g.warm_up_time(Duration::from_millis(300));
        g.measurement_time(Duration::from_secs(1));
        g.throughput(Throughput::Elements(W as u64 * H as u64));
        for n in [8u32, 16, 64] {
            let rows = frame_spans(n, 8192, 4096);
            for kernel in Kernel::available() {
                let k = kernel.select().expect("an available kernel");
                g.bench_function(BenchmarkId::new(kernel.name(), n), |b| {
                    b.iter(|| {
                        for jobs in &rows {
                            match sampler {
                                "nearest" => {
                                    for batch in jobs.chunks(MAX_JOBS) {
                                        black_box(k.nearest_spans(&t0, &mut out, batch));
                                    }
                                }
                                "bilinear" => {
                                    for batch in jobs.chunks(MAX_JOBS) {
                                        black_box(k.bilinear_spans(&t0, &mut out, batch));
                                    }
                                }
                                _ => {
                                    // levels 0 and 1 blended half way: both levels read
                                    let lods = [128; MAX_JOBS];
                                    for batch in jobs.chunks(MAX_JOBS) {
                                        let l = &lods[..batch.len()];
                                        black_box(k.trilinear_spans(&levels, &mut out, batch, l));
                                    }
                                }
                            }
                            black_box(&out);
                        }
                    })
                });
            }
        }
        g.finish();
    }
}

criterion_group!(benches, kernels);
criterion_main!(benches);
