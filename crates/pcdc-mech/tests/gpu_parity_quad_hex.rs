//! CPU–GPU parity of Quad4/Hex8 cells (mixed discretisation, `pcdc_mech::mixed`): the
//! trace pass and the cell-mean volumetric strain run on the device with the CPU's
//! arithmetic, so in f64 displacements and stresses agree to 1e-12 relative. The scene
//! mixes Tri3 and Quad4 cells (2D) or uses Hex8 (3D), spins, and yields in Mohr–Coulomb
//! in half of it. Skips without a GPU adapter (fails with PCDC_REQUIRE_GPU=1).

mod common;
use common::{noise, rel_diff};

use pcdc_compute::gpu::gpu_test_backend;
use pcdc_compute::{Backend, Precision, Simulation};
use pcdc_mech::{LinearElastic, Mechanics, MohrCoulomb};
use pcdc_mesh::{builders, Dim, Mesh, Range};

fn scene<D: Dim>(mesh: Mesh<D>, backend: Backend, steps: u64) -> (Vec<f64>, Vec<f64>) {
    let e = LinearElastic::new(10e9, 0.3, 2500.0).unwrap();
    let mc = MohrCoulomb::new(e.clone(), 2e6, 30.0, 0.0, 1e6).unwrap();
    let (lo, hi) = mesh.bounding_box();
    let half = Range::HalfSpace {
        point: [0.5 * (lo[0] + hi[0]), 0.0, 0.0],
        normal: [1.0, 0.0, 0.0],
    };
    let mut sim = Simulation::builder(mesh, backend)
        .physics(
            Mechanics::new()
                .material(Range::All, e.with_damping(0.1).unwrap())
                .material(half, mc),
        )
        .build()
        .unwrap();
    let d = D::D;
    let x = sim.mesh().coords().to_vec();
    let c: Vec<f64> = (0..d).map(|k| 0.5 * (lo[k] + hi[k])).collect();
    for n in 0..sim.mesh().n_nodes() {
        for k in 0..d {
            sim.state.u[n * d + k] = 2e-5 * noise(n * d + k);
        }
        let (rx, ry) = (x[n * d] - c[0], x[n * d + 1] - c[1]);
        sim.state.v[n * d] = -200.0 * ry;
        sim.state.v[n * d + 1] = 200.0 * rx;
    }
    sim.run(steps).unwrap();
    (sim.state.u.clone(), sim.field("stress").unwrap().to_vec())
}

fn parity<D: Dim>(mesh: Mesh<D>, precision: Precision, tol: f64) {
    let Some(gpu) = gpu_test_backend(Some(precision)) else {
        return;
    };
    assert!(mesh.cells().has_composite());
    let (u_cpu, s_cpu) = scene(mesh.clone(), Backend::cpu(1).unwrap(), 150);
    let (u_gpu, s_gpu) = scene(mesh, gpu, 150);
    let (du, ds) = (rel_diff(&u_cpu, &u_gpu), rel_diff(&s_cpu, &s_gpu));
    println!(
        "{} {}: max relative difference displacement {du:.3e}, stress {ds:.3e}",
        D::NAME,
        precision.name()
    );
    assert!(du <= tol, "displacement differs by {du:e} (> {tol:e})");
    assert!(ds <= 10.0 * tol, "stress differs by {ds:e}");
}

#[test]
fn mixed_tri3_quad4_f64_matches_cpu() {
    parity(
        builders::ring_mixed([0.0; 2], 0.05, 0.4, 0.02).unwrap(),
        Precision::F64,
        1e-12,
    );
}

#[test]
fn hex8_f64_matches_cpu() {
    parity(
        builders::cuboid_hexes([0.0; 3], [0.1, 0.05, 0.05], 0.02).unwrap(),
        Precision::F64,
        1e-12,
    );
}

#[test]
fn quad4_f32_error_is_small() {
    parity(
        builders::rectangle_quads(0.0, 0.0, 0.2, 0.1, 0.02).unwrap(),
        Precision::F32,
        1e-2,
    );
}
