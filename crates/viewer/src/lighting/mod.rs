//! Luminaires lighting a rendered room panorama: the `--light ...` options `viewer render`
//! and the window share, and the light state ([`LightsState`]) they become, which the
//! window's panel edits.

mod state;

pub use state::{
    format_lux, LightEntry, LightsKey, LightsState, DEFAULT_CAMERA_HEIGHT, DEFAULT_EXPOSURE_LUX,
    DEFAULT_ROOM,
};

use crate::args::values::finite;
use anyhow::Result;
use clap::Args;
use lut_core::View;
use lut_core::{LightTable, Room, ShadeOptions};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Options that light a rendered room panorama (flattened into `viewer render` and the
/// window).
// The field docs are the command-line help: `[:YAW,PITCH]` there is not a link.
#[allow(rustdoc::broken_intra_doc_links)]
#[derive(Args, Debug, Default, Clone)]
pub struct LightArgs {
    /// Place a luminaire: FILE@X,Y,Z[:YAW,PITCH] in metres and degrees (repeatable); FILE is
    /// an IES or EULUMDAT (.ldt) file, recognized by content.
    /// World frame: X right, Y up from the floor, Z forward at yaw 0; the camera is at
    /// (0, camera height, 0). Aim defaults to straight down (yaw 0, pitch -90).
    #[arg(long = "light", value_parser = parse_light, allow_hyphen_values = true)]
    pub lights: Vec<LightSpec>,
    /// Room size WIDTHxDEPTHxHEIGHT in metres, centred on the camera (default 5x5x2.7).
    /// For a cube panorama give a cube.
    #[arg(long, value_parser = parse_room)]
    pub room: Option<(f64, f64, f64)>,
    /// Camera height above the floor in metres (default 1.6).
    #[arg(long)]
    pub camera_height: Option<f64>,
    /// Illuminance in lux that reproduces the panorama's own brightness (default 300).
    #[arg(long)]
    pub exposure_lux: Option<f64>,
    /// Light factor with no luminaire (0 = black, 1 = as photographed; default 0.15).
    #[arg(long)]
    pub ambient: Option<f64>,
    /// Multiply every luminaire's intensity (default 1).
    #[arg(long)]
    pub light_multiplier: Option<f64>,
    /// Overlay a false-colour illuminance map (log scale, 3 decades).
    #[arg(long)]
    pub false_color: bool,
    /// Illuminance at the top (red) of the false-colour scale in lux (default 1000).
    #[arg(long)]
    pub false_color_max: Option<f64>,
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
        Some(&[w, d, h]) => Ok((w, d, h)),
        _ => Err(format!(
            "room '{s}' must be WIDTHxDEPTHxHEIGHT in metres, e.g. 5x4x2.7"
        )),
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
        let lux = self.exposure_lux.unwrap_or(DEFAULT_EXPOSURE_LUX);
        if !(lux.is_finite() && lux > 0.0) {
            return Err(crate::usage!(
                "--exposure-lux must be a positive number of lux, got {lux}"
            ));
        }
        let d = ShadeOptions::default();
        let mut st = LightsState {
            room: self.room.unwrap_or(DEFAULT_ROOM),
            camera_height: self.camera_height.unwrap_or(DEFAULT_CAMERA_HEIGHT),
            multiplier: self.light_multiplier.unwrap_or(1.0),
            exposure_lux: lux,
            ambient: self.ambient.unwrap_or(d.ambient),
            false_color: self.false_color,
            false_color_max: self.false_color_max.unwrap_or(d.false_color_max_lux),
            ..LightsState::default()
        };
        if self.lights.is_empty() {
            return Ok(st);
        }
        let (w, d, h) = st.room;
        Room::new(w, d, h, st.camera_height)
            .map_err(|e| crate::usage!("--room/--camera-height: {e}"))?;
        let mut tables: HashMap<&Path, Arc<LightTable>> = HashMap::new();
        for spec in &self.lights {
            let table = match tables.get(spec.file.as_path()) {
                Some(t) => t.clone(),
                None => {
                    let t = Arc::new(LightTable::load(&spec.file)?);
                    tables.insert(spec.file.as_path(), t.clone());
                    t
                }
            };
            st.lights.push(LightEntry {
                path: spec.file.clone(),
                table,
                position: spec.position,
                yaw: spec.aim.0,
                pitch: spec.aim.1,
            });
        }
        // What is left to go wrong is where the lights are: command-line values.
        st.scene().map_err(|e| crate::usage!("{e}"))?;
        Ok(st)
    }
}

/// Light a rendered frame of `view` in place; a no-op when no `--light` is given.
///
/// # Errors
/// As [`LightArgs::state`], or a frame that is not `w × h`.
pub fn apply_lights(args: &LightArgs, view: View, frame: &mut [u32], w: u32, h: u32) -> Result<()> {
    if args.lights.is_empty() {
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
            lights: vec![spec([0.0, 2.6, 0.0]), spec([1.0, 2.6, -1.0])],
            room: Some((6.0, 4.0, 2.7)),
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
        let outside = LightArgs {
            lights: vec![spec([0.0, 9.0, 0.0])],
            ..a.clone()
        };
        assert!(outside.state().is_err());
        let dark = LightArgs {
            exposure_lux: Some(0.0),
            ..a.clone()
        };
        assert!(format!("{:#}", dark.state().unwrap_err()).contains("--exposure-lux"));
        let high = LightArgs {
            camera_height: Some(5.0),
            ..a
        };
        assert!(format!("{:#}", high.state().unwrap_err()).contains("--camera-height"));
    }
}
