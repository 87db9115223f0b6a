//! How the viewer ends: exit statuses, usage errors, and writing to standard output
//! without panicking.
//!
//! ## Exit statuses (the one rule every command follows; README and docs/viewer.md)
//! * **0**: done. Also when standard output is a pipe whose reader has gone
//!   (`viewer ies lamp.ies | head -3`): the output was not wanted, which is not an error.
//! * **1**: the command line was fine but something about the files or devices failed: a
//!   file missing, unreadable, damaged or of an unsupported kind; an output that cannot
//!   be written (no folder, a full disk, one of the inputs); no display for the window.
//! * **2**: the command line itself is wrong, whatever the files hold: an unknown option,
//!   a value out of range or malformed, options that do not go together (clap's own
//!   usage errors exit 2 too; the commands' later checks use [`Usage`]).
//! * **128 + N**: ended by signal N (130 for Ctrl+C, 143 for SIGTERM), after removing
//!   any temporary file being written (see [`crate::signals`]).

use std::fmt;
use std::io::Write;

/// A usage error: the command line asks for something no file could make right
/// (exit status 2). Build one with [`usage!`](crate::usage).
#[derive(Debug)]
pub struct Usage(pub String);

impl fmt::Display for Usage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Usage {}

/// An `anyhow::Error` holding a [`Usage`] error with a formatted message.
#[macro_export]
macro_rules! usage {
    ($($t:tt)*) => {
        anyhow::Error::new($crate::exit::Usage(format!($($t)*)))
    };
}

/// The exit status for an error (see the module docs): 2 for a usage error anywhere in
/// its chain (ours, or lut-core's `CubeError::Usage`), 1 otherwise.
pub fn code(e: &anyhow::Error) -> u8 {
    let usage = e.chain().any(|c| {
        c.is::<Usage>()
            || matches!(
                c.downcast_ref::<lut_core::CubeError>(),
                Some(lut_core::CubeError::Usage(_))
            )
    });
    if usage {
        2
    } else {
        1
    }
}

/// True when `e` is standard output's reader having gone away (a closed pipe).
pub fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// Write `args` and a line break to standard output, returning an error (naming standard
/// output) instead of panicking as `println!` does on a closed pipe or a full disk.
///
/// # Errors
/// The write's error, with context.
pub fn line(args: fmt::Arguments<'_>) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_fmt(args)
        .and_then(|()| out.write_all(b"\n"))
        .map_err(stdout_error)
}

/// Flush standard output (the last lines may sit in its buffer), as an error naming it.
///
/// # Errors
/// The flush's error.
pub fn flush() -> anyhow::Result<()> {
    std::io::stdout().flush().map_err(stdout_error)
}

fn stdout_error(e: std::io::Error) -> anyhow::Error {
    anyhow::Error::new(e).context("cannot write to standard output")
}

/// As [`line()`] for standard error, where a failure has nowhere to be reported: it is
/// ignored (never a panic, as `eprintln!` would on a full disk).
pub fn err_line(args: fmt::Arguments<'_>) {
    let mut e = std::io::stderr().lock();
    let _ = e.write_fmt(args).and_then(|()| e.write_all(b"\n"));
}

/// `println!` that returns an error instead of panicking (see [`line()`]).
#[macro_export]
macro_rules! outln {
    ($($t:tt)*) => {
        $crate::exit::line(format_args!($($t)*))
    };
}

/// `eprintln!` that never panics (see [`err_line`]).
#[macro_export]
macro_rules! errln {
    ($($t:tt)*) => {
        $crate::exit::err_line(format_args!($($t)*))
    };
}

/// The first place in `v` that holds `null` (as a JSON path, `$.points[0].lux`).
fn first_null(v: &serde_json::Value, at: &str) -> Option<String> {
    match v {
        serde_json::Value::Null => Some(at.to_string()),
        serde_json::Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, x)| first_null(x, &format!("{at}[{i}]"))),
        serde_json::Value::Object(m) => m
            .iter()
            .find_map(|(k, x)| first_null(x, &format!("{at}.{k}"))),
        _ => None,
    }
}

/// `value` as JSON for output (one line, or pretty), refusing a result that holds a
/// number that is not finite (serde_json writes NaN and infinities as `null`): the one
/// check every JSON output goes through, so JSON output never holds `null` for a number.
/// Output types use no `null` of their own (absent fields are skipped).
///
/// # Errors
/// A usage error naming the field: the command line (or the file it names) asked for
/// something whose answer is not a finite number.
pub fn finite_json<T: serde::Serialize>(value: &T, pretty: bool) -> anyhow::Result<String> {
    let v = serde_json::to_value(value)?;
    if let Some(at) = first_null(&v, "$") {
        return Err(crate::usage!(
            "the result {at} is not a finite number: the values given are out of range"
        ));
    }
    Ok(if pretty {
        serde_json::to_string_pretty(&v)?
    } else {
        serde_json::to_string(&v)?
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn usage_errors_exit_2_anywhere_in_the_chain() {
        assert_eq!(code(&usage!("--size {} is bad", 3)), 2);
        assert_eq!(code(&usage!("bad").context("render")), 2);
        let cube = anyhow::Error::new(lut_core::CubeError::Usage(lut_core::UsageProblem::NoInput));
        assert_eq!(code(&cube), 2);
        assert_eq!(code(&anyhow::anyhow!("a.jpg: cannot read")), 1);
        let io = std::io::Error::new(std::io::ErrorKind::BrokenPipe, "pipe");
        let e = anyhow::Error::new(io).context("cannot write to standard output");
        assert!(is_broken_pipe(&e));
        assert_eq!(code(&e), 1);
        assert!(!is_broken_pipe(&anyhow::anyhow!("x")));
    }

    #[test]
    fn json_output_never_holds_null_for_a_number() {
        #[derive(serde::Serialize)]
        struct R {
            lux: f64,
            normal: [f64; 3],
        }
        let ok = finite_json(
            &R {
                lux: 1.5,
                normal: [0.0, 1.0, 0.0],
            },
            false,
        )
        .unwrap();
        assert_eq!(ok, r#"{"lux":1.5,"normal":[0.0,1.0,0.0]}"#);
        for (r, at) in [
            (
                R {
                    lux: f64::INFINITY,
                    normal: [0.0; 3],
                },
                "$.lux",
            ),
            (
                R {
                    lux: 0.0,
                    normal: [0.0, f64::NAN, 0.0],
                },
                "$.normal[1]",
            ),
        ] {
            let e = finite_json(&r, true).unwrap_err();
            assert_eq!(code(&e), 2);
            assert!(e.to_string().contains(at), "{e}");
        }
    }
}
