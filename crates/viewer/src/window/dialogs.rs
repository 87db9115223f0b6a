//! The Open and Save dialogs: `egui-file-dialog`, drawn by egui like the rest of the
//! window (so they work wherever the window does, bare X servers and the Xvfb tests
//! included, with no desktop portal), modal, keyboard-driven (arrows, Enter, Esc, `/`
//! to type a path). The Open dialog lists the panorama formats the loader decodes; the
//! Save dialog offers PNG and JPEG and, beside the files, the size of the saved view.

use super::folder::PANORAMA_EXTENSIONS;
use egui_file_dialog::{DialogState, FileDialog};
use std::path::{Path, PathBuf};

/// What a dialog is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Purpose {
    Open,
    Save,
    SaveScene,
    SaveReport,
}

/// What the user chose.
#[derive(Debug, Clone, PartialEq)]
pub enum Chosen {
    /// Open this file.
    Open(PathBuf),
    /// Save the view to this file.
    Save(PathBuf),
    /// Save the scene (room, luminaires, exposure, panorama, view) to this file.
    SaveScene(PathBuf),
    /// Write the lighting report (`viewer report`'s, of the panel's lights) to this file.
    SaveReport(PathBuf),
}

/// The window's file dialogs (one at a time).
pub struct Dialogs {
    dialog: FileDialog,
    purpose: Option<Purpose>,
}

impl Default for Dialogs {
    fn default() -> Self {
        Dialogs::new()
    }
}

impl Dialogs {
    /// The dialogs, closed.
    pub fn new() -> Dialogs {
        let dialog = FileDialog::new()
            .add_file_filter_extensions("Panoramas", PANORAMA_EXTENSIONS.to_vec())
            .add_file_filter_extensions("Scenes", vec!["json"])
            .add_file_filter_extensions("Luminaires", vec!["ies", "ldt"])
            .default_file_filter("Panoramas")
            .add_save_extension("PNG", "png")
            .add_save_extension("JPEG", "jpg")
            .add_save_extension("Scene", "json")
            .add_save_extension("Report (HTML)", "html")
            .default_save_extension("PNG")
            .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO);
        Dialogs {
            dialog,
            purpose: None,
        }
    }

    /// True while a dialog is open (every key goes to it).
    pub fn is_open(&self) -> bool {
        self.purpose.is_some()
    }

    /// Fit the dialog in a `screen`-sized window (points) and take the keyboard from
    /// whatever egui widget had it (the dialog's own keys ignore input while another
    /// widget is focused).
    fn prepare(&mut self, ctx: &egui::Context) {
        let screen = ctx.content_rect().size();
        let c = self.dialog.config_mut();
        c.default_size = egui::vec2(720.0, 440.0).min(screen - egui::vec2(24.0, 24.0));
        c.max_size = Some(screen - egui::vec2(8.0, 8.0));
        c.min_size = egui::vec2(200.0, 160.0).min(screen);
        ctx.memory_mut(|m| {
            if let Some(id) = m.focused() {
                m.surrender_focus(id);
            }
        });
    }

    /// Show the Open dialog in `dir`.
    pub fn open_panorama(&mut self, ctx: &egui::Context, dir: &Path) {
        self.prepare(ctx);
        let c = self.dialog.config_mut();
        c.initial_directory = dir.to_path_buf();
        c.title = Some("Open a panorama, scene or luminaire".into());
        c.default_file_filter = Some("Panoramas".into());
        self.dialog.pick_file();
        self.purpose = Some(Purpose::Open);
    }

    /// Show the Save dialog in `dir` with the file name `name`.
    pub fn save_view(&mut self, ctx: &egui::Context, dir: &Path, name: &str) {
        self.prepare(ctx);
        let c = self.dialog.config_mut();
        c.initial_directory = dir.to_path_buf();
        c.default_file_name = name.to_string();
        c.title = Some("Save the view".into());
        c.default_save_extension = Some("PNG".into());
        self.dialog.save_file();
        self.purpose = Some(Purpose::Save);
    }

    /// Show the Open dialog in `dir` listing scene files (the file is judged by content
    /// whatever the filter).
    pub fn open_scene(&mut self, ctx: &egui::Context, dir: &Path) {
        self.open_panorama(ctx, dir);
        let c = self.dialog.config_mut();
        c.title = Some("Open a scene".into());
        c.default_file_filter = Some("Scenes".into());
        self.dialog.pick_file();
    }

    /// Show the Save dialog for a scene file in `dir` named `name`.
    pub fn save_scene(&mut self, ctx: &egui::Context, dir: &Path, name: &str) {
        self.prepare(ctx);
        let c = self.dialog.config_mut();
        c.initial_directory = dir.to_path_buf();
        c.default_file_name = name.to_string();
        c.title = Some("Save the scene".into());
        c.default_save_extension = Some("Scene".into());
        self.dialog.save_file();
        self.purpose = Some(Purpose::SaveScene);
    }

    /// Show the Save dialog for a lighting report in `dir` named `name` (`.html`, and
    /// `.json` or `.png` by the name typed).
    pub fn save_report(&mut self, ctx: &egui::Context, dir: &Path, name: &str) {
        self.prepare(ctx);
        let c = self.dialog.config_mut();
        c.initial_directory = dir.to_path_buf();
        c.default_file_name = name.to_string();
        c.title = Some("Write the lighting report (.html, .json or .png)".into());
        c.default_save_extension = Some("Report (HTML)".into());
        self.dialog.save_file();
        self.purpose = Some(Purpose::SaveReport);
    }

    /// Draw the open dialog (if any) and return what was chosen. `scale` is the Save
    /// dialog's size choice (the scene's size times it), `size_of` the image size for a
    /// scale.
    pub fn update(
        &mut self,
        ctx: &egui::Context,
        scale: &mut u32,
        size_of: &dyn Fn(u32) -> (u32, u32),
    ) -> Option<Chosen> {
        let purpose = self.purpose?;
        // One Esc closes the dialog, even while its file name field has the keyboard
        // (egui_file_dialog would only take the focus from the field on the first).
        if ctx.input(|i| i.key_pressed(egui::Key::Escape)) {
            self.purpose = None;
            ctx.memory_mut(|m| {
                if let Some(id) = m.focused() {
                    m.surrender_focus(id);
                }
            });
            return None;
        }
        if purpose == Purpose::Save {
            self.dialog.update_with_right_panel_ui(ctx, &mut |ui, _| {
                ui.heading("Size");
                for k in super::input::EXPORT_SCALES {
                    let (w, h) = size_of(k);
                    ui.radio_value(scale, k, format!("{k}x: {w}×{h}"));
                }
            });
        } else {
            self.dialog.update(ctx);
        }
        match self.dialog.state() {
            DialogState::Open => None,
            DialogState::Picked(p) => {
                let p = p.clone();
                self.purpose = None;
                Some(match purpose {
                    Purpose::Open => Chosen::Open(p),
                    Purpose::Save => Chosen::Save(p),
                    Purpose::SaveScene => Chosen::SaveScene(p),
                    Purpose::SaveReport => Chosen::SaveReport(p),
                })
            }
            _ => {
                self.purpose = None;
                None
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One UI pass of a 1024×640 window with `events`, the dialogs drawn.
    fn pass(ctx: &egui::Context, d: &mut Dialogs, events: Vec<egui::Event>) -> Option<Chosen> {
        let raw = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(
                egui::Pos2::ZERO,
                egui::vec2(1024.0, 640.0),
            )),
            events,
            ..Default::default()
        };
        let mut chosen = None;
        let _ = ctx.run_ui(raw, |ui| {
            chosen = d.update(ui.ctx(), &mut 1, &|k| (800 * k, 500 * k));
        });
        chosen
    }

    fn key(key: egui::Key) -> egui::Event {
        egui::Event::Key {
            key,
            physical_key: None,
            pressed: true,
            repeat: false,
            modifiers: egui::Modifiers::NONE,
        }
    }

    /// Issue 33 (9): the Save dialog opens with its file name field focused; one Esc
    /// closes it all the same (and the Open dialog).
    #[test]
    fn one_escape_closes_a_dialog() {
        let dir = tempfile::tempdir().unwrap();
        for save in [true, false] {
            let ctx = egui::Context::default();
            let mut d = Dialogs::new();
            if save {
                d.save_view(&ctx, dir.path(), "view-1.png");
            } else {
                d.open_panorama(&ctx, dir.path());
            }
            for _ in 0..3 {
                assert_eq!(pass(&ctx, &mut d, Vec::new()), None);
            }
            assert!(d.is_open());
            if save {
                assert!(
                    ctx.memory(|m| m.focused().is_some()),
                    "the name field has the keyboard"
                );
            }
            assert_eq!(pass(&ctx, &mut d, vec![key(egui::Key::Escape)]), None);
            assert!(!d.is_open(), "save={save}: still open after one Esc");
            assert!(ctx.memory(|m| m.focused().is_none()));
        }
    }
}
