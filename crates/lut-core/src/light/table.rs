//! The goniometric light table of EP 0613099.
//!
//! * Claim 1-3: illumination values in a 2-D table indexed by the direction from the light
//!   relative to its aim, as a pair of polar angles (vertical, horizontal); the index has
//!   an integer and a fractional part and the value is filtered (bilinear) by the fraction.
//!   The table is kept at the file's measured angles, so lookups are exact there and linear
//!   between; a uniformly spaced axis is indexed by one multiply, any other by bisection.
//! * Claim 9: the symmetry of the file (rotational, quadrant, bilateral about 0-180 or
//!   90-270, lateral for types A/B) is folded at lookup: only the measured subset is stored.
//! * Claim 8: leading and trailing vertical ranges where every value is the same constant
//!   (zero beyond a cut-off, say) are not stored; the constant is substituted at lookup.
//!   Outside the measured vertical range the value is zero.
//! * Claims 4-7: a series of tables for increasing distance. Level k serves distance
//!   d_ref·2^k; it is level k−1 pre-filtered with a [¼ ½ ¼] kernel and decimated, so it is
//!   about half the size in each dimension that still has three or more entries. The
//!   distance index D = log2(d / d_ref) (clamped to the series) has a fraction that
//!   interpolates between two levels. Values are stored normalized to the reference
//!   distance (lux at d_ref on a surface facing the light, I / d_ref²) and scaled by
//!   (d_ref / d)² at lookup.
//!
//! Angles per photometric type, from a unit direction (x, y, z) in the light's frame
//! (x right, y up, z along the aim):
//! * type C: vertical γ = acos z (0 = the aim, "nadir" for a light aimed down), horizontal
//!   C = atan2(−x, y) in [0°, 360°): C = 0 toward the light's up axis, C = 90° toward its
//!   left (counter-clockwise seen from behind the light, i.e. from above for a downlight);
//! * type A: polar axis = the light's up axis. Horizontal H = atan2(x, z) (positive right),
//!   vertical V = asin y (positive up);
//! * type B: polar axis = the light's lateral (right) axis. Horizontal H = asin x (positive
//!   right), vertical V = atan2(y, z) (positive up).
//!
//! (LM-63 leaves types A and B loosely defined; near the beam axis all three agree that
//! horizontal is left-right and vertical is up-down.)

use super::ies::{IesError, IesFile, PhotometricType, TiltData};
use super::LightError;
use glam::DVec3;

/// The symmetry a file's horizontal angles declare, folded at lookup.
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

/// Options for building a [`LightTable`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableOptions {
    /// The reference distance d_ref in metres (level 0 serves d ≤ d_ref). Default 4 m, so
    /// most of a room is lit from the full-resolution table.
    pub reference_distance: f64,
    /// Most tables in the distance series (1 = no series). Default 4.
    pub max_levels: usize,
}

impl Default for TableOptions {
    fn default() -> Self {
        TableOptions {
            reference_distance: 4.0,
            max_levels: 4,
        }
    }
}

/// One table axis: increasing angles, with a fast path when they are evenly spaced.
#[derive(Debug, Clone, PartialEq)]
struct Axis {
    a: Vec<f64>,
    /// (first angle, 1 / step) when evenly spaced.
    uniform: Option<(f64, f64)>,
}

impl Axis {
    fn new(a: Vec<f64>) -> Axis {
        let uniform = if a.len() >= 2 {
            let step = (a[a.len() - 1] - a[0]) / (a.len() - 1) as f64;
            let even = a
                .windows(2)
                .all(|w| ((w[1] - w[0]) - step).abs() <= 1e-9 * step.abs().max(1.0));
            (even && step > 0.0).then(|| (a[0], 1.0 / step))
        } else {
            None
        };
        Axis { a, uniform }
    }

    fn first(&self) -> f64 {
        self.a[0]
    }

    fn last(&self) -> f64 {
        self.a[self.a.len() - 1]
    }

    /// Integer index and fraction of `x`, which lies in [first, last]: x sits between
    /// entries i and i+1 at fraction t (i = 0, t = 0 for a one-entry axis).
    #[inline]
    fn locate(&self, x: f64) -> (usize, f64) {
        let n = self.a.len();
        if n < 2 {
            return (0, 0.0);
        }
        if let Some((a0, inv)) = self.uniform {
            let f = ((x - a0) * inv).max(0.0);
            let i = (f as usize).min(n - 2);
            return (i, (f - i as f64).clamp(0.0, 1.0));
        }
        let i = self.a.partition_point(|&v| v <= x).clamp(1, n - 1) - 1;
        let (x0, x1) = (self.a[i], self.a[i + 1]);
        (i, ((x - x0) / (x1 - x0)).clamp(0.0, 1.0))
    }
}

/// One table of the distance series: values at (horizontal, vertical) angle pairs,
/// normalized to the reference distance, with constant vertical ranges cut off.
#[derive(Debug, Clone, PartialEq)]
struct Level {
    h: Axis,
    /// The stored vertical subset (constant ranges removed).
    v: Axis,
    /// Horizontal-major: values[ih * nv + iv], lux at d_ref.
    values: Vec<f64>,
    /// The measured vertical range; zero outside.
    v_measured: (f64, f64),
    /// Constant below / above the stored vertical subset.
    below: f64,
    above: f64,
    /// Type C without symmetry whose last angle is short of 360°: wrap to the first.
    wrap: bool,
    /// Type A/B: zero outside the measured horizontal range.
    h_bounded: bool,
}

impl Level {
    /// The value at vertical angle v when it lies in a range that is not stored (zero
    /// outside the measured range, or a constant range); `None` inside the stored rows.
    #[inline]
    fn constant_at(&self, v: f64) -> Option<f64> {
        if !(v >= self.v_measured.0 && v <= self.v_measured.1) {
            Some(0.0)
        } else if v < self.v.first() {
            Some(self.below)
        } else if v > self.v.last() {
            Some(self.above)
        } else {
            None
        }
    }

    /// The value at (folded) horizontal angle h and vertical angle v.
    #[inline]
    fn sample(&self, h: f64, v: f64) -> f64 {
        if let Some(c) = self.constant_at(v) {
            return c;
        }
        let nv = self.v.a.len();
        let nh = self.h.a.len();
        let (ih0, ih1, th) = if nh == 1 {
            (0, 0, 0.0)
        } else if h > self.h.last() || h < self.h.first() {
            if self.wrap && h > self.h.last() {
                let span = self.h.first() + 360.0 - self.h.last();
                (nh - 1, 0, ((h - self.h.last()) / span).clamp(0.0, 1.0))
            } else if self.h_bounded {
                return 0.0;
            } else {
                // Folding keeps h inside; a rounding step outside clamps to the edge.
                let i = if h > self.h.last() { nh - 1 } else { 0 };
                (i, i, 0.0)
            }
        } else {
            let (i, t) = self.h.locate(h);
            (i, i + 1, t)
        };
        let (iv, tv) = self.v.locate(v);
        let iv1 = (iv + 1).min(nv - 1);
        let row0 = &self.values[ih0 * nv..ih0 * nv + nv];
        let row1 = &self.values[ih1 * nv..ih1 * nv + nv];
        let a = row0[iv] + (row0[iv1] - row0[iv]) * tv;
        let b = row1[iv] + (row1[iv1] - row1[iv]) * tv;
        a + (b - a) * th
    }
}

/// A full measured grid in f64 (before trimming), horizontal-major.
#[derive(Debug, Clone)]
struct Grid {
    h: Vec<f64>,
    v: Vec<f64>,
    vals: Vec<f64>,
}

#[derive(Debug, Clone, Copy)]
enum Edge {
    /// Mirror about the end entries (symmetry planes, poles, range ends).
    Mirror,
    /// Periodic with this many distinct entries.
    Wrap(usize),
}

/// [¼ ½ ¼] pre-filter along one line of `n` values read with `get(i)`.
fn filter_line(line: &[f64], edge: Edge) -> Vec<f64> {
    let n = line.len();
    let at = |i: isize| -> f64 {
        match edge {
            Edge::Mirror => {
                let i = if i < 0 {
                    -i
                } else if i >= n as isize {
                    2 * (n as isize - 1) - i
                } else {
                    i
                };
                line[i.clamp(0, n as isize - 1) as usize]
            }
            Edge::Wrap(p) => line[i.rem_euclid(p as isize) as usize],
        }
    };
    (0..n as isize)
        .map(|i| 0.25 * at(i - 1) + 0.5 * at(i) + 0.25 * at(i + 1))
        .collect()
}

/// Every other index, always keeping the last.
fn kept(n: usize) -> Vec<usize> {
    let mut k: Vec<usize> = (0..n).step_by(2).collect();
    if k.last() != Some(&(n - 1)) {
        k.push(n - 1);
    }
    k
}

impl Grid {
    /// Pre-filter and decimate each dimension with ≥ 3 entries; `None` when none has.
    /// `h_periodic`: the horizontal angles go round the full circle (type C, no symmetry).
    fn halve(&self, h_periodic: bool) -> Option<Grid> {
        let (nh, nv) = (self.h.len(), self.v.len());
        if nh < 3 && nv < 3 {
            return None;
        }
        let mut g = self.clone();
        if nv >= 3 {
            let keep = kept(nv);
            let mut vals = Vec::with_capacity(nh * keep.len());
            for row in g.vals.chunks_exact(nv) {
                let f = filter_line(row, Edge::Mirror);
                vals.extend(keep.iter().map(|&i| f[i]));
            }
            g.v = keep.iter().map(|&i| g.v[i]).collect();
            g.vals = vals;
        }
        let nv = g.v.len();
        if nh >= 3 {
            let h_edge = if h_periodic {
                // A last angle of first + 360 repeats the first: one period is n − 1.
                let dup = (self.h[nh - 1] - self.h[0] - 360.0).abs() < 1e-6;
                Edge::Wrap(if dup { nh - 1 } else { nh })
            } else {
                Edge::Mirror
            };
            let keep = kept(nh);
            let mut cols = vec![0.0; keep.len() * nv];
            let mut line = vec![0.0; nh];
            for iv in 0..nv {
                for (ih, l) in line.iter_mut().enumerate() {
                    *l = g.vals[ih * nv + iv];
                }
                let f = filter_line(&line, h_edge);
                for (k, &i) in keep.iter().enumerate() {
                    cols[k * nv + iv] = f[i];
                }
            }
            g.h = keep.iter().map(|&i| g.h[i]).collect();
            g.vals = cols;
        }
        Some(g)
    }

    /// Cut constant leading/trailing vertical ranges and normalize to lux at d_ref.
    fn to_level(&self, scale: f64, wrap: bool, h_bounded: bool) -> Level {
        let nv = self.v.len();
        let row_const = |iv: usize| -> Option<f64> {
            let c = self.vals[iv];
            (0..self.h.len())
                .all(|ih| self.vals[ih * nv + iv] == c)
                .then_some(c)
        };
        // Largest `lead` with rows 0..=lead all the same constant; likewise `trail`.
        let mut lead = 0;
        let mut below = 0.0;
        if let Some(c) = row_const(0) {
            below = c;
            while lead + 1 < nv && row_const(lead + 1) == Some(c) {
                lead += 1;
            }
        }
        let mut trail = nv - 1;
        let mut above = 0.0;
        if let Some(c) = row_const(nv - 1) {
            above = c;
            while trail > lead && row_const(trail - 1) == Some(c) {
                trail -= 1;
            }
        }
        let (start, end) = (lead, trail.max(lead));
        let stored = end - start + 1;
        let mut values = Vec::with_capacity(self.h.len() * stored);
        for row in self.vals.chunks_exact(nv) {
            values.extend(row[start..=end].iter().map(|&c| c * scale));
        }
        Level {
            h: Axis::new(self.h.clone()),
            v: Axis::new(self.v[start..=end].to_vec()),
            values,
            v_measured: (self.v[0], self.v[nv - 1]),
            below: below * scale,
            above: above * scale,
            wrap,
            h_bounded,
        }
    }
}

/// An [`IesFile`] built by hand (its fields are public) must still be consistent.
fn check_file(f: &IesFile) -> Result<(), LightError> {
    let (nv, nh) = (f.vertical_angles.len(), f.horizontal_angles.len());
    let increasing =
        |a: &[f64]| a.iter().all(|x| x.is_finite()) && a.windows(2).all(|w| w[0] < w[1]);
    let what = if nv == 0 || nh == 0 {
        Some("at least one vertical and one horizontal angle")
    } else if f.candela.len() != nv * nh {
        Some("vertical × horizontal candela values")
    } else if !increasing(&f.vertical_angles) || !increasing(&f.horizontal_angles) {
        Some("finite, strictly increasing angles")
    } else if !f.candela.iter().all(|c| c.is_finite()) || !f.candela_multiplier.is_finite() {
        Some("finite candela values and multiplier")
    } else {
        None
    };
    match what {
        Some(expected) => Err(LightError::Inconsistent {
            file: f.name.clone(),
            expected,
        }),
        None => Ok(()),
    }
}

/// A luminaire's intensity distribution as the patent's series of tables.
#[derive(Debug, Clone, PartialEq)]
pub struct LightTable {
    photometric_type: PhotometricType,
    symmetry: Symmetry,
    levels: Vec<Level>,
    d_ref: f64,
    d_ref2: f64,
    tilt: Option<TiltData>,
}

impl LightTable {
    /// Build the series from a parsed file: candela × multiplier (negative values, which
    /// some instruments write for noise, become 0).
    ///
    /// # Errors
    /// [`LightError::BadOption`] for a reference distance that is not a positive finite
    /// number or `max_levels` of 0; [`LightError::Ies`] when the horizontal angles declare
    /// no symmetry LM-63 knows (type C must start at 0°, or at 90° ending at 270°).
    pub fn from_ies(file: &IesFile, opts: &TableOptions) -> Result<LightTable, LightError> {
        if !(opts.reference_distance.is_finite() && opts.reference_distance > 0.0) {
            return Err(LightError::BadOption {
                name: "reference distance",
                expected: "a positive number of metres",
                value: opts.reference_distance,
            });
        }
        if opts.max_levels == 0 {
            return Err(LightError::BadOption {
                name: "max_levels",
                expected: "at least 1",
                value: 0.0,
            });
        }
        check_file(file)?;
        let h = &file.horizontal_angles;
        let (first, last) = (h[0], h[h.len() - 1]);
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
            _ => {
                if close(first, 0.0) && h.len() > 1 {
                    Symmetry::Lateral
                } else {
                    Symmetry::None
                }
            }
        };
        let is_c = file.photometric_type == PhotometricType::C;
        let wrap = is_c && symmetry == Symmetry::None && !close(last, 360.0);
        let h_bounded = !is_c;
        let h_periodic = is_c && symmetry == Symmetry::None;
        let mut grid = Grid {
            h: h.clone(),
            v: file.vertical_angles.clone(),
            vals: file
                .candela
                .iter()
                .map(|&c| (c * file.candela_multiplier).max(0.0))
                .collect(),
        };
        let d_ref = opts.reference_distance;
        let scale = 1.0 / (d_ref * d_ref);
        let mut levels = vec![grid.to_level(scale, wrap, h_bounded)];
        while levels.len() < opts.max_levels {
            match grid.halve(h_periodic) {
                Some(g) => {
                    levels.push(g.to_level(scale, wrap, h_bounded));
                    grid = g;
                }
                None => break,
            }
        }
        Ok(LightTable {
            photometric_type: file.photometric_type,
            symmetry,
            levels,
            d_ref,
            d_ref2: d_ref * d_ref,
            tilt: match &file.tilt {
                super::ies::Tilt::Include(t) => Some(t.clone()),
                super::ies::Tilt::None => None,
            },
        })
    }

    /// Parse an IES file and build its table with default options.
    ///
    /// # Errors
    /// As [`IesFile::load`] and [`LightTable::from_ies`].
    pub fn load(path: &std::path::Path) -> Result<LightTable, LightError> {
        let f = IesFile::load(path)?;
        LightTable::from_ies(&f, &TableOptions::default())
    }

    /// The goniometer type.
    pub fn photometric_type(&self) -> PhotometricType {
        self.photometric_type
    }

    /// The symmetry folded at lookup.
    pub fn symmetry(&self) -> Symmetry {
        self.symmetry
    }

    /// The reference distance in metres.
    pub fn reference_distance(&self) -> f64 {
        self.d_ref
    }

    /// Tilt data of a `TILT=INCLUDE` file.
    pub fn tilt(&self) -> Option<&TiltData> {
        self.tilt.as_ref()
    }

    /// Number of tables in the distance series.
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// (horizontal entries, stored vertical entries) of table `k`, `None` past the end.
    pub fn level_size(&self, k: usize) -> Option<(usize, usize)> {
        self.levels.get(k).map(|l| (l.h.a.len(), l.v.a.len()))
    }

    /// Fold a horizontal angle (degrees) into the stored subset by the symmetry.
    pub fn fold_horizontal(&self, h: f64) -> f64 {
        match self.photometric_type {
            PhotometricType::C => {
                let c = h.rem_euclid(360.0);
                match self.symmetry {
                    Symmetry::Rotational => self.levels[0].h.first(),
                    Symmetry::Quadrant => {
                        let c = if c > 180.0 { 360.0 - c } else { c };
                        if c > 90.0 {
                            180.0 - c
                        } else {
                            c
                        }
                    }
                    Symmetry::Bilateral0To180 => {
                        if c > 180.0 {
                            360.0 - c
                        } else {
                            c
                        }
                    }
                    Symmetry::Bilateral90To270 => {
                        if c < 90.0 {
                            180.0 - c
                        } else if c > 270.0 {
                            540.0 - c
                        } else {
                            c
                        }
                    }
                    Symmetry::Lateral | Symmetry::None => c,
                }
            }
            _ => match self.symmetry {
                Symmetry::Lateral => h.abs(),
                _ => h,
            },
        }
    }

    /// Candela of table `k` at photometric angles (vertical, horizontal) in degrees,
    /// horizontal folded by the symmetry; 0 outside the measured ranges; `None` past the
    /// series.
    pub fn level_candela(&self, k: usize, vertical: f64, horizontal: f64) -> Option<f64> {
        let l = self.levels.get(k)?;
        Some(l.sample(self.fold_horizontal(horizontal), vertical) * self.d_ref2)
    }

    /// Interpolated candela (file value × multiplier) at photometric angles in degrees:
    /// for type C vertical γ from the aim (nadir) and horizontal C. Zero outside the
    /// measured vertical range.
    pub fn candela(&self, vertical: f64, horizontal: f64) -> f64 {
        self.level_candela(0, vertical, horizontal).unwrap_or(0.0)
    }

    /// Photometric angles (vertical, horizontal) in degrees of a unit direction in the
    /// light's frame (x right, y up, z along the aim); see the module docs.
    #[inline]
    pub fn angles_of(&self, d: DVec3) -> (f64, f64) {
        (self.vertical_of(d), self.horizontal_of(d))
    }

    /// The vertical photometric angle in degrees (first, so constant ranges can be
    /// recognised before the horizontal angle is computed).
    #[inline]
    fn vertical_of(&self, d: DVec3) -> f64 {
        match self.photometric_type {
            PhotometricType::C => d.z.clamp(-1.0, 1.0).acos().to_degrees(),
            PhotometricType::A => d.y.clamp(-1.0, 1.0).asin().to_degrees(),
            PhotometricType::B => d.y.atan2(d.z).to_degrees(),
        }
    }

    /// The horizontal photometric angle in degrees (type C in [0, 360)).
    #[inline]
    fn horizontal_of(&self, d: DVec3) -> f64 {
        match self.photometric_type {
            PhotometricType::C => {
                let c = (-d.x).atan2(d.y).to_degrees();
                if c < 0.0 {
                    c + 360.0
                } else {
                    c
                }
            }
            PhotometricType::A => d.x.atan2(d.z).to_degrees(),
            PhotometricType::B => d.x.clamp(-1.0, 1.0).asin().to_degrees(),
        }
    }

    /// Candela toward a unit direction in the light's frame (full-resolution table).
    pub fn candela_dir(&self, d: DVec3) -> f64 {
        let (v, h) = self.angles_of(d);
        self.candela(v, h)
    }

    /// Illuminance in lux on a surface facing the light at distance `dist` metres toward
    /// unit direction `d` in the light's frame: the distance series (D = log2(dist / d_ref),
    /// its fraction interpolating two tables) times (d_ref / dist)². 0 for dist ≤ 0.
    #[inline]
    pub fn illuminance_normal(&self, d: DVec3, dist: f64) -> f64 {
        if dist.is_nan() || dist <= 0.0 {
            return 0.0;
        }
        let v = self.vertical_of(d);
        let inv_sq = self.d_ref2 / (dist * dist);
        let top = self.levels.len() - 1;
        // Distance index D: integer part picks the table, fraction blends with the next.
        let (i, t) = if dist <= self.d_ref || top == 0 {
            (0, 0.0)
        } else {
            let big_d = (dist / self.d_ref).log2().min(top as f64);
            let i = (big_d as usize).min(top);
            (i, if i == top { 0.0 } else { big_d - i as f64 })
        };
        let a_const = self.levels[i].constant_at(v);
        let b_const = if t > 0.0 {
            self.levels[i + 1].constant_at(v)
        } else {
            a_const
        };
        // In a constant range (beyond a cut-off, say) no horizontal angle is needed.
        if let (Some(a), Some(b)) = (a_const, b_const) {
            return (a + (b - a) * t) * inv_sq;
        }
        let h = self.fold_horizontal(self.horizontal_of(d));
        let a = a_const.unwrap_or_else(|| self.levels[i].sample(h, v));
        if t == 0.0 {
            return a * inv_sq;
        }
        let b = b_const.unwrap_or_else(|| self.levels[i + 1].sample(h, v));
        (a + (b - a) * t) * inv_sq
    }

    /// Total luminous flux in lumens of the full-resolution table, integrated over the
    /// sphere on a 0.25° latitude-longitude grid in the light's frame (midpoint rule).
    pub fn luminous_flux(&self) -> f64 {
        let (nlat, nlon) = (720usize, 1440usize);
        let dlat = std::f64::consts::PI / nlat as f64;
        let dlon = 2.0 * std::f64::consts::PI / nlon as f64;
        let mut total = 0.0;
        for i in 0..nlat {
            // Polar angle θ from the aim axis z.
            let th = (i as f64 + 0.5) * dlat;
            let (st, ct) = th.sin_cos();
            let mut ring = 0.0;
            for j in 0..nlon {
                let ph = (j as f64 + 0.5) * dlon;
                let (sp, cp) = ph.sin_cos();
                ring += self.candela_dir(DVec3::new(st * cp, st * sp, ct));
            }
            total += ring * st * dlat * dlon;
        }
        total
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_locate_uniform_and_not() {
        let u = Axis::new(vec![0.0, 10.0, 20.0, 30.0]);
        assert!(u.uniform.is_some());
        assert_eq!(u.locate(15.0), (1, 0.5));
        assert_eq!(u.locate(30.0), (2, 1.0));
        let n = Axis::new(vec![0.0, 5.0, 20.0]);
        assert!(n.uniform.is_none());
        assert_eq!(n.locate(12.5), (1, 0.5));
        assert_eq!(n.locate(0.0), (0, 0.0));
    }

    #[test]
    fn kept_halves_and_keeps_the_end() {
        assert_eq!(kept(5), vec![0, 2, 4]);
        assert_eq!(kept(4), vec![0, 2, 3]);
        assert_eq!(kept(37).len(), 19);
    }

    #[test]
    fn filter_preserves_constants_and_sums() {
        let f = filter_line(&[2.0, 2.0, 2.0], Edge::Mirror);
        assert_eq!(f, vec![2.0, 2.0, 2.0]);
        let x = [1.0, 5.0, 3.0, 0.0];
        let f = filter_line(&x, Edge::Wrap(4));
        let (a, b): (f64, f64) = (x.iter().sum(), f.iter().sum());
        assert!((a - b).abs() < 1e-12);
    }
}
