//! The pixel limit refuses huge images from their header, before any pixel buffer is
//! allocated (decompression-bomb defence). A counting global allocator measures the
//! peak bytes allocated during each load; a control load with the limit raised shows the
//! same measurement does see the map's buffer, so the tests can fail.

use lut_core::{EnvMap, LoadOptions, MapError};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

struct Counting;
static CURRENT: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(n: usize) {
    let now = CURRENT.fetch_add(n, Ordering::Relaxed) + n;
    PEAK.fetch_max(now, Ordering::Relaxed);
}

// SAFETY: forwards to the system allocator unchanged; only counts bytes.
#[allow(unsafe_code)]
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        grew(l.size());
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(l) }
    }
    unsafe fn alloc_zeroed(&self, l: Layout) -> *mut u8 {
        grew(l.size());
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc_zeroed(l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        grew(new);
        CURRENT.fetch_sub(l.size(), Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(p, l, new) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        CURRENT.fetch_sub(l.size(), Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(p, l) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// One measurement at a time (the counters are global).
static LOCK: Mutex<()> = Mutex::new(());

/// Peak bytes allocated above the starting level while `f` runs.
fn peak_during<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let base = CURRENT.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let out = f();
    (out, PEAK.load(Ordering::Relaxed).saturating_sub(base))
}

#[path = "support/bombs.rs"]
mod bombs;
use bombs::{jpeg_header_only, png_header_only};

/// Allowed during a refused load: the 1 MiB file read buffer, format guessing, the
/// header, the error message (the files claim 30 to 40 GB of pixels).
const SMALL: usize = 4 << 20;

fn check_refused(e: MapError, name: &str, w: u64, h: u64, limit: u64) {
    let msg = e.to_string();
    assert!(
        matches!(e, MapError::TooManyPixels { width, height, limit: l, .. } if width == w && height == h && l == limit),
        "{msg}"
    );
    for part in [
        name.to_string(),
        format!("{w}x{h}"),
        limit.to_string(),
        "--max-pixels".into(),
    ] {
        assert!(msg.contains(&part), "'{part}' missing from: {msg}");
    }
}

#[test]
fn header_only_huge_files_are_refused_without_allocating() {
    let _g = LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "huge.png",
            png_header_only(100_000, 100_000),
            100_000,
            100_000,
        ),
        ("huge.jpg", jpeg_header_only(65_000, 65_000), 65_000, 65_000),
    ];
    for (name, bytes, w, h) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, &bytes).unwrap();
        let opts = LoadOptions::default();
        // From a file (streamed) and from memory.
        let (r, peak) = peak_during(|| EnvMap::load_with(&path, &opts, &mut |_| {}));
        check_refused(r.unwrap_err(), name, w, h, opts.max_pixels);
        assert!(peak < SMALL, "{name}: {peak} bytes allocated");
        let (r, peak) = peak_during(|| EnvMap::decode_with(&bytes, name, &opts, &mut |_| {}));
        check_refused(r.unwrap_err(), name, w, h, opts.max_pixels);
        assert!(peak < SMALL, "{name}: {peak} bytes allocated");
        // The plain entry points keep the same default limit.
        assert!(matches!(
            EnvMap::load(&path, None),
            Err(MapError::TooManyPixels { .. })
        ));
    }
}

#[test]
fn a_real_bomb_is_refused_and_the_control_load_does_allocate() {
    let _g = LOCK.lock().unwrap_or_else(|e| e.into_inner());
    // 8000 × 4000 black: 96 MB of RGB in a PNG of about 100 KB.
    let (w, h) = (8000u32, 4000u32);
    let img = image::RgbImage::new(w, h);
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    drop(img);
    assert!(png.len() < 1 << 20, "{} bytes", png.len());
    let map_bytes = (w as usize + 1) * (h as usize + 1) * 4;

    let refuse = LoadOptions {
        max_pixels: 10_000_000,
        ..LoadOptions::default()
    };
    let (r, peak) = peak_during(|| EnvMap::decode_with(&png, "bomb.png", &refuse, &mut |_| {}));
    check_refused(r.unwrap_err(), "bomb.png", w.into(), h.into(), 10_000_000);
    assert!(peak < SMALL, "{peak} bytes allocated");

    // Control: the same file under a limit it fits is decoded, and the counter sees
    // the map's buffer; decoding into that buffer keeps the peak near the map alone.
    let allow = LoadOptions {
        max_pixels: u64::from(w) * u64::from(h),
        ..LoadOptions::default()
    };
    let (r, peak) = peak_during(|| EnvMap::decode_with(&png, "bomb.png", &allow, &mut |_| {}));
    let map = r.unwrap();
    assert_eq!((map.width(), map.height()), (w, h));
    assert!(peak >= map_bytes, "{peak} < {map_bytes}");
    assert!(
        peak < map_bytes + map_bytes / 4,
        "peak {peak} bytes for a {map_bytes}-byte map: an intermediate image buffer?"
    );
}
