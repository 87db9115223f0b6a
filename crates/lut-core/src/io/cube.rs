//! Reading cube maps from files: six face files (a folder or a list) or one layout image
//! (see `cube/layout.rs` for the face names, namings and layouts).
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

use crate::cube::layout::{Layout, Naming};
use crate::cube::{
    check_face_size, CubeError, CubeMap, Face, FacesProblem, LayoutProblem, UsageProblem,
    MAX_FACE_SIZE,
};
use crate::error::MapError;
use crate::geom::projection::Projection;
use crate::io::load::{decode_reader, LoadOptions};
use crate::map::tone::Tone;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

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

/// The pixel limit for cube images: a layout image of six faces of the largest size.
const CUBE_MAX_PIXELS: u64 = 6 * (MAX_FACE_SIZE as u64) * (MAX_FACE_SIZE as u64);

/// Decode an image file to 0RGB, checking its size from the header first.
fn read_image(
    path: &Path,
    check: impl Fn(u32, u32) -> Result<(), CubeError>,
) -> Result<Decoded, CubeError> {
    let err = |reason: String| CubeError::Read {
        path: path.to_path_buf(),
        reason,
    };
    let file = crate::file::open_regular(path).map_err(|e| err(e.to_string()))?;
    let len = file.metadata().map_err(|e| err(e.to_string()))?.len();
    decode_image(
        std::io::BufReader::new(file),
        len,
        &path.display().to_string(),
        CUBE_MAX_PIXELS,
        check,
    )
}

/// Decode an image from `src` (`len` bytes) to 0RGB with the map loader (the same
/// decoders, checks and tone as a panorama), after `check` has accepted the size its
/// header gives; `check` sees the decoded size again.
fn decode_image<R: std::io::BufRead + std::io::Seek>(
    mut src: R,
    len: u64,
    what: &str,
    max_pixels: u64,
    check: impl Fn(u32, u32) -> Result<(), CubeError>,
) -> Result<Decoded, CubeError> {
    let err = |reason: String| CubeError::Read {
        path: what.into(),
        reason,
    };
    if let Ok(size) = imagesize::reader_size(&mut src) {
        let side = |v: usize| u32::try_from(v).unwrap_or(u32::MAX);
        check(side(size.width), side(size.height))?;
    }
    src.seek(std::io::SeekFrom::Start(0))
        .map_err(|e| err(e.to_string()))?;
    let opts = LoadOptions {
        // Any aspect ratio; the padding is dropped below.
        projection: Some(Projection::Elliptical),
        tone: Tone::default(),
        max_pixels,
    };
    let map = decode_reader(src, len, what, &opts, &mut |_| {}).map_err(|e| match e {
        MapError::Decode { reason, .. } => err(reason),
        other => err(other.to_string()),
    })?;
    let (w, h) = (map.width(), map.height());
    check(w, h)?;
    let (padded, stride) = map.padded();
    let mut px = Vec::with_capacity(w as usize * h as usize);
    for row in padded.chunks_exact(stride).take(h as usize) {
        px.extend_from_slice(&row[..w as usize]);
    }
    Ok((w, h, px))
}

/// The face files of a cube folder: its images whose names say which face they are
/// (see the module docs), sorted. A face-named entry that cannot be read (a broken
/// symbolic link or a link loop, no permission) or is not a regular file is an error
/// naming it, never taken for a missing face.
///
/// # Errors
/// [`CubeError::Read`] for the folder or such an entry, [`CubeError::Faces`] when no
/// file is named like a face.
pub fn cube_face_files(dir: &Path) -> Result<Vec<PathBuf>, CubeError> {
    let read_err = |path: &Path, reason: String| CubeError::Read {
        path: path.to_path_buf(),
        reason,
    };
    let entries = std::fs::read_dir(dir).map_err(|e| read_err(dir, e.to_string()))?;
    let mut files = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|e| read_err(dir, e.to_string()))?;
        let p = entry.path();
        if !is_image(&p) || classify(&p).is_none() {
            continue;
        }
        match std::fs::metadata(&p) {
            Ok(m) => match crate::file::special_kind(&m) {
                None => files.push(p),
                Some(kind) => {
                    return Err(read_err(
                        &p,
                        format!("not a regular file ({kind}); only regular files are read"),
                    ))
                }
            },
            Err(e) => {
                let link = std::fs::symlink_metadata(&p).is_ok_and(|m| m.file_type().is_symlink());
                let reason = match (link, e.kind()) {
                    (true, std::io::ErrorKind::NotFound) => format!(
                        "a symbolic link to a missing file ({})",
                        std::fs::read_link(&p)
                            .map_or_else(|_| "?".into(), |t| t.display().to_string())
                    ),
                    _ => e.to_string(),
                };
                return Err(read_err(&p, reason));
            }
        }
    }
    files.sort();
    if files.is_empty() {
        return Err(CubeError::Faces {
            what: dir.display().to_string(),
            problem: FacesProblem::NoFaceImages,
        });
    }
    Ok(files)
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
        [] => Err(CubeError::Usage(UsageProblem::NoInput)),
        [one] if one.is_dir() => {
            if let Some(l) = layout.filter(|l| *l != Layout::Files) {
                return Err(CubeError::Usage(UsageProblem::FolderForSingleImage {
                    path: one.clone(),
                    layout: l,
                }));
            }
            let files = cube_face_files(one)?;
            load_face_files(&one.display().to_string(), &files, naming)
        }
        [one] => match layout {
            Some(Layout::Files) => Err(CubeError::Usage(UsageProblem::OneFileForFiles {
                path: one.clone(),
            })),
            l => load_layout_image(one, l),
        },
        many => {
            if let Some(l) = layout.filter(|l| *l != Layout::Files) {
                return Err(CubeError::Usage(UsageProblem::ManyForSingleImage {
                    count: many.len(),
                    layout: l,
                }));
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
                problem: FacesProblem::UnnamedFace,
            });
        };
        if let Some((prev, _)) = slots[face.index()] {
            return Err(CubeError::Faces {
                what: what.into(),
                problem: FacesProblem::Duplicate {
                    face,
                    first: prev.to_path_buf(),
                    second: f.to_path_buf(),
                },
            });
        }
        slots[face.index()] = Some((f, kind));
    }
    let missing: Vec<Face> = Face::ALL
        .into_iter()
        .filter(|f| slots[f.index()].is_none())
        .collect();
    if !missing.is_empty() {
        return Err(CubeError::Faces {
            what: what.into(),
            problem: FacesProblem::Missing { missing },
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
    // Every slot is filled (a missing face was reported above): the six paths in face
    // order.
    let paths: Vec<&PathBuf> = slots.iter().flatten().map(|(p, _)| *p).collect();
    let decoded: Vec<Result<Decoded, CubeError>> = paths
        .par_iter()
        .map(|p| read_image(p, check_square(p)))
        .collect();
    let mut faces: [Vec<u32>; 6] = Default::default();
    let mut first: Option<(&PathBuf, u32)> = None;
    for (k, (r, path)) in decoded.into_iter().zip(paths.iter().copied()).enumerate() {
        let (w, _, px) = r?;
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
    layout_image(path, layout, |check| read_image(path, check))
}

/// As [`load_layout_image`] for an encoded image in memory (`what` names it in errors),
/// with a pixel limit for the whole image (`load_layout_image` allows six faces of
/// [`MAX_FACE_SIZE`]).
///
/// # Errors
/// As [`load_layout_image`].
pub fn decode_layout_image(
    bytes: &[u8],
    what: &str,
    layout: Option<Layout>,
    max_pixels: u64,
) -> Result<CubeMap, CubeError> {
    let cursor = std::io::Cursor::new(bytes);
    layout_image(Path::new(what), layout, |check| {
        decode_image(cursor, bytes.len() as u64, what, max_pixels, check)
    })
}

/// A cube map from one layout image read by `read` (which runs the size check it is
/// given before decoding).
fn layout_image(
    path: &Path,
    layout: Option<Layout>,
    read: impl FnOnce(&dyn Fn(u32, u32) -> Result<(), CubeError>) -> Result<Decoded, CubeError>,
) -> Result<CubeMap, CubeError> {
    if layout == Some(Layout::Files) {
        return Err(CubeError::Usage(UsageProblem::OneFileForFiles {
            path: path.to_path_buf(),
        }));
    }
    let chosen = std::cell::Cell::new(None);
    let check = |w: u32, h: u32| {
        let l = match layout {
            Some(l) => l,
            None => Layout::detect(w, h).ok_or_else(|| CubeError::Layout {
                path: path.to_path_buf(),
                problem: LayoutProblem::NoLayout {
                    width: w,
                    height: h,
                },
            })?,
        };
        let (c, r) = l.grid().unwrap_or((1, 1));
        if !w.is_multiple_of(c) || !h.is_multiple_of(r) || w / c != h / r {
            return Err(CubeError::Layout {
                path: path.to_path_buf(),
                problem: LayoutProblem::NotFaces {
                    width: w,
                    height: h,
                    cols: c,
                    rows: r,
                    layout: l,
                },
            });
        }
        check_face_size(&path.display().to_string(), w / c)?;
        chosen.set(Some(l));
        Ok(())
    };
    let (w, _, px) = read(&check)?;
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
