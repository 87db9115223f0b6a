//! A counting global allocator: forwards to the system allocator and counts calls, bytes
//! in use and the peak. A test binary installs it with
//! `#[global_allocator] static A: Counting = Counting::new();`.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// The counting allocator (see the module docs).
pub struct Counting {
    calls: AtomicUsize,
    current: AtomicUsize,
    peak: AtomicUsize,
    /// Held by a test while it measures (see [`Counting::exclusive`]).
    lock: Mutex<()>,
}

impl Counting {
    /// A new allocator with zero counts.
    pub const fn new() -> Counting {
        Counting {
            calls: AtomicUsize::new(0),
            current: AtomicUsize::new(0),
            peak: AtomicUsize::new(0),
            lock: Mutex::new(()),
        }
    }

    /// Allocation calls so far (alloc, alloc_zeroed, realloc).
    pub fn calls(&self) -> usize {
        self.calls.load(Ordering::Relaxed)
    }

    /// Hold this for the whole of a test that measures, so that no other test of the
    /// binary allocates meanwhile (the counters are global).
    pub fn exclusive(&self) -> std::sync::MutexGuard<'_, ()> {
        self.lock.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Peak bytes allocated above the starting level while `f` runs (other threads'
    /// allocations in that time count too: see [`Counting::exclusive`]).
    pub fn peak_during<T>(&self, f: impl FnOnce() -> T) -> (T, usize) {
        let base = self.current.load(Ordering::Relaxed);
        self.peak.store(base, Ordering::Relaxed);
        let out = f();
        (out, self.peak.load(Ordering::Relaxed).saturating_sub(base))
    }

    fn grew(&self, n: usize) {
        self.calls.fetch_add(1, Ordering::Relaxed);
        let now = self.current.fetch_add(n, Ordering::Relaxed) + n;
        self.peak.fetch_max(now, Ordering::Relaxed);
    }
}

impl Default for Counting {
    fn default() -> Self {
        Counting::new()
    }
}

// SAFETY: forwards to the system allocator unchanged; only counts.
#[allow(unsafe_code)]
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        self.grew(l.size());
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(l) }
    }
    unsafe fn alloc_zeroed(&self, l: Layout) -> *mut u8 {
        self.grew(l.size());
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc_zeroed(l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        self.grew(new);
        self.current.fetch_sub(l.size(), Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(p, l, new) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        self.current.fetch_sub(l.size(), Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(p, l) }
    }
}
