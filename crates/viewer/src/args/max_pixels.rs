//! `--max-pixels N`: the pixel limit every command that opens a panorama takes (render,
//! convert, bench, bench-load and the window). Checked from the file header before
//! anything is decoded (see `lut_core::load`).

use clap::Args;

/// The flag's default, as typed: 32768 × 16384 (a 32k equirectangular map).
pub const DEFAULT: &str = "536870912";

/// The `--max-pixels` flag, flattened into each command's arguments.
#[derive(Args, Debug, Clone, Copy, PartialEq, Eq)]
pub struct MaxPixelsArg {
    /// Refuse images with more pixels than N, read from the file header before decoding
    /// (a defence against decompression bombs). A whole number or a decimal with a
    /// suffix K, M or G (10^3, 10^6, 10^9), e.g. 600M or 1.5G. Default 536870912 =
    /// 32768x16384; 1073741824 (2^30) is the most any map can have.
    #[arg(long = "max-pixels", value_name = "N", default_value = DEFAULT, value_parser = parse_max_pixels)]
    pub max_pixels: u64,
}

impl Default for MaxPixelsArg {
    fn default() -> Self {
        MaxPixelsArg {
            max_pixels: lut_core::DEFAULT_MAX_PIXELS,
        }
    }
}

impl MaxPixelsArg {
    /// Load options with this limit and the given projection and tone.
    pub fn options(
        self,
        projection: Option<lut_core::Projection>,
        tone: lut_core::Tone,
    ) -> lut_core::LoadOptions {
        lut_core::LoadOptions {
            projection,
            tone,
            max_pixels: self.max_pixels,
        }
    }
}

/// Parse a pixel count: `536870912`, `600M`, `1.5G`, `20k` (decimal suffixes).
pub fn parse_max_pixels(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (num, mult) = match t.char_indices().last() {
        Some((i, 'k' | 'K')) => (&t[..i], 1e3),
        Some((i, 'm' | 'M')) => (&t[..i], 1e6),
        Some((i, 'g' | 'G')) => (&t[..i], 1e9),
        _ => (t, 1.0),
    };
    let bad = || {
        format!("pixel limit '{s}' must be a positive whole number of pixels, or a number with K, M or G (e.g. 600M, 1.5G)")
    };
    let num = num.trim();
    if num.is_empty() || !num.bytes().all(|b| b.is_ascii_digit() || b == b'.') {
        return Err(bad());
    }
    let n = if mult == 1.0 {
        num.parse::<u64>().map_err(|_| bad())?
    } else {
        let v: f64 = num.parse().map_err(|_| bad())?;
        let p = (v * mult).round();
        if !(p.is_finite() && p < 1.8e19) {
            return Err(bad());
        }
        p as u64
    };
    if n == 0 {
        return Err(bad());
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_plain_and_suffixed_counts() {
        assert_eq!(parse_max_pixels(DEFAULT), Ok(lut_core::DEFAULT_MAX_PIXELS));
        assert_eq!(parse_max_pixels("1000"), Ok(1000));
        assert_eq!(parse_max_pixels("600M"), Ok(600_000_000));
        assert_eq!(parse_max_pixels("1.5G"), Ok(1_500_000_000));
        assert_eq!(parse_max_pixels("20k"), Ok(20_000));
        assert_eq!(parse_max_pixels(" 2g "), Ok(2_000_000_000));
        for bad in [
            "", "0", "-5", "M", "1.5", "1e9", "abc", "5T", "1.2.3M", "0.0001K",
        ] {
            assert!(parse_max_pixels(bad).is_err(), "{bad}");
        }
    }
}
