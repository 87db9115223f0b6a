//! Step bounds: the longest index-interpolation step per region of a scanline whose
//! linear-interpolation error stays within [`SPAN_ERROR_BUDGET`], from an analytic bound on
//! the second derivative of the map coordinates along the scanline.

/// Largest sampling-position error, in source pixels, index interpolation may add to a
/// span (on top of the table's own budget, [`crate::TABLE_ERROR_BUDGET`]).
pub const SPAN_ERROR_BUDGET: f64 = 0.02;

/// Largest step the adaptive mode takes.
pub const ADAPTIVE_MAX_STEP: u32 = 64;

/// Each scanline is cut into this many regions of |X| (distance from the screen's
/// centre column), each with its own index step: the curvature of the map coordinates
/// peaks in one region and is small elsewhere, so a per-region step is several times
/// longer on average than one step per scanline, at the same error bound.
pub(crate) const STEP_REGIONS: usize = 8;

/// Factors of the second-derivative bound of the map coordinates along a scanline.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepBounds {
    /// W / 2π: Λ pixels per radian of longitude.
    pub(crate) lam_px: f64,
    /// max |dV/dφ| and |d²V/dφ²| over the covered latitudes.
    pub(crate) v1: f64,
    pub(crate) v2: f64,
    /// How a V error turns into a u error through the row scale.
    pub(crate) coupling: f64,
    /// Bilinear with a level per region (`Renderer::set_region_lod`): the deepest
    /// pyramid level (`Some`), so that the budget is that of the level a region's spans
    /// are sure to read ([`lod_budget`]); `None`: level 0's.
    pub(crate) lod_cap: Option<u32>,
}

/// The span error budget, in level-0 map pixels, of spans of `reach` pixels starting
/// at |X| ≤ `xs.hi` on `line` ([`step_fits`]), when each span reads the pyramid level
/// nearest its footprint (`Renderer::set_region_lod`, capped at level `cap`):
/// [`SPAN_ERROR_BUDGET`] · 2^k, k the level such a span reads at least, so the budget is
/// [`SPAN_ERROR_BUDGET`] pixels of the level read.
///
/// Why k is a floor: along the scanline Λ = (W/2π)·atan2(t, c) + const, whose slope
/// (W/2π)·c/(t² + c²) per unit t falls with |t|, so every span of the region (|t| up to
/// t_far = (|X| + reach)·dt) steps at least f = (W/2π)·c·dt/(t_far² + c²) map pixels per
/// pixel in Λ (its chord is the mean of the slope over it), and a span's level is chosen
/// from the larger of its |dΛ|, |dV| and the vertical footprint
/// (`map::pyramid::nearest_level_of`): at least the level of f, and at least
/// `line.k_floor`, the level of the vertical footprint (near a pole the larger: there Λ
/// turns from one scanline to the next). 3 % is taken off f for the table's own error in
/// the chord's ends.
pub(crate) fn lod_budget(b: &StepBounds, line: StepLine, xs: XRange, reach: f64) -> f64 {
    let Some(cap) = b.lod_cap else {
        return SPAN_ERROR_BUDGET;
    };
    let t_far = (xs.hi + reach) * line.dt;
    let f = 0.97 * b.lam_px * line.c * line.dt / (t_far * t_far + line.c * line.c);
    let k = crate::map::pyramid::nearest_level_of(f)
        .max(line.k_floor)
        .min(cap);
    SPAN_ERROR_BUDGET * (1u64 << k) as f64
}

/// A scanline as the step bounds see it (see [`step_for`]): its folded angle a as
/// `s` = |sin a| and `c` = |cos a|, `dt` the change of t per pixel, and `t_min` the |t|
/// below which pixels are evaluated exactly (the pole zone; 0 for none).
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepLine {
    pub(crate) s: f64,
    pub(crate) c: f64,
    pub(crate) t_min: f64,
    pub(crate) dt: f64,
    /// With a level per region ([`lod_budget`]): a level the region's spans read at
    /// least whatever their step (from the scanline's vertical footprint there, which
    /// the level of every span of the region includes); 0 otherwise.
    pub(crate) k_floor: u32,
}

/// Where a region's spans start: |X| ∈ [`lo`, `hi`], pixels from the screen's centre
/// column.
#[derive(Debug, Clone, Copy)]
pub(crate) struct XRange {
    pub(crate) lo: f64,
    pub(crate) hi: f64,
}

/// The longest power-of-two step ≤ `nominal` whose linear-interpolation error is bounded
/// by [`SPAN_ERROR_BUDGET`] for every span that starts in `xs` = |X| ∈ [x_lo, x_hi]
/// (pixels from the screen's centre column) on the scanline `line`.
///
/// Along a scanline at folded angle `a` (s = sin a, c = cos a) the direction is
/// (t, s, c), λ = atan2(t, c), φ = atan2(s, ρ) with ρ = √(t²+c²), and t = X/ρ_screen
/// linear in the pixel (`dt` per pixel). |λ_tt| = 2|t|c/ρ⁴ exactly: unimodal in |t|
/// with its peak 0.6495/c² at |t| = c/√3, so its maximum over an interval is at the point
/// of the interval nearest the peak. φ_t = −s·t/(ρ(1+t²)) and
/// φ_tt = −s·(c²(1+t²) − 2t²ρ²)/(ρ³(1+t²)²), whose second factor is at most 1/ρ in size
/// (checked on a dense grid of t and c): |φ_tt| ≤ s/ρ, largest at the smallest |t|, and
/// |φ_t| ≤ s. Pixels with |t| < `t_min` are evaluated exactly (pole zone) and bound no
/// span. A span of n pixels from |X| in [x_lo, x_hi] covers |X| ∈ [x_lo − n, x_hi + n];
/// linear interpolation over it errs by at most (n·dt)²/8 · max|f''| there. (Bounds
/// checked numerically; 10 % margin added.)
///
/// `nominal` is a power of two. The search starts at `hint` (the same region's step on
/// the scanline before, usually the answer: two tests instead of up to seven from the
/// top) and is the same as from the top: a step that fits makes every shorter one fit
/// (its interval lies inside the longer one's, so its bound is no larger, up to
/// rounding, while its error term is a quarter).
pub(crate) fn step_for(b: &StepBounds, line: StepLine, xs: XRange, nominal: u32, hint: u32) -> u32 {
    debug_assert!(nominal.is_power_of_two() && hint.is_power_of_two());
    let top = nominal.max(1);
    let fits = |n: u32| step_fits(b, line, xs, n);
    let mut n = hint.clamp(1, top);
    if fits(n) {
        while n < top && fits(2 * n) {
            n *= 2;
        }
        return n;
    }
    // (1 always fits.)
    loop {
        n >>= 1;
        if fits(n) {
            return n;
        }
    }
}

/// Whether a step of `n` pixels keeps the error bound for spans starting in `xs`
/// ([`step_for`]; a step of 1 always does).
fn step_fits(b: &StepBounds, line: StepLine, xs: XRange, n: u32) -> bool {
    let StepLine { t_min, dt, .. } = line;
    let reach = n as f64;
    let t_lo = ((xs.lo - reach) * dt).max(t_min).max(0.0);
    let t_hi = ((xs.hi + reach) * dt).max(t_lo);
    let bound = span_bound(b, line, t_lo, t_hi);
    let len = reach * dt;
    n == 1 || (bound.is_finite() && len * len / 8.0 * bound <= lod_budget(b, line, xs, reach))
}

/// [`step_for`] searched from the top, as it was before the hint (the reference the
/// hinted search is tested against).
#[cfg(test)]
pub(crate) fn step_from_top(b: &StepBounds, line: StepLine, xs: XRange, nominal: u32) -> u32 {
    let mut n = nominal.max(1);
    while !step_fits(b, line, xs, n) {
        n >>= 1;
    }
    n
}

/// Bound on the second derivative (in source pixels per unit t²) of the map position
/// along a scanline over |t| ∈ [t_lo, t_hi] (see [`step_for`]).
fn span_bound(b: &StepBounds, line: StepLine, t_lo: f64, t_hi: f64) -> f64 {
    let StepLine { s, c, .. } = line;
    let lam_tt = if c <= 0.0 {
        if t_lo > 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    } else {
        let t = (c / 3f64.sqrt()).clamp(t_lo, t_hi);
        let r2 = t * t + c * c;
        2.0 * t * c / (r2 * r2)
    };
    let rho_min = (t_lo * t_lo + c * c).sqrt();
    let phi_tt = if rho_min > 0.0 {
        1.125 * s / rho_min
    } else {
        f64::INFINITY
    };
    let v_tt = b.v1 * phi_tt + b.v2 * s * s;
    1.1 * (b.lam_px * lam_tt + (1.0 + b.coupling) * v_tt)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// The search from any hint finds what the search from the top finds, over
        /// scanline angles, regions, pole zones, map factors and steps (log-uniform
        /// over the ranges frames have, and beyond), with the budget of level 0 and of
        /// the level read (`lod_cap`: a shorter step's level is never finer, so the
        /// search stays monotone).
        #[test]
        fn hinted_step_equals_the_search_from_the_top(
            a in 0.0f64..std::f64::consts::FRAC_PI_2,
            (x_lo, w) in (0.0f64..4000.0, 1.0f64..1000.0),
            t_min in prop_oneof![Just(0.0), 0.0f64..3.0],
            dt in (-14.0f64..-4.0).prop_map(f64::exp2),
            (lam, v1, v2, cpl) in (8.0f64..16.0, 7.0f64..16.0, 0.0f64..14.0, 0.0f64..2.0),
            nominal in prop::sample::select(vec![1u32, 2, 4, 8, 16, 64]),
            hint_log in 0u32..8,
            lod_cap in prop_oneof![Just(None), (0u32..14).prop_map(Some)],
            k_floor in 0u32..6,
        ) {
            let b = StepBounds {
                lam_px: lam.exp2(),
                v1: v1.exp2(),
                v2: v2.exp2() - 1.0,
                coupling: cpl,
                lod_cap,
            };
            let line = StepLine { s: a.sin(), c: a.cos(), t_min, dt, k_floor };
            let xs = XRange { lo: x_lo, hi: x_lo + w };
            let want = step_from_top(&b, line, xs, nominal);
            let got = step_for(&b, line, xs, nominal, 1 << hint_log);
            prop_assert_eq!(got, want);
        }
    }
}
