//! Helpers shared by the viewer's CLI tests: run the binary, make a scratch folder.

#![allow(dead_code)] // each test binary uses its own subset

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Run `viewer` with `args` (no backtraces, so a panic shows as a plain message).
pub fn viewer(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_viewer"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("run viewer")
}

/// A fresh, empty scratch folder for one test (`prefix` names the test file).
pub fn tmpdir(prefix: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("{prefix}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A path as `&str` for a command line.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}
