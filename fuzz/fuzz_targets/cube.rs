//! Cube maps from one layout image in memory: layout detection from the size (or the
//! layout the first byte picks), the face checks, decoding through the map loader with a
//! small pixel limit, cutting the faces out.
#![no_main]
use libfuzzer_sys::fuzz_target;
use lut_core::Layout;

fuzz_target!(|data: &[u8]| {
    let Some((&pick, image)) = data.split_first() else {
        return;
    };
    let layout = match pick % 4 {
        0 => None,
        1 => Some(Layout::Cross),
        2 => Some(Layout::Strip),
        _ => Some(Layout::Grid3x2),
    };
    if let Ok(cube) = lut_core::decode_layout_image(image, "fuzz", layout, 1 << 18) {
        assert!(cube.face_size() >= 1);
    }
    let _ = Layout::detect(u32::from(pick) * 4, u32::from(pick) * 3);
});
