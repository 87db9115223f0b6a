//! The output frame: a pixel buffer with its size, validated once.

use crate::error::ViewError;
use crate::geom::camera::check_size;

/// An output frame: row-major 0RGB pixels, `width × height`, borrowed from the caller.
///
/// Built by [`Frame::new`], which checks the size limits and the buffer length once;
/// every renderer then takes a `&mut Frame` and checks nothing again.
#[derive(Debug)]
pub struct Frame<'a> {
    pixels: &'a mut [u32],
    width: u32,
    height: u32,
}

impl<'a> Frame<'a> {
    /// A frame over `pixels`, which must hold exactly `width × height` pixels; each side
    /// must be in `1..=`[`crate::MAX_OUTPUT_SIDE`].
    ///
    /// # Errors
    /// [`ViewError::BadSize`] for a bad size, [`ViewError::BufferSize`] for a buffer of
    /// another length.
    pub fn new(pixels: &'a mut [u32], width: u32, height: u32) -> Result<Frame<'a>, ViewError> {
        check_size(width, height)?;
        let needed = width as usize * height as usize;
        if pixels.len() != needed {
            return Err(ViewError::BufferSize {
                len: pixels.len(),
                width,
                height,
                needed,
            });
        }
        Ok(Frame {
            pixels,
            width,
            height,
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The pixels, row-major.
    pub fn pixels(&self) -> &[u32] {
        self.pixels
    }

    /// The pixels, row-major, for writing.
    pub fn pixels_mut(&mut self) -> &mut [u32] {
        self.pixels
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn size_and_length_are_checked_once() {
        let mut buf = vec![0u32; 12];
        let f = Frame::new(&mut buf, 4, 3).unwrap();
        assert_eq!((f.width(), f.height(), f.pixels().len()), (4, 3, 12));
        assert!(matches!(
            Frame::new(&mut buf, 5, 3),
            Err(ViewError::BufferSize {
                len: 12,
                needed: 15,
                ..
            })
        ));
        assert!(matches!(
            Frame::new(&mut buf, 0, 3),
            Err(ViewError::BadSize { .. })
        ));
        let mut big = vec![];
        assert!(matches!(
            Frame::new(&mut big, crate::MAX_OUTPUT_SIDE + 1, 1),
            Err(ViewError::BadSize { .. })
        ));
    }
}
