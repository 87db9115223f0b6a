//! Comparing 0RGB images: PSNR and per-channel differences; the sRGB transfer function
//! in f64 (an independent check of lut-core's tables).

/// sRGB (8-bit) → linear.
pub fn srgb_to_linear(c: u32) -> f64 {
    let c = f64::from(c) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear → sRGB (8-bit, clamped).
pub fn linear_to_srgb(l: f64) -> u32 {
    let l = l.clamp(0.0, 1.0);
    let s = if l <= 0.003_130_8 {
        l * 12.92
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u32
}

/// The largest difference of one channel between two 0RGB pixels.
pub fn max_channel_diff(a: u32, b: u32) -> u32 {
    [0, 8, 16]
        .iter()
        .map(|s| ((a >> s) & 0xFF).abs_diff((b >> s) & 0xFF))
        .max()
        .unwrap_or(0)
}

/// PSNR (dB) of `a` against `b` over all three channels (`a` and `b` must have the same
/// length; identical images give about 168 dB, the floor of the mean squared error).
pub fn psnr(a: &[u32], b: &[u32]) -> f64 {
    assert_eq!(a.len(), b.len(), "images of different sizes");
    let mut se = 0f64;
    for (p, q) in a.iter().zip(b) {
        for s in [0, 8, 16] {
            let d = ((p >> s) & 0xFF) as f64 - ((q >> s) & 0xFF) as f64;
            se += d * d;
        }
    }
    let mse = se / (a.len() * 3) as f64;
    10.0 * (255.0f64 * 255.0 / mse.max(1e-12)).log10()
}

/// How two images differ, per pixel by the largest channel difference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Diff {
    /// The largest difference of any channel of any pixel.
    pub worst: u32,
    /// The mean over pixels of each pixel's largest channel difference.
    pub mean: f64,
    /// Pixels that differ at all.
    pub differ: usize,
    /// Pixels compared.
    pub pixels: usize,
}

/// Compare `a` with `b` (same length) pixel by pixel.
pub fn diff(a: &[u32], b: &[u32]) -> Diff {
    assert_eq!(a.len(), b.len(), "images of different sizes");
    let (mut worst, mut sum, mut differ) = (0u32, 0u64, 0usize);
    for (p, q) in a.iter().zip(b) {
        let m = max_channel_diff(*p, *q);
        worst = worst.max(m);
        sum += u64::from(m);
        differ += usize::from(m > 0);
    }
    Diff {
        worst,
        mean: sum as f64 / a.len().max(1) as f64,
        differ,
        pixels: a.len(),
    }
}

/// 0RGB pixels as an 8-bit RGB image.
pub fn to_rgb(px: &[u32], w: u32, h: u32) -> image::RgbImage {
    let mut v = Vec::with_capacity(px.len() * 3);
    for p in px {
        v.extend_from_slice(&[(p >> 16) as u8, (p >> 8) as u8, *p as u8]);
    }
    image::RgbImage::from_raw(w, h, v).expect("w × h pixels")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics() {
        assert_eq!(max_channel_diff(0x102030, 0x112233), 3);
        let a = [0x000000, 0xFFFFFF];
        let b = [0x000000, 0xFFFF00];
        let d = diff(&a, &b);
        assert_eq!((d.worst, d.differ, d.pixels), (255, 1, 2));
        assert!((d.mean - 127.5).abs() < 1e-9);
        // one channel of six off by 255: mse = 255²/6, psnr = 10·log10(6)
        assert!((psnr(&a, &b) - 10.0 * 6f64.log10()).abs() < 1e-9);
        assert!(psnr(&a, &a) > 100.0);
    }
}
