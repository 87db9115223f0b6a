//! The guards every input path shares (docs/reliability.md, "The classes"): one
//! containment for decoders ([`contain`]), one way to echo text that came from input
//! ([`shown`], [`one_line`]), and the limit check with its message ([`check_limit`]).
//! Depends on nothing else in the crate, so every stage (and the viewer, and code still
//! to come: tours, tiles) can use it.

use std::cell::Cell;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The most characters of one echoed value (a file name, a number, a key) that a
/// message repeats; longer values are cut and marked with their length.
pub const ECHO_MAX_CHARS: usize = 200;
/// The most characters of a whole one-line message ([`one_line`]).
pub const MESSAGE_MAX_CHARS: usize = 2000;

/// A decoder that panicked on a file: the file's error, with the panic's message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DecoderPanic {
    /// The file (or the name given to in-memory bytes).
    pub path: PathBuf,
    /// The panic's message (escaped and shortened).
    pub message: String,
}

impl fmt::Display for DecoderPanic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: the file is damaged or of a kind the decoder cannot handle (the decoder \
             failed on it: {})",
            shown(&self.path.display().to_string()),
            self.message
        )
    }
}

impl std::error::Error for DecoderPanic {}

thread_local! {
    /// Containments active on this thread.
    static QUIET: Cell<usize> = const { Cell::new(0) };
}
/// Containments active on any thread (a decoder's rayon workers panic off the thread
/// that contains them; rayon hands the panic back to it).
static ACTIVE: AtomicUsize = AtomicUsize::new(0);

/// Install, once, the panic hook that keeps contained panics off standard error and hands
/// every other panic to the hook that was there before.
fn install_hook() {
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let before = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let here = QUIET.with(Cell::get) > 0;
            // A rayon worker's panic inside a contained decoder is resumed on the
            // containing thread, which turns it into an error.
            let worker =
                ACTIVE.load(Ordering::SeqCst) > 0 && rayon::current_thread_index().is_some();
            if !(here || worker) {
                before(info);
            }
        }));
    });
}

/// Run `f`, returning a panic inside it as `Err(message)` instead of unwinding further;
/// the panic is not printed. For code that is not a file's decoder (a fuzz target, a
/// thread's body); decoders use [`contain`].
pub fn catch_quiet<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    install_hook();
    QUIET.with(|q| q.set(q.get() + 1));
    ACTIVE.fetch_add(1, Ordering::SeqCst);
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    ACTIVE.fetch_sub(1, Ordering::SeqCst);
    QUIET.with(|q| q.set(q.get() - 1));
    r.map_err(|p| panic_message(p.as_ref()))
}

/// A panic payload's message, escaped and shortened.
pub fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    let m = p
        .downcast_ref::<&str>()
        .map(|s| (*s).to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "an internal error".to_string());
    shown(&m)
}

/// The one containment every decoder runs behind: `f` (which reads or decodes `path`),
/// with a panic inside it (also on its rayon workers) turned into the file's error
/// ([`DecoderPanic`], converted into `E`) instead of ending the process or the thread.
/// The panic is not printed.
///
/// ```
/// use lut_core::{contain, DecoderPanic};
/// use std::path::Path;
/// let r: Result<u32, DecoderPanic> = contain(Path::new("bad.png"), || panic!("PLTE"));
/// assert!(r.unwrap_err().to_string().contains("bad.png"));
/// ```
///
/// # Errors
/// `f`'s own error, or a [`DecoderPanic`] naming `path`.
pub fn contain<T, E: From<DecoderPanic>>(
    path: &Path,
    f: impl FnOnce() -> Result<T, E>,
) -> Result<T, E> {
    catch_quiet(f).unwrap_or_else(|message| {
        Err(E::from(DecoderPanic {
            path: path.to_path_buf(),
            message,
        }))
    })
}

/// Environment variable naming fault points to trigger, comma-separated (the tests'
/// way to prove a containment end to end: `LUTPANO_FAULT=decoder viewer render x.png`
/// must exit 1 with one line). Unset in normal use.
pub const FAULT_ENV: &str = "LUTPANO_FAULT";

/// Panic here when [`FAULT_ENV`] names `point` (see there): `decoder` inside every
/// image decoder's containment, `tile` inside a tiled pyramid's tile decoder only (the
/// pyramid opens; each tile fails), `loader` on the window's loading thread outside it.
pub fn fault_point(point: &str) {
    if let Some(v) = std::env::var_os(FAULT_ENV) {
        if v.to_str().is_some_and(|s| s.split(',').any(|p| p == point)) {
            panic!("fault point '{point}' ({FAULT_ENV})");
        }
    }
}

/// Whether `c` is written as an escape in echoed text: control characters (C0, DEL,
/// C1: escape sequences, line breaks, carriage returns) and invisible format characters
/// (bidi overrides and isolates, zero-width characters, byte-order marks).
fn needs_escape(c: char) -> bool {
    c.is_control()
        || matches!(c,
            '\u{200B}'..='\u{200F}' | '\u{202A}'..='\u{202E}' | '\u{2060}'..='\u{2064}'
            | '\u{2066}'..='\u{2069}' | '\u{FEFF}' | '\u{FFF9}'..='\u{FFFB}')
}

/// `s` with every control or invisible format character written as an escape (`\n`,
/// `\t`, `\u{1b}`, ...): safe to print on a terminal or in a one-line message.
pub fn escape_controls(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        if needs_escape(c) {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// The first `max` characters of `s` followed by `… (N characters)` when it is longer.
fn shorten(s: &str, max: usize) -> String {
    let n = s.chars().count();
    if n <= max {
        return s.to_string();
    }
    let head: String = s.chars().take(max).collect();
    format!("{head}… ({n} characters)")
}

/// A value from input (a file name, a number as typed, a key) as a message may repeat
/// it: control characters escaped ([`escape_controls`]) and cut to [`ECHO_MAX_CHARS`]
/// characters with its full length noted.
pub fn shown(s: &str) -> String {
    shorten(&escape_controls(s), ECHO_MAX_CHARS)
}

/// A path as a message may repeat it (see [`shown`]).
pub fn shown_path(p: &Path) -> String {
    shown(&p.display().to_string())
}

/// A whole message made fit to print as one line, whatever it quotes: control
/// characters escaped (so also line breaks), every run of characters without a space
/// longer than [`ECHO_MAX_CHARS`] (a huge file name, a 309-digit number) cut as by
/// [`shown`], and the line cut at [`MESSAGE_MAX_CHARS`]. Every message path uses it at
/// the end (the viewer's error line, the window's notices).
pub fn one_line(msg: &str) -> String {
    let escaped = escape_controls(msg.trim_end_matches('\n'));
    let mut out = String::with_capacity(escaped.len().min(4 * MESSAGE_MAX_CHARS));
    for (i, word) in escaped.split(' ').enumerate() {
        if i > 0 {
            out.push(' ');
        }
        out.push_str(&shorten(word, ECHO_MAX_CHARS));
    }
    shorten(&out, MESSAGE_MAX_CHARS)
}

/// A number that sizes work or memory beyond its limit (docs/reliability.md, "Limits"):
/// "room width 4170 m exceeds the limit of 100 m".
#[derive(Debug, Clone, PartialEq)]
pub struct LimitError {
    /// What the number is ("room width", "luminaires").
    pub what: String,
    /// The value given (as text: it may be any size).
    pub value: String,
    /// The limit.
    pub limit: String,
    /// The unit, with its leading space ("" for a count, " m", " pixels").
    pub unit: &'static str,
}

impl fmt::Display for LimitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} {}{} exceeds the limit of {}{}",
            self.what,
            shown(&self.value),
            self.unit,
            self.limit,
            self.unit
        )
    }
}

impl std::error::Error for LimitError {}

/// Check a number that sizes work or memory against its limit, before any work.
///
/// # Errors
/// A [`LimitError`] naming `what`, the value and the limit, for a value over the limit
/// or not a number.
pub fn check_limit<T: PartialOrd + fmt::Display>(
    what: &str,
    value: T,
    limit: T,
    unit: &'static str,
) -> Result<(), LimitError> {
    // `!(v <= limit)` also catches NaN.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(value <= limit) {
        return Err(LimitError {
            what: what.to_string(),
            value: value.to_string(),
            limit: limit.to_string(),
            unit,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panics_become_the_files_error_quietly() {
        #[derive(Debug)]
        struct E(String);
        impl From<DecoderPanic> for E {
            fn from(p: DecoderPanic) -> E {
                E(p.to_string())
            }
        }
        let r: Result<(), E> = contain(Path::new("x.png"), || panic!("index out of range"));
        let e = r.unwrap_err().0;
        assert!(e.starts_with("x.png: the file is damaged"), "{e}");
        assert!(e.contains("index out of range"), "{e}");
        // Errors and values pass through.
        let r: Result<u8, E> = contain(Path::new("x"), || Err(E("own".into())));
        assert_eq!(r.unwrap_err().0, "own");
        assert_eq!(contain::<u8, E>(Path::new("x"), || Ok(3)).unwrap(), 3);
        // A panic on a rayon worker inside the containment.
        use rayon::prelude::*;
        let r: Result<Vec<u32>, E> = contain(Path::new("y"), || {
            Ok((0..64u32)
                .into_par_iter()
                .map(|i| if i == 40 { panic!("worker") } else { i })
                .collect())
        });
        assert!(r.unwrap_err().0.contains("worker"));
        // Nested containments keep working after the inner one ends.
        let outer = catch_quiet(|| {
            let inner = catch_quiet(|| panic!("inner"));
            assert!(inner.is_err());
            panic!("outer")
        });
        assert_eq!(outer.unwrap_err(), "outer");
    }

    #[test]
    fn echoed_text_is_escaped_and_shortened() {
        assert_eq!(shown("a\u{1b}]0;title\u{7}b"), "a\\u{1b}]0;title\\u{7}b");
        assert_eq!(shown("line\nbreak\r"), "line\\nbreak\\r");
        assert_eq!(shown("\u{202E}gpj.exe"), "\\u{202e}gpj.exe");
        assert_eq!(shown("naïve ünïcode"), "naïve ünïcode");
        let long = "9".repeat(309);
        let s = shown(&long);
        assert!(s.starts_with(&"9".repeat(200)), "{s}");
        assert!(s.ends_with("… (309 characters)"), "{s}");
        assert_eq!(
            s.chars().count(),
            200 + "… (309 characters)".chars().count()
        );
        // A whole message: every long word cut, the rest kept, one line.
        let name = "n".repeat(10 << 20);
        let msg = format!("viewer: {name}.jpg: cannot read image: No such file\nsecond");
        let line = one_line(&msg);
        assert!(line.len() < 400, "{}", line.len());
        assert!(
            line.ends_with("cannot read image: No such file\\nsecond"),
            "{line}"
        );
        assert!(line.contains(&format!("({} characters)", (10 << 20) + 5)));
        assert!(!line.contains('\n'));
        // Many short words: the line is cut as a whole.
        let many = "ab ".repeat(5000);
        assert!(one_line(&many).chars().count() < MESSAGE_MAX_CHARS + 40);
    }

    #[test]
    fn limits_name_the_value_and_the_limit() {
        let e = check_limit("room width", 4170.0, 100.0, " m").unwrap_err();
        assert_eq!(
            e.to_string(),
            "room width 4170 m exceeds the limit of 100 m"
        );
        assert!(check_limit("room width", f64::NAN, 100.0, " m").is_err());
        assert!(check_limit("luminaires", 10_000usize, 200, "").is_err());
        assert!(check_limit("luminaires", 200usize, 200, "").is_ok());
        let huge = check_limit("room width", 1e300, 100.0, " m").unwrap_err();
        assert!(huge.to_string().contains("exceeds the limit of 100 m"));
    }
}
