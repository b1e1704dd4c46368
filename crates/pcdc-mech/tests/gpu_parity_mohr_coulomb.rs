//! CPU–GPU parity of Mohr–Coulomb (manual 7.2.4): the WGSL body repeats the CPU's
//! return mapping, so in f64 displacements, stresses and the plastic history agree to
//! 1e-12 relative. The scene yields in shear and in tension (random initial
//! displacements of 1e-3 strain on strengths of a few MPa), spins (the return runs in the
//! co-rotated frame) and has a softening material. Skips without a GPU adapter (fails
//! with PCDC_REQUIRE_GPU=1).

mod common;
use common::{noise, rel_diff};

use pcdc_compute::gpu::gpu_test_backend;
use pcdc_compute::{Backend, Precision, Simulation, Table};
use pcdc_mech::mohr_coulomb::{state, MC_STATE};
use pcdc_mech::{LinearElastic, Mechanics, MohrCoulomb, Softening};
use pcdc_mesh::{builders, Dim, Mesh, Range};

fn table(points: &[(f64, f64)]) -> Option<Table> {
    Some(Table::new("softening", points).unwrap())
}

struct Out {
    u: Vec<f64>,
    stress: Vec<f64>,
    history: Vec<f64>,
}

fn scene<D: Dim>(mesh: Mesh<D>, backend: Backend, steps: u64) -> Out {
    let e = LinearElastic::new(10e9, 0.25, 2500.0).unwrap();
    let plain =
        MohrCoulomb::new(e.clone().with_damping(0.2).unwrap(), 2e6, 30.0, 10.0, 1e6).unwrap();
    let soft = MohrCoulomb::new(e, 3e6, 35.0, 5.0, 1.5e6)
        .unwrap()
        .with_softening(Softening {
            cohesion: table(&[(0.0, 3e6), (2e-4, 1e6), (1e-3, 0.5e6)]),
            friction: table(&[(0.0, 35.0), (5e-4, 28.0)]),
            dilation: None,
            tensile: table(&[(0.0, 1.5e6), (1e-4, 0.0)]),
        })
        .unwrap();
    let (lo, hi) = mesh.bounding_box();
    let half = Range::HalfSpace {
        point: [0.5 * (lo[0] + hi[0]), 0.0, 0.0],
        normal: [1.0, 0.0, 0.0],
    };
    let mut s0 = [0.0; 6];
    s0[0] = -3e6;
    s0[1] = -1e6;
    s0[3] = 5e5;
    let mut sim = Simulation::builder(mesh, backend)
        .physics(
            Mechanics::new()
                .material(Range::All, plain)
                .material(half.clone(), soft)
                .initial_stress(half, s0),
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
    Out {
        u: sim.state.u.clone(),
        stress: sim.field("stress").unwrap().to_vec(),
        history: sim.field("model_state").unwrap().to_vec(),
    }
}

fn parity<D: Dim>(mesh: Mesh<D>, precision: Precision, tol: f64) {
    let Some(gpu) = gpu_test_backend(Some(precision)) else {
        return;
    };
    let steps = 200;
    let cpu = scene(mesh.clone(), Backend::cpu(1).unwrap(), steps);
    let dev = scene(mesh, gpu, steps);
    // The scene must exercise the plastic paths it checks.
    let ne = cpu.history.len() / MC_STATE;
    let count = |k: usize| {
        (0..ne)
            .filter(|e| cpu.history[e * MC_STATE + k] > 0.0)
            .count()
    };
    let (shear, tension) = (count(state::SHEAR_PAST), count(state::TENSION_PAST));
    assert!(
        shear > ne / 10 && tension > ne / 10,
        "shear {shear}, tension {tension} of {ne}"
    );
    let du = rel_diff(&cpu.u, &dev.u);
    let ds = rel_diff(&cpu.stress, &dev.stress);
    // Flags exactly equal where f64 rounding cannot flip them; strains to rounding.
    let dh = rel_diff(&cpu.history, &dev.history);
    println!(
        "{} {}: {shear} shear / {tension} tension of {ne} elements; max relative \
         difference displacement {du:.3e}, stress {ds:.3e}, history {dh:.3e}",
        D::NAME,
        precision.name()
    );
    assert!(du <= tol, "displacement differs by {du:e} (> {tol:e})");
    assert!(ds <= 10.0 * tol, "stress differs by {ds:e}");
    if precision == Precision::F64 {
        assert!(dh <= 10.0 * tol, "plastic history differs by {dh:e}");
    }
}

#[test]
fn mohr_coulomb_tri3_f64_matches_cpu() {
    parity(
        builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.02).unwrap(),
        Precision::F64,
        1e-12,
    );
}

#[test]
fn mohr_coulomb_tet4_f64_matches_cpu() {
    parity(
        builders::cuboid([0.0; 3], [0.1, 0.05, 0.05], 0.025).unwrap(),
        Precision::F64,
        1e-12,
    );
}

#[test]
fn mohr_coulomb_tri3_f32_error_is_small() {
    parity(
        builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.02).unwrap(),
        Precision::F32,
        1e-2,
    );
}
