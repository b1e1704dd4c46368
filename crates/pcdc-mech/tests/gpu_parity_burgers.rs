//! CPU–GPU parity of Burgers creep (manual 7.2.5): random initial displacements (every
//! strain component), a spin, and a creep step in effect from the clock, then a second
//! creep step (the commit of e^K) and one without creep; in f64 displacements agree to
//! 1e-12 relative, stresses and the history to 1e-11 or twice the difference the
//! elastic part shows in the same scene (the kinematics' rounding of U − I, about
//! 4e-11 of the largest stress here in 3D), whichever is larger. Skips without a GPU adapter (fails with
//! PCDC_REQUIRE_GPU=1).

mod common;
use common::{noise, rel_diff};

use pcdc_compute::gpu::gpu_test_backend;
use pcdc_compute::{Backend, Precision, Simulation};
use pcdc_mech::{Burgers, CreepClock, LinearElastic, Mechanics, CREEP_CLOCK};
use pcdc_mesh::{builders, Dim, Mesh, Range};

/// The scene with Burgers or, with `elastic`, its instantaneous elastic part (the
/// kinematics' own CPU–GPU difference in this scene).
fn scene<D: Dim>(mesh: Mesh<D>, backend: Backend, elastic: bool) -> [Vec<f64>; 3] {
    let e = LinearElastic::from_bulk_shear(5e9, 3e9, 2500.0)
        .unwrap()
        .with_damping(0.1)
        .unwrap();
    let b = Burgers::new(e, 2e9, 1e11, 5e11)
        .unwrap()
        .with_kelvin_strain([1e-4, -0.5e-4, -0.5e-4, 2e-5, 0.0, 1e-5])
        .unwrap();
    let clock = CreepClock::new(&[&b], 1.0).unwrap();
    let mut sim = Simulation::builder(mesh, backend)
        .physics(if elastic {
            Mechanics::new().material(Range::All, b.elastic().clone())
        } else {
            Mechanics::new().material(Range::All, b)
        })
        .physics(clock)
        .build()
        .unwrap();
    let d = D::D;
    let x = sim.mesh().coords().to_vec();
    for n in 0..sim.mesh().n_nodes() {
        for k in 0..d {
            sim.state.u[n * d + k] = 1e-5 * noise(n * d + k);
        }
        sim.state.v[n * d] = -50.0 * x[n * d + 1];
        sim.state.v[n * d + 1] = 50.0 * x[n * d];
    }
    let set_clock = |sim: &mut Simulation<D>, index: f64, dt: f64| {
        let id = sim.state.fields.id(CREEP_CLOCK).unwrap();
        for c in sim.state.fields.get_mut(id).chunks_exact_mut(4) {
            c[0] = index;
            c[1] = dt;
        }
    };
    set_clock(&mut sim, 1.0, 5.0);
    sim.run(60).unwrap();
    set_clock(&mut sim, 2.0, 20.0);
    sim.run(60).unwrap();
    set_clock(&mut sim, 3.0, 0.0);
    sim.run(60).unwrap();
    [
        sim.state.u.clone(),
        sim.field("stress").unwrap().to_vec(),
        sim.field("model_state").unwrap().to_vec(),
    ]
}

fn parity<D: Dim>(mesh: Mesh<D>, precision: Precision, tol: f64) {
    let Some(gpu) = gpu_test_backend(Some(precision)) else {
        return;
    };
    let cpu = scene(mesh.clone(), Backend::cpu(1).unwrap(), false);
    let dev = scene(mesh.clone(), gpu.clone(), false);
    let d: Vec<f64> = (0..3).map(|k| rel_diff(&cpu[k], &dev[k])).collect();
    // The stress of U − I carries the kinematics' rounding (≈ 2G ulp(1) a step, the 3D
    // polar iteration's last digit): measured on the elastic part in the same scene.
    let floor = rel_diff(
        &scene(mesh.clone(), Backend::cpu(1).unwrap(), true)[1],
        &scene(mesh, gpu, true)[1],
    );
    println!(
        "{} {}: max relative difference displacement {:.3e}, stress {:.3e} (elastic part \
         in the same scene {floor:.3e}), history {:.3e}",
        D::NAME,
        precision.name(),
        d[0],
        d[1],
        d[2]
    );
    assert!(d[0] <= tol, "displacement differs by {:e}", d[0]);
    let bar = (10.0 * tol).max(2.0 * floor);
    assert!(d[1] <= bar, "stress differs by {:e} (> {bar:e})", d[1]);
    assert!(d[2] <= bar, "history differs by {:e} (> {bar:e})", d[2]);
}

#[test]
fn burgers_tri3_f64_matches_cpu() {
    parity(
        builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.02).unwrap(),
        Precision::F64,
        1e-12,
    );
}

#[test]
fn burgers_tet4_f64_matches_cpu() {
    parity(
        builders::cuboid([0.0; 3], [0.1, 0.05, 0.05], 0.025).unwrap(),
        Precision::F64,
        1e-12,
    );
}

#[test]
fn burgers_tri3_f32_error_is_small() {
    parity(
        builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.02).unwrap(),
        Precision::F32,
        1e-2,
    );
}
