//! How to read a panorama: `--projection` (one declaration for render, convert, bench and
//! the window), the cube map's `--layout` and `--naming` (render, convert and the window),
//! and the options `viewer render` and the window share.

use super::named::{named, named_or_parse};
use anyhow::Result;
use clap::Args;
use lut_core::{name_list, parse_name, Coverage, CubeRenderer, Layout, Named, Naming, Projection};
use std::path::PathBuf;
use std::str::FromStr;

/// The `--projection` choice: auto, one of the map projections, or a cube map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProjectionArg {
    /// 2:1 images are equirectangular; a folder or several files are a cube map.
    Auto,
    /// A map on a surface of revolution.
    Map(Projection),
    /// A cube map (six faces or one layout image).
    Cube,
}

/// auto, every map projection in its order, cube.
const PROJECTION_ARGS: [ProjectionArg; Projection::ALL.len() + 2] = {
    let mut all = [ProjectionArg::Auto; Projection::ALL.len() + 2];
    let mut i = 0;
    while i < Projection::ALL.len() {
        all[i + 1] = ProjectionArg::Map(Projection::ALL[i]);
        i += 1;
    }
    all[i + 1] = ProjectionArg::Cube;
    all
};

impl Named for ProjectionArg {
    const ALL: &'static [Self] = &PROJECTION_ARGS;
    fn name(self) -> &'static str {
        match self {
            ProjectionArg::Auto => "auto",
            ProjectionArg::Map(p) => p.name(),
            ProjectionArg::Cube => "cube",
        }
    }
    fn help(self) -> &'static str {
        match self {
            ProjectionArg::Auto => {
                "2:1 images are equirectangular; a folder or several files are a cube map"
            }
            ProjectionArg::Map(p) => Named::help(p),
            ProjectionArg::Cube => "A cube map: a folder, six face files, or one layout image",
        }
    }
}

/// The names, and a map projection's aliases (any case, `equirectangular`, …).
impl FromStr for ProjectionArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        parse_name(s)
            .or_else(|| s.parse().ok().map(ProjectionArg::Map))
            .ok_or_else(|| {
                format!(
                    "unknown projection '{s}' (expected {})",
                    name_list::<ProjectionArg>()
                )
            })
    }
}

impl ProjectionArg {
    /// True when `inputs` are read as a cube map: `cube`, or `auto` with a folder or
    /// several files.
    pub fn reads_cube(self, inputs: &[PathBuf]) -> bool {
        match self {
            ProjectionArg::Cube => true,
            ProjectionArg::Map(_) => false,
            ProjectionArg::Auto => inputs.len() > 1 || inputs.iter().any(|p| p.is_dir()),
        }
    }

    /// The map projection given, `None` for auto (detected) or cube.
    pub fn map(self) -> Option<Projection> {
        match self {
            ProjectionArg::Map(p) => Some(p),
            ProjectionArg::Auto | ProjectionArg::Cube => None,
        }
    }

    /// The map projection for a command that reads one map panorama (`None`: detected).
    ///
    /// # Errors
    /// `cube`, which `what` does not read.
    pub fn map_only(self, what: &str) -> Result<Option<Projection>> {
        if self == ProjectionArg::Cube {
            return Err(crate::usage!(
                "--projection cube: {what} reads a map panorama, not a cube map"
            ));
        }
        Ok(self.map())
    }
}

/// `--projection`, flattened into every command that reads a panorama.
#[derive(Args, Debug, Clone, Copy, PartialEq, Eq)]
pub struct ProjectionOpt {
    /// How the panorama maps the sphere. auto: 2:1 images are equirect and, where a cube map
    /// can be read, a folder or several files are one (bench's generated map: equirect).
    #[arg(
        id = "projection",
        long = "projection",
        value_name = "NAME",
        default_value = "auto",
        value_parser = named_or_parse::<ProjectionArg>()
    )]
    pub value: ProjectionArg,
}

/// A cube map's `--layout` and `--naming`, flattened into render, convert and the window.
#[derive(Args, Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CubeArgs {
    /// Cube map layout. Reading a cube: detected when omitted; `convert --to cube`: the
    /// layout written (default files).
    #[arg(long, value_parser = named::<Layout>())]
    pub layout: Option<Layout>,
    /// Cube face naming/orientation (default from the file names: cube2 for
    /// ft/rt/bk/lf/up/dn, conventions otherwise; see docs/cube.md).
    #[arg(long, value_parser = named_or_parse::<Naming>())]
    pub naming: Option<Naming>,
}

/// How to read a panorama: the options `viewer render` and the window share.
#[derive(Args, Debug, Clone)]
pub struct InputArgs {
    /// `--projection`.
    #[command(flatten)]
    pub projection: ProjectionOpt,
    /// `--layout`, `--naming`.
    #[command(flatten)]
    pub cube: CubeArgs,
    /// Cube renderer (per pixel, or per scanline with face segments).
    #[arg(long, default_value = "scanline", value_parser = named::<CubeRenderer>())]
    pub cube_renderer: CubeRenderer,
    /// The area the image covers, for partial panoramas: HFOVxVFOV[±YAW±PITCH] in
    /// degrees (e.g. 120x60+30-10: 120 x 60 centred on yaw 30, pitch -10). Overrides
    /// GPano XMP metadata in the file. Equirectangular images only (in the window: the
    /// panorama named on the command line only).
    #[arg(long, value_name = "HFOVxVFOV[±YAW±PITCH]", value_parser = parse_coverage, allow_hyphen_values = true)]
    pub coverage: Option<Coverage>,
}

/// Parse `--coverage HFOVxVFOV[±YAW±PITCH]` (see `lut_core::Coverage`).
pub fn parse_coverage(s: &str) -> Result<Coverage, String> {
    s.parse::<Coverage>().map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_values_are_auto_the_maps_and_cube() {
        let names: Vec<&str> = ProjectionArg::ALL.iter().map(|p| p.name()).collect();
        assert_eq!(
            names,
            [
                "auto",
                "equirect",
                "cylinder",
                "sine",
                "elliptical",
                "diamond",
                "cube"
            ]
        );
        assert_eq!("cube".parse(), Ok(ProjectionArg::Cube));
        assert_eq!(
            "Equirectangular".parse(),
            Ok(ProjectionArg::Map(Projection::Equirect))
        );
        let e = "mercator".parse::<ProjectionArg>().unwrap_err();
        assert!(e.contains("mercator") && e.contains("or cube"), "{e}");
        assert!(ProjectionArg::Cube.map_only("bench").is_err());
        assert_eq!(ProjectionArg::Auto.map_only("bench").unwrap(), None);
    }

    #[test]
    fn cube_is_read_from_folders_and_several_files() {
        let dir = std::env::temp_dir();
        let files = [PathBuf::from("a.jpg"), PathBuf::from("b.jpg")];
        assert!(ProjectionArg::Auto.reads_cube(std::slice::from_ref(&dir)));
        assert!(ProjectionArg::Auto.reads_cube(&files));
        assert!(!ProjectionArg::Auto.reads_cube(&files[..1]));
        assert!(!ProjectionArg::Auto.reads_cube(&[]));
        assert!(ProjectionArg::Cube.reads_cube(&files[..1]));
        assert!(!ProjectionArg::Map(Projection::Sine).reads_cube(&files));
    }

    #[test]
    fn coverage_flag_errors_name_the_text() {
        assert!(parse_coverage("120x60+30-10").is_ok());
        let e = parse_coverage("120x60+30").unwrap_err();
        assert!(e.contains("120x60+30"), "{e}");
    }
}
