//! The goniometric light table of EP 0613099.
//!
//! * Claim 1-3: illumination values in a 2-D table indexed by the direction from the light
//!   relative to its aim, as a pair of polar angles (vertical, horizontal); the index has
//!   an integer and a fractional part and the value is filtered by the fraction: bilinear,
//!   or Catmull-Rom ([`Interpolation`]). The table is kept at the file's measured angles,
//!   so lookups are exact there; a uniformly spaced axis is indexed by one multiply, any
//!   other by bisection.
//! * Claim 9: the symmetry of the file (rotational, quadrant, bilateral about 0-180 or
//!   90-270, lateral for types A/B) is folded at lookup: only the measured subset is stored.
//! * Claim 8, in both directions: leading and trailing vertical ranges (rows) and
//!   horizontal ranges (C or H planes) where every value the interpolation reads is the
//!   same constant (zero beyond a cut-off, a dark side) are not stored; the constant is
//!   substituted at lookup, giving bit for bit the lookups of the uncut table. Outside the
//!   measured vertical range the value is zero.
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

use super::ies::{IesFile, PhotometricType, TiltData};
use super::ldt::LdtFile;
pub use super::level::Interpolation;
use super::level::{Edge, Edges, Grid, Level, LevelSpec};
use super::photometry::Photometry;
pub use super::photometry::Symmetry;
use super::LightError;
use glam::DVec3;

/// Options for building a [`LightTable`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableOptions {
    /// The reference distance d_ref in metres (level 0 serves d ≤ d_ref). Default 4 m, so
    /// most of a room is lit from the full-resolution table.
    pub reference_distance: f64,
    /// Most tables in the distance series (1 = no series). Default 4.
    pub max_levels: usize,
    /// Filtering between measured angles. Default linear.
    pub interpolation: Interpolation,
    /// Leave constant ranges out of the stored tables (claim 8). Default true; the
    /// lookups are the same either way, only the memory differs.
    pub cut_constant_ranges: bool,
    /// Keep a table of the distance series only while it reproduces the measured table
    /// within this fraction: at every measured angle (and between them),
    /// |I_k − I_0| ≤ tolerance · max(I_0, 5 % of the peak). The series stops at the first
    /// table that does not (a smooth distribution measured finely keeps several tables;
    /// a peaked one, or one measured coarsely, keeps its measured table at every
    /// distance, so lux readings are never blurred by the pre-filter). Default
    /// `Some(0.004)`; `None` builds the plain series (every table halves, whatever it
    /// costs in accuracy; see docs/lights.md for what that costs a narrow beam).
    pub series_tolerance: Option<f64>,
}

impl Default for TableOptions {
    fn default() -> Self {
        TableOptions {
            reference_distance: 4.0,
            max_levels: 4,
            interpolation: Interpolation::Linear,
            cut_constant_ranges: true,
            series_tolerance: Some(0.004),
        }
    }
}

/// A luminaire's intensity distribution as the patent's series of tables.
#[derive(Debug, Clone, PartialEq)]
pub struct LightTable {
    photometric_type: PhotometricType,
    symmetry: Symmetry,
    interpolation: Interpolation,
    levels: Vec<Level>,
    d_ref: f64,
    d_ref2: f64,
    tilt: Option<TiltData>,
    /// EULUMDAT's tilt during measurement, degrees (0 for IES).
    measurement_tilt: f64,
    /// The smallest step between measured angles, degrees (either axis).
    finest_step: f64,
    /// Type C: the γ beyond which every value is 0 (the lit cone's half-angle); 180
    /// otherwise.
    lit_cone: f64,
}

impl LightTable {
    /// Build the series from an IES file: candela × multiplier.
    ///
    /// # Errors
    /// As [`Photometry::from_ies`] and [`LightTable::from_photometry`].
    pub fn from_ies(file: &IesFile, opts: &TableOptions) -> Result<LightTable, LightError> {
        LightTable::from_photometry(&Photometry::from_ies(file)?, opts)
    }

    /// Build the series from an EULUMDAT file (see [`Photometry::from_ldt`]).
    ///
    /// # Errors
    /// As [`LightTable::from_photometry`].
    pub fn from_ldt(file: &LdtFile, opts: &TableOptions) -> Result<LightTable, LightError> {
        LightTable::from_photometry(&Photometry::from_ldt(file), opts)
    }

    /// Build the series from a photometric distribution, IES or EULUMDAT (negative
    /// candela, which some instruments write for noise, become 0).
    ///
    /// # Errors
    /// [`LightError::BadOption`] for a reference distance that is not a positive finite
    /// number or `max_levels` of 0; [`LightError::Inconsistent`] when the fields do not
    /// agree (counts, increasing angles, symmetry against the horizontal angles).
    pub fn from_photometry(p: &Photometry, opts: &TableOptions) -> Result<LightTable, LightError> {
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
        if let Some(t) = opts.series_tolerance {
            if !(t.is_finite() && t >= 0.0) {
                return Err(LightError::BadOption {
                    name: "series tolerance",
                    expected: "a finite number ≥ 0",
                    value: t,
                });
            }
        }
        p.check()?;
        let is_c = p.photometric_type == PhotometricType::C;
        let symmetry = p.symmetry;
        let mut grid = Grid {
            h: p.horizontal_angles.clone(),
            v: p.vertical_angles.clone(),
            vals: p.candela.iter().map(|&c| c.max(0.0)).collect(),
        };
        // A type C table without symmetry goes round the circle: close it with a plane at
        // 360° so lookups never wrap, and read neighbours periodically.
        let h_edges = match symmetry {
            Symmetry::None if is_c => {
                grid.close_circle();
                let p = grid.h.len() - 1;
                Edges {
                    lo: Edge::Wrap(p),
                    hi: Edge::Wrap(p),
                }
            }
            Symmetry::None => Edges {
                lo: Edge::Clamp,
                hi: Edge::Clamp,
            },
            Symmetry::Lateral => Edges {
                lo: Edge::Mirror,
                hi: Edge::Clamp,
            },
            _ => Edges::MIRROR,
        };
        // Vertically: mirrored at the poles (type C γ 0 and 180, type A V ±90), repeated
        // at the end of a shorter measured range.
        let pole = |a: f64| match p.photometric_type {
            PhotometricType::C => a == 0.0 || a == 180.0,
            PhotometricType::A => a.abs() == 90.0,
            PhotometricType::B => false,
        };
        let edge = |a: f64| if pole(a) { Edge::Mirror } else { Edge::Clamp };
        let v_edges = Edges {
            lo: edge(grid.v[0]),
            hi: edge(grid.v[grid.v.len() - 1]),
        };
        let d_ref = opts.reference_distance;
        let spec = LevelSpec {
            scale: 1.0 / (d_ref * d_ref),
            interpolation: opts.interpolation,
            cut: opts.cut_constant_ranges,
            h_edges,
            v_edges,
            h_bounded: !is_c,
        };
        let mut levels = vec![grid.to_level(&spec)];
        // Where the series is checked: every measured angle and the midpoints between
        // (folded horizontal angles of the stored subset, as lookups pass them).
        let probes = |a: &[f64]| -> Vec<f64> {
            let mut out = a.to_vec();
            out.extend(a.windows(2).map(|w| 0.5 * (w[0] + w[1])));
            out
        };
        let (hs, vs) = (probes(&grid.h), probes(&grid.v));
        let peak = grid.vals.iter().cloned().fold(0.0, f64::max) * spec.scale;
        while levels.len() < opts.max_levels {
            let Some(g) = grid.halve(h_edges) else {
                break;
            };
            let level = g.to_level(&spec);
            if let Some(tol) = opts.series_tolerance {
                let faithful = hs.iter().all(|&h| {
                    vs.iter().all(|&v| {
                        let want = levels[0].sample(h, v);
                        (level.sample(h, v) - want).abs() <= tol * want.max(0.05 * peak)
                    })
                });
                if !faithful {
                    break;
                }
            }
            levels.push(level);
            grid = g;
        }
        let steps = |a: &[f64]| {
            a.windows(2)
                .map(|w| w[1] - w[0])
                .fold(f64::INFINITY, f64::min)
        };
        let finest_step = steps(&p.vertical_angles)
            .min(steps(&p.horizontal_angles))
            .min(180.0);
        let nv = p.vertical_angles.len();
        let lit_cone = if is_c {
            // The last γ with light in any plane; past the next measured angle (where the
            // interpolation has come down to 0) and past the measured range all is dark.
            let last = (0..nv)
                .rev()
                .find(|&v| p.candela.iter().skip(v).step_by(nv).any(|&c| c > 0.0));
            match last {
                Some(v) if v + 1 < nv => p.vertical_angles[v + 1],
                Some(v) => p.vertical_angles[v],
                None => 0.0,
            }
        } else {
            180.0
        };
        Ok(LightTable {
            finest_step,
            lit_cone,
            photometric_type: p.photometric_type,
            symmetry,
            interpolation: opts.interpolation,
            levels,
            d_ref,
            d_ref2: d_ref * d_ref,
            tilt: p.tilt.clone(),
            measurement_tilt: p.measurement_tilt_deg(),
        })
    }

    /// Read an IES or EULUMDAT file (chosen by content, see [`Photometry::load`]) and build
    /// its table with default options.
    ///
    /// # Errors
    /// As [`Photometry::load`] and [`LightTable::from_photometry`].
    pub fn load(path: &std::path::Path) -> Result<LightTable, LightError> {
        let p = Photometry::load(path)?;
        crate::guard::contain(path, || {
            LightTable::from_photometry(&p, &TableOptions::default())
        })
    }

    /// The goniometer type.
    pub fn photometric_type(&self) -> PhotometricType {
        self.photometric_type
    }

    /// The symmetry folded at lookup.
    pub fn symmetry(&self) -> Symmetry {
        self.symmetry
    }

    /// The filtering between measured angles.
    pub fn interpolation(&self) -> Interpolation {
        self.interpolation
    }

    /// The reference distance in metres.
    pub fn reference_distance(&self) -> f64 {
        self.d_ref
    }

    /// The smallest step between the file's measured angles in degrees (either axis;
    /// 180 for a file with one angle on each): light varies on this angular scale, so the
    /// illuminance map samples surfaces finely enough to resolve it.
    pub fn finest_step_deg(&self) -> f64 {
        self.finest_step
    }

    /// For type C, the angle γ from the aim beyond which the luminaire gives no light in
    /// any plane (180 when it lights the whole sphere); 180 for types A and B. The
    /// pre-filtered tables of the distance series may spread light one step further (each
    /// level a step of its own); the illuminance map uses this only to choose its node
    /// spacing, never to leave light out.
    pub fn lit_cone_deg(&self) -> f64 {
        self.lit_cone
    }

    /// Tilt data of a `TILT=INCLUDE` file.
    pub fn tilt(&self) -> Option<&TiltData> {
        self.tilt.as_ref()
    }

    /// The luminaire's tilt during measurement in degrees (EULUMDAT line 25; 0 for IES
    /// files). CIE S 017 (17-25-112): the angle between a datum axis of the luminaire
    /// (nominally horizontal in use) and the horizontal when it was mounted on the
    /// goniometer; positive raises its C90 side, as a road luminaire is raised toward the
    /// carriageway. The table is in the goniometer's frame; a placed luminaire's aim is its
    /// own (datum) frame, so [`Luminaire::frame`](super::Luminaire::frame) turns the table
    /// by this angle about the C0-C180 axis: a luminaire aimed straight down sends the
    /// table's nadir ray this far toward its C270 side, and one aimed to undo the tilt
    /// reproduces the table as measured.
    pub fn measurement_tilt_deg(&self) -> f64 {
        self.measurement_tilt
    }

    /// Number of tables in the distance series.
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// (stored horizontal entries, stored vertical entries) of table `k` (constant ranges
    /// cut; a type C table without symmetry counts its closing plane at 360°), `None`
    /// past the end.
    pub fn level_size(&self, k: usize) -> Option<(usize, usize)> {
        self.levels.get(k).map(Level::size)
    }

    /// Number of f64 values table `k` holds (its stored window plus, for Catmull-Rom, the
    /// ring of neighbours around it), `None` past the end.
    pub fn stored_values(&self, k: usize) -> Option<usize> {
        self.levels.get(k).map(Level::stored_values)
    }

    /// Fold a horizontal angle (degrees) into the stored subset by the symmetry.
    pub fn fold_horizontal(&self, h: f64) -> f64 {
        match self.photometric_type {
            PhotometricType::C => {
                let c = h.rem_euclid(360.0);
                match self.symmetry {
                    Symmetry::Rotational => self.levels[0].h_first(),
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
