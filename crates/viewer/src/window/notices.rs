//! Short messages over the scene ("saved view-3.png", "no other panorama in this
//! folder", a light file that does not load): seen wherever the panel is, gone after a
//! few seconds unless they are errors, which stay until dismissed. Anything in the
//! window posts with [`Notices::info`] or [`Notices::error`]. Pure state: times are the
//! window's clock in seconds, so expiry is unit-tested.

/// How long an information notice stays, seconds.
pub const INFO_S: f64 = 4.0;
/// At most this many notices are kept (the oldest goes first).
pub const MAX_NOTICES: usize = 5;

/// How a notice looks and how long it stays.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    /// Goes after [`INFO_S`].
    Info,
    /// Stays until dismissed (or pushed out by newer notices).
    Error,
}

/// One notice.
#[derive(Debug, Clone, PartialEq)]
pub struct Notice {
    /// Identifies it for dismissal.
    pub id: u64,
    /// The text (one line).
    pub text: String,
    /// Info or error.
    pub level: Level,
    /// When it was posted (window clock, seconds).
    pub posted: f64,
}

/// The notices shown.
#[derive(Debug, Clone, Default)]
pub struct Notices {
    list: Vec<Notice>,
    next_id: u64,
}

impl Notices {
    /// Post an information notice at time `t`.
    pub fn info(&mut self, text: impl Into<String>, t: f64) -> u64 {
        self.post(Level::Info, text.into(), t)
    }

    /// Post an error notice at time `t` (stays until dismissed).
    pub fn error(&mut self, text: impl Into<String>, t: f64) -> u64 {
        self.post(Level::Error, text.into(), t)
    }

    fn post(&mut self, level: Level, text: String, t: f64) -> u64 {
        // Every notice is escaped and shortened the same way (lut_core::one_line): text
        // from input (file names, keys, values) never reaches the screen raw.
        let text = lut_core::one_line(&text);
        // The same text again (a key held down) refreshes the old notice.
        self.list.retain(|n| n.text != text);
        self.next_id += 1;
        self.list.push(Notice {
            id: self.next_id,
            text,
            level,
            posted: t,
        });
        if self.list.len() > MAX_NOTICES {
            self.list.remove(0);
        }
        self.next_id
    }

    /// Remove notice `id`.
    pub fn dismiss(&mut self, id: u64) {
        self.list.retain(|n| n.id != id);
    }

    /// Drop the information notices that have expired by `t`; true when any went.
    pub fn expire(&mut self, t: f64) -> bool {
        let n = self.list.len();
        self.list
            .retain(|n| n.level == Level::Error || t < n.posted + INFO_S);
        n != self.list.len()
    }

    /// The notices, oldest first.
    pub fn list(&self) -> &[Notice] {
        &self.list
    }

    /// When the next information notice expires (a frame is due then to remove it).
    pub fn next_expiry(&self) -> Option<f64> {
        self.list
            .iter()
            .filter(|n| n.level == Level::Info)
            .map(|n| n.posted + INFO_S)
            .reduce(f64::min)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn info_expires_errors_stay_until_dismissed() {
        let mut n = Notices::default();
        n.info("saved a.png", 1.0);
        let e = n.error("b.jpg: cannot read", 2.0);
        assert_eq!(n.list().len(), 2);
        assert_eq!(n.next_expiry(), Some(1.0 + INFO_S));
        assert!(!n.expire(1.0 + INFO_S - 0.01));
        assert!(n.expire(1.0 + INFO_S));
        assert_eq!(n.list().len(), 1);
        assert_eq!(n.next_expiry(), None);
        assert!(!n.expire(1000.0), "errors stay");
        n.dismiss(e);
        assert!(n.list().is_empty());
    }

    #[test]
    fn repeated_text_refreshes_and_the_list_is_bounded() {
        let mut n = Notices::default();
        n.info("same", 0.0);
        n.info("same", 3.0);
        assert_eq!(n.list().len(), 1);
        assert_eq!(n.list()[0].posted, 3.0);
        for i in 0..10 {
            n.info(format!("n{i}"), 4.0);
        }
        assert_eq!(n.list().len(), MAX_NOTICES);
        assert_eq!(n.list().last().unwrap().text, "n9");
    }
}
