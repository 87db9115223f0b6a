//! IES LM-63 photometric files: the 1986 (no header), 1991, 1995, 2002 and 2019 variants.
//!
//! Written here rather than taken from a crate: the one maintained Rust parser found
//! (`eulumdat`) is AGPL-3.0, which this MIT/Apache workspace cannot take.
//!
//! The file is a header (format line, `[KEYWORD] value` lines or free text), a `TILT=` line,
//! the optional tilt block, then whitespace- (or comma-) separated numbers that may be
//! spread over any number of lines. Every error names the file, the 1-based line and what
//! was expected there; text quoted from the file has its control characters escaped, so
//! a hostile file cannot put escape sequences into a terminal through an error message.

use super::{quoted, sanitize};
use std::path::Path;

/// Largest accepted number of vertical or horizontal angles (real files have ≤ 361).
pub const MAX_ANGLES: usize = 10_000;
/// Largest accepted number of candela values in one file.
pub const MAX_VALUES: usize = 4_000_000;
/// Largest accepted number of tilt angle/factor pairs.
pub const MAX_TILT_PAIRS: usize = 10_000;

/// Which LM-63 edition the file says it follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IesFormat {
    /// LM-63-1986: no format line, free text before `TILT=`.
    Lm63_1986,
    /// LM-63-1991 (`IESNA91`).
    Lm63_1991,
    /// LM-63-1995 (`IESNA:LM-63-1995`).
    Lm63_1995,
    /// LM-63-2002 (`IESNA:LM-63-2002`).
    Lm63_2002,
    /// LM-63-2019 (`IES:LM-63-2019`).
    Lm63_2019,
}

impl IesFormat {
    /// The edition's usual name, e.g. `LM-63-2002`.
    pub fn name(self) -> &'static str {
        match self {
            IesFormat::Lm63_1986 => "LM-63-1986",
            IesFormat::Lm63_1991 => "LM-63-1991",
            IesFormat::Lm63_1995 => "LM-63-1995",
            IesFormat::Lm63_2002 => "LM-63-2002",
            IesFormat::Lm63_2019 => "LM-63-2019",
        }
    }
}

/// The goniometer type the angles refer to (LM-63 field "photometric type").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PhotometricType {
    /// Type C (1): vertical polar axis; vertical angle γ from nadir, horizontal angle C.
    C,
    /// Type B (2): horizontal (lateral) polar axis; floodlights.
    B,
    /// Type A (3): vertical polar axis through a horizontal beam; automotive.
    A,
}

impl PhotometricType {
    /// "A", "B" or "C".
    pub fn letter(self) -> &'static str {
        match self {
            PhotometricType::A => "A",
            PhotometricType::B => "B",
            PhotometricType::C => "C",
        }
    }
}

/// Lamp tilt data of a `TILT=INCLUDE` file.
#[derive(Debug, Clone, PartialEq)]
pub struct TiltData {
    /// Lamp-to-luminaire geometry code (1, 2 or 3).
    pub geometry: u32,
    /// Tilt angles in degrees, increasing.
    pub angles: Vec<f64>,
    /// Multiplying factor at each angle.
    pub factors: Vec<f64>,
}

impl TiltData {
    /// The factor at `angle_deg`, linearly interpolated, clamped to the end values.
    pub fn factor_at(&self, angle_deg: f64) -> f64 {
        interp_clamped(&self.angles, &self.factors, angle_deg)
    }
}

/// Linear interpolation in an increasing table, clamped at both ends (1 for empty).
fn interp_clamped(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let n = xs.len().min(ys.len());
    if n == 0 {
        return 1.0;
    }
    if x.is_nan() || x <= xs[0] {
        return ys[0];
    }
    if x >= xs[n - 1] {
        return ys[n - 1];
    }
    let i = xs[..n].partition_point(|&a| a <= x).clamp(1, n - 1);
    let (x0, x1) = (xs[i - 1], xs[i]);
    let t = if x1 > x0 { (x - x0) / (x1 - x0) } else { 0.0 };
    ys[i - 1] + (ys[i] - ys[i - 1]) * t
}

/// The `TILT=` line.
#[derive(Debug, Clone, PartialEq)]
pub enum Tilt {
    /// `TILT=NONE`: the lamp output does not depend on the luminaire's tilt.
    None,
    /// `TILT=INCLUDE`: the tilt table follows in the file.
    Include(TiltData),
}

/// A parsed IES file. Candela values are as stored in the file (not yet multiplied).
#[derive(Debug, Clone, PartialEq)]
pub struct IesFile {
    /// The name the file was parsed under (its path), used in error messages.
    pub name: String,
    /// The edition.
    pub format: IesFormat,
    /// `[KEYWORD] value` lines in file order (free text of a 1986 file goes under `""`).
    pub keywords: Vec<(String, String)>,
    /// Tilt data.
    pub tilt: Tilt,
    /// Number of lamps.
    pub lamps: u32,
    /// Rated lumens per lamp; `None` for absolute photometry (`-1` in the file).
    pub lumens_per_lamp: Option<f64>,
    /// Multiplier for every candela value.
    pub candela_multiplier: f64,
    /// Goniometer type.
    pub photometric_type: PhotometricType,
    /// 1 = feet, 2 = metres (for the luminous opening).
    pub units_type: u32,
    /// Luminous opening width, length, height (LM-63-2002+ use negative values for shapes).
    pub opening: [f64; 3],
    /// Ballast factor.
    pub ballast_factor: f64,
    /// "Future use" (≤2002) or file generation type (2019).
    pub file_generation_type: f64,
    /// Input watts.
    pub input_watts: f64,
    /// Vertical angles in degrees, strictly increasing.
    pub vertical_angles: Vec<f64>,
    /// Horizontal angles in degrees, strictly increasing.
    pub horizontal_angles: Vec<f64>,
    /// Candela values, horizontal-major: `candela[h * vertical_angles.len() + v]`.
    pub candela: Vec<f64>,
    /// Line (1-based) where the vertical angles start, for error messages.
    pub vertical_angles_line: usize,
    /// Line (1-based) where the horizontal angles start, for error messages.
    pub horizontal_angles_line: usize,
}

impl IesFile {
    /// The stored candela value at (horizontal index, vertical index), times the multiplier.
    pub fn candela_at(&self, h: usize, v: usize) -> Option<f64> {
        let nv = self.vertical_angles.len();
        if v >= nv {
            return None;
        }
        self.candela
            .get(h * nv + v)
            .map(|c| c * self.candela_multiplier)
    }

    /// Largest candela value times the multiplier.
    pub fn max_candela(&self) -> f64 {
        self.candela
            .iter()
            .fold(0.0f64, |m, &c| m.max(c * self.candela_multiplier))
    }

    /// Rated lumens of all lamps, `None` for absolute photometry.
    pub fn rated_lumens(&self) -> Option<f64> {
        self.lumens_per_lamp.map(|l| l * self.lamps as f64)
    }

    /// The value of the first `[KEYWORD]` line with this keyword (without brackets).
    pub fn keyword(&self, key: &str) -> Option<&str> {
        self.keywords
            .iter()
            .find(|(k, _)| k.eq_ignore_ascii_case(key))
            .map(|(_, v)| v.as_str())
    }

    /// Read and parse a file.
    ///
    /// # Errors
    /// [`IesError::Io`] when it cannot be read (or is larger than
    /// [`MAX_LIGHT_FILE_BYTES`](crate::MAX_LIGHT_FILE_BYTES)), otherwise as [`IesFile::parse`].
    pub fn load(path: &Path) -> Result<IesFile, IesError> {
        let name = path.display().to_string();
        // UTF-8, or Latin-1 as old files often are; refused past MAX_FILE_BYTES.
        let text = super::read_text(path).map_err(|reason| IesError::Io {
            file: name.clone(),
            reason,
        })?;
        // Behind the one containment: a parser's panic is the file's error.
        crate::guard::catch_quiet(|| IesFile::parse(&text, &name)).unwrap_or_else(|panic| {
            Err(IesError::Io {
                file: name.clone(),
                reason: format!("the parser failed on it (an internal error: {panic})"),
            })
        })
    }

    /// Parse the text of an IES file; `file` names it in errors.
    ///
    /// # Errors
    /// [`IesError::Syntax`] for a missing or malformed field (naming the line and what was
    /// expected), [`IesError::Truncated`] when the file ends early,
    /// [`IesError::TiltFileUnsupported`] for `TILT=<file>`.
    pub fn parse(text: &str, file: &str) -> Result<IesFile, IesError> {
        Parser::new(text, file).parse()
    }
}

/// Why an IES file could not be used. Every variant names the file; syntax errors name
/// the 1-based line and what was expected there.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum IesError {
    /// The file could not be read.
    #[error("{file}: cannot read: {reason}")]
    Io {
        /// The file.
        file: String,
        /// Why.
        reason: String,
    },
    /// A field is malformed.
    #[error("{file}:{line}: expected {expected}, found {found}")]
    Syntax {
        /// The file.
        file: String,
        /// 1-based line.
        line: usize,
        /// What was expected there.
        expected: String,
        /// What was there instead (file text quoted and with control characters escaped).
        found: String,
    },
    /// The file ended before a field.
    #[error("{file}:{line}: file ends early: expected {expected}")]
    Truncated {
        /// The file.
        file: String,
        /// The last line of the file.
        line: usize,
        /// What was expected next.
        expected: String,
    },
    /// `TILT=<file name>`: tilt data in a separate file is not supported.
    #[error(
        "{file}:{line}: TILT={name} refers to a separate tilt file, which is not supported \
         (only TILT=NONE and TILT=INCLUDE)"
    )]
    TiltFileUnsupported {
        /// The file.
        file: String,
        /// 1-based line of the TILT line.
        line: usize,
        /// The referenced tilt file (control characters escaped).
        name: String,
    },
}

struct Token<'a> {
    text: &'a str,
    line: usize,
}

struct Parser<'a> {
    file: &'a str,
    lines: Vec<&'a str>,
    tokens: Vec<Token<'a>>,
    pos: usize,
}

impl<'a> Parser<'a> {
    fn new(text: &'a str, file: &'a str) -> Parser<'a> {
        let lines = text
            .split('\n')
            .map(|l| l.strip_suffix('\r').unwrap_or(l))
            .collect();
        Parser {
            file,
            lines,
            tokens: Vec::new(),
            pos: 0,
        }
    }

    fn syntax(
        &self,
        line: usize,
        expected: impl Into<String>,
        found: impl Into<String>,
    ) -> IesError {
        IesError::Syntax {
            file: self.file.to_string(),
            line,
            expected: expected.into(),
            found: found.into(),
        }
    }

    fn last_line(&self) -> usize {
        // The last line that has any content (a trailing newline makes an empty last line).
        self.lines
            .iter()
            .rposition(|l| !l.trim().is_empty())
            .map_or(1, |i| i + 1)
    }

    fn next(&mut self, expected: &str) -> Result<&Token<'a>, IesError> {
        if self.pos >= self.tokens.len() {
            return Err(IesError::Truncated {
                file: self.file.to_string(),
                line: self.last_line(),
                expected: expected.to_string(),
            });
        }
        self.pos += 1;
        Ok(&self.tokens[self.pos - 1])
    }

    fn number(&mut self, expected: &str) -> Result<(f64, usize), IesError> {
        let tok = self.next(expected)?;
        let (text, line) = (tok.text, tok.line);
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok((v, line)),
            _ => Err(self.syntax(line, expected, quoted(text))),
        }
    }

    /// A whole number in `min..=max` (written as an integer or as an integral decimal).
    fn count(&mut self, expected: &str, min: i64, max: i64) -> Result<(u32, usize), IesError> {
        let tok = self.next(expected)?;
        let (text, line) = (tok.text, tok.line);
        let full = format!("{expected} (a whole number in {min}..={max})");
        let v = match text.parse::<i64>() {
            Ok(v) => v,
            Err(_) => match text.parse::<f64>() {
                Ok(f) if f.is_finite() && f.fract() == 0.0 && f.abs() < 1e12 => f as i64,
                _ => return Err(self.syntax(line, full, quoted(text))),
            },
        };
        if v < min || v > max {
            return Err(self.syntax(line, full, quoted(text)));
        }
        Ok((v as u32, line))
    }

    fn angles(
        &mut self,
        n: usize,
        what: &str,
        lo: f64,
        hi: f64,
    ) -> Result<(Vec<f64>, usize), IesError> {
        let mut out = Vec::with_capacity(n);
        let mut first_line = 0;
        for i in 0..n {
            let expected = format!("{what} angle {} of {n} (degrees)", i + 1);
            let (a, line) = self.number(&expected)?;
            if i == 0 {
                first_line = line;
            }
            if a < lo || a > hi {
                return Err(self.syntax(
                    line,
                    format!("{expected} in [{lo}, {hi}]"),
                    format!("{a}"),
                ));
            }
            if let Some(&prev) = out.last() {
                if a <= prev {
                    return Err(self.syntax(
                        line,
                        format!("{expected}, larger than the previous angle {prev}"),
                        format!("{a}"),
                    ));
                }
            }
            out.push(a);
        }
        Ok((out, first_line))
    }

    fn parse(mut self) -> Result<IesFile, IesError> {
        // --- header: format line, keywords, up to TILT= ---
        // A UTF-8 byte-order mark would hide the format line.
        if let Some(l) = self.lines.first_mut() {
            *l = l.trim_start_matches('\u{feff}');
        }
        let first = self.lines.first().map_or("", |l| l.trim());
        let upper = first.to_ascii_uppercase();
        let (format, header_start) = if upper.starts_with("IESNA91") {
            (IesFormat::Lm63_1991, 1)
        } else if upper.starts_with("IESNA:LM-63-1995") {
            (IesFormat::Lm63_1995, 1)
        } else if upper.starts_with("IESNA:LM-63-2002") {
            (IesFormat::Lm63_2002, 1)
        } else if upper.starts_with("IES:LM-63-2019") {
            (IesFormat::Lm63_2019, 1)
        } else if upper.starts_with("IESNA:LM-63-1991") || upper.starts_with("IESNA:LM-63") {
            // Unusual spellings: take the edition from the year when present.
            let f = if upper.contains("1991") {
                IesFormat::Lm63_1991
            } else {
                IesFormat::Lm63_2002
            };
            (f, 1)
        } else {
            (IesFormat::Lm63_1986, 0)
        };

        let mut keywords: Vec<(String, String)> = Vec::new();
        let mut tilt_line = None;
        for (i, raw) in self.lines.iter().enumerate().skip(header_start) {
            let line = raw.trim();
            if line.to_ascii_uppercase().starts_with("TILT") && line.contains('=') {
                tilt_line = Some(i);
                break;
            }
            if let Some(rest) = line.strip_prefix('[') {
                if let Some((k, v)) = rest.split_once(']') {
                    keywords.push((k.trim().to_string(), v.trim().to_string()));
                    continue;
                }
            }
            if !line.is_empty() {
                keywords.push((String::new(), line.to_string()));
            }
        }
        let Some(tilt_idx) = tilt_line else {
            return Err(IesError::Truncated {
                file: self.file.to_string(),
                line: self.last_line(),
                expected: "a TILT= line (TILT=NONE or TILT=INCLUDE) after the header".into(),
            });
        };
        let tilt_text = self.lines[tilt_idx].trim();
        let value = tilt_text.split_once('=').map_or("", |(_, v)| v.trim());
        let tilt_include = match value.to_ascii_uppercase().as_str() {
            "NONE" => false,
            "INCLUDE" => true,
            "" => {
                return Err(self.syntax(
                    tilt_idx + 1,
                    "TILT=NONE, TILT=INCLUDE or TILT=<file>",
                    quoted(tilt_text),
                ))
            }
            _ => {
                return Err(IesError::TiltFileUnsupported {
                    file: self.file.to_string(),
                    line: tilt_idx + 1,
                    name: sanitize(value),
                })
            }
        };

        // --- the numbers, over any number of lines ---
        for (i, &raw) in self.lines.iter().enumerate().skip(tilt_idx + 1) {
            for t in raw.split(|c: char| c.is_whitespace() || c == ',') {
                if !t.is_empty() {
                    self.tokens.push(Token {
                        text: t,
                        line: i + 1,
                    });
                }
            }
        }

        let tilt = if tilt_include {
            let (geometry, _) = self.count("the TILT=INCLUDE lamp-to-luminaire geometry", 1, 3)?;
            let (n, _) = self.count(
                "the number of TILT=INCLUDE angle/factor pairs",
                1,
                MAX_TILT_PAIRS as i64,
            )?;
            let n = n as usize;
            let (angles, _) = self.angles(n, "tilt", -360.0, 360.0)?;
            let mut factors = Vec::with_capacity(n);
            for i in 0..n {
                let (f, line) = self.number(&format!("tilt factor {} of {n}", i + 1))?;
                if f < 0.0 {
                    return Err(self.syntax(
                        line,
                        format!("tilt factor {} of {n} (not negative)", i + 1),
                        format!("{f}"),
                    ));
                }
                factors.push(f);
            }
            Tilt::Include(TiltData {
                geometry,
                angles,
                factors,
            })
        } else {
            Tilt::None
        };

        let (lamps, _) = self.count("the number of lamps", 1, 1_000_000)?;
        let (lumens, lumens_line) =
            self.number("lumens per lamp (or -1 for absolute photometry)")?;
        let lumens_per_lamp = if lumens < 0.0 {
            if (lumens + 1.0).abs() > 1e-9 {
                return Err(self.syntax(
                    lumens_line,
                    "lumens per lamp: a positive number, or -1 for absolute photometry",
                    format!("{lumens}"),
                ));
            }
            None
        } else {
            Some(lumens)
        };
        let (candela_multiplier, mline) = self.number("the candela multiplier")?;
        if candela_multiplier < 0.0 {
            return Err(self.syntax(
                mline,
                "a candela multiplier ≥ 0",
                format!("{candela_multiplier}"),
            ));
        }
        let (nv, _) = self.count("the number of vertical angles", 1, MAX_ANGLES as i64)?;
        let (nh, _) = self.count("the number of horizontal angles", 1, MAX_ANGLES as i64)?;
        let (pt, _) = self.count("the photometric type (1 = C, 2 = B, 3 = A)", 1, 3)?;
        let photometric_type = match pt {
            1 => PhotometricType::C,
            2 => PhotometricType::B,
            _ => PhotometricType::A,
        };
        let (units_type, _) = self.count("the units type (1 = feet, 2 = metres)", 1, 2)?;
        let (w, _) = self.number("the luminous opening width")?;
        let (l, _) = self.number("the luminous opening length")?;
        let (h, _) = self.number("the luminous opening height")?;
        let (ballast_factor, _) = self.number("the ballast factor")?;
        let (file_generation_type, _) =
            self.number("the ballast-lamp factor / file generation type")?;
        let (input_watts, _) = self.number("the input watts")?;

        let (nv, nh) = (nv as usize, nh as usize);
        if nv * nh > MAX_VALUES {
            return Err(self.syntax(
                self.tokens[self.pos - 1].line,
                format!("at most {MAX_VALUES} candela values"),
                format!("{nv} × {nh}"),
            ));
        }
        let (vlo, vhi, hlo, hhi) = match photometric_type {
            PhotometricType::C => (0.0, 180.0, 0.0, 360.0),
            _ => (-90.0, 90.0, -180.0, 180.0),
        };
        let (vertical_angles, vertical_angles_line) = self.angles(nv, "vertical", vlo, vhi)?;
        let (horizontal_angles, horizontal_angles_line) =
            self.angles(nh, "horizontal", hlo, hhi)?;
        let mut candela = Vec::with_capacity(nv * nh);
        for &ha in &horizontal_angles {
            for vi in 0..nv {
                let (c, _) = self.number(&format!(
                    "candela value {} of {nv} for horizontal angle {ha}",
                    vi + 1
                ))?;
                candela.push(c);
            }
        }
        if let Some(extra) = self.tokens.get(self.pos) {
            return Err(self.syntax(
                extra.line,
                format!("the end of the data after {} candela values", nv * nh),
                quoted(extra.text),
            ));
        }
        Ok(IesFile {
            name: self.file.to_string(),
            format,
            keywords,
            tilt,
            lamps,
            lumens_per_lamp,
            candela_multiplier,
            photometric_type,
            units_type,
            opening: [w, l, h],
            ballast_factor,
            file_generation_type,
            input_watts,
            vertical_angles,
            horizontal_angles,
            candela,
            vertical_angles_line,
            horizontal_angles_line,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MINIMAL: &str = "IESNA:LM-63-2002\n[TEST] t\nTILT=NONE\n1 1000 2 3 1 1 2 0 0 0\n1 1 10\n0 45 90\n0\n100 50 0\n";

    #[test]
    fn minimal_2002() {
        let f = IesFile::parse(MINIMAL, "m.ies").unwrap();
        assert_eq!(f.format, IesFormat::Lm63_2002);
        assert_eq!(f.keyword("test"), Some("t"));
        assert_eq!(f.vertical_angles, vec![0.0, 45.0, 90.0]);
        assert_eq!(f.candela_at(0, 1), Some(100.0));
        assert_eq!(f.max_candela(), 200.0);
        assert_eq!(f.rated_lumens(), Some(1000.0));
        assert_eq!(f.vertical_angles_line, 6);
    }

    #[test]
    fn format_1986_and_1991() {
        let body = "TILT=NONE\n1 -1 1 1 1 1 2 0 0 0 1 1 10 0 0 5\n";
        let f = IesFile::parse(&format!("some free text\n{body}"), "x").unwrap();
        assert_eq!(f.format, IesFormat::Lm63_1986);
        assert_eq!(f.lumens_per_lamp, None);
        let f = IesFile::parse(&format!("IESNA91\n[TEST] a\n{body}"), "x").unwrap();
        assert_eq!(f.format, IesFormat::Lm63_1991);
    }

    #[test]
    fn byte_order_mark_is_ignored() {
        let f = IesFile::parse(&format!("\u{feff}{MINIMAL}"), "bom.ies").unwrap();
        assert_eq!(f.format, IesFormat::Lm63_2002);
    }

    #[test]
    fn crlf_and_commas() {
        let t = MINIMAL.replace('\n', "\r\n").replace("0 45 90", "0,45,90");
        let f = IesFile::parse(&t, "m.ies").unwrap();
        assert_eq!(f.vertical_angles, vec![0.0, 45.0, 90.0]);
    }

    #[test]
    fn tilt_factor_interpolates_and_clamps() {
        let t = TiltData {
            geometry: 1,
            angles: vec![0.0, 10.0],
            factors: vec![1.0, 0.5],
        };
        assert_eq!(t.factor_at(5.0), 0.75);
        assert_eq!(t.factor_at(-3.0), 1.0);
        assert_eq!(t.factor_at(90.0), 0.5);
    }
}
