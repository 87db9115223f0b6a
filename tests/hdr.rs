//! HDR environment maps: the sample EXRs (DWAB-compressed; lossy float16 with negative
//! values) decode, and every value is clamped and tone-mapped, never propagated.

use lut_core::tone_map;
use lut_core::LoadOptions;
use lut_core::{EnvMap, Projection, RenderOptions, Renderer, Tone, View};
use std::path::PathBuf;
use test_support::render::render_frame;

fn data(name: &str) -> PathBuf {
    test_support::test_data("hdr").join(name)
}

#[test]
fn sample_exrs_load_clamped_and_toned() {
    for name in ["interior.exr", "venice.exr"] {
        let path = data(name);
        let raw = image::open(&path).unwrap().to_rgb32f();
        let map = lut_core::load_map(&path, &LoadOptions::default(), &mut |_| {}).unwrap();
        assert_eq!((map.width(), map.height()), raw.dimensions(), "{name}");
        assert_eq!(map.projection(), Projection::Equirect);
        let mut negatives = 0;
        for (x, y, p) in raw.enumerate_pixels() {
            let got = map.pixel(x, y);
            for c in 0..3 {
                let v = p[c];
                if v < 0.0 || v.is_nan() {
                    negatives += 1;
                }
                let want = tone_map(v) as u32;
                assert_eq!(
                    (got >> (16 - 8 * c)) & 0xFF,
                    want,
                    "{name} ({x},{y}) channel {c} value {v}"
                );
            }
        }
        if name == "venice.exr" {
            assert!(negatives > 0, "venice.exr is known to hold negative values");
        }
        // Renders without trouble.
        let mut r = Renderer::new(&map);
        let view = View::new(10.0, 5.0, 90.0).unwrap();
        render_frame(&mut r, &map, view, &RenderOptions::default(), 64, 32);
    }
}

#[test]
fn exposure_brightens() {
    let bytes = std::fs::read(data("interior.exr")).unwrap();
    let dark = lut_core::decode_map(
        &bytes,
        "interior.exr",
        &LoadOptions {
            tone: Tone { exposure_ev: -2.0 },
            ..LoadOptions::default()
        },
        &mut |_| {},
    )
    .unwrap();
    let bright = lut_core::decode_map(
        &bytes,
        "interior.exr",
        &LoadOptions {
            tone: Tone { exposure_ev: 2.0 },
            ..LoadOptions::default()
        },
        &mut |_| {},
    )
    .unwrap();
    let sum = |m: &EnvMap| -> u64 {
        (0..m.height())
            .flat_map(|y| (0..m.width()).map(move |x| (x, y)))
            .map(|(x, y)| (m.pixel(x, y) & 0xFF) as u64)
            .sum()
    };
    assert!(sum(&bright) > sum(&dark) * 2);
}

/// Every compression `exr` writes, in scan lines and tiles, half and full floats, decodes
/// to the same map as `image`'s own EXR decoder (an independent path: its high-level
/// reader) followed by the tone curve.
#[test]
fn every_exr_compression_decodes_like_image_does() {
    use exr::prelude::{Blocks, Vec2};
    use test_support::exr_files::{compressions, exr_file};
    for (name, c) in compressions() {
        for (blocks, layout) in [
            (Blocks::ScanLines, "scan lines"),
            (Blocks::Tiles(Vec2(16, 8)), "tiles"),
        ] {
            for half in [true, false] {
                let what = format!("{name}, {layout}, half {half}");
                let bytes = exr_file(40, 20, &["R", "G", "B", "A"], c, blocks, half);
                let map =
                    lut_core::decode_map(&bytes, "t.exr", &LoadOptions::default(), &mut |_| {})
                        .unwrap_or_else(|e| panic!("{what}: {e}"));
                let raw = image::load_from_memory(&bytes).unwrap().to_rgb32f();
                assert_eq!((map.width(), map.height()), raw.dimensions(), "{what}");
                for (x, y, p) in raw.enumerate_pixels() {
                    let want = (u32::from(tone_map(p[0])) << 16)
                        | (u32::from(tone_map(p[1])) << 8)
                        | u32::from(tone_map(p[2]));
                    assert_eq!(map.pixel(x, y), want, "{what}: ({x},{y})");
                }
            }
        }
    }
}
