//! Cube map layouts and namings: how six faces are given (six files or one layout image),
//! which file goes on which face turned how, and assembling layout images for writing. The
//! files themselves are read in `io/cube.rs`.
//!
//! # Namings (orientation)
//! Which image goes on which face, and turned how, is a [`Naming`]:
//! * [`Naming::Conventions`]: every name means the face it says, and the image is that
//!   face exactly as `docs/conventions.md` defines it (the hfov-90° view at the face's
//!   yaw/pitch, up toward +Y on the sides; the up face's bottom edge meets the front's top
//!   edge). `px ... nz` in this naming are the OpenGL / RenderMan / Direct3D cube-map
//!   faces, which follow the same orientation. Default for word and axis names.
//! * [`Naming::Cube2`]: Sauerbraten / Cube 2 sky boxes (`ft rt bk lf up dn`), as in
//!   `assets/cube` of the shared samples: laid out left to right the side faces run
//!   `rt → ft → lf → bk`, and the up image sits above `rt`. Default for sky-box names.
//! * [`Naming::Irrlicht`]: Irrlicht-style sky boxes, `lf → ft → rt → bk` left to right,
//!   the up image sitting above `lf` (from its documentation; no sample file checked).
//!
//! # Layouts
//! A single image is one of (faces oriented as in [`Naming::Conventions`]):
//! * [`Layout::Cross`], 4:3: `up` above `front`; `left front right back` in the middle row;
//!   `down` below `front`.
//! * [`Layout::Strip`], 6:1: `px nx py ny pz nz` = right, left, up, down, front, back.
//! * [`Layout::Grid3x2`], 3:2: `px nx py` over `ny pz nz` = right left up / down front back.

use super::{CubeError, CubeMap, Face, UsageProblem};
use crate::named::{parse_name, unknown_name, Named};

/// How the six faces are given.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Layout {
    /// Six files (a folder or a list).
    Files,
    /// One 4:3 image, horizontal cross.
    Cross,
    /// One 6:1 image, `px nx py ny pz nz`.
    Strip,
    /// One 3:2 image, `px nx py` over `ny pz nz`.
    Grid3x2,
}

impl Layout {
    /// All layouts.
    pub const ALL: [Layout; 4] = [Layout::Files, Layout::Cross, Layout::Strip, Layout::Grid3x2];

    /// Name used on the command line (see [`crate::Named`]).
    pub fn name(self) -> &'static str {
        Named::name(self)
    }

    /// Grid of a single-image layout in face cells: (columns, rows); `None` for files.
    pub fn grid(self) -> Option<(u32, u32)> {
        match self {
            Layout::Files => None,
            Layout::Cross => Some((4, 3)),
            Layout::Strip => Some((6, 1)),
            Layout::Grid3x2 => Some((3, 2)),
        }
    }

    /// The cell (column, row) of each face, in [`Face::ALL`] order; `None` for files.
    pub fn cells(self) -> Option<[(u32, u32); 6]> {
        // Face::ALL order: front, right, back, left, up, down.
        match self {
            Layout::Files => None,
            Layout::Cross => Some([(1, 1), (2, 1), (3, 1), (0, 1), (1, 0), (1, 2)]),
            Layout::Strip => Some([(4, 0), (0, 0), (5, 0), (1, 0), (2, 0), (3, 0)]),
            Layout::Grid3x2 => Some([(1, 1), (0, 0), (2, 1), (1, 0), (2, 0), (0, 1)]),
        }
    }

    /// The single-image layout whose aspect ratio the image has, if any.
    pub fn detect(width: u32, height: u32) -> Option<Layout> {
        [Layout::Cross, Layout::Strip, Layout::Grid3x2]
            .into_iter()
            .find(|l| {
                let (c, r) = l.grid().unwrap_or((1, 1));
                width as u64 * r as u64 == height as u64 * c as u64
            })
    }
}

impl std::str::FromStr for Layout {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        parse_name(s).ok_or_else(|| unknown_name::<Layout>("layout", s))
    }
}

impl Named for Layout {
    const ALL: &'static [Self] = &Layout::ALL;
    fn name(self) -> &'static str {
        match self {
            Layout::Files => "files",
            Layout::Cross => "cross",
            Layout::Strip => "strip",
            Layout::Grid3x2 => "3x2",
        }
    }
    fn help(self) -> &'static str {
        match self {
            Layout::Files => "Six files (a folder or a list)",
            Layout::Cross => "One 4:3 image, horizontal cross",
            Layout::Strip => "One 6:1 image: px nx py ny pz nz",
            Layout::Grid3x2 => "One 3:2 image: px nx py over ny pz nz",
        }
    }
}

/// Size in pixels of a layout image for faces of side `face_size`.
pub fn layout_dimensions(layout: Layout, face_size: u32) -> Option<(u32, u32)> {
    layout.grid().map(|(c, r)| (c * face_size, r * face_size))
}

/// A turn or mirror of a square image, applied when loading: first mirror left-right (if
/// `mirror`), then turn clockwise by `quarter_turns` × 90°.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Transform {
    /// Mirror left-right first.
    pub mirror: bool,
    /// Clockwise quarter turns (0..4) after the mirror.
    pub quarter_turns: u8,
}

impl Transform {
    /// No change.
    pub const IDENTITY: Transform = Transform {
        mirror: false,
        quarter_turns: 0,
    };

    /// A turn by `quarter_turns` × 90° clockwise.
    pub const fn cw(quarter_turns: u8) -> Transform {
        Transform {
            mirror: false,
            quarter_turns,
        }
    }

    /// All eight transforms of the square.
    pub fn all() -> [Transform; 8] {
        std::array::from_fn(|i| Transform {
            mirror: i >= 4,
            quarter_turns: (i % 4) as u8,
        })
    }

    /// Apply to an `n × n` row-major image.
    pub fn apply(self, px: &[u32], n: u32) -> Vec<u32> {
        let n = n as usize;
        let mut out = vec![0u32; n * n];
        for y in 0..n {
            for x in 0..n {
                // Undo the turn, then the mirror, to find the source texel.
                let (mut sx, mut sy) = (x, y);
                for _ in 0..self.quarter_turns % 4 {
                    // one clockwise turn maps source (c, r) to (n-1-r, c); invert it
                    let (cx, cy) = (sy, n - 1 - sx);
                    sx = cx;
                    sy = cy;
                }
                if self.mirror {
                    sx = n - 1 - sx;
                }
                out[y * n + x] = px[sy * n + sx];
            }
        }
        out
    }
}

/// How named face images map onto the faces of `docs/conventions.md` (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Naming {
    /// Names mean what they say; images oriented as `docs/conventions.md` (and OpenGL).
    Conventions,
    /// Sauerbraten / Cube 2 sky boxes (`ft rt bk lf up dn`).
    Cube2,
    /// Irrlicht sky boxes.
    Irrlicht,
}

impl Naming {
    /// Name used on the command line (see [`crate::Named`]).
    pub fn name(self) -> &'static str {
        Named::name(self)
    }

    /// Where the image a file name calls `named` goes, and how it is turned.
    pub fn place(self, named: Face) -> (Face, Transform) {
        match self {
            Naming::Conventions => (named, Transform::IDENTITY),
            // Checked against the shared sample set by edge continuity (tests/cube.rs).
            Naming::Cube2 => match named {
                Face::Front => (Face::Front, Transform::IDENTITY),
                Face::Right => (Face::Left, Transform::IDENTITY),
                Face::Back => (Face::Back, Transform::IDENTITY),
                Face::Left => (Face::Right, Transform::IDENTITY),
                Face::Up => (Face::Up, Transform::cw(1)),
                Face::Down => (Face::Down, Transform::cw(3)),
            },
            // lf → ft → rt → bk with the up image above lf: sides as named, the up image's
            // bottom edge meets the left face, so it is turned a quarter clockwise (and the
            // down image, whose top edge meets the left face, a quarter counter-clockwise).
            Naming::Irrlicht => match named {
                Face::Up => (Face::Up, Transform::cw(1)),
                Face::Down => (Face::Down, Transform::cw(3)),
                f => (f, Transform::IDENTITY),
            },
        }
    }
}

impl std::str::FromStr for Naming {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        // The names, and a few aliases.
        parse_name(s)
            .or(match s {
                "plain" | "opengl" | "gl" => Some(Naming::Conventions),
                "sauerbraten" => Some(Naming::Cube2),
                _ => None,
            })
            .ok_or_else(|| unknown_name::<Naming>("naming", s))
    }
}

impl Named for Naming {
    const ALL: &'static [Self] = &[Naming::Conventions, Naming::Cube2, Naming::Irrlicht];
    fn name(self) -> &'static str {
        match self {
            Naming::Conventions => "conventions",
            Naming::Cube2 => "cube2",
            Naming::Irrlicht => "irrlicht",
        }
    }
    fn help(self) -> &'static str {
        match self {
            Naming::Conventions => "Names mean what they say, images oriented as the conventions",
            Naming::Cube2 => "Sauerbraten / Cube 2 sky boxes (ft rt bk lf up dn)",
            Naming::Irrlicht => "Irrlicht sky boxes",
        }
    }
}

impl CubeMap {
    /// Assemble a single layout image (unused cells black): `(width, height, pixels)`.
    ///
    /// # Errors
    /// [`CubeError::Usage`] for [`Layout::Files`], which is not one image.
    pub fn to_layout(&self, layout: Layout) -> Result<(u32, u32, Vec<u32>), CubeError> {
        let (Some((w, h)), Some(cells)) =
            (layout_dimensions(layout, self.face_size()), layout.cells())
        else {
            return Err(CubeError::Usage(UsageProblem::FilesIsNotOneImage));
        };
        let n = self.face_size() as usize;
        let mut out = vec![0u32; w as usize * h as usize];
        for face in Face::ALL {
            let (cx, cy) = cells[face.index()];
            let px = self.face_pixels(face);
            for y in 0..n {
                let row = (cy as usize * n + y) * w as usize + cx as usize * n;
                out[row..row + n].copy_from_slice(&px[y * n..(y + 1) * n]);
            }
        }
        Ok((w, h, out))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transforms() {
        // 2x2: a b / c d
        let px = [1, 2, 3, 4];
        assert_eq!(Transform::cw(1).apply(&px, 2), vec![3, 1, 4, 2]);
        assert_eq!(Transform::cw(2).apply(&px, 2), vec![4, 3, 2, 1]);
        assert_eq!(Transform::cw(3).apply(&px, 2), vec![2, 4, 1, 3]);
        let m = Transform {
            mirror: true,
            quarter_turns: 0,
        };
        assert_eq!(m.apply(&px, 2), vec![2, 1, 4, 3]);
        let mt = Transform {
            mirror: true,
            quarter_turns: 1,
        };
        // mirror → b a / d c, then clockwise → d b / c a
        assert_eq!(mt.apply(&px, 2), vec![4, 2, 3, 1]);
    }

    #[test]
    fn layout_detection() {
        assert_eq!(Layout::detect(400, 300), Some(Layout::Cross));
        assert_eq!(Layout::detect(600, 100), Some(Layout::Strip));
        assert_eq!(Layout::detect(300, 200), Some(Layout::Grid3x2));
        assert_eq!(Layout::detect(200, 100), None);
    }
}
