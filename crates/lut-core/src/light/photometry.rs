//! One photometric model for IES LM-63 and EULUMDAT files.
//!
//! Both formats describe the same thing: candela at pairs of angles on a goniometer. A
//! [`Photometry`] holds that in one form (type, symmetry, vertical and horizontal angles,
//! candela already scaled) from which [`LightTable`](super::LightTable) is built, so the
//! table, its symmetry folding and interpolation do not depend on the file format.
//!
//! EULUMDAT data is type C (C planes, γ from the nadir, the IES type C convention). Its
//! symmetry indicator maps to the table's symmetries: Isym 1 → rotational (one plane),
//! 2 → bilateral 0-180 (C0 to C180), 4 → quadrant (C0 to C90), 0 → none (all planes, the
//! table wraps around 360°), and 3 → bilateral 90-270. EULUMDAT stores the Isym 3 half
//! from C270 through C0 to C90; it is symmetric to the C90-C270 plane, I(C) = I(180° − C),
//! so the plane at C holds the values of 180° − C: those planes, reversed, are the half
//! from C90 through C180 to C270 that IES files store and the table folds into.
//!
//! Which format a file is in is decided by its content ([`detect_format`]), so a misnamed
//! file still loads; the extension only decides for a file whose content is too broken to
//! tell, so that it gets the right parser's error.

use super::ies::{IesError, IesFile, PhotometricType, Tilt, TiltData};
use super::ldt::{parse_number, parse_whole, LdtFile, LdtSymmetry};
use super::LightError;
use std::path::Path;

/// The symmetry of a distribution, folded at lookup (only the measured subset is stored).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Symmetry {
    /// Type C, one horizontal angle: the same in every C plane.
    Rotational,
    /// Type C, C from 0 to 90: symmetric about the 0-180 and 90-270 planes.
    Quadrant,
    /// Type C, C from 0 to 180: symmetric about the 0-180 plane.
    Bilateral0To180,
    /// Type C, C from 90 to 270: symmetric about the 90-270 plane.
    Bilateral90To270,
    /// Type A/B, H from 0: symmetric left-right (H → |H|).
    Lateral,
    /// No symmetry: the full measured range is stored (type C wraps around 360°).
    None,
}

impl Symmetry {
    /// A short name: "rotational", "quadrant", "bilateral 0-180", ...
    pub fn name(self) -> &'static str {
        match self {
            Symmetry::Rotational => "rotational",
            Symmetry::Quadrant => "quadrant",
            Symmetry::Bilateral0To180 => "bilateral 0-180",
            Symmetry::Bilateral90To270 => "bilateral 90-270",
            Symmetry::Lateral => "lateral",
            Symmetry::None => "none",
        }
    }
}

/// A photometric file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LightFileFormat {
    /// IES LM-63 (any edition).
    Ies,
    /// EULUMDAT (.ldt).
    Eulumdat,
}

impl LightFileFormat {
    /// "IES" or "EULUMDAT".
    pub fn name(self) -> &'static str {
        match self {
            LightFileFormat::Ies => "IES",
            LightFileFormat::Eulumdat => "EULUMDAT",
        }
    }
}

/// The format of a photometric file's text, judged by content only; `None` when neither
/// fits. In order:
/// 1. a first line starting `IESNA` or `IES:` (LM-63-1991 and later) → IES;
/// 2. lines 2 to 7 are an EULUMDAT type indicator (a whole number 0-3), symmetry
///    indicator (0-4), C-plane count (≥ 1), C-plane distance (a number), γ count (≥ 1) and
///    γ distance → EULUMDAT;
/// 3. a line starting `TILT` with an `=` (every IES file has one; LM-63-1986 has no format
///    line) → IES;
/// 4. lines 2 and 3 alone look like the two EULUMDAT indicators → EULUMDAT (a damaged
///    EULUMDAT file then gets the EULUMDAT parser's error naming the line).
pub fn detect_format(text: &str) -> Option<LightFileFormat> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let head: Vec<&str> = text.lines().take(7).collect();
    let first = head
        .first()
        .map_or(String::new(), |l| l.trim().to_ascii_uppercase());
    if first.starts_with("IESNA") || first.starts_with("IES:") {
        return Some(LightFileFormat::Ies);
    }
    let whole_in = |i: usize, lo: i64, hi: i64| {
        head.get(i)
            .and_then(|l| parse_whole(l))
            .is_some_and(|v| (lo..=hi).contains(&v))
    };
    let number = |i: usize| head.get(i).and_then(|l| parse_number(l)).is_some();
    let indicators = whole_in(1, 0, 3) && whole_in(2, 0, 4);
    if indicators && whole_in(3, 1, i64::MAX) && number(4) && whole_in(5, 1, i64::MAX) && number(6)
    {
        return Some(LightFileFormat::Eulumdat);
    }
    let has_tilt = text.lines().any(|l| {
        let l = l.trim_start();
        l.get(..4).is_some_and(|t| t.eq_ignore_ascii_case("TILT")) && l.contains('=')
    });
    if has_tilt {
        return Some(LightFileFormat::Ies);
    }
    indicators.then_some(LightFileFormat::Eulumdat)
}

/// The parsed file a [`Photometry`] came from, for its format-specific fields.
#[derive(Debug, Clone, PartialEq)]
pub enum PhotometrySource {
    /// An IES LM-63 file.
    Ies(IesFile),
    /// An EULUMDAT file.
    Ldt(LdtFile),
}

/// A luminaire's intensity distribution, whatever file it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Photometry {
    /// The name the file was parsed under (its path), used in messages.
    pub name: String,
    /// The parsed file.
    pub source: PhotometrySource,
    /// Goniometer type (EULUMDAT is always type C).
    pub photometric_type: PhotometricType,
    /// The symmetry, folded at lookup; it must match the horizontal angles (type C:
    /// rotational one angle, quadrant 0..90, bilateral 0..180 or 90..270, none from 0).
    pub symmetry: Symmetry,
    /// Vertical angles in degrees, strictly increasing (type C: γ, 0 = nadir).
    pub vertical_angles: Vec<f64>,
    /// Horizontal angles in degrees, strictly increasing (type C: C).
    pub horizontal_angles: Vec<f64>,
    /// Candela, horizontal-major: `candela[h * vertical_angles.len() + v]`, scaled (IES:
    /// × candela multiplier; EULUMDAT: cd/klm × lamp flux / 1000 × conversion factor).
    pub candela: Vec<f64>,
    /// Lamp output against tilt (IES `TILT=INCLUDE`).
    pub tilt: Option<TiltData>,
}

impl Photometry {
    /// Read a file and parse it as IES or EULUMDAT by its content ([`detect_format`]),
    /// falling back on the extension (`.ies`, `.ldt`) when the content does not tell.
    ///
    /// # Errors
    /// [`LightError::Io`] when it cannot be read, [`LightError::UnknownFormat`], or the
    /// chosen parser's error naming the line.
    pub fn load(path: &Path) -> Result<Photometry, LightError> {
        let name = path.display().to_string();
        let text = super::read_text(path).map_err(|reason| LightError::Io {
            file: name.clone(),
            reason,
        })?;
        // Behind the one containment: a parser's panic is the file's error.
        crate::guard::contain(path, || Photometry::parse(&text, &name))
    }

    /// Parse text as IES or EULUMDAT by its content; `name` names it in errors and its
    /// extension decides when the content does not.
    ///
    /// # Errors
    /// [`LightError::UnknownFormat`], or the chosen parser's error naming the line.
    pub fn parse(text: &str, name: &str) -> Result<Photometry, LightError> {
        let by_extension = || {
            let ext = Path::new(name).extension()?.to_str()?.to_ascii_lowercase();
            match ext.as_str() {
                "ies" => Some(LightFileFormat::Ies),
                "ldt" => Some(LightFileFormat::Eulumdat),
                _ => None,
            }
        };
        match detect_format(text).or_else(by_extension) {
            Some(LightFileFormat::Ies) => Photometry::from_ies(&IesFile::parse(text, name)?),
            Some(LightFileFormat::Eulumdat) => {
                Ok(Photometry::from_ldt(&LdtFile::parse(text, name)?))
            }
            None => Err(LightError::UnknownFormat {
                file: name.to_string(),
            }),
        }
    }

    /// The photometry of an IES file: candela × multiplier; the symmetry from the
    /// horizontal angles (LM-63: type C one angle, 0-90, 0-180, 90-270 or 0 to more than
    /// 180; types A and B lateral when they start at 0).
    ///
    /// # Errors
    /// [`LightError::Ies`] naming the line of the horizontal angles when a type C range
    /// declares no LM-63 symmetry; [`LightError::Inconsistent`] for a hand-made file whose
    /// fields do not agree.
    pub fn from_ies(file: &IesFile) -> Result<Photometry, LightError> {
        let h = &file.horizontal_angles;
        let (Some(&first), Some(&last)) = (h.first(), h.last()) else {
            return Err(LightError::Inconsistent {
                file: file.name.clone(),
                expected: "at least one vertical and one horizontal angle",
            });
        };
        let close = |a: f64, b: f64| (a - b).abs() < 1e-6;
        let symmetry = match file.photometric_type {
            PhotometricType::C => {
                if h.len() == 1 {
                    Symmetry::Rotational
                } else if close(first, 0.0) && close(last, 90.0) {
                    Symmetry::Quadrant
                } else if close(first, 0.0) && close(last, 180.0) {
                    Symmetry::Bilateral0To180
                } else if close(first, 90.0) && close(last, 270.0) {
                    Symmetry::Bilateral90To270
                } else if close(first, 0.0) && last > 180.0 {
                    Symmetry::None
                } else {
                    return Err(IesError::Syntax {
                        file: file.name.clone(),
                        line: file.horizontal_angles_line,
                        expected: "type C horizontal angles from 0 to 0, 90, 180 or 180-360, \
                                   or from 90 to 270"
                            .into(),
                        found: format!("{first} to {last}"),
                    }
                    .into());
                }
            }
            _ if close(first, 0.0) && h.len() > 1 => Symmetry::Lateral,
            _ => Symmetry::None,
        };
        let p = Photometry {
            name: file.name.clone(),
            source: PhotometrySource::Ies(file.clone()),
            photometric_type: file.photometric_type,
            symmetry,
            vertical_angles: file.vertical_angles.clone(),
            horizontal_angles: h.clone(),
            candela: file
                .candela
                .iter()
                .map(|&c| c * file.candela_multiplier)
                .collect(),
            tilt: match &file.tilt {
                Tilt::Include(t) => Some(t.clone()),
                Tilt::None => None,
            },
        };
        p.check()?;
        Ok(p)
    }

    /// The photometry of an EULUMDAT file (type C): intensities × the first lamp set's
    /// flux / 1000 × the conversion factor, its stored planes mapped to the table's
    /// symmetry (module docs).
    pub fn from_ldt(file: &LdtFile) -> Photometry {
        let scale = file.candela_scale();
        let ng = file.gamma_angles.len();
        let planes = file.stored_c_angles();
        let rows: Vec<&[f64]> = file.intensities.chunks_exact(ng).collect();
        let (symmetry, angles, order): (Symmetry, Vec<f64>, Vec<usize>) = match file.symmetry {
            _ if planes.len() == 1 => (Symmetry::Rotational, vec![planes[0]], vec![0]),
            LdtSymmetry::None => (Symmetry::None, planes.clone(), (0..planes.len()).collect()),
            LdtSymmetry::VerticalAxis => (Symmetry::Rotational, vec![planes[0]], vec![0]),
            LdtSymmetry::PlaneC0C180 => (
                Symmetry::Bilateral0To180,
                planes.clone(),
                (0..planes.len()).collect(),
            ),
            LdtSymmetry::BothPlanes => (
                Symmetry::Quadrant,
                planes.clone(),
                (0..planes.len()).collect(),
            ),
            LdtSymmetry::PlaneC90C270 => {
                // Plane k at C holds I(180° − C); reversed they run from C90 to C270.
                let order: Vec<usize> = (0..planes.len()).rev().collect();
                let angles = order
                    .iter()
                    .map(|&k| (180.0 - planes[k]).rem_euclid(360.0))
                    .collect();
                (Symmetry::Bilateral90To270, angles, order)
            }
        };
        let candela = order
            .iter()
            .flat_map(|&k| rows[k].iter().map(|&v| v * scale))
            .collect();
        Photometry {
            name: file.name.clone(),
            source: PhotometrySource::Ldt(file.clone()),
            photometric_type: PhotometricType::C,
            symmetry,
            vertical_angles: file.gamma_angles.clone(),
            horizontal_angles: angles,
            candela,
            tilt: None,
        }
    }

    /// The luminaire's tilt during measurement in degrees (EULUMDAT line 25; 0 for IES
    /// files, which have no such field): the table is in the goniometer's frame, in
    /// which the luminaire's datum axis was raised by this angle on its C90 side. See
    /// [`LightTable::measurement_tilt_deg`](super::LightTable::measurement_tilt_deg).
    pub fn measurement_tilt_deg(&self) -> f64 {
        match &self.source {
            PhotometrySource::Ies(_) => 0.0,
            PhotometrySource::Ldt(f) => f.measurement_tilt,
        }
    }

    /// The file format's name: the IES edition ("LM-63-2002", ...) or "EULUMDAT".
    pub fn format_name(&self) -> &'static str {
        match &self.source {
            PhotometrySource::Ies(f) => f.format.name(),
            PhotometrySource::Ldt(_) => "EULUMDAT",
        }
    }

    /// The luminaire's name or description, when the file gives one.
    pub fn luminaire(&self) -> Option<&str> {
        match &self.source {
            PhotometrySource::Ies(f) => f.keyword("LUMINAIRE"),
            PhotometrySource::Ldt(f) => Some(f.luminaire_name.as_str()),
        }
        .filter(|s| !s.is_empty())
    }

    /// The factor from the file's stored values to candela: the IES candela multiplier,
    /// or the EULUMDAT lamp flux / 1000 × conversion factor.
    pub fn candela_scale(&self) -> f64 {
        match &self.source {
            PhotometrySource::Ies(f) => f.candela_multiplier,
            PhotometrySource::Ldt(f) => f.candela_scale(),
        }
    }

    /// Rated lamp lumens (IES: lamps × lumens per lamp; EULUMDAT: the first set's total
    /// lamp flux); `None` for absolute photometry.
    pub fn rated_lumens(&self) -> Option<f64> {
        match &self.source {
            PhotometrySource::Ies(f) => f.rated_lumens(),
            PhotometrySource::Ldt(f) => (!f.is_absolute()).then(|| f.lamp_flux()),
        }
    }

    /// Largest candela value.
    pub fn max_candela(&self) -> f64 {
        self.candela.iter().fold(0.0f64, |m, &c| m.max(c))
    }

    /// Candela at (horizontal index, vertical index), `None` outside.
    pub fn candela_at(&self, h: usize, v: usize) -> Option<f64> {
        let nv = self.vertical_angles.len();
        if v >= nv {
            return None;
        }
        self.candela.get(h * nv + v).copied()
    }

    /// The fields must agree (they are public, so a caller may assemble one by hand).
    pub(crate) fn check(&self) -> Result<(), LightError> {
        let (v, h) = (&self.vertical_angles, &self.horizontal_angles);
        let increasing =
            |a: &[f64]| a.iter().all(|x| x.is_finite()) && a.windows(2).all(|w| w[0] < w[1]);
        let is_c = self.photometric_type == PhotometricType::C;
        let close = |a: f64, b: f64| (a - b).abs() < 1e-6;
        let what = if v.is_empty() || h.is_empty() {
            Some("at least one vertical and one horizontal angle")
        } else if self.candela.len() != v.len() * h.len() {
            Some("vertical × horizontal candela values")
        } else if !increasing(v) || !increasing(h) {
            Some("finite, strictly increasing angles")
        } else if !self.candela.iter().all(|c| c.is_finite()) {
            Some("finite candela values")
        } else {
            let (first, last) = (h[0], h[h.len() - 1]);
            let fits = match self.symmetry {
                Symmetry::Rotational => is_c && h.len() == 1,
                Symmetry::Quadrant => is_c && close(first, 0.0) && close(last, 90.0),
                Symmetry::Bilateral0To180 => is_c && close(first, 0.0) && close(last, 180.0),
                Symmetry::Bilateral90To270 => is_c && close(first, 90.0) && close(last, 270.0),
                Symmetry::Lateral => !is_c && close(first, 0.0),
                Symmetry::None => !is_c || (close(first, 0.0) && last <= 360.0 + 1e-6),
            };
            (!fits).then_some("horizontal angles that match the symmetry")
        };
        match what {
            Some(expected) => Err(LightError::Inconsistent {
                file: self.name.clone(),
                expected,
            }),
            None => Ok(()),
        }
    }
}
