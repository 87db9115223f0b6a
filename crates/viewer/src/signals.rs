//! SIGINT, SIGTERM and SIGHUP: remove the temporary file of an output being written
//! (`.viewer-XXXX.tmp` beside the target, see [`crate::output`]), then die of the same
//! signal as if it had not been caught (the shell sees 130 for Ctrl+C, 143 for SIGTERM).
//! SIGKILL cannot be caught: a temporary file may then stay behind; it has a random
//! name, so the next run never trips over it (and `ls` shows it as `.viewer-*.tmp`).
//!
//! signal-hook (MIT/Apache-2.0) runs the handling on a thread of its own, outside the
//! signal handler, so it may take locks and remove files. Unix only; elsewhere nothing
//! is installed.

/// Install the handling (once, at start-up). Failing to install it is not fatal: the
/// viewer then behaves as before (the default action, no clean-up).
pub fn install() {
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
            return;
        };
        let spawned = std::thread::Builder::new()
            .name("signals".into())
            .spawn(move || {
                if let Some(sig) = signals.forever().next() {
                    // Holds the lock of the temporary files until the process is gone:
                    // no new one is created, none is renamed into place half-written.
                    let _held = crate::output::remove_temporaries();
                    let _ = signal_hook::low_level::emulate_default_handler(sig);
                    // Not reached for these signals (their default action ends the
                    // process); exit the conventional way anyway.
                    std::process::exit(128 + sig);
                }
            });
        drop(spawned);
    }
}
