//! Loading cube maps: six face files (a folder or a list) or one layout image, and
//! assembling layout images for writing.
//!
//! # Face file names
//! The last word of the file stem (split at anything not a letter or digit, so
//! `skyfantasy_ft.jpg` → `ft`) names the face:
//!
//! | word | means |
//! |---|---|
//! | `front right back left up down` (also `top bottom`) | that face |
//! | `ft rt bk lf up dn` (sky-box names) | front right back left up down *as named* |
//! | `px nx py ny pz nz` (also `posx negx ...`) | right left up down front back |
//!
//! # Namings (orientation)
//! Which image goes on which face, and turned how, is a [`Naming`]:
//! * [`Naming::Conventions`]: every name means the face it says, and the image is that
//!   face exactly as `conventions.md` defines it (the hfov-90° view at the face's
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

use super::{check_face_size, CubeError, CubeMap, Face, MAX_FACE_SIZE};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

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

    /// Name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Layout::Files => "files",
            Layout::Cross => "cross",
            Layout::Strip => "strip",
            Layout::Grid3x2 => "3x2",
        }
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
        match s {
            "files" => Ok(Layout::Files),
            "cross" => Ok(Layout::Cross),
            "strip" => Ok(Layout::Strip),
            "3x2" => Ok(Layout::Grid3x2),
            o => Err(format!(
                "unknown layout '{o}' (expected files, cross, strip or 3x2)"
            )),
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

/// How named face images map onto the faces of `conventions.md` (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Naming {
    /// Names mean what they say; images oriented as `conventions.md` (and OpenGL).
    Conventions,
    /// Sauerbraten / Cube 2 sky boxes (`ft rt bk lf up dn`).
    Cube2,
    /// Irrlicht sky boxes.
    Irrlicht,
}

impl Naming {
    /// Name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Naming::Conventions => "conventions",
            Naming::Cube2 => "cube2",
            Naming::Irrlicht => "irrlicht",
        }
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
        match s {
            "conventions" | "plain" | "opengl" | "gl" => Ok(Naming::Conventions),
            "cube2" | "sauerbraten" => Ok(Naming::Cube2),
            "irrlicht" => Ok(Naming::Irrlicht),
            o => Err(format!(
                "unknown naming '{o}' (expected conventions, cube2 or irrlicht)"
            )),
        }
    }
}

/// What kind of name a face file has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum NameKind {
    Word,
    SkyBox,
    Axis,
}

/// The face a file's name gives (the last word of its stem) and the kind of name.
fn classify(path: &Path) -> Option<(Face, NameKind)> {
    let stem = path.file_stem()?.to_str()?.to_ascii_lowercase();
    let word = stem.rsplit(|c: char| !c.is_ascii_alphanumeric()).next()?;
    use NameKind::*;
    Some(match word {
        "front" => (Face::Front, Word),
        "right" => (Face::Right, Word),
        "back" => (Face::Back, Word),
        "left" => (Face::Left, Word),
        "up" | "top" => (Face::Up, Word),
        "down" | "bottom" => (Face::Down, Word),
        "ft" => (Face::Front, SkyBox),
        "rt" => (Face::Right, SkyBox),
        "bk" => (Face::Back, SkyBox),
        "lf" => (Face::Left, SkyBox),
        "dn" => (Face::Down, SkyBox),
        "px" | "posx" => (Face::Right, Axis),
        "nx" | "negx" => (Face::Left, Axis),
        "py" | "posy" => (Face::Up, Axis),
        "ny" | "negy" => (Face::Down, Axis),
        "pz" | "posz" => (Face::Front, Axis),
        "nz" | "negz" => (Face::Back, Axis),
        _ => return None,
    })
}

const IMAGE_EXTENSIONS: &[&str] = &[
    "jpg", "jpeg", "png", "bmp", "tga", "tif", "tiff", "webp", "exr", "hdr", "gif", "ppm", "pnm",
    "qoi",
];

fn is_image(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .map(|e| IMAGE_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
        .unwrap_or(false)
}

/// A decoded image: width, height, 0RGB pixels.
type Decoded = (u32, u32, Vec<u32>);

/// Decode an image file to 0RGB, checking its size from the header first.
fn read_image(
    path: &Path,
    check: impl Fn(u32, u32) -> Result<(), CubeError>,
) -> Result<Decoded, CubeError> {
    let err = |reason: String| CubeError::Read {
        path: path.to_path_buf(),
        reason,
    };
    let reader = image::ImageReader::open(path)
        .map_err(|e| err(e.to_string()))?
        .with_guessed_format()
        .map_err(|e| err(e.to_string()))?;
    if reader.format().is_none() {
        return Err(err("unrecognized or unsupported image format".into()));
    }
    let (w, h) = reader.into_dimensions().map_err(|e| err(e.to_string()))?;
    check(w, h)?;
    let mut reader = image::ImageReader::open(path)
        .map_err(|e| err(e.to_string()))?
        .with_guessed_format()
        .map_err(|e| err(e.to_string()))?;
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(6 * (MAX_FACE_SIZE as u64).pow(2) * 16);
    reader.limits(limits);
    let img = reader.decode().map_err(|e| err(e.to_string()))?;
    let rgb = img.to_rgb8();
    let px = rgb
        .pixels()
        .map(|p| (p[0] as u32) << 16 | (p[1] as u32) << 8 | p[2] as u32)
        .collect();
    Ok((w, h, px))
}

/// Load a cube map from `inputs`: one folder (six face files in it), six face files, or
/// one layout image. `layout` overrides the detection (`None` = from the inputs and the
/// image's aspect ratio); `naming` overrides the orientation the file names imply.
///
/// # Errors
/// [`CubeError`] naming the file or folder and the reason: unreadable or undecodable
/// files, faces missing, repeated or unrecognized, non-square or unequal faces, an image
/// that fits no layout, or a layout that does not fit the inputs.
pub fn load_cube(
    inputs: &[PathBuf],
    layout: Option<Layout>,
    naming: Option<Naming>,
) -> Result<CubeMap, CubeError> {
    match inputs {
        [] => Err(CubeError::Usage("no cube map input given".into())),
        [one] if one.is_dir() => {
            if let Some(l) = layout.filter(|l| *l != Layout::Files) {
                return Err(CubeError::Usage(format!(
                    "{}: is a folder, but layout {} is a single image",
                    one.display(),
                    l.name()
                )));
            }
            let entries = std::fs::read_dir(one).map_err(|e| CubeError::Read {
                path: one.clone(),
                reason: e.to_string(),
            })?;
            let mut files = Vec::new();
            for entry in entries {
                let entry = entry.map_err(|e| CubeError::Read {
                    path: one.clone(),
                    reason: e.to_string(),
                })?;
                let p = entry.path();
                if p.is_file() && is_image(&p) && classify(&p).is_some() {
                    files.push(p);
                }
            }
            files.sort();
            if files.is_empty() {
                return Err(CubeError::Faces {
                    what: one.display().to_string(),
                    reason: "no face images found (expected names ending in front/right/back/left/up/down, \
                             ft/rt/bk/lf/up/dn or px/nx/py/ny/pz/nz)"
                        .into(),
                });
            }
            load_face_files(&one.display().to_string(), &files, naming)
        }
        [one] => match layout {
            Some(Layout::Files) => Err(CubeError::Usage(format!(
                "{}: layout files needs six face files or a folder, got one file",
                one.display()
            ))),
            l => load_layout_image(one, l),
        },
        many => {
            if let Some(l) = layout.filter(|l| *l != Layout::Files) {
                return Err(CubeError::Usage(format!(
                    "{} inputs given, but layout {} is a single image",
                    many.len(),
                    l.name()
                )));
            }
            load_face_files("face list", many, naming)
        }
    }
}

/// Load six face files whose names say which face each is (see the module docs).
/// `what` names the folder or list in errors.
///
/// # Errors
/// As [`load_cube`].
pub fn load_face_files(
    what: &str,
    files: &[PathBuf],
    naming: Option<Naming>,
) -> Result<CubeMap, CubeError> {
    let mut slots: [Option<(&PathBuf, NameKind)>; 6] = [None; 6];
    for f in files {
        let Some((face, kind)) = classify(f) else {
            return Err(CubeError::Faces {
                what: f.display().to_string(),
                reason: "the file name does not say which face it is (expected it to end in \
                         front/right/back/left/up/down, ft/rt/bk/lf/up/dn or px/nx/py/ny/pz/nz)"
                    .into(),
            });
        };
        if let Some((prev, _)) = slots[face.index()] {
            return Err(CubeError::Faces {
                what: what.into(),
                reason: format!(
                    "two files for the {} face: {} and {}",
                    face.name(),
                    prev.display(),
                    f.display()
                ),
            });
        }
        slots[face.index()] = Some((f, kind));
    }
    let missing: Vec<&str> = Face::ALL
        .iter()
        .filter(|f| slots[f.index()].is_none())
        .map(|f| f.name())
        .collect();
    if !missing.is_empty() {
        return Err(CubeError::Faces {
            what: what.into(),
            reason: format!(
                "{} face file(s) given, a cube needs six; missing: {}",
                6 - missing.len(),
                missing.join(", ")
            ),
        });
    }
    let sky = slots.iter().flatten().any(|(_, k)| *k == NameKind::SkyBox);
    let naming = naming.unwrap_or(if sky {
        Naming::Cube2
    } else {
        Naming::Conventions
    });

    let check_square = |path: &Path| {
        let path = path.to_path_buf();
        move |w: u32, h: u32| {
            if w != h {
                return Err(CubeError::NotSquare {
                    what: path.display().to_string(),
                    width: w,
                    height: h,
                });
            }
            check_face_size(&path.display().to_string(), w)
        }
    };
    let decoded: Vec<Result<Decoded, CubeError>> = slots
        .par_iter()
        .map(|s| {
            let (p, _) = s.expect("all six checked above");
            read_image(p, check_square(p))
        })
        .collect();
    let mut faces: [Vec<u32>; 6] = Default::default();
    let mut first: Option<(&PathBuf, u32)> = None;
    for (k, r) in decoded.into_iter().enumerate() {
        let (w, _, px) = r?;
        let path = slots[k].map(|(p, _)| p).expect("present");
        match first {
            None => first = Some((path, w)),
            Some((fp, fs)) if fs != w => {
                return Err(CubeError::UnequalSizes {
                    what: path.display().to_string(),
                    size: w,
                    first: fp.display().to_string(),
                    first_size: fs,
                })
            }
            _ => {}
        }
        let (face, t) = naming.place(Face::ALL[k]);
        faces[face.index()] = t.apply(&px, w);
    }
    let size = first.map(|(_, s)| s).unwrap_or(0);
    let refs: [&[u32]; 6] = std::array::from_fn(|k| faces[k].as_slice());
    CubeMap::from_faces(size, refs)
}

/// Load one layout image (`layout` `None` = detect from the aspect ratio).
///
/// # Errors
/// [`CubeError::Read`] for an unreadable file, [`CubeError::Layout`] when the image's
/// size fits no layout (or not the one asked for).
pub fn load_layout_image(path: &Path, layout: Option<Layout>) -> Result<CubeMap, CubeError> {
    let chosen = std::cell::Cell::new(None);
    let check = |w: u32, h: u32| {
        let l = match layout {
            Some(l) => l,
            None => Layout::detect(w, h).ok_or_else(|| CubeError::Layout {
                path: path.to_path_buf(),
                reason: format!(
                    "image is {w}x{h}; a single-image cube map must be 4:3 (cross), 6:1 (strip) or \
                     3:2 (3x2); for six files give a folder or six paths"
                ),
            })?,
        };
        let (c, r) = l.grid().unwrap_or((1, 1));
        if !w.is_multiple_of(c) || !h.is_multiple_of(r) || w / c != h / r {
            return Err(CubeError::Layout {
                path: path.to_path_buf(),
                reason: format!(
                    "image is {w}x{h}, which is not {c}x{r} square faces as layout {} needs",
                    l.name()
                ),
            });
        }
        check_face_size(&path.display().to_string(), w / c)?;
        chosen.set(Some(l));
        Ok(())
    };
    let (w, _, px) = read_image(path, check)?;
    let layout = chosen.get().unwrap_or(Layout::Cross);
    let (c, _) = layout.grid().unwrap_or((1, 1));
    let n = w / c;
    let cells = layout.cells().unwrap_or([(0, 0); 6]);
    let faces: [Vec<u32>; 6] = std::array::from_fn(|k| {
        let (cx, cy) = cells[k];
        let mut f = Vec::with_capacity((n * n) as usize);
        for y in 0..n {
            let row = ((cy * n + y) * w + cx * n) as usize;
            f.extend_from_slice(&px[row..row + n as usize]);
        }
        f
    });
    let refs: [&[u32]; 6] = std::array::from_fn(|k| faces[k].as_slice());
    CubeMap::from_faces(n, refs)
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
            return Err(CubeError::Usage(
                "layout files is six images, not one".into(),
            ));
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
    fn names() {
        let c = |s: &str| classify(Path::new(s)).map(|(f, _)| f);
        assert_eq!(c("a/skyfantasy_ft.jpg"), Some(Face::Front));
        assert_eq!(c("x-nz.png"), Some(Face::Back));
        assert_eq!(c("posx.png"), Some(Face::Right));
        assert_eq!(c("Sky.Top.PNG"), Some(Face::Up));
        assert_eq!(c("left.png"), Some(Face::Left));
        assert_eq!(c("leftover.png"), None);
    }

    #[test]
    fn layout_detection() {
        assert_eq!(Layout::detect(400, 300), Some(Layout::Cross));
        assert_eq!(Layout::detect(600, 100), Some(Layout::Strip));
        assert_eq!(Layout::detect(300, 200), Some(Layout::Grid3x2));
        assert_eq!(Layout::detect(200, 100), None);
    }
}
