//! Choosing the kernel: CPU detection, `LUTPANO_KERNEL`, the active kernel.

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

    /// This kernel, to call its operations (the methods of [`SelectedKernel`]).
    ///
    /// # Errors
    /// [`KernelError::Unsupported`] when the CPU does not run it.
    pub fn select(self) -> Result<SelectedKernel, KernelError> {
        SelectedKernel::new(self).ok_or_else(|| KernelError::unsupported(self))
    }

    /// [`Kernel::select`] for the tests, which run only the kernels the CPU has.
    ///
    /// # Panics
    /// When the CPU does not run this kernel.
    #[cfg(test)]
    pub(crate) fn selected(self) -> SelectedKernel {
        match SelectedKernel::new(self) {
            Some(s) => s,
            None => panic!(
                "the {} kernel needs CPU features this machine lacks",
                self.name()
            ),
        }
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

/// The active kernel ([`active_kernel`]), as the operations take it.
#[inline(always)]
pub(crate) fn active() -> SelectedKernel {
    match ACTIVE.load(Ordering::Relaxed) {
        UNSET => init(),
        // Only supported kernels are stored (init and set_kernel check).
        n => SelectedKernel(decode(n)),
    }
}

#[cold]
fn init() -> SelectedKernel {
    let (k, source) = match kernel_from_env() {
        Ok(Some(k)) => (k, KernelSource::Env),
        _ => (Kernel::best(), KernelSource::Auto),
    };
    let k = SelectedKernel::new(k).unwrap_or(SelectedKernel(Kernel::Scalar));
    // A concurrent set_kernel wins.
    if ACTIVE
        .compare_exchange(UNSET, k.0 as u8, Ordering::Relaxed, Ordering::Relaxed)
        .is_ok()
    {
        SOURCE.store(source as u8, Ordering::Relaxed);
    }
    SelectedKernel(decode(ACTIVE.load(Ordering::Relaxed)))
}

/// Use `kernel` from now on in this process (`None`: the best the CPU runs); returns
/// the kernel now active. Rendered bytes do not change, only the speed.
///
/// # Errors
/// [`KernelError::Unsupported`] when the CPU cannot run it (nothing changes).
pub fn set_kernel(kernel: Option<Kernel>) -> Result<Kernel, KernelError> {
    let k = kernel.unwrap_or_else(Kernel::best);
    let s = SelectedKernel::new(k).ok_or_else(|| KernelError::unsupported(k))?;
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

/// A kernel this CPU runs, made only by [`Kernel::select`] (or, for the active kernel,
/// by the renderer's `active()`), which check: the operations are its methods (each
/// operation's `mod.rs`: `span/`, `row/`, `face/`, `nodes/`, `shade/`), and their SIMD
/// forms rely on that check.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SelectedKernel(pub(super) Kernel);

impl SelectedKernel {
    fn new(k: Kernel) -> Option<SelectedKernel> {
        k.is_supported().then_some(SelectedKernel(k))
    }

    /// The kernel.
    pub fn kernel(self) -> Kernel {
        self.0
    }
}
