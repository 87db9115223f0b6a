//! Scene files: a lit room saved and reopened — the panorama, the room fitted to it, the
//! luminaires and the exposure, as a small JSON file (docs/lights.md, "Scene files").
//!
//! ```json
//! {
//!   "format": "lutpano-scene",
//!   "version": 1,
//!   "panorama": "interior.jpg",
//!   "view": { "yaw": 30.0, "pitch": -25.0, "hfov": 110.0 },
//!   "room": { "width": 4.2, "depth": 5.6, "height": 2.7, "camera_height": 1.45,
//!             "yaw": -12.0, "center": [0.3, -0.4] },
//!   "lights": [ { "file": "../tests/data/ldt/office_louvre_2x28w.ldt",
//!                 "position": [0.5, 2.65, 1.0], "yaw": 0.0, "pitch": -90.0,
//!                 "multiplier": 1.0, "enabled": true } ],
//!   "light_multiplier": 1.0, "interpolation": "linear",
//!   "exposure_lux": 300.0, "auto_exposure": false, "ambient": 0.15,
//!   "false_color": false, "false_color_max": 1000.0
//! }
//! ```
//!
//! Paths are written relative to the scene file's folder (so a scene moves with its
//! files) and read relative to it; absolute paths stay absolute. Unknown keys are an error
//! naming the key and its line, so a misspelt setting is never silently ignored.

use super::state::{LightEntry, LightsState};
use anyhow::{bail, Context, Result};
use lut_core::{parse_name, Interpolation, Named};
use serde::{Deserialize, Serialize};
use std::path::{Component, Path, PathBuf};

/// The value of the `format` key.
pub const FORMAT: &str = "lutpano-scene";
/// The version this viewer writes and reads.
pub const VERSION: u32 = 1;

/// The view to open the scene with.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneView {
    /// Yaw in degrees.
    pub yaw: f64,
    /// Pitch in degrees.
    pub pitch: f64,
    /// Horizontal field of view in degrees.
    pub hfov: f64,
}

/// The room box, room coordinates (docs/lights.md).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneRoom {
    /// Along X, metres.
    pub width: f64,
    /// Along Z, metres.
    pub depth: f64,
    /// Along Y, metres.
    pub height: f64,
    /// The camera above the floor, metres.
    pub camera_height: f64,
    /// The box's turn about the vertical axis, degrees.
    #[serde(default)]
    pub yaw: f64,
    /// The box centre (x, z) from the point below the camera, metres.
    #[serde(default)]
    pub center: [f64; 2],
}

/// One luminaire.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneLight {
    /// The IES or EULUMDAT file.
    pub file: PathBuf,
    /// Position, metres, room coordinates.
    pub position: [f64; 3],
    /// Aim yaw in degrees.
    #[serde(default)]
    pub yaw: f64,
    /// Aim pitch in degrees (−90 = straight down).
    #[serde(default = "down")]
    pub pitch: f64,
    /// Its own multiplier (times the scene's `light_multiplier`).
    #[serde(default = "one")]
    pub multiplier: f64,
    /// Whether it is switched on.
    #[serde(default = "yes")]
    pub enabled: bool,
}

fn down() -> f64 {
    -90.0
}
fn one() -> f64 {
    1.0
}
fn yes() -> bool {
    true
}

/// A scene's panorama: `"panorama": "FILE-OR-FOLDER"`, or the face files of a cube
/// opened from separate files, `"panorama": ["front.jpg", "right.jpg", ...]` (as given,
/// so the scene reopens exactly those files).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ScenePanorama {
    /// One image file, or a folder of cube faces.
    One(PathBuf),
    /// A cube map's face files.
    Faces(Vec<PathBuf>),
}

impl ScenePanorama {
    /// The paths as written in the file.
    pub fn paths(&self) -> Vec<PathBuf> {
        match self {
            ScenePanorama::One(p) => vec![p.clone()],
            ScenePanorama::Faces(f) => f.clone(),
        }
    }
}

/// A scene file's content.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Always `"lutpano-scene"` ([`FORMAT`](super::SCENE_FORMAT)): recognizes a scene file by content.
    pub format: String,
    /// The version ([`VERSION`](super::SCENE_VERSION)).
    pub version: u32,
    /// The panorama (a file, a folder of cube faces or a cube's face files); none for the
    /// bundled sample.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub panorama: Option<ScenePanorama>,
    /// The view to open with.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub view: Option<SceneView>,
    /// The room.
    pub room: SceneRoom,
    /// The luminaires.
    #[serde(default)]
    pub lights: Vec<SceneLight>,
    /// Multiplies every luminaire.
    #[serde(default = "one")]
    pub light_multiplier: f64,
    /// `linear` or `catmull-rom`.
    #[serde(default = "linear")]
    pub interpolation: String,
    /// The illuminance that looks like the photograph, lux.
    pub exposure_lux: f64,
    /// Whether the exposure follows the lights.
    #[serde(default)]
    pub auto_exposure: bool,
    /// Light factor with no luminaire.
    pub ambient: f64,
    /// Diffuse reflectances of the surfaces (default floor 0.2, walls 0.5, ceiling 0.7).
    #[serde(default)]
    pub reflectances: SceneReflectances,
    /// Inter-reflections on (default true; false: the direct light only).
    #[serde(default = "yes")]
    pub indirect: bool,
    /// The false-colour overlay.
    #[serde(default)]
    pub false_color: bool,
    /// Top of the false-colour scale, lux.
    #[serde(default = "thousand")]
    pub false_color_max: f64,
}

/// The surfaces' diffuse reflectances, each in [0, 1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneReflectances {
    /// The floor.
    pub floor: f64,
    /// The four walls.
    pub walls: f64,
    /// The ceiling.
    pub ceiling: f64,
}

impl Default for SceneReflectances {
    fn default() -> Self {
        lut_core::Reflectances::default().into()
    }
}

impl From<lut_core::Reflectances> for SceneReflectances {
    fn from(r: lut_core::Reflectances) -> Self {
        SceneReflectances {
            floor: r.floor,
            walls: r.walls,
            ceiling: r.ceiling,
        }
    }
}

impl From<SceneReflectances> for lut_core::Reflectances {
    fn from(r: SceneReflectances) -> Self {
        lut_core::Reflectances {
            floor: r.floor,
            walls: r.walls,
            ceiling: r.ceiling,
        }
    }
}

fn linear() -> String {
    Interpolation::Linear.name().into()
}
fn thousand() -> f64 {
    1000.0
}

/// Whether `text` looks like a scene file (a JSON object with `"format": "lutpano-scene"`),
/// for routing a dropped or opened file by its content.
pub fn is_scene(text: &str) -> bool {
    let t = text.trim_start();
    t.starts_with('{') && t.contains(FORMAT)
}

/// Whether the file at `path` is a scene file (reads at most its first 64 KiB).
pub fn is_scene_file(path: &Path) -> bool {
    use std::io::Read;
    // Regular files only: a FIFO must not block the drop handler or the command line.
    let Ok(f) = lut_core::open_regular(path) else {
        return false;
    };
    let mut head = Vec::new();
    if f.take(64 << 10).read_to_end(&mut head).is_err() {
        return false;
    }
    is_scene(&String::from_utf8_lossy(&head))
}

/// A path's components with `.` dropped and `name/..` folded.
fn clean(p: &Path) -> Vec<Component<'_>> {
    let mut out: Vec<Component<'_>> = Vec::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out
}

/// `target` relative to the folder `base` when both can be resolved (`..` as needed),
/// else `target` as given.
fn relative_to(base: &Path, target: &Path) -> PathBuf {
    let (Ok(b), Ok(t)) = (std::path::absolute(base), std::path::absolute(target)) else {
        return target.to_path_buf();
    };
    let (b, t) = (clean(&b), clean(&t));
    // Different roots (drives): keep the absolute path.
    if b.first() != t.first() {
        return t.iter().collect();
    }
    let common = b.iter().zip(&t).take_while(|(x, y)| x == y).count();
    let mut rel = PathBuf::new();
    for _ in common..b.len() {
        rel.push("..");
    }
    for c in &t[common..] {
        rel.push(c);
    }
    rel
}

impl SceneFile {
    /// The scene of a light state, the panorama shown (its file or folder, or a cube's
    /// face files; none for the bundled sample) and the view; paths relative to `dir`, the
    /// folder the file will be written to.
    pub fn from_state(
        state: &LightsState,
        panorama: &[PathBuf],
        view: Option<SceneView>,
        dir: &Path,
    ) -> SceneFile {
        let (w, d, h) = state.room;
        SceneFile {
            format: FORMAT.into(),
            version: VERSION,
            panorama: match panorama {
                [] => None,
                [one] => Some(ScenePanorama::One(relative_to(dir, one))),
                faces => Some(ScenePanorama::Faces(
                    faces.iter().map(|p| relative_to(dir, p)).collect(),
                )),
            },
            view,
            room: SceneRoom {
                width: w,
                depth: d,
                height: h,
                camera_height: state.camera_height,
                yaw: state.room_yaw,
                center: [state.room_center.0, state.room_center.1],
            },
            lights: state
                .lights
                .iter()
                .map(|l| SceneLight {
                    file: relative_to(dir, &l.path),
                    position: l.position,
                    yaw: l.yaw,
                    pitch: l.pitch,
                    multiplier: l.multiplier,
                    enabled: l.enabled,
                })
                .collect(),
            light_multiplier: state.multiplier,
            interpolation: state.interpolation.name().into(),
            exposure_lux: state.exposure_lux,
            auto_exposure: state.auto_exposure,
            ambient: state.ambient,
            reflectances: state.reflectances.into(),
            indirect: state.indirect,
            false_color: state.false_color,
            false_color_max: state.false_color_max,
        }
    }

    /// Read and check a scene file.
    ///
    /// # Errors
    /// An unreadable file, bad JSON or an unknown key (with its line and column), a
    /// format or version this viewer does not read, a view's hfov no projection takes,
    /// a view's pitch beyond ±90° or a yaw that is not finite.
    pub fn load(path: &Path) -> Result<SceneFile> {
        // The one reader for small input files: regular files only (a FIFO never
        // blocks), at most MAX_SCENE_FILE_BYTES.
        let bytes = lut_core::read_regular(path, lut_core::limits::MAX_SCENE_FILE_BYTES)
            .with_context(|| format!("{}: cannot read", path.display()))?;
        SceneFile::parse(&bytes, path)
    }

    /// Parse and check a scene file's bytes; `path` names it in errors (as
    /// [`SceneFile::load`], which reads the file first).
    ///
    /// # Errors
    /// As [`SceneFile::load`], but for reading the file.
    pub fn parse(bytes: &[u8], path: &Path) -> Result<SceneFile> {
        let text = std::str::from_utf8(bytes).map_err(|e| {
            anyhow::anyhow!(
                "{}: not a valid scene file: not UTF-8 text ({e})",
                path.display()
            )
        })?;
        // Behind the one containment, as every decoder.
        let scene: SceneFile = lut_core::contain(path, || {
            serde_json::from_str::<SceneFile>(text)
                .with_context(|| format!("{}: not a valid scene file", path.display()))
        })?;
        scene
            .check_limits()
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        if scene.format != FORMAT {
            bail!(
                "{}: \"format\" is '{}', expected '{FORMAT}'",
                path.display(),
                scene.format
            );
        }
        if matches!(&scene.panorama, Some(ScenePanorama::Faces(f)) if f.is_empty()) {
            bail!(
                "{}: \"panorama\" is an empty list (give a file, a folder or the cube's face files)",
                path.display()
            );
        }
        if scene.version != VERSION {
            bail!(
                "{}: scene file version {} (this viewer reads version {VERSION})",
                path.display(),
                scene.version
            );
        }
        // No view projection takes more (its own range is checked where the view is made).
        if let Some(v) = scene.view.filter(|v| !(v.hfov > 0.0 && v.hfov <= 360.0)) {
            bail!(
                "{}: \"view\": \"hfov\" is {}, expected more than 0 and at most 360 degrees",
                path.display(),
                v.hfov
            );
        }
        // A pitch beyond the poles is not a view (the window would clamp it silently).
        if let Some(v) = scene.view.filter(|v| !(-90.0..=90.0).contains(&v.pitch)) {
            bail!(
                "{}: \"view\": \"pitch\" is {}, expected -90 to 90 degrees",
                path.display(),
                v.pitch
            );
        }
        if let Some(v) = scene.view.filter(|v| !v.yaw.is_finite()) {
            bail!(
                "{}: \"view\": \"yaw\" is {}, expected a finite number of degrees",
                path.display(),
                v.yaw
            );
        }
        Ok(scene)
    }

    /// The limits module's checks on the numbers of a scene that size work: the room's
    /// sides, the number of luminaires (before any of their files is read), the
    /// multipliers.
    ///
    /// # Errors
    /// The first number over its limit, named with the limit.
    pub fn check_limits(&self) -> std::result::Result<(), lut_core::LimitError> {
        use lut_core::{check_limit, limits};
        let r = &self.room;
        for (name, v) in [
            ("\"room\": \"width\"", r.width),
            ("\"room\": \"depth\"", r.depth),
            ("\"room\": \"height\"", r.height),
        ] {
            check_limit(name, v.abs(), limits::MAX_ROOM_SIDE, " m")?;
        }
        check_limit(
            "\"lights\": luminaires",
            self.lights.len(),
            limits::MAX_LIGHTS,
            "",
        )?;
        check_limit(
            "\"light_multiplier\"",
            self.light_multiplier.abs(),
            limits::MAX_LIGHT_MULTIPLIER,
            "",
        )?;
        for (i, l) in self.lights.iter().enumerate() {
            check_limit(
                &format!("light {}: \"multiplier\"", i + 1),
                l.multiplier.abs(),
                limits::MAX_LIGHT_MULTIPLIER,
                "",
            )?;
        }
        Ok(())
    }

    /// Write the scene as pretty JSON, atomically (a temporary file renamed over the
    /// target, so an interrupted save never leaves half a file).
    ///
    /// # Errors
    /// The folder cannot be written.
    pub fn save(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self).context("scene to JSON")?;
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let mut tmp = tempfile::NamedTempFile::new_in(dir)
            .with_context(|| format!("{}: cannot write", path.display()))?;
        use std::io::Write;
        tmp.write_all(text.as_bytes())
            .and_then(|_| tmp.write_all(b"\n"))
            .with_context(|| format!("{}: cannot write", path.display()))?;
        tmp.persist(path)
            .with_context(|| format!("{}: cannot write", path.display()))?;
        Ok(())
    }

    /// The panorama's paths (one file or folder, or a cube's face files; none for the
    /// bundled sample) resolved against the scene file's folder `dir`.
    pub fn panorama_paths(&self, dir: &Path) -> Vec<PathBuf> {
        self.panorama.as_ref().map_or_else(Vec::new, |p| {
            p.paths().iter().map(|p| dir.join(p)).collect()
        })
    }

    /// The light state this scene describes: every luminaire file loaded (paths against
    /// `dir`), the room and shading checked.
    ///
    /// # Errors
    /// A luminaire file that does not load, an unknown interpolation, a room or light the
    /// scene cannot be built from (named).
    pub fn to_state(&self, dir: &Path) -> Result<LightsState> {
        let interpolation: Interpolation = parse_name(&self.interpolation).ok_or_else(|| {
            anyhow::anyhow!(
                "\"interpolation\" is '{}', expected {}",
                self.interpolation,
                lut_core::name_list::<Interpolation>()
            )
        })?;
        let r = &self.room;
        let mut st = LightsState {
            room: (r.width, r.depth, r.height),
            camera_height: r.camera_height,
            room_yaw: r.yaw,
            room_center: (r.center[0], r.center[1]),
            multiplier: self.light_multiplier,
            interpolation,
            exposure_lux: self.exposure_lux,
            auto_exposure: self.auto_exposure,
            ambient: self.ambient,
            reflectances: self.reflectances.into(),
            indirect: self.indirect,
            false_color: self.false_color,
            false_color_max: self.false_color_max,
            ..LightsState::default()
        };
        for (i, l) in self.lights.iter().enumerate() {
            let path = dir.join(&l.file);
            let table = st
                .table_for(&path)
                .with_context(|| format!("light {}", i + 1))?;
            st.lights.push(LightEntry {
                path,
                table,
                position: l.position,
                yaw: l.yaw,
                pitch: l.pitch,
                multiplier: l.multiplier,
                enabled: l.enabled,
            });
        }
        st.check()?;
        Ok(st)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths() {
        let p = |s: &str| PathBuf::from(s);
        assert_eq!(relative_to(&p("/a/b"), &p("/a/b/c.jpg")), p("c.jpg"));
        assert_eq!(relative_to(&p("/a/b"), &p("/a/x/c.ies")), p("../x/c.ies"));
        assert_eq!(relative_to(&p("/a/b/"), &p("/a/./b/../b/c")), p("c"));
        assert_eq!(relative_to(&p("/a"), &p("/z/q")), p("../z/q"));
    }

    #[test]
    fn scene_files_are_recognized_by_content() {
        assert!(is_scene(
            "  {\n \"format\": \"lutpano-scene\", \"version\": 1 }"
        ));
        assert!(!is_scene("IESNA:LM-63-2002"));
        assert!(!is_scene("[1, 2]"));
    }
}
