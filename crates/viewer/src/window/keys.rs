//! Key bindings: one table, [`BINDINGS`], that both the input handling ([`key_action`],
//! [`Shortcuts`]) and the help overlay (`?` / F1) read, so a key added there works and
//! shows up in the help at once. Mouse actions the help lists are in [`MOUSE_HELP`].
//!
//! **Routing** ([`Shortcuts::route`]): the shortcut keys are taken out of egui's input
//! before egui sees it, so they work whatever widget has keyboard focus (Tab moves egui's
//! focus between buttons and no longer traps the keyboard). Two exceptions: while a text
//! field is being edited every key goes to it, and while a modal dialog (the file
//! dialog) is open every key goes to the dialog.
//!
//! Adding a key: a [`KeyAction`] variant, a row in [`BINDINGS`], and what the action does
//! in the window's `apply_requests` (views, lights, ...).

use super::input::{Held, Turn};
use egui::{Event, Key, Modifiers};

/// What a key does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KeyAction {
    /// Turn while held.
    Turn(Turn),
    /// One zoom step in.
    ZoomIn,
    /// One zoom step out.
    ZoomOut,
    /// Back to the panorama's start view (the paper's RESIZE).
    Reset,
    /// Toggle fullscreen.
    ToggleFullscreen,
    /// Leave fullscreen, close the help.
    LeaveFullscreen,
    /// Show or hide the engineering panel.
    TogglePanel,
    /// Show or hide the help overlay.
    Help,
    /// The Open dialog.
    Open,
    /// The previous panorama in the current file's folder.
    OpenPrevious,
    /// The next panorama in the current file's folder.
    OpenNext,
    /// Save the current view (the Save dialog).
    SaveView,
    /// HDR panoramas: exposure down [`EXPOSURE_KEY_STEP_EV`] stops.
    ExposureDown,
    /// HDR panoramas: exposure up [`EXPOSURE_KEY_STEP_EV`] stops.
    ExposureUp,
    /// Auto-rotate on or off.
    AutoRotate,
    /// The next output projection (rectilinear, stereographic, fisheye, ...).
    CycleProjection,
    /// Into the little planet, or back to the view it left.
    LittlePlanet,
    /// The error heat map on or off.
    HeatMap,
    /// A tour: the level-horizon mode on or off (drag the horizon line).
    LevelHorizon,
    /// Close the window.
    Quit,
}

impl KeyAction {
    /// True for actions that act for as long as the key is held (turning).
    pub fn is_held(self) -> bool {
        matches!(self, KeyAction::Turn(_))
    }

    /// True for actions a held key repeats (zoom steps); the others act once per press.
    pub fn repeats(self) -> bool {
        matches!(self, KeyAction::ZoomIn | KeyAction::ZoomOut)
    }
}

/// Stops the `[` and `]` keys change the exposure of an HDR panorama by.
pub const EXPOSURE_KEY_STEP_EV: f64 = 0.5;

/// A key with the Ctrl (or Cmd) state it needs. Shift is ignored (`?` is Shift+/ and `+`
/// Shift+= on many layouts); Alt combinations are never shortcuts (egui and the file
/// dialog use them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Chord {
    /// The key.
    pub key: Key,
    /// Ctrl (or Cmd on macOS) held.
    pub command: bool,
}

const fn plain(key: Key) -> Chord {
    Chord {
        key,
        command: false,
    }
}

const fn ctrl(key: Key) -> Chord {
    Chord { key, command: true }
}

impl Chord {
    /// The chord as the help (and the README) shows it: "Ctrl+O", "⬅", "PageDown".
    pub fn label(self) -> String {
        let key = match self.key {
            Key::Escape => "Esc",
            Key::Minus => "−",
            Key::ArrowLeft => "⬅",
            Key::ArrowRight => "➡",
            Key::ArrowUp => "⬆",
            Key::ArrowDown => "⬇",
            k => k.symbol_or_name(),
        };
        if self.command {
            format!("Ctrl+{key}")
        } else {
            key.to_string()
        }
    }

    fn matches(self, key: Key, m: Modifiers) -> bool {
        self.key == key && self.command == (m.ctrl || m.command) && !m.alt
    }
}

/// One row of the key table: the chords, the action, and the help line.
#[derive(Debug, Clone, Copy)]
pub struct Binding {
    /// Keys that do it (any of them).
    pub chords: &'static [Chord],
    /// What they do.
    pub action: KeyAction,
    /// The help overlay's description.
    pub help: &'static str,
}

impl Binding {
    /// The chords as the help shows them: "⬅ or A".
    pub fn keys_label(&self) -> String {
        let labels: Vec<String> = self.chords.iter().map(|c| c.label()).collect();
        labels.join(" or ")
    }
}

/// Every key binding, in the order the help lists them.
pub const BINDINGS: &[Binding] = &[
    Binding {
        chords: &[plain(Key::ArrowLeft), plain(Key::A)],
        action: KeyAction::Turn(Turn::Left),
        help: "turn left while held",
    },
    Binding {
        chords: &[plain(Key::ArrowRight), plain(Key::D)],
        action: KeyAction::Turn(Turn::Right),
        help: "turn right while held",
    },
    Binding {
        chords: &[plain(Key::ArrowUp), plain(Key::W)],
        action: KeyAction::Turn(Turn::Up),
        help: "look up while held",
    },
    Binding {
        chords: &[plain(Key::ArrowDown), plain(Key::S)],
        action: KeyAction::Turn(Turn::Down),
        help: "look down while held",
    },
    Binding {
        chords: &[plain(Key::Plus), plain(Key::Equals)],
        action: KeyAction::ZoomIn,
        help: "zoom in one step",
    },
    Binding {
        chords: &[plain(Key::Minus)],
        action: KeyAction::ZoomOut,
        help: "zoom out one step",
    },
    Binding {
        chords: &[plain(Key::R)],
        action: KeyAction::Reset,
        help: "back to the panorama's start view",
    },
    Binding {
        chords: &[plain(Key::Space)],
        action: KeyAction::AutoRotate,
        help: "auto-rotate on/off (starts at once)",
    },
    Binding {
        chords: &[plain(Key::V)],
        action: KeyAction::CycleProjection,
        help: "next projection: rectilinear, stereographic, fisheye, equisolid, Pannini",
    },
    Binding {
        chords: &[plain(Key::L)],
        action: KeyAction::LittlePlanet,
        help: "little planet on/off (animated; back to the view it left)",
    },
    Binding {
        chords: &[plain(Key::E)],
        action: KeyAction::HeatMap,
        help: "error heat map on/off (sampling error against the exact map)",
    },
    Binding {
        chords: &[plain(Key::T)],
        action: KeyAction::LevelHorizon,
        help: "a tour: level the horizon by dragging its line (Esc or Enter: done)",
    },
    Binding {
        chords: &[ctrl(Key::O)],
        action: KeyAction::Open,
        help: "open a panorama (file dialog)",
    },
    Binding {
        chords: &[plain(Key::PageUp)],
        action: KeyAction::OpenPrevious,
        help: "previous panorama in the folder",
    },
    Binding {
        chords: &[plain(Key::PageDown)],
        action: KeyAction::OpenNext,
        help: "next panorama in the folder",
    },
    Binding {
        chords: &[ctrl(Key::S), plain(Key::P)],
        action: KeyAction::SaveView,
        help: "save the view as an image (file dialog)",
    },
    Binding {
        chords: &[plain(Key::OpenBracket)],
        action: KeyAction::ExposureDown,
        help: "HDR panoramas: exposure −0.5 EV",
    },
    Binding {
        chords: &[plain(Key::CloseBracket)],
        action: KeyAction::ExposureUp,
        help: "HDR panoramas: exposure +0.5 EV",
    },
    Binding {
        chords: &[plain(Key::F)],
        action: KeyAction::ToggleFullscreen,
        help: "fullscreen on/off",
    },
    Binding {
        chords: &[plain(Key::Escape)],
        action: KeyAction::LeaveFullscreen,
        help: "leave the level-horizon mode, else leave fullscreen, close the help",
    },
    Binding {
        chords: &[plain(Key::H)],
        action: KeyAction::TogglePanel,
        help: "engineering panel on/off (remembered)",
    },
    Binding {
        chords: &[plain(Key::Questionmark), plain(Key::F1)],
        action: KeyAction::Help,
        help: "this help on/off",
    },
    Binding {
        chords: &[ctrl(Key::Q), ctrl(Key::W)],
        action: KeyAction::Quit,
        help: "close the window",
    },
];

/// Mouse actions and drops, for the help overlay: (input, what it does).
pub const MOUSE_HELP: &[(&str, &str)] = &[
    ("drag", "turn the view (grab or QTVR: panel)"),
    ("quick drag, release", "keeps turning briefly (inertia)"),
    ("wheel", "zoom toward the cursor"),
    ("double-click", "zoom in toward the point"),
    ("drop an image", "open it"),
    ("drop a folder", "open it as a cube map (or six faces)"),
    ("drop .ies / .ldt", "add a light (recognized by content)"),
    ("drop a scene file", "open its panorama, room and lights"),
    ("click a light", "select it (Show room on)"),
    ("drag a light", "move it along the ceiling or its wall"),
    (
        "drag a room edge",
        "move its walls to fit the photo (Show room on)",
    ),
    ("drag a room corner", "move the two walls meeting there"),
    (
        "Shift-drag a floor/ceiling edge",
        "raise or lower the ceiling or the floor (height, camera height)",
    ),
    (
        "drag the horizon line",
        "a tour, level mode (T): the scene turns with it",
    ),
    ("Tab, Enter", "focus and press the buttons"),
];

/// The action of `key` pressed with `modifiers`, from [`BINDINGS`].
pub fn key_action(key: Key, modifiers: Modifiers) -> Option<KeyAction> {
    BINDINGS
        .iter()
        .find(|b| b.chords.iter().any(|c| c.matches(key, modifiers)))
        .map(|b| b.action)
}

/// Where this frame's key presses go.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Route {
    /// Bound keys are shortcuts, taken out of egui's input; the rest goes to egui.
    Shortcuts,
    /// A text field is being edited: every key goes to it.
    TextEditing,
    /// A modal dialog is open: every key goes to it.
    Modal,
}

/// The shortcut keys: which turn keys are held, and routing key events (see the module
/// docs).
#[derive(Debug, Clone, Default)]
pub struct Shortcuts {
    /// Turn keys held down (pressed as shortcuts, not released yet).
    held: Vec<(Key, Turn)>,
}

impl Shortcuts {
    /// Take this frame's shortcut key events out of `events` (what remains goes to
    /// egui) and return the discrete actions in order. Releases always update the held
    /// keys; a lost window focus releases them all; outside [`Route::Shortcuts`] nothing
    /// is held.
    pub fn route(&mut self, events: &mut Vec<Event>, route: Route) -> Vec<KeyAction> {
        let mut actions = Vec::new();
        if route != Route::Shortcuts {
            self.held.clear();
        }
        events.retain(|ev| match ev {
            Event::WindowFocused(false) => {
                self.held.clear();
                true
            }
            Event::Key {
                key,
                pressed: false,
                ..
            } => {
                self.held.retain(|(k, _)| k != key);
                true
            }
            Event::Key {
                key,
                pressed: true,
                repeat,
                modifiers,
                ..
            } if route == Route::Shortcuts => match key_action(*key, *modifiers) {
                None => true,
                Some(KeyAction::Turn(t)) => {
                    if !self.held.iter().any(|(k, _)| k == key) {
                        self.held.push((*key, t));
                    }
                    false
                }
                Some(a) => {
                    if !*repeat || a.repeats() {
                        actions.push(a);
                    }
                    false
                }
            },
            _ => true,
        });
        actions
    }

    /// The turns held by keys.
    pub fn held(&self) -> Held {
        let mut h = Held::default();
        for (_, t) in &self.held {
            match t {
                Turn::Left => h.left = true,
                Turn::Right => h.right = true,
                Turn::Up => h.up = true,
                Turn::Down => h.down = true,
            }
        }
        h
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn press(key: Key, modifiers: Modifiers, repeat: bool) -> Event {
        Event::Key {
            key,
            physical_key: None,
            pressed: true,
            repeat,
            modifiers,
        }
    }

    fn release(key: Key) -> Event {
        Event::Key {
            key,
            physical_key: None,
            pressed: false,
            repeat: false,
            modifiers: Modifiers::NONE,
        }
    }

    #[test]
    fn key_bindings() {
        use Key as K;
        let cases = [
            (K::ArrowLeft, KeyAction::Turn(Turn::Left)),
            (K::A, KeyAction::Turn(Turn::Left)),
            (K::ArrowRight, KeyAction::Turn(Turn::Right)),
            (K::D, KeyAction::Turn(Turn::Right)),
            (K::ArrowUp, KeyAction::Turn(Turn::Up)),
            (K::W, KeyAction::Turn(Turn::Up)),
            (K::ArrowDown, KeyAction::Turn(Turn::Down)),
            (K::S, KeyAction::Turn(Turn::Down)),
            (K::Plus, KeyAction::ZoomIn),
            (K::Equals, KeyAction::ZoomIn),
            (K::Minus, KeyAction::ZoomOut),
            (K::R, KeyAction::Reset),
            (K::F, KeyAction::ToggleFullscreen),
            (K::Escape, KeyAction::LeaveFullscreen),
            (K::H, KeyAction::TogglePanel),
            (K::OpenBracket, KeyAction::ExposureDown),
            (K::CloseBracket, KeyAction::ExposureUp),
            (K::P, KeyAction::SaveView),
            (K::Questionmark, KeyAction::Help),
            (K::F1, KeyAction::Help),
            (K::PageUp, KeyAction::OpenPrevious),
            (K::PageDown, KeyAction::OpenNext),
            (K::Space, KeyAction::AutoRotate),
            (K::V, KeyAction::CycleProjection),
            (K::L, KeyAction::LittlePlanet),
            (K::E, KeyAction::HeatMap),
        ];
        let none = Modifiers::NONE;
        for (k, a) in cases {
            assert_eq!(key_action(k, none), Some(a), "{k:?}");
        }
        assert_eq!(key_action(K::Q, none), None);
        assert_eq!(key_action(K::Tab, none), None, "Tab is egui's focus key");
        let ctrl = Modifiers::CTRL;
        assert_eq!(key_action(K::Q, ctrl), Some(KeyAction::Quit));
        assert_eq!(key_action(K::W, ctrl), Some(KeyAction::Quit));
        assert_eq!(key_action(K::O, ctrl), Some(KeyAction::Open));
        assert_eq!(key_action(K::S, ctrl), Some(KeyAction::SaveView));
        assert_eq!(key_action(K::O, none), None);
        assert_eq!(key_action(K::A, ctrl), None, "Ctrl+A does not turn");
        assert_eq!(
            key_action(K::Questionmark, Modifiers::SHIFT),
            Some(KeyAction::Help)
        );
        assert_eq!(key_action(K::R, Modifiers::ALT), None);
    }

    #[test]
    fn every_action_has_one_row_and_the_help_lists_every_chord() {
        let mut seen = Vec::new();
        for b in BINDINGS {
            assert!(!b.chords.is_empty() && !b.help.is_empty(), "{:?}", b.action);
            assert!(!seen.contains(&b.action), "{:?} twice", b.action);
            seen.push(b.action);
            let label = b.keys_label();
            for c in b.chords {
                assert!(label.contains(&c.label()), "{label} lacks {}", c.label());
                // No chord is bound twice: the first row wins, so a second would be dead.
                let m = if c.command {
                    Modifiers::CTRL
                } else {
                    Modifiers::NONE
                };
                assert_eq!(key_action(c.key, m), Some(b.action), "{}", c.label());
            }
        }
        assert_eq!(ctrl(Key::O).label(), "Ctrl+O");
        assert_eq!(plain(Key::PageDown).label(), "PageDown");
    }

    #[test]
    fn shortcuts_are_taken_from_egui_and_turn_keys_are_held() {
        let mut s = Shortcuts::default();
        let mut ev = vec![
            press(Key::Tab, Modifiers::NONE, false),
            press(Key::ArrowRight, Modifiers::NONE, false),
            press(Key::R, Modifiers::NONE, false),
            Event::Text("r".into()),
        ];
        let a = s.route(&mut ev, Route::Shortcuts);
        assert_eq!(a, [KeyAction::Reset]);
        // Tab and the text stay for egui; the shortcuts do not reach it (an arrow would
        // move egui's focus).
        assert_eq!(ev.len(), 2);
        assert!(matches!(ev[0], Event::Key { key: Key::Tab, .. }));
        assert!(s.held().right && !s.held().left);
        // Repeats: a held R resets once; a held + zooms each repeat.
        let mut ev = vec![
            press(Key::R, Modifiers::NONE, true),
            press(Key::Plus, Modifiers::NONE, true),
            press(Key::ArrowRight, Modifiers::NONE, true),
        ];
        assert_eq!(s.route(&mut ev, Route::Shortcuts), [KeyAction::ZoomIn]);
        assert!(ev.is_empty());
        let mut ev = vec![release(Key::ArrowRight)];
        s.route(&mut ev, Route::Shortcuts);
        assert!(!s.held().any());
        assert_eq!(ev.len(), 1, "releases pass through");
    }

    #[test]
    fn text_fields_and_dialogs_get_every_key() {
        let mut s = Shortcuts::default();
        let mut ev = vec![press(Key::ArrowUp, Modifiers::NONE, false)];
        s.route(&mut ev, Route::Shortcuts);
        assert!(s.held().up);
        for route in [Route::TextEditing, Route::Modal] {
            let mut ev = vec![
                press(Key::R, Modifiers::NONE, false),
                press(Key::ArrowLeft, Modifiers::NONE, false),
                press(Key::Q, Modifiers::CTRL, false),
            ];
            assert!(s.route(&mut ev, route).is_empty());
            assert_eq!(ev.len(), 3, "{route:?}");
            assert!(!s.held().any(), "{route:?}: nothing turns");
        }
        // Focus lost: held keys are released (their key-up never comes).
        let mut ev = vec![press(Key::ArrowDown, Modifiers::NONE, false)];
        s.route(&mut ev, Route::Shortcuts);
        let mut ev = vec![Event::WindowFocused(false)];
        s.route(&mut ev, Route::Shortcuts);
        assert!(!s.held().any());
    }
}
