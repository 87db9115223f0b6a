//! The analytic per-cell error bound of the table's bilinear interpolation (see the
//! table's module docs): second-derivative bounds of λ and φ over a cell of the cylinder
//! or the plane, and the cells they prove within budget, which are then not measured.

use super::{row_yz, Surface, ZoneCheck, TABLE_ERROR_BUDGET, V_CLAMP};
use crate::geom::projection::Projection;
use std::f64::consts::{PI, TAU};

/// Cells proven together first (one bound over the block; a block that fails is checked
/// cell by cell).
pub(super) const PROOF_BLOCK: usize = 16;

/// A cell whose analytic error bound is at most this is not measured: 10 % under
/// [`TABLE_ERROR_BUDGET`] (the margin covers the floating-point evaluation of the bound
/// many times over).
pub(super) const PROVEN_LIMIT: f64 = 0.9 * TABLE_ERROR_BUDGET;

/// Largest Q15.16 rounding of a node, map pixels.
const Q_ROUND: f64 = 0.5 / 65536.0;

/// Bounds, over one cell `[r0, r1] × [t0, t1]`, of the derivatives of λ and φ (radians)
/// with respect to the table's row (r) and column (t) coordinates, and of tan φ and cos φ.
#[derive(Debug, Clone, Copy)]
pub(super) struct CellGeom {
    /// sup |λ_rr|, sup |λ_tt| (λ_rr ≥ 0 ≥ λ_tt: they never share a sign).
    pub(super) lam_rr: f64,
    pub(super) lam_tt: f64,
    /// sup |φ_r|, sup |φ_t|, sup |φ_rr|, sup |φ_tt|.
    pub(super) phi_r: f64,
    pub(super) phi_t: f64,
    pub(super) phi_rr: f64,
    pub(super) phi_tt: f64,
    /// Bounds tan φ_min ≥ `tan_min` and tan φ_max ≤ `tan_max` (φ ≥ 0 in the stored region).
    pub(super) tan_min: f64,
    pub(super) tan_max: f64,
    /// sup cos φ.
    pub(super) cos_max: f64,
}

/// Peak of `2x/(1+x²)²` over x ≥ 0 (at x = 1/√3, 0.64952), rounded up.
const ATAN_TT_PEAK: f64 = 0.6496;

impl CellGeom {
    /// The cylinder cell `a ∈ [a0, a1] ⊂ [0, π/2)` given as `s = sin a`, `c = cos a` at both
    /// ends, `t ∈ [t0, t1]`, `t0 ≥ 0`. The direction is `(t, s, c)`, so with
    /// `q = √(t² + c²)`:
    /// `λ = atan2(t, c)`, `λ_tt = −2tc/(c²+t²)²`, `λ_aa = tc(c²+t²+2s²)/(c²+t²)²`;
    /// `φ = atan2(s, q)`, `φ_a = c/q`, `φ_t = −st/(q(1+t²))`, `φ_aa = −st²/q³`,
    /// `φ_tt = −s/((1+t²)q) · (c²/q² − 2t²/(1+t²))`; `tan φ = s/q`, `cos φ = q/√(1+t²)`.
    /// Every factor is monotone in a (s rises, c falls) and in t ≥ 0, so each bound takes
    /// numerators at their largest and denominators at their smallest corner value (and
    /// ratios known to be ≤ 1, such as c/q and t/q, at most 1). `None` unless `c1 > 0`.
    pub(super) fn cylinder(
        s0: f64,
        c0: f64,
        s1: f64,
        c1: f64,
        t0: f64,
        t1: f64,
    ) -> Option<CellGeom> {
        if !(c1 > 0.0 && s0 >= 0.0 && t0 >= 0.0) {
            return None;
        }
        let q2_min = t0 * t0 + c1 * c1;
        let q_min = q2_min.sqrt();
        let q_max = (t1 * t1 + c0 * c0).sqrt();
        let d_min = q2_min * q2_min;
        let one_t0 = 1.0 + t0 * t0;
        Some(CellGeom {
            lam_rr: t1 * c0 * (c0 * c0 + t1 * t1 + 2.0 * s1 * s1) / d_min,
            lam_tt: (2.0 * t1 * c0 / d_min).min(ATAN_TT_PEAK / (c1 * c1)),
            phi_r: (c0 / q_min).min(1.0),
            phi_t: s1 / one_t0 * (t1 / q_min).min(1.0),
            phi_rr: s1 / q_min * (t1 * t1 / q2_min).min(1.0),
            phi_tt: s1 / (one_t0 * q_min)
                * (c0 * c0 / q2_min)
                    .min(1.0)
                    .max(2.0 * t1 * t1 / (1.0 + t1 * t1)),
            tan_min: s0 / q_max,
            tan_max: s1 / q_min,
            cos_max: (q_max / one_t0.sqrt()).min(1.0),
        })
    }

    /// The plane cell `y ∈ [y0, y1]`, `x ∈ [x0, x1]`, both ≥ 0. The direction is
    /// `(x, y, 1)`, so with `m = √(1+x²)`, `D = 1 + x² + y²`:
    /// `λ = atan(x)`, `λ_xx = −2x/m⁴`, `λ_yy = 0`; `φ = atan2(y, m)`, `φ_y = m/D`,
    /// `φ_x = −xy/(mD)`, `φ_yy = −2ym/D²`, `φ_xx = −y/(mD) · (1/m² − 2x²/D)`;
    /// `tan φ = y/m`, `cos φ = m/√D`.
    pub(super) fn plane(y0: f64, y1: f64, x0: f64, x1: f64) -> Option<CellGeom> {
        if !(y0 >= 0.0 && x0 >= 0.0) {
            return None;
        }
        let m0 = (1.0 + x0 * x0).sqrt();
        let m1 = (1.0 + x1 * x1).sqrt();
        let d_min = 1.0 + x0 * x0 + y0 * y0;
        Some(CellGeom {
            lam_rr: 0.0,
            lam_tt: (2.0 * x1 / (m0 * m0 * m0 * m0)).min(ATAN_TT_PEAK),
            phi_r: (m1 / d_min).min(1.0 / m0),
            phi_t: x1 * y1 / (m0 * d_min),
            phi_rr: 2.0 * y1 * m1 / (d_min * d_min),
            phi_tt: y1 / (m0 * d_min) * (1.0 / (m0 * m0)).max(2.0 * x1 * x1 / d_min),
            tan_min: y0 / m1,
            tan_max: y1 / m0,
            cos_max: (m1 / d_min.sqrt()).min(1.0),
        })
    }
}

/// The analytic per-cell error bound of the table's bilinear interpolation.
///
/// Bilinear interpolation of a C² function `f` over a cell of side `h` errs by
/// `e = E_t + E_r`: linear interpolation along t errs by `E_t = −x(h−x)/2 · f_tt(ξ)`, and
/// the interpolation along r of the rows' errors `−y(h−y)/2 · f_rr(η)` (weights in [0, 1])
/// adds `E_r`; so `|e| ≤ h²/8 · (sup|f_rr| + sup|f_tt|)`. When `f_tt` and `f_rr` have
/// opposite signs over the whole cell, so do `E_t` and `E_r`, and `|e| ≤ h²/8 ·
/// max(sup|f_rr|, sup|f_tt|)`: that holds for λ everywhere in the stored region (cylinder:
/// `λ_tt = −2tc/q⁴ ≤ 0 ≤ λ_aa`; plane: `λ_yy = 0`), and halves the bound near the poles,
/// where λ is nearly harmonic. For Λ = λ·W/2π and V = P(φ) (`V_rr = P''φ_r² + P'φ_rr`,
/// no sign used), plus the nodes' Q15.16 rounding, this bounds |ΔΛ| and |ΔV|;
/// [`entry_error`] then is at most
/// `cos φ·|ΔΛ| + (1 + 2·coupling)·|ΔV|` (the u error is scaled by at most cos φ, and for
/// scaled rows the row scale moves by at most `coupling·|ΔV|` in u, scaled by at most 2).
pub(super) struct CellBounds {
    surface: Surface,
    p: Projection,
    h: f64,
    step: f64,
    /// `step²/8`.
    hh8: f64,
    /// W/2π (Λ pixels per radian).
    lam_px: f64,
    /// `1 + 2·coupling` (1 for rectangular rows).
    v_factor: f64,
    /// False: measure every cell.
    enabled: bool,
}

/// The bound for one row band: its row ends' direction components.
pub(super) struct BandBounds<'a> {
    c: &'a CellBounds,
    /// Cylinder: (sin a, cos a) at both ends; plane: (y, 1).
    y0: f64,
    z0: f64,
    y1: f64,
    z1: f64,
}

impl CellBounds {
    pub(super) fn new(
        surface: Surface,
        p: Projection,
        w: f64,
        h: f64,
        step: f64,
        check: ZoneCheck,
    ) -> Self {
        // The proof needs unsaturated entries: |V| ≤ H/2 below the clamp, Λ ≤ W/4 in Q15.16.
        let fits = h * 0.5 + 1.0 < V_CLAMP && w * 0.25 + 1.0 < i32::MAX as f64 / 65536.0;
        CellBounds {
            surface,
            p,
            h,
            step,
            hh8: step * step / 8.0,
            lam_px: w / TAU,
            v_factor: 1.0 + 2.0 * p.row_scale_coupling(w, h),
            // No closed-form bounds are derived for the diamond's faces: every cell is
            // measured.
            enabled: check == ZoneCheck::Bounded
                && fits
                && step > 0.0
                && surface != Surface::Diamond,
        }
    }

    /// The bounds of band `b`, or `None` when its cells must all be measured.
    pub(super) fn band(&self, b: usize) -> Option<BandBounds<'_>> {
        if !self.enabled {
            return None;
        }
        let (y0, z0) = row_yz(self.surface, b as f64 * self.step);
        let (y1, z1) = row_yz(self.surface, (b + 1) as f64 * self.step);
        Some(BandBounds {
            c: self,
            y0,
            z0,
            y1,
            z1,
        })
    }

    /// The error bound of a cell with geometry `g`: `Some(bound)` when it proves the cell
    /// within [`PROVEN_LIMIT`] (`Some(0)`: the whole cell is above a cylinder map's top, so
    /// both exact and interpolated positions are background), else `None` (measure it).
    fn bound(&self, g: &CellGeom) -> Option<f64> {
        let (w, h) = (self.lam_px * TAU, self.h);
        // λ_rr and λ_tt never share a sign (see the type's doc): the larger one bounds.
        let e_lam = self.hh8 * self.lam_px * g.lam_rr.max(g.lam_tt) + Q_ROUND;
        let (p1, p2) = match self.p {
            Projection::Equirect | Projection::Elliptical | Projection::Diamond => (h / PI, 0.0),
            Projection::Sine => (h * 0.5, h * 0.5),
            Projection::Cylinder => {
                // P = r tan φ: P' = r sec²φ, P'' = 2r sec²φ tan φ; sec²φ = 1 + tan²φ.
                let r = w / TAU;
                let sec2 = 1.0 + g.tan_max * g.tan_max;
                (r * sec2, 2.0 * r * sec2 * g.tan_max)
            }
        };
        let v_rr = p2 * g.phi_r * g.phi_r + p1 * g.phi_rr;
        let v_tt = p2 * g.phi_t * g.phi_t + p1 * g.phi_tt;
        let e_v = self.hh8 * (v_rr + v_tt) + Q_ROUND;
        if self.p == Projection::Cylinder {
            // Coverage is |V| ≤ H/2, V = r tan φ ≥ 0 here.
            let r = w / TAU;
            if r * g.tan_min > h * 0.5 + 1e-3 {
                // Every exact V, and so every node and every blend of nodes, is above the
                // map (H/2 + 1 < the clamp, see `new`).
                return Some(0.0);
            }
            if r * g.tan_max + e_v + 1e-3 > h * 0.5 {
                return None; // the cell may straddle the map's edge: measure
            }
            // (A NaN anywhere makes `bound` NaN, which proves nothing below.)
        }
        let bound = g.cos_max * e_lam + self.v_factor * e_v;
        (bound <= PROVEN_LIMIT).then_some(bound)
    }
}

impl BandBounds<'_> {
    /// The geometry bounds over cells `k0..k1` of this band.
    fn geom(&self, k0: usize, k1: usize) -> Option<CellGeom> {
        let step = self.c.step;
        let (t0, t1) = (k0 as f64 * step, k1 as f64 * step);
        match self.c.surface {
            Surface::Cylinder => CellGeom::cylinder(self.y0, self.z0, self.y1, self.z1, t0, t1),
            Surface::Plane => CellGeom::plane(self.y0, self.y1, t0, t1),
            Surface::Diamond => None,
        }
    }

    /// An error bound proven for each of cells `k0..k1` (one bound over their union), or
    /// `None` (check them one by one).
    #[inline]
    pub(super) fn cells(&self, k0: usize, k1: usize) -> Option<f64> {
        self.geom(k0, k1).and_then(|g| self.c.bound(&g))
    }
}
