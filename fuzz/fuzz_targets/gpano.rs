//! GPano XMP: the JPEG segment walk, the XML parse and the placement of an image in its
//! full panorama (`crop_for_image`) for a few image sizes.
#![no_main]
use libfuzzer_sys::fuzz_target;
use lut_core::{read_gpano, GPano};

fn place(g: &GPano) {
    let mut sizes = vec![(512, 256), (1, 1), (300, 200), (4096, 3)];
    if let (Some(w), Some(h)) = (
        g.cropped_area_image_width_pixels,
        g.cropped_area_image_height_pixels,
    ) {
        if (1.0..=65536.0).contains(&w) && (1.0..=65536.0).contains(&h) {
            sizes.push((w as u32, h as u32));
        }
    }
    for (w, h) in sizes {
        if let Ok(c) = g.crop_for_image(w, h) {
            assert!(c.left() < c.full_width() && c.top() + c.height() <= c.full_height());
            assert_eq!((c.width(), c.height()), (w, h));
        }
    }
}

fuzz_target!(|data: &[u8]| {
    if let Ok(Some(g)) = read_gpano(data) {
        place(&g);
    }
    if let Ok(s) = std::str::from_utf8(data) {
        if let Ok(Some(g)) = GPano::from_xmp(s) {
            place(&g);
        }
    }
});
