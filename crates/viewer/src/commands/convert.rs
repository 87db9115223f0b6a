//! `viewer convert INPUT... OUTPUT --to cube|equirect`: equirect → cube faces (six files in
//! a folder, or one layout image) and cube → equirect. Every file is written atomically.

use crate::args::{named, parse_size, CubeArgs, MaxPixelsArg, ProjectionOpt};
use crate::output::{check_not_input, output_kind, write_image};
use crate::panorama::load_cube;
use crate::usage;
use anyhow::{anyhow, Context, Result};
use clap::Args;
use lut_core::{CubeMap, Face};
use lut_core::{Layout, Named, Sampler};
use std::path::{Path, PathBuf};

/// What to convert to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// Six cube faces (a folder of files, or one layout image with --layout).
    Cube,
    /// One equirectangular (2:1) image.
    Equirect,
}

impl Named for Target {
    const ALL: &'static [Self] = &[Target::Cube, Target::Equirect];
    fn name(self) -> &'static str {
        match self {
            Target::Cube => "cube",
            Target::Equirect => "equirect",
        }
    }
    fn help(self) -> &'static str {
        match self {
            Target::Cube => "Six cube faces (a folder of files, or one layout image with --layout)",
            Target::Equirect => "One equirectangular (2:1) image",
        }
    }
}

/// Arguments of `viewer convert`.
#[derive(Args, Debug)]
pub struct ConvertArgs {
    /// The input(s), then the output. `--to cube`: one panorama, then a folder (layout
    /// files) or an image file (cross/strip/3x2). `--to equirect`: a cube map (a folder,
    /// six face files or one layout image), then the output image.
    #[arg(required = true, num_args = 2.., value_name = "INPUT... OUTPUT")]
    pub paths: Vec<PathBuf>,
    /// Target format.
    #[arg(long, value_parser = named::<Target>())]
    pub to: Target,
    /// Cube face side in pixels, 1 to 8192 (`--to cube`; default: input width / 4).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(lut_core::MAX_FACE_SIZE)))]
    pub face_size: Option<u32>,
    /// `--layout` (`--to cube`: the output layout, default files; `--to equirect`: the
    /// input's layout, overriding detection) and `--naming` (of the input's face files).
    #[command(flatten)]
    pub cube: CubeArgs,
    /// Output size WxH, 2:1 (`--to equirect`; default 4N x 2N for faces of side N).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// The input panorama's projection (`--to cube`).
    #[command(flatten)]
    pub projection: ProjectionOpt,
    /// Resampling filter.
    #[arg(long, default_value = "bilinear", value_parser = named::<Sampler>())]
    pub sampler: Sampler,
    /// The pixel limit for the input panorama (`--to cube`).
    #[command(flatten)]
    pub limit: MaxPixelsArg,
}

/// Run `viewer convert`.
pub fn run(a: ConvertArgs) -> Result<()> {
    let (output, inputs) = a
        .paths
        .split_last()
        .ok_or_else(|| anyhow!("convert needs INPUT... OUTPUT"))?;
    match a.to {
        Target::Cube => to_cube(&a, inputs, output),
        Target::Equirect => to_equirect(&a, inputs, output),
    }
}

fn to_cube(a: &ConvertArgs, inputs: &[PathBuf], output: &Path) -> Result<()> {
    let [input] = inputs else {
        return Err(usage!(
            "--to cube takes one input panorama, got {}",
            inputs.len()
        ));
    };
    if a.size.is_some() {
        return Err(usage!(
            "--size is for --to equirect; use --face-size for cube faces"
        ));
    }
    let layout = a.cube.layout.unwrap_or(Layout::Files);
    let projection = a.projection.value.map_only("convert --to cube")?;
    let outputs = cube_outputs(layout, output)?;
    check_not_input(&outputs, inputs)?;
    let opts = a.limit.options(projection, lut_core::Tone::default());
    let map = lut_core::load_map(input, &opts, &mut |_| {}).map_err(crate::panorama::map_error)?;
    let face_size = a.face_size.unwrap_or((map.width() / 4).max(1));
    let cube = CubeMap::from_envmap(&map, face_size, a.sampler)?;
    write_cube(&cube, layout, output)
}

/// The files `convert --to cube` writes for `layout` at `output`: six `<face>.png` in
/// the folder for [`Layout::Files`], else the one layout image (whose name must say
/// PNG or JPEG).
///
/// # Errors
/// A usage error for an image name given to the files layout, or an image name the
/// viewer cannot write.
fn cube_outputs(layout: Layout, output: &Path) -> Result<Vec<PathBuf>> {
    if layout != Layout::Files {
        output_kind(output)?;
        return Ok(vec![output.to_path_buf()]);
    }
    if output.extension().is_some() && !output.is_dir() {
        return Err(usage!(
            "{}: layout files writes six images into a folder; give a folder, or --layout cross|strip|3x2 for one image",
            output.display()
        ));
    }
    Ok(Face::ALL
        .iter()
        .map(|f| output.join(format!("{}.png", f.name())))
        .collect())
}

/// Write a cube map: six `<face>.png` files into folder `output` (created if missing) for
/// [`Layout::Files`], else one layout image (PNG or JPEG by extension). Atomic per file.
///
/// # Errors
/// As `cube_outputs`, or a file that cannot be written.
pub fn write_cube(cube: &CubeMap, layout: Layout, output: &Path) -> Result<()> {
    let n = cube.face_size();
    let outputs = cube_outputs(layout, output)?;
    if layout == Layout::Files {
        std::fs::create_dir_all(output)
            .with_context(|| format!("{}: cannot create folder", output.display()))?;
        for (face, path) in Face::ALL.into_iter().zip(&outputs) {
            write_image(path, &cube.face_pixels(face), n, n)?;
        }
        return Ok(());
    }
    let (w, h, px) = cube.to_layout(layout)?;
    write_image(output, &px, w, h)
}

fn to_equirect(a: &ConvertArgs, inputs: &[PathBuf], output: &Path) -> Result<()> {
    if a.face_size.is_some() {
        return Err(usage!(
            "--face-size is for --to cube; use --size WxH for the equirect"
        ));
    }
    if let Some((w, h)) = a.size {
        if w != 2 * h {
            return Err(usage!(
                "--size {w}x{h}: an equirectangular image is 2:1 (e.g. {}x{h} or {w}x{})",
                2 * h,
                (w / 2).max(1)
            ));
        }
    }
    output_kind(output)?;
    check_not_input(&[output.to_path_buf()], inputs)?;
    let cube = load_cube(inputs, a.cube)?;
    let n = cube.face_size();
    let (w, h) = a.size.unwrap_or((4 * n, 2 * n));
    let px = cube.to_equirect(w, h, a.sampler)?;
    write_image(output, &px, w, h)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_cube() -> CubeMap {
        let n = 8u32;
        let faces: Vec<Vec<u32>> = (0..6u32)
            .map(|k| {
                (0..n * n)
                    .map(|i| ((k * 40) << 16) | ((i * 3) << 8) | ((i % n) * 20))
                    .collect()
            })
            .collect();
        let refs: [&[u32]; 6] = std::array::from_fn(|k| faces[k].as_slice());
        CubeMap::from_faces(n, refs).unwrap()
    }

    #[test]
    fn written_cubes_load_back_identically() {
        let tmp = tempfile::tempdir().unwrap();
        let cube = sample_cube();
        let dir = tmp.path().join("faces");
        write_cube(&cube, Layout::Files, &dir).unwrap();
        let back = load_cube(std::slice::from_ref(&dir), CubeArgs::default()).unwrap();
        assert!(back == cube, "files");
        for (layout, name) in [
            (Layout::Cross, "c.png"),
            (Layout::Strip, "s.png"),
            (Layout::Grid3x2, "g.png"),
        ] {
            let path = tmp.path().join(name);
            write_cube(&cube, layout, &path).unwrap();
            let back = load_cube(std::slice::from_ref(&path), CubeArgs::default()).unwrap();
            assert!(back == cube, "{name}");
        }
    }

    #[test]
    fn failed_writes_leave_nothing() {
        let tmp = tempfile::tempdir().unwrap();
        let cube = sample_cube();
        let out = tmp.path().join("missing/c.png");
        assert!(write_cube(&cube, Layout::Cross, &out).is_err());
        assert!(!out.exists());
        let bad = tmp.path().join("c.bmp");
        let e = write_cube(&cube, Layout::Cross, &bad).unwrap_err();
        assert_eq!(crate::exit::code(&e), 2, "{e:#}");
        assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 0);
        // layout files into something named like an image is refused, not a folder made
        let img = tmp.path().join("faces.png");
        let e = write_cube(&cube, Layout::Files, &img).unwrap_err();
        assert_eq!(crate::exit::code(&e), 2, "{e:#}");
        assert!(!img.exists());
    }
}
