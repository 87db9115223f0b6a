//! JPEG tiles: RGB8 pixels to a baseline JPEG at a quality, by libjpeg (the `mozjpeg`
//! crate) with its libjpeg-v6 defaults (`set_fastest_defaults`: the standard
//! quantization tables scaled by the quality, 4:2:0 chroma, no trellis or progressive
//! scans): the files libjpeg-turbo writes, as Pillow does for generate.py's tiles, at
//! libjpeg-turbo's SIMD speed (the `image` crate's pure-Rust encoder was several times
//! slower per pixel here).

use anyhow::{anyhow, Result};

/// Encode `w × h` RGB8 pixels as a JPEG of `quality` (1..=100) into `out`.
///
/// # Errors
/// The encoder's (it unwinds on errors; caught here).
pub fn encode_rgb(px: &[u8], w: u32, h: u32, quality: u8, out: &mut Vec<u8>) -> Result<()> {
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(
        || -> std::io::Result<Vec<u8>> {
            let mut c = mozjpeg::Compress::new(mozjpeg::ColorSpace::JCS_RGB);
            c.set_fastest_defaults();
            c.set_size(w as usize, h as usize);
            c.set_quality(f32::from(quality));
            let mut s = c.start_compress(Vec::with_capacity(px.len() / 8))?;
            s.write_scanlines(px)?;
            s.finish()
        },
    ));
    match r {
        Ok(Ok(bytes)) => {
            *out = bytes;
            Ok(())
        }
        Ok(Err(e)) => Err(anyhow!("cannot encode JPEG tile: {e}")),
        Err(_) => Err(anyhow!("cannot encode JPEG tile: the encoder failed")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_decode_back_close_to_the_pixels() {
        let (w, h) = (37u32, 20u32);
        let px: Vec<u8> = (0..w * h)
            .flat_map(|i| [(i % w * 6) as u8, (i / w * 12) as u8, 128])
            .collect();
        let mut out = Vec::new();
        encode_rgb(&px, w, h, 95, &mut out).unwrap();
        let back = image::load_from_memory(&out).unwrap().to_rgb8();
        assert_eq!(back.dimensions(), (w, h));
        let worst = back
            .as_raw()
            .iter()
            .zip(&px)
            .map(|(a, b)| a.abs_diff(*b))
            .max()
            .unwrap();
        assert!(worst <= 12, "worst {worst}");
        let mut low = Vec::new();
        encode_rgb(&px, w, h, 20, &mut low).unwrap();
        assert!(low.len() < out.len(), "quality matters");
    }
}
