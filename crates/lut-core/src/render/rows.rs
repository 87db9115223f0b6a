//! Running a per-row function over an image, on one thread or in row bands on rayon.

use rayon::prelude::*;
use std::cell::Cell;
use std::thread::LocalKey;

/// Pixels per rayon task (whole rows, at least one), so small frames stay on one thread.
///
/// Also the largest task: rayon cuts an indexed loop into about as many pieces as there
/// are threads and cuts a piece further only when another thread steals it, so a frame
/// could end with one thread drawing the rest of a quarter-frame piece while the other
/// waited (on 2 threads the 1080p frame took ~15 % longer than with tasks of 8 rows).
/// Tasks of one size let the threads share the work down to the last rows.
const PIXELS_PER_TASK: usize = 16384;

/// Rows per task for rows `width` long (see [`PIXELS_PER_TASK`]).
pub(crate) fn rows_per_task(width: usize) -> usize {
    (PIXELS_PER_TASK / width.max(1)).max(1)
}

/// Call `f(y, row)` for every `width`-long row of `out`, in parallel row bands when
/// `threads` is true. `f` sees the same rows either way, so the output does not depend on
/// the split.
pub(crate) fn for_each_row<T: Send>(
    out: &mut [T],
    width: usize,
    threads: bool,
    f: impl Fn(usize, &mut [T]) + Sync + Send,
) {
    let width = width.max(1);
    if threads && out.len() > width {
        out.par_chunks_mut(width)
            .enumerate()
            .with_min_len(rows_per_task(width))
            .with_max_len(rows_per_task(width))
            .for_each(|(y, row)| f(y, row));
    } else {
        out.chunks_mut(width)
            .enumerate()
            .for_each(|(y, row)| f(y, row));
    }
}

/// [`for_each_row`] with per-task state made by `init` (scratch buffers kept from row to
/// row).
pub(crate) fn for_each_row_init<T: Send, St>(
    out: &mut [T],
    width: usize,
    threads: bool,
    init: impl Fn() -> St + Sync + Send,
    f: impl Fn(&mut St, usize, &mut [T]) + Sync + Send,
) {
    let width = width.max(1);
    if threads && out.len() > width {
        out.par_chunks_mut(width)
            .enumerate()
            .with_min_len(rows_per_task(width))
            .with_max_len(rows_per_task(width))
            .for_each_init(init, |st, (y, row)| f(st, y, row));
    } else {
        let mut st = init();
        out.chunks_mut(width)
            .enumerate()
            .for_each(|(y, row)| f(&mut st, y, row));
    }
}

/// [`for_each_row_init`] in bands of `band_rows` rows (the last one shorter), calling
/// `post(y0, band)` on each band right after its rows were written (while they are still
/// in cache). Bands start at multiples of `band_rows`, whatever the threads; each band is
/// one task (see [`PIXELS_PER_TASK`]).
pub(crate) fn for_each_band_init<T: Send, St>(
    out: &mut [T],
    width: usize,
    band_rows: usize,
    threads: bool,
    init: impl Fn() -> St + Sync + Send,
    f: impl Fn(&mut St, usize, &mut [T]) + Sync + Send,
    post: impl Fn(usize, &mut [T]) + Sync + Send,
) {
    let width = width.max(1);
    let band_rows = band_rows.max(1);
    let run = |st: &mut St, (b, band): (usize, &mut [T])| {
        let y0 = b * band_rows;
        for (i, row) in band.chunks_mut(width).enumerate() {
            f(st, y0 + i, row);
        }
        post(y0, band);
    };
    if threads && out.len() > width * band_rows {
        out.par_chunks_mut(width * band_rows)
            .enumerate()
            .with_max_len(1)
            .for_each_init(init, run);
    } else {
        let mut st = init();
        out.chunks_mut(width * band_rows)
            .enumerate()
            .for_each(|b| run(&mut st, b));
    }
}

/// `post(y0, band)` over `out` in bands of `band_rows` rows (the last one shorter), in
/// parallel when `threads`: a [`for_each_band_init`] hook after a renderer that wrote the
/// whole frame itself.
pub(crate) fn post_bands<T: Send>(
    out: &mut [T],
    width: usize,
    band_rows: usize,
    threads: bool,
    post: impl Fn(usize, &mut [T]) + Sync + Send,
) {
    let chunk = width.max(1) * band_rows.max(1);
    if threads {
        out.par_chunks_mut(chunk)
            .enumerate()
            .with_max_len(1)
            .for_each(|(b, band)| post(b * band_rows, band));
    } else {
        out.chunks_mut(chunk)
            .enumerate()
            .for_each(|(b, band)| post(b * band_rows, band));
    }
}

/// Where a thread keeps a task's scratch of type `T` between tasks ([`Loan`]).
pub(crate) type Kept<T> = LocalKey<Cell<Option<Box<T>>>>;

/// A task's scratch on loan from its thread: the one the thread's last task gave back
/// (any frame), or a new one the first time; back to the thread when the loan drops.
/// With tasks of one band each ([`rows_per_task`]) a scratch made afresh per task was
/// allocated and zeroed ~135 times a 1080p frame. (What a scratch holds when lent is
/// never read: every task writes what it reads.)
pub(crate) struct Loan<T: 'static> {
    value: Option<Box<T>>,
    home: &'static Kept<T>,
}

impl<T: 'static> Loan<T> {
    /// The scratch `home` keeps for this thread, or `make()`'s.
    pub(crate) fn take(home: &'static Kept<T>, make: impl FnOnce() -> T) -> Loan<T> {
        let kept = home.take();
        Loan {
            value: Some(kept.unwrap_or_else(|| Box::new(make()))),
            home,
        }
    }
}

impl<T> std::ops::Deref for Loan<T> {
    type Target = T;
    fn deref(&self) -> &T {
        self.value.as_deref().expect("on loan until dropped")
    }
}

impl<T> std::ops::DerefMut for Loan<T> {
    fn deref_mut(&mut self) -> &mut T {
        self.value.as_deref_mut().expect("on loan until dropped")
    }
}

impl<T> Drop for Loan<T> {
    fn drop(&mut self) {
        // (During thread teardown the slot may be gone: the scratch is then freed.)
        let _ = self.home.try_with(|k| k.set(self.value.take()));
    }
}
