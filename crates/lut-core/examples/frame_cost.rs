//! The cost of whole LUT frames with one span kernel, for profilers: renders one untimed
//! view (building tables and scratch), then `frames` views of a pan, and prints the
//! kernel, the CPU features and the median wall time per frame.
//!
//! ```sh
//! cargo build --release -p lut-core --example frame_cost
//! target/release/examples/frame_cost sampler=bilinear kernel=avx2 frames=20 threads=2
//! # instructions per pixel: the timed frames only, divided by frames x pixels
//! valgrind --tool=callgrind --toggle-collect=frame_cost::timed_frames \
//!     target/release/examples/frame_cost sampler=nearest kernel=scalar frames=2 threads=1
//! ```
//!
//! Arguments (`key=value`, any order): `sampler` nearest|bilinear|trilinear (bilinear),
//! `kernel` auto|scalar|sse41|avx2|avx512 (auto), `frames` (10), `threads` 1|2 (1), `map` WxH
//! (8192x4096), `size` WxH (1920x1080), `hfov` (90), `pitch` (10), `yaw` (start, 30; each
//! frame turns 7.3°), `step` adaptive|1|2|4|8|16 (adaptive), `mode` lut|gather (lut:
//! gather = a plain gather along the frame's precomputed nearest indices, the floor the
//! nearest kernel is compared with; cube = the cube scanline renderer on a cube of faces a
//! quarter of the map's width, converted from the map as `viewer bench` does; cube-basic =
//! the per-pixel cube renderer), `face` N (the cube's face side; default a quarter of the
//! map's width, `pi` for the map's width / π rounded: the face whose centre has the
//! map's texel density at the equator), `cache` PATH (keep the generated map's pixels there, and
//! a cube's faces in PATH.cubeN, and read them on later runs: much faster under valgrind),
//! `level` 0|1|2 (0: bilinear reads the map; 1: bilinear reads the pyramid level matching
//! the footprint at the centre, `Renderer::set_bilinear_level`, as the window does while
//! moving; 2: the level no pixel is magnified by more than √2 on,
//! `Renderer::set_still_level`, the window's still bilinear frames; the pyramid is
//! built before timing).
//! `rlod` 0|1 (0): 1 = bilinear chooses its pyramid level per region of the frame
//! (`Renderer::set_region_lod`; the pyramid is built by the untimed first view).
//! `crop` WxH+LEFT+TOP: render a partial map holding only that rectangle of the map's
//! pixels (the cropped kernels).
//! `file` PATH: render that panorama instead of the generated map (e.g. `viewer
//! bench-load`'s cached JPEGs; `map` is then ignored).
//! `lit` none|frame|baked (none): light the frames from an illuminance map of the lights
//! benchmark's room (6 × 5 × 2.8 m, eight luminaires on a ring, built before timing):
//! `frame` lights each frame as its rows are drawn (`Panorama::render_with` with
//! `FrameShader::shade_band` as the band hook, the window's path while the lighting
//! changes); `baked` pans the lit copy (`IlluminanceMap::bake_panorama`, baked before
//! timing, the window's path once it has settled).
//!
//! The checksum printed is of the last frame's pixels: compare it across commits for
//! byte identity (docs/performance.md, "Byte identity across refactors").

use lut_core::grid_map;
use lut_core::{Camera, IlluminanceMap, MapOptions, ShadeOptions};
use lut_core::{CubeMap, CubeRenderer, Face};
use lut_core::{
    Frame, IndexStep, MapGeometry, Panorama, Projection, RenderOptions, Renderer, Sampler, View,
};
use std::time::Instant;
use test_support::light_fixtures::{bench_table, ring};

fn main() {
    if let Err(e) = run() {
        eprintln!("frame_cost: {e}");
        std::process::exit(2);
    }
}

fn size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once('x')
        .ok_or_else(|| format!("'{s}' is not WxH"))?;
    let p = |x: &str| x.parse::<u32>().map_err(|_| format!("'{s}' is not WxH"));
    Ok((p(w)?, p(h)?))
}

/// CPU time of the process so far in ms (all threads), where the platform tells it: on a
/// shared machine it is steadier than wall time (time slices given to other processes do
/// not count; their cache pollution still does).
#[cfg(unix)]
#[allow(unsafe_code)]
fn cpu_ms() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid timespec for the call to write.
    unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) };
    t.tv_sec as f64 * 1e3 + t.tv_nsec as f64 * 1e-6
}

#[cfg(not(unix))]
fn cpu_ms() -> f64 {
    0.0
}

/// The frames measured (callgrind: `--toggle-collect=frame_cost::timed_frames`).
#[inline(never)]
fn timed_frames(
    frames: usize,
    f: &mut dyn FnMut(usize) -> Result<(), String>,
) -> Result<(Vec<f64>, f64), String> {
    let mut times = Vec::with_capacity(frames);
    let cpu0 = cpu_ms();
    for i in 0..frames {
        let t = Instant::now();
        f(i)?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    Ok((times, (cpu_ms() - cpu0) / frames.max(1) as f64))
}

/// One frame of a plain gather along precomputed indices, in row bands.
fn gather_frame(src: &[u32], idx: &[u32], out: &mut [u32], w: usize) {
    use rayon::prelude::*;
    let rows = (16384 / w.max(1)).max(1);
    // Tasks of one size, as the renderer's and `viewer bench`'s gather.
    out.par_chunks_mut(w)
        .zip(idx.par_chunks(w))
        .with_min_len(rows)
        .with_max_len(rows)
        .for_each(|(o, i)| {
            for (o, &i) in o.iter_mut().zip(i) {
                *o = src[i as usize];
            }
        })
}

/// The generated grid map, or its pixels from `cache` (raw little-endian 0RGB, written
/// there on first use): generating an 8k map costs ~20 G instructions, which under
/// valgrind takes minutes.
fn load_map(
    (w, h): (u32, u32),
    cache: Option<&std::path::Path>,
) -> Result<lut_core::EnvMap, String> {
    let n = w as usize * h as usize;
    if let Some(bytes) = cache.and_then(|p| std::fs::read(p).ok()) {
        if bytes.len() == n * 4 {
            let px: Vec<u32> = bytes
                .chunks_exact(4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect();
            return lut_core::EnvMap::from_pixels(w, h, &px, Projection::Equirect)
                .map_err(|e| e.to_string());
        }
    }
    let map = grid_map(w, h, Projection::Equirect).map_err(|e| e.to_string())?;
    if let Some(p) = cache {
        let bytes: Vec<u8> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .flat_map(|(x, y)| map.pixel(x, y).to_le_bytes())
            .collect();
        std::fs::write(p, bytes).map_err(|e| format!("{}: {e}", p.display()))?;
    }
    Ok(map)
}

/// The cube of `n`-texel faces converted from `map` (bilinear, as `viewer bench` does), or
/// its faces read from `cache` (raw little-endian 0RGB, six faces in [`Face::ALL`] order).
fn load_cube(
    map: &lut_core::EnvMap,
    n: u32,
    cache: Option<&std::path::Path>,
) -> Result<CubeMap, String> {
    let texels = n as usize * n as usize;
    let cache = cache.map(|p| {
        let mut s = p.as_os_str().to_owned();
        s.push(format!(".cube{n}"));
        std::path::PathBuf::from(s)
    });
    if let Some(bytes) = cache.as_ref().and_then(|p| std::fs::read(p).ok()) {
        if bytes.len() == 6 * texels * 4 {
            let px: Vec<u32> = bytes
                .chunks_exact(4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect();
            let faces: [&[u32]; 6] = std::array::from_fn(|k| &px[k * texels..(k + 1) * texels]);
            return CubeMap::from_faces(n, faces).map_err(|e| e.to_string());
        }
    }
    let cube = CubeMap::from_envmap(map, n, Sampler::Bilinear).map_err(|e| e.to_string())?;
    if let Some(p) = cache {
        let bytes: Vec<u8> = Face::ALL
            .iter()
            .flat_map(|&f| cube.face_pixels(f))
            .flat_map(|px| px.to_le_bytes())
            .collect();
        std::fs::write(&p, bytes).map_err(|e| format!("{}: {e}", p.display()))?;
    }
    Ok(cube)
}

fn run() -> Result<(), String> {
    let mut sampler = Sampler::Bilinear;
    let mut kernel = None;
    let (mut frames, mut threads) = (10usize, 1usize);
    let (mut map_wh, mut out_wh) = ((8192, 4096), (1920, 1080));
    let (mut hfov, mut pitch, mut yaw) = (90.0, 10.0, 30.0);
    let mut step = IndexStep::Adaptive;
    let mut gather = false;
    let mut cube_renderer = None;
    let mut cache = None;
    let mut level = 0;
    let mut rlod = false;
    let mut file = None;
    let mut crop: Option<(u32, u32, u32, u32)> = None;
    let mut lit = "none";
    let mut face = None;
    for a in std::env::args().skip(1) {
        let (k, v) = a
            .split_once('=')
            .ok_or_else(|| format!("argument '{a}' is not key=value"))?;
        let num = |v: &str| {
            v.parse::<f64>()
                .map_err(|_| format!("{k}={v}: not a number"))
        };
        match k {
            "sampler" => sampler = v.parse()?,
            "kernel" => kernel = lut_core::parse_kernel(v).map_err(|e| e.to_string())?,
            "frames" => frames = num(v)? as usize,
            "threads" => threads = num(v)? as usize,
            "map" => map_wh = size(v)?,
            "crop" => {
                let bad = || format!("crop={v}: not WxH+LEFT+TOP");
                let (wh, rest) = v.split_once('+').ok_or_else(bad)?;
                let (l, t) = rest.split_once('+').ok_or_else(bad)?;
                let (cw, ch) = size(wh)?;
                let n = |x: &str| x.parse::<u32>().map_err(|_| bad());
                crop = Some((cw, ch, n(l)?, n(t)?));
            }
            "size" => out_wh = size(v)?,
            "hfov" => hfov = num(v)?,
            "pitch" => pitch = num(v)?,
            "yaw" => yaw = num(v)?,
            "step" => {
                step = match v {
                    "adaptive" => IndexStep::Adaptive,
                    n => IndexStep::Fixed(num(n)? as u32),
                }
            }
            "mode" => match v {
                "lut" => {}
                "gather" => gather = true,
                "cube" => cube_renderer = Some(CubeRenderer::Accelerated),
                "cube-basic" => cube_renderer = Some(CubeRenderer::Basic),
                _ => {
                    return Err(format!(
                        "mode={v}: expected lut, gather, cube or cube-basic"
                    ))
                }
            },
            "cache" => cache = Some(std::path::PathBuf::from(v)),
            "level" => level = num(v)? as u32,
            "face" => {
                face = Some(match v {
                    "pi" => None,
                    n => Some(num(n)? as u32),
                })
            }
            "rlod" => rlod = num(v)? != 0.0,
            "file" => file = Some(std::path::PathBuf::from(v)),
            "lit" => {
                lit = match v {
                    "none" => "none",
                    "frame" => "frame",
                    "baked" => "baked",
                    _ => return Err(format!("lit={v}: expected none, frame or baked")),
                }
            }
            _ => return Err(format!("unknown argument '{k}'")),
        }
    }
    lut_core::set_kernel(kernel).map_err(|e| e.to_string())?;
    let t_load = Instant::now();
    let map = match &file {
        Some(p) => lut_core::load_map(p, &lut_core::LoadOptions::default(), &mut |_| {})
            .map_err(|e| e.to_string())?,
        None => load_map(map_wh, cache.as_deref())?,
    };
    // A partial map: the crop's pixels of the full map, placed where they were.
    let map = match crop {
        None => map,
        Some((cw, ch, l, t)) => {
            let px: Vec<u32> = (0..ch)
                .flat_map(|y| (0..cw).map(move |x| (x, y)))
                .map(|(x, y)| map.pixel((l + x) % map.width(), t + y))
                .collect();
            let c = lut_core::Crop::new(map.width(), map.height(), l, t, cw, ch)
                .map_err(|e| e.to_string())?;
            lut_core::EnvMap::from_pixels(cw, ch, &px, Projection::Equirect)
                .map_err(|e| e.to_string())?
                .into_partial(c)
                .map_err(|e| e.to_string())?
        }
    };
    // Shared with the panorama drawn (a map's), not copied.
    let map = std::sync::Arc::new(map);
    let map_wh = (map.width(), map.height());
    eprintln!("map ready in {:.2} s", t_load.elapsed().as_secs_f64());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .build()
        .map_err(|e| e.to_string())?;
    let opts = RenderOptions {
        sampler,
        index_step: step,
        threads: threads > 1,
        cube: cube_renderer.unwrap_or_default(),
        ..RenderOptions::default()
    };
    let cube = match cube_renderer {
        Some(_) => {
            let n = match face {
                None => (map_wh.0 / 4).max(1),
                Some(None) => (map_wh.0 as f64 / std::f64::consts::PI).round() as u32,
                Some(Some(n)) => n,
            };
            Some(load_cube(&map, n, cache.as_deref())?)
        }
        None => None,
    };
    let source = match &cube {
        Some(c) => format!(" (cube of {0}x{0} faces)", c.face_size()),
        None => String::new(),
    };
    let mut pano = match cube {
        Some(c) => Panorama::cube(c),
        None => Panorama::map(map.clone()),
    };
    let (w, h) = out_wh;
    let mut out = vec![0u32; w as usize * h as usize];
    pano.set_bilinear_level(level == 1);
    pano.set_still_level(level == 2);
    pano.set_region_lod(rlod);
    // The lights benchmark's room and luminaires; the map of their light is built (and a
    // lit copy baked) before timing.
    let shade = ShadeOptions::default();
    let lights = match lit {
        "none" => None,
        _ => Some(
            IlluminanceMap::build(&ring(&bench_table()), &MapOptions::default())
                .map_err(|e| e.to_string())?,
        ),
    };
    if let (Some(m), "baked") = (&lights, lit) {
        let t = Instant::now();
        pano = m
            .bake_panorama(&pano, &shade, &std::sync::atomic::AtomicBool::new(false))
            .map_err(|e| e.to_string())?;
        eprintln!("lit copy baked in {:.2} s", t.elapsed().as_secs_f64());
    }
    let frame_lights = lights.as_ref().filter(|_| lit == "frame");
    // The gather's positions (the map's geometry).
    let mut r = Renderer::new(&map);
    if level != 0 {
        let t = Instant::now();
        map.pyramid();
        eprintln!("pyramid built in {:.2} s", t.elapsed().as_secs_f64());
    }
    let view = |i: usize| View::new(yaw + 7.3 * i as f64, pitch, hfov).map_err(|e| e.to_string());
    let (mut times, cpu);
    if gather {
        // Indices of the padded map (stride W + 1) for the first view's nearest samples.
        let (pos, _) = r
            .positions(
                MapGeometry::new(map.width(), map.height(), Projection::Equirect),
                view(0)?,
                &opts,
                w,
                h,
            )
            .map_err(|e| e.to_string())?;
        let src: Vec<u32> = (0..=map.height())
            .flat_map(|y| (0..=map.width()).map(move |x| (x, y)))
            .map(|(x, y)| map.pixel(x.min(map.width() - 1), y.min(map.height() - 1)))
            .collect();
        let stride = map.width() as usize + 1;
        let idx: Vec<u32> = pos
            .iter()
            .map(|p| p.map_or(0, |(u, v)| (v as usize * stride + u as usize) as u32))
            .collect();
        let f = || gather_frame(&src, &idx, &mut out, w as usize);
        pool.install(f);
        (times, cpu) = pool.install(|| {
            timed_frames(frames, &mut |_| {
                gather_frame(&src, &idx, &mut out, w as usize);
                Ok(())
            })
        })?;
    } else {
        // One frame of `view`, lit as its rows are drawn with `lit=frame`.
        let mut draw = |out: &mut [u32], view: View| {
            let mut f = Frame::new(out, w, h).map_err(|e| e.to_string())?;
            match frame_lights {
                None => pano.render(view, &opts, &mut f),
                Some(m) => {
                    let cam = Camera::new(view, w, h);
                    let shader = m.frame_shader(&cam, &shade).map_err(|e| e.to_string())?;
                    let hook = |y0: usize, rows: &mut [u32]| shader.shade_band(y0, rows);
                    pano.render_with(view, &opts, &mut f, &hook)
                }
            }
            .map_err(|e| e.to_string())
        };
        // The first frame builds the tables and sizes the scratch: not counted.
        let rep = pool.install(|| draw(&mut out, view(0)?))?;
        eprintln!(
            "first view: index steps {}..={}, {} pixels evaluated exactly",
            rep.min_step, rep.max_step, rep.exact_pixels
        );
        (times, cpu) = pool
            .install(|| timed_frames(frames, &mut |i| draw(&mut out, view(i + 1)?).map(|_| ())))?;
    }
    let timed = &mut times[..];
    timed.sort_by(f64::total_cmp);
    let med = timed.get(timed.len() / 2).copied().unwrap_or(0.0);
    let min = timed.first().copied().unwrap_or(0.0);
    let checksum = out
        .iter()
        .fold(0u64, |a, &p| a.wrapping_mul(31).wrapping_add(p as u64));
    println!(
        "{} | {} {}{} {}x{} from {}x{}{source}, hfov {hfov}, {threads} thread(s): median {med:.2} ms (min {min:.2}; CPU {cpu:.2} ms per frame, all threads) over {} frame(s) (checksum {checksum:016x})",
        lut_core::kernel_info(),
        match (gather, cube_renderer) {
            (true, _) => "gather",
            (_, Some(r)) => r.name(),
            _ => "lut",
        },
        sampler.name(),
        match lit {
            "none" => String::new(),
            l => format!(" lit={l}"),
        },
        w,
        h,
        map_wh.0,
        map_wh.1,
        timed.len()
    );
    Ok(())
}
