//! Partial maps: an [`EnvMap`] that stores only the pixels of a [`Crop`] of the full
//! panorama, and the cropped samplers (background outside the crop, the crop's edge
//! texels clamped inside; on pyramid levels the padded full map's bilinear,
//! [`EnvMap::bilinear_padded`]). The rules are in `geom/coverage.rs`.

use crate::error::CoverageError;
use crate::geom::coverage::{Coverage, Crop, StartView};
use crate::geom::fixed::{Fx, FX_BITS, FX_HALF};
use crate::geom::projection::Projection;
use crate::map::envmap::EnvMap;
use crate::map::sample::{lerp_px, Sampler};

impl EnvMap {
    /// Where the stored pixels sit in the full panorama, for a partial map.
    pub fn crop(&self) -> Option<Crop> {
        self.crop
    }

    /// The covered area in degrees ([`Coverage::FULL`] for a whole map; for projections
    /// other than equirectangular the crop is not used and this is also `FULL`).
    pub fn coverage(&self) -> Coverage {
        self.crop.map_or(Coverage::FULL, |c| c.coverage())
    }

    /// Compass heading, in degrees, of the map's centre column (longitude 0): GPano
    /// `PoseHeadingDegrees`, when the file has it.
    pub fn pose_heading_deg(&self) -> Option<f64> {
        self.pose_heading
    }

    /// Set (or clear) the compass heading of longitude 0 (see
    /// [`EnvMap::pose_heading_deg`]). Non-finite values clear it.
    pub fn set_pose_heading_deg(&mut self, heading: Option<f64>) {
        self.pose_heading = heading
            .filter(|h| h.is_finite())
            .map(|h| h.rem_euclid(360.0));
    }

    /// The view the file asks to be opened at (GPano `InitialView*`), when it has one.
    pub fn start_view(&self) -> Option<StartView> {
        self.start_view
    }

    /// Set (or clear) the start view (see [`EnvMap::start_view`]).
    pub fn set_start_view(&mut self, view: Option<StartView>) {
        self.start_view = view;
    }

    /// Width of the stored pixels (the crop's width for a partial map, else
    /// [`EnvMap::width`]).
    pub fn stored_width(&self) -> u32 {
        self.width
    }
    /// Height of the stored pixels.
    pub fn stored_height(&self) -> u32 {
        self.height
    }

    /// Turn a map holding the pixels of `crop` (`crop.width() × crop.height()`) into a
    /// partial equirectangular map of the full panorama. A crop that is the whole
    /// panorama gives an ordinary map.
    ///
    /// # Errors
    /// [`CoverageError::StoredSize`] when the stored size is not the crop's size.
    pub fn into_partial(self, crop: Crop) -> Result<EnvMap, CoverageError> {
        if (self.width, self.height) != (crop.width(), crop.height()) {
            return Err(CoverageError::StoredSize {
                crop_width: crop.width(),
                crop_height: crop.height(),
                full_width: crop.full_width(),
                full_height: crop.full_height(),
                width: self.width,
                height: self.height,
            });
        }
        // The padding column must repeat column 0 only when the crop spans 360°.
        let wrap = crop.width() == crop.full_width();
        // A crop that is the whole panorama becomes a plain map: its stored column 0 is
        // panorama column `left`, so the columns are turned to put panorama column 0
        // first (e.g. `360x180+30+0`: the stored image starts 30° east).
        let turn = crop.is_full() && crop.left() != 0;
        let mut m = if self.projection.wraps() == wrap && !turn {
            self
        } else {
            let (w, h) = (self.width, self.height);
            // Panorama column x is stored column (x − left) mod W (left is 0 unless
            // `turn`).
            let shift = if turn { w - crop.left() % w } else { 0 };
            let px: Vec<u32> = (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| self.pixel((x + shift) % w, y))
                .collect();
            // (elliptical maps pad by repeating the last column)
            let pad_as = if wrap {
                Projection::Equirect
            } else {
                Projection::Elliptical
            };
            let mut m = EnvMap::from_pixels(w, h, &px, pad_as)?;
            m.background = self.background;
            m.pose_heading = self.pose_heading;
            m.start_view = self.start_view;
            m
        };
        // Bilinear only wraps for column −1 / W; a non-360° crop never asks for those
        // (see `bilinear_cropped`), so the projection can say equirect in both cases.
        m.projection = Projection::Equirect;
        m.row_extent.clear();
        m.crop = if crop.is_full() { None } else { Some(crop) };
        Ok(m)
    }

    /// Nearest sample at a full-panorama position (Q.16) of a partial map: the covered
    /// pixel containing it, or the background. For a map without a crop it is
    /// [`EnvMap::nearest`].
    #[inline]
    pub fn nearest_cropped(&self, u: Fx, v: Fx) -> u32 {
        match self.crop {
            None => self.nearest(u, v),
            Some(c) => match c.locate(u, v) {
                Some((su, sv)) => self.nearest(su, sv),
                None => self.background,
            },
        }
    }

    /// Bilinear sample at a full-panorama position (Q.16) of a partial map: background
    /// where the containing pixel is not covered; inside, the four nearest covered pixel
    /// centres, clamped to the crop's edge texels (wrapping only for a 360°-wide crop).
    /// For a map without a crop it is [`EnvMap::bilinear`].
    #[inline]
    pub fn bilinear_cropped(&self, u: Fx, v: Fx) -> u32 {
        match self.crop {
            None => self.bilinear(u, v),
            Some(c) => match c.locate(u, v) {
                Some((su, sv)) => {
                    // Left edge: clamp to column 0 rather than wrap to the last column
                    // (the right edge reads the padding column, which repeats the last).
                    let su = if c.width() < c.full_width() {
                        su.max(FX_HALF)
                    } else {
                        su
                    };
                    self.bilinear(su, sv)
                }
                None => self.background,
            },
        }
    }

    /// Bilinear at a full-panorama position (Q.16) as the full map padded with the
    /// background gives it (`EnvMap::bilinear` of that map: columns wrap round the
    /// panorama, rows clamp, and a texel off the stored pixels is the background): how
    /// the pyramid levels of a partial map are read (`map/pyramid.rs`), so a level blends
    /// into the background across the crop's edge as the padded map's level does. For a
    /// map without a crop it is [`EnvMap::bilinear`].
    #[inline]
    pub(crate) fn bilinear_padded(&self, u: Fx, v: Fx) -> u32 {
        let Some(c) = self.crop else {
            return self.bilinear(u, v);
        };
        let (w, h) = (c.full_width() as i64, c.full_height() as i64);
        let (uu, vv) = (u - FX_HALF, v - FX_HALF);
        let x0 = (uu >> FX_BITS).rem_euclid(w);
        let fx = ((uu >> (FX_BITS - 8)) & 0xFF) as u32;
        let x1 = if x0 + 1 < w { x0 + 1 } else { 0 };
        let (mut y0, mut fy) = (vv >> FX_BITS, ((vv >> (FX_BITS - 8)) & 0xFF) as u32);
        if y0 < 0 {
            (y0, fy) = (0, 0);
        } else if y0 >= h - 1 {
            (y0, fy) = (h - 1, 0);
        }
        let y1 = (y0 + 1).min(h - 1);
        let (left, top) = (c.left() as i64, c.top() as i64);
        let (cw, ch) = (c.width() as i64, c.height() as i64);
        let at = |x: i64, y: i64| {
            let (sx, sy) = ((x - left).rem_euclid(w), y - top);
            if sx < cw && (0..ch).contains(&sy) {
                self.pixel(sx as u32, sy as u32)
            } else {
                self.background
            }
        };
        let top = lerp_px(at(x0, y0), at(x1, y0), fx);
        let bot = lerp_px(at(x0, y1), at(x1, y1), fx);
        lerp_px(top, bot, fy)
    }

    /// [`EnvMap::sample`] for a partial map.
    #[inline]
    pub(crate) fn sample_cropped(&self, sampler: Sampler, u: Fx, v: Fx) -> u32 {
        match sampler {
            Sampler::Nearest => self.nearest_cropped(u, v),
            Sampler::Bilinear | Sampler::Trilinear => self.bilinear_cropped(u, v),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::fixed::to_fx;

    fn partial(crop: Crop) -> EnvMap {
        let (w, h) = (crop.width(), crop.height());
        let px: Vec<u32> = (0..w * h)
            .map(|i| 0x010000 * (i % w) + 0x100 * (i / w) + 1)
            .collect();
        let mut m = EnvMap::from_pixels(w, h, &px, Projection::Elliptical)
            .unwrap()
            .into_partial(crop)
            .unwrap();
        m.set_background(0xABCDEF);
        m
    }

    #[test]
    fn sampling_inside_outside_and_across_the_seam() {
        // 10 columns from column 95 of 100: 95..100 and 0..5
        let m = partial(Crop::new(100, 50, 95, 10, 10, 20).unwrap());
        assert_eq!((m.width(), m.height(), m.stored_width()), (100, 50, 10));
        let at = |u: f64, v: f64| m.nearest_cropped(to_fx(u), to_fx(v));
        assert_eq!(at(95.5, 10.5), m.pixel(0, 0));
        assert_eq!(at(99.5, 29.5), m.pixel(4, 19));
        assert_eq!(at(0.5, 12.5), m.pixel(5, 2));
        assert_eq!(at(4.99, 12.5), m.pixel(9, 2));
        for (u, v) in [
            (5.0, 12.5),
            (94.99, 12.5),
            (50.0, 20.0),
            (97.0, 9.99),
            (97.0, 30.0),
        ] {
            assert_eq!(at(u, v), 0xABCDEF, "({u}, {v})");
            assert_eq!(m.bilinear_cropped(to_fx(u), to_fx(v)), 0xABCDEF);
        }
        // bilinear across the seam blends stored columns 4 and 5
        let b = m.bilinear_cropped(to_fx(100.0), to_fx(12.5));
        assert_eq!(b, lerp_px(m.pixel(4, 2), m.pixel(5, 2), 128));
        // edges clamp to the edge texels
        assert_eq!(m.bilinear_cropped(to_fx(95.1), to_fx(10.1)), m.pixel(0, 0));
        assert_eq!(m.bilinear_cropped(to_fx(4.9), to_fx(29.9)), m.pixel(9, 19));
        // sample() goes through the crop
        assert_eq!(
            m.sample(Sampler::Nearest, to_fx(0.5), to_fx(12.5)),
            m.pixel(5, 2)
        );
        assert_eq!(
            m.sample(Sampler::Bilinear, to_fx(50.0), to_fx(12.5)),
            0xABCDEF
        );
    }

    #[test]
    fn full_width_crop_wraps() {
        let m = partial(Crop::new(16, 20, 0, 5, 16, 6).unwrap());
        let b = m.bilinear_cropped(to_fx(0.0), to_fx(7.5));
        assert_eq!(b, lerp_px(m.pixel(15, 2), m.pixel(0, 2), 128));
        let b = m.bilinear_cropped(to_fx(15.9999), to_fx(7.5));
        assert_eq!(b, lerp_px(m.pixel(15, 2), m.pixel(0, 2), 128));
        assert_eq!(m.nearest_cropped(to_fx(3.5), to_fx(4.9)), 0xABCDEF);
        assert_eq!(m.nearest_cropped(to_fx(3.5), to_fx(11.0)), 0xABCDEF);
    }

    #[test]
    fn whole_crop_is_a_plain_map() {
        let m = partial(Crop::new(16, 8, 0, 0, 16, 8).unwrap());
        assert!(m.crop().is_none());
        assert_eq!(m.coverage(), Coverage::FULL);
        let b = m.bilinear(to_fx(0.0), to_fx(2.5));
        assert_eq!(b, lerp_px(m.pixel(15, 2), m.pixel(0, 2), 128));
    }

    /// Regression: a crop covering the whole panorama from column `left` (e.g.
    /// `--coverage 360x180+30+0`) used to become a plain map with the offset dropped.
    #[test]
    fn whole_crop_with_an_offset_is_turned() {
        let crop = Crop::new(16, 8, 3, 0, 16, 8).unwrap();
        let stored = partial_source(16, 8);
        let m = EnvMap::from_pixels(16, 8, &stored, Projection::Elliptical)
            .unwrap()
            .into_partial(crop)
            .unwrap();
        assert!(m.crop().is_none());
        for y in 0..8 {
            for x in 0..16 {
                // Panorama column x is stored column (x − 3) mod 16.
                let want = stored[(y * 16 + (x + 13) % 16) as usize];
                assert_eq!(m.pixel(x, y), want, "({x}, {y})");
            }
        }
        // The padding column wraps to the new column 0 (a plain 360° map).
        let b = m.bilinear(to_fx(0.0), to_fx(2.5));
        assert_eq!(b, lerp_px(m.pixel(15, 2), m.pixel(0, 2), 128));
        // The same stored image with the offset given as a full-width crop of part of
        // the rows (kept as a crop) samples the same panorama column.
        let band = Crop::new(16, 10, 3, 1, 16, 8).unwrap();
        let p = EnvMap::from_pixels(16, 8, &stored, Projection::Equirect)
            .unwrap()
            .into_partial(band)
            .unwrap();
        for x in 0..16 {
            let u = to_fx(x as f64 + 0.5);
            assert_eq!(
                p.nearest_cropped(u, to_fx(3.5)),
                m.pixel(x, 2),
                "column {x}"
            );
        }
    }

    fn partial_source(w: u32, h: u32) -> Vec<u32> {
        (0..w * h)
            .map(|i| 0x010000 * (i % w) + 0x100 * (i / w) + 7)
            .collect()
    }

    #[test]
    fn wrong_stored_size_is_an_error() {
        let m = EnvMap::from_pixels(4, 4, &[0; 16], Projection::Cylinder).unwrap();
        let e = m.into_partial(Crop::new(100, 50, 0, 0, 5, 4).unwrap());
        assert!(matches!(e, Err(CoverageError::StoredSize { .. })));
    }
}
