//! Tours: several panoramas linked by hotspots, as people make them for the web with
//! Pannellum (a JSON tour or single-scene config) or the Marzipano tool (`data.js`).
//!
//! * [`Tour`]: the model (scenes, their start views, north, horizon, hotspots), the one
//!   form every reader produces and the writer saves; angles in degrees in this
//!   project's conventions (yaw positive to the right, pitch positive up: Pannellum's own;
//!   Marzipano's radians and downward pitch are converted on reading).
//! * [`pannellum`]: read a tour or single-scene config, write one Pannellum opens.
//! * [`marzipano`]: read a Marzipano tool export (`data.js` and its `tiles/`).
//! * [`check`]: every link, file and scene id (`viewer tour check`).
//! * [`edit`]: the edit operations and their undo stack (the window's editor).
//! * [`markers`]: hotspot markers drawn on a rendered view.
//! * [`level`]: the horizon line and the correction that drags it (the level mode).
//!
//! Reading never stops at the first problem: each bad scene or hotspot is left out with a
//! [`Problem`] naming its place (line and path in the file), and the rest of the tour
//! opens.

pub mod check;
pub mod edit;
pub mod level;
pub mod literal;
pub mod markers;
pub mod marzipano;
pub mod pannellum;
pub mod render;

use std::fmt;
use std::path::{Component, Path, PathBuf};

/// More hotspots than this in one scene are refused (the rest of the scene opens).
pub const MAX_HOTSPOTS: usize = lut_core::limits::MAX_TOUR_HOTSPOTS;
/// More scenes than this in one tour are refused.
pub const MAX_SCENES: usize = lut_core::limits::MAX_TOUR_SCENES;

/// A tour: its scenes and the one it starts in.
#[derive(Debug, Clone, PartialEq)]
pub struct Tour {
    /// The folder paths are relative to (the config's folder).
    pub dir: PathBuf,
    /// The first scene's id (Pannellum's `default.firstScene`).
    pub first_scene: String,
    /// The scenes in file order.
    pub scenes: Vec<TourScene>,
    /// Crossfade between scenes, milliseconds (Pannellum's `sceneFadeDuration`).
    pub fade_ms: Option<f64>,
    /// The tour's title, when it has one.
    pub title: Option<String>,
    /// Members of `default` not interpreted here, kept for saving.
    pub default_extra: serde_json::Map<String, serde_json::Value>,
    /// Members of a tour config's root other than `default` and `scenes` (Pannellum
    /// merges them over every scene), kept for saving at the root as they were: moved
    /// into `default`, the scene options among them would change meaning (and were lost
    /// on the next save; found by the tour_pannellum fuzz target).
    pub root_extra: serde_json::Map<String, serde_json::Value>,
    /// Whether it came from a single-scene config (saved as a tour anyway).
    pub single: bool,
}

/// One panorama of a tour.
#[derive(Debug, Clone, PartialEq)]
pub struct TourScene {
    /// Its id (the key in Pannellum's `scenes`, Marzipano's `id`).
    pub id: String,
    /// Its title (Pannellum `title`, Marzipano `name`).
    pub title: Option<String>,
    /// Where its pixels are.
    pub source: Source,
    /// The view it starts at.
    pub start: Angles,
    /// Compass heading of the panorama's centre column, degrees (`northOffset`).
    pub north_offset: f64,
    /// The horizon correction (Pannellum `horizonPitch`/`horizonRoll`).
    pub horizon: Horizon,
    /// Its hotspots.
    pub hotspots: Vec<Hotspot>,
    /// The line of the scene in its file (0 when made in the window).
    pub line: usize,
    /// The line of its image path(s) in its file (0 when made in the window).
    pub source_line: usize,
    /// Members not interpreted here, kept for saving.
    pub extra: serde_json::Map<String, serde_json::Value>,
}

/// A view: yaw, pitch, horizontal field of view, degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Angles {
    /// Yaw, positive to the right.
    pub yaw: f64,
    /// Pitch, positive up.
    pub pitch: f64,
    /// Horizontal field of view.
    pub hfov: f64,
}

/// Pannellum's default start view: yaw 0, pitch 0, hfov 100.
pub const DEFAULT_START: Angles = Angles {
    yaw: 0.0,
    pitch: 0.0,
    hfov: 100.0,
};

/// The pitch and roll of a panorama's horizon, degrees (Pannellum's `horizonPitch` and
/// `horizonRoll`, GPano's `PosePitchDegrees` and `PoseRollDegrees`): what is rotated
/// away before projection so the horizon is level.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Horizon {
    /// Pitch of the image's horizon.
    pub pitch: f64,
    /// Roll of the image's horizon.
    pub roll: f64,
}

impl Horizon {
    /// No correction.
    pub fn is_level(&self) -> bool {
        self.pitch == 0.0 && self.roll == 0.0
    }
}

/// Where a scene's pixels are (paths as written, relative to the tour's folder).
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    /// An equirectangular image (`panorama`).
    Equirect(String),
    /// Six faces, front, right, back, left, up, down (`cubeMap`; `None`: a missing face).
    Cube(Vec<Option<String>>),
    /// Pannellum's multiresolution cube tiles (`multiRes`, kept as written).
    Multires(serde_json::Value),
    /// A Marzipano tool scene: `tiles/<id>/<z>/<face>/<y>/<x>.jpg`.
    MarzipanoTiles {
        /// The scene's tile folder (`tiles/<id>`).
        dir: String,
        /// `levels` as written: (tileSize, size, fallbackOnly).
        levels: Vec<(u32, u32, bool)>,
        /// `faceSize`.
        face_size: u32,
    },
}

/// A hotspot.
#[derive(Debug, Clone, PartialEq)]
pub struct Hotspot {
    /// Its direction: yaw, degrees, positive to the right.
    pub yaw: f64,
    /// Its direction: pitch, degrees, positive up.
    pub pitch: f64,
    /// The text shown on hover.
    pub text: String,
    /// A link to a scene or information.
    pub kind: HotspotKind,
    /// The line in its file (0 when made in the window).
    pub line: usize,
    /// Its place in its file (`scenes.hall.hotSpots[2]`; empty when made in the window).
    pub place: String,
    /// Members not interpreted here, kept for saving.
    pub extra: serde_json::Map<String, serde_json::Value>,
}

/// What a hotspot does.
#[derive(Debug, Clone, PartialEq)]
pub enum HotspotKind {
    /// Goes to another scene.
    Scene {
        /// The target scene's id.
        scene_id: String,
        /// The view it arrives at.
        target: Target,
    },
    /// Shows text (and a link).
    Info {
        /// `URL`, when given.
        url: Option<String>,
    },
}

/// The view a scene link arrives at (each part: a value, the current view's, or the
/// target scene's own start view).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Target {
    /// `targetYaw`.
    pub yaw: TargetAngle,
    /// `targetPitch`.
    pub pitch: TargetAngle,
    /// `targetHfov`.
    pub hfov: TargetAngle,
}

/// One part of a [`Target`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum TargetAngle {
    /// Not given: the target scene's start view.
    #[default]
    Scene,
    /// A value in degrees.
    Value(f64),
    /// `"same"`: the current view's value.
    Same,
    /// `"sameAzimuth"` (yaw only): the same compass direction, through both scenes'
    /// `northOffset`.
    SameAzimuth,
}

/// A problem found in a tour: where, and what.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// The file.
    pub file: PathBuf,
    /// The line (0: the file as a whole).
    pub line: usize,
    /// The place inside the file: `scenes.hall.hotSpots[2].sceneId`.
    pub place: String,
    /// What is wrong.
    pub message: String,
}

/// A number as people write it: `1e300`, not three hundred digits.
pub fn num_text(x: f64) -> String {
    if x != 0.0 && (x.abs() >= 1e7 || x.abs() < 1e-4) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// One line, escaped and shortened as every echoed text ([`lut_core::one_line`]): the
/// place and the message repeat ids and paths from the file.
impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut s = self.file.display().to_string();
        if self.line > 0 {
            s += &format!(":{}", self.line);
        }
        if !self.place.is_empty() {
            s += &format!(": {}", self.place);
        }
        s += &format!(": {}", self.message);
        f.write_str(&lut_core::one_line(&s))
    }
}

/// A tour read from a file, with the problems met (each left out of the tour).
#[derive(Debug, Clone)]
pub struct Loaded {
    /// What opened.
    pub tour: Tour,
    /// What did not, each with its place.
    pub problems: Vec<Problem>,
}

/// Which format a file is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// A Pannellum JSON config (tour or single scene).
    Pannellum,
    /// A Marzipano tool `data.js`.
    Marzipano,
}

/// Whether `path` is a tour file, by its content whatever its name: a text that assigns
/// `APP_DATA` (`var APP_DATA = {`: a Marzipano export's `data.js`, renamed or not; not
/// the app's `index.js`, which only reads `window.APP_DATA`), or a JSON object (a `.json`
/// file, or any text starting with `{`) with `scenes`/`firstScene` or `panorama`/
/// `cubeMap`/`multiRes`/`hotSpots` (Pannellum). Reads at most the first 64 KiB; a file
/// with a NUL byte there (an image) is none.
pub fn sniff(path: &Path) -> Option<Format> {
    use std::io::Read;
    let json_ext = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let f = lut_core::open_regular(path).ok()?;
    let mut head = Vec::new();
    f.take(64 * 1024).read_to_end(&mut head).ok()?;
    if head.contains(&0) {
        return None;
    }
    let t = String::from_utf8_lossy(&head);
    let body = t.trim_start_matches('\u{feff}').trim_start();
    if !body.starts_with('{') && assigns_app_data(&t) {
        return Some(Format::Marzipano);
    }
    if !json_ext && !body.starts_with('{') {
        return None;
    }
    let keys = [
        "\"scenes\"",
        "\"firstScene\"",
        "\"panorama\"",
        "\"cubeMap\"",
        "\"multiRes\"",
        "\"hotSpots\"",
    ];
    keys.iter()
        .any(|k| t.contains(k))
        .then_some(Format::Pannellum)
}

/// Whether `text` assigns `APP_DATA` (`APP_DATA =`, not `==`), as Marzipano's `data.js`
/// does.
pub fn assigns_app_data(text: &str) -> bool {
    text.match_indices("APP_DATA").any(|(at, k)| {
        let rest = text[at + k.len()..].trim_start();
        rest.starts_with('=') && !rest.starts_with("==")
    })
}

/// Largest tour file read ([`lut_core::limits::MAX_TOUR_FILE_BYTES`]).
pub const MAX_FILE_BYTES: u64 = lut_core::limits::MAX_TOUR_FILE_BYTES;

/// Read a tour file of either format (by [`sniff`], else by extension): read as every
/// small input file is ([`lut_core::read_regular`]: a FIFO or device is refused without
/// blocking, the size limited), parsed behind the decoders' one containment
/// ([`lut_core::contain`]).
///
/// # Errors
/// The file cannot be read, is not a tour, or has a syntax error (one line, with the
/// line number): nothing opens. Problems within scenes are in [`Loaded::problems`].
pub fn load(path: &Path) -> anyhow::Result<Loaded> {
    let bytes = lut_core::read_regular(path, MAX_FILE_BYTES)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    lut_core::contain(path, || parse(&bytes, path))
}

/// Read a tour from its bytes (`path` names it and gives its folder and format).
///
/// # Errors
/// As [`load`] (without the containment: [`load`] adds it).
pub fn parse(bytes: &[u8], path: &Path) -> anyhow::Result<Loaded> {
    lut_core::fault_point("decoder");
    let text = std::str::from_utf8(bytes)
        .map_err(|_| anyhow::anyhow!("{}: not UTF-8 text: not a tour config", path.display()))?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    // A Marzipano export by its content (`APP_DATA =`), whatever the file's name.
    let is_js = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("js"))
        || (!text
            .trim_start_matches('\u{feff}')
            .trim_start()
            .starts_with('{')
            && assigns_app_data(text));
    if is_js {
        marzipano::read(text, path, &dir)
    } else {
        pannellum::read(text, path, &dir)
    }
}

/// Why a path of a tour cannot be used.
pub fn path_problem(rel: &str) -> Option<String> {
    if rel.is_empty() {
        return Some("an empty path".into());
    }
    if rel.contains("://") || rel.starts_with("data:") || rel.starts_with("//") {
        return Some(format!(
            "\"{rel}\" is a URL: only files beside the tour open (offline)"
        ));
    }
    let p = Path::new(rel);
    if p.is_absolute() || rel.starts_with('/') || rel.starts_with('\\') {
        return Some(format!(
            "\"{rel}\" is an absolute path: paths are relative to the tour's folder"
        ));
    }
    if p.components()
        .any(|c| matches!(c, Component::ParentDir | Component::Prefix(_)))
    {
        return Some(format!("\"{rel}\" leaves the tour's folder (..): refused"));
    }
    None
}

impl Tour {
    /// An empty tour in `dir`.
    pub fn new(dir: PathBuf) -> Tour {
        Tour {
            dir,
            first_scene: String::new(),
            scenes: Vec::new(),
            fade_ms: None,
            title: None,
            default_extra: serde_json::Map::new(),
            root_extra: serde_json::Map::new(),
            single: false,
        }
    }

    /// The scene with id `id`.
    pub fn scene(&self, id: &str) -> Option<&TourScene> {
        self.scenes.iter().find(|s| s.id == id)
    }

    /// The index of the scene with id `id`.
    pub fn index(&self, id: &str) -> Option<usize> {
        self.scenes.iter().position(|s| s.id == id)
    }

    /// The scene it starts in: `first_scene`, else the first.
    pub fn first(&self) -> Option<&TourScene> {
        self.scene(&self.first_scene).or(self.scenes.first())
    }

    /// A path of the tour as a file path (relative to [`Tour::dir`]).
    ///
    /// # Errors
    /// The path is a URL, absolute, or leaves the tour's folder.
    pub fn resolve(&self, rel: &str) -> Result<PathBuf, String> {
        match path_problem(rel) {
            Some(p) => Err(p),
            None => Ok(self.dir.join(rel)),
        }
    }

    /// The folder a Pannellum multires scene's tiles are in (`multiRes` block `m`): the
    /// tour's folder plus its `basePath`.
    ///
    /// # Errors
    /// `basePath` leaves the tour's folder or is a URL (one line naming the scene).
    pub fn multires_base(&self, scene: &str, m: &serde_json::Value) -> Result<PathBuf, String> {
        let base = m.get("basePath").and_then(|b| b.as_str()).unwrap_or("");
        let base = base.trim_start_matches("./").trim_start_matches('/');
        if base.is_empty() || base == "." {
            Ok(self.dir.clone())
        } else {
            self.resolve(base)
                .map_err(|why| format!("scene \"{scene}\": {why}"))
        }
    }

    /// The pyramid a Pannellum multires scene's inline `multiRes` numbers describe
    /// (`tileResolution`, `maxLevel`, `cubeResolution`, `path`, `extension`, under
    /// [`Tour::multires_base`]), read as a `config.json` is; `file` names it in errors.
    ///
    /// # Errors
    /// The numbers or the template are refused ([`lut_core::MultiresConfig::parse`]).
    pub fn multires_config(
        &self,
        file: &Path,
        m: &serde_json::Value,
    ) -> Result<lut_core::MultiresConfig, String> {
        let mut m = m.clone();
        if let Some(o) = m.as_object_mut() {
            // Relative to the tour's folder, as the reader keeps it.
            let b = o
                .get("basePath")
                .and_then(|b| b.as_str())
                .unwrap_or("")
                .trim_start_matches("./")
                .to_string();
            if b.is_empty() || b == "." {
                o.remove("basePath");
            } else {
                o.insert("basePath".into(), serde_json::Value::String(b));
            }
        }
        let one = serde_json::json!({ "type": "multires", "multiRes": m });
        lut_core::MultiresConfig::parse(one.to_string().as_bytes(), file, &self.dir)
            .map_err(|e| e.to_string())
    }

    /// The pyramid folder of a Pannellum multires scene whose `multiRes` block is `m`:
    /// the tour's folder plus `basePath`, when it holds the `config.json` that
    /// Pannellum's `generate.py` and `viewer tile` write, or else when the scene's own
    /// inline `multiRes` numbers describe a pyramid there (the folder then opens through
    /// the config that describes it, [`crate::panorama::pannellum_inline`]).
    ///
    /// # Errors
    /// `basePath` leaves the tour's folder or is a URL, or the folder holds no pyramid
    /// and the inline numbers are refused: one line naming the scene.
    pub fn multires_dir(&self, scene: &str, m: &serde_json::Value) -> Result<PathBuf, String> {
        let dir = self.multires_base(scene, m)?;
        if !dir.is_dir() {
            return Err(format!(
                "scene \"{scene}\": its basePath {} is not a folder",
                dir.display()
            ));
        }
        if dir.join("config.json").is_file() {
            return Ok(dir);
        }
        match self.multires_config(&dir, m) {
            Ok(_) => Ok(dir),
            Err(e) => Err(format!(
                "scene \"{scene}\": no config.json in {} and its multiRes numbers are refused: {e}",
                dir.display()
            )),
        }
    }

    /// The view a scene link from `from` (the current scene, seen at `current`) arrives
    /// at, in the target scene: Pannellum's rules (`same`, `sameAzimuth`, or the target's
    /// start view for parts not given). `None` if the target is not in the tour.
    pub fn arrival(
        &self,
        from: &TourScene,
        current: Angles,
        link: &Hotspot,
    ) -> Option<(usize, Angles)> {
        let HotspotKind::Scene { scene_id, target } = &link.kind else {
            return None;
        };
        let i = self.index(scene_id)?;
        let to = &self.scenes[i];
        let pick = |t: TargetAngle, own: f64, cur: f64| match t {
            TargetAngle::Scene => own,
            TargetAngle::Value(v) => v,
            TargetAngle::Same => cur,
            TargetAngle::SameAzimuth => cur + from.north_offset - to.north_offset,
        };
        let yaw = pick(target.yaw, to.start.yaw, current.yaw);
        Some((
            i,
            Angles {
                yaw: (yaw + 180.0).rem_euclid(360.0) - 180.0,
                pitch: pick(target.pitch, to.start.pitch, current.pitch).clamp(-90.0, 90.0),
                hfov: pick(target.hfov, to.start.hfov, current.hfov),
            },
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tours_are_recognised_by_content_whatever_their_name() {
        let d = tempfile::tempdir().unwrap();
        let put = |name: &str, text: &[u8]| {
            let p = d.path().join(name);
            std::fs::write(&p, text).unwrap();
            p
        };
        let js = "// the tour\nvar APP_DATA = {\"scenes\": []};\n";
        for name in ["data.js", "tour-data.js", "tour.txt", "APP"] {
            assert_eq!(
                sniff(&put(name, js.as_bytes())),
                Some(Format::Marzipano),
                "{name}"
            );
        }
        // The export's app reads APP_DATA; it assigns none.
        let app = "var data = window.APP_DATA;\nif (data == APP_DATA) {}\n";
        assert_eq!(sniff(&put("index.js", app.as_bytes())), None);
        let json = r#"{"default": {"firstScene": "a"}, "scenes": {}}"#;
        assert_eq!(
            sniff(&put("tour.json", json.as_bytes())),
            Some(Format::Pannellum)
        );
        assert_eq!(
            sniff(&put("tour.cfg", json.as_bytes())),
            Some(Format::Pannellum)
        );
        // A binary file naming APP_DATA is not a tour.
        let mut bin = b"\xff\xd8\x00\x10 var APP_DATA = {}".to_vec();
        bin.push(0);
        assert_eq!(sniff(&put("x.jpg", &bin)), None);
        // And a renamed data.js reads as Marzipano: its scene, its angles converted.
        let t = r#"// comment naming APP_DATA first
var APP_DATA = {"scenes": [{"id": "0-a", "name": "A", "levels": [{"tileSize": 64, "size": 64}],
  "faceSize": 64, "initialViewParameters": {"yaw": 0, "pitch": 0.1, "fov": 1.2},
  "linkHotspots": [], "infoHotspots": []}], "name": "t"};"#;
        let loaded = load(&put("my tour.txt", t.as_bytes())).unwrap();
        assert_eq!(loaded.tour.scenes.len(), 1, "{:?}", loaded.problems);
        assert!(loaded.tour.scenes[0].start.pitch < 0.0, "pitch negated");
    }

    #[test]
    fn paths_that_leave_the_folder_are_refused() {
        assert!(path_problem("pano/a.jpg").is_none());
        assert!(path_problem("a b.jpg").is_none());
        for bad in [
            "../a.jpg",
            "a/../../b.jpg",
            "/etc/passwd",
            "http://x/a.jpg",
            "",
        ] {
            assert!(path_problem(bad).is_some(), "{bad}");
        }
    }
}
