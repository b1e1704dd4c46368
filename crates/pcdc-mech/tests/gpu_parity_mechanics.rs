//! CPU–GPU parity of element mechanics: one test body, instantiated for both backends.
//! In f64 the displacements agree to 1e-12 relative; in f32 the difference is measured
//! and printed. Without a GPU adapter the tests skip (and fail with PCDC_REQUIRE_GPU=1).

use pcdc_compute::gpu::gpu_test_backend;
use pcdc_compute::{Backend, Precision, Simulation};
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim, Mesh, Range};

/// Deterministic pseudo-random numbers in [-1, 1).
fn noise(i: usize) -> f64 {
    let x = (i as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let x = (x ^ (x >> 29)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    ((x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// A free-vibration and spin scene: random initial displacement and a rigid spin, two
/// materials (one damped, with an initial stress), `steps` explicit steps.
fn scene<D: Dim>(mesh: Mesh<D>, backend: Backend, steps: u64) -> (Vec<f64>, Vec<f64>) {
    let soft = LinearElastic::new(10e9, 0.3, 2400.0).unwrap();
    let stiff = LinearElastic::new(40e9, 0.2, 2700.0)
        .unwrap()
        .with_damping(0.3)
        .unwrap();
    let (lo, hi) = mesh.bounding_box();
    let mid = 0.5 * (lo[0] + hi[0]);
    let half = Range::HalfSpace {
        point: [mid, 0.0, 0.0],
        normal: [1.0, 0.0, 0.0],
    };
    let mut s0 = [0.0; 6];
    s0[0] = -1e6;
    s0[3] = 2e5;
    let mut sim = Simulation::builder(mesh, backend)
        .physics(
            Mechanics::new()
                .material(Range::All, soft)
                .material(half.clone(), stiff)
                .initial_stress(half, s0),
        )
        .build()
        .unwrap();
    let d = D::D;
    let x = sim.mesh().coords().to_vec();
    let c: Vec<f64> = (0..d).map(|k| 0.5 * (lo[k] + hi[k])).collect();
    for n in 0..sim.mesh().n_nodes() {
        for k in 0..d {
            sim.state.u[n * d + k] = 1e-5 * noise(n * d + k);
        }
        // Spin ω = 200 rad/s about z (and about x in 3D).
        let (rx, ry) = (x[n * d] - c[0], x[n * d + 1] - c[1]);
        sim.state.v[n * d] = -200.0 * ry;
        sim.state.v[n * d + 1] = 200.0 * rx;
        if d == 3 {
            let rz = x[n * d + 2] - c[2];
            sim.state.v[n * d + 1] -= 150.0 * rz;
            sim.state.v[n * d + 2] = 150.0 * ry;
        }
    }
    sim.run(steps).unwrap();
    let stress = sim.field("stress").unwrap().to_vec();
    (sim.state.u.clone(), stress)
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let diff = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    diff / scale
}

fn parity<D: Dim>(mesh: Mesh<D>, precision: Precision, tol: f64) {
    let Some(gpu) = gpu_test_backend(Some(precision)) else {
        return;
    };
    let steps = 300;
    let (u_cpu, s_cpu) = scene(mesh.clone(), Backend::cpu(1).unwrap(), steps);
    let reads = gpu.as_gpu().expect("a GPU backend").readbacks();
    let (u_gpu, s_gpu) = scene(mesh, gpu.clone(), steps);
    // One read-back for the whole 300-step run (plus none while building).
    assert_eq!(
        gpu.as_gpu().expect("a GPU backend").readbacks() - reads,
        1,
        "device reads inside the step loop"
    );
    let (du, ds) = (rel_diff(&u_cpu, &u_gpu), rel_diff(&s_cpu, &s_gpu));
    println!(
        "{} {} on {}: max relative difference displacement {du:.3e}, stress {ds:.3e}",
        D::NAME,
        precision.name(),
        gpu.as_gpu().expect("a GPU backend").adapter_name()
    );
    assert!(du <= tol, "displacement differs by {du:e} (> {tol:e})");
    assert!(ds <= tol * 10.0, "stress differs by {ds:e}");
}

#[test]
fn tri3_f64_matches_cpu() {
    let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.02).unwrap();
    parity(mesh, Precision::F64, 1e-12);
}

#[test]
fn tet4_f64_matches_cpu() {
    let mesh = builders::cuboid([0.0; 3], [0.1, 0.05, 0.05], 0.025).unwrap();
    parity(mesh, Precision::F64, 1e-12);
}

#[test]
fn tri3_f32_error_is_small() {
    let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.02).unwrap();
    parity(mesh, Precision::F32, 1e-3);
}

#[test]
fn tet4_f32_error_is_small() {
    let mesh = builders::cuboid([0.0; 3], [0.1, 0.05, 0.05], 0.025).unwrap();
    parity(mesh, Precision::F32, 1e-3);
}

/// A time step far above the stable one: both backends stop with the same step and node.
#[test]
fn watchdog_names_the_same_step_and_node() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    fn diverge(backend: Backend) -> (u64, String) {
        let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.02).unwrap();
        let rock = LinearElastic::new(30e9, 0.25, 2600.0).unwrap();
        let mut sim = Simulation::builder(mesh, backend)
            .physics(Mechanics::new().material(Range::All, rock))
            .time_step(5e-6)
            .runaway_displacement(1.0)
            .build()
            .unwrap();
        sim.state.u[7] = 1e-6;
        match sim.run(2000) {
            Err(pcdc_compute::ComputeError::Diverged { step, entity, .. }) => (step, entity),
            other => panic!("expected divergence, got {other:?}"),
        }
    }
    let cpu = diverge(Backend::cpu(1).unwrap());
    let gpu = diverge(gpu);
    println!("cpu stops at {cpu:?}, gpu at {gpu:?}");
    assert_eq!(cpu, gpu);
}

/// Restore-and-continue on the GPU equals the uninterrupted GPU run bit for bit.
#[test]
fn gpu_restore_and_continue_is_exact() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let mesh = builders::cuboid([0.0; 3], [0.1, 0.05, 0.05], 0.025).unwrap();
    let build = || {
        let rock = LinearElastic::new(30e9, 0.25, 2600.0)
            .unwrap()
            .with_damping(0.2)
            .unwrap();
        let mut sim = Simulation::builder(mesh.clone(), gpu.clone())
            .physics(Mechanics::new().material(Range::All, rock))
            .build()
            .unwrap();
        for (i, v) in sim.state.v.iter_mut().enumerate() {
            *v = 0.1 * noise(i);
        }
        sim
    };
    let mut a = build();
    a.run(100).unwrap();
    let snap = a.snapshot_bytes().unwrap();
    a.run(150).unwrap();
    let mut b = build();
    b.restore_bytes(&snap).unwrap();
    b.run(150).unwrap();
    assert_eq!(a.state.u, b.state.u);
    assert_eq!(a.field("stress").unwrap(), b.field("stress").unwrap());
}

/// Static relaxation (mass scaling, local damping, unbalanced-force ratio) reaches the
/// same equilibrium. Not to rounding: local damping switches on sign(v), so rounding
/// differences (GPU compilers fuse multiply-adds) flip the branch where a velocity
/// crosses zero and the two runs take different paths to the same state; the agreement
/// is that of the convergence tolerance.
#[test]
fn relaxation_matches_cpu() {
    use pcdc_compute::StaticOptions;
    use pcdc_mech::{Boundary, FaceStress};
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    fn relax(backend: Backend) -> (u64, Vec<f64>) {
        let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.4, 0.02).unwrap();
        let rock = LinearElastic::new(30e9, 0.25, 2600.0).unwrap();
        let mut sim = Simulation::builder(mesh, backend)
            .physics(Mechanics::new().material(Range::All, rock))
            .physics(
                Boundary::new()
                    .fix(Range::group("bottom"))
                    .face_stress(Range::group("top"), FaceStress::normal(-1e6))
                    .face_stress(Range::group("left"), FaceStress::diagonal(-3e5, 0.0, 0.0)),
            )
            .build()
            .unwrap();
        let r = sim.relax(&StaticOptions::default()).unwrap();
        (r.steps, sim.state.u.clone())
    }
    let (n_cpu, u_cpu) = relax(Backend::cpu(1).unwrap());
    let (n_gpu, u_gpu) = relax(gpu);
    let d = rel_diff(&u_cpu, &u_gpu);
    println!("relaxation: cpu {n_cpu} steps, gpu {n_gpu} steps, rel. diff u {d:.3e}");
    assert!(d < 1e-3, "{d:e}");
    assert!((n_gpu as f64 - n_cpu as f64).abs() < 0.3 * n_cpu as f64);
}
