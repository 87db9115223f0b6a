//! The per-pixel samplers every renderer shares: nearest and bilinear on the padded map
//! (FIG. 10 of the patent), their cropped forms for partial maps (`map/crop.rs`), and
//! the 0RGB blend. The span kernels the LUT renderer runs are in `render/kernel/`.

use crate::geom::fixed::{Fx, FX_BITS, FX_HALF};
use crate::map::envmap::EnvMap;
use crate::named::{parse_name, unknown_name, Named};

/// Pixel interpolation (the patent's FIG. 10).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Sampler {
    /// The source pixel containing (u, v).
    Nearest,
    /// The four pixel centers around (u − ½, v − ½), weighted by the fractions.
    Bilinear,
    /// Bilinear on the two pyramid levels around the pixel footprint, blended
    /// (minification anti-aliasing, see [`crate::EnvMap::pyramid`]; partial maps and cube
    /// faces have pyramids too). Where no footprint is known (single samples) it is
    /// bilinear.
    Trilinear,
}

impl Sampler {
    /// Name used on the command line (see [`crate::Named`]).
    pub fn name(self) -> &'static str {
        Named::name(self)
    }
}

impl std::str::FromStr for Sampler {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        parse_name(s).ok_or_else(|| unknown_name::<Sampler>("sampler", s))
    }
}

impl Named for Sampler {
    const ALL: &'static [Self] = &[Sampler::Nearest, Sampler::Bilinear, Sampler::Trilinear];
    fn name(self) -> &'static str {
        match self {
            Sampler::Nearest => "nearest",
            Sampler::Bilinear => "bilinear",
            Sampler::Trilinear => "trilinear",
        }
    }
    fn help(self) -> &'static str {
        match self {
            Sampler::Nearest => "Nearest source pixel",
            Sampler::Bilinear => "Bilinear",
            Sampler::Trilinear => {
                "Trilinear: bilinear on the two pyramid levels around the pixel footprint \
                 (anti-aliased when zoomed out; the pyramid takes up to 1/3 more memory)"
            }
        }
    }
}

impl EnvMap {
    /// Sample at (u, v) (Q.16 map coordinates; u is expected in [0, W) for wrapping maps
    /// and is clamped otherwise). For a partial map, (u, v) are full-panorama
    /// coordinates and uncovered positions give the background.
    #[inline(always)]
    pub fn sample(&self, sampler: Sampler, u: Fx, v: Fx) -> u32 {
        if self.crop.is_some() {
            return self.sample_cropped(sampler, u, v);
        }
        match sampler {
            Sampler::Nearest => self.nearest(u, v),
            Sampler::Bilinear | Sampler::Trilinear => self.bilinear(u, v),
        }
    }

    /// Nearest: the pixel containing (u, v), clamped into the image (on elliptical and
    /// diamond maps, into the row's pixels on the sphere). (u, v) are stored coordinates:
    /// for a partial map use [`EnvMap::nearest_cropped`].
    #[inline(always)]
    pub fn nearest(&self, u: Fx, v: Fx) -> u32 {
        let w = self.width as i64;
        let h = self.height as i64;
        let mut x = (u >> FX_BITS).clamp(0, w - 1);
        let y = (v >> FX_BITS).clamp(0, h - 1);
        if let Some(&(lo, hi)) = self.row_extent.get(y as usize) {
            x = x.clamp(lo, hi);
        }
        self.padded().0[y as usize * (w as usize + 1) + x as usize]
    }

    /// Bilinear over the four pixel centers around (u − ½, v − ½), 8-bit weights;
    /// wraps in u for 360° maps, clamps otherwise and in v. Elliptical and diamond rows
    /// are circles of their own length: a neighbour beyond a row's end is the pixel at
    /// its other end (the same longitude, ±180°), never the area outside the map's shape.
    /// (u, v) are stored coordinates: for a partial map use [`EnvMap::bilinear_cropped`].
    #[inline(always)]
    pub fn bilinear(&self, u: Fx, v: Fx) -> u32 {
        if !self.row_extent.is_empty() {
            return self.bilinear_rows(u, v);
        }
        let w = self.width as i64;
        let h = self.height as i64;
        let uu = u - FX_HALF;
        let vv = v - FX_HALF;
        let mut x0 = uu >> FX_BITS;
        let mut fx = ((uu >> (FX_BITS - 8)) & 0xFF) as u32;
        let mut y0 = vv >> FX_BITS;
        let mut fy = ((vv >> (FX_BITS - 8)) & 0xFF) as u32;
        if x0 < 0 {
            if self.projection.wraps() && x0 == -1 {
                x0 = w - 1; // column W (padding) is column 0
            } else {
                x0 = 0;
                fx = 0;
            }
        } else if x0 >= w {
            if self.projection.wraps() && x0 == w {
                x0 = 0;
            } else {
                x0 = w - 1;
                fx = 0;
            }
        }
        if y0 < 0 {
            y0 = 0;
            fy = 0;
        } else if y0 >= h - 1 {
            y0 = h - 1; // row H (padding) repeats row H-1
            fy = 0;
        }
        let stride = w as usize + 1;
        let i = y0 as usize * stride + x0 as usize;
        let data = self.padded().0;
        let row0 = &data[i..i + 2];
        let row1 = &data[i + stride..i + stride + 2];
        let top = lerp_px(row0[0], row0[1], fx);
        let bot = lerp_px(row1[0], row1[1], fx);
        lerp_px(top, bot, fy)
    }
}

impl EnvMap {
    /// [`EnvMap::bilinear`] of an elliptical or diamond map: each row's neighbours wrap
    /// within the row's pixels on the sphere (`row_extent`), rows clamp in v.
    #[inline(never)]
    fn bilinear_rows(&self, u: Fx, v: Fx) -> u32 {
        let h = self.height as i64;
        let uu = u - FX_HALF;
        let vv = v - FX_HALF;
        let x0 = uu >> FX_BITS;
        let fx = ((uu >> (FX_BITS - 8)) & 0xFF) as u32;
        let mut y0 = vv >> FX_BITS;
        let mut fy = ((vv >> (FX_BITS - 8)) & 0xFF) as u32;
        if y0 < 0 {
            y0 = 0;
            fy = 0;
        } else if y0 >= h - 1 {
            y0 = h - 1;
            fy = 0;
        }
        let y1 = (y0 + 1).min(h - 1);
        let row = |y: i64| {
            let a = self.row_pixel(x0, y);
            let b = self.row_pixel(x0 + 1, y);
            lerp_px(a, b, fx)
        };
        let top = row(y0);
        if fy == 0 {
            return top;
        }
        lerp_px(top, row(y1), fy)
    }

    /// Pixel `x` of row `y` of an elliptical or diamond map, `x` taken round the row's
    /// pixels on the sphere (so one past the last is the first).
    #[inline(always)]
    fn row_pixel(&self, x: i64, y: i64) -> u32 {
        let (lo, hi) = self.row_extent[y as usize];
        let x = if x < lo || x > hi {
            lo + (x - lo).rem_euclid(hi - lo + 1)
        } else {
            x
        };
        self.pixel(x as u32, y as u32)
    }

    /// Stored pixel (x, y), for an elliptical or diamond map with `x` clamped into the
    /// row's pixels on the sphere (the pyramid averages these, never the area outside).
    #[inline]
    pub(crate) fn pixel_on_sphere(&self, x: u32, y: u32) -> u32 {
        match self.row_extent.get(y as usize) {
            Some(&(lo, hi)) => self.pixel((x as i64).clamp(lo, hi) as u32, y),
            None => self.pixel(x, y),
        }
    }
}

/// Blend two 0RGB pixels: `a · (256 − w) + b · w`, rounded, two channels per multiply.
#[inline(always)]
pub fn lerp_px(a: u32, b: u32, w: u32) -> u32 {
    let iw = 256 - w;
    let rb = (((a & 0x00FF_00FF) * iw + (b & 0x00FF_00FF) * w + 0x0080_0080) >> 8) & 0x00FF_00FF;
    let g = (((a & 0x0000_FF00) * iw + (b & 0x0000_FF00) * w + 0x0000_8000) >> 8) & 0x0000_FF00;
    rb | g
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::fixed::to_fx;
    use crate::geom::projection::Projection;

    fn ramp(w: u32, h: u32, p: Projection) -> EnvMap {
        let px: Vec<u32> = (0..w * h).map(|i| (i % w) << 16 | (i / w) << 8).collect();
        EnvMap::from_pixels(w, h, &px, p).unwrap()
    }

    #[test]
    fn lerp_endpoints_and_middle() {
        assert_eq!(lerp_px(0x102030, 0x405060, 0), 0x102030);
        assert_eq!(lerp_px(0x000000, 0xFFFFFF, 128), 0x808080);
        assert_eq!(lerp_px(0xFFFFFF, 0xFFFFFF, 255), 0xFFFFFF);
    }

    #[test]
    fn bilinear_at_centers_is_the_pixel() {
        let m = ramp(16, 8, Projection::Equirect);
        for (x, y) in [(0, 0), (15, 7), (3, 4)] {
            let s = m.bilinear(to_fx(x as f64 + 0.5), to_fx(y as f64 + 0.5));
            assert_eq!(s, m.pixel(x, y));
        }
    }

    #[test]
    fn bilinear_wraps_horizontally() {
        let m = ramp(16, 8, Projection::Equirect);
        // halfway between column 15 and column 0
        let s = m.bilinear(to_fx(16.0), to_fx(2.5));
        assert_eq!(s >> 16, 8); // (15*128 + 0*128 + 128) >> 8 = 8
        let s0 = m.bilinear(to_fx(0.0), to_fx(2.5));
        assert_eq!(s, s0);
    }

    /// Elliptical rows are circles of their own length: the equator row (all 16 pixels)
    /// wraps from column 15 to column 0, the top row (pixels 6..=9 on the sphere) from 9
    /// to 6, and nearest clamps into the row's pixels.
    #[test]
    fn elliptical_rows_wrap_within_their_length() {
        let m = ramp(16, 8, Projection::Elliptical);
        assert_eq!(m.row_extent[3], (0, 15));
        assert_eq!(m.row_extent[0], (6, 9));
        // u = 0.1 on the equator row: centres 15 (wrapped) and 0, weight 0.6 (153/256).
        let want = lerp_px(m.pixel(15, 3), m.pixel(0, 3), 153);
        assert_eq!(m.bilinear(to_fx(0.1), to_fx(3.5)), want);
        // u = 6.0 on the top row: between the centres of 9 (wrapped from 5) and 6.
        let want = lerp_px(m.pixel(9, 0), m.pixel(6, 0), 128);
        assert_eq!(m.bilinear(to_fx(6.0), to_fx(0.5)), want);
        assert_eq!(m.nearest(to_fx(0.1), to_fx(0.1)), m.pixel(6, 0));
        assert_eq!(m.nearest(to_fx(15.9), to_fx(0.1)), m.pixel(9, 0));
    }

    /// No sample of an elliptical or diamond map ever reads a pixel off the sphere: with
    /// those pixels a sentinel colour and every pixel on it grey, every sample is grey.
    #[test]
    fn samples_never_read_off_the_sphere() {
        for p in [Projection::Elliptical, Projection::Diamond] {
            let (w, h) = (40u32, 20u32);
            let px: Vec<u32> = (0..w * h)
                .map(|i| {
                    let (x, y) = (i % w, i / w);
                    match p.direction(x as f64 + 0.5, y as f64 + 0.5, w as f64, h as f64) {
                        Some(_) => 0x404040,
                        None => 0xFF00FF,
                    }
                })
                .collect();
            let m = EnvMap::from_pixels(w, h, &px, p).unwrap();
            for i in 0..=400 {
                for j in 0..=200 {
                    let (u, v) = (to_fx(i as f64 * 0.1), to_fx(j as f64 * 0.1));
                    assert_eq!(m.bilinear(u, v), 0x404040, "{p} bilinear at ({i}, {j})/10");
                    assert_eq!(m.nearest(u, v), 0x404040, "{p} nearest at ({i}, {j})/10");
                    assert_eq!(
                        m.trilinear(u, v, 300),
                        0x404040,
                        "{p} trilinear at ({i}, {j})/10"
                    );
                }
            }
        }
    }
}
