//! EULUMDAT (.ldt) photometric files.
//!
//! Written here rather than taken from a crate: the one maintained Rust parser found
//! (`eulumdat`) is AGPL-3.0, which this MIT/Apache workspace cannot take.
//!
//! The format (A. W. Stockmar, "EULUMDAT - ein Leuchtendatenformat für den europäischen
//! Beleuchtungsplaner", Licht '90; the item list as published by Lighting Analysts,
//! <http://www.helios32.com/Eulumdat.htm> and
//! <https://docs.agi32.com/PhotometricToolbox/Content/Open_Tool/eulumdat_file_format.htm>)
//! is one field per line:
//!
//! | line | field |
//! |---|---|
//! | 1 | company identification / data bank / version |
//! | 2 | Ityp, type indicator: 0 point source without symmetry, 1 point source symmetric about the vertical axis, 2 linear luminaire, 3 point source with any other symmetry |
//! | 3 | Isym, symmetry indicator: 0 none, 1 about the vertical axis, 2 to the C0-C180 plane, 3 to the C90-C270 plane, 4 to both |
//! | 4, 5 | Mc, the number of C planes in 0..360°, and Dc, their distance (0: not equidistant) |
//! | 6, 7 | Ng, the number of intensities (γ angles) per C plane, and Dg, their distance |
//! | 8-12 | measurement report number, luminaire name, luminaire number, file name, date/user |
//! | 13-21 | luminaire length/diameter, width, height; luminous area length/diameter, width, heights at C0, C90, C180, C270 (mm) |
//! | 22, 23 | DFF, downward flux fraction (%); LORL, light output ratio of the luminaire (%) |
//! | 24 | conversion factor for luminous intensities |
//! | 25 | tilt of the luminaire during measurement (degrees; road lighting) |
//! | 26 | n, the number of standard sets of lamps |
//! | 26a-f | per set: number of lamps, lamp type, total luminous flux of the set's lamps (lm), colour temperature, colour rendering, wattage with ballast (W) |
//! | 27 | 10 direct ratios for room indices k = 0.6 … 5 |
//! | 28, 29 | the Mc C angles, the Ng γ angles (degrees) |
//! | 30 | (Mc2 − Mc1 + 1) · Ng intensities in cd/klm, C plane after C plane |
//!
//! The stored planes Mc1..=Mc2 (1-based indices into the C angles) follow from Isym:
//! 0: 1..=Mc; 1: 1..=1; 2: 1..=Mc/2+1 (C0 to C180); 3: 3Mc/4+1..=3Mc/4+1+Mc/2, counted
//! modulo Mc (C270 through C0 to C90); 4: 1..=Mc/4+1 (C0 to C90).
//!
//! **Lamp sets.** The sets are read set after set (26a to 26f for the first set, then for
//! the second, ...), as the files in circulation are written. Field 26c is the *total*
//! flux of the set's lamps (the lamp count times the flux of one lamp is already in it).
//! The intensities refer to the first set, the luminaire's standard equipment: candela
//! = value × 26c of set 1 / 1000 × conversion factor (line 24). Further sets are
//! alternative equipment; [`LdtFile::candela_scale_for`] scales to one of them instead.
//!
//! **Absolute photometry.** A negative number of lamps marks absolute photometry, the
//! convention Lighting Analysts (AGi32) and DIAL (DIALux) agreed for LED luminaires
//! ("Handling of absolute photometry data in EULUMDAT files", 2009): field 26c then holds
//! the luminaire's own measured flux, LORL is 100 % and the intensities are still in cd per
//! 1000 lm of that flux. Both cases therefore scale the same way; what differs is the
//! meaning (no lamp to exchange, [`LdtFile::is_absolute`]).
//!
//! LORL, DFF and the direct ratios are kept as read: the intensities already carry the
//! luminaire's losses (integrated, they give LORL % of the lamp flux). The measurement
//! tilt (line 25) is applied where the luminaire is placed: the table is in the
//! goniometer's frame, in which the luminaire was tilted by this angle, and a placed
//! luminaire's aim is its own frame
//! ([`LightTable::measurement_tilt_deg`](super::LightTable::measurement_tilt_deg)).
//!
//! Lines end in CR LF or LF; a decimal comma is read as a decimal point; header text may
//! be ISO-8859-1. Every error names the file, the 1-based line, what was expected and (for
//! a malformed value) what was found, with control characters escaped.

use super::ies::{MAX_ANGLES, MAX_VALUES};
use super::quoted;
use std::path::Path;

/// Largest accepted number of lamp sets (real files have 1 to 3).
pub const MAX_LAMP_SETS: usize = 1000;

/// The type indicator Ityp (line 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LdtType {
    /// 0: point source without symmetry.
    PointNoSymmetry,
    /// 1: point source with symmetry about the vertical axis.
    PointRotational,
    /// 2: linear luminaire (subdivided in longitudinal and transverse directions).
    Linear,
    /// 3: point source with any other symmetry.
    PointOther,
}

impl LdtType {
    /// The indicator's number, 0 to 3.
    pub fn code(self) -> u32 {
        self as u32
    }

    /// A short description.
    pub fn name(self) -> &'static str {
        match self {
            LdtType::PointNoSymmetry => "point source without symmetry",
            LdtType::PointRotational => "point source, symmetric about the vertical axis",
            LdtType::Linear => "linear luminaire",
            LdtType::PointOther => "point source with other symmetry",
        }
    }
}

/// The symmetry indicator Isym (line 3): which C planes the file stores.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LdtSymmetry {
    /// 0: no symmetry, all Mc planes stored.
    None,
    /// 1: symmetric about the vertical axis, one plane stored.
    VerticalAxis,
    /// 2: symmetric to the C0-C180 plane, C0 to C180 stored.
    PlaneC0C180,
    /// 3: symmetric to the C90-C270 plane, C270 through C0 to C90 stored.
    PlaneC90C270,
    /// 4: symmetric to both planes, C0 to C90 stored.
    BothPlanes,
}

impl LdtSymmetry {
    /// The indicator's number, 0 to 4.
    pub fn code(self) -> u32 {
        self as u32
    }

    /// The stored planes Mc1..=Mc2 as 0-based indices into the C angles (Isym 3 counts
    /// past Mc: take them modulo Mc). `mc` must suit the symmetry (see [`LdtFile`]).
    pub fn stored_planes(self, mc: usize) -> (usize, usize) {
        match self {
            LdtSymmetry::None => (0, mc - 1),
            LdtSymmetry::VerticalAxis => (0, 0),
            LdtSymmetry::PlaneC0C180 => (0, mc / 2),
            LdtSymmetry::PlaneC90C270 => (3 * mc / 4, 3 * mc / 4 + mc / 2),
            LdtSymmetry::BothPlanes => (0, mc / 4),
        }
    }
}

/// One standard set of lamps (lines 26a-26f).
#[derive(Debug, Clone, PartialEq)]
pub struct LampSet {
    /// Number of lamps; negative marks absolute photometry.
    pub count: i64,
    /// Lamp type (free text).
    pub lamp_type: String,
    /// Total luminous flux of the set's lamps in lumens (the luminaire's flux for
    /// absolute photometry).
    pub total_flux: f64,
    /// Colour appearance / temperature (free text).
    pub colour: String,
    /// Colour rendering group / index (free text).
    pub colour_rendering: String,
    /// Wattage including ballast, W.
    pub watts: f64,
}

/// A parsed EULUMDAT file. Intensities are as stored (cd/klm), see
/// [`LdtFile::candela_scale`].
#[derive(Debug, Clone, PartialEq)]
pub struct LdtFile {
    /// The name the file was parsed under (its path), used in error messages.
    pub name: String,
    /// Line 1: company identification / data bank / version.
    pub company: String,
    /// Line 2.
    pub type_indicator: LdtType,
    /// Line 3.
    pub symmetry: LdtSymmetry,
    /// Line 5: Dc, distance between C planes in degrees (0: not equidistant).
    pub c_step: f64,
    /// Line 7: Dg, distance between γ angles in degrees (0: not equidistant).
    pub gamma_step: f64,
    /// Lines 8-12: report number, luminaire name, luminaire number, file name, date/user.
    pub report_number: String,
    /// Line 9.
    pub luminaire_name: String,
    /// Line 10.
    pub luminaire_number: String,
    /// Line 11.
    pub file_name: String,
    /// Line 12.
    pub date_user: String,
    /// Lines 13-15: luminaire length (or diameter), width (0: circular), height, mm.
    pub luminaire_mm: [f64; 3],
    /// Lines 16-17: luminous area length (or diameter), width (0: circular), mm.
    pub luminous_area_mm: [f64; 2],
    /// Lines 18-21: luminous area height at C0, C90, C180, C270, mm.
    pub luminous_heights_mm: [f64; 4],
    /// Line 22: downward flux fraction, %.
    pub downward_flux_fraction: f64,
    /// Line 23: light output ratio of the luminaire, %.
    pub light_output_ratio: f64,
    /// Line 24: conversion factor for luminous intensities.
    pub conversion_factor: f64,
    /// Line 25: tilt of the luminaire during measurement, degrees.
    pub measurement_tilt: f64,
    /// Lines 26a-f, at least one set.
    pub lamp_sets: Vec<LampSet>,
    /// Line 27: direct ratios for room indices 0.6, 0.8, 1, 1.25, 1.5, 2, 2.5, 3, 4, 5.
    pub direct_ratios: [f64; 10],
    /// Line 28: all Mc C angles in degrees, from 0, increasing.
    pub c_angles: Vec<f64>,
    /// Line 29: the Ng γ angles in degrees (0 = nadir), increasing.
    pub gamma_angles: Vec<f64>,
    /// Line 30: cd/klm, the stored planes in file order, plane-major:
    /// `intensities[k * Ng + j]` for stored plane k (see [`LdtFile::stored_c_angles`]).
    pub intensities: Vec<f64>,
    /// 1-based line of the first C angle, for error messages.
    pub c_angles_line: usize,
}

impl LdtFile {
    /// Read and parse a file.
    ///
    /// # Errors
    /// [`LdtError::Io`] when it cannot be read (or is larger than
    /// [`MAX_LIGHT_FILE_BYTES`](crate::MAX_LIGHT_FILE_BYTES)), otherwise as [`LdtFile::parse`].
    pub fn load(path: &Path) -> Result<LdtFile, LdtError> {
        let name = path.display().to_string();
        let text = super::read_text(path).map_err(|reason| LdtError::Io {
            file: name.clone(),
            reason,
        })?;
        // Behind the one containment: a parser's panic is the file's error.
        crate::guard::catch_quiet(|| LdtFile::parse(&text, &name)).unwrap_or_else(|panic| {
            Err(LdtError::Io {
                file: name.clone(),
                reason: format!("the parser failed on it (an internal error: {panic})"),
            })
        })
    }

    /// Parse the text of an EULUMDAT file; `file` names it in errors.
    ///
    /// # Errors
    /// [`LdtError::Syntax`] for a malformed or inconsistent field (naming the line, what
    /// was expected and what was found), [`LdtError::Truncated`] when the file ends early.
    pub fn parse(text: &str, file: &str) -> Result<LdtFile, LdtError> {
        Parser::new(text, file).parse()
    }

    /// Number of C planes Mc (line 4).
    pub fn c_plane_count(&self) -> usize {
        self.c_angles.len()
    }

    /// The C angles of the stored planes, in file order (Isym 3: C270 … C345, C0 … C90).
    pub fn stored_c_angles(&self) -> Vec<f64> {
        let mc = self.c_angles.len();
        let (a, b) = self.symmetry.stored_planes(mc);
        (a..=b).map(|i| self.c_angles[i % mc]).collect()
    }

    /// True for absolute photometry (a negative number of lamps in the first set).
    pub fn is_absolute(&self) -> bool {
        self.lamp_sets.first().is_some_and(|s| s.count < 0)
    }

    /// The factor from stored cd/klm to candela for lamp set `set` (0-based): its total
    /// flux / 1000 × the conversion factor; `None` past the sets.
    pub fn candela_scale_for(&self, set: usize) -> Option<f64> {
        self.lamp_sets
            .get(set)
            .map(|s| s.total_flux / 1000.0 * self.conversion_factor)
    }

    /// The factor from stored cd/klm to candela for the first (standard) lamp set.
    pub fn candela_scale(&self) -> f64 {
        self.candela_scale_for(0).unwrap_or(0.0)
    }

    /// The flux the intensities refer to: the first set's total lamp flux (the
    /// luminaire's flux for absolute photometry), lumens.
    pub fn lamp_flux(&self) -> f64 {
        self.lamp_sets.first().map_or(0.0, |s| s.total_flux)
    }

    /// The luminaire's flux the file declares: lamp flux × LORL / 100, lumens.
    pub fn luminaire_flux(&self) -> f64 {
        self.lamp_flux() * self.light_output_ratio / 100.0
    }

    /// Candela of stored plane `k` at γ index `j` (first lamp set), `None` outside.
    pub fn candela_at(&self, k: usize, j: usize) -> Option<f64> {
        let ng = self.gamma_angles.len();
        if j >= ng {
            return None;
        }
        self.intensities
            .get(k * ng + j)
            .map(|v| v * self.candela_scale())
    }
}

/// Why an EULUMDAT file could not be used. Every variant names the file; syntax errors
/// name the 1-based line, what was expected there and what was found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LdtError {
    /// The file could not be read.
    #[error("{file}: cannot read: {reason}")]
    Io {
        /// The file.
        file: String,
        /// Why.
        reason: String,
    },
    /// A field is malformed, out of range or inconsistent with another.
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
        /// The last line of the file with content.
        line: usize,
        /// What was expected next.
        expected: String,
    },
}

/// A number as written in an EULUMDAT file: a decimal comma counts as a point.
pub(crate) fn parse_number(text: &str) -> Option<f64> {
    let t = text.trim();
    let v = if t.contains(',') && !t.contains('.') && t.matches(',').count() == 1 {
        t.replacen(',', ".", 1).parse::<f64>().ok()
    } else {
        t.parse::<f64>().ok()
    };
    v.filter(|v| v.is_finite())
}

/// A whole number, written as an integer or an integral decimal ("24", "24.0").
pub(crate) fn parse_whole(text: &str) -> Option<i64> {
    let t = text.trim();
    t.parse::<i64>().ok().or_else(|| {
        parse_number(t)
            .filter(|f| f.fract() == 0.0 && f.abs() < 1e15)
            .map(|f| f as i64)
    })
}

struct Parser<'a> {
    file: &'a str,
    lines: Vec<&'a str>,
    /// 0-based index of the next header line.
    next: usize,
    /// Numeric tokens after the lamp sets: (text, 1-based line).
    tokens: Vec<(&'a str, usize)>,
    pos: usize,
}

impl<'a> Parser<'a> {
    fn new(text: &'a str, file: &'a str) -> Parser<'a> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let lines = text
            .split('\n')
            .map(|l| l.strip_suffix('\r').unwrap_or(l))
            .collect();
        Parser {
            file,
            lines,
            next: 0,
            tokens: Vec::new(),
            pos: 0,
        }
    }

    fn syntax(&self, line: usize, expected: impl Into<String>, found: String) -> LdtError {
        LdtError::Syntax {
            file: self.file.to_string(),
            line,
            expected: expected.into(),
            found,
        }
    }

    fn truncated(&self, expected: impl Into<String>) -> LdtError {
        LdtError::Truncated {
            file: self.file.to_string(),
            line: self
                .lines
                .iter()
                .rposition(|l| !l.trim().is_empty())
                .map_or(1, |i| i + 1),
            expected: expected.into(),
        }
    }

    /// The next header line (text without the line end) and its 1-based number. A
    /// trailing empty piece after the last newline does not count as a line.
    fn line(&mut self, expected: &str) -> Result<(&'a str, usize), LdtError> {
        let last_is_empty = self.lines.last().is_some_and(|l| l.is_empty());
        let n = self.lines.len() - usize::from(last_is_empty);
        if self.next >= n {
            return Err(self.truncated(expected));
        }
        self.next += 1;
        Ok((self.lines[self.next - 1], self.next))
    }

    fn text(&mut self, expected: &str) -> Result<String, LdtError> {
        Ok(self.line(expected)?.0.trim().to_string())
    }

    fn number(&mut self, expected: &str) -> Result<(f64, usize), LdtError> {
        let (t, line) = self.line(expected)?;
        match parse_number(t) {
            Some(v) => Ok((v, line)),
            None => Err(self.syntax(line, format!("{expected} (a number)"), found(t))),
        }
    }

    /// A number in `lo..=hi`.
    fn number_in(&mut self, expected: &str, lo: f64, hi: f64) -> Result<f64, LdtError> {
        let (t, line) = self.line(expected)?;
        match parse_number(t) {
            Some(v) if (lo..=hi).contains(&v) => Ok(v),
            _ => Err(self.syntax(
                line,
                format!("{expected} (a number in {lo}..={hi})"),
                found(t),
            )),
        }
    }

    fn whole(&mut self, expected: &str, lo: i64, hi: i64) -> Result<(i64, usize), LdtError> {
        let (t, line) = self.line(expected)?;
        match parse_whole(t) {
            Some(v) if (lo..=hi).contains(&v) => Ok((v, line)),
            _ => Err(self.syntax(
                line,
                format!("{expected} (a whole number in {lo}..={hi})"),
                found(t),
            )),
        }
    }

    fn token(&mut self, expected: &str) -> Result<(f64, usize), LdtError> {
        let Some(&(t, line)) = self.tokens.get(self.pos) else {
            return Err(self.truncated(expected));
        };
        self.pos += 1;
        match parse_number(t) {
            Some(v) => Ok((v, line)),
            None => Err(self.syntax(line, format!("{expected} (a number)"), quoted(t))),
        }
    }

    /// `n` strictly increasing angles in `lo..=hi`; with `step` > 0 the i-th must be
    /// first + i·step (within 0.01°). Returns them and the line of the first.
    fn angles(
        &mut self,
        n: usize,
        what: &str,
        hi: f64,
        step: (f64, &str),
    ) -> Result<(Vec<f64>, usize), LdtError> {
        let mut out: Vec<f64> = Vec::with_capacity(n);
        let mut first_line = 0;
        for i in 0..n {
            let expected = format!("{what} angle {} of {n} (degrees)", i + 1);
            let (a, line) = self.token(&expected)?;
            if i == 0 {
                first_line = line;
            }
            if !(0.0..=hi).contains(&a) {
                return Err(self.syntax(line, format!("{expected} in [0, {hi}]"), format!("{a}")));
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
            let (dc, name) = step;
            if dc > 0.0 {
                let want = out.first().copied().unwrap_or(a) + i as f64 * dc;
                if (a - want).abs() > 0.01 {
                    return Err(self.syntax(
                        line,
                        format!("{expected} = {want}, as {name} = {dc} says"),
                        format!("{a}"),
                    ));
                }
            }
            out.push(a);
        }
        Ok((out, first_line))
    }

    fn parse(mut self) -> Result<LdtFile, LdtError> {
        let company = self.text("the company identification (line 1)")?;
        let (ityp, _) = self.whole("the type indicator Ityp", 0, 3)?;
        let (isym, _) = self.whole("the symmetry indicator Isym", 0, 4)?;
        let symmetry = match isym {
            0 => LdtSymmetry::None,
            1 => LdtSymmetry::VerticalAxis,
            2 => LdtSymmetry::PlaneC0C180,
            3 => LdtSymmetry::PlaneC90C270,
            _ => LdtSymmetry::BothPlanes,
        };
        let type_indicator = match ityp {
            0 => LdtType::PointNoSymmetry,
            1 => LdtType::PointRotational,
            2 => LdtType::Linear,
            _ => LdtType::PointOther,
        };
        let (mc, mc_line) = self.whole("the number of C planes Mc", 1, MAX_ANGLES as i64)?;
        let mc = mc as usize;
        let need = match symmetry {
            LdtSymmetry::PlaneC0C180 | LdtSymmetry::PlaneC90C270 => 2,
            LdtSymmetry::BothPlanes => 4,
            _ => 1,
        };
        if !mc.is_multiple_of(need) {
            return Err(self.syntax(
                mc_line,
                format!(
                    "a number of C planes Mc divisible by {need}, as symmetry indicator {isym} \
                     stores a {} of them",
                    if need == 2 { "half" } else { "quarter" }
                ),
                format!("{mc}"),
            ));
        }
        let c_step = self.number_in("the distance Dc between C planes", 0.0, 360.0)?;
        let (ng, ng_line) = self.whole(
            "the number Ng of intensities per C plane",
            1,
            MAX_ANGLES as i64,
        )?;
        let ng = ng as usize;
        let gamma_step = self.number_in("the distance Dg between intensities", 0.0, 180.0)?;
        let (a, b) = symmetry.stored_planes(mc);
        let stored = b - a + 1;
        if stored * ng > MAX_VALUES {
            return Err(self.syntax(
                ng_line,
                format!("at most {MAX_VALUES} intensities"),
                format!("{stored} planes × {ng}"),
            ));
        }
        let report_number = self.text("the measurement report number (line 8)")?;
        let luminaire_name = self.text("the luminaire name (line 9)")?;
        let luminaire_number = self.text("the luminaire number (line 10)")?;
        let file_name = self.text("the file name (line 11)")?;
        let date_user = self.text("the date/user (line 12)")?;
        let mut mm = [0.0; 9];
        for (v, what) in mm.iter_mut().zip([
            "the luminaire length or diameter in mm",
            "the luminaire width in mm",
            "the luminaire height in mm",
            "the luminous area length or diameter in mm",
            "the luminous area width in mm",
            "the luminous area height at C0 in mm",
            "the luminous area height at C90 in mm",
            "the luminous area height at C180 in mm",
            "the luminous area height at C270 in mm",
        ]) {
            *v = self.number(what)?.0;
        }
        let downward_flux_fraction =
            self.number_in("the downward flux fraction DFF in %", 0.0, 100.0)?;
        let (light_output_ratio, lorl_line) = self.number("the light output ratio LORL in %")?;
        if light_output_ratio < 0.0 {
            return Err(self.syntax(
                lorl_line,
                "a light output ratio LORL in % that is not negative",
                format!("{light_output_ratio}"),
            ));
        }
        let (conversion_factor, cf_line) =
            self.number("the conversion factor for luminous intensities")?;
        if conversion_factor <= 0.0 {
            return Err(self.syntax(
                cf_line,
                "a positive conversion factor for luminous intensities",
                format!("{conversion_factor}"),
            ));
        }
        let measurement_tilt = self.number_in(
            "the tilt of the luminaire during measurement in degrees",
            -180.0,
            180.0,
        )?;
        let (n_sets, _) = self.whole("the number n of lamp sets", 1, MAX_LAMP_SETS as i64)?;
        let mut lamp_sets = Vec::with_capacity(n_sets as usize);
        for s in 1..=n_sets {
            let (count, count_line) = self.whole(
                &format!("the number of lamps of set {s} (negative: absolute photometry)"),
                -1_000_000,
                1_000_000,
            )?;
            if count == 0 {
                return Err(self.syntax(
                    count_line,
                    format!("a non-zero number of lamps of set {s}"),
                    "'0'".into(),
                ));
            }
            let lamp_type = self.text(&format!("the lamp type of set {s}"))?;
            let (total_flux, flux_line) =
                self.number(&format!("the total luminous flux of set {s} in lm"))?;
            if total_flux <= 0.0 && s == 1 {
                return Err(self.syntax(
                    flux_line,
                    "a positive total luminous flux of set 1 (it scales the cd/klm intensities)",
                    format!("{total_flux}"),
                ));
            }
            let colour = self.text(&format!("the colour temperature of set {s}"))?;
            let colour_rendering = self.text(&format!("the colour rendering index of set {s}"))?;
            let watts = self.number(&format!("the wattage of set {s} in W"))?.0;
            lamp_sets.push(LampSet {
                count,
                lamp_type,
                total_flux,
                colour,
                colour_rendering,
                watts,
            });
        }

        // --- the numbers: one per line as written, but read as tokens so a writer that
        // puts several on a line still parses; each keeps its line for errors.
        for (i, raw) in self.lines.iter().enumerate().skip(self.next) {
            for t in raw.split_whitespace() {
                self.tokens.push((t, i + 1));
            }
        }
        let mut direct_ratios = [0.0; 10];
        for (i, d) in direct_ratios.iter_mut().enumerate() {
            *d = self.token(&format!("direct ratio {} of 10", i + 1))?.0;
        }
        let (c_angles, c_angles_line) = self.angles(mc, "C", 360.0, (c_step, "Dc"))?;
        if c_angles[0] != 0.0 {
            return Err(self.syntax(
                c_angles_line,
                "C angle 1 = 0 (the C planes start at C0)",
                format!("{}", c_angles[0]),
            ));
        }
        // The stored half or quarter must end on the symmetry planes.
        let plane = |i: usize, want: f64| (i, want);
        let checks: &[(usize, f64)] = match symmetry {
            LdtSymmetry::PlaneC0C180 => &[plane(mc / 2, 180.0)],
            LdtSymmetry::PlaneC90C270 => &[plane(mc / 4, 90.0), plane(3 * mc / 4, 270.0)],
            LdtSymmetry::BothPlanes => &[plane(mc / 4, 90.0)],
            _ => &[],
        };
        for &(i, want) in checks {
            if (c_angles[i] - want).abs() > 0.01 {
                // The angle's own line: the C angles are the tokens after the ratios.
                let line = self.tokens[10 + i].1;
                return Err(self.syntax(
                    line,
                    format!(
                        "C angle {} = {want}: symmetry indicator {isym} stores the planes up to \
                         C{want}",
                        i + 1
                    ),
                    format!("{}", c_angles[i]),
                ));
            }
        }
        let (gamma_angles, _) = self.angles(ng, "gamma", 180.0, (gamma_step, "Dg"))?;
        let stored_angles: Vec<f64> = (a..=b).map(|i| c_angles[i % mc]).collect();
        let mut intensities = Vec::with_capacity(stored * ng);
        for c in &stored_angles {
            for j in 0..ng {
                let expected = format!("intensity {} of {ng} (cd/klm) of plane C{c}", j + 1);
                intensities.push(self.token(&expected)?.0);
            }
        }
        if let Some(&(t, line)) = self.tokens.get(self.pos) {
            return Err(self.syntax(
                line,
                format!("the end of the data after {} intensities", stored * ng),
                quoted(t),
            ));
        }
        Ok(LdtFile {
            name: self.file.to_string(),
            company,
            type_indicator,
            symmetry,
            c_step,
            gamma_step,
            report_number,
            luminaire_name,
            luminaire_number,
            file_name,
            date_user,
            luminaire_mm: [mm[0], mm[1], mm[2]],
            luminous_area_mm: [mm[3], mm[4]],
            luminous_heights_mm: [mm[5], mm[6], mm[7], mm[8]],
            downward_flux_fraction,
            light_output_ratio,
            conversion_factor,
            measurement_tilt,
            lamp_sets,
            direct_ratios,
            c_angles,
            gamma_angles,
            intensities,
            c_angles_line,
        })
    }
}

/// A header line as found: quoted, or "an empty line".
fn found(t: &str) -> String {
    if t.trim().is_empty() {
        "an empty line".into()
    } else {
        quoted(t.trim())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_accept_a_decimal_comma() {
        assert_eq!(parse_number("2,5"), Some(2.5));
        assert_eq!(parse_number(" 15 "), Some(15.0));
        assert_eq!(parse_number("1,2,3"), None);
        assert_eq!(parse_number("inf"), None);
        assert_eq!(parse_whole("24.0"), Some(24));
        assert_eq!(parse_whole("24.5"), None);
    }

    #[test]
    fn stored_planes_follow_the_symmetry() {
        assert_eq!(LdtSymmetry::None.stored_planes(24), (0, 23));
        assert_eq!(LdtSymmetry::VerticalAxis.stored_planes(24), (0, 0));
        assert_eq!(LdtSymmetry::PlaneC0C180.stored_planes(24), (0, 12));
        assert_eq!(LdtSymmetry::PlaneC90C270.stored_planes(24), (18, 30));
        assert_eq!(LdtSymmetry::BothPlanes.stored_planes(24), (0, 6));
    }
}
