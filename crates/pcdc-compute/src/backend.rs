//! Backends: where the per-step kernels run, chosen at run time.
//!
//! [`Backend`] is a value, not a type parameter: a program opens a CPU pool or a GPU
//! device once (e.g. from its command line) and hands it to
//! [`crate::Simulation::builder`]; physics, scenes and simulations have one type for
//! both. `CpuBackend` runs on a private rayon thread pool. Every kernel writes
//! per-entity slots and every node sums its slots in a fixed order, so results are
//! bit-identical for any thread count.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::ComputeError;

/// Which kind of backend runs a simulation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum BackendKind {
    /// rayon on the CPU (the reference backend).
    Cpu,
    /// wgpu on a GPU (or lavapipe).
    Gpu,
}

impl BackendKind {
    /// Short name as printed in RESULT lines (`cpu`).
    pub fn name(self) -> &'static str {
        match self {
            BackendKind::Cpu => "cpu",
            BackendKind::Gpu => "gpu",
        }
    }

    /// Parses `cpu` or `gpu`.
    pub fn parse(s: &str) -> Result<Self, ComputeError> {
        match s {
            "cpu" => Ok(BackendKind::Cpu),
            "gpu" => Ok(BackendKind::Gpu),
            _ => Err(ComputeError::param("backend", s, "expected cpu or gpu")),
        }
    }
}

/// Floating-point precision of the kernels (the CPU always runs f64).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Precision {
    /// 64-bit (on a GPU it needs the adapter feature `SHADER_F64`); matches the CPU to
    /// rounding.
    F64,
    /// 32-bit (GPU only): runs everywhere and fast on consumer GPUs; its error is
    /// measured, not hidden.
    F32,
}

impl Precision {
    /// `f64` or `f32`.
    pub fn name(self) -> &'static str {
        match self {
            Precision::F64 => "f64",
            Precision::F32 => "f32",
        }
    }

    /// Bytes per real number on the device.
    pub fn bytes(self) -> usize {
        match self {
            Precision::F64 => 8,
            Precision::F32 => 4,
        }
    }

    /// Parses `f64` or `f32`.
    pub fn parse(s: &str) -> Result<Self, ComputeError> {
        match s {
            "f64" => Ok(Precision::F64),
            "f32" => Ok(Precision::F32),
            _ => Err(ComputeError::param("precision", s, "expected f64 or f32")),
        }
    }
}

/// A backend request, e.g. from a program's command line: the kind and, for a GPU, the
/// precision. [`Backend::open`] turns it into a backend. The library parses no process
/// arguments; [`BackendChoice::from_env`] reads only `PCDC_BACKEND` and
/// `PCDC_PRECISION`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BackendChoice {
    /// CPU or GPU.
    pub kind: BackendKind,
    /// Requested precision (`None`: f64 where available).
    pub precision: Option<Precision>,
}

impl BackendChoice {
    /// A checked choice: f32 is a GPU option only.
    pub fn new(kind: BackendKind, precision: Option<Precision>) -> Result<Self, ComputeError> {
        if kind == BackendKind::Cpu && precision == Some(Precision::F32) {
            return Err(ComputeError::param(
                "precision",
                "f32",
                "the CPU backend runs in f64 only; f32 is a GPU option",
            ));
        }
        Ok(BackendChoice { kind, precision })
    }

    /// The choice named by `PCDC_BACKEND` (`cpu`, `gpu`) and `PCDC_PRECISION` (`f64`,
    /// `f32`), the CPU in f64 where they are unset.
    pub fn from_env() -> Result<Self, ComputeError> {
        let kind = match std::env::var("PCDC_BACKEND") {
            Ok(s) => BackendKind::parse(&s)?,
            Err(_) => BackendKind::Cpu,
        };
        let precision = std::env::var("PCDC_PRECISION")
            .ok()
            .map(|p| Precision::parse(&p))
            .transpose()?;
        Self::new(kind, precision)
    }
}

/// The CPU backend: rayon over entities on a private pool with a settable thread count.
#[derive(Clone)]
pub struct CpuBackend {
    pool: Arc<rayon::ThreadPool>,
    threads: usize,
}

impl std::fmt::Debug for CpuBackend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "CpuBackend {{ threads: {} }}", self.threads)
    }
}

impl CpuBackend {
    /// A CPU backend with `threads` worker threads (`0` = one per available core, or the
    /// value of the `PCDC_THREADS` environment variable when set).
    pub fn new(threads: usize) -> Result<Self, ComputeError> {
        let threads = if threads == 0 {
            std::env::var("PCDC_THREADS")
                .ok()
                .and_then(|s| s.parse::<usize>().ok())
                .filter(|&t| t > 0)
                .unwrap_or_else(|| {
                    std::thread::available_parallelism()
                        .map(|n| n.get())
                        .unwrap_or(1)
                })
        } else {
            threads
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("pcdc-cpu-{i}"))
            .build()
            .map_err(|e| ComputeError::param("threads", threads, e.to_string()))?;
        Ok(CpuBackend {
            pool: Arc::new(pool),
            threads,
        })
    }

    /// Number of worker threads.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Runs `f` on this pool (rayon parallel iterators inside use it).
    pub fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        self.pool.install(f)
    }
}

/// The backend a simulation runs on: a CPU thread pool or a GPU device (cargo feature
/// `gpu`, on by default). Cheap to clone (clones share the pool or device).
#[derive(Clone, Debug)]
pub enum Backend {
    /// rayon on the CPU.
    Cpu(CpuBackend),
    /// wgpu on a GPU.
    #[cfg(feature = "gpu")]
    Gpu(crate::gpu::WgpuBackend),
}

impl Backend {
    /// A CPU backend with `threads` worker threads (see [`CpuBackend::new`]).
    pub fn cpu(threads: usize) -> Result<Self, ComputeError> {
        Ok(Backend::Cpu(CpuBackend::new(threads)?))
    }

    /// The best GPU (see [`crate::gpu::WgpuBackend::new`]).
    #[cfg(feature = "gpu")]
    pub fn gpu(precision: Option<Precision>) -> Result<Self, ComputeError> {
        Ok(Backend::Gpu(crate::gpu::WgpuBackend::new(precision)?))
    }

    /// Opens the backend a [`BackendChoice`] names (the CPU with one thread per core or
    /// `PCDC_THREADS`). A GPU choice in a build without the `gpu` feature is an error.
    pub fn open(choice: BackendChoice) -> Result<Self, ComputeError> {
        let choice = BackendChoice::new(choice.kind, choice.precision)?;
        match choice.kind {
            BackendKind::Cpu => Self::cpu(0),
            #[cfg(feature = "gpu")]
            BackendKind::Gpu => Self::gpu(choice.precision),
            #[cfg(not(feature = "gpu"))]
            BackendKind::Gpu => Err(ComputeError::Gpu(
                "this build has no GPU backend: enable the cargo feature `gpu`".into(),
            )),
        }
    }

    /// The kind of this backend.
    pub fn kind(&self) -> BackendKind {
        match self {
            Backend::Cpu(_) => BackendKind::Cpu,
            #[cfg(feature = "gpu")]
            Backend::Gpu(_) => BackendKind::Gpu,
        }
    }

    /// Number of worker threads (CPU) or 1 (GPU queue).
    pub fn threads(&self) -> usize {
        match self {
            Backend::Cpu(c) => c.threads(),
            #[cfg(feature = "gpu")]
            Backend::Gpu(_) => 1,
        }
    }

    /// Floating-point precision of the kernels (the CPU always runs f64).
    pub fn precision_kind(&self) -> Precision {
        match self {
            Backend::Cpu(_) => Precision::F64,
            #[cfg(feature = "gpu")]
            Backend::Gpu(g) => g.precision(),
        }
    }

    /// Floating-point precision name (`f64` or `f32`), as printed in RESULT lines.
    pub fn precision(&self) -> &'static str {
        self.precision_kind().name()
    }

    /// Runs host-side work `f` (rayon parallel iterators inside use this backend's CPU
    /// pool: the CPU backend's own, or the GPU backend's host pool).
    pub fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        match self {
            Backend::Cpu(c) => c.install(f),
            #[cfg(feature = "gpu")]
            Backend::Gpu(g) => g.host().install(f),
        }
    }

    /// The GPU backend, when this is one.
    #[cfg(feature = "gpu")]
    pub fn as_gpu(&self) -> Option<&crate::gpu::WgpuBackend> {
        match self {
            Backend::Gpu(g) => Some(g),
            Backend::Cpu(_) => None,
        }
    }

    /// One line for reports, e.g. `cpu (2 threads), f64` or
    /// `gpu: NAME (Vulkan, software adapter: correct, not fast), f64`.
    pub fn describe(&self) -> String {
        match self {
            Backend::Cpu(c) => format!("cpu ({} threads), {}", c.threads(), self.precision()),
            #[cfg(feature = "gpu")]
            Backend::Gpu(g) => format!(
                "gpu: {} ({}{}), {}",
                g.adapter_name(),
                g.api(),
                if g.is_software() {
                    ", software adapter: correct, not fast"
                } else {
                    ""
                },
                self.precision()
            ),
        }
    }
}

impl From<CpuBackend> for Backend {
    fn from(c: CpuBackend) -> Self {
        Backend::Cpu(c)
    }
}

#[cfg(feature = "gpu")]
impl From<crate::gpu::WgpuBackend> for Backend {
    fn from(g: crate::gpu::WgpuBackend) -> Self {
        Backend::Gpu(g)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f32_is_a_gpu_option_only() {
        assert!(BackendChoice::new(BackendKind::Cpu, Some(Precision::F32)).is_err());
        assert!(BackendChoice::new(BackendKind::Cpu, Some(Precision::F64)).is_ok());
        assert!(BackendChoice::new(BackendKind::Gpu, Some(Precision::F32)).is_ok());
        assert!(BackendKind::parse("gpu").is_ok() && BackendKind::parse("cuda").is_err());
        assert!(Precision::parse("f16").is_err());
    }

    #[test]
    fn cpu_backend_is_described_with_its_threads() {
        let b = Backend::cpu(2).unwrap();
        assert_eq!(b.kind(), BackendKind::Cpu);
        assert_eq!(b.describe(), "cpu (2 threads), f64");
        assert_eq!(b.install(rayon::current_num_threads), 2);
    }
}
