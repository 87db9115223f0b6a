//! Choosing the kernel: CPU detection, `LUTPANO_KERNEL`, the active kernel.

use super::jobs::{cropped, jobs, span, tri_jobs, trilinear};
use super::{SpanJob, Texels, Window};
use crate::geom::fixed::Fx;
use crate::named::Named;
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::OnceLock;

/// The environment variable that forces a kernel (read once per process).
pub const KERNEL_ENV: &str = "LUTPANO_KERNEL";

/// An implementation of the span kernels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Kernel {
    /// Portable Rust, one pixel at a time: the reference every other kernel equals.
    Scalar,
    /// x86-64 SSE4.1, 4 pixels per step.
    Sse41,
    /// x86-64 AVX2, 8 pixels per step.
    Avx2,
    /// x86-64 AVX-512 (F, BW, VL, DQ), 16 pixels per step: the row and cube-face
    /// kernels; the span kernels, which have no AVX-512 version, run the AVX2 code.
    Avx512,
}

/// The kernels in order, slowest first; the names `LUTPANO_KERNEL`, `viewer bench
/// --kernel` and the reports use.
impl Named for Kernel {
    const ALL: &'static [Kernel] = &[Kernel::Scalar, Kernel::Sse41, Kernel::Avx2, Kernel::Avx512];

    fn name(self) -> &'static str {
        match self {
            Kernel::Scalar => "scalar",
            Kernel::Sse41 => "sse41",
            Kernel::Avx2 => "avx2",
            Kernel::Avx512 => "avx512",
        }
    }

    fn help(self) -> &'static str {
        match self {
            Kernel::Scalar => "Portable scalar code (the reference)",
            Kernel::Sse41 => "x86-64 SSE4.1, 4 pixels per step",
            Kernel::Avx2 => "x86-64 AVX2, 8 pixels per step",
            Kernel::Avx512 => "x86-64 AVX-512 (F, BW, VL, DQ), 16 pixels per step",
        }
    }
}

impl Kernel {
    /// The kernel's name (see [`Named`]).
    pub fn name(self) -> &'static str {
        Named::name(self)
    }

    /// True when this CPU runs the kernel.
    pub fn is_supported(self) -> bool {
        match self {
            Kernel::Scalar => true,
            #[cfg(target_arch = "x86_64")]
            Kernel::Sse41 => std::arch::is_x86_feature_detected!("sse4.1"),
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx2 => std::arch::is_x86_feature_detected!("avx2"),
            // AVX2 too: where no AVX-512 version exists, this kernel runs the AVX2 code.
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512 => {
                std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("avx512bw")
                    && std::arch::is_x86_feature_detected!("avx512vl")
                    && std::arch::is_x86_feature_detected!("avx512dq")
            }
            #[cfg(not(target_arch = "x86_64"))]
            Kernel::Sse41 | Kernel::Avx2 | Kernel::Avx512 => false,
        }
    }

    /// The fastest kernel this CPU runs.
    pub fn best() -> Kernel {
        Kernel::ALL
            .iter()
            .rev()
            .copied()
            .find(|k| k.is_supported())
            .unwrap_or(Kernel::Scalar)
    }

    /// The kernels this CPU runs, slowest first.
    pub fn available() -> Vec<Kernel> {
        Kernel::ALL
            .iter()
            .copied()
            .filter(|k| k.is_supported())
            .collect()
    }

    pub(super) fn selected(self) -> Selected {
        match Selected::new(self) {
            Some(s) => s,
            None => panic!(
                "the {} span kernel needs CPU features this machine lacks",
                self.name()
            ),
        }
    }

    /// Nearest samples along a span: `out[i]` = the pixel containing
    /// (u + i·du, v + i·dv) (Q.16 map coordinates; for a wrapping map u may start up to
    /// one period outside [0, W)). Returns `false`, writing nothing, when some position
    /// falls outside the map: the caller then samples per pixel (with clamps and wraps).
    /// The renderer calls this with the [`active_kernel`].
    ///
    /// # Panics
    /// When the CPU does not run this kernel ([`Kernel::is_supported`]).
    pub fn nearest_span(self, t: &Texels, out: &mut [u32], u: Fx, v: Fx, du: Fx, dv: Fx) -> bool {
        span::<false>(self.selected(), t, out, (u, v), (du, dv))
    }

    /// [`Kernel::nearest_span`] for a batch of spans of one output row (at most
    /// [`MAX_JOBS`](super::MAX_JOBS)): one call for many short spans. Returns a mask of
    /// the spans left unwritten because they leave the map (bit i: `spans[i]`).
    ///
    /// # Panics
    /// When the CPU does not run this kernel, a span does not fit in `row`, or there are
    /// more than [`MAX_JOBS`](super::MAX_JOBS) spans.
    pub fn nearest_spans(self, t: &Texels, row: &mut [u32], spans: &[SpanJob]) -> u64 {
        jobs::<false>(self.selected(), t, row, spans)
    }

    /// [`Kernel::bilinear_span`] for a batch of spans of one output row (see
    /// [`Kernel::nearest_spans`]).
    ///
    /// # Panics
    /// As [`Kernel::nearest_spans`].
    pub fn bilinear_spans(self, t: &Texels, row: &mut [u32], spans: &[SpanJob]) -> u64 {
        jobs::<true>(self.selected(), t, row, spans)
    }

    /// Bilinear samples along a span: the four pixel centres around each position
    /// − ½, 8-bit weights (see [`Kernel::nearest_span`] for the coordinates and the
    /// return value).
    ///
    /// # Panics
    /// When the CPU does not run this kernel ([`Kernel::is_supported`]).
    pub fn bilinear_span(self, t: &Texels, out: &mut [u32], u: Fx, v: Fx, du: Fx, dv: Fx) -> bool {
        span::<true>(self.selected(), t, out, (u, v), (du, dv))
    }

    /// Trilinear samples along a span with level of detail `lod` (Q.8, 256 = one
    /// level, as `lod_q8` in the pyramid module computes it): `levels[0]` is the map,
    /// `levels[k]` its pyramid level k (half the size of level k − 1). `lod` ≤ 0 is
    /// bilinear on level 0; otherwise levels k = `lod >> 8` and k + 1 (each clamped to
    /// the last) are sampled bilinearly at the positions and steps shifted right by their
    /// index and blended by `lod & 0xFF` (level k alone when that is 0 or both clamp to
    /// the same level); the second level restarts its position every
    /// [`TRILINEAR_CHUNK`](super::TRILINEAR_CHUNK) pixels. Returns `false` when a level's
    /// span leaves its map; `out` may then hold partial results and the caller samples it
    /// another way.
    ///
    /// # Panics
    /// When the CPU does not run this kernel, or `levels` is empty.
    #[allow(clippy::too_many_arguments)]
    pub fn trilinear_span(
        self,
        levels: &[Texels],
        lod: i32,
        out: &mut [u32],
        u: Fx,
        v: Fx,
        du: Fx,
        dv: Fx,
    ) -> bool {
        trilinear(self.selected(), levels, lod, out, (u, v), (du, dv))
    }

    /// [`Kernel::trilinear_span`] for a batch of spans of one output row, `lods[i]` the
    /// level of detail of `spans[i]` (see [`Kernel::nearest_spans`] for the batch and
    /// the answer).
    ///
    /// # Panics
    /// As [`Kernel::nearest_spans`], and when `lods` and `spans` differ in length or
    /// `levels` is empty.
    pub fn trilinear_spans(
        self,
        levels: &[Texels],
        row: &mut [u32],
        spans: &[SpanJob],
        lods: &[i32],
    ) -> u64 {
        tri_jobs(self.selected(), levels, row, spans, lods)
    }

    /// Nearest (`bilinear` false) or bilinear samples of a partial map along a span of
    /// full-panorama positions (see [`Window`]; `t` holds the stored pixels, wrapping
    /// only when they span 360°). Handled when the whole span lies in the stored
    /// pixels' interior (where the crop changes nothing: the plain span kernel on the
    /// stored pixels) or wholly in the background; otherwise (a span over the crop's
    /// edge) it returns `false`, writing nothing, and the caller samples per pixel.
    ///
    /// # Panics
    /// When the CPU does not run this kernel ([`Kernel::is_supported`]).
    #[allow(clippy::too_many_arguments)]
    pub fn cropped_span(
        self,
        bilinear: bool,
        t: &Texels,
        w: &Window,
        out: &mut [u32],
        u: Fx,
        v: Fx,
        du: Fx,
        dv: Fx,
    ) -> bool {
        cropped(self.selected(), bilinear, t, w, out, (u, v), (du, dv))
    }
}

impl std::fmt::Display for Kernel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Why a kernel choice cannot be used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum KernelError {
    /// A name that is not a kernel.
    #[error("{KERNEL_ENV}={value}: unknown kernel (expected auto, scalar, sse41, avx2 or avx512)")]
    Unknown {
        /// The value given.
        value: String,
    },
    /// A kernel this CPU cannot run.
    #[error("the {kernel} kernel needs CPU features this machine lacks (it runs: {runs})")]
    Unsupported {
        /// The kernel asked for.
        kernel: Kernel,
        /// The kernels it does run, comma-separated.
        runs: String,
    },
}

impl KernelError {
    fn unsupported(kernel: Kernel) -> KernelError {
        let runs: Vec<&str> = Kernel::available().iter().map(|k| k.name()).collect();
        KernelError::Unsupported {
            kernel,
            runs: runs.join(", "),
        }
    }
}

/// Parse a kernel name: `auto` (`None`: the best this CPU runs) or a [`Kernel::name`].
///
/// # Errors
/// [`KernelError::Unknown`] for another name, [`KernelError::Unsupported`] for a kernel
/// this CPU cannot run.
pub fn parse_kernel(s: &str) -> Result<Option<Kernel>, KernelError> {
    let s = s.trim();
    if s.eq_ignore_ascii_case("auto") {
        return Ok(None);
    }
    let k = Kernel::ALL
        .iter()
        .copied()
        .find(|k| s.eq_ignore_ascii_case(k.name()))
        .ok_or_else(|| KernelError::Unknown {
            value: s.to_string(),
        })?;
    if k.is_supported() {
        Ok(Some(k))
    } else {
        Err(KernelError::unsupported(k))
    }
}

/// The kernel `LUTPANO_KERNEL` asks for (`Ok(None)`: unset, empty or `auto`). Read once
/// per process; programs call this at start to reject a bad value with a clear message
/// (the renderer itself then falls back to the best kernel).
///
/// # Errors
/// As [`parse_kernel`].
pub fn kernel_from_env() -> Result<Option<Kernel>, KernelError> {
    static ENV: OnceLock<Result<Option<Kernel>, KernelError>> = OnceLock::new();
    ENV.get_or_init(|| match std::env::var(KERNEL_ENV) {
        Ok(s) if !s.trim().is_empty() => parse_kernel(&s),
        Ok(_) | Err(std::env::VarError::NotPresent) => Ok(None),
        Err(std::env::VarError::NotUnicode(s)) => Err(KernelError::Unknown {
            value: s.to_string_lossy().into_owned(),
        }),
    })
    .clone()
}

/// How the active kernel was chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KernelSource {
    /// The best kernel the CPU runs.
    Auto,
    /// `LUTPANO_KERNEL`.
    Env,
    /// [`set_kernel`].
    Api,
}

/// Which kernel runs, and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KernelInfo {
    /// The kernel the renderer uses.
    pub active: Kernel,
    /// How it was chosen.
    pub source: KernelSource,
    /// The fastest kernel this CPU runs.
    pub best: Kernel,
    /// The SIMD features this CPU reports (of those the kernels could use).
    pub cpu_features: Vec<&'static str>,
    /// A bad `LUTPANO_KERNEL` value, ignored in favour of the best kernel.
    pub env_error: Option<KernelError>,
}

impl std::fmt::Display for KernelInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let how = match self.source {
            KernelSource::Auto => "auto".to_string(),
            KernelSource::Env => format!("forced by {KERNEL_ENV}"),
            KernelSource::Api => "chosen by the program".to_string(),
        };
        let cpu = if self.cpu_features.is_empty() {
            "no SIMD features used here".to_string()
        } else {
            self.cpu_features.join(" ")
        };
        write!(f, "kernel {} ({how}; CPU: {cpu})", self.active)?;
        if let Some(e) = &self.env_error {
            write!(f, "; ignored: {e}")?;
        }
        Ok(())
    }
}

/// The CPU's SIMD features relevant to the kernels.
pub fn cpu_features() -> Vec<&'static str> {
    #[allow(unused_mut)]
    let mut v = Vec::new();
    #[cfg(target_arch = "x86_64")]
    {
        macro_rules! probe {
            ($($f:tt),*) => {$(
                if std::arch::is_x86_feature_detected!($f) {
                    v.push($f);
                }
            )*};
        }
        probe!("sse4.1", "avx2", "fma", "avx512f", "avx512bw", "avx512vl", "avx512dq");
    }
    #[cfg(target_arch = "aarch64")]
    {
        if std::arch::is_aarch64_feature_detected!("neon") {
            v.push("neon");
        }
    }
    v
}

/// `ACTIVE` before the first use.
const UNSET: u8 = u8::MAX;
/// The active kernel (`Kernel as u8`, only ever a supported one) and how it was chosen.
static ACTIVE: AtomicU8 = AtomicU8::new(UNSET);
static SOURCE: AtomicU8 = AtomicU8::new(KernelSource::Auto as u8);

fn decode(n: u8) -> Kernel {
    Kernel::ALL
        .get(n as usize)
        .copied()
        .unwrap_or(Kernel::Scalar)
}

/// The kernel the renderer uses (decided on first use, see the module docs).
#[inline]
pub fn active_kernel() -> Kernel {
    active().0
}

#[inline(always)]
pub(super) fn active() -> Selected {
    match ACTIVE.load(Ordering::Relaxed) {
        UNSET => init(),
        // Only supported kernels are stored (init and set_kernel check).
        n => Selected(decode(n)),
    }
}

#[cold]
fn init() -> Selected {
    let (k, source) = match kernel_from_env() {
        Ok(Some(k)) => (k, KernelSource::Env),
        _ => (Kernel::best(), KernelSource::Auto),
    };
    let k = Selected::new(k).unwrap_or(Selected(Kernel::Scalar));
    // A concurrent set_kernel wins.
    if ACTIVE
        .compare_exchange(UNSET, k.0 as u8, Ordering::Relaxed, Ordering::Relaxed)
        .is_ok()
    {
        SOURCE.store(source as u8, Ordering::Relaxed);
    }
    Selected(decode(ACTIVE.load(Ordering::Relaxed)))
}

/// Use `kernel` from now on in this process (`None`: the best the CPU runs); returns
/// the kernel now active. Rendered bytes do not change, only the speed.
///
/// # Errors
/// [`KernelError::Unsupported`] when the CPU cannot run it (nothing changes).
pub fn set_kernel(kernel: Option<Kernel>) -> Result<Kernel, KernelError> {
    let k = kernel.unwrap_or_else(Kernel::best);
    let s = Selected::new(k).ok_or_else(|| KernelError::unsupported(k))?;
    ACTIVE.store(s.0 as u8, Ordering::Relaxed);
    let source = if kernel.is_some() {
        KernelSource::Api
    } else {
        KernelSource::Auto
    };
    SOURCE.store(source as u8, Ordering::Relaxed);
    Ok(k)
}

/// Which kernel runs, how it was chosen, and the CPU's features.
pub fn kernel_info() -> KernelInfo {
    let active = active_kernel();
    let source = match SOURCE.load(Ordering::Relaxed) {
        x if x == KernelSource::Env as u8 => KernelSource::Env,
        x if x == KernelSource::Api as u8 => KernelSource::Api,
        _ => KernelSource::Auto,
    };
    KernelInfo {
        active,
        source,
        best: Kernel::best(),
        cpu_features: cpu_features(),
        env_error: kernel_from_env().err(),
    }
}

/// A kernel this CPU runs: made only by [`Selected::new`], which checks.
#[derive(Debug, Clone, Copy)]
pub(super) struct Selected(pub(super) Kernel);

impl Selected {
    fn new(k: Kernel) -> Option<Selected> {
        k.is_supported().then_some(Selected(k))
    }
}
