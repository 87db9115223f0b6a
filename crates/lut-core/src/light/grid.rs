//! Calculation grids of EN 12464-1 and the figures read from them (docs/lights.md,
//! "Reports").
//!
//! **Grid** (EN 12464-1:2011 section 4.4, kept in EN 12464-1:2021): the largest cell size
//! is p = 0.2 × 5^log10(d) m, d the longer side of the calculation area, p ≤ 10 m. The
//! number of points along that side is the smallest whole number n ≥ d / p, so the cells
//! there are d / n long; the other side gets the smallest whole number of cells no longer
//! than that. The points sit at the centres of the cells.
//!
//! **Border band**: on the work plane a band next to the walls is left out of the
//! calculation area (the standard: 0.5 m, "except when a task area is in or extends into
//! this border area"; in small rooms 15 % of the room's shorter side, as EN 12464-1:2021
//! allows): the band is min(0.5 m, 0.15 × the shorter side). Walls, floor and ceiling are
//! calculated over the whole surface.
//!
//! **Figures** per area: the mean Em, the minimum Emin and maximum Emax of the points,
//! U0 = Emin / Em and Ud = Emin / Emax (1 for a uniformly lit area; 0 for an unlit one).

use super::room::{Room, RoomFace};
use super::LightError;
use glam::DVec3;

/// The most points one report may compute (all areas together).
pub const MAX_GRID_POINTS: usize = 200_000;

/// EN 12464-1's largest cell size for an area whose longer side is `d` metres:
/// 0.2 × 5^log10(d), at most 10 m.
pub fn en12464_spacing(d: f64) -> f64 {
    (0.2 * 5f64.powf(d.log10())).min(10.0)
}

/// The border band left out of a work plane `width × depth`: min(0.5, 0.15 × the
/// shorter side) metres.
pub fn border_band(width: f64, depth: f64) -> f64 {
    (0.15 * width.min(depth)).min(0.5)
}

/// One calculation area: a rectangle of points at the centres of equal cells.
#[derive(Debug, Clone, PartialEq)]
pub struct CalcGrid {
    /// Its name ("work plane", "floor", "left wall", ...).
    pub name: String,
    /// The surface it lies on, `None` for the work plane.
    pub face: Option<RoomFace>,
    /// The axes along the rectangle (room coordinates), u and v.
    pub axes: (usize, usize),
    /// Its range along u and v.
    pub u: [f64; 2],
    /// Its range along v.
    pub v: [f64; 2],
    /// Cells along u and v.
    pub nu: usize,
    /// Cells along v.
    pub nv: usize,
    /// The unit normal of the surface the points are read on.
    pub normal: DVec3,
    /// The points, row-major (v rows of nu), room coordinates.
    pub points: Vec<DVec3>,
}

impl CalcGrid {
    /// The grid over a rectangle by EN 12464-1's rule: `axes` and the ranges `u`, `v`, the
    /// plane's coordinate `plane` along the third axis.
    fn new(
        name: String,
        face: Option<RoomFace>,
        axes: (usize, usize),
        u: [f64; 2],
        v: [f64; 2],
        plane: f64,
        normal: DVec3,
    ) -> Result<CalcGrid, LightError> {
        let (su, sv) = (u[1] - u[0], v[1] - v[0]);
        let d = su.max(sv);
        let p = en12464_spacing(d);
        // The longer side: n ≥ d / p; the other side: cells no longer than d / n.
        let n_long = (d / p - 1e-9).ceil().max(1.0);
        let cell = d / n_long;
        let n_short = (su.min(sv) / cell - 1e-9).ceil().max(1.0);
        let (nu, nv) = if su >= sv {
            (n_long, n_short)
        } else {
            (n_short, n_long)
        };
        let count = nu * nv;
        if count > MAX_GRID_POINTS as f64 {
            return Err(LightError::TooMany {
                what: "calculation grid points",
                count: count.min(usize::MAX as f64) as usize,
                max: MAX_GRID_POINTS,
            });
        }
        let (nu, nv) = (nu as usize, nv as usize);
        let third = 3 - axes.0 - axes.1;
        let mut points = Vec::with_capacity(nu * nv);
        for j in 0..nv {
            for i in 0..nu {
                let mut p = DVec3::ZERO;
                p[third] = plane;
                p[axes.0] = u[0] + (i as f64 + 0.5) * su / nu as f64;
                p[axes.1] = v[0] + (j as f64 + 0.5) * sv / nv as f64;
                points.push(p);
            }
        }
        Ok(CalcGrid {
            name,
            face,
            axes,
            u,
            v,
            nu,
            nv,
            normal,
            points,
        })
    }

    /// The work plane `height` metres above the floor, facing up, without the border
    /// band ([`border_band`]).
    ///
    /// # Errors
    /// [`LightError::BadOption`] for a height not strictly between floor and ceiling,
    /// [`LightError::TooMany`] beyond [`MAX_GRID_POINTS`].
    pub fn work_plane(room: &Room, height: f64) -> Result<CalcGrid, LightError> {
        if !(height.is_finite() && height > 0.0 && height < room.height()) {
            return Err(LightError::BadOption {
                name: "work plane height",
                expected: "a number of metres strictly between the floor and the ceiling",
                value: height,
            });
        }
        let (lo, hi) = room.bounds();
        let band = border_band(room.width(), room.depth());
        CalcGrid::new(
            "work plane".into(),
            None,
            (0, 2),
            [lo.x + band, hi.x - band],
            [lo.z + band, hi.z - band],
            height,
            DVec3::Y,
        )
    }

    /// The whole of `face`, read on its inward normal.
    ///
    /// # Errors
    /// [`LightError::TooMany`] beyond [`MAX_GRID_POINTS`].
    pub fn face(room: &Room, face: RoomFace) -> Result<CalcGrid, LightError> {
        let (lo, hi) = room.bounds();
        let (ua, va) = face.plane_axes();
        CalcGrid::new(
            face.name().into(),
            Some(face),
            (ua, va),
            [lo[ua], hi[ua]],
            [lo[va], hi[va]],
            room.plane(face),
            face.inward_normal(),
        )
    }

    /// The area in m².
    pub fn area_m2(&self) -> f64 {
        (self.u[1] - self.u[0]) * (self.v[1] - self.v[0])
    }

    /// The cell size along the area's longer side, metres (the spacing of the points).
    pub fn spacing_m(&self) -> f64 {
        let (su, sv) = (self.u[1] - self.u[0], self.v[1] - self.v[0]);
        if su >= sv {
            su / self.nu as f64
        } else {
            sv / self.nv as f64
        }
    }
}

/// Em, Emin, Emax, U0 and Ud of an area's point values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AreaStats {
    /// The mean, lux.
    pub em: f64,
    /// The smallest value, lux.
    pub emin: f64,
    /// The largest value, lux.
    pub emax: f64,
    /// Emin / Em (0 when Em is 0).
    pub u0: f64,
    /// Emin / Emax (0 when Emax is 0).
    pub ud: f64,
}

impl AreaStats {
    /// The figures of `values` (at least one; the cells are equal, so the mean is plain).
    pub fn of(values: &[f64]) -> AreaStats {
        let n = values.len().max(1) as f64;
        let em = values.iter().sum::<f64>() / n;
        let emin = values.iter().copied().fold(f64::INFINITY, f64::min);
        let emax = values.iter().copied().fold(0.0, f64::max);
        let emin = if emin.is_finite() { emin } else { 0.0 };
        AreaStats {
            em,
            emin,
            emax,
            u0: if em > 0.0 { emin / em } else { 0.0 },
            ud: if emax > 0.0 { emin / emax } else { 0.0 },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spacing_follows_the_formula() {
        // p = 0.2 × 5^log10(d): 1 m → 0.2, 10 m → 1, 100 m → 5, capped at 10.
        assert!((en12464_spacing(1.0) - 0.2).abs() < 1e-12);
        assert!((en12464_spacing(10.0) - 1.0).abs() < 1e-12);
        assert!((en12464_spacing(100.0) - 5.0).abs() < 1e-12);
        assert_eq!(en12464_spacing(1e4), 10.0);
    }

    #[test]
    fn grids_of_a_6_by_5_room() {
        let room = Room::new(6.0, 5.0, 2.8, 1.6).unwrap();
        // Work plane 5 × 4 m after the 0.5 m band: p(5) = 0.2 × 5^0.699 = 0.6143 m, so
        // 9 cells of 0.5556 m along X and ceil(4 / 0.5556) = 8 along Z.
        let wp = CalcGrid::work_plane(&room, 0.75).unwrap();
        assert_eq!((wp.nu, wp.nv, wp.points.len()), (9, 8, 72));
        assert!((wp.spacing_m() - 5.0 / 9.0).abs() < 1e-12);
        assert!((wp.area_m2() - 20.0).abs() < 1e-12);
        assert!((wp.points[0] - DVec3::new(-2.5 + 5.0 / 18.0, 0.75, -2.0 + 0.25)).length() < 1e-12);
        // The left wall: 5 × 2.8 m, p(5) again: 9 × ceil(2.8 / 0.5556) = 9 × 6.
        let lw = CalcGrid::face(&room, RoomFace::Left).unwrap();
        assert_eq!((lw.nu, lw.nv), (9, 6));
        // The floor: 6 × 5, p(6) = 0.2 × 5^0.778 = 0.7012: 9 × ceil(5 / 0.6667) = 9 × 8.
        let fl = CalcGrid::face(&room, RoomFace::Floor).unwrap();
        assert_eq!((fl.nu, fl.nv), (9, 8));
        assert!(CalcGrid::work_plane(&room, 2.8).is_err());
        assert!(CalcGrid::work_plane(&room, f64::NAN).is_err());
    }

    #[test]
    fn uniform_values_have_uniformity_one() {
        let s = AreaStats::of(&[300.0; 12]);
        assert_eq!(
            (s.em, s.emin, s.emax, s.u0, s.ud),
            (300.0, 300.0, 300.0, 1.0, 1.0)
        );
        let s = AreaStats::of(&[100.0, 200.0, 300.0]);
        assert_eq!((s.u0, s.ud), (0.5, 100.0 / 300.0));
    }
}
