//! Lighting a room panorama at 1920×1080 on 2 threads (a rayon pool of 2).
//!
//! Run: `cargo bench -p lut-core --bench lights` (add a filter, e.g. `-- pan`); its
//! output is the "Measured" table of docs/lights.md.
//!
//! * `lights_pan`: whole frames of a pan (yaw +7.3° per frame, pitch −15°, hfov 100°) of a
//!   4096×2048 equirectangular grid map with the default render options (LUT, bilinear,
//!   adaptive step): `unlit`, then lit with 0, 1 and 8 lights (`map/N`: frames of the lit
//!   panorama baked once from the illuminance map, `IlluminanceMap::bake_map`, as the
//!   window pans once the lighting has settled; the shading's cost is `map/N` − `unlit`),
//!   lit from the illuminance map frame by frame with 8 lights (`band/8`: each band of rows
//!   lit as soon as it is drawn, `Renderer::render_with` with `FrameShader::shade_band` as
//!   the hook, as the window does while the lighting changes and for panoramas too large
//!   to bake, and `viewer render`), the same lit in a second pass over the rendered frame
//!   (`band_second_pass/8`), and lit per pixel with 1 light (`per_pixel/1`).
//! * `lights_shade`: the shading pass alone over a whole frame on a fixed view, each
//!   iteration copying the unlit frame first (8 MB in, 8 MB out: the copy is in the time):
//!   from the map (`map/N`) and per pixel with 1 and 8 lights,
//!   linear and Catmull-Rom.
//! * `lights_relight`: what a lighting change costs once it has settled, with 0, 1 and 8
//!   lights (`map/N`: the illuminance map, then the lit 4096×2048 panorama baked from it,
//!   its pyramid included, as the window does), the bake alone (`bake/8`), the bake of an
//!   8192×4096 panorama (`bake_8192/8`, the largest [`lut_core::BAKE_MAX_BYTES`] allows),
//!   and the coarse map the window shows while a value is being dragged (`preview/8`).
//!
//! The luminaire is a synthetic type C, bilateral (0-180) distribution with 5° steps and a
//! cut-off at 80° (so the constant range is exercised), hung 10 cm below the ceiling of a
//! 6 × 5 × 2.8 m room, eight of them on a ring.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::DVec3;
use lut_core::{grid_map, Frame, Projection, RenderOptions, Renderer};
use lut_core::{
    shade_frame, IesFile, IlluminanceMap, Interpolation, LightScene, LightTable, Luminaire,
    MapOptions, Room, ShadeOptions, TableOptions,
};
use lut_core::{AreaStats, CalcGrid, FormFactors, Radiosity, Reflectances, RoomFace};
use lut_core::{Camera, View};
use std::hint::black_box;
use std::sync::Arc;
use std::time::Duration;

const W: u32 = 1920;
const H: u32 = 1080;

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
                    // The planes agree at the nadir, as a measured luminaire's do.
                    let (sg, cg) = g.to_radians().sin_cos();
                    2000.0 * cg * cg * (1.0 + 0.2 * hh.to_radians().cos() * sg)
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

fn scene(n: usize, table: &Arc<LightTable>) -> LightScene {
    let room = Room::new(6.0, 5.0, 2.8, 1.5).expect("room");
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
    LightScene::new(room, lights).expect("scene")
}

fn pool() -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("thread pool")
}

fn pan_view(frame: &mut u32) -> View {
    *frame = frame.wrapping_add(1);
    View::new((*frame as f64 * 7.3) % 360.0, -15.0, 100.0).expect("view")
}

fn short(g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>) {
    g.sample_size(10);
    g.warm_up_time(Duration::from_millis(500));
    g.measurement_time(Duration::from_secs(3));
}

/// Whole frames of a pan: render, then light.
fn pan(c: &mut Criterion) {
    let pool = pool();
    let table = Arc::new(synthetic_table(Interpolation::Linear));
    let map = grid_map(4096, 2048, Projection::Equirect).expect("map");
    let mut renderer = Renderer::new(&map);
    let opts = RenderOptions::default();
    let shade = ShadeOptions::default();
    let mut pixels = vec![0u32; (W * H) as usize];
    let mut g = c.benchmark_group("lights_pan");
    g.throughput(Throughput::Elements(u64::from(W * H)));
    short(&mut g);
    let mut k = 0u32;
    {
        g.bench_function("unlit", |b| {
            pool.install(|| {
                b.iter(|| {
                    let view = pan_view(&mut k);
                    let mut frame = Frame::new(&mut pixels, W, H).expect("frame");
                    renderer
                        .render(&map, view, &opts, &mut frame)
                        .expect("render");
                    black_box(&pixels);
                })
            })
        });
        for n in [0usize, 1, 8] {
            let s = scene(n, &table);
            let lmap = IlluminanceMap::build(&s, &MapOptions::default()).expect("map");
            let lit = pool.install(|| lmap.bake_map(&map, &shade).expect("bake"));
            g.bench_with_input(BenchmarkId::new("map", n), &n, |b, _| {
                pool.install(|| {
                    b.iter(|| {
                        // A frame of the lit panorama, as the window pans a settled room.
                        let view = pan_view(&mut k);
                        let mut frame = Frame::new(&mut pixels, W, H).expect("frame");
                        renderer
                            .render(&lit, view, &opts, &mut frame)
                            .expect("render");
                        black_box(&pixels);
                    })
                })
            });
            if n < 8 {
                continue;
            }
            g.bench_with_input(BenchmarkId::new("band", n), &n, |b, _| {
                pool.install(|| {
                    b.iter(|| {
                        // Lit as the rows are drawn, as the window does while the lighting
                        // changes (and `viewer render`).
                        let view = pan_view(&mut k);
                        let cam = Camera::new(view, W, H);
                        let shader = lmap.frame_shader(&cam, &shade).expect("shader");
                        let hook = |y0: usize, rows: &mut [u32]| shader.shade_band(y0, rows);
                        let mut frame = Frame::new(&mut pixels, W, H).expect("frame");
                        renderer
                            .render_with(&map, view, &opts, &mut frame, &hook)
                            .expect("render");
                        black_box(&pixels);
                    })
                })
            });
            // The same frames rendered, then lit in a second pass over the frame.
            g.bench_function(BenchmarkId::new("band_second_pass", n), |b| {
                pool.install(|| {
                    b.iter(|| {
                        let view = pan_view(&mut k);
                        let mut frame = Frame::new(&mut pixels, W, H).expect("frame");
                        renderer
                            .render(&map, view, &opts, &mut frame)
                            .expect("render");
                        let cam = Camera::new(view, W, H);
                        lmap.shade_frame(&cam, &mut pixels, W, H, &shade)
                            .expect("shade");
                        black_box(&pixels);
                    })
                })
            });
        }
        let s = scene(1, &table);
        g.bench_function(BenchmarkId::new("per_pixel", 1), |b| {
            pool.install(|| {
                b.iter(|| {
                    let view = pan_view(&mut k);
                    let mut frame = Frame::new(&mut pixels, W, H).expect("frame");
                    renderer
                        .render(&map, view, &opts, &mut frame)
                        .expect("render");
                    let cam = Camera::new(view, W, H);
                    shade_frame(&s, &cam, &mut pixels, W, H, &shade).expect("shade");
                    black_box(&pixels);
                })
            })
        });
    }
    g.finish();
}

/// The shading pass alone, on one view.
fn shade_pass(c: &mut Criterion) {
    let pool = pool();
    let linear = Arc::new(synthetic_table(Interpolation::Linear));
    let cubic = Arc::new(synthetic_table(Interpolation::CatmullRom));
    let cam = Camera::new(View::new(30.0, -15.0, 100.0).expect("view"), W, H);
    let base: Vec<u32> = (0..W * H)
        .map(|i| (i.wrapping_mul(2_654_435_761)) & 0xff_ffff)
        .collect();
    let mut frame = base.clone();
    let opts = ShadeOptions::default();
    let mut g = c.benchmark_group("lights_shade");
    g.throughput(Throughput::Elements(u64::from(W * H)));
    short(&mut g);
    {
        for n in [0usize, 8] {
            let lmap =
                IlluminanceMap::build(&scene(n, &linear), &MapOptions::default()).expect("map");
            g.bench_with_input(BenchmarkId::new("map", n), &n, |b, _| {
                pool.install(|| {
                    b.iter(|| {
                        frame.copy_from_slice(&base);
                        lmap.shade_frame(&cam, &mut frame, W, H, &opts)
                            .expect("shade");
                        black_box(&frame);
                    })
                })
            });
        }
        for (name, n, table) in [
            ("per_pixel", 0usize, &linear),
            ("per_pixel", 1, &linear),
            ("per_pixel", 8, &linear),
            ("per_pixel_catmull_rom", 8, &cubic),
        ] {
            let s = scene(n, table);
            g.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                pool.install(|| {
                    b.iter(|| {
                        frame.copy_from_slice(&base);
                        shade_frame(black_box(&s), &cam, &mut frame, W, H, &opts).expect("shade");
                        black_box(&frame);
                    })
                })
            });
        }
    }
    g.finish();
}

/// What a settled lighting change costs: the illuminance map, then the lit panorama.
fn relight(c: &mut Criterion) {
    let pool = pool();
    let table = Arc::new(synthetic_table(Interpolation::Linear));
    let shade = ShadeOptions::default();
    let pano = grid_map(4096, 2048, Projection::Equirect).expect("map");
    // The window's panorama has its pyramid once the view has moved (moving frames read
    // a level of it): the lit copy gets one too.
    pano.pyramid();
    let mut g = c.benchmark_group("lights_relight");
    short(&mut g);
    {
        for n in [0usize, 1, 8] {
            let s = scene(n, &table);
            g.bench_with_input(BenchmarkId::new("map", n), &n, |b, _| {
                pool.install(|| {
                    b.iter(|| {
                        let lmap = IlluminanceMap::build(&s, &MapOptions::default()).expect("map");
                        black_box(lmap.bake_map(&pano, &shade).expect("bake"))
                    })
                })
            });
        }
        let s = scene(8, &table);
        let lmap = IlluminanceMap::build(&s, &MapOptions::default()).expect("map");
        g.bench_function(BenchmarkId::new("bake", 8), |b| {
            pool.install(|| b.iter(|| black_box(lmap.bake_map(&pano, &shade).expect("bake"))))
        });
        g.bench_function(BenchmarkId::new("preview", 8), |b| {
            pool.install(|| b.iter(|| black_box(IlluminanceMap::build(&s, &MapOptions::preview()))))
        });
        // With inter-reflections, the form factors of the room kept (computed once, on the
        // first iteration).
        let refl = Reflectances::default();
        g.bench_function(BenchmarkId::new("indirect", 8), |b| {
            pool.install(|| {
                b.iter(|| {
                    let r = Arc::new(Radiosity::solve(&s, refl).expect("solve"));
                    let lit = s.clone().with_radiosity(r);
                    let lmap = IlluminanceMap::build(&lit, &MapOptions::default()).expect("map");
                    black_box(lmap.bake_map(&pano, &shade).expect("bake"))
                })
            })
        });
        g.bench_function(BenchmarkId::new("solve", 8), |b| {
            pool.install(|| {
                b.iter(|| {
                    let r = Arc::new(Radiosity::solve(&s, refl).expect("solve"));
                    let lit = s.clone().with_radiosity(r);
                    let grid = CalcGrid::work_plane(lit.room(), 0.75).expect("grid");
                    black_box(AreaStats::of(&read_grid(&lit, &grid)))
                })
            })
        });
        drop(pano);
        let big = grid_map(8192, 4096, Projection::Equirect).expect("map");
        big.pyramid();
        g.bench_function(BenchmarkId::new("bake_8192", 8), |b| {
            pool.install(|| b.iter(|| black_box(lmap.bake_map(&big, &shade).expect("bake"))))
        });
    }
    g.finish();
}

/// The illuminance (direct + exact indirect) at each point of `grid`, as `viewer report`
/// reads its grids.
fn read_grid(scene: &LightScene, grid: &CalcGrid) -> Vec<f64> {
    use rayon::prelude::*;
    grid.points
        .par_iter()
        .map(|&p| scene.direct(p, grid.normal) + scene.indirect(p, grid.normal))
        .collect()
}

/// `viewer report`'s figures for the 6 × 5 × 2.8 m room with 8 lights, from scratch.
fn report(c: &mut Criterion) {
    let pool = pool();
    let table = Arc::new(synthetic_table(Interpolation::Linear));
    let s = scene(8, &table);
    let refl = Reflectances::default();
    let mut g = c.benchmark_group("lights_report");
    short(&mut g);
    g.bench_function(BenchmarkId::new("figures", 8), |b| {
        pool.install(|| {
            b.iter(|| {
                // A fresh process has no form factors: compute them (the solve below then
                // finds the room's in the cache, so they are counted once).
                black_box(FormFactors::new(s.room(), lut_core::DEFAULT_PATCHES).expect("ff"));
                let r = Arc::new(Radiosity::solve(&s, refl).expect("solve"));
                let lit = s.clone().with_radiosity(r);
                let mut grids = vec![CalcGrid::work_plane(lit.room(), 0.75).expect("grid")];
                for face in RoomFace::ALL {
                    grids.push(CalcGrid::face(lit.room(), face).expect("grid"));
                }
                let stats: Vec<AreaStats> = grids
                    .iter()
                    .map(|g| AreaStats::of(&read_grid(&lit, g)))
                    .collect();
                black_box(stats)
            })
        })
    });
    g.finish();
}

criterion_group!(benches, pan, shade_pass, relight, report);
criterion_main!(benches);
