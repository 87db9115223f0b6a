//! The luminaires lighting a scene: what the window's "Lights" section edits and what
//! `viewer render --light ...` builds from its options, turned into the `lut_core::light`
//! scene and shading options. Pure data (no window), so the conversions are unit-tested.

use lut_core::{
    Interpolation, LightScene, LightTable, Luminaire, Reflectances, Room, ShadeOptions,
};
use lut_core::{Photometry, TableOptions};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Default room (width × depth × height, metres).
pub const DEFAULT_ROOM: (f64, f64, f64) = (5.0, 5.0, 2.7);
/// Default camera height above the floor in metres.
pub const DEFAULT_CAMERA_HEIGHT: f64 = 1.6;
/// Default exposure: the illuminance that reproduces the photograph's brightness.
pub const DEFAULT_EXPOSURE_LUX: f64 = 300.0;
/// The automatic exposure's quantile of the room's illuminance (see
/// [`LightsState::apply_auto_exposure`]).
pub const AUTO_EXPOSURE_QUANTILE: f64 = 0.95;

/// One luminaire in the panel.
#[derive(Debug, Clone)]
pub struct LightEntry {
    /// The IES file it was loaded from.
    pub path: PathBuf,
    /// Its intensity distribution (shared by entries of the same file).
    pub table: Arc<LightTable>,
    /// Position in metres (world frame: X right, Y up from the floor, Z forward).
    pub position: [f64; 3],
    /// Aim yaw in degrees.
    pub yaw: f64,
    /// Aim pitch in degrees (−90 = straight down).
    pub pitch: f64,
    /// This luminaire's own multiplier (times [`LightsState::multiplier`]).
    pub multiplier: f64,
    /// Switched on.
    pub enabled: bool,
}

impl LightEntry {
    /// The file name for the list.
    pub fn name(&self) -> String {
        self.path.file_name().map_or_else(
            || self.path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        )
    }
}

/// The luminaires and their shading: everything the "Lights" section shows and edits.
#[derive(Debug, Clone)]
pub struct LightsState {
    /// The luminaires.
    pub lights: Vec<LightEntry>,
    /// The "IES file" text field.
    pub path_input: String,
    /// Room width (X), depth (Z), height (Y) in metres.
    pub room: (f64, f64, f64),
    /// Camera height above the floor in metres.
    pub camera_height: f64,
    /// The room's turn about the vertical axis in degrees (its front wall faces this
    /// panorama yaw).
    pub room_yaw: f64,
    /// The room's centre (x, z) from the point below the camera, metres.
    pub room_center: (f64, f64),
    /// Multiplies every luminaire's intensity.
    pub multiplier: f64,
    /// How the luminaires' tables interpolate between measured angles.
    pub interpolation: Interpolation,
    /// Illuminance in lux that reproduces the panorama's own brightness.
    pub exposure_lux: f64,
    /// The exposure follows the lights (set from the illuminance map after each change).
    pub auto_exposure: bool,
    /// Light factor with no luminaire.
    pub ambient: f64,
    /// The surfaces' diffuse reflectances (floor, walls, ceiling).
    pub reflectances: Reflectances,
    /// Inter-reflections on (off: the direct light only, `--direct-only`).
    pub indirect: bool,
    /// Overlay the false-colour illuminance map.
    pub false_color: bool,
    /// Top of the false-colour scale in lux.
    pub false_color_max: f64,
    /// The last IES file that did not load.
    pub error: Option<String>,
    /// Why the lights cannot light the scene (a light outside the room), if so.
    pub scene_error: Option<String>,
    /// Illuminance at the pointer (lights only), when the pointer is over the scene.
    pub lux_at_cursor: Option<f64>,
    /// Where the window's lit panorama stands (`super::BakeState::describe`; empty
    /// without luminaires).
    pub lit_panorama: String,
    /// The work plane's figures as the window last had them from the solving thread
    /// ([`super::Solver`]): "Em … U0 …", "computing…", or why there are none; empty
    /// without luminaires.
    pub work_plane: String,
    /// Draw the room box and the luminaires over the view (the window's "Show room").
    pub show_room: bool,
    /// The luminaire selected in the view or the panel.
    pub selected: Option<usize>,
}

impl Default for LightsState {
    fn default() -> Self {
        let d = ShadeOptions::default();
        LightsState {
            lights: Vec::new(),
            path_input: String::new(),
            room: DEFAULT_ROOM,
            camera_height: DEFAULT_CAMERA_HEIGHT,
            room_yaw: 0.0,
            room_center: (0.0, 0.0),
            multiplier: 1.0,
            interpolation: Interpolation::Linear,
            exposure_lux: DEFAULT_EXPOSURE_LUX,
            auto_exposure: false,
            ambient: d.ambient,
            reflectances: Reflectances::default(),
            indirect: true,
            false_color: false,
            false_color_max: d.false_color_max_lux,
            error: None,
            scene_error: None,
            lux_at_cursor: None,
            lit_panorama: String::new(),
            work_plane: String::new(),
            show_room: false,
            selected: None,
        }
    }
}

/// What a lit frame depends on: when it is unchanged, the cached scene stays valid.
#[derive(Debug, Clone, PartialEq)]
pub struct LightsKey {
    lights: Vec<(usize, [f64; 3], f64, f64, f64, bool)>,
    room: (f64, f64, f64),
    camera_height: f64,
    room_yaw: f64,
    room_center: (f64, f64),
    multiplier: f64,
    reflectances: Option<[f64; 3]>,
    shade: Option<ShadeOptions>,
}

impl LightsKey {
    /// The same room (size, camera height, turn, centre) and reflectances: a solve of
    /// the inter-reflections for one key is a close stand-in for the other while only
    /// the luminaires differ.
    pub fn same_room(&self, other: &LightsKey) -> bool {
        self.room == other.room
            && self.camera_height == other.camera_height
            && self.room_yaw == other.room_yaw
            && self.room_center == other.room_center
            && self.reflectances == other.reflectances
    }
}

impl LightsState {
    /// Add a luminaire with `table`, hung below the ceiling and aimed straight down;
    /// each new one is moved along X so they do not stack (kept inside the room).
    pub fn add(&mut self, path: PathBuf, table: Arc<LightTable>) {
        let (w, _, h) = self.room;
        let n = self.lights.len() as f64;
        // 0, +0.5, −0.5, +1, −1, ... metres, within the walls.
        let step = ((n + 1.0) / 2.0).floor() * 0.5;
        let x = if self.lights.len() % 2 == 1 {
            step
        } else {
            -step
        };
        let half = (w / 2.0 - 0.05).max(0.0);
        let y = (h - 0.05).max(h * 0.5);
        self.lights.push(LightEntry {
            path,
            table,
            position: [
                (self.room_center.0 + x)
                    .clamp(self.room_center.0 - half, self.room_center.0 + half),
                y,
                self.room_center.1,
            ],
            yaw: 0.0,
            pitch: -90.0,
            multiplier: 1.0,
            enabled: true,
        });
    }

    /// The table of the luminaire file `path` with this state's interpolation: shared
    /// with a light of the same file, else loaded (IES or EULUMDAT, by content).
    ///
    /// # Errors
    /// An unreadable or malformed file (named, with the line).
    pub fn table_for(&self, path: &Path) -> anyhow::Result<Arc<LightTable>> {
        if let Some(l) = self.lights.iter().find(|l| l.path == path) {
            return Ok(l.table.clone());
        }
        Ok(Arc::new(load_table(path, self.interpolation)?))
    }

    /// Use `interpolation` from now on: every luminaire's table is rebuilt from its file.
    ///
    /// # Errors
    /// A file that no longer loads (the state is left as it was).
    pub fn set_interpolation(&mut self, interpolation: Interpolation) -> anyhow::Result<()> {
        if interpolation == self.interpolation {
            return Ok(());
        }
        let mut tables: Vec<(PathBuf, Arc<LightTable>)> = Vec::new();
        for l in &self.lights {
            if !tables.iter().any(|(p, _)| *p == l.path) {
                tables.push((
                    l.path.clone(),
                    Arc::new(load_table(&l.path, interpolation)?),
                ));
            }
        }
        for l in &mut self.lights {
            if let Some((_, t)) = tables.iter().find(|(p, _)| *p == l.path) {
                l.table = t.clone();
            }
        }
        self.interpolation = interpolation;
        Ok(())
    }

    /// The room box these numbers describe.
    ///
    /// # Errors
    /// A size, camera height, yaw or centre out of range (named).
    pub fn room_box(&self) -> Result<Room, String> {
        let (w, d, h) = self.room;
        Room::new(w, d, h, self.camera_height)
            .and_then(|r| r.with_yaw(self.room_yaw))
            .and_then(|r| r.with_center(self.room_center.0, self.room_center.1))
            .map_err(|e| e.to_string())
    }

    /// Check everything a render needs: the room, every light inside it, the exposure,
    /// the multipliers.
    ///
    /// # Errors
    /// The first problem found, named.
    pub fn check(&self) -> anyhow::Result<()> {
        let lux = self.exposure_lux;
        if !(lux.is_finite() && lux > 0.0) {
            anyhow::bail!("the exposure must be a positive number of lux, got {lux}");
        }
        for (name, v) in [
            ("ambient", self.ambient),
            ("light multiplier", self.multiplier),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                anyhow::bail!("the {name} must be a finite number ≥ 0, got {v}");
            }
        }
        if !(self.false_color_max.is_finite() && self.false_color_max > 0.0) {
            anyhow::bail!(
                "the false-colour maximum must be a positive number of lux, got {}",
                self.false_color_max
            );
        }
        self.room_box().map_err(anyhow::Error::msg)?;
        self.reflectances.check()?;
        self.direct_scene().map_err(anyhow::Error::msg)?;
        Ok(())
    }

    /// Load `path` (an IES file) and add a luminaire with it; the table is shared with
    /// lights of the same file. The error (named file, line, what was expected) is kept
    /// in [`LightsState::error`] and returned.
    ///
    /// # Errors
    /// An unreadable or malformed IES file.
    pub fn load_and_add(&mut self, path: &Path) -> Result<(), String> {
        let existing = self
            .lights
            .iter()
            .find(|l| l.path == path)
            .map(|l| l.table.clone());
        let table = match existing {
            Some(t) => t,
            None => match load_table(path, self.interpolation) {
                Ok(t) => Arc::new(t),
                Err(e) => {
                    let msg = format!("{e:#}");
                    self.error = Some(msg.clone());
                    return Err(msg);
                }
            },
        };
        self.error = None;
        self.add(path.to_path_buf(), table);
        Ok(())
    }

    /// The scene to light, `None` with no luminaire.
    ///
    /// # Errors
    /// A bad room or camera height, a light outside the room, a non-finite value.
    pub fn scene(&self) -> Result<Option<LightScene>, String> {
        let Some(scene) = self.direct_scene()? else {
            return Ok(None);
        };
        if !self.indirect {
            return Ok(Some(scene));
        }
        scene
            .with_reflectances(self.reflectances)
            .map(Some)
            .map_err(|e| e.to_string())
    }

    /// The scene with the direct light only (no inter-reflections solved): what a check
    /// of the room and luminaires needs, `None` with no luminaire.
    ///
    /// # Errors
    /// As [`LightsState::scene`].
    pub fn direct_scene(&self) -> Result<Option<LightScene>, String> {
        if self.lights.is_empty() {
            return Ok(None);
        }
        let room = self.room_box()?;
        // Every light is placed (so one outside the room is reported with its number);
        // switched-off ones with no light.
        let lights = self
            .lights
            .iter()
            .map(|l| {
                let mut lum = Luminaire::new(l.table.clone(), l.position.into());
                lum.yaw_deg = l.yaw;
                lum.pitch_deg = l.pitch;
                lum.multiplier = if l.enabled {
                    self.multiplier * l.multiplier
                } else {
                    0.0
                };
                lum
            })
            .collect();
        LightScene::new(room, lights)
            .map(Some)
            .map_err(|e| e.to_string())
    }

    /// The reflectances the light is computed with: [`LightsState::reflectances`], or
    /// all zero when inter-reflections are off.
    pub fn effective_reflectances(&self) -> Reflectances {
        if self.indirect {
            self.reflectances
        } else {
            Reflectances::ZERO
        }
    }

    /// Set the exposure from the illuminance map of these lights (when
    /// [`LightsState::auto_exposure`] is on): the lux that [`AUTO_EXPOSURE_QUANTILE`] of
    /// the room's surface stays below (area-weighted, over walls, floor and ceiling)
    /// looks like the photograph, so a light just added brightens the room without
    /// blowing it out. With no light on (all dark) the exposure is left alone.
    pub fn apply_auto_exposure(&mut self, map: &lut_core::IlluminanceMap) {
        if !self.auto_exposure {
            return;
        }
        let lux = map.quantile(AUTO_EXPOSURE_QUANTILE);
        if lux.is_finite() && lux > 0.0 {
            self.exposure_lux = lux.max(1.0);
        }
    }

    /// Luminaires were added (dropped, opened, typed in the panel): with a fixed exposure
    /// the picture would turn white under a new light, so the exposure follows the
    /// lights from now on. Returns the notice saying so and how to fix it again (`None`:
    /// it already did).
    pub fn lights_added(&mut self) -> Option<String> {
        if self.auto_exposure || self.lights.is_empty() {
            return None;
        }
        self.auto_exposure = true;
        Some(format!(
            "exposure now follows the lights (it was fixed at {:.0} lx, which a new light \
             can blow out); to fix it again, untick Lights > Exposure > automatic",
            self.exposure_lux
        ))
    }

    /// How the lit frame is shaded.
    pub fn shade_options(&self) -> ShadeOptions {
        ShadeOptions {
            ambient: self.ambient,
            exposure: if self.exposure_lux > 0.0 {
                1.0 / self.exposure_lux
            } else {
                0.0
            },
            false_color: self.false_color,
            false_color_max_lux: self.false_color_max,
        }
    }

    /// What the illuminance map depends on: the luminaires and the room, not the
    /// shading.
    pub fn geometry_key(&self) -> LightsKey {
        LightsKey {
            shade: None,
            ..self.key()
        }
    }

    /// What the lit frame depends on.
    pub fn key(&self) -> LightsKey {
        LightsKey {
            lights: self
                .lights
                .iter()
                .map(|l| {
                    (
                        Arc::as_ptr(&l.table) as usize,
                        l.position,
                        l.yaw,
                        l.pitch,
                        l.multiplier,
                        l.enabled,
                    )
                })
                .collect(),
            room: self.room,
            camera_height: self.camera_height,
            room_yaw: self.room_yaw,
            room_center: self.room_center,
            multiplier: self.multiplier,
            reflectances: self.indirect.then_some([
                self.reflectances.floor,
                self.reflectances.walls,
                self.reflectances.ceiling,
            ]),
            shade: (!self.lights.is_empty()).then(|| self.shade_options()),
        }
    }
}

/// Load a luminaire file (IES or EULUMDAT, by content) as a table with `interpolation`.
///
/// # Errors
/// An unreadable or malformed file (named, with the line).
pub fn load_table(path: &Path, interpolation: Interpolation) -> anyhow::Result<LightTable> {
    let opts = TableOptions {
        interpolation,
        ..TableOptions::default()
    };
    Ok(LightTable::from_photometry(
        &Photometry::load(path)?,
        &opts,
    )?)
}

/// The "lux at cursor" readout: `—` off the scene or with no light, else the value with
/// precision that suits its size.
pub fn format_lux(lux: Option<f64>) -> String {
    match lux {
        Some(l) if l.is_finite() && l >= 0.0 => {
            if l >= 100.0 {
                format!("{l:.0} lx")
            } else if l >= 1.0 {
                format!("{l:.1} lx")
            } else {
                format!("{l:.3} lx")
            }
        }
        _ => "—".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lighting::sample_path;
    use lut_core::{Camera, View};

    #[test]
    fn no_light_no_scene() {
        let s = LightsState::default();
        assert!(s.scene().unwrap().is_none());
        assert_eq!(s.key().shade, None);
    }

    #[test]
    fn panel_state_becomes_the_scene() {
        let mut s = LightsState::default();
        s.load_and_add(&sample_path()).unwrap();
        s.load_and_add(&sample_path()).unwrap();
        s.lights[1].position = [1.0, 2.0, -1.5];
        s.lights[1].yaw = 30.0;
        s.lights[1].pitch = -45.0;
        s.multiplier = 2.5;
        let scene = s.scene().unwrap().unwrap();
        let l = scene.luminaires();
        assert_eq!(l.len(), 2);
        // Same file: one shared table.
        assert!(Arc::ptr_eq(&l[0].table, &l[1].table));
        assert_eq!(l[0].pitch_deg, -90.0);
        assert_eq!(l[1].position, glam::DVec3::new(1.0, 2.0, -1.5));
        assert_eq!((l[1].yaw_deg, l[1].pitch_deg), (30.0, -45.0));
        assert!(l.iter().all(|x| x.multiplier == 2.5));
        // New lights are spread along X and hang inside the room.
        assert_ne!(s.lights[0].position, [1.0, 2.0, -1.5]);
        assert!(s.lights[0].position[1] < s.room.2);
    }

    #[test]
    fn the_same_state_lights_like_viewer_render() {
        // The window's lux readout is lux_at over the scene viewer render builds from the
        // same numbers: check one against the other at the image centre.
        let mut s = LightsState::default();
        s.load_and_add(&sample_path()).unwrap();
        let scene = s.scene().unwrap().unwrap();
        let cam = Camera::new(View::new(0.0, -90.0, 90.0).unwrap(), 64, 64);
        let lux = lut_core::lux_at(&scene, &cam, 32.0, 32.0);
        let direct = scene.illuminance(glam::DVec3::new(0.0, 0.0, 0.0), glam::DVec3::Y);
        assert!(
            (lux - direct).abs() <= 1e-9 * direct.max(1.0),
            "{lux} {direct}"
        );
        assert!(lux > 0.0);
    }

    #[test]
    fn bad_file_and_outside_light_are_errors_not_panics() {
        let mut s = LightsState::default();
        let e = s.load_and_add(Path::new("/no/such/lamp.ies")).unwrap_err();
        assert!(e.contains("lamp.ies"), "{e}");
        assert_eq!(s.error.as_deref(), Some(e.as_str()));
        assert!(s.lights.is_empty());
        s.load_and_add(&sample_path()).unwrap();
        assert!(s.error.is_none());
        s.lights[0].position = [0.0, 9.0, 0.0];
        assert!(s.scene().is_err());
        s.lights[0].position = [0.0, 2.0, 0.0];
        s.camera_height = 3.0; // above the ceiling
        assert!(s.scene().is_err());
    }

    #[test]
    fn key_follows_every_edit() {
        let mut s = LightsState::default();
        s.load_and_add(&sample_path()).unwrap();
        let k = s.key();
        assert_eq!(k, s.key());
        let mut t = s.clone();
        t.lights[0].yaw += 1.0;
        assert_ne!(k, t.key());
        let mut t = s.clone();
        t.false_color = true;
        assert_ne!(k, t.key());
        let mut t = s.clone();
        t.exposure_lux = 100.0;
        assert_ne!(k, t.key());
        let mut t = s.clone();
        t.lights.clear();
        assert_ne!(k, t.key());
        // The text field does not change the picture.
        let mut t = s.clone();
        t.path_input = "x".into();
        assert_eq!(k, t.key());
    }

    #[test]
    fn no_light_leaves_the_frame_alone_and_a_light_shades_it() {
        let mut s = LightsState::default();
        let view = View::new(0.0, -30.0, 90.0).unwrap();
        let mut f = vec![0x0080_8080u32; 16 * 12];
        s.light_frame(view, &mut f, 16, 12).unwrap();
        assert!(f.iter().all(|&p| p == 0x0080_8080));
        s.load_and_add(&sample_path()).unwrap();
        s.light_frame(view, &mut f, 16, 12).unwrap();
        assert!(f.iter().any(|&p| p != 0x0080_8080));
        assert!(s.light_frame(view, &mut f, 16, 13).is_err());
    }

    #[test]
    fn exposure_becomes_a_factor() {
        let mut s = LightsState {
            exposure_lux: 250.0,
            ..LightsState::default()
        };
        assert!((s.shade_options().exposure - 1.0 / 250.0).abs() < 1e-15);
        s.exposure_lux = 0.0;
        assert_eq!(s.shade_options().exposure, 0.0);
    }

    #[test]
    fn added_lights_stay_in_an_off_centre_room() {
        let mut s = LightsState {
            room: (2.0, 3.0, 2.7),
            room_center: (0.8, -0.5),
            camera_height: 1.2,
            ..LightsState::default()
        };
        for _ in 0..6 {
            s.load_and_add(&sample_path()).unwrap();
        }
        let room = s.room_box().unwrap();
        assert!(s.lights.iter().all(|l| room.contains(l.position.into())));
        assert!(s.scene().is_ok());
    }

    #[test]
    fn lux_readout() {
        assert_eq!(format_lux(None), "—");
        assert_eq!(format_lux(Some(f64::NAN)), "—");
        assert_eq!(format_lux(Some(1234.4)), "1234 lx");
        assert_eq!(format_lux(Some(12.34)), "12.3 lx");
        assert_eq!(format_lux(Some(0.01234)), "0.012 lx");
        assert_eq!(format_lux(Some(0.0)), "0.000 lx");
    }
}
