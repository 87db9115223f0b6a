//! The pixel storage of maps and pyramid levels: a zeroed `u32` buffer that, on Linux,
//! asks the kernel for transparent huge pages (`madvise(MADV_HUGEPAGE)`) on its whole
//! 2 MiB pages before any pixel is written.
//!
//! Why: a scanline of a panorama walks the map's rows 32 KiB (8k map) to 128 KiB (32k)
//! apart, so nearly every texel row it crosses is another 4 KiB page, and a 128 MiB to
//! 2 GiB map is far beyond what the TLB covers in 4 KiB pages (a few MiB); in 2 MiB pages
//! it covers gigabytes. Most Linux desktops run transparent huge pages in `madvise` mode
//! (`/sys/kernel/mm/transparent_hugepage/enabled`), where only memory that asks for them
//! gets them. Measured in `docs/huge.md` ("Huge pages").
//!
//! The buffer is a zeroed allocation from the global allocator (so allocation counters
//! see the map; for large blocks the system allocator maps fresh zero pages and touches
//! none of them), and the advice covers the 2 MiB-aligned part of it (all but less than
//! 2 MiB at each end) while it is still untouched: the pages are then faulted in as huge
//! pages when the pixels are first written, zeroed once by the kernel. (A 2 MiB-aligned
//! allocation was tried first: the allocator cannot hand it out zeroed without writing
//! it, and the extra zeroing pass made loading a 32k map slower.) Elsewhere, below 4 MiB,
//! when the kernel refuses the advice (no THP, `never` mode) or without
//! `LUTPANO_HUGE_PAGES=on`, it is an ordinary zeroed allocation: the pixels are the same
//! either way.
//!
//! **Off by default.** The idle-machine run of `scripts/perf-report.sh` (1 December 2026,
//! docs/huge.md) showed no frame gain beyond the run-to-run noise with the advice on,
//! while loading a 32k map took 4.5 s instead of 1.9 s on this VM (the first huge-page
//! faults of fresh guest memory are slow); interleaved CPU-time runs on a loaded machine
//! had shown 6–15 % per frame. Until a physical machine says otherwise, the advice is an
//! opt-in (`LUTPANO_HUGE_PAGES=on`). This module alone may use `unsafe` (allocation,
//! `madvise`), each block with its `// SAFETY:`.

#![allow(unsafe_code)]

use std::alloc::Layout;
use std::ptr::NonNull;
use std::sync::OnceLock;

/// The transparent huge page size (x86-64, and aarch64 with 4 KiB base pages).
pub const HUGE_PAGE: usize = 2 << 20;

/// Environment variable: `on` (or `1`) turns the huge-page advice on (read once; off by
/// default, see the module docs).
pub const HUGE_PAGES_ENV: &str = "LUTPANO_HUGE_PAGES";

/// Whether large buffers ask for huge pages: on Linux when [`HUGE_PAGES_ENV`] says
/// `on` / `1` / `yes` / `true`.
pub fn huge_pages_enabled() -> bool {
    static ON: OnceLock<bool> = OnceLock::new();
    *ON.get_or_init(|| {
        cfg!(target_os = "linux")
            && std::env::var(HUGE_PAGES_ENV).is_ok_and(|v| {
                matches!(
                    v.trim().to_ascii_lowercase().as_str(),
                    "on" | "1" | "yes" | "true"
                )
            })
    })
}

/// A zeroed, owned `[u32]` (see the module docs). Dereferences to the slice.
pub struct PixelBuf {
    ptr: NonNull<u32>,
    len: usize,
    /// The layout it was allocated with (`None`: empty, nothing allocated).
    layout: Option<Layout>,
}

// SAFETY: `PixelBuf` owns its allocation exclusively, like a `Vec<u32>`: sending it moves
// that ownership, and shared references only read.
unsafe impl Send for PixelBuf {}
// SAFETY: as above; `&PixelBuf` gives only `&[u32]`.
unsafe impl Sync for PixelBuf {}

impl PixelBuf {
    /// `len` zeroed pixels, or `None` when the memory cannot be had (or `len · 4`
    /// overflows).
    pub fn try_zeroed(len: usize) -> Option<PixelBuf> {
        let layout = Layout::array::<u32>(len).ok()?;
        if layout.size() == 0 {
            return Some(PixelBuf {
                ptr: NonNull::dangling(),
                len: 0,
                layout: None,
            });
        }
        // SAFETY: `layout` has a nonzero size.
        let p = unsafe { std::alloc::alloc_zeroed(layout) };
        let ptr = NonNull::new(p.cast::<u32>())?;
        if layout.size() >= 2 * HUGE_PAGE && huge_pages_enabled() {
            advise_huge(p, layout.size());
        }
        Some(PixelBuf {
            ptr,
            len,
            layout: Some(layout),
        })
    }

    /// `len` zeroed pixels; aborts as `vec!` does when the memory cannot be had.
    pub fn zeroed(len: usize) -> PixelBuf {
        PixelBuf::try_zeroed(len).unwrap_or_else(|| {
            std::alloc::handle_alloc_error(
                Layout::array::<u32>(len).unwrap_or_else(|_| Layout::new::<u32>()),
            )
        })
    }

    /// A copy of `px`.
    pub fn from_slice(px: &[u32]) -> PixelBuf {
        let mut b = PixelBuf::zeroed(px.len());
        b.copy_from_slice(px);
        b
    }
}

/// The 2 MiB-aligned part of `[p, p + bytes)`: its start and length (0 if none).
fn huge_part(p: usize, bytes: usize) -> (usize, usize) {
    let start = p.next_multiple_of(HUGE_PAGE);
    let end = (p + bytes) / HUGE_PAGE * HUGE_PAGE;
    (start, end.saturating_sub(start))
}

/// Ask for transparent huge pages on the whole 2 MiB pages of `[p, p + bytes)`. Advice
/// only: an error (no THP in this kernel) changes nothing.
#[cfg(target_os = "linux")]
fn advise_huge(p: *mut u8, bytes: usize) {
    let (start, len) = huge_part(p as usize, bytes);
    if len > 0 {
        // SAFETY: [start, start + len) lies inside the live allocation [p, p + bytes)
        // and starts on a 2 MiB (so a page) boundary, as madvise requires; MADV_HUGEPAGE
        // changes how the kernel backs the range, never its contents or validity.
        let _ =
            unsafe { libc::madvise(p.add(start - p as usize).cast(), len, libc::MADV_HUGEPAGE) };
    }
}

#[cfg(not(target_os = "linux"))]
fn advise_huge(_p: *mut u8, _bytes: usize) {}

impl Drop for PixelBuf {
    fn drop(&mut self) {
        if let Some(layout) = self.layout {
            // SAFETY: allocated in `try_zeroed` with exactly this layout, freed once.
            unsafe { std::alloc::dealloc(self.ptr.as_ptr().cast(), layout) };
        }
    }
}

impl std::ops::Deref for PixelBuf {
    type Target = [u32];
    #[inline(always)]
    fn deref(&self) -> &[u32] {
        // SAFETY: `ptr` points to `len` initialized (zeroed at allocation) `u32`s owned
        // by `self` (or is dangling with `len` 0).
        unsafe { std::slice::from_raw_parts(self.ptr.as_ptr(), self.len) }
    }
}

impl std::ops::DerefMut for PixelBuf {
    #[inline(always)]
    fn deref_mut(&mut self) -> &mut [u32] {
        // SAFETY: as in `deref`; `&mut self` makes this the only reference.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.as_ptr(), self.len) }
    }
}

impl Clone for PixelBuf {
    fn clone(&self) -> PixelBuf {
        PixelBuf::from_slice(self)
    }
}

impl std::fmt::Debug for PixelBuf {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PixelBuf").field("len", &self.len).finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The `VmFlags` line of the mapping holding address `a` in /proc/self/smaps.
    #[cfg(target_os = "linux")]
    fn vm_flags_at(a: usize) -> Option<String> {
        let smaps = std::fs::read_to_string("/proc/self/smaps").ok()?;
        let mut inside = false;
        for line in smaps.lines() {
            let first = line.split_whitespace().next().unwrap_or("");
            if let Some((lo, hi)) = first.split_once('-') {
                if let (Ok(lo), Ok(hi)) =
                    (usize::from_str_radix(lo, 16), usize::from_str_radix(hi, 16))
                {
                    inside = (lo..hi).contains(&a);
                    continue;
                }
            }
            if inside && line.starts_with("VmFlags:") {
                return Some(line.to_string());
            }
        }
        None
    }

    #[test]
    fn zeroed_and_writable() {
        for len in [
            0usize,
            1,
            3,
            1000,
            HUGE_PAGE / 4 - 1,
            HUGE_PAGE / 2,
            HUGE_PAGE + 5,
        ] {
            let mut b = PixelBuf::zeroed(len);
            assert_eq!(b.len(), len);
            assert!(b.iter().all(|&p| p == 0), "len {len}");
            assert_eq!(b.as_ptr() as usize % 4, 0);
            for (i, p) in b.iter_mut().enumerate() {
                *p = (i as u32).wrapping_mul(2654435761);
            }
            let c = b.clone();
            assert_eq!(&c[..], &b[..]);
            assert!(c
                .iter()
                .enumerate()
                .all(|(i, &p)| p == (i as u32).wrapping_mul(2654435761)));
        }
        assert!(PixelBuf::try_zeroed(usize::MAX / 2).is_none());
    }

    #[test]
    fn the_advised_part_is_whole_huge_pages_inside() {
        let h = HUGE_PAGE;
        assert_eq!(huge_part(h, 2 * h), (h, 2 * h));
        assert_eq!(huge_part(h + 16, h), (2 * h, 0));
        assert_eq!(huge_part(h + 16, 3 * h), (2 * h, 2 * h));
        assert_eq!(huge_part(16, 8 * h + 5), (h, 7 * h));
        for p in [16usize, 4096 + 16, 3 * h - 8] {
            let bytes = 64 * h + 12;
            let (s, n) = huge_part(p, bytes);
            assert!(s >= p && s + n <= p + bytes && s % h == 0 && n % h == 0);
            assert!(bytes - n < 2 * h, "all but less than 2 MiB at each end");
        }
    }

    /// A map's padded pixels (and its pyramid levels') sit in such a buffer: the same
    /// pixels as given.
    #[test]
    fn maps_and_levels_keep_their_pixels() {
        use crate::{EnvMap, Projection};
        let (w, h) = (1024u32, 512u32);
        let px: Vec<u32> = (0..w * h)
            .map(|i| i.wrapping_mul(2654435761) & 0xFFFFFF)
            .collect();
        let m = EnvMap::from_pixels(w, h, &px, Projection::Equirect).unwrap();
        for y in 0..h {
            for x in 0..w {
                assert_eq!(m.pixel(x, y), px[(y * w + x) as usize]);
            }
        }
        let (data, stride) = m.padded();
        assert_eq!(stride, w as usize + 1);
        assert_eq!(data.len(), (w as usize + 1) * (h as usize + 1));
        let c = m.clone();
        assert_eq!(c.padded().0, data);
        assert_eq!(m.pyramid()[0].width(), w / 2);
    }

    /// On Linux with transparent huge pages available, a large buffer's mapping carries
    /// the advice (`hg` in its `VmFlags`) unless it was turned off.
    #[cfg(target_os = "linux")]
    #[test]
    fn large_buffers_ask_for_huge_pages() {
        let thp = std::fs::read_to_string("/sys/kernel/mm/transparent_hugepage/enabled");
        let b = PixelBuf::zeroed(3 * HUGE_PAGE / 2);
        let (start, len) = huge_part(b.as_ptr() as usize, b.len() * 4);
        assert!(len > 0);
        let flags = vm_flags_at(start).expect("the buffer's mapping in smaps");
        let hg = flags.split_whitespace().any(|f| f == "hg");
        match (thp, huge_pages_enabled()) {
            (Ok(_), true) => assert!(hg, "{flags}"),
            (_, false) => assert!(!hg, "{flags}"),
            (Err(_), true) => {} // a kernel without THP refuses the advice
        }
    }
}
