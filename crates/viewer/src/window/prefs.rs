//! Settings kept between runs: panel shown, anti-aliasing mode, sampler, drag style,
//! inertia, zoom limit, auto-rotation, export scale, recent files and the save folder,
//! as JSON in the user's config folder (`$XDG_CONFIG_HOME/lutpano/settings.json`, else
//! `~/.config/lutpano/`, or the platform's equivalent through the `directories` crate;
//! [`CONFIG_DIR_ENV`] overrides it, which the tests use so they never touch the real
//! home). Option values are stored by their panel names (`lut_core::Named`).
//!
//! A missing file gives the defaults; a file that cannot be read gives the defaults and a
//! message (the window shows it), and is replaced on the next save.

use super::input::DragStyle;
use super::quality::AaMode;
use anyhow::{Context, Result};
use lut_core::Sampler;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Environment variable naming the config folder (tests, portable setups).
pub const CONFIG_DIR_ENV: &str = "LUTPANO_CONFIG_DIR";
/// The settings file in the config folder.
pub const FILE_NAME: &str = "settings.json";
/// Recent files kept.
pub const MAX_RECENT: usize = 10;
/// The default zoom limit: the narrowest view shows one map pixel over this many screen
/// pixels.
pub const DEFAULT_ZOOM_LIMIT: f64 = 2.0;

/// The settings kept between runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Prefs {
    /// The engineering panel is shown.
    pub panel: bool,
    /// Anti-aliasing mode.
    #[serde(with = "by_name")]
    pub aa: AaMode,
    /// Sampler of full-quality frames.
    #[serde(with = "by_name")]
    pub sampler: Sampler,
    /// Drag style.
    #[serde(with = "by_name")]
    pub drag: DragStyle,
    /// Inertia after a grab drag.
    pub inertia: bool,
    /// Zoom limit: screen pixels per map pixel at the narrowest view; `None`: off (any
    /// hfov down to 1°, for inspection).
    pub zoom_limit: Option<f64>,
    /// Auto-rotation on.
    pub auto_rotate: bool,
    /// Auto-rotation speed, degrees per second.
    pub auto_rotate_speed: f64,
    /// Seconds without input before auto-rotation starts.
    pub auto_rotate_idle_s: f64,
    /// "Save view…": the scene's size times this.
    pub export_scale: u32,
    /// Recently opened files and folders, newest first.
    pub recent: Vec<PathBuf>,
    /// The folder "Save view…" last wrote to.
    pub save_dir: Option<PathBuf>,
}

impl Default for Prefs {
    fn default() -> Self {
        let s = super::quality::Settings::default();
        let a = super::input::AutoRotate::default();
        Prefs {
            panel: false,
            aa: s.aa,
            sampler: s.sampler,
            drag: s.drag,
            inertia: s.inertia,
            zoom_limit: Some(DEFAULT_ZOOM_LIMIT),
            auto_rotate: a.enabled,
            auto_rotate_speed: a.speed_deg_s,
            auto_rotate_idle_s: a.idle_s,
            export_scale: s.export_scale,
            recent: Vec::new(),
            save_dir: None,
        }
    }
}

/// Option values by their `Named` names.
mod by_name {
    use lut_core::{name_list, parse_name, Named};
    use serde::{de::Error, Deserialize, Deserializer, Serializer};

    pub fn serialize<T: Named, S: Serializer>(v: &T, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(v.name())
    }

    pub fn deserialize<'de, T: Named, D: Deserializer<'de>>(d: D) -> Result<T, D::Error> {
        let s = String::deserialize(d)?;
        parse_name(&s).ok_or_else(|| {
            D::Error::custom(format!(
                "unknown value '{s}' (expected {})",
                name_list::<T>()
            ))
        })
    }
}

/// The config folder: [`CONFIG_DIR_ENV`] when set, else the platform's (XDG on Linux);
/// `None` when there is no home to put it in.
pub fn config_dir() -> Option<PathBuf> {
    match std::env::var_os(CONFIG_DIR_ENV) {
        Some(d) if !d.is_empty() => Some(PathBuf::from(d)),
        _ => directories::ProjectDirs::from("", "", "lutpano").map(|d| d.config_dir().into()),
    }
}

impl Prefs {
    /// The settings in `dir`: the defaults when there are none yet; the defaults and a
    /// message naming the file when it cannot be read or parsed.
    pub fn load(dir: &Path) -> (Prefs, Option<String>) {
        let path = dir.join(FILE_NAME);
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return (Prefs::default(), None),
            Err(e) => return (Prefs::default(), Some(bad(&path, &e.to_string()))),
        };
        match serde_json::from_str::<Prefs>(&text) {
            Ok(p) => (p.sanitized(), None),
            Err(e) => (Prefs::default(), Some(bad(&path, &e.to_string()))),
        }
    }

    /// Write the settings to `dir` (created if missing), atomically.
    ///
    /// # Errors
    /// The folder cannot be created or the file written (naming it).
    pub fn save(&self, dir: &Path) -> Result<()> {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create the config folder {}", dir.display()))?;
        let json = serde_json::to_string_pretty(self)?;
        crate::output::write_image_atomic(&dir.join(FILE_NAME), |w| {
            w.write_all(json.as_bytes())?;
            Ok(())
        })
    }

    /// Values outside their ranges replaced by the defaults (a hand-edited file must not
    /// make the window misbehave).
    fn sanitized(mut self) -> Prefs {
        let d = Prefs::default();
        if !self.zoom_limit.is_none_or(|z| z.is_finite() && z > 0.0) {
            self.zoom_limit = d.zoom_limit;
        }
        if !(self.auto_rotate_speed.is_finite() && self.auto_rotate_speed.abs() <= 360.0) {
            self.auto_rotate_speed = d.auto_rotate_speed;
        }
        if !(self.auto_rotate_idle_s.is_finite() && self.auto_rotate_idle_s >= 0.0) {
            self.auto_rotate_idle_s = d.auto_rotate_idle_s;
        }
        if !super::input::EXPORT_SCALES.contains(&self.export_scale) {
            self.export_scale = d.export_scale;
        }
        self.recent.truncate(MAX_RECENT);
        self
    }

    /// `path` was opened: first in the recent list, once, at most [`MAX_RECENT`] kept.
    pub fn add_recent(&mut self, path: PathBuf) {
        self.recent.retain(|p| *p != path);
        self.recent.insert(0, path);
        self.recent.truncate(MAX_RECENT);
    }

    /// `path` is gone: out of the recent list.
    pub fn remove_recent(&mut self, path: &Path) {
        self.recent.retain(|p| p != path);
    }
}

fn bad(path: &Path, why: &str) -> String {
    format!(
        "settings {} not read ({why}); using the defaults",
        path.display()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_round_trip_through_the_file() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("lutpano");
        let (p, msg) = Prefs::load(&dir);
        assert_eq!((p.clone(), msg), (Prefs::default(), None), "no file yet");
        let mut p = Prefs {
            panel: true,
            aa: AaMode::StillOnly,
            sampler: Sampler::Bilinear,
            drag: DragStyle::Qtvr,
            inertia: false,
            zoom_limit: None,
            auto_rotate: true,
            auto_rotate_speed: -7.5,
            auto_rotate_idle_s: 10.0,
            export_scale: 4,
            recent: vec![],
            save_dir: Some(PathBuf::from("/pictures")),
        };
        p.add_recent(PathBuf::from("/a/one.jpg"));
        p.add_recent(PathBuf::from("/a/two.jpg"));
        p.save(&dir).unwrap();
        let text = std::fs::read_to_string(dir.join(FILE_NAME)).unwrap();
        assert!(
            text.contains("\"Still only\"") && text.contains("\"QTVR\""),
            "{text}"
        );
        let (q, msg) = Prefs::load(&dir);
        assert_eq!(msg, None);
        assert_eq!(q, p);
        // Only the written file is left (atomic write: no temporary file).
        let files: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
        assert_eq!(files.len(), 1);
    }

    #[test]
    fn bad_files_give_the_defaults_and_say_why() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join(FILE_NAME);
        for (text, why) in [
            ("{not json", "key must be a string"),
            (r#"{"aa": "Sometimes"}"#, "unknown value 'Sometimes'"),
            (r#"{"colour": 3}"#, "unknown field"),
        ] {
            std::fs::write(&path, text).unwrap();
            let (p, msg) = Prefs::load(tmp.path());
            assert_eq!(p, Prefs::default());
            let msg = msg.expect("a message");
            assert!(msg.contains(FILE_NAME) && msg.contains(why), "{msg}");
        }
        // Missing fields take their defaults; values out of range are reset.
        std::fs::write(
            &path,
            r#"{"panel": true, "zoom_limit": -1, "export_scale": 3, "auto_rotate_speed": 1e9}"#,
        )
        .unwrap();
        let (p, msg) = Prefs::load(tmp.path());
        assert_eq!(msg, None);
        assert!(p.panel);
        let d = Prefs::default();
        assert_eq!(
            (p.zoom_limit, p.export_scale, p.auto_rotate_speed),
            (d.zoom_limit, d.export_scale, d.auto_rotate_speed)
        );
        // `null` switches the zoom limit off.
        std::fs::write(&path, r#"{"zoom_limit": null}"#).unwrap();
        assert_eq!(Prefs::load(tmp.path()).0.zoom_limit, None);
    }

    #[test]
    fn recent_list_newest_first_once_bounded() {
        let mut p = Prefs::default();
        for i in 0..15 {
            p.add_recent(PathBuf::from(format!("/p/{i}.jpg")));
        }
        assert_eq!(p.recent.len(), MAX_RECENT);
        assert_eq!(p.recent[0], PathBuf::from("/p/14.jpg"));
        assert_eq!(p.recent[MAX_RECENT - 1], PathBuf::from("/p/5.jpg"));
        p.add_recent(PathBuf::from("/p/9.jpg"));
        assert_eq!(p.recent[0], PathBuf::from("/p/9.jpg"));
        assert_eq!(
            p.recent.len(),
            MAX_RECENT,
            "moved to the front, not added twice"
        );
        assert_eq!(
            p.recent
                .iter()
                .filter(|r| r.as_path() == Path::new("/p/9.jpg"))
                .count(),
            1
        );
        p.remove_recent(Path::new("/p/9.jpg"));
        assert_eq!(p.recent[0], PathBuf::from("/p/14.jpg"));
    }

    #[test]
    fn the_config_dir_env_var_wins() {
        // Read only: the variable is not set by the test harness.
        if std::env::var_os(CONFIG_DIR_ENV).is_none() {
            if let Some(d) = config_dir() {
                assert!(d.ends_with("lutpano"), "{}", d.display());
            }
        }
    }
}
