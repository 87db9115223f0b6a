//! Kernel benchmarks of the LUT renderer: table build, per-frame setup plus one scanline,
//! and whole frames at 1280×720 and 1920×1080 from 4k, 8k and 16k equirectangular maps
//! (generated grid maps), on 1 and 2 threads.
//!
//! Run: `cargo bench -p lut-core --bench render` (add a filter, e.g. `-- frame/8k`).
//!
//! Every frame iteration renders the next view of a pan (yaw +7.3° per frame, pitch 10°,
//! hfov 90°, bilinear, index step 4, the wide table), so the time includes all per-view
//! work. Tables are built before timing. Run times are kept short (10 samples, 2 s): this
//! is for comparing changes, `viewer bench` is the full report.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use lut_core::grid_map;
use lut_core::Frame;
use lut_core::{
    IndexStep, LutChoice, Projection, RenderOptions, Renderer, RendererKind, Sampler, View,
};
use lut_core::{LutTable, Surface, TableKind, TableSpec};
use std::hint::black_box;
use std::time::Duration;

const MAPS: [(&str, u32); 3] = [("4k", 4096), ("8k", 8192), ("16k", 16384)];

fn opts(sampler: Sampler, threads: bool) -> RenderOptions {
    RenderOptions {
        renderer: RendererKind::Lut,
        sampler,
        index_step: IndexStep::Fixed(4),
        lut: LutChoice::Wide,
        surface: Surface::Cylinder,
        threads,
        ..RenderOptions::default()
    }
}

fn pool(n: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .expect("thread pool")
}

fn pan_view(frame: &mut u32) -> View {
    *frame = frame.wrapping_add(1);
    View::new((*frame as f64 * 7.3) % 360.0, 10.0, 90.0).expect("view")
}

/// Table build for each kind, per map width (the table depends on the map's geometry only).
fn table_build(c: &mut Criterion) {
    let mut g = c.benchmark_group("table_build");
    g.sample_size(10);
    g.warm_up_time(Duration::from_millis(300));
    g.measurement_time(Duration::from_secs(2));
    for (label, w) in MAPS {
        for (kind, name) in [(TableKind::Wide, "wide"), (TableKind::High, "high")] {
            let spec = TableSpec::default_for(Surface::Cylinder, kind, w);
            g.bench_function(BenchmarkId::new(name, label), |b| {
                b.iter(|| black_box(LutTable::build(spec, Projection::Equirect, w, w / 2)))
            });
        }
    }
    g.finish();
}

/// Per-frame setup plus one scanline: a 1920×1 frame (all per-scanline setup of a frame
/// is O(height), so this is the fixed cost of a view change plus one row's kernel).
fn setup_one_scanline(c: &mut Criterion) {
    let map = grid_map(8192, 4096, Projection::Equirect).expect("map");
    let mut r = Renderer::new(&map);
    let mut out = vec![0u32; 1920];
    let o = opts(Sampler::Bilinear, false);
    r.render(
        &map,
        View::new(0.0, 0.0, 90.0).unwrap(),
        &o,
        &mut Frame::new(&mut out, 1920, 1).unwrap(),
    )
    .expect("warm-up");
    let mut g = c.benchmark_group("scanline");
    g.sample_size(10);
    g.warm_up_time(Duration::from_millis(300));
    g.measurement_time(Duration::from_secs(1));
    g.throughput(Throughput::Elements(1920));
    let mut frame = 0;
    g.bench_function("setup_plus_row_1920_8k", |b| {
        b.iter(|| {
            let v = pan_view(&mut frame);
            r.render(&map, v, &o, &mut Frame::new(&mut out, 1920, 1).unwrap())
                .expect("render");
            black_box(&out);
        })
    });
    g.finish();
}

/// Whole frames: output size × map size × threads, bilinear (and nearest at 1080p).
fn frames(c: &mut Criterion) {
    let pools = [(1usize, pool(1)), (2, pool(2))];
    for (label, w) in MAPS {
        let map = grid_map(w, w / 2, Projection::Equirect).expect("map");
        let mut r = Renderer::new(&map);
        r.table(Surface::Cylinder, TableKind::Wide);
        let mut g = c.benchmark_group(format!("frame/{label}"));
        g.sample_size(10);
        g.warm_up_time(Duration::from_millis(300));
        g.measurement_time(Duration::from_secs(2));
        for (ow, oh) in [(1280u32, 720u32), (1920, 1080)] {
            g.throughput(Throughput::Elements(ow as u64 * oh as u64));
            let mut out = vec![0u32; (ow * oh) as usize];
            for (n, p) in &pools {
                for sampler in [Sampler::Bilinear, Sampler::Nearest] {
                    if sampler == Sampler::Nearest && ow != 1920 {
                        continue;
                    }
                    let o = opts(sampler, *n > 1);
                    let mut frame = 0;
                    let id = BenchmarkId::new(
                        format!("{}_{}t", sampler.name(), n),
                        format!("{ow}x{oh}"),
                    );
                    g.bench_function(id, |b| {
                        p.install(|| {
                            b.iter(|| {
                                let v = pan_view(&mut frame);
                                r.render(&map, v, &o, &mut Frame::new(&mut out, ow, oh).unwrap())
                                    .expect("render");
                                black_box(&out);
                            })
                        })
                    });
                }
            }
        }
        g.finish();
    }
}

criterion_group!(benches, table_build, setup_one_scanline, frames);
criterion_main!(benches);
