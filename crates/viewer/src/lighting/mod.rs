//! Luminaires lighting a rendered room panorama: the options `viewer render`, `viewer
//! lux` and the window share, the light state ([`LightsState`]) they become, which the
//! window's panel edits, and scene files ([`SceneFile`]) that save and reopen it.

mod baked;
mod baker;
mod files;
pub mod legend;
mod lit;
pub mod overlay;
mod scene_file;
mod solver;
mod state;

pub use baked::{BakeKey, BakeState, LitPanorama};
pub use baker::Wake;
pub use files::{file_kind, FileKind};
pub use lit::{LitCache, LitRenderError};
pub use scene_file::{
    is_scene, is_scene_file, SceneFile, SceneLight, ScenePanorama, SceneRoom, SceneView,
    FORMAT as SCENE_FORMAT, VERSION as SCENE_VERSION,
};
pub use solver::{describe_work_plane, read_grid, work_plane, Solved, Solver, WORK_PLANE_HEIGHT};
pub use state::{
    format_lux, load_table, LightEntry, LightsKey, LightsState, AUTO_EXPOSURE_QUANTILE,
    DEFAULT_CAMERA_HEIGHT, DEFAULT_EXPOSURE_LUX, DEFAULT_ROOM,
};

use crate::args::named;
use crate::args::values::{finite, parse_finite, parse_multiplier};
use anyhow::{Context, Result};
use clap::Args;
use lut_core::{Interpolation, View};
use std::path::{Path, PathBuf};

/// The room and its luminaires: the options `viewer render`, the window and `viewer lux`
/// share (one definition each).
// The field docs are the command-line help: `[:YAW,PITCH]` there is not a link.
#[allow(rustdoc::broken_intra_doc_links)]
#[derive(Args, Debug, Default, Clone)]
pub struct RoomArgs {
    /// A scene file (saved by the window): its room, luminaires and exposure, and for
    /// `render` and the window its panorama and view; the options below override it and
    /// --light adds to its luminaires.
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
    /// Place a luminaire: FILE@X,Y,Z[:YAW,PITCH] in metres and degrees (repeatable); FILE is
    /// an IES or EULUMDAT (.ldt) file, recognized by content.
    /// Room coordinates: X right, Y up from the floor, Z forward along the room's edges,
    /// origin on the floor below the camera. Aim defaults to straight down (yaw 0,
    /// pitch -90).
    #[arg(long = "light", value_parser = parse_light, allow_hyphen_values = true)]
    pub lights: Vec<LightSpec>,
    /// Room size WIDTHxDEPTHxHEIGHT in metres (default 5x5x2.7). For a cube panorama give
    /// a cube.
    #[arg(long, value_parser = parse_room)]
    pub room: Option<(f64, f64, f64)>,
    /// Camera height above the floor in metres (default 1.6).
    #[arg(long, value_parser = parse_finite, allow_hyphen_values = true)]
    pub camera_height: Option<f64>,
    /// The room's turn about the vertical axis in degrees: its front wall faces this yaw
    /// of the panorama (default 0).
    #[arg(long, value_parser = parse_finite, allow_hyphen_values = true)]
    pub room_yaw: Option<f64>,
    /// The room's centre X,Z in metres from the point below the camera, when the camera
    /// is not in the middle of the room (default 0,0).
    #[arg(long, value_parser = parse_center, allow_hyphen_values = true)]
    pub room_center: Option<(f64, f64)>,
    /// Multiply every luminaire's intensity (default 1; at most 1000000).
    #[arg(long, value_parser = parse_multiplier)]
    pub light_multiplier: Option<f64>,
    /// How luminaire tables interpolate between measured angles (default linear).
    #[arg(long, value_parser = named::<Interpolation>())]
    pub light_interpolation: Option<Interpolation>,
    /// Diffuse reflectances of the floor, walls and ceiling, F,W,C, each in [0, 1)
    /// (default 0.2,0.5,0.7): the light they reflect is added (inter-reflections).
    #[arg(long, value_parser = parse_reflectances)]
    pub reflectances: Option<lut_core::Reflectances>,
    /// Direct light only: no inter-reflections (the numbers of a black room).
    #[arg(long)]
    pub direct_only: bool,
}

/// Options that light a rendered room panorama (flattened into `viewer render` and the
/// window).
#[derive(Args, Debug, Default, Clone)]
pub struct LightArgs {
    /// The room and its luminaires.
    #[command(flatten)]
    pub room: RoomArgs,
    /// Illuminance in lux that reproduces the panorama's own brightness (default 300).
    #[arg(long, value_parser = parse_finite, allow_hyphen_values = true)]
    pub exposure_lux: Option<f64>,
    /// Light factor with no luminaire (0 = black, 1 = as photographed; default 0.15).
    #[arg(long, value_parser = parse_finite, allow_hyphen_values = true)]
    pub ambient: Option<f64>,
    /// Overlay a false-colour illuminance map (log scale, 3 decades).
    #[arg(long)]
    pub false_color: bool,
    /// Illuminance at the top (red) of the false-colour scale in lux (default 1000).
    #[arg(long, value_parser = parse_finite, allow_hyphen_values = true)]
    pub false_color_max: Option<f64>,
    /// Draw the room box as a wireframe and the luminaires as markers over the view, to
    /// fit the room to the photograph's walls, floor and ceiling (the window's "Show
    /// room").
    #[arg(long)]
    pub show_room: bool,
}

/// One `--light FILE.ies@X,Y,Z[:YAW,PITCH]`.
#[derive(Debug, Clone, PartialEq)]
pub struct LightSpec {
    /// The IES or EULUMDAT (.ldt) file; the format is recognized by content.
    pub file: PathBuf,
    /// Position in metres.
    pub position: [f64; 3],
    /// Aim (yaw, pitch) in degrees.
    pub aim: (f64, f64),
}

/// Parse one `--light FILE@X,Y,Z[:YAW,PITCH]` (the file is not opened).
///
/// # Errors
/// A message quoting `s` and saying which part is wrong.
pub fn parse_light(s: &str) -> Result<LightSpec, String> {
    let (file, rest) = s
        .rsplit_once('@')
        .ok_or_else(|| format!("light '{s}' must look like FILE.ies@X,Y,Z[:YAW,PITCH]"))?;
    if file.is_empty() {
        return Err(format!(
            "light '{s}': the IES file name is missing before '@'"
        ));
    }
    let (pos, aim) = match rest.split_once(':') {
        Some((p, a)) => (p, Some(a)),
        None => (rest, None),
    };
    let nums = |t: &str, n: usize, what: &str| -> Result<Vec<f64>, String> {
        t.split(',')
            .map(finite)
            .collect::<Option<Vec<f64>>>()
            .filter(|v| v.len() == n)
            .ok_or_else(|| format!("light '{s}': {what} '{t}' must be {n} numbers"))
    };
    let p = nums(pos, 3, "position X,Y,Z")?;
    let aim = match aim {
        Some(a) => {
            let a = nums(a, 2, "aim YAW,PITCH")?;
            (a[0], a[1])
        }
        None => (0.0, -90.0),
    };
    Ok(LightSpec {
        file: PathBuf::from(file),
        position: [p[0], p[1], p[2]],
        aim,
    })
}

fn parse_room(s: &str) -> Result<(f64, f64, f64), String> {
    match s
        .split(['x', 'X'])
        .map(|x| finite(x).filter(|v| *v > 0.0))
        .collect::<Option<Vec<f64>>>()
        .as_deref()
    {
        Some(&[w, d, h]) => {
            // The limits module, before any work (a room typed in millimetres).
            for side in [w, d, h] {
                lut_core::check_limit("room side", side, lut_core::limits::MAX_ROOM_SIDE, " m")
                    .map_err(|e| e.to_string())?;
            }
            Ok((w, d, h))
        }
        _ => Err(format!(
            "room '{}' must be WIDTHxDEPTHxHEIGHT in metres, e.g. 5x4x2.7",
            lut_core::shown(s)
        )),
    }
}

/// Parse `--reflectances F,W,C` (floor, walls, ceiling), each in [0, 1).
///
/// # Errors
/// A message quoting `s` and saying what is wrong.
pub fn parse_reflectances(s: &str) -> Result<lut_core::Reflectances, String> {
    let v = s
        .split(',')
        .map(finite)
        .collect::<Option<Vec<f64>>>()
        .filter(|v| v.len() == 3)
        .ok_or_else(|| {
            format!("reflectances '{s}' must be FLOOR,WALLS,CEILING, e.g. 0.2,0.5,0.7")
        })?;
    let r = lut_core::Reflectances {
        floor: v[0],
        walls: v[1],
        ceiling: v[2],
    };
    r.check().map_err(|e| format!("reflectances '{s}': {e}"))?;
    Ok(r)
}

fn parse_center(s: &str) -> Result<(f64, f64), String> {
    match s
        .split(',')
        .map(finite)
        .collect::<Option<Vec<f64>>>()
        .as_deref()
    {
        Some(&[x, z]) => Ok((x, z)),
        _ => Err(format!(
            "room centre '{s}' must be X,Z in metres, e.g. 0.4,-0.6"
        )),
    }
}

impl RoomArgs {
    /// The scene file's light state (paths against its folder), or the defaults.
    ///
    /// # Errors
    /// As [`SceneFile::load`] and [`SceneFile::to_state`].
    fn base(&self) -> Result<LightsState> {
        match &self.scene {
            Some(path) => {
                let scene = SceneFile::load(path)?;
                let dir = path.parent().unwrap_or(Path::new(""));
                scene
                    .to_state(dir)
                    .with_context(|| format!("{}", path.display()))
            }
            None => Ok(LightsState::default()),
        }
    }

    /// Apply these options over `st` (the scene's or the defaults): room numbers replace,
    /// `--light`s are loaded and added.
    ///
    /// # Errors
    /// An unreadable or malformed luminaire file.
    fn apply(&self, st: &mut LightsState) -> Result<()> {
        if let Some(r) = self.room {
            st.room = r;
        }
        if let Some(h) = self.camera_height {
            st.camera_height = h;
        }
        if let Some(y) = self.room_yaw {
            st.room_yaw = y;
        }
        if let Some(c) = self.room_center {
            st.room_center = c;
        }
        if let Some(m) = self.light_multiplier {
            st.multiplier = m;
        }
        if let Some(i) = self.light_interpolation {
            st.set_interpolation(i)?;
        }
        // The limits module: counted before any file is read.
        lut_core::check_limit(
            "luminaires",
            st.lights.len() + self.lights.len(),
            lut_core::limits::MAX_LIGHTS,
            "",
        )
        .map_err(|e| crate::usage!("--light: {e}"))?;
        if let Some(r) = self.reflectances {
            st.reflectances = r;
        }
        if self.direct_only {
            st.indirect = false;
        }
        for spec in &self.lights {
            let table = st.table_for(&spec.file)?;
            st.lights.push(LightEntry {
                path: spec.file.clone(),
                table,
                position: spec.position,
                yaw: spec.aim.0,
                pitch: spec.aim.1,
                multiplier: 1.0,
                enabled: true,
            });
        }
        Ok(())
    }

    /// The room and luminaires these options describe, without the shading (for
    /// `viewer lux`), checked.
    ///
    /// # Errors
    /// As [`LightArgs::state`].
    pub fn state(&self) -> Result<LightsState> {
        let mut st = self.base()?;
        self.apply(&mut st)?;
        // Values, as for `render` (LightArgs::state): usage errors, the same exit
        // status for the same option in every command.
        st.room_box()
            .map_err(|e| crate::usage!("--room/--camera-height/--room-yaw/--room-center: {e}"))?;
        st.direct_scene().map_err(|e| crate::usage!("{e}"))?;
        Ok(st)
    }

    /// The scene file's panorama (its file or folder, or a cube's face files, resolved
    /// against its folder; empty when it names none) and view, when a scene file is given.
    ///
    /// # Errors
    /// As [`SceneFile::load`].
    pub fn scene_panorama(&self) -> Result<(Vec<PathBuf>, Option<SceneView>)> {
        match &self.scene {
            Some(path) => {
                let scene = SceneFile::load(path)?;
                let dir = path.parent().unwrap_or(Path::new(""));
                Ok((scene.panorama_paths(dir), scene.view))
            }
            None => Ok((Vec::new(), None)),
        }
    }
}

impl LightArgs {
    /// The light state these options describe: every IES file loaded (once per file),
    /// the room and shading checked, so a bad option is reported before anything renders.
    ///
    /// # Errors
    /// An unreadable or malformed IES file, a bad room size or camera height, a light
    /// outside the room, a non-positive `--exposure-lux`.
    pub fn state(&self) -> Result<LightsState> {
        let mut st = self.room.base()?;
        self.room.apply(&mut st)?;
        if let Some(lux) = self.exposure_lux {
            if !(lux.is_finite() && lux > 0.0) {
                return Err(crate::usage!(
                    "--exposure-lux must be a positive number of lux, got {lux}"
                ));
            }
            st.exposure_lux = lux;
            st.auto_exposure = false;
        }
        if let Some(a) = self.ambient {
            st.ambient = a;
        }
        st.show_room = self.show_room;
        if self.false_color {
            st.false_color = true;
        }
        if let Some(m) = self.false_color_max {
            st.false_color_max = m;
        }
        if st.lights.is_empty() {
            return Ok(st);
        }
        // What is left to go wrong are values (the files are read): usage errors.
        st.room_box()
            .map_err(|e| crate::usage!("--room/--camera-height/--room-yaw/--room-center: {e}"))?;
        st.check().map_err(|e| crate::usage!("{e:#}"))?;
        Ok(st)
    }
}

/// Light a rendered frame of `view` in place; a no-op when no `--light` or `--scene`
/// is given (or the scene has no luminaire).
///
/// # Errors
/// As [`LightArgs::state`], or a frame that is not `w × h`.
pub fn apply_lights(args: &LightArgs, view: View, frame: &mut [u32], w: u32, h: u32) -> Result<()> {
    if args.room.lights.is_empty() && args.room.scene.is_none() {
        return Ok(());
    }
    args.state()?
        .light_frame(view, frame, w, h)
        .map_err(anyhow::Error::msg)
}

/// A real IES file of the test data, for the unit tests.
#[cfg(test)]
fn sample_path() -> PathBuf {
    test_support::test_data("ies/type_b_full.ies")
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    #[test]
    fn light_spec_parses() {
        let l = parse_light("C:/lamps/a.ies@1,2.5,-3:45,-60").unwrap();
        assert_eq!(l.file, PathBuf::from("C:/lamps/a.ies"));
        assert_eq!(l.position, [1.0, 2.5, -3.0]);
        assert_eq!(l.aim, (45.0, -60.0));
        let l = parse_light("a.ies@0,2.7,0").unwrap();
        assert_eq!(l.aim, (0.0, -90.0));
        assert!(parse_light("a.ies").is_err());
        assert!(parse_light("a.ies@1,2").is_err());
        assert!(parse_light("a.ies@1,2,x").is_err());
        assert!(parse_light("@1,2,3").is_err());
        assert!(parse_light("a.ies@1,2,3:5").is_err());
        assert!(parse_light("a.ies@1,2,inf").is_err());
    }

    #[test]
    fn room_parses() {
        assert_eq!(parse_room("5x4x2.7").unwrap(), (5.0, 4.0, 2.7));
        assert!(parse_room("5x4").is_err());
        assert!(parse_room("5x4x2x1").is_err());
        assert!(parse_room("5x-4x2").is_err());
    }

    #[test]
    fn no_light_is_a_no_op() {
        let mut f = vec![0x123456u32; 4];
        apply_lights(&LightArgs::default(), View::default(), &mut f, 2, 2).unwrap();
        assert_eq!(f, vec![0x123456u32; 4]);
    }

    #[test]
    fn options_become_the_state_and_bad_ones_are_refused() {
        let spec = |pos: [f64; 3]| LightSpec {
            file: sample_path(),
            position: pos,
            aim: (30.0, -60.0),
        };
        let a = LightArgs {
            room: RoomArgs {
                lights: vec![spec([0.0, 2.6, 0.0]), spec([1.0, 2.6, -1.0])],
                room: Some((6.0, 4.0, 2.7)),
                ..RoomArgs::default()
            },
            ambient: Some(0.3),
            exposure_lux: Some(150.0),
            ..LightArgs::default()
        };
        let st = a.state().unwrap();
        assert_eq!(st.lights.len(), 2);
        assert!(Arc::ptr_eq(&st.lights[0].table, &st.lights[1].table));
        assert_eq!((st.lights[1].yaw, st.lights[1].pitch), (30.0, -60.0));
        assert_eq!(st.room, (6.0, 4.0, 2.7));
        let o = st.shade_options();
        assert_eq!(o.ambient, 0.3);
        assert!((o.exposure - 1.0 / 150.0).abs() < 1e-15);
        let mut outside = a.clone();
        outside.room.lights = vec![spec([0.0, 9.0, 0.0])];
        assert!(outside.state().is_err());
        let dark = LightArgs {
            exposure_lux: Some(0.0),
            ..a.clone()
        };
        assert!(format!("{:#}", dark.state().unwrap_err()).contains("--exposure-lux"));
        let mut high = a;
        high.room.camera_height = Some(5.0);
        assert!(format!("{:#}", high.state().unwrap_err()).contains("--camera-height"));
    }
}
