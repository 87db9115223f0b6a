//! Writes the seed corpora of the fuzz targets (fuzz/seeds/TARGET/): small valid inputs
//! of every kind each parser reads, so coverage-guided fuzzing starts inside the formats.
//! Deterministic; the committed seeds are its output:
//!
//! ```text
//! cargo run -p lut-core --example fuzz_seeds -- fuzz/seeds
//! ```
//!
//! Larger real files in tests/data are added as further seed folders by
//! scripts/fuzz.sh (IES, EULUMDAT, JPEGs); see docs/reliability.md.

use exr::prelude::{Blocks, Compression, Vec2};
use image::{DynamicImage, ImageFormat, RgbImage};
use std::path::{Path, PathBuf};
use test_support::exr_files::{compressions, exr_file as exr};

fn pattern(w: u32, h: u32) -> RgbImage {
    RgbImage::from_fn(w, h, |x, y| {
        image::Rgb([
            (x * 255 / w.max(1)) as u8,
            (y * 255 / h.max(1)) as u8,
            ((x ^ y) * 16) as u8,
        ])
    })
}

fn encode(img: &DynamicImage, format: ImageFormat) -> Vec<u8> {
    let mut v = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut v), format)
        .expect("encode");
    v
}

fn jpeg(img: &RgbImage, quality: u8) -> Vec<u8> {
    let mut v = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut v, quality)
        .encode(
            img.as_raw(),
            img.width(),
            img.height(),
            image::ExtendedColorType::Rgb8,
        )
        .expect("jpeg");
    v
}

struct Out(PathBuf);

impl Out {
    fn put(&self, target: &str, name: &str, bytes: &[u8]) {
        let dir = self.0.join(target);
        std::fs::create_dir_all(&dir).expect("create seed folder");
        std::fs::write(dir.join(name), bytes).expect("write seed");
    }
}

fn gpano_fields(left: &str) -> Vec<(&'static str, String)> {
    vec![
        ("FullPanoWidthPixels", "64".into()),
        ("FullPanoHeightPixels", "32".into()),
        ("CroppedAreaLeftPixels", left.into()),
        ("CroppedAreaTopPixels", "8".into()),
        ("CroppedAreaImageWidthPixels", "32".into()),
        ("CroppedAreaImageHeightPixels", "16".into()),
        ("PoseHeadingDegrees", "-45.5".into()),
        ("ProjectionType", "equirectangular".into()),
    ]
}

fn main() {
    let dir = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "fuzz/seeds".into());
    let out = Out(PathBuf::from(&dir));
    let _ = std::fs::remove_dir_all(Path::new(&dir));

    // Maps: JPEG, PNG, Radiance HDR, OpenEXR.
    let p = pattern(32, 16);
    out.put("map_jpeg", "rgb-32x16.jpg", &jpeg(&p, 90));
    out.put("map_jpeg", "rgb-13x7-q30.jpg", &jpeg(&pattern(13, 7), 30));
    out.put(
        "map_jpeg",
        "gray-16x8.jpg",
        &encode(
            &DynamicImage::ImageLuma8(DynamicImage::ImageRgb8(pattern(16, 8)).to_luma8()),
            ImageFormat::Jpeg,
        ),
    );
    let fields = gpano_fields("40");
    let f: Vec<(&str, &str)> = fields.iter().map(|(k, v)| (*k, v.as_str())).collect();
    let tagged = lut_core::insert_xmp(&jpeg(&p, 80), &lut_core::xmp_packet(&f)).expect("xmp");
    out.put("map_jpeg", "gpano-32x16.jpg", &tagged);

    let d = DynamicImage::ImageRgb8(pattern(16, 8));
    out.put("map_png", "rgb8.png", &encode(&d, ImageFormat::Png));
    out.put(
        "map_png",
        "rgba8.png",
        &encode(&DynamicImage::ImageRgba8(d.to_rgba8()), ImageFormat::Png),
    );
    out.put(
        "map_png",
        "gray8.png",
        &encode(&DynamicImage::ImageLuma8(d.to_luma8()), ImageFormat::Png),
    );
    out.put(
        "map_png",
        "graya8.png",
        &encode(
            &DynamicImage::ImageLumaA8(d.to_luma_alpha8()),
            ImageFormat::Png,
        ),
    );
    out.put(
        "map_png",
        "rgb16.png",
        &encode(&DynamicImage::ImageRgb16(d.to_rgb16()), ImageFormat::Png),
    );

    let hdr = |w: u32, h: u32| {
        let img = DynamicImage::ImageRgb8(pattern(w, h)).to_rgb32f();
        let px: Vec<image::Rgb<f32>> = img
            .pixels()
            .map(|p| image::Rgb([p[0] * 4.0, p[1], p[2] * 0.25]))
            .collect();
        let mut v = Vec::new();
        image::codecs::hdr::HdrEncoder::new(&mut v)
            .encode(&px, w as usize, h as usize)
            .expect("hdr");
        v
    };
    out.put("map_hdr", "rle-32x16.hdr", &hdr(32, 16));
    out.put("map_hdr", "flat-4x2.hdr", &hdr(4, 2));

    let scan = Blocks::ScanLines;
    for (name, c) in compressions() {
        out.put(
            "map_exr",
            &format!("rgb-half-{name}.exr"),
            &exr(32, 16, &["R", "G", "B"], c, scan, true),
        );
    }
    out.put(
        "map_exr",
        "rgba-float-zip.exr",
        &exr(
            32,
            16,
            &["R", "G", "B", "A"],
            Compression::ZIP16,
            scan,
            false,
        ),
    );
    out.put(
        "map_exr",
        "y-float-piz.exr",
        &exr(32, 16, &["Y"], Compression::PIZ, scan, false),
    );
    out.put(
        "map_exr",
        "y-half-dwab.exr",
        &exr(40, 20, &["Y"], Compression::DWAB(None), scan, true),
    );
    let tiles = Blocks::Tiles(Vec2(16, 8));
    out.put(
        "map_exr",
        "rgb-half-tiled-zip.exr",
        &exr(40, 20, &["R", "G", "B"], Compression::ZIP1, tiles, true),
    );
    out.put(
        "map_exr",
        "rgb-half-tiled-dwaa.exr",
        &exr(
            40,
            20,
            &["R", "G", "B"],
            Compression::DWAA(None),
            tiles,
            true,
        ),
    );

    // Cube layout images: the first byte picks the layout (0: detect from the size).
    for (name, w, h) in [("cross", 64, 48), ("strip", 96, 16), ("3x2", 48, 32)] {
        let img = DynamicImage::ImageRgb8(pattern(w, h));
        for (ext, bytes) in [
            ("png", encode(&img, ImageFormat::Png)),
            ("jpg", jpeg(&pattern(w, h), 85)),
        ] {
            let mut v = vec![0u8];
            v.extend_from_slice(&bytes);
            out.put("cube", &format!("{name}.{ext}"), &v);
        }
    }

    // GPano XMP: tagged JPEGs (attribute form), and the element form as a bare packet.
    out.put("gpano", "attributes.jpg", &tagged);
    let wrapping = gpano_fields("60");
    let f: Vec<(&str, &str)> = wrapping.iter().map(|(k, v)| (*k, v.as_str())).collect();
    out.put("gpano", "wraps.xmp", lut_core::xmp_packet(&f).as_bytes());
    out.put(
        "gpano",
        "elements.xmp",
        br#"<x:xmpmeta xmlns:x="adobe:ns:meta/"><rdf:RDF xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#"><rdf:Description xmlns:GPano="http://ns.google.com/photos/1.0/panorama/"><GPano:FullPanoWidthPixels>8000</GPano:FullPanoWidthPixels><GPano:CroppedAreaLeftPixels>7000</GPano:CroppedAreaLeftPixels><GPano:CroppedAreaTopPixels>1000</GPano:CroppedAreaTopPixels><GPano:CroppedAreaImageWidthPixels>2000</GPano:CroppedAreaImageWidthPixels><GPano:CroppedAreaImageHeightPixels>1500</GPano:CroppedAreaImageHeightPixels></rdf:Description></rdf:RDF></x:xmpmeta>"#,
    );

    // The --coverage grammar and --light specs.
    for (i, s) in [
        "360x180",
        "120x60+30-10",
        "90x45-170+20",
        "360x90+0-45",
        "1x1",
        "200X100+0+0",
        "120x60 +30 -10",
    ]
    .iter()
    .enumerate()
    {
        out.put("coverage", &format!("{i}.txt"), s.as_bytes());
    }
    for (i, s) in [
        "lamp.ies@0,2.5,1",
        "a b/lamp.ldt@-1.5,2,0.5:90,-45",
        "x@1e-3,2,3:0,0",
        "C:/lights/l.ies@0,1,2",
    ]
    .iter()
    .enumerate()
    {
        out.put("light_spec", &format!("{i}.txt"), s.as_bytes());
    }
    // A minimal IES (the tests/data files are added as seed folders too).
    out.put(
        "ies",
        "minimal.ies",
        b"IESNA:LM-63-2002\n[TEST] x\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 100\n0 45 90\n0\n100 80 10\n",
    );
    println!("seeds written to {dir}");
}
