//! The window's document: what is shown, what is loading, the last error, the files
//! dropped. A pure state machine — no window, no thread, no clock: its methods take what
//! happened (a load's progress or result, a drop, a panel action) and return the
//! [`Effect`]s the event loop carries out (start a load, set the title, print a line,
//! show the panel), so every transition is unit-tested like `input.rs`.
//!
//! Rules:
//! * A load runs in the background; the current panorama stays until it is done, and
//!   stays if it fails. A newer load supersedes an older one: the older one's reports
//!   are ignored.
//! * A failed load shows its error (a notice over the scene); with nothing to show yet the
//!   bundled sample opens under the message (its success keeps the message). Any other
//!   successful load clears the error.
//! * A panorama *opened* (command line, drop, Open dialog, recent list, PageUp/PageDown)
//!   starts at its own start view: the command line's `--yaw/--pitch/--hfov` for the file
//!   named there, else the file's GPano start view, else the default. A *reload* (another
//!   projection, another exposure) keeps the view.
//! * Exposure changes while an exposure reload runs wait for it, then the latest one
//!   loads (a slider dragged across the range decodes a few times, not once per frame).
//! * The panel's projection choice reopens the file it applies to: the current one, or
//!   the one that failed.
//! * Paths dropped in one event batch open together, each judged by its content:
//!   luminaire files (IES, EULUMDAT) add lights, a scene file opens, the rest is one
//!   panorama or cube map. A file opened from the dialog or the recent list likewise.

use super::loader::{LoadRequest, Loaded, Source};
use super::ui::{LoadStatus, LoadStep, Readouts};
use crate::lighting::{file_kind, FileKind};
use lut_core::{Coverage, EnvMap, LoadOptions, Naming, Projection, StartView, Tone};
use std::path::PathBuf;

/// A report from the loading thread.
pub enum LoadEvent {
    /// A step's progress.
    Progress {
        /// Which load.
        id: u64,
        /// The step it is in.
        step: LoadStep,
        /// Done fraction of the step, when known.
        fraction: Option<f32>,
    },
    /// The load finished.
    Done {
        /// Which load.
        id: u64,
        /// The panorama, or the error (one line).
        result: Result<Box<Loaded>, String>,
    },
}

/// What the event loop does for the document.
#[derive(Debug, Clone, PartialEq)]
pub enum Effect {
    /// Run this load on a loading thread and report back through
    /// [`Document::on_event`] (or [`Document::load_not_started`]).
    Load(LoadRequest),
    /// Add a light for each of these (dropped or opened) IES or EULUMDAT files.
    AddLights(Vec<PathBuf>),
    /// Open this scene file: its room, luminaires and exposure, its panorama and view.
    OpenScene(PathBuf),
    /// The window title.
    Title(String),
    /// A line for stdout with `--print-view`.
    PrintView(String),
    /// A message for stderr.
    Stderr(String),
    /// Show the panel: there is something to read in it.
    ShowPanel,
    /// A panorama was opened: go to its start view.
    StartView(StartView),
    /// A panorama was opened on its own (the Open dialog, the recent list, PageUp/Down,
    /// a drop without luminaires or a scene): the previous scene's room, lights and
    /// scene file go.
    NewScene,
    /// This file or folder was opened (for the recent list).
    Opened(PathBuf),
}

/// The start view given on the command line: each value given overrides the file's.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StartArgs {
    /// `--yaw`.
    pub yaw: Option<f64>,
    /// `--pitch`.
    pub pitch: Option<f64>,
    /// `--hfov`.
    pub hfov: Option<f64>,
}

/// A load in progress.
struct Loading {
    id: u64,
    source: Source,
    status: LoadStatus,
    /// Opened (not a reload): goes to its start view.
    opening: bool,
    /// A reload for another exposure.
    exposure: bool,
    /// A panorama opened on its own (not with a scene, its lights or the command
    /// line's): the previous scene's room and lights go when it is shown.
    new_scene: bool,
}

/// The document state (see the module docs for its rules).
pub struct Document {
    current: Option<Box<Loaded>>,
    /// Bumped for every panorama shown (cached frames of the old one are stale).
    generation: u64,
    /// Projection chosen in the panel for the current (or failed) file.
    projection: Option<Projection>,
    /// The source the projection choice applies to: the current one, or a failed one.
    projection_source: Option<Source>,
    loading: Option<Loading>,
    next_id: u64,
    error: Option<String>,
    /// The running load is the fallback after a failed one: its success keeps the error.
    keep_error: bool,
    /// Paths dropped since the last event batch: one drop of several items arrives as one
    /// event per item, and they open together (six face files are one cube map).
    pending_drops: Vec<PathBuf>,
    /// `--coverage`, for the source given on the command line only.
    coverage: Option<(Source, Coverage)>,
    /// `--yaw/--pitch/--hfov`, for the source given on the command line only.
    start: Option<(Source, StartArgs)>,
    /// The exposure asked for while an exposure reload was running.
    pending_exposure: Option<f64>,
    /// The last single file opened (shown or failed): PageUp/PageDown step from it.
    last_file: Option<PathBuf>,
    /// `--max-pixels`: the pixel limit for every panorama opened.
    max_pixels: u64,
    /// Cube face naming from the command line (for every cube opened).
    naming: Option<Naming>,
    /// What the panel shows about the document and its last frame.
    pub readouts: Readouts,
}

/// What the panel shows and edits of the document.
pub struct PanelParts<'a> {
    /// The projection choice (`None` = auto); the panel edits it.
    pub projection: &'a mut Option<Projection>,
    /// The readouts.
    pub readouts: &'a Readouts,
    /// The load in progress.
    pub loading: Option<&'a LoadStatus>,
}

impl Document {
    /// An empty document: nothing shown, nothing loading. `projection` is the command
    /// line's, `max_pixels` and `naming` apply to everything opened.
    pub fn new(projection: Option<Projection>, max_pixels: u64, naming: Option<Naming>) -> Self {
        Document {
            current: None,
            generation: 0,
            projection,
            projection_source: None,
            loading: None,
            next_id: 0,
            error: None,
            keep_error: false,
            pending_drops: Vec::new(),
            coverage: None,
            start: None,
            pending_exposure: None,
            last_file: None,
            max_pixels,
            naming,
            readouts: Readouts::default(),
        }
    }

    /// Open what the command line names, placed by `coverage` when given, starting at
    /// `start` where given.
    pub fn open(
        &mut self,
        source: Source,
        coverage: Option<Coverage>,
        start: StartArgs,
        exposure_ev: f64,
    ) -> Effect {
        self.coverage = coverage.map(|c| (source.clone(), c));
        self.start = (start != StartArgs::default()).then(|| (source.clone(), start));
        self.start_load(source, self.projection, exposure_ev, true)
    }

    /// Open a file or folder chosen in the window (the Open dialog, the recent list,
    /// PageUp/PageDown): as a drop of that one path.
    /// Luminaire and scene files are recognized by content (as drops are).
    pub fn open_path(&mut self, path: PathBuf, exposure_ev: f64) -> Option<Effect> {
        match file_kind(&path) {
            FileKind::Light => return Some(Effect::AddLights(vec![path])),
            FileKind::Scene => return Some(Effect::OpenScene(path)),
            FileKind::Other => {}
        }
        let source = Source::of_paths(vec![path], false, None)?;
        let fx = self.start_load(source, None, exposure_ev, true);
        self.mark_new_scene();
        Some(fx)
    }

    /// Start loading `source`; the current panorama stays until it is done. `opening`:
    /// a panorama opened (it goes to its start view), not a reload.
    fn start_load(
        &mut self,
        source: Source,
        projection: Option<Projection>,
        exposure_ev: f64,
        opening: bool,
    ) -> Effect {
        self.next_id += 1;
        let id = self.next_id;
        if opening && source != Source::Sample {
            // A folder or six faces: nothing to step from (the sample shown after a
            // failed load keeps the failed file).
            self.last_file = source
                .single_path()
                .filter(|p| !p.is_dir())
                .map(|p| p.to_path_buf());
        }
        self.loading = Some(Loading {
            id,
            source: source.clone(),
            status: LoadStatus::new(source.name()),
            opening,
            exposure: false,
            new_scene: false,
        });
        self.keep_error = false;
        let coverage = self
            .coverage
            .as_ref()
            .filter(|(s, _)| *s == source)
            .map(|(_, c)| *c);
        Effect::Load(LoadRequest {
            id,
            source,
            opts: LoadOptions {
                projection,
                tone: Tone { exposure_ev },
                max_pixels: self.max_pixels,
            },
            naming: self.naming,
            coverage,
            horizon: None,
        })
    }

    /// The load `id` could not be started (no thread): it is not running.
    pub fn load_not_started(&mut self, id: u64, why: &str) {
        if self.loading.as_ref().is_some_and(|l| l.id == id) {
            self.loading = None;
            self.error = Some(format!("cannot start loading: {why}"));
        }
    }

    /// A report from the loading thread. Reports of a superseded load are ignored.
    /// `exposure_ev` is the panel's, for the fallback load after a failure.
    pub fn on_event(&mut self, ev: LoadEvent, exposure_ev: f64) -> Vec<Effect> {
        let current_id = self.loading.as_ref().map(|l| l.id);
        match ev {
            LoadEvent::Progress { id, step, fraction } if Some(id) == current_id => {
                if let Some(l) = &mut self.loading {
                    l.status.advance(step, fraction);
                }
                Vec::new()
            }
            LoadEvent::Done { id, result } if Some(id) == current_id => {
                let Some(l) = self.loading.take() else {
                    return Vec::new();
                };
                let mut fx = match result {
                    Ok(loaded) => {
                        let mut fx = Vec::new();
                        if l.opening && l.new_scene {
                            fx.push(Effect::NewScene);
                        }
                        fx.extend(self.show(loaded, l.opening));
                        fx
                    }
                    Err(e) => self.failed(e, Some(l.source), exposure_ev),
                };
                if let Some(ev) = self.pending_exposure.take() {
                    fx.extend(self.reload_exposure(ev));
                }
                fx
            }
            _ => Vec::new(), // from a superseded load
        }
    }

    /// A load succeeded: show it (at its start view when `opening`).
    fn show(&mut self, loaded: Box<Loaded>, opening: bool) -> Vec<Effect> {
        let mut fx = Vec::new();
        let (mw, mh, proj) = loaded.describe();
        fx.push(Effect::PrintView(format!(
            "loaded {} {mw}x{mh} {proj}",
            loaded.source.name()
        )));
        // Every readout of the last frame belonged to the previous panorama.
        self.readouts = Readouts {
            map: loaded.label(),
            ..Readouts::default()
        };
        fx.push(Effect::Title(format!(
            "viewer: {} ({})",
            loaded.source.short_name(),
            loaded.size_label()
        )));
        if opening {
            fx.push(Effect::StartView(self.start_view_of(&loaded)));
            if let Some(p) = loaded.source.single_path() {
                fx.push(Effect::Opened(p.to_path_buf()));
            }
        }
        if !std::mem::take(&mut self.keep_error) {
            self.error = None;
            self.projection = loaded.projection;
            self.projection_source = Some(loaded.source.clone());
        }
        self.readouts.hdr = loaded.hdr;
        let map = loaded.map();
        self.readouts.partial = map.and_then(crate::panorama::coverage_text);
        self.readouts.pose_heading = map.and_then(EnvMap::pose_heading_deg);
        if let Some(p) = &self.readouts.partial {
            fx.push(Effect::PrintView(format!("partial {p}")));
        }
        self.current = Some(loaded);
        self.generation += 1;
        fx
    }

    /// Where `loaded` starts: the command line's values for its source, else the file's
    /// start view, else yaw 0, pitch 0 and the default hfov (`None`).
    fn start_view_of(&self, loaded: &Loaded) -> StartView {
        let file = loaded
            .map()
            .and_then(EnvMap::start_view)
            .unwrap_or(StartView {
                yaw_deg: 0.0,
                pitch_deg: 0.0,
                hfov_deg: None,
            });
        match &self.start {
            Some((s, a)) if *s == loaded.source => StartView {
                yaw_deg: a.yaw.unwrap_or(file.yaw_deg),
                pitch_deg: a.pitch.unwrap_or(file.pitch_deg),
                hfov_deg: a.hfov.or(file.hfov_deg),
            },
            _ => file,
        }
    }

    /// A load failed: keep what is shown, say why; with nothing shown, open the sample.
    fn failed(&mut self, e: String, source: Option<Source>, exposure_ev: f64) -> Vec<Effect> {
        // Escaped and shortened like every echoed message (lut_core::one_line).
        let e = lut_core::one_line(&e);
        let mut fx = vec![Effect::Stderr(format!("viewer: {e}"))];
        self.error = Some(e);
        // A projection chosen next retries this file.
        let was_sample = source == Some(Source::Sample);
        self.projection_source = source;
        if self.current.is_none() && !was_sample {
            // Nothing to keep showing: fall back to the bundled sample (once: a sample
            // that fails too leaves the error on show, never a loop of loads).
            fx.push(self.start_load(Source::Sample, None, exposure_ev, true));
            self.keep_error = true;
        }
        fx
    }

    /// A path was dropped on the window (opened with the rest of its batch by
    /// [`Document::open_drops`]).
    pub fn drop_path(&mut self, path: PathBuf) {
        self.pending_drops.push(path);
    }

    /// True when dropped paths wait to be opened.
    pub fn has_drops(&self) -> bool {
        !self.pending_drops.is_empty()
    }

    /// Open what was dropped, each file judged by its content
    /// ([`crate::lighting::file_kind`]): luminaire files (IES, EULUMDAT) add lights, a
    /// scene file opens (the last one dropped, before the rest), the rest is one panorama
    /// or cube.
    pub fn open_drops(&mut self, exposure_ev: f64) -> Vec<Effect> {
        let (mut lights, mut scenes, mut rest) = (Vec::new(), Vec::new(), Vec::new());
        for p in std::mem::take(&mut self.pending_drops) {
            match file_kind(&p) {
                FileKind::Light => lights.push(p),
                FileKind::Scene => scenes.push(p),
                FileKind::Other => rest.push(p),
            }
        }
        let mut fx = Vec::new();
        if let Some(scene) = scenes.pop() {
            fx.push(Effect::OpenScene(scene));
        }
        if !lights.is_empty() {
            fx.push(Effect::AddLights(lights));
            fx.push(Effect::ShowPanel);
        }
        if let Some(source) = Source::of_paths(rest, false, None) {
            fx.push(self.start_load(source, None, exposure_ev, true));
            // Dropped with luminaires or a scene: part of that scene.
            if fx.len() == 1 {
                self.mark_new_scene();
            }
        }
        fx
    }

    /// The load just started opens a panorama on its own (see [`Effect::NewScene`]).
    fn mark_new_scene(&mut self) {
        if let Some(l) = &mut self.loading {
            l.new_scene = true;
        }
    }

    /// The panel's "Dismiss": the error goes, the projection choice is the current one's.
    pub fn dismiss_error(&mut self) {
        self.error = None;
        self.projection_source = self.current.as_ref().map(|c| c.source.clone());
        self.projection = self.current.as_ref().and_then(|c| c.projection);
    }

    /// The panel's projection choice changed: reopen the file it applies to with it.
    pub fn projection_changed(&mut self, exposure_ev: f64) -> Option<Effect> {
        let source = self
            .projection_source
            .clone()
            .or_else(|| self.current.as_ref().map(|c| c.source.clone()))?;
        Some(self.start_load(source.as_map(), self.projection, exposure_ev, false))
    }

    /// The exposure changed: decode the current HDR file again with it (the current
    /// picture stays until it is ready). Nothing for 8-bit images or an unchanged value;
    /// while an exposure reload runs the value waits for it (the latest one wins).
    pub fn reload_exposure(&mut self, exposure_ev: f64) -> Option<Effect> {
        let cur = self.current.as_ref().filter(|c| c.hdr)?;
        if self.loading.as_ref().is_some_and(|l| l.exposure) {
            self.pending_exposure = Some(exposure_ev);
            return None;
        }
        if cur.exposure_ev == exposure_ev && self.loading.is_none() {
            return None;
        }
        let (source, projection) = (cur.source.clone(), cur.projection);
        let fx = self.start_load(source, projection, exposure_ev, false);
        if let Some(l) = &mut self.loading {
            l.exposure = true;
        }
        Some(fx)
    }

    /// The file PageUp/PageDown step from: the last single file opened, shown or not.
    pub fn last_file(&self) -> Option<&std::path::Path> {
        self.last_file.as_deref()
    }

    /// The panorama shown, if any.
    pub fn current(&self) -> Option<&Loaded> {
        self.current.as_deref()
    }

    /// The panorama shown, to render it.
    pub fn current_mut(&mut self) -> Option<&mut Loaded> {
        self.current.as_deref_mut()
    }

    /// Bumped each time another panorama is shown.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The load in progress.
    pub fn loading(&self) -> Option<&LoadStatus> {
        self.loading.as_ref().map(|l| &l.status)
    }

    /// The error shown.
    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    /// Show an error (a frame that failed to render).
    pub fn set_error(&mut self, e: String) {
        self.error = Some(e);
    }

    /// The projection chosen in the panel (`None` = auto).
    pub fn projection(&self) -> Option<Projection> {
        self.projection
    }

    /// The panel's view of the document.
    pub fn panel_parts(&mut self) -> PanelParts<'_> {
        PanelParts {
            projection: &mut self.projection,
            readouts: &self.readouts,
            loading: self.loading.as_ref().map(|l| &l.status),
        }
    }

    /// A partial map's coverage (the view limit keeps the view inside it).
    pub fn partial_coverage(&self) -> Option<Coverage> {
        let map = self.current.as_ref()?.map()?;
        map.crop().is_some().then(|| map.coverage())
    }
}

#[cfg(test)]
mod tests;
