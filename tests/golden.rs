//! Golden images: every projection at hard views (poles, near-poles, the seam, hfov 1 and
//! 170, 1x1 and odd sizes), rendered by the LUT renderer from a procedural grid map.
//!
//! Each image is checked two ways:
//! 1. **against the exact renderer** rendered in the same test (independent geometry):
//!    bilinear images may differ by at most 20 levels per channel at any pixel (a 0.05 px
//!    position error across a hard edge of contrast 255 in both axes moves the blend by at
//!    most 0.05·255·√2 ≈ 18 levels, plus up to 2 levels of 8-bit weight truncation) and by
//!    at most 0.5 level on average; nearest images may differ in at
//!    most 2 % of pixels (nearest flips at pixel boundaries, magnified at hfov 1);
//! 2. **against the stored truth** in `tests/truth/` (regressions): identical bytes
//!    required. `REGENERATE=1 cargo test --test golden` rewrites truths after an intended
//!    change; mismatches write `target/golden-out/<name>-{actual,diff}.png`.

use lut_core::{render_exact, Projection, RenderOptions, Renderer, Sampler, View};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn to_rgb(px: &[u32], w: u32, h: u32) -> image::RgbImage {
    let mut v = Vec::with_capacity(px.len() * 3);
    for p in px {
        v.extend_from_slice(&[(p >> 16) as u8, (p >> 8) as u8, *p as u8]);
    }
    image::RgbImage::from_raw(w, h, v).unwrap()
}

fn compare_to_truth(name: &str, px: &[u32], w: u32, h: u32) {
    let path = root().join("tests/truth").join(format!("{name}.png"));
    let img = to_rgb(px, w, h);
    if std::env::var_os("REGENERATE").is_some()
        || !path.exists() && std::env::var_os("CI").is_none()
    {
        img.save(&path).unwrap();
        return;
    }
    let truth = image::open(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (run with REGENERATE=1 to create)", path.display()))
        .to_rgb8();
    assert_eq!(truth.dimensions(), (w, h), "{name}: size changed");
    let mut worst = 0u8;
    let mut count = 0usize;
    let mut diff = image::RgbImage::new(w, h);
    for ((a, b), d) in img.pixels().zip(truth.pixels()).zip(diff.pixels_mut()) {
        let m = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap();
        if m > 0 {
            count += 1;
        }
        worst = worst.max(m);
        *d = image::Rgb([m, m, m]);
    }
    if count > 0 {
        let out = root().join("target/golden-out");
        std::fs::create_dir_all(&out).unwrap();
        img.save(out.join(format!("{name}-actual.png"))).unwrap();
        diff.save(out.join(format!("{name}-diff.png"))).unwrap();
        panic!("{name}: {count} pixels differ from the truth, worst by {worst}");
    }
}

fn cases() -> Vec<(&'static str, f64, f64, f64, u32, u32)> {
    vec![
        ("front", 0.0, 0.0, 90.0, 96, 64),
        ("zenith", 0.0, 90.0, 90.0, 96, 64),
        ("nadir", 30.0, -90.0, 100.0, 96, 64),
        ("near-zenith", 0.0, 89.9, 90.0, 95, 63),
        ("near-nadir", -60.0, -89.9, 120.0, 95, 63),
        ("seam", 180.0, 10.0, 60.0, 96, 64),
        ("seam-neg", -180.0, 60.0, 110.0, 97, 61),
        ("hfov1", 45.0, 20.0, 1.0, 64, 48),
        ("hfov170", 0.0, 30.0, 170.0, 128, 64),
        ("tiny", 12.0, 5.0, 80.0, 1, 1),
        ("odd", -77.0, -33.0, 70.0, 33, 17),
    ]
}

fn map_for(p: Projection) -> lut_core::EnvMap {
    let (w, h) = match p {
        Projection::Cylinder => (512, 192),
        _ => (512, 256),
    };
    lut_core::synth::grid_map(w, h, p).unwrap()
}

#[test]
fn golden_every_projection() {
    for p in Projection::ALL {
        let map = map_for(p);
        let mut r = Renderer::new(&map);
        for (case, yaw, pitch, hfov, w, h) in cases() {
            let view = View::new(yaw, pitch, hfov).unwrap();
            for sampler in [Sampler::Bilinear, Sampler::Nearest] {
                let n = (w * h) as usize;
                let mut lut = vec![0u32; n];
                let mut ex = vec![0u32; n];
                let opts = RenderOptions {
                    sampler,
                    ..RenderOptions::default()
                };
                r.render(&map, view, &opts, &mut lut, w, h).unwrap();
                render_exact(&map, view, sampler, &mut ex, w, h, false).unwrap();
                let name = format!("{p}_{}_{case}", sampler.name());
                let (mut worst, mut sum, mut differ) = (0u32, 0u64, 0usize);
                for (a, b) in lut.iter().zip(&ex) {
                    let m = (0..3)
                        .map(|c| ((a >> (8 * c)) & 0xFF).abs_diff((b >> (8 * c)) & 0xFF))
                        .max()
                        .unwrap();
                    worst = worst.max(m);
                    sum += m as u64;
                    differ += (m > 0) as usize;
                }
                let mean = sum as f64 / n as f64;
                match sampler {
                    Sampler::Bilinear | Sampler::Trilinear => assert!(
                        worst <= 20 && mean <= 0.5,
                        "{name}: LUT vs exact worst {worst} mean {mean:.3}"
                    ),
                    Sampler::Nearest => assert!(
                        differ as f64 <= 0.02 * n as f64 + 1.0,
                        "{name}: LUT vs exact, {differ} of {n} pixels differ"
                    ),
                }
                compare_to_truth(&name, &lut, w, h);
            }
        }
    }
}
