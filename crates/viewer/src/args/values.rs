//! Parsers of plain values on the command line: sizes "WxH", angles, stops.

/// A finite number (surrounding blanks allowed), or `None`.
pub fn finite(s: &str) -> Option<f64> {
    s.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

/// "WxH" (or "WXH") into two whole numbers; `what` and `example` word the errors.
/// The one parser of sizes: the callers check the range.
fn parse_wxh(s: &str, what: &str, example: &str) -> Result<(u32, u32), String> {
    let (a, b) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("{what} '{s}' must look like WIDTHxHEIGHT, e.g. {example}"))?;
    let side = |t: &str, name: &str| {
        t.trim()
            .parse::<u32>()
            .map_err(|_| format!("{what} '{s}': {name} '{t}' is not a whole number"))
    };
    Ok((side(a, "width")?, side(b, "height")?))
}

/// An output size "WxH", each side in 1..=`MAX_OUTPUT_SIDE`.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = parse_wxh(s, "size", "1280x720")?;
    lut_core::check_size(w, h).map_err(|e| format!("size '{s}': {e}"))?;
    Ok((w, h))
}

/// The size "WxH" of a generated map, within the map limits.
pub fn parse_map_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = parse_wxh(s, "map size", "8192x4096")?;
    lut_core::check_map_size("generated map", w, h).map_err(|e| e.to_string())?;
    Ok((w, h))
}

/// A finite angle in degrees.
pub fn parse_angle(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!("'{s}' is not a finite number of degrees")),
        Err(_) => Err(format!("'{s}' is not a number of degrees")),
    }
}

/// A finite number (a clap value parser): NaN, infinities and numbers beyond `f64` are
/// refused on the command line (exit 2) by every command alike.
pub fn parse_finite(s: &str) -> Result<f64, String> {
    finite(s).ok_or_else(|| format!("'{}' is not a finite number", lut_core::shown(s)))
}

/// A luminaire multiplier: finite, at least 0 and at most
/// [`lut_core::limits::MAX_LIGHT_MULTIPLIER`].
pub fn parse_multiplier(s: &str) -> Result<f64, String> {
    let v = parse_finite(s)?;
    if v < 0.0 {
        return Err(format!("'{s}' is negative: give a factor of 0 or more"));
    }
    lut_core::check_limit(
        "light multiplier",
        v,
        lut_core::limits::MAX_LIGHT_MULTIPLIER,
        "",
    )
    .map_err(|e| e.to_string())?;
    Ok(v)
}

/// An exposure in stops (a finite number).
pub fn parse_stops(s: &str) -> Result<f64, String> {
    finite(s).ok_or_else(|| format!("exposure '{s}' is not a finite number of stops"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_name_the_bad_text() {
        assert_eq!(parse_size("1280x720"), Ok((1280, 720)));
        assert_eq!(parse_size(" 3 X 2 "), Ok((3, 2)));
        for bad in ["big", "0x10", "100000x10", "10x", "x10", "1.5x2", "-1x2"] {
            let e = parse_size(bad).unwrap_err();
            assert!(e.contains(bad), "{bad}: {e}");
        }
        assert_eq!(parse_map_size("8192x4096"), Ok((8192, 4096)));
        assert!(parse_map_size("8192").unwrap_err().contains("8192"));
        assert!(parse_map_size("1000000x500000").is_err());
    }

    #[test]
    fn numbers_must_be_finite() {
        assert_eq!(parse_angle("-135"), Ok(-135.0));
        assert_eq!(parse_angle("1e9"), Ok(1e9));
        assert!(parse_angle("nan").unwrap_err().contains("nan"));
        assert!(parse_angle("inf").unwrap_err().contains("finite"));
        assert!(parse_angle("ten").unwrap_err().contains("ten"));
        assert_eq!(parse_stops("-1.5"), Ok(-1.5));
        assert!(parse_stops("inf").is_err());
        assert_eq!(finite(" 2 "), Some(2.0));
        assert_eq!(finite("NaN"), None);
    }
}
