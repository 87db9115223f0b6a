//! Cube panoramas (Wei, Gao, Gong 2003, "The technique of browsing virtual world based on
//! cubic panorama"): six square faces, a per-pixel renderer and a per-scanline-segment one.
//!
//! # Geometry (`docs/conventions.md`, cube section)
//! Face `k` is exactly the view the project's camera renders with hfov 90° into a square
//! image at the face's yaw/pitch:
//!
//! | face | yaw | pitch | major axis | s (image x, right) | t (image y, up) |
//! |---|---|---|---|---|---|
//! | front | 0 | 0 | +Z | X/Z | Y/Z |
//! | right | 90 | 0 | +X | −Z/X | Y/X |
//! | back | 180 | 0 | −Z | −X/\|Z\| | Y/\|Z\| |
//! | left | −90 | 0 | −X | Z/\|X\| | Y/\|X\| |
//! | up | 0 | +90 | +Y | X/Y | −Z/Y |
//! | down | 0 | −90 | −Y | X/\|Y\| | Z/\|Y\| |
//!
//! A face of `N × N` texels is read at pixel coordinates `u = N/2 (1 + s)`,
//! `v = N/2 (1 − t)`. A ray's face is the axis of its largest absolute world coordinate;
//! ties (edges, corners) go to the first face in the order above ([`face_of`]). This is
//! also the OpenGL / RenderMan cube-map convention with `px nx py ny pz nz` =
//! right, left, up, down, front, back and image row 0 at the top.
//!
//! # Storage
//! Each face is kept as `(N + 2) × (N + 2)` 0RGB texels: the face plus a one-texel border
//! filled, once at construction, by sampling the neighbouring faces in the direction of
//! each border texel's center. Bilinear sampling then never branches and never clamps at a
//! face edge, and reads across into the neighbour, so edges and corners show no seam.
//!
//! # Renderers (`render/cube.rs`)
//! [`crate::Panorama::render`] of a [`crate::Panorama::cube`] with [`CubeRenderer::Basic`] (the paper's section 1: per pixel, ray → face →
//! face coordinates → sample) or [`CubeRenderer::Accelerated`] (section 2: each scanline is
//! a 3-D line, cut into face segments found by binary search, drawn inside each segment
//! without choosing a face). Both compute every ray with the same expression, and the
//! accelerated path *proves* each segment's face before using it (falling back to the
//! per-pixel choice where it cannot), so the faces agree; inside a segment the face
//! coordinates are evaluated exactly at every pixel in SIMD lanes, with the basic
//! renderer's arithmetic: nearest and bilinear images are byte-identical. Trilinear sampling
//! reads a face pyramid (`cube/pyramid.rs`). See `docs/cube.md`.
//!
//! Loading from files is `io/cube.rs`; layouts and namings are `cube/layout.rs`.

pub(crate) mod layout;
pub(crate) mod level;
pub(crate) mod pyramid;

use crate::error::ViewError;
use crate::geom::camera::{check_size, lat_long_to_dir, View};
use crate::geom::fixed::{to_fx, FX_BITS, FX_HALF, FX_ONE};
use crate::map::sample::{lerp_px, Sampler};
use glam::DVec3;
use layout::Layout;
use rayon::prelude::*;
use std::path::PathBuf;
use std::sync::OnceLock;

/// Largest accepted face side: six 8192² faces are 1.6 GB of 0RGB texels.
pub const MAX_FACE_SIZE: u32 = 8192;

/// One face of a cube map, in the order of `docs/conventions.md` (which is also the tie order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Face {
    /// yaw 0, pitch 0 (+Z).
    Front = 0,
    /// yaw 90, pitch 0 (+X).
    Right = 1,
    /// yaw 180, pitch 0 (−Z).
    Back = 2,
    /// yaw −90, pitch 0 (−X).
    Left = 3,
    /// yaw 0, pitch +90 (+Y).
    Up = 4,
    /// yaw 0, pitch −90 (−Y).
    Down = 5,
}

impl Face {
    /// All six faces in conventions order.
    pub const ALL: [Face; 6] = [
        Face::Front,
        Face::Right,
        Face::Back,
        Face::Left,
        Face::Up,
        Face::Down,
    ];

    /// Index in conventions order (0..6).
    #[inline]
    pub fn index(self) -> usize {
        self as usize
    }

    /// The face with index `i` (`i % 6`).
    pub fn from_index(i: usize) -> Face {
        Face::ALL[i % 6]
    }

    /// Lower-case name (`front`, `right`, ...), also the file stem `convert` writes.
    pub fn name(self) -> &'static str {
        match self {
            Face::Front => "front",
            Face::Right => "right",
            Face::Back => "back",
            Face::Left => "left",
            Face::Up => "up",
            Face::Down => "down",
        }
    }

    /// (yaw, pitch) in degrees of the hfov-90° view that this face is.
    pub fn yaw_pitch(self) -> (f64, f64) {
        match self {
            Face::Front => (0.0, 0.0),
            Face::Right => (90.0, 0.0),
            Face::Back => (180.0, 0.0),
            Face::Left => (-90.0, 0.0),
            Face::Up => (0.0, 90.0),
            Face::Down => (0.0, -90.0),
        }
    }

    /// The face's view (hfov 90°).
    pub fn view(self) -> View {
        let (y, p) = self.yaw_pitch();
        View::new(y, p, 90.0).unwrap_or_default()
    }
}

/// The face a world direction hits: the axis of its largest absolute coordinate, ties to
/// the first face in [`Face::ALL`]. (A NaN direction gives [`Face::Down`]; callers never
/// pass one.)
#[inline(always)]
pub fn face_of(d: DVec3) -> Face {
    let m = d.x.abs().max(d.y.abs()).max(d.z.abs());
    if d.z == m {
        Face::Front
    } else if d.x == m {
        Face::Right
    } else if -d.z == m {
        Face::Back
    } else if -d.x == m {
        Face::Left
    } else if d.y == m {
        Face::Up
    } else {
        Face::Down
    }
}

/// The direction expressed on a face's axes: `(a, b, m)` with `s = a/m`, `t = b/m`, and `m`
/// the (positive, for rays on that face) major coordinate. Only sign changes and
/// reordering: exact in floating point.
#[inline(always)]
pub fn face_axes(face: Face, d: DVec3) -> (f64, f64, f64) {
    match face {
        Face::Front => (d.x, d.y, d.z),
        Face::Right => (-d.z, d.y, d.x),
        Face::Back => (-d.x, d.y, -d.z),
        Face::Left => (d.z, d.y, -d.x),
        Face::Up => (d.x, -d.z, d.y),
        Face::Down => (d.x, d.z, -d.y),
    }
}

/// Face pixel coordinates `(u, v)` of direction `d` on `face`, for faces of side `2 · half`:
/// `u = half + a · (half / m)`, `v = half − b · (half / m)`. Every renderer uses exactly this
/// expression, so equal rays give equal bits.
#[inline(always)]
pub fn face_uv(face: Face, d: DVec3, half: f64) -> (f64, f64) {
    let (a, b, m) = face_axes(face, d);
    let r = half / m;
    (half + a * r, half - b * r)
}

/// World direction (not normalized) through face point `(s, t)` (each −1..1 on the face).
#[inline]
pub fn face_dir(face: Face, s: f64, t: f64) -> DVec3 {
    match face {
        Face::Front => DVec3::new(s, t, 1.0),
        Face::Right => DVec3::new(1.0, t, -s),
        Face::Back => DVec3::new(-s, t, -1.0),
        Face::Left => DVec3::new(-1.0, t, s),
        Face::Up => DVec3::new(s, 1.0, -t),
        Face::Down => DVec3::new(s, -1.0, t),
    }
}

/// A cube map could not be built or loaded. Every variant names the file (or the input)
/// and the reason.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CubeError {
    /// A file could not be read or decoded.
    #[error("{path}: cannot read image: {reason}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// A face image is not square.
    #[error("{what}: cube face is {width}x{height}, faces must be square")]
    NotSquare {
        /// The file or face.
        what: String,
        /// Width.
        width: u32,
        /// Height.
        height: u32,
    },
    /// Two faces differ in size.
    #[error("{what}: face is {size}x{size} but {first} is {first_size}x{first_size}; all six faces must be the same size")]
    UnequalSizes {
        /// The offending file or face.
        what: String,
        /// Its side.
        size: u32,
        /// The first face read.
        first: String,
        /// Its side.
        first_size: u32,
    },
    /// A face size of 0 or above [`MAX_FACE_SIZE`].
    #[error("{what}: face size {size} is not supported (1..={max})")]
    FaceSize {
        /// The file or face.
        what: String,
        /// The side.
        size: u32,
        /// The limit.
        max: u32,
    },
    /// Not exactly one file per face.
    #[error("{what}: {problem}")]
    Faces {
        /// The folder, the file or the list of inputs.
        what: String,
        /// Which faces are missing, repeated or unrecognized.
        problem: FacesProblem,
    },
    /// A single image whose size fits no layout, or the wrong layout for it.
    #[error("{path}: {problem}")]
    Layout {
        /// The file.
        path: PathBuf,
        /// Why.
        problem: LayoutProblem,
    },
    /// Inputs that do not fit the request, or an output that cannot be made.
    #[error("{0}")]
    Usage(UsageProblem),
    /// A pixel buffer does not hold `size × size` texels.
    #[error("{what}: buffer holds {len} texels, a {size}x{size} face needs {needed}")]
    Buffer {
        /// The face.
        what: String,
        /// Buffer length.
        len: usize,
        /// Face side.
        size: u32,
        /// size².
        needed: usize,
    },
}

/// Why the face files do not make a cube (see [`CubeError::Faces`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FacesProblem {
    /// A folder without face images.
    #[error(
        "no face images found (expected names ending in front/right/back/left/up/down, \
         ft/rt/bk/lf/up/dn or px/nx/py/ny/pz/nz)"
    )]
    NoFaceImages,
    /// A file whose name names no face.
    #[error(
        "the file name does not say which face it is (expected it to end in \
         front/right/back/left/up/down, ft/rt/bk/lf/up/dn or px/nx/py/ny/pz/nz)"
    )]
    UnnamedFace,
    /// Two files name the same face.
    #[error("two files for the {} face: {} and {}", face.name(), first.display(), second.display())]
    Duplicate {
        /// The face.
        face: Face,
        /// The first file.
        first: PathBuf,
        /// The second file.
        second: PathBuf,
    },
    /// Fewer than six faces.
    #[error(
        "{} face file(s) given, a cube needs six; missing: {}",
        6 - missing.len(),
        missing.iter().map(|f| f.name()).collect::<Vec<_>>().join(", ")
    )]
    Missing {
        /// The faces without a file.
        missing: Vec<Face>,
    },
}

/// Why a single image is not the layout asked for (see [`CubeError::Layout`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum LayoutProblem {
    /// Its aspect ratio is no layout's.
    #[error(
        "image is {width}x{height}; a single-image cube map must be 4:3 (cross), 6:1 (strip) or \
         3:2 (3x2); for six files give a folder or six paths"
    )]
    NoLayout {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
    },
    /// Its size is not whole square faces of the layout asked for.
    #[error(
        "image is {width}x{height}, which is not {cols}x{rows} square faces as layout {} needs",
        layout.name()
    )]
    NotFaces {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// Faces across.
        cols: u32,
        /// Faces down.
        rows: u32,
        /// The layout.
        layout: Layout,
    },
}

/// Inputs that do not fit the request (see [`CubeError::Usage`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum UsageProblem {
    /// No input at all.
    #[error("no cube map input given")]
    NoInput,
    /// A folder with a single-image layout.
    #[error("{}: is a folder, but layout {} is a single image", path.display(), layout.name())]
    FolderForSingleImage {
        /// The folder.
        path: PathBuf,
        /// The layout asked for.
        layout: Layout,
    },
    /// One file with the six-files layout.
    #[error("{}: layout files needs six face files or a folder, got one file", path.display())]
    OneFileForFiles {
        /// The file.
        path: PathBuf,
    },
    /// Several inputs with a single-image layout.
    #[error("{count} inputs given, but layout {} is a single image", layout.name())]
    ManyForSingleImage {
        /// How many inputs.
        count: usize,
        /// The layout asked for.
        layout: Layout,
    },
    /// The six-files layout asked of one image.
    #[error("layout files is six images, not one")]
    FilesIsNotOneImage,
    /// An output size that cannot be rendered.
    #[error("{0}")]
    Output(ViewError),
    /// A face that cannot be rendered.
    #[error("cannot render {} face: {error}", face.name())]
    FaceRender {
        /// The face.
        face: Face,
        /// Why.
        error: ViewError,
    },
}

/// A cube map: six equal square faces of 0RGB texels, each stored with a one-texel border
/// taken from its neighbours (see the module docs).
#[derive(Clone)]
pub struct CubeMap {
    size: u32,
    /// `(size + 2)²` texels per face, row-major, border included.
    faces: [Vec<u32>; 6],
    /// The face pyramid (levels 1, 2, ...), built on first use (`cube/pyramid.rs`).
    levels: OnceLock<Vec<CubeMap>>,
}

/// Equal faces (the pyramid, derived from them, is not compared).
impl PartialEq for CubeMap {
    fn eq(&self, other: &Self) -> bool {
        self.size == other.size && self.faces == other.faces
    }
}

impl Eq for CubeMap {}

impl std::fmt::Debug for CubeMap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CubeMap").field("size", &self.size).finish()
    }
}

/// Check a face side against `1..=MAX_FACE_SIZE`.
///
/// # Errors
/// [`CubeError::FaceSize`] naming `what`.
pub fn check_face_size(what: &str, size: u32) -> Result<(), CubeError> {
    if size == 0 || size > MAX_FACE_SIZE {
        return Err(CubeError::FaceSize {
            what: what.to_string(),
            size,
            max: MAX_FACE_SIZE,
        });
    }
    Ok(())
}

/// Clamped bilinear read of an unbordered `n × n` face at pixel coordinates (u, v): used
/// only to fill the borders.
fn bilinear_clamped(px: &[u32], n: u32, u: f64, v: f64) -> u32 {
    let n = n as i64;
    let uu = to_fx(u.clamp(0.0, n as f64)) - FX_HALF;
    let vv = to_fx(v.clamp(0.0, n as f64)) - FX_HALF;
    let x0 = uu >> FX_BITS;
    let y0 = vv >> FX_BITS;
    let fx = ((uu >> (FX_BITS - 8)) & 0xFF) as u32;
    let fy = ((vv >> (FX_BITS - 8)) & 0xFF) as u32;
    let at = |x: i64, y: i64| px[(y.clamp(0, n - 1) * n + x.clamp(0, n - 1)) as usize];
    let top = lerp_px(at(x0, y0), at(x0 + 1, y0), fx);
    let bot = lerp_px(at(x0, y0 + 1), at(x0 + 1, y0 + 1), fx);
    lerp_px(top, bot, fy)
}

impl CubeMap {
    /// Build a cube map from six `size × size` row-major 0RGB faces in [`Face::ALL`] order,
    /// each oriented as `docs/conventions.md` requires.
    ///
    /// # Errors
    /// [`CubeError::FaceSize`] or [`CubeError::Buffer`].
    pub fn from_faces(size: u32, faces: [&[u32]; 6]) -> Result<CubeMap, CubeError> {
        check_face_size("cube map", size)?;
        let n = size as usize;
        for (f, px) in Face::ALL.iter().zip(faces.iter()) {
            if px.len() != n * n {
                return Err(CubeError::Buffer {
                    what: format!("{} face", f.name()),
                    len: px.len(),
                    size,
                    needed: n * n,
                });
            }
        }
        let stride = n + 2;
        let half = size as f64 / 2.0;
        let mut out: [Vec<u32>; 6] = Default::default();
        for (k, face) in Face::ALL.iter().enumerate() {
            let mut data = vec![0u32; stride * stride];
            for y in 0..n {
                data[(y + 1) * stride + 1..(y + 1) * stride + 1 + n]
                    .copy_from_slice(&faces[k][y * n..(y + 1) * n]);
            }
            // Border texels: the neighbour's color in the direction of the texel center.
            let border = |i: i64, j: i64| {
                let s = (i as f64 + 0.5 - half) / half;
                let t = (half - (j as f64 + 0.5)) / half;
                let d = face_dir(*face, s, t);
                let g = face_of(d);
                let (u, v) = face_uv(g, d, half);
                bilinear_clamped(faces[g.index()], size, u, v)
            };
            let last = n as i64;
            for i in -1..=last {
                data[(i + 1) as usize] = border(i, -1);
                data[(n + 1) * stride + (i + 1) as usize] = border(i, last);
            }
            for j in 0..last {
                data[(j + 1) as usize * stride] = border(-1, j);
                data[(j + 1) as usize * stride + n + 1] = border(last, j);
            }
            out[k] = data;
        }
        Ok(CubeMap {
            size,
            faces: out,
            levels: OnceLock::new(),
        })
    }

    /// Face side in texels.
    pub fn face_size(&self) -> u32 {
        self.size
    }

    /// Texel (x, y) of a face, `x, y < face_size`.
    ///
    /// # Panics
    /// When (x, y) lies outside the face and its one-texel border.
    #[inline]
    pub fn pixel(&self, face: Face, x: u32, y: u32) -> u32 {
        let stride = self.size as usize + 2;
        self.faces[face.index()][(y as usize + 1) * stride + x as usize + 1]
    }

    /// A copy of one face without its border, row-major `size × size`.
    pub fn face_pixels(&self, face: Face) -> Vec<u32> {
        let n = self.size as usize;
        let stride = n + 2;
        let data = &self.faces[face.index()];
        let mut out = Vec::with_capacity(n * n);
        for y in 0..n {
            out.extend_from_slice(&data[(y + 1) * stride + 1..(y + 1) * stride + 1 + n]);
        }
        out
    }

    /// The stored face including its one-texel border, `(size + 2)²` row-major.
    pub fn bordered_face(&self, face: Face) -> &[u32] {
        &self.faces[face.index()]
    }

    /// Memory held by the texels, in bytes.
    pub fn bytes(&self) -> usize {
        self.faces.iter().map(|f| f.len() * 4).sum()
    }

    /// Sample at face pixel coordinates (u, v) (clamped to [0, size]); trilinear is
    /// bilinear here (no footprint is known: [`CubeMap::trilinear_dir`] takes one).
    #[inline(always)]
    pub fn sample_uv(&self, sampler: Sampler, face: Face, u: f64, v: f64) -> u32 {
        match sampler {
            Sampler::Nearest => self.nearest(face, u, v),
            Sampler::Bilinear | Sampler::Trilinear => self.bilinear(face, u, v),
        }
    }

    /// Sample the cube in world direction `d`.
    #[inline]
    pub fn sample_dir(&self, sampler: Sampler, d: DVec3) -> u32 {
        let face = face_of(d);
        let (u, v) = face_uv(face, d, self.size as f64 / 2.0);
        self.sample_uv(sampler, face, u, v)
    }

    /// Nearest: the texel containing (u, v), clamped into the face.
    #[inline(always)]
    pub fn nearest(&self, face: Face, u: f64, v: f64) -> u32 {
        let n = self.size as usize;
        // Clamp first (NaN → 0): then `as` truncation is floor, with no libm call.
        let x = (u.max(0.0) as usize).min(n - 1);
        let y = (v.max(0.0) as usize).min(n - 1);
        self.faces[face.index()][(y + 1) * (n + 2) + x + 1]
    }

    /// Bilinear over the four texel centers around (u − ½, v − ½), 8-bit weights, reading
    /// the border (the neighbouring faces) at the edges.
    #[inline(always)]
    pub fn bilinear(&self, face: Face, u: f64, v: f64) -> u32 {
        let n = self.size as f64;
        // In [0, n] (NaN → 0): with the +1 border offset and −½ for centers, the top-left
        // texel index is in [0, n] and its right/lower neighbour in [1, n + 1].
        // Q.16 rounded half up: the coordinates are non-negative here, so `+ ½, as` is
        // `round` without the libm call `f64::round` costs on baseline x86-64.
        let uu = (u.max(0.0).min(n) * FX_ONE as f64 + 0.5) as i64 + FX_HALF;
        let vv = (v.max(0.0).min(n) * FX_ONE as f64 + 0.5) as i64 + FX_HALF;
        let x0 = (uu >> FX_BITS) as usize;
        let y0 = (vv >> FX_BITS) as usize;
        let fx = ((uu >> (FX_BITS - 8)) & 0xFF) as u32;
        let fy = ((vv >> (FX_BITS - 8)) & 0xFF) as u32;
        let stride = self.size as usize + 2;
        let data = &self.faces[face.index()];
        let i = y0 * stride + x0;
        let row0 = &data[i..i + 2];
        let row1 = &data[i + stride..i + stride + 2];
        lerp_px(
            lerp_px(row0[0], row0[1], fx),
            lerp_px(row1[0], row1[1], fx),
            fy,
        )
    }

    /// Resample to an equirectangular `width × height` image (row-major 0RGB): each pixel
    /// center's (λ, φ) per `docs/conventions.md`, sampled in that direction.
    ///
    /// # Errors
    /// [`CubeError::Usage`] for an empty or oversized output.
    pub fn to_equirect(
        &self,
        width: u32,
        height: u32,
        sampler: Sampler,
    ) -> Result<Vec<u32>, CubeError> {
        check_size(width, height).map_err(|e| CubeError::Usage(UsageProblem::Output(e)))?;
        let (w, h) = (width as usize, height as usize);
        let mut out = vec![0u32; w * h];
        out.par_chunks_mut(w).enumerate().for_each(|(j, row)| {
            let phi =
                std::f64::consts::FRAC_PI_2 - (j as f64 + 0.5) / h as f64 * std::f64::consts::PI;
            for (i, px) in row.iter_mut().enumerate() {
                let lambda =
                    (i as f64 + 0.5) / w as f64 * std::f64::consts::TAU - std::f64::consts::PI;
                *px = self.sample_dir(sampler, lat_long_to_dir(lambda, phi));
            }
        });
        Ok(out)
    }

    /// The same faces with each border copied from the face's own edge texels (clamping)
    /// instead of the neighbours: the seam a naive cube sampler shows. For tests that must
    /// be able to detect seams.
    pub fn with_clamped_borders(&self) -> CubeMap {
        let mut c = self.clone();
        c.levels = OnceLock::new();
        let n = self.size as usize;
        let s = n + 2;
        for f in c.faces.iter_mut() {
            for y in 0..s {
                for x in 0..s {
                    let cx = x.clamp(1, n);
                    let cy = y.clamp(1, n);
                    f[y * s + x] = f[cy * s + cx];
                }
            }
        }
        c
    }

    /// Apply a transform to every face (used by tests and by namings): a new cube map
    /// whose face `k` is `faces[k]` of `self` transformed.
    pub fn map_faces(&self, f: impl Fn(Face, Vec<u32>) -> Vec<u32>) -> Result<CubeMap, CubeError> {
        let faces: [Vec<u32>; 6] =
            std::array::from_fn(|k| f(Face::ALL[k], self.face_pixels(Face::ALL[k])));
        let refs: [&[u32]; 6] = std::array::from_fn(|k| faces[k].as_slice());
        CubeMap::from_faces(self.size, refs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::camera::Camera;

    #[test]
    fn faces_are_the_conventions_camera() {
        // Face coordinates of a face camera's pixel centers are that pixel's center.
        let n = 8u32;
        for face in Face::ALL {
            let cam = Camera::new(face.view(), n, n);
            for (x, y) in [(0u32, 0u32), (7, 0), (3, 5), (7, 7), (0, 6)] {
                let d = cam.world_ray(x as f64 + 0.5, y as f64 + 0.5);
                assert_eq!(face_of(d), face, "{face:?} ({x},{y})");
                let (u, v) = face_uv(face, d, n as f64 / 2.0);
                assert!((u - (x as f64 + 0.5)).abs() < 1e-9, "{face:?} u {u}");
                assert!((v - (y as f64 + 0.5)).abs() < 1e-9, "{face:?} v {v}");
                let back = face_dir(face, (u - 4.0) / 4.0, (4.0 - v) / 4.0);
                assert!(back.normalize().dot(d.normalize()) > 1.0 - 1e-12);
            }
        }
    }

    #[test]
    fn ties_go_to_the_first_face() {
        assert_eq!(face_of(DVec3::new(1.0, 0.0, 1.0)), Face::Front);
        assert_eq!(face_of(DVec3::new(1.0, 0.0, -1.0)), Face::Right);
        assert_eq!(face_of(DVec3::new(-1.0, 0.0, -1.0)), Face::Back);
        assert_eq!(face_of(DVec3::new(-1.0, 1.0, 0.0)), Face::Left);
        assert_eq!(face_of(DVec3::new(0.0, 1.0, -1.0)), Face::Back);
        assert_eq!(face_of(DVec3::new(0.0, -1.0, 0.0)), Face::Down);
        assert_eq!(face_of(DVec3::new(1.0, 1.0, 1.0)), Face::Front);
        assert_eq!(face_of(DVec3::new(-1.0, 1.0, -1.0)), Face::Back);
    }

    #[test]
    fn border_reads_the_neighbour() {
        // Each face a flat color: the border strip takes the adjacent face's color.
        let n = 4u32;
        let faces: Vec<Vec<u32>> = (0..6).map(|k| vec![0x10 * (k + 1); 16]).collect();
        let refs: [&[u32]; 6] = std::array::from_fn(|k| faces[k].as_slice());
        let cube = CubeMap::from_faces(n, refs).unwrap();
        let front = cube.bordered_face(Face::Front);
        let stride = 6;
        assert_eq!(front[stride * 2], 0x10 * 4, "left border of front is left");
        assert_eq!(
            front[stride * 2 + 5],
            0x10 * 2,
            "right border of front is right"
        );
        assert_eq!(front[2], 0x10 * 5, "top border of front is up");
        assert_eq!(
            front[5 * stride + 2],
            0x10 * 6,
            "bottom border of front is down"
        );
        let up = cube.bordered_face(Face::Up);
        assert_eq!(up[5 * stride + 2], 0x10, "bottom border of up is front");
        assert_eq!(up[2], 0x30, "top border of up is back");
    }

    #[test]
    fn bad_buffers_error() {
        let a = vec![0u32; 16];
        let b = vec![0u32; 15];
        let refs: [&[u32]; 6] = [&a, &a, &a, &a, &a, &b];
        assert!(matches!(
            CubeMap::from_faces(4, refs),
            Err(CubeError::Buffer { .. })
        ));
        assert!(matches!(
            CubeMap::from_faces(0, [&[][..]; 6]),
            Err(CubeError::FaceSize { .. })
        ));
    }
}
