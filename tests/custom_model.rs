//! The custom-model example as a test: a user constitutive model with a history variable
//! and its WGSL body softens the plate on the CPU and gives the same displacements on
//! the GPU (f64, to 1e-12; skipped without an adapter, required with PCDC_REQUIRE_GPU=1).

#[allow(dead_code)]
#[path = "../examples/custom_model.rs"]
mod custom_model;

use pcdc::compute::gpu::gpu_test_backend;
use pcdc::compute::{Backend, Precision};

#[test]
fn user_model_softens_and_matches_on_the_gpu() {
    let cpu = custom_model::run(Backend::cpu(2).unwrap()).unwrap();
    assert!(cpu.max_damage > 0.5, "largest damage {}", cpu.max_damage);
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let g = custom_model::run(gpu).unwrap();
    assert_eq!(g.steps, cpu.steps);
    let scale = cpu.u.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let diff = cpu
        .u
        .iter()
        .zip(&g.u)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    eprintln!(
        "custom model: GPU-CPU relative displacement difference {:e}",
        diff / scale
    );
    assert!(diff <= 1e-12 * scale, "{}", diff / scale);
}
