//! The lights in the window: the lit scene from the illuminance map, the room and
//! luminaires drawn over it, picking and dragging luminaires in the view, and scene files
//! opened and saved.

use super::App;
use crate::lighting::overlay::{
    drag_on_surface, drag_room_corner, drag_room_edge, drag_room_level, draw_room_and_lights,
    pick_light, pick_room_corner, pick_room_edge, project_point,
};
use crate::lighting::{legend::draw_legend, BakeKey, SceneFile, SceneView};
use crate::window::document::StartArgs;
use crate::window::loader::Source;
use crate::window::paint::SceneRect;
use lut_core::{Camera, IlluminanceMap, View};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How near (scene pixels) a click or press must be to a luminaire's marker to take it.
pub(super) const PICK_RADIUS: f64 = 12.0;
/// How near (scene pixels) a press must be to a room edge to drag it.
pub(super) const EDGE_RADIUS: f64 = 6.0;

/// What a drag in the view moves instead of turning the view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum SceneDrag {
    /// A luminaire (its index), along the face it is nearest to.
    Light(usize),
    /// A room corner (an index into `lut_core::Room::corners`): its two walls.
    Corner(usize),
    /// A room edge (an index into `lut_core::Room::EDGES`): its walls.
    Edge(usize),
    /// A floor or ceiling edge taken with Shift: the floor or ceiling, up or down.
    Level(usize),
}

impl App {
    /// The illuminance map for this frame (rebuilt, coarse first, when the lights
    /// changed); a scene that cannot be lit (a light outside the room) is reported in the
    /// panel.
    pub(super) fn update_lit(&mut self) -> Option<Arc<IlluminanceMap>> {
        self.update_solve();
        match self.lit.update(&mut self.lights, true) {
            Ok(map) => {
                self.lights.scene_error = None;
                map
            }
            Err(e) => {
                self.lights.scene_error = Some(e);
                None
            }
        }
    }

    /// The inter-reflections and the work plane's figures: ask the solving thread after
    /// each change of the luminaires, room or reflectances; take what it sent back for
    /// the lights as they are now (stale results are dropped) and hand its solve to the
    /// illuminance map; show the figures in the panel.
    fn update_solve(&mut self) {
        self.solver.request(&self.lights);
        let key = self.lights.geometry_key();
        if self.solver.poll(&key) {
            if let Some(s) = self.solver.latest() {
                self.lit.set_indirect(s.key.clone(), s.radiosity.clone());
            }
        }
        let line = crate::lighting::describe_work_plane(
            self.solver.latest().filter(|s| s.key == key),
            self.solver.pending(),
        );
        if line != self.lights.work_plane && self.print_view && !self.lights.lights.is_empty() {
            let _ = crate::outln!("work-plane {line}");
        }
        self.lights.work_plane = line;
        self.poll_report();
    }

    /// The Save dialog for a lighting report, beside the scene or panorama.
    pub(super) fn start_report_dialog(&mut self) {
        let near = self
            .scene_file
            .clone()
            .or(self.doc.last_file().map(Path::to_path_buf));
        let dir = near
            .as_deref()
            .and_then(Path::parent)
            .filter(|d| d.is_dir())
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
        self.dialogs
            .save_report(&self.egui_ctx, &dir, "report.html");
        if self.print_view {
            let _ = crate::outln!("dialog save-report {}", dir.display());
        }
    }

    /// Write the report of the panel's lights to `path` on a thread of its own (the
    /// radiosity solve and the grids take a while): `viewer report`'s computation
    /// ([`crate::commands::report::write_from_state`]), the lit view from the panorama
    /// shown. The outcome is a notice when it is done.
    pub(super) fn write_report(&mut self, path: PathBuf, t: f64) {
        let st = self.lights.clone();
        let mut pano = self.doc.current().map(|c| c.scene.share());
        let look = self.ctl.look();
        let view = [look.yaw_deg(), look.pitch_deg(), look.hfov_deg()];
        let (tx, rx) = std::sync::mpsc::channel();
        let proxy = self.proxy.clone();
        let spawned = std::thread::Builder::new()
            .name("viewer-report".into())
            .spawn(move || {
                let r = crate::commands::report::write_from_state(&st, pano.as_mut(), view, &path)
                    .map_err(|e| format!("report failed: {e:#}"));
                let _ = tx.send(r);
                let _ = proxy.send_event(super::AppEvent::Baked);
            });
        match spawned {
            Ok(_) => {
                self.report_job = Some(rx);
                self.notices.info("writing the report…", t);
            }
            Err(e) => {
                self.notices
                    .error(format!("report failed: cannot start its thread: {e}"), t);
            }
        }
    }

    /// A report written: its line as a notice (and on stdout with `--print-view`).
    fn poll_report(&mut self) {
        let Some(rx) = &self.report_job else {
            return;
        };
        let Ok(r) = rx.try_recv() else {
            return;
        };
        self.report_job = None;
        let t = self.now();
        let line = match r {
            Ok(l) => {
                self.notices.info(&l, t);
                l
            }
            Err(e) => {
                self.notices.error(&e, t);
                e
            }
        };
        if self.print_view {
            let _ = crate::outln!("{line}");
        }
    }

    /// Request the lit panorama's bake from `map` once the lighting has settled (the full
    /// map built, nothing dragged, the same lighting as on the frame before), take it when
    /// it has arrived from the baking thread (see [`crate::lighting::LitPanorama`]), and
    /// show its state in the panel. True when this frame pans the lit copy instead of
    /// lighting the frame.
    pub(super) fn update_baked(&mut self, map: Option<&Arc<IlluminanceMap>>) -> bool {
        let settled = !self.lit.refining() && self.scene_drag.is_none();
        let key = map.map(|_| BakeKey {
            map_generation: self.lit.generation(),
            scene_generation: self.doc.generation(),
            shade: self.lights.shade_options(),
        });
        let Some(cur) = self.doc.current() else {
            return false;
        };
        let on = self.baked.update(key, settled, map, &cur.scene);
        self.lights.lit_panorama = self.baked.state().describe();
        on
    }

    /// Light the freshly rendered scene from `unlit` (the map, when the render did not
    /// light the rows as it drew them; as `viewer render` does), then draw the room and
    /// luminaires ("Show room") and, when the scene is lit (`map`), the false colours'
    /// legend over it.
    pub(super) fn light_scene(
        &mut self,
        map: Option<&IlluminanceMap>,
        unlit: Option<&IlluminanceMap>,
        view: View,
        r: SceneRect,
    ) {
        let (w, h) = (r.w, r.h);
        if let Some(map) = unlit {
            let cam = Camera::new(view, w, h);
            let opts = self.lights.shade_options();
            if let Err(e) = map.shade_frame(&cam, &mut self.scene, w, h, &opts) {
                self.lights.scene_error = Some(e.to_string());
            }
        }
        let l = &self.lights;
        let mut result = Ok(());
        if l.show_room {
            result = draw_room_and_lights(l, view, &mut self.scene, w, h);
        }
        if l.false_color && map.is_some() {
            result = result.and(draw_legend(&mut self.scene, w, h, l.false_color_max));
        }
        if let Err(e) = result {
            self.lights.scene_error = Some(e);
        }
        if self.print_view && self.lights.show_room {
            self.print_markers(view, r);
        }
    }

    /// `--print-view`: where each luminaire's marker is in the scene (pixels), when that
    /// changed: "markers 1=X,Y 2=X,Y" (lights behind the camera left out).
    fn print_markers(&mut self, view: View, r: SceneRect) {
        let Ok(room) = self.lights.room_box() else {
            return;
        };
        let cam = Camera::new(view, r.w, r.h);
        let line: Vec<String> = self
            .lights
            .lights
            .iter()
            .enumerate()
            .filter_map(|(i, l)| {
                let (x, y) = project_point(&room, &cam, l.position.into())?;
                Some(format!("{}={x:.0},{y:.0}", i + 1))
            })
            .collect();
        // And the middle of each room edge in view: "edges K=X,Y" (K into Room::EDGES).
        let c = room.corners();
        let edges: Vec<String> = lut_core::Room::EDGES
            .iter()
            .enumerate()
            .filter_map(|(k, &(i, j))| {
                let pieces = crate::lighting::overlay::edge_pieces(&room, &cam, c[i], c[j]);
                let ((x0, y0), (x1, y1)) = *pieces.get(pieces.len() / 2)?;
                let (x, y) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
                let inside = x >= 0.0 && y >= 0.0 && x < r.w as f64 && y < r.h as f64;
                inside.then(|| format!("{k}={x:.0},{y:.0}"))
            })
            .collect();
        // And each room corner in view: "corners K=X,Y" (K into Room::corners).
        let corners: Vec<String> = c
            .iter()
            .enumerate()
            .filter_map(|(k, &p)| {
                let (x, y) = project_point(&room, &cam, p)?;
                let inside = x >= 0.0 && y >= 0.0 && x < r.w as f64 && y < r.h as f64;
                inside.then(|| format!("{k}={x:.0},{y:.0}"))
            })
            .collect();
        let line = format!(
            "markers {}\nedges {}\ncorners {}",
            line.join(" "),
            edges.join(" "),
            corners.join(" ")
        );
        if line != self.printed_markers {
            let _ = crate::outln!("{line}");
            self.printed_markers = line;
        }
    }

    /// `--print-view`: the selection.
    fn print_selection(&self) {
        if self.print_view {
            match self.lights.selected {
                Some(i) => {
                    let _ = crate::outln!("light {} selected", i + 1);
                }
                None => {
                    let _ = crate::outln!("no light selected");
                }
            }
        }
    }

    /// A click on the scene at `at` (scene pixels): select the luminaire whose marker is
    /// there (the room shown), or clear the selection.
    pub(super) fn click_scene(&mut self, at: (f64, f64), size: (u32, u32)) {
        if !self.lights.show_room {
            return;
        }
        let view = self.ctl.look();
        self.lights.selected = pick_light(&self.lights, view, size.0, size.1, at, PICK_RADIUS);
        self.print_selection();
    }

    /// A drag starts at `at`: on a luminaire's marker (the room shown) it moves that
    /// luminaire, on a corner of the room box the two walls meeting there, on an edge that
    /// edge's walls, and with `shift` held on a floor or ceiling edge the floor or the
    /// ceiling, instead of turning the view. True when one of them was taken.
    pub(super) fn press_light(&mut self, at: (f64, f64), size: (u32, u32), shift: bool) -> bool {
        self.scene_drag = self.pick_scene_drag(at, size, shift);
        if let Some(SceneDrag::Light(i)) = self.scene_drag {
            self.lights.selected = Some(i);
            self.print_selection();
        }
        self.scene_drag.is_some()
    }

    /// What a press at `at` takes (see [`App::press_light`]).
    fn pick_scene_drag(&self, at: (f64, f64), size: (u32, u32), shift: bool) -> Option<SceneDrag> {
        if !self.lights.show_room {
            return None;
        }
        let view = self.ctl.look();
        if let Some(i) = pick_light(&self.lights, view, size.0, size.1, at, PICK_RADIUS) {
            return Some(SceneDrag::Light(i));
        }
        let cam = Camera::new(view, size.0, size.1);
        let room = self.lights.room_box().ok()?;
        if shift {
            // Only the floor and ceiling edges have a level to take.
            let e = pick_room_edge(&room, &cam, at, EDGE_RADIUS)?;
            let (i, j) = lut_core::Room::EDGES[e];
            return (i & 2 == j & 2).then_some(SceneDrag::Level(e));
        }
        // A corner first (it lies on three edges), then an edge.
        pick_room_corner(&room, &cam, at, EDGE_RADIUS)
            .map(SceneDrag::Corner)
            .or_else(|| pick_room_edge(&room, &cam, at, EDGE_RADIUS).map(SceneDrag::Edge))
    }

    /// The dragged luminaire follows the cursor along the face it is nearest to; a
    /// dragged room corner or edge moves its walls to the cursor, a dragged level its
    /// floor or ceiling. Where the cursor's ray misses the plane the drag follows, the
    /// room stays as it is.
    pub(super) fn drag_light(&mut self, at: (f64, f64), size: (u32, u32)) {
        let Ok(room) = self.lights.room_box() else {
            return;
        };
        let cam = Camera::new(self.ctl.look(), size.0, size.1);
        let walls = match self.scene_drag {
            Some(SceneDrag::Corner(c)) => drag_room_corner(&room, &cam, c, at),
            Some(SceneDrag::Edge(e)) => drag_room_edge(&room, &cam, e, at),
            Some(SceneDrag::Level(e)) => {
                if let Some((h, c)) = drag_room_level(&room, &cam, e, at) {
                    self.lights.room.2 = h;
                    self.lights.camera_height = c;
                }
                return;
            }
            Some(SceneDrag::Light(i)) => {
                if let Some(l) = self.lights.lights.get_mut(i) {
                    if let Some(p) = drag_on_surface(&room, &cam, l.position.into(), at) {
                        l.position = p.into();
                    }
                }
                return;
            }
            None => return,
        };
        if let Some((w, d, cx, cz)) = walls {
            self.lights.room.0 = w;
            self.lights.room.1 = d;
            self.lights.room_center = (cx, cz);
        }
    }

    /// The drag of a luminaire or of the room ended (`--print-view`: where it is now).
    pub(super) fn end_light_drag(&mut self) {
        let Some(drag) = self.scene_drag.take() else {
            return;
        };
        if !self.print_view {
            return;
        }
        if let SceneDrag::Light(i) = drag {
            if let Some(l) = self.lights.lights.get(i) {
                let [x, y, z] = l.position;
                let _ = crate::outln!("light {} moved to {x:.3},{y:.3},{z:.3}", i + 1);
            }
        } else {
            let (w, d, h) = self.lights.room;
            let (cx, cz) = self.lights.room_center;
            let c = self.lights.camera_height;
            let _ = crate::outln!("room {w:.3}x{d:.3}x{h:.3} centre {cx:.3},{cz:.3} camera {c:.3}");
        }
    }

    /// A panorama opened on its own: the previous scene's room, luminaires and scene
    /// file go (the text typed in the "IES file" field stays).
    pub(super) fn new_scene(&mut self) {
        let had = !self.lights.lights.is_empty() || self.scene_file.is_some();
        let path_input = std::mem::take(&mut self.lights.path_input);
        // The window's default: the exposure follows the lights (`window::run`).
        self.lights = crate::lighting::LightsState {
            path_input,
            auto_exposure: true,
            ..crate::lighting::LightsState::default()
        };
        self.scene_file = None;
        if had {
            let t = self.now();
            self.notices.info(
                "a new panorama: the previous scene's room and lights are cleared",
                t,
            );
        }
    }

    /// Open a scene file: its room, luminaires and exposure replace the panel's; its
    /// panorama (if it names one) opens at its view. Errors are notices.
    pub(super) fn open_scene(&mut self, path: PathBuf) {
        let t = self.now();
        let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
        let loaded = SceneFile::load(&path).and_then(|f| Ok((f.to_state(&dir)?, f)));
        let (mut state, file) = match loaded {
            Ok(x) => x,
            Err(e) => {
                self.notices.error(format!("{e:#}"), t);
                return;
            }
        };
        state.path_input = std::mem::take(&mut self.lights.path_input);
        state.show_room = self.lights.show_room;
        self.lights = state;
        self.scene_file = Some(path.clone());
        self.prefs.panel = true;
        self.notices.info(format!("scene {}", path.display()), t);
        let paths = file.panorama_paths(&dir);
        if let Some(p) = paths.first().cloned() {
            let start = file.view.map_or_else(StartArgs::default, |v| StartArgs {
                yaw: Some(v.yaw),
                pitch: Some(v.pitch),
                hfov: Some(v.hfov),
            });
            let source = Source::of_paths(paths, false, None).unwrap_or(Source::File(p));
            let fx = self
                .doc
                .open(source, None, start, self.ctl.settings.exposure_ev);
            self.apply(vec![fx]);
        }
    }

    /// The Save dialog for a scene file, beside the scene opened last (else the
    /// panorama's folder).
    pub(super) fn start_save_scene_dialog(&mut self) {
        let near = self
            .scene_file
            .clone()
            .or(self.doc.last_file().map(Path::to_path_buf));
        let dir = near
            .as_deref()
            .and_then(Path::parent)
            .filter(|d| d.is_dir())
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
        let name = match (&self.scene_file, self.doc.last_file()) {
            (Some(s), _) => s.file_name().map(|n| n.to_string_lossy().into_owned()),
            (None, Some(p)) => p
                .file_stem()
                .map(|s| format!("{}.json", s.to_string_lossy())),
            (None, None) => None,
        };
        let name = name.unwrap_or_else(|| "scene.json".into());
        self.dialogs.save_scene(&self.egui_ctx, &dir, &name);
        if self.print_view {
            let _ = crate::outln!("dialog save-scene {}", dir.display());
        }
    }

    /// Write the scene (the panorama shown, the view, the panel's lights) to `path`.
    pub(super) fn save_scene_to(&mut self, path: &Path, t: f64) {
        let panorama = self
            .doc
            .current()
            .map_or_else(Vec::new, |c| c.source.paths());
        let look = self.ctl.look();
        let view = SceneView {
            yaw: look.yaw_deg(),
            pitch: look.pitch_deg(),
            hfov: look.hfov_deg(),
        };
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let file = SceneFile::from_state(&self.lights, &panorama, Some(view), dir);
        let status = match file.save(path) {
            Ok(()) => {
                self.scene_file = Some(path.to_path_buf());
                let msg = format!("saved scene {}", path.display());
                self.notices.info(&msg, t);
                msg
            }
            Err(e) => {
                let msg = format!("save failed: {e:#}");
                self.notices.error(&msg, t);
                msg
            }
        };
        if self.print_view {
            let _ = crate::outln!("{status}");
        }
    }
}
