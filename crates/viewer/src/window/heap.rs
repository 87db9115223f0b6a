//! Giving freed heap memory back to the system while the window runs (glibc).
//!
//! glibc's malloc serves a block of at least its *mmap threshold* with a mapping of its
//! own, returned to the system on `free`; smaller blocks come from the heap arenas, whose
//! freed memory stays resident unless it lies at the top of an arena. The threshold
//! starts at 128 KiB and is dynamic: each time a mapped block is freed it rises to that
//! block's size (up to 32 MiB on 64-bit). The window frees blocks of several MiB from
//! its first seconds (a decoded map and its pyramid, tables, scene and lit buffers, a
//! loaded file's bytes), so soon nearly every block comes from the arenas — shared by
//! the event loop, the loading thread and rayon's workers — and after some loads,
//! resizes and projection changes their free space lies between blocks still in use
//! and is never given back. That is retention, not a leak: in a 10-minute soak the
//! bytes in use at the same state grew by 4 MiB while the heap held 40 MiB more and the
//! resident memory doubled (`scripts/window-soak.sh --heap`; docs/reliability.md, "The
//! window soak").
//!
//! Pinning the threshold at 128 KiB (`mallopt`) would map and unmap every large block,
//! but the egui painter (`egui_software_backend`) allocates its changed primitives'
//! canvases (about the window's size) afresh every frame: mapped, they cost ~700 page
//! faults and 1–2 ms of CPU per 800×500 frame. Instead [`give_back`] (`malloc_trim(0)`)
//! returns the free pages of the arenas once the window has settled (see
//! [`next_trim`]); the frames keep reusing heap blocks as before.
//!
//! `malloc_trim` gives back the free blocks inside every arena but shrinks only the main
//! arena's top: the top of a thread's arena (rayon's workers, the loading thread) grows
//! with the temporaries freed there and stays resident (its trim threshold rises with the
//! mmap threshold). With the trim alone the soak's resident memory still rose by 8 MiB at
//! flat bytes in use. [`one_arena`], called before any other thread starts, makes every
//! thread allocate from the main arena (`mallopt(M_ARENA_MAX, 1)`, which leaves the
//! dynamic threshold alone), so one trim reaches all of it; the render loops allocate
//! nothing per pixel, and the shared arena's lock cost nothing measurable (CPU time per
//! frame, A/B on the shared machine). Elsewhere (musl, macOS, Windows) neither does
//! anything.

use std::time::{Duration, Instant};

/// How long after its last frame the window counts as settled.
pub const TRIM_QUIET: Duration = Duration::from_millis(500);
/// While it keeps drawing (auto-rotation, a long drag, an egui animation), the longest
/// time between two trims: what frames free in that time is all that stays resident.
pub const TRIM_EVERY: Duration = Duration::from_secs(2);

/// When the heap should next be given back: [`TRIM_QUIET`] after the last frame, or
/// [`TRIM_EVERY`] after the last trim if that comes first; `None` when no frame was
/// drawn since the last trim (nothing new to give back).
pub fn next_trim(last_frame: Option<Instant>, last_trim: Instant) -> Option<Instant> {
    let last_frame = last_frame.filter(|&f| f > last_trim)?;
    Some((last_frame + TRIM_QUIET).min(last_trim + TRIM_EVERY))
}

/// Make every thread allocate from glibc's main arena (see the module docs): call once,
/// before the process starts any other thread (glibc fixes its arena limit when a
/// second thread first allocates; `main` calls it first thing for the window). Returns
/// whether the allocator took it (always `false` off glibc).
pub fn one_arena() -> bool {
    glibc::one_arena()
}

/// Give the free memory of every heap arena back to the system (glibc's
/// `malloc_trim(0)`: whole free pages anywhere in the arenas, not only at their tops).
/// Returns whether any was given back (always `false` off glibc). Costs a walk over the
/// free blocks (about a millisecond), and the pages given back fault in again when
/// reused: call it when the window has settled, not every frame.
pub fn give_back() -> bool {
    glibc::trim()
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[allow(unsafe_code)]
mod glibc {
    pub fn trim() -> bool {
        // SAFETY: malloc_trim(3) takes a size and works on the allocator's own state
        // under its arena locks (safe to call from any thread while others allocate); it
        // only returns free pages to the system and moves no block in use. Pad 0 keeps
        // nothing extra at the heap's top. It returns 1 when memory was given back.
        unsafe { libc::malloc_trim(0) == 1 }
    }

    pub fn one_arena() -> bool {
        // SAFETY: mallopt(3) takes two integers and changes only the allocator's own
        // parameters under its lock (any thread may call it while others allocate);
        // M_ARENA_MAX 1 is valid and only stops new arenas from being created (threads
        // then share the main one). It returns 1 on success.
        unsafe { libc::mallopt(libc::M_ARENA_MAX, 1) == 1 }
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
mod glibc {
    pub fn trim() -> bool {
        false
    }

    pub fn one_arena() -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_trim_waits_for_a_quiet_moment_or_comes_every_two_seconds() {
        let t0 = Instant::now();
        let s = Duration::from_secs;
        let ms = Duration::from_millis;
        // Nothing drawn since the last trim, or ever: no trim.
        assert_eq!(next_trim(None, t0), None);
        assert_eq!(next_trim(Some(t0), t0), None);
        assert_eq!(next_trim(Some(t0), t0 + s(1)), None);
        // A frame after the trim: half a second after it.
        assert_eq!(next_trim(Some(t0 + s(1)), t0), Some(t0 + ms(1_500)));
        // Frames still coming 2 s after the trim: at 2 s.
        assert_eq!(next_trim(Some(t0 + ms(1_800)), t0), Some(t0 + s(2)));
        assert_eq!(next_trim(Some(t0 + s(25)), t0), Some(t0 + s(2)));
    }
}
