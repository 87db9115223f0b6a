//! The pixel storage of maps and pyramid levels: a zeroed `u32` buffer that, on Linux and
//! from 2 MiB up, is 2 MiB-aligned and asks the kernel for transparent huge pages
//! (`madvise(MADV_HUGEPAGE)`) before any pixel is written.
//!
//! Why: a scanline of a panorama walks the map's rows 32 KiB (8k map) to 128 KiB (32k)
//! apart, so nearly every texel row it crosses is another 4 KiB page, and a 128 MiB to
//! 2 GiB map is far beyond what the TLB covers in 4 KiB pages (a few MiB); in 2 MiB pages
//! it covers gigabytes. Most Linux desktops run transparent huge pages in `madvise` mode
//! (`/sys/kernel/mm/transparent_hugepage/enabled`), where only memory that asks for them
//! gets them. Measured in `docs/huge.md` ("Huge pages").
//!
//! The buffer comes from the global allocator (so allocation counters see the map), with
//! a 2 MiB alignment so whole huge pages fit; the advice is given while the memory is
//! still untouched, then the buffer is zeroed in parallel bands (the first write faults
//! the pages in, as huge pages where the kernel has them). Elsewhere, below 2 MiB, when
//! the kernel refuses the advice (no THP, `never` mode) or with `LUTPANO_HUGE_PAGES=off`
//! (for A/B measurements), it is an ordinary zeroed allocation: the pixels are the same
//! either way. This module alone may use `unsafe` (allocation, `madvise`), each block
//! with its `// SAFETY:`.

#![allow(unsafe_code)]

use rayon::prelude::*;
use std::alloc::Layout;
use std::ptr::NonNull;
use std::sync::OnceLock;

/// The huge page size the buffer aligns to (x86-64 and aarch64 with 4 KiB base pages).
pub const HUGE_PAGE: usize = 2 << 20;

/// Environment variable: `off` (or `0`) turns the huge-page advice off (read once).
pub const HUGE_PAGES_ENV: &str = "LUTPANO_HUGE_PAGES";

/// Alignment of buffers too small for huge pages: a cache line.
const SMALL_ALIGN: usize = 64;

/// Whether large buffers ask for huge pages: on Linux unless [`HUGE_PAGES_ENV`] says
/// `off` / `0` / `no` / `false`.
pub fn huge_pages_enabled() -> bool {
    static ON: OnceLock<bool> = OnceLock::new();
    *ON.get_or_init(|| {
        cfg!(target_os = "linux")
            && !std::env::var(HUGE_PAGES_ENV).is_ok_and(|v| {
                matches!(
                    v.trim().to_ascii_lowercase().as_str(),
                    "off" | "0" | "no" | "false"
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
        let bytes = len.checked_mul(4)?;
        if bytes == 0 {
            return Some(PixelBuf {
                ptr: NonNull::dangling(),
                len: 0,
                layout: None,
            });
        }
        let huge = bytes >= HUGE_PAGE && huge_pages_enabled();
        let align = if huge { HUGE_PAGE } else { SMALL_ALIGN };
        let layout = Layout::from_size_align(bytes, align).ok()?;
        if !huge {
            // SAFETY: `layout` has a nonzero size.
            let p = unsafe { std::alloc::alloc_zeroed(layout) };
            return NonNull::new(p.cast::<u32>()).map(|ptr| PixelBuf {
                ptr,
                len,
                layout: Some(layout),
            });
        }
        // Not zeroed by the allocator: `alloc_zeroed` with a large alignment writes the
        // zeros itself, which would fault the pages in (as 4 KiB pages) before the
        // advice below.
        // SAFETY: `layout` has a nonzero size.
        let p = unsafe { std::alloc::alloc(layout) };
        let ptr = NonNull::new(p.cast::<u32>())?;
        advise_huge(p, bytes);
        // Zero in parallel bands of whole huge pages (each band's first writes fault its
        // pages in). The address goes to the workers as an integer.
        let base = p as usize;
        (0..bytes.div_ceil(HUGE_PAGE))
            .into_par_iter()
            .with_min_len(8)
            .for_each(|k| {
                let start = k * HUGE_PAGE;
                let n = HUGE_PAGE.min(bytes - start);
                // SAFETY: [start, start + n) lies inside the allocation of `bytes` bytes
                // made above, and the bands are disjoint; nothing else refers to it yet.
                unsafe { std::ptr::write_bytes((base + start) as *mut u8, 0, n) };
            });
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

    /// The alignment of the allocation (tests: 2 MiB for huge-page buffers).
    pub fn align(&self) -> usize {
        self.layout.map_or(1, |l| l.align())
    }
}

/// Ask for transparent huge pages on `[p, p + bytes)` (whole huge pages only; `p` is
/// 2 MiB-aligned). Advice only: an error (no THP in this kernel) changes nothing.
#[cfg(target_os = "linux")]
fn advise_huge(p: *mut u8, bytes: usize) {
    let len = bytes / HUGE_PAGE * HUGE_PAGE;
    if len > 0 {
        // SAFETY: `p` is the start of a live allocation of `bytes` ≥ `len` bytes, aligned
        // to 2 MiB (a multiple of the page size, as madvise requires); MADV_HUGEPAGE
        // changes how the kernel backs the range, never its contents or validity.
        let _ = unsafe { libc::madvise(p.cast(), len, libc::MADV_HUGEPAGE) };
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
        f.debug_struct("PixelBuf")
            .field("len", &self.len)
            .field("align", &self.align())
            .finish()
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
    fn zeroed_writable_and_aligned() {
        for len in [
            0usize,
            1,
            3,
            1000,
            HUGE_PAGE / 4 - 1,
            HUGE_PAGE / 4,
            3 * HUGE_PAGE / 4 + 5,
        ] {
            let mut b = PixelBuf::zeroed(len);
            assert_eq!(b.len(), len);
            assert!(b.iter().all(|&p| p == 0), "len {len}");
            let huge = len * 4 >= HUGE_PAGE && huge_pages_enabled();
            if len > 0 {
                let want = if huge { HUGE_PAGE } else { SMALL_ALIGN };
                assert_eq!(b.align(), want, "len {len}");
                assert_eq!(b.as_ptr() as usize % want, 0, "len {len}");
            }
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

    /// A map's padded pixels (and its pyramid levels') sit in such a buffer: the same
    /// pixels as given, 2 MiB-aligned when large.
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
        if huge_pages_enabled() {
            assert_eq!(data.as_ptr() as usize % HUGE_PAGE, 0);
        }
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
        let b = PixelBuf::zeroed(3 * HUGE_PAGE / 4);
        let flags = vm_flags_at(b.as_ptr() as usize).expect("the buffer's mapping in smaps");
        let hg = flags.split_whitespace().any(|f| f == "hg");
        match (thp, huge_pages_enabled()) {
            (Ok(_), true) => assert!(hg, "{flags}"),
            (_, false) => assert!(!hg, "{flags}"),
            (Err(_), true) => {} // a kernel without THP refuses the advice
        }
    }
}
