//! The GPU backend on wgpu (Vulkan, Metal, DX12; Mesa's lavapipe on machines without a
//! GPU).
//!
//! * [`WgpuBackend`] picks an adapter (`WGPU_ADAPTER_NAME` narrows the choice by name,
//!   `WGPU_BACKEND` by API), creates a device with the adapter's own limits and runs in
//!   f64 when the adapter has `SHADER_F64`, in f32 otherwise or on request.
//! * Physics contribute WGSL kernels through [`crate::Physics::gpu_setup`] with a
//!   [`GpuSetup`]: they upload constant data, name the fields they touch and add kernels
//!   to the force or the kinematics phase. The backend owns every buffer, builds the
//!   pipelines and records whole batches of steps without reading anything back.
//! * One shader template serves both precisions: every module starts with
//!   `alias Real = f64;` (or `f32`) and the same prelude ([`assemble_source`]).
//! * Fields stay on the device during a run; [`crate::Simulation::run`] uploads the host
//!   state at its start and reads it back once at its end (output, histories, save).
//!   [`WgpuBackend::readbacks`] counts the device-to-host reads so tests can prove that
//!   no read happens inside the step loop.
//!
//! No kernel uses float atomics: forces go to per-contributor slots and every node sums
//! its slots in a fixed order, exactly as on the CPU; the only atomics are the integer
//! `atomicMin`s of the divergence watchdog.

//!
//! The declarations ([`GpuSetup`], [`Kernel`], WGSL assembly) are always compiled, so a
//! physics crate declares its kernels without any cfg; the device, the runs and naga's
//! validation come with the cargo feature `gpu` (on by default).

#[cfg(feature = "gpu")]
mod backend;
#[cfg(feature = "gpu")]
mod energy;
#[cfg_attr(not(feature = "gpu"), allow(dead_code))]
mod program;
#[cfg(feature = "gpu")]
mod run;

#[cfg(feature = "gpu")]
pub use backend::{gpu_test_backend, WgpuBackend};
pub use program::{
    assemble_source, splice_models, Access, ConstValue, GpuBuffer, GpuData, GpuSetup, Kernel,
    ModelSplice, Phase, PRELUDE,
};
#[cfg(feature = "gpu")]
pub use program::{offline_kernel_sources, validate_wgsl};
#[cfg(not(feature = "gpu"))]
mod disabled;
pub use crate::Precision;
#[cfg(not(feature = "gpu"))]
pub(crate) use disabled::GpuRun;
#[cfg(feature = "gpu")]
pub(crate) use run::GpuRun;

/// WGSL library of shared geometry for physics kernels (prepend it to a kernel's source):
/// `fn face_measure_normal(x, &n) -> Real`, the twin of `Dim::face_measure_normal`.
pub const WGSL_GEOMETRY: &str = include_str!("shaders/geometry.wgsl");
