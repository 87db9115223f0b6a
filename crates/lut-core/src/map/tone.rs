//! How HDR (floating-point) images become 8-bit display pixels: exposure, the tone curve
//! `x / (1 + x)`, sRGB encoding.

/// How HDR (floating-point) images become 8-bit display pixels.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Tone {
    /// Exposure in stops: linear values are multiplied by 2^EV before the tone curve.
    pub exposure_ev: f64,
}

/// One linear HDR value → 8-bit sRGB: clamp (negative, NaN → 0; +∞ → 1), the curve
/// x/(1+x), then the sRGB transfer function.
#[inline]
pub fn tone_map(x: f32) -> u8 {
    let y = if x.is_nan() || x <= 0.0 {
        0.0
    } else if x.is_infinite() {
        1.0
    } else {
        x / (1.0 + x)
    };
    let s = if y <= 0.003_130_8 {
        12.92 * y
    } else {
        1.055 * y.powf(1.0 / 2.4) - 0.055
    };
    (s.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tone_map_clamps_and_curves() {
        assert_eq!(tone_map(f32::NAN), 0);
        assert_eq!(tone_map(-3.0), 0);
        assert_eq!(tone_map(f32::NEG_INFINITY), 0);
        assert_eq!(tone_map(f32::INFINITY), 255);
        assert_eq!(tone_map(0.0), 0);
        // 1 -> 0.5 linear -> sRGB 0.7354 -> 188
        assert_eq!(tone_map(1.0), 188);
        assert!(tone_map(2.0) > tone_map(1.0));
    }
}
