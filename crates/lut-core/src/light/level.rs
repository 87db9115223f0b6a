//! One table of the distance series: its storage with constant ranges cut (EP 0613099
//! claim 8, in both directions), and its interpolation (claim 3: linear or Catmull-Rom).
//!
//! A [`Grid`] is a full measured table (f64, horizontal-major). [`Grid::to_level`] finds
//! the leading and trailing ranges, vertical (rows) and horizontal (planes), where every
//! value the interpolation would read is the same constant, and stores only the window of
//! values between them. Lookups locate the angle on the *full* axes (angles cost nothing
//! next to the values), so inside the window the index, fraction and arithmetic are the
//! same as without the cut, and in a cut range the interpolation of equal values is that
//! value exactly: lookups with and without the cut are bit for bit identical.
//!
//! Which values an interpolation reads: linear reads the two entries around the angle;
//! Catmull-Rom also one more on each side. Beyond an axis end the neighbour comes from
//! the end rule ([`Edge`]): mirrored at symmetry planes and poles, periodic around a full
//! circle, repeated at the end of a measured range. A cell (between two entries) is
//! constant when every entry it reads, neighbours included, is the same constant; the
//! cut ranges are runs of such cells from either end.

use crate::named::Named;

/// How a table value is filtered between measured angles (claim 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Interpolation {
    /// Bilinear: continuous, never overshoots, exact at the measured angles.
    #[default]
    Linear,
    /// Catmull-Rom (bicubic over 4 × 4 values, the form Blender Cycles uses for IES
    /// lights): smooth slopes, exact at the measured angles; may overshoot near sharp
    /// cut-offs, and is clamped at zero.
    CatmullRom,
}

impl Named for Interpolation {
    const ALL: &'static [Interpolation] = &[Interpolation::Linear, Interpolation::CatmullRom];

    fn name(self) -> &'static str {
        match self {
            Interpolation::Linear => "linear",
            Interpolation::CatmullRom => "catmull-rom",
        }
    }

    fn help(self) -> &'static str {
        match self {
            Interpolation::Linear => "bilinear between measured angles (default)",
            Interpolation::CatmullRom => "bicubic Catmull-Rom (as Blender Cycles), clamped at 0",
        }
    }
}

impl std::fmt::Display for Interpolation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Interpolation {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        crate::named::parse_name(s)
            .ok_or_else(|| crate::named::unknown_name::<Interpolation>("light interpolation", s))
    }
}

/// One table axis: increasing angles, with a fast path when they are evenly spaced.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Axis {
    pub(crate) a: Vec<f64>,
    /// (first angle, 1 / step) when evenly spaced.
    uniform: Option<(f64, f64)>,
}

impl Axis {
    pub(crate) fn new(a: Vec<f64>) -> Axis {
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

    pub(crate) fn first(&self) -> f64 {
        self.a[0]
    }

    pub(crate) fn last(&self) -> f64 {
        self.a[self.a.len() - 1]
    }

    /// Integer index and fraction of `x`, which lies in [first, last]: x sits between
    /// entries i and i+1 at fraction t (i = 0, t = 0 for a one-entry axis).
    #[inline]
    pub(crate) fn locate(&self, x: f64) -> (usize, f64) {
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

/// How an index beyond one end of an axis maps back into it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Edge {
    /// Mirror about the end entry (symmetry planes, poles): index −1 → 1.
    Mirror,
    /// Repeat the end entry (the end of a measured range).
    Clamp,
    /// Periodic with this many distinct entries (a last entry at first + 360° repeats
    /// the first).
    Wrap(usize),
}

/// The end rules of one axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Edges {
    pub(crate) lo: Edge,
    pub(crate) hi: Edge,
}

impl Edges {
    pub(crate) const MIRROR: Edges = Edges {
        lo: Edge::Mirror,
        hi: Edge::Mirror,
    };

    /// The entry index that index `i` of an axis of `n` entries reads.
    pub(crate) fn index(self, i: isize, n: usize) -> usize {
        let last = n as isize - 1;
        let j = if i < 0 {
            match self.lo {
                Edge::Mirror => -i,
                Edge::Clamp => 0,
                Edge::Wrap(p) => i.rem_euclid(p as isize),
            }
        } else if i > last {
            match self.hi {
                Edge::Mirror => 2 * last - i,
                Edge::Clamp => last,
                Edge::Wrap(p) => i.rem_euclid(p as isize),
            }
        } else {
            i
        };
        j.clamp(0, last.max(0)) as usize
    }
}

/// Catmull-Rom (uniform, the form Blender Cycles uses for IES lights) between `b` and `c`
/// at fraction `t`, written in differences so equal inputs give that value exactly.
#[inline]
pub(crate) fn catmull_rom(a: f64, b: f64, c: f64, d: f64, t: f64) -> f64 {
    let (d0, d1, d2) = (b - a, c - b, d - c);
    b + 0.5 * t * ((d0 + d1) + t * ((3.0 * d1 - 2.0 * d0 - d2) + t * (d0 - 2.0 * d1 + d2)))
}

/// How to build a [`Level`] from a [`Grid`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct LevelSpec {
    /// Stored values × scale (normalization to the reference distance).
    pub(crate) scale: f64,
    pub(crate) interpolation: Interpolation,
    /// Cut constant ranges (claim 8); `false` stores every value.
    pub(crate) cut: bool,
    pub(crate) h_edges: Edges,
    pub(crate) v_edges: Edges,
    /// Type A/B: zero outside the measured horizontal range.
    pub(crate) h_bounded: bool,
}

/// One table of the distance series: the stored window of values, normalized to the
/// reference distance, and the constants of the cut ranges around it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Level {
    /// Full axes (every measured angle), for locating.
    h: Axis,
    v: Axis,
    /// Stored window: planes ps..=pe, rows rs..=re of the full grid.
    ps: usize,
    pe: usize,
    rs: usize,
    re: usize,
    /// Their angles (h[ps], h[pe], v[rs], v[re]).
    h_lo: f64,
    h_hi: f64,
    v_lo: f64,
    v_hi: f64,
    /// Constants below / above the stored rows and left / right of the stored planes.
    below: f64,
    above: f64,
    left: Option<f64>,
    right: Option<f64>,
    /// Window index of full-grid plane i: i + p_off, within 0..=p_max (the window with
    /// its neighbours); rows likewise.
    p_off: isize,
    p_max: isize,
    r_off: isize,
    r_max: isize,
    /// Values of the window with `g` neighbours on each side, horizontal-major:
    /// `values[(ih - ps + g) * stride + (iv - rs + g)]`, lux at d_ref.
    values: Vec<f64>,
    stride: usize,
    interpolation: Interpolation,
    h_bounded: bool,
}

/// Leading and trailing runs of constant cells of an axis of `n` entries whose entry `i`
/// is `Some(c)` when constant: (cells cut at the start and their constant, the first cut
/// cell at the end and its constant). A cell k (entries k, k+1) is constant when entries
/// k−g ..= k+1+g (read through `edges`) are all the same constant.
fn constant_runs(
    entry: &[Option<f64>],
    edges: Edges,
    g: usize,
) -> ((usize, Option<f64>), (usize, Option<f64>)) {
    let n = entry.len();
    if n < 2 {
        return ((0, None), (n.saturating_sub(1), None));
    }
    let cell = |k: usize| -> Option<f64> {
        let lo = k as isize - g as isize;
        let hi = (k + 1 + g) as isize;
        let c = entry[edges.index(lo, n)]?;
        (lo..=hi)
            .all(|i| entry[edges.index(i, n)] == Some(c))
            .then_some(c)
    };
    let cells = n - 1;
    let lead_c = cell(0);
    let mut lead = 0;
    if lead_c.is_some() {
        while lead < cells && cell(lead) == lead_c {
            lead += 1;
        }
    }
    let trail_c = cell(cells - 1);
    let mut trail = cells; // index of the first trailing constant cell
    if trail_c.is_some() {
        while trail > 0 && cell(trail - 1) == trail_c {
            trail -= 1;
        }
    }
    ((lead, lead_c), (trail, trail_c))
}

/// A full measured grid in f64 (before trimming), horizontal-major.
#[derive(Debug, Clone)]
pub(crate) struct Grid {
    pub(crate) h: Vec<f64>,
    pub(crate) v: Vec<f64>,
    pub(crate) vals: Vec<f64>,
}

/// [¼ ½ ¼] pre-filter along one line of values, neighbours read through `edges`.
pub(crate) fn filter_line(line: &[f64], edges: Edges) -> Vec<f64> {
    let n = line.len();
    let at = |i: isize| line[edges.index(i, n)];
    (0..n as isize)
        .map(|i| 0.25 * at(i - 1) + 0.5 * at(i) + 0.25 * at(i + 1))
        .collect()
}

/// Every other index, always keeping the last.
pub(crate) fn kept(n: usize) -> Vec<usize> {
    let mut k: Vec<usize> = (0..n).step_by(2).collect();
    if k.last() != Some(&(n - 1)) {
        k.push(n - 1);
    }
    k
}

impl Grid {
    /// Append a plane at first + 360° repeating the first, unless the last already is
    /// there: a full circle then needs no wrap-around at lookup.
    pub(crate) fn close_circle(&mut self) {
        let nv = self.v.len();
        let (first, last) = (self.h[0], self.h[self.h.len() - 1]);
        if (last - first - 360.0).abs() > 1e-6 {
            self.h.push(first + 360.0);
            let plane0: Vec<f64> = self.vals[..nv].to_vec();
            self.vals.extend(plane0);
        }
    }

    /// Pre-filter and decimate each dimension with ≥ 3 entries; `None` when none has.
    /// Vertically the filter mirrors at both ends; horizontally it follows `h_edges`.
    pub(crate) fn halve(&self, h_edges: Edges) -> Option<Grid> {
        let (nh, nv) = (self.h.len(), self.v.len());
        if nh < 3 && nv < 3 {
            return None;
        }
        let mut g = self.clone();
        if nv >= 3 {
            let keep = kept(nv);
            let mut vals = Vec::with_capacity(nh * keep.len());
            for row in g.vals.chunks_exact(nv) {
                let f = filter_line(row, Edges::MIRROR);
                vals.extend(keep.iter().map(|&i| f[i]));
            }
            g.v = keep.iter().map(|&i| g.v[i]).collect();
            g.vals = vals;
        }
        let nv = g.v.len();
        if nh >= 3 {
            let keep = kept(nh);
            let mut cols = vec![0.0; keep.len() * nv];
            let mut line = vec![0.0; nh];
            for iv in 0..nv {
                for (ih, l) in line.iter_mut().enumerate() {
                    *l = g.vals[ih * nv + iv];
                }
                let f = filter_line(&line, h_edges);
                for (k, &i) in keep.iter().enumerate() {
                    cols[k * nv + iv] = f[i];
                }
            }
            g.h = keep.iter().map(|&i| g.h[i]).collect();
            g.vals = cols;
        }
        Some(g)
    }

    /// The level of this grid: constant ranges cut (when `spec.cut`), values × scale.
    pub(crate) fn to_level(&self, spec: &LevelSpec) -> Level {
        let (nh, nv) = (self.h.len(), self.v.len());
        let g = match spec.interpolation {
            Interpolation::Linear => 0,
            Interpolation::CatmullRom => 1,
        };
        let at = |ih: usize, iv: usize| self.vals[ih * nv + iv];
        // Rows: constant across every plane (a vertical cut serves any horizontal angle).
        let (mut rs, mut re) = (0, nv - 1);
        let (mut below, mut above) = (0.0, 0.0);
        if spec.cut {
            let rows: Vec<Option<f64>> = (0..nv)
                .map(|iv| {
                    let c = at(0, iv);
                    (0..nh).all(|ih| at(ih, iv) == c).then_some(c)
                })
                .collect();
            let ((lead, lc), (trail, tc)) = constant_runs(&rows, spec.v_edges, g);
            rs = lead.min(nv - 1);
            re = trail.max(rs);
            below = lc.unwrap_or(0.0);
            above = tc.unwrap_or(0.0);
        }
        // Planes: constant over the rows the stored window's interpolation reads.
        let (rlo, rhi) = (rs as isize - g as isize, (re + g) as isize);
        let (mut ps, mut pe) = (0, nh - 1);
        let (mut left, mut right) = (None, None);
        if spec.cut && nh > 1 {
            let planes: Vec<Option<f64>> = (0..nh)
                .map(|ih| {
                    let c = at(ih, spec.v_edges.index(rlo, nv));
                    (rlo..=rhi)
                        .all(|i| at(ih, spec.v_edges.index(i, nv)) == c)
                        .then_some(c)
                })
                .collect();
            let ((lead, lc), (trail, tc)) = constant_runs(&planes, spec.h_edges, g);
            ps = lead.min(nh - 1);
            pe = trail.max(ps);
            left = lc.filter(|_| lead > 0);
            right = tc.filter(|_| trail < nh - 1);
        }
        let (wh, wv) = (pe - ps + 1 + 2 * g, re - rs + 1 + 2 * g);
        let mut values = Vec::with_capacity(wh * wv);
        for ph in 0..wh {
            let ih = spec
                .h_edges
                .index(ps as isize - g as isize + ph as isize, nh);
            for pv in 0..wv {
                let iv = spec
                    .v_edges
                    .index(rs as isize - g as isize + pv as isize, nv);
                values.push(at(ih, iv) * spec.scale);
            }
        }
        Level {
            h: Axis::new(self.h.clone()),
            v: Axis::new(self.v.clone()),
            ps,
            pe,
            rs,
            re,
            h_lo: self.h[ps],
            h_hi: self.h[pe],
            v_lo: self.v[rs],
            v_hi: self.v[re],
            below: below * spec.scale,
            above: above * spec.scale,
            left: left.map(|c| c * spec.scale),
            right: right.map(|c| c * spec.scale),
            p_off: g as isize - ps as isize,
            p_max: wh as isize - 1,
            r_off: g as isize - rs as isize,
            r_max: wv as isize - 1,
            values,
            stride: wv,
            interpolation: spec.interpolation,
            h_bounded: spec.h_bounded,
        }
    }
}

impl Level {
    /// (stored planes, stored rows): the window, without interpolation neighbours.
    pub(crate) fn size(&self) -> (usize, usize) {
        (self.pe - self.ps + 1, self.re - self.rs + 1)
    }

    /// The first horizontal angle.
    pub(crate) fn h_first(&self) -> f64 {
        self.h.first()
    }

    /// Number of values held, interpolation neighbours included.
    pub(crate) fn stored_values(&self) -> usize {
        self.values.len()
    }

    /// The value at vertical angle v when it lies in a range that is not stored (zero
    /// outside the measured range, or a cut constant range); `None` inside the window.
    #[inline]
    pub(crate) fn constant_at(&self, v: f64) -> Option<f64> {
        if !(v >= self.v.first() && v <= self.v.last()) {
            Some(0.0)
        } else if v < self.v_lo {
            Some(self.below)
        } else if v > self.v_hi {
            Some(self.above)
        } else {
            None
        }
    }

    /// The value at (folded) horizontal angle h and vertical angle v.
    #[inline]
    pub(crate) fn sample(&self, h: f64, v: f64) -> f64 {
        if let Some(c) = self.constant_at(v) {
            return c;
        }
        let nh = self.h.a.len();
        let (ih, th) = if nh == 1 {
            (0, 0.0)
        } else if !(h >= self.h_lo && h <= self.h_hi) {
            if self.h_bounded && !(h >= self.h.first() && h <= self.h.last()) {
                return 0.0;
            }
            match (h < self.h_lo, self.left, self.right) {
                (true, Some(c), _) | (false, _, Some(c)) => return c,
                // Folding keeps h inside; a rounding step outside clamps to the edge.
                (true, None, _) => (self.ps, 0.0),
                (false, _, None) => (self.pe.max(1) - 1, 1.0),
            }
        } else {
            self.h.locate(h)
        };
        let (iv, tv) = self.v.locate(v);
        match self.interpolation {
            Interpolation::Linear => self.bilinear(ih, th, iv, tv),
            Interpolation::CatmullRom => self.bicubic(ih, th, iv, tv).max(0.0),
        }
    }

    /// Window index of full-grid plane `ih + d` (d from −1 to 2), clamped into the
    /// stored window: at a window edge the fraction is 0 or 1, so the clamped neighbour
    /// is multiplied by zero (or is an equal value).
    #[inline]
    fn plane(&self, ih: usize, d: isize) -> usize {
        (ih as isize + self.p_off + d).clamp(0, self.p_max) as usize
    }

    #[inline]
    fn row(&self, iv: usize, d: isize) -> usize {
        (iv as isize + self.r_off + d).clamp(0, self.r_max) as usize
    }

    #[inline]
    fn bilinear(&self, ih: usize, th: f64, iv: usize, tv: f64) -> f64 {
        let (p0, p1) = (self.plane(ih, 0), self.plane(ih, 1));
        let (r0, r1) = (self.row(iv, 0), self.row(iv, 1));
        let (i0, i1) = (p0 * self.stride, p1 * self.stride);
        let v = &self.values;
        let a = v[i0 + r0] + (v[i0 + r1] - v[i0 + r0]) * tv;
        let b = v[i1 + r0] + (v[i1 + r1] - v[i1 + r0]) * tv;
        a + (b - a) * th
    }

    #[inline]
    fn bicubic(&self, ih: usize, th: f64, iv: usize, tv: f64) -> f64 {
        let rows = [-1, 0, 1, 2].map(|d| self.row(iv, d));
        let col = |p: usize| {
            let r = &self.values[p * self.stride..(p + 1) * self.stride];
            catmull_rom(r[rows[0]], r[rows[1]], r[rows[2]], r[rows[3]], tv)
        };
        if self.h.a.len() == 1 {
            return col(self.plane(ih, 0));
        }
        let c = [-1, 0, 1, 2].map(|d| col(self.plane(ih, d)));
        catmull_rom(c[0], c[1], c[2], c[3], th)
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
        let f = filter_line(&[2.0, 2.0, 2.0], Edges::MIRROR);
        assert_eq!(f, vec![2.0, 2.0, 2.0]);
        let x = [1.0, 5.0, 3.0, 0.0];
        let wrap = Edges {
            lo: Edge::Wrap(4),
            hi: Edge::Wrap(4),
        };
        let f = filter_line(&x, wrap);
        let (a, b): (f64, f64) = (x.iter().sum(), f.iter().sum());
        assert!((a - b).abs() < 1e-12);
    }

    #[test]
    fn edges_mirror_clamp_and_wrap() {
        let m = Edges::MIRROR;
        assert_eq!((m.index(-1, 5), m.index(5, 5), m.index(-2, 5)), (1, 3, 2));
        let c = Edges {
            lo: Edge::Clamp,
            hi: Edge::Clamp,
        };
        assert_eq!((c.index(-1, 5), c.index(6, 5)), (0, 4));
        // Closed circle of 5 entries, the last repeating the first: period 4.
        let w = Edges {
            lo: Edge::Wrap(4),
            hi: Edge::Wrap(4),
        };
        assert_eq!((w.index(-1, 5), w.index(5, 5)), (3, 1));
        assert_eq!(m.index(-1, 1), 0);
    }

    #[test]
    fn catmull_rom_is_exact_at_the_nodes_and_for_constants() {
        assert_eq!(catmull_rom(1.0, 2.0, 4.0, 8.0, 0.0), 2.0);
        assert!((catmull_rom(1.0, 2.0, 4.0, 8.0, 1.0) - 4.0).abs() < 1e-15);
        for t in [0.1, 0.37, 0.5, 0.99] {
            assert_eq!(catmull_rom(0.3, 0.3, 0.3, 0.3, t), 0.3);
        }
        // Reproduces a straight line (uniform spacing).
        assert!((catmull_rom(1.0, 2.0, 3.0, 4.0, 0.25) - 2.25).abs() < 1e-15);
    }

    #[test]
    fn constant_runs_need_every_value_read() {
        let e: Vec<Option<f64>> = [Some(0.0), Some(0.0), Some(0.0), None, Some(0.0)].into();
        let clamp = Edges {
            lo: Edge::Clamp,
            hi: Edge::Clamp,
        };
        // Linear: cells 0, 1 are constant; none at the end (cell 3 reads entry 3).
        assert_eq!(constant_runs(&e, clamp, 0), ((2, Some(0.0)), (4, None)));
        // Catmull-Rom: cell 1 also reads entry 3, so only cell 0 is constant.
        assert_eq!(constant_runs(&e, clamp, 1).0, (1, Some(0.0)));
    }
}
