//! Backends: where the per-step kernels run.
//!
//! `CpuBackend` runs on a private rayon thread pool. Every kernel writes per-entity slots
//! and every node sums its slots in a fixed order, so results are bit-identical for any
//! thread count.

use std::sync::Arc;

use crate::ComputeError;

/// Which kind of backend runs a simulation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
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
}

/// A compute backend. Physics implement [`crate::Physics`] for each backend they support.
pub trait Backend: Send + Sync + Clone + 'static {
    /// The kind of this backend.
    fn kind(&self) -> BackendKind;
    /// Number of worker threads (CPU) or 1 (GPU queue).
    fn threads(&self) -> usize;
    /// Floating-point precision of the kernels (the CPU always runs f64).
    fn precision_kind(&self) -> crate::Precision {
        crate::Precision::F64
    }
    /// Floating-point precision name (`f64` or `f32`), as printed in RESULT lines.
    fn precision(&self) -> &'static str {
        self.precision_kind().name()
    }
    /// Runs host-side work `f` (rayon parallel iterators inside use this backend's CPU
    /// pool: the CPU backend's own, or the GPU backend's host pool).
    fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R;
    /// The GPU backend, when this is one.
    fn as_gpu(&self) -> Option<&crate::gpu::WgpuBackend> {
        None
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
}

impl Backend for CpuBackend {
    fn kind(&self) -> BackendKind {
        BackendKind::Cpu
    }
    fn threads(&self) -> usize {
        self.threads
    }
    fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        self.pool.install(f)
    }
}
