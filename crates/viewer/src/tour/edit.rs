//! Editing a tour: the operations (add, change, delete hotspots; a scene's start view,
//! north and horizon; add and remove scenes; the first scene) and the undo stack.
//!
//! Pure: no window. Each [`Op`] applied to a [`Tour`] gives back its inverse, so undo
//! applies the inverse and redo the inverse of that. The window (`crate::window::tour`)
//! builds the ops from the pointer and the panel; saving is the Pannellum writer's
//! (`super::pannellum::write`).

use super::{Angles, Horizon, Hotspot, HotspotKind, Source, Target, Tour, TourScene};
use serde_json::Map;
use std::path::{Component, Path};

/// Undo steps kept (the oldest are dropped past this).
pub const MAX_UNDO: usize = 1000;

/// One change to a tour.
#[derive(Debug, Clone, PartialEq)]
pub enum Op {
    /// Insert `hotspot` into scene `scene` at `index`.
    InsertHotspot {
        /// The scene's index.
        scene: usize,
        /// Where in its list.
        index: usize,
        /// The hotspot.
        hotspot: Box<Hotspot>,
    },
    /// Remove hotspot `index` of scene `scene`.
    RemoveHotspot {
        /// The scene's index.
        scene: usize,
        /// The hotspot's index.
        index: usize,
    },
    /// Replace hotspot `index` of scene `scene` (a move, a new text or target).
    SetHotspot {
        /// The scene's index.
        scene: usize,
        /// The hotspot's index.
        index: usize,
        /// Its new value.
        hotspot: Box<Hotspot>,
    },
    /// A scene's start view.
    SetStart {
        /// The scene's index.
        scene: usize,
        /// The view.
        start: Angles,
    },
    /// A scene's `northOffset`.
    SetNorth {
        /// The scene's index.
        scene: usize,
        /// Degrees.
        north: f64,
    },
    /// A scene's horizon correction.
    SetHorizon {
        /// The scene's index.
        scene: usize,
        /// Pitch and roll.
        horizon: Horizon,
    },
    /// Insert `scene` at `index`.
    InsertScene {
        /// Where.
        index: usize,
        /// The scene.
        scene: Box<TourScene>,
    },
    /// Remove scene `index` (its links elsewhere are removed by [`remove_scene`]).
    RemoveScene {
        /// The scene's index.
        index: usize,
    },
    /// The tour's first scene.
    SetFirst {
        /// Its id.
        id: String,
    },
    /// Several ops as one step, applied in order.
    Batch(Vec<Op>),
}

fn bad(what: &str) -> String {
    format!("no such {what} in the tour (the edit is stale)")
}

/// Apply `op` to `tour`; returns the op that undoes it.
///
/// # Errors
/// An index out of range or a repeated scene id: the tour is unchanged.
pub fn apply(tour: &mut Tour, op: Op) -> Result<Op, String> {
    Ok(match op {
        Op::InsertHotspot {
            scene,
            index,
            hotspot,
        } => {
            let s = tour.scenes.get_mut(scene).ok_or_else(|| bad("scene"))?;
            if index > s.hotspots.len() {
                return Err(bad("hotspot"));
            }
            s.hotspots.insert(index, *hotspot);
            Op::RemoveHotspot { scene, index }
        }
        Op::RemoveHotspot { scene, index } => {
            let s = tour.scenes.get_mut(scene).ok_or_else(|| bad("scene"))?;
            if index >= s.hotspots.len() {
                return Err(bad("hotspot"));
            }
            let hotspot = Box::new(s.hotspots.remove(index));
            Op::InsertHotspot {
                scene,
                index,
                hotspot,
            }
        }
        Op::SetHotspot {
            scene,
            index,
            hotspot,
        } => {
            let h = tour
                .scenes
                .get_mut(scene)
                .and_then(|s| s.hotspots.get_mut(index))
                .ok_or_else(|| bad("hotspot"))?;
            let old = Box::new(std::mem::replace(h, *hotspot));
            Op::SetHotspot {
                scene,
                index,
                hotspot: old,
            }
        }
        Op::SetStart { scene, start } => {
            let s = tour.scenes.get_mut(scene).ok_or_else(|| bad("scene"))?;
            let old = std::mem::replace(&mut s.start, start);
            Op::SetStart { scene, start: old }
        }
        Op::SetNorth { scene, north } => {
            let s = tour.scenes.get_mut(scene).ok_or_else(|| bad("scene"))?;
            let old = std::mem::replace(&mut s.north_offset, north);
            Op::SetNorth { scene, north: old }
        }
        Op::SetHorizon { scene, horizon } => {
            let s = tour.scenes.get_mut(scene).ok_or_else(|| bad("scene"))?;
            let old = std::mem::replace(&mut s.horizon, horizon);
            Op::SetHorizon {
                scene,
                horizon: old,
            }
        }
        Op::InsertScene { index, scene } => {
            if index > tour.scenes.len() {
                return Err(bad("scene"));
            }
            if tour.scene(&scene.id).is_some() {
                return Err(format!("a scene \"{}\" is already in the tour", scene.id));
            }
            tour.scenes.insert(index, *scene);
            Op::RemoveScene { index }
        }
        Op::RemoveScene { index } => {
            if index >= tour.scenes.len() {
                return Err(bad("scene"));
            }
            let scene = Box::new(tour.scenes.remove(index));
            Op::InsertScene { index, scene }
        }
        Op::SetFirst { id } => {
            let old = std::mem::replace(&mut tour.first_scene, id);
            Op::SetFirst { id: old }
        }
        Op::Batch(ops) => {
            let mut undo = Vec::with_capacity(ops.len());
            for op in ops {
                match apply(tour, op) {
                    Ok(u) => undo.push(u),
                    Err(e) => {
                        // Leave the tour as it was.
                        for u in undo.into_iter().rev() {
                            let _ = apply(tour, u);
                        }
                        return Err(e);
                    }
                }
            }
            undo.reverse();
            Op::Batch(undo)
        }
    })
}

/// The op removing scene `index` with every link to it from the other scenes, and
/// naming another first scene when it was the first.
pub fn remove_scene(tour: &Tour, index: usize) -> Option<Op> {
    let id = &tour.scenes.get(index)?.id;
    let mut ops = Vec::new();
    for (si, s) in tour.scenes.iter().enumerate() {
        if si == index {
            continue;
        }
        // From the last, so the indices of the ones before stay right.
        for (hi, h) in s.hotspots.iter().enumerate().rev() {
            if matches!(&h.kind, HotspotKind::Scene { scene_id, .. } if scene_id == id) {
                ops.push(Op::RemoveHotspot {
                    scene: si,
                    index: hi,
                });
            }
        }
    }
    if tour.first().map(|f| &f.id) == Some(id) {
        let next = tour
            .scenes
            .iter()
            .find(|s| s.id != *id)
            .map_or(String::new(), |s| s.id.clone());
        ops.push(Op::SetFirst { id: next });
    }
    ops.push(Op::RemoveScene { index });
    Some(Op::Batch(ops))
}

/// A new hotspot at (`yaw`, `pitch`): a link to scene `target` (arriving at that scene's
/// start view), or, `None`, an info hotspot.
pub fn new_hotspot(yaw: f64, pitch: f64, text: &str, target: Option<&str>) -> Hotspot {
    Hotspot {
        yaw: wrap180(yaw),
        pitch: pitch.clamp(-90.0, 90.0),
        text: text.to_string(),
        kind: match target {
            Some(id) => HotspotKind::Scene {
                scene_id: id.to_string(),
                target: Target::default(),
            },
            None => HotspotKind::Info { url: None },
        },
        line: 0,
        place: String::new(),
        extra: Map::new(),
    }
}

/// `a` wrapped to [-180, 180).
pub fn wrap180(a: f64) -> f64 {
    (a + 180.0).rem_euclid(360.0) - 180.0
}

/// The `northOffset` that makes the view at `yaw` face north (a heading is
/// `northOffset + yaw`).
pub fn north_facing(yaw: f64) -> f64 {
    let n = wrap180(-yaw);
    if n == -0.0 {
        0.0
    } else {
        n
    }
}

/// A new scene for the panorama `file` (an equirectangular image inside the tour's
/// folder), its id made from the file name and unique in the tour.
///
/// # Errors
/// The file is not inside the tour's folder (a saved tour names paths relative to it).
pub fn scene_for_file(tour: &Tour, file: &Path) -> Result<TourScene, String> {
    let rel = relative_inside(&tour.dir, file).ok_or_else(|| {
        format!(
            "{}: not inside the tour's folder {}: copy it there to add it",
            file.display(),
            tour.dir.display()
        )
    })?;
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "scene".into());
    let mut id = stem.clone();
    let mut n = 2;
    while tour.scene(&id).is_some() {
        id = format!("{stem}-{n}");
        n += 1;
    }
    Ok(TourScene {
        id,
        title: Some(stem),
        source: Source::Equirect(rel),
        start: super::DEFAULT_START,
        north_offset: 0.0,
        horizon: Horizon::default(),
        hotspots: Vec::new(),
        line: 0,
        source_line: 0,
        extra: Map::new(),
    })
}

/// `file` relative to `dir` with `/` separators, when it is inside it (both made
/// absolute; no `..` after that).
pub fn relative_inside(dir: &Path, file: &Path) -> Option<String> {
    let d = std::path::absolute(dir).ok()?;
    let f = std::path::absolute(file).ok()?;
    let rest = f.strip_prefix(&d).ok()?;
    let parts: Vec<String> = rest
        .components()
        .map(|c| match c {
            Component::Normal(p) => Some(p.to_string_lossy().into_owned()),
            _ => None,
        })
        .collect::<Option<_>>()?;
    (!parts.is_empty()).then(|| parts.join("/"))
}

/// A tour and its edits: the undo and redo stacks, and whether it changed since saved.
#[derive(Debug, Clone)]
pub struct History {
    undo: Vec<(String, Op)>,
    redo: Vec<(String, Op)>,
    /// Steps since the last save (negative after undoing past it; `None`: unreachable).
    since_save: Option<i64>,
}

impl Default for History {
    fn default() -> Self {
        History::new()
    }
}

impl History {
    /// A history with nothing to undo, the tour as saved.
    pub fn new() -> History {
        History {
            undo: Vec::new(),
            redo: Vec::new(),
            since_save: Some(0),
        }
    }

    /// Apply `op` (named `what`, for the undo button's tip) to `tour` as a new step; the
    /// redo stack is dropped.
    ///
    /// # Errors
    /// As [`apply`]: nothing changes.
    pub fn edit(&mut self, tour: &mut Tour, what: &str, op: Op) -> Result<(), String> {
        let inv = apply(tour, op)?;
        self.undo.push((what.to_string(), inv));
        if self.undo.len() > MAX_UNDO {
            self.undo.remove(0);
        }
        self.redo.clear();
        self.since_save = match self.since_save {
            // The saved state can no longer be reached by redo.
            Some(n) if n < 0 => None,
            Some(n) => Some(n + 1),
            None => None,
        };
        Ok(())
    }

    /// Undo the last step; returns its name.
    pub fn undo(&mut self, tour: &mut Tour) -> Option<String> {
        let (what, op) = self.undo.pop()?;
        match apply(tour, op) {
            Ok(inv) => {
                self.redo.push((what.clone(), inv));
                self.since_save = self.since_save.map(|n| n - 1);
                Some(what)
            }
            Err(_) => {
                // A stale step (cannot happen when every change goes through here).
                self.undo.clear();
                self.redo.clear();
                None
            }
        }
    }

    /// Redo the last undone step; returns its name.
    pub fn redo(&mut self, tour: &mut Tour) -> Option<String> {
        let (what, op) = self.redo.pop()?;
        match apply(tour, op) {
            Ok(inv) => {
                self.undo.push((what.clone(), inv));
                self.since_save = self.since_save.map(|n| n + 1);
                Some(what)
            }
            Err(_) => {
                self.undo.clear();
                self.redo.clear();
                None
            }
        }
    }

    /// The names of the next undo and redo steps.
    pub fn next(&self) -> (Option<&str>, Option<&str>) {
        (
            self.undo.last().map(|u| u.0.as_str()),
            self.redo.last().map(|r| r.0.as_str()),
        )
    }

    /// Whether the tour differs from what was last saved (or opened).
    pub fn modified(&self) -> bool {
        self.since_save != Some(0)
    }

    /// The tour was saved as it is now.
    pub fn saved(&mut self) {
        self.since_save = Some(0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tour::pannellum as write;

    fn sample() -> Tour {
        let loaded = crate::tour::load(&test_support::test_data("tours/pannellum/tour.json"))
            .expect("the test tour opens");
        assert!(loaded.problems.is_empty(), "{:?}", loaded.problems);
        loaded.tour
    }

    /// Scenes, hotspots and views as saved: what a round trip must keep.
    fn summary(t: &Tour) -> String {
        let mut s = format!("first={}\n", t.first().map_or("", |f| f.id.as_str()));
        for sc in &t.scenes {
            s += &format!(
                "{} {:?} {:?} start={:?} north={} horizon={:?}\n",
                sc.id, sc.title, sc.source, sc.start, sc.north_offset, sc.horizon
            );
            for h in &sc.hotspots {
                s += &format!("  {} {} {:?} {:?}\n", h.yaw, h.pitch, h.text, h.kind);
            }
        }
        s
    }

    #[test]
    fn each_op_undoes_and_redoes_to_the_same_tour() {
        let t0 = sample();
        let link = new_hotspot(370.0, -100.0, "To the cube", Some("courtyardCube"));
        assert_eq!((link.yaw, link.pitch), (10.0, -90.0), "wrapped and clamped");
        let mut moved = t0.scenes[0].hotspots[1].clone();
        moved.yaw = 33.0;
        moved.pitch = 4.0;
        let extra = scene_for_file(
            &t0,
            &test_support::test_data("tours/pannellum/interior.jpg"),
        )
        .unwrap();
        assert_eq!(extra.id, "interior-2", "the id is unique in the tour");
        assert_eq!(extra.source, Source::Equirect("interior.jpg".into()));
        let ops = vec![
            Op::InsertHotspot {
                scene: 1,
                index: 2,
                hotspot: Box::new(link),
            },
            Op::InsertHotspot {
                scene: 0,
                index: 0,
                hotspot: Box::new(new_hotspot(1.0, 2.0, "A note", None)),
            },
            Op::RemoveHotspot { scene: 0, index: 2 },
            Op::SetHotspot {
                scene: 0,
                index: 1,
                hotspot: Box::new(moved),
            },
            Op::SetStart {
                scene: 2,
                start: Angles {
                    yaw: 45.0,
                    pitch: 10.0,
                    hfov: 75.0,
                },
            },
            Op::SetNorth {
                scene: 1,
                north: north_facing(100.0),
            },
            Op::SetHorizon {
                scene: 0,
                horizon: Horizon {
                    pitch: 2.5,
                    roll: -1.5,
                },
            },
            Op::InsertScene {
                index: 3,
                scene: Box::new(extra),
            },
            Op::SetFirst {
                id: "interior".into(),
            },
            remove_scene(&t0, 1).unwrap(),
        ];
        for op in ops {
            let mut t = t0.clone();
            let mut h = History::new();
            h.edit(&mut t, "op", op.clone()).unwrap();
            assert_ne!(t, t0, "{op:?} changes the tour");
            assert!(h.modified());
            let after = t.clone();
            assert_eq!(h.undo(&mut t).as_deref(), Some("op"));
            assert_eq!(t, t0, "undo of {op:?}");
            assert!(!h.modified());
            assert_eq!(h.redo(&mut t).as_deref(), Some("op"));
            assert_eq!(t, after, "redo of {op:?}");
            assert!(h.undo(&mut t).is_some() && h.undo(&mut t).is_none());
            assert_eq!(t, t0);
        }
    }

    #[test]
    fn removing_a_scene_takes_its_links_and_first_place_with_it() {
        let mut t = sample();
        let mut h = History::new();
        let op = remove_scene(&t, 0).unwrap();
        h.edit(&mut t, "remove courtyard", op).unwrap();
        assert_eq!(t.scenes.len(), 2);
        assert_eq!(t.first().unwrap().id, "interior");
        assert_eq!(t.first_scene, "interior");
        for s in &t.scenes {
            for hs in &s.hotspots {
                assert!(
                    !matches!(&hs.kind, HotspotKind::Scene { scene_id, .. } if scene_id == "courtyard"),
                    "a link to the removed scene is left in {}",
                    s.id
                );
            }
        }
        // interior kept its info hotspot, lost its one link.
        assert_eq!(t.scenes[0].hotspots.len(), 1);
        assert_eq!(t.scenes[1].hotspots.len(), 0);
        h.undo(&mut t);
        assert_eq!(t, sample());
    }

    #[test]
    fn a_bad_op_changes_nothing_and_a_new_edit_drops_the_redo() {
        let t0 = sample();
        let mut t = t0.clone();
        let mut h = History::new();
        let bad = Op::Batch(vec![
            Op::SetNorth {
                scene: 0,
                north: 5.0,
            },
            Op::RemoveHotspot {
                scene: 0,
                index: 99,
            },
        ]);
        assert!(h.edit(&mut t, "bad", bad).is_err());
        assert_eq!(t, t0, "a failed batch is rolled back");
        assert_eq!(h.next(), (None, None));
        let dup = Op::InsertScene {
            index: 0,
            scene: Box::new(t0.scenes[1].clone()),
        };
        assert!(apply(&mut t, dup).unwrap_err().contains("already"));
        h.edit(
            &mut t,
            "north",
            Op::SetNorth {
                scene: 0,
                north: 1.0,
            },
        )
        .unwrap();
        h.undo(&mut t);
        assert_eq!(h.next(), (None, Some("north")));
        h.edit(
            &mut t,
            "start",
            Op::SetStart {
                scene: 0,
                start: crate::tour::DEFAULT_START,
            },
        )
        .unwrap();
        assert_eq!(h.next(), (Some("start"), None));
        assert!(h.redo(&mut t).is_none());
        // Undone past the save, then a new edit: the saved state is out of reach.
        h.saved();
        h.undo(&mut t);
        h.edit(
            &mut t,
            "north",
            Op::SetNorth {
                scene: 0,
                north: 2.0,
            },
        )
        .unwrap();
        h.undo(&mut t);
        assert!(h.modified());
    }

    #[test]
    fn an_edited_tour_saved_and_read_again_has_the_same_scenes_hotspots_and_views() {
        let mut t = sample();
        let mut h = History::new();
        let dir = tempfile::tempdir().unwrap();
        // The tour's images are beside the saved file (paths relative to it).
        for f in ["courtyard.jpg", "interior.jpg"] {
            std::fs::copy(
                test_support::test_data(&format!("tours/pannellum/{f}")),
                dir.path().join(f),
            )
            .unwrap();
        }
        t.dir = dir.path().to_path_buf();
        let ops = vec![
            Op::InsertHotspot {
                scene: 1,
                index: 0,
                hotspot: Box::new(new_hotspot(
                    -12.5,
                    7.25,
                    "To the cube",
                    Some("courtyardCube"),
                )),
            },
            Op::InsertHotspot {
                scene: 2,
                index: 1,
                hotspot: Box::new(new_hotspot(90.0, -30.0, "Note \"quoted\" é", None)),
            },
            Op::SetStart {
                scene: 1,
                start: Angles {
                    yaw: -100.0,
                    pitch: 12.0,
                    hfov: 65.0,
                },
            },
            Op::SetNorth {
                scene: 2,
                north: north_facing(30.0),
            },
            Op::SetHorizon {
                scene: 1,
                horizon: Horizon {
                    pitch: -3.0,
                    roll: 1.25,
                },
            },
            Op::InsertScene {
                index: 3,
                scene: Box::new(scene_for_file(&t, &dir.path().join("interior.jpg")).unwrap()),
            },
            Op::SetFirst {
                id: "interior".into(),
            },
        ];
        for op in ops {
            h.edit(&mut t, "e", op).unwrap();
        }
        let file = dir.path().join("edited.json");
        let left_out = write::save(&t, &file).unwrap();
        assert!(left_out.is_empty());
        let back = crate::tour::load(&file).unwrap();
        assert!(
            back.problems.iter().all(|p| p.message.contains("cube")
                || p.message.contains("not found")
                || p.message.contains("No such")),
            "{:?}",
            back.problems
        );
        assert_eq!(summary(&back.tour), summary(&t));
        assert_eq!(back.tour.first_scene, "interior");
    }

    #[test]
    fn north_and_paths() {
        assert_eq!(north_facing(30.0), -30.0);
        assert_eq!(north_facing(-170.0), 170.0);
        assert_eq!(north_facing(0.0), 0.0);
        let d = Path::new("/a/tour");
        assert_eq!(
            relative_inside(d, Path::new("/a/tour/pano/x.jpg")).as_deref(),
            Some("pano/x.jpg")
        );
        assert_eq!(relative_inside(d, Path::new("/a/other/x.jpg")), None);
        assert_eq!(relative_inside(d, Path::new("/a/tour")), None);
        let t = Tour::new(d.into());
        assert!(scene_for_file(&t, Path::new("/b/x.jpg"))
            .unwrap_err()
            .contains("not inside"));
    }

    #[test]
    fn a_marzipano_tour_saved_as_pannellum_starts_in_a_scene_it_saves() {
        let src = test_support::test_data("tours/marzipano/data.js");
        let mut t = crate::tour::load(&src).unwrap().tour;
        assert_eq!(t.first_scene, "0-courtyard");
        // Levels three times apart: no Pannellum multires form.
        for s in &mut t.scenes {
            if let crate::tour::Source::MarzipanoTiles { levels, .. } = &mut s.source {
                *levels = vec![(16, 16, true), (16, 32, false), (48, 96, false)];
            }
        }
        let dir = tempfile::tempdir().unwrap();
        std::fs::copy(
            test_support::test_data("tours/pannellum/interior.jpg"),
            dir.path().join("room.jpg"),
        )
        .unwrap();
        t.dir = dir.path().to_path_buf();
        let room = scene_for_file(&t, &dir.path().join("room.jpg")).unwrap();
        let mut h = History::new();
        h.edit(
            &mut t,
            "add",
            Op::InsertScene {
                index: 2,
                scene: Box::new(room),
            },
        )
        .unwrap();
        // The tiles scenes have no Pannellum form: the saved tour must not start in one.
        let file = dir.path().join("tour.json");
        let left_out = write::save(&t, &file).unwrap();
        assert_eq!(left_out.len(), 2);
        for (entry, id) in left_out.iter().zip(["0-courtyard", "1-interior"]) {
            assert!(
                entry.starts_with(&format!("{id}: ")) && entry.contains("tiles of 16 and 48 px"),
                "{entry}"
            );
        }
        let back = crate::tour::load(&file).unwrap();
        assert_eq!(back.tour.first_scene, "room");
        assert!(
            !back.problems.iter().any(|p| p.place.contains("firstScene")),
            "{:?}",
            back.problems
        );
        // A tour whose first scene is saved keeps it.
        h.edit(&mut t, "first", Op::SetFirst { id: "room".into() })
            .unwrap();
        let (text, _) = write::to_text(&t);
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["default"]["firstScene"], "room");
    }
}
