//! The wgpu device, adapter choice and precision.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use crate::{Backend, ComputeError, CpuBackend, Precision};

struct Device {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    limits: wgpu::Limits,
    precision: Precision,
    readbacks: AtomicU64,
    host: CpuBackend,
}

/// The GPU backend: a wgpu device and queue, shared by clones.
#[derive(Clone)]
pub struct WgpuBackend {
    inner: Arc<Device>,
}

impl std::fmt::Debug for WgpuBackend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "WgpuBackend {{ adapter: {:?}, api: {:?}, precision: {} }}",
            self.inner.info.name,
            self.inner.info.backend,
            self.inner.precision.name()
        )
    }
}

fn rank(t: wgpu::DeviceType) -> u8 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    }
}

impl WgpuBackend {
    /// Opens the best adapter: discrete before integrated before software, restricted to
    /// names containing `WGPU_ADAPTER_NAME` (case-insensitive) and to the APIs in
    /// `WGPU_BACKEND` (e.g. `vulkan`) when these are set. `precision = None` takes f64
    /// when the adapter supports it and f32 otherwise; `Some(F64)` on an adapter without
    /// `SHADER_F64` is an error. Host-side work (assembly checks, output) uses a CPU pool
    /// with `PCDC_THREADS` or all cores.
    pub fn new(precision: Option<Precision>) -> Result<Self, ComputeError> {
        let backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY);
        let desc = wgpu::InstanceDescriptor {
            backends,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        };
        let instance = wgpu::Instance::new(desc);
        let mut adapters = pollster::block_on(instance.enumerate_adapters(backends));
        if adapters.is_empty() {
            return Err(ComputeError::Gpu(
                "no GPU adapter found (on Debian/Ubuntu without a GPU, install Mesa's lavapipe: apt-get install mesa-vulkan-drivers)".into(),
            ));
        }
        let all: Vec<String> = adapters
            .iter()
            .map(|a| {
                let i = a.get_info();
                format!("{} ({:?})", i.name, i.backend)
            })
            .collect();
        if let Ok(want) = std::env::var("WGPU_ADAPTER_NAME") {
            let want = want.to_lowercase();
            adapters.retain(|a| a.get_info().name.to_lowercase().contains(&want));
            if adapters.is_empty() {
                return Err(ComputeError::Gpu(format!(
                    "no adapter name contains WGPU_ADAPTER_NAME={want:?}; adapters: {}",
                    all.join(", ")
                )));
            }
        }
        if precision == Some(Precision::F64) {
            adapters.retain(|a| a.features().contains(wgpu::Features::SHADER_F64));
            if adapters.is_empty() {
                return Err(ComputeError::Gpu(format!(
                    "precision f64 requested but no adapter has SHADER_F64 ({}); use --precision f32",
                    all.join(", ")
                )));
            }
        }
        // Best kind first; among equals prefer f64 support.
        adapters.sort_by_key(|a| {
            (
                rank(a.get_info().device_type),
                !a.features().contains(wgpu::Features::SHADER_F64),
            )
        });
        let adapter = adapters.swap_remove(0);
        let has_f64 = adapter.features().contains(wgpu::Features::SHADER_F64);
        let precision = precision.unwrap_or(if has_f64 {
            Precision::F64
        } else {
            Precision::F32
        });
        let limits = adapter.limits();
        let required_features = if precision == Precision::F64 {
            wgpu::Features::SHADER_F64
        } else {
            wgpu::Features::empty()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("pcdc"),
            required_features,
            required_limits: limits.clone(),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .map_err(|e| ComputeError::Gpu(format!("device request failed: {e}")))?;
        Ok(WgpuBackend {
            inner: Arc::new(Device {
                device,
                queue,
                info: adapter.get_info(),
                limits,
                precision,
                readbacks: AtomicU64::new(0),
                host: CpuBackend::new(0)?,
            }),
        })
    }

    /// The adapter's name, e.g. "NVIDIA GeForce RTX 4090" or "llvmpipe (LLVM 15.0.6, 256 bits)".
    pub fn adapter_name(&self) -> &str {
        &self.inner.info.name
    }

    /// The graphics API in use (Vulkan, Metal, DX12).
    pub fn api(&self) -> String {
        format!("{:?}", self.inner.info.backend)
    }

    /// Whether the adapter is a software rasteriser (lavapipe, WARP): correct, not fast.
    pub fn is_software(&self) -> bool {
        self.inner.info.device_type == wgpu::DeviceType::Cpu
    }

    /// Number of device-to-host reads so far (each `run`, `evaluate_forces` or
    /// `update_state` call that ends in a read counts one).
    pub fn readbacks(&self) -> u64 {
        self.inner.readbacks.load(Ordering::Relaxed)
    }

    pub(crate) fn count_readback(&self) {
        self.inner.readbacks.fetch_add(1, Ordering::Relaxed);
    }

    /// Precision of the kernels.
    pub fn precision(&self) -> Precision {
        self.inner.precision
    }

    /// The host-side CPU pool (assembly checks, output).
    pub(crate) fn host(&self) -> &CpuBackend {
        &self.inner.host
    }

    /// The device limits in force (the adapter's own).
    pub fn limits(&self) -> &wgpu::Limits {
        &self.inner.limits
    }

    pub(crate) fn device(&self) -> &wgpu::Device {
        &self.inner.device
    }

    pub(crate) fn queue(&self) -> &wgpu::Queue {
        &self.inner.queue
    }
}

/// For GPU tests: the backend, or `None` after printing why the test is skipped. With
/// `PCDC_REQUIRE_GPU=1` a missing adapter panics instead (CI installs lavapipe).
pub fn gpu_test_backend(precision: Option<Precision>) -> Option<Backend> {
    match WgpuBackend::new(precision) {
        Ok(b) => Some(Backend::Gpu(b)),
        Err(e) => {
            if std::env::var("PCDC_REQUIRE_GPU").is_ok_and(|v| v == "1") {
                panic!("PCDC_REQUIRE_GPU=1 but no usable GPU adapter: {e}");
            }
            eprintln!("skipping GPU test: {e}");
            None
        }
    }
}
