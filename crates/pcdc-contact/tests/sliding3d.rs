//! 3D: a tetrahedral block sliding with Coulomb friction on a fixed base stops after
//! d = v0² / (2 g tan φ) (manual eq. 62, the 3D form of validation scene 2), and a
//! snapshot of the sliding block restores bit for bit.

use pcdc_compute::{Backend, Simulation};
use pcdc_contact::Contact;
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim3, Range};

const E: f64 = 1e6;
const RHO: f64 = 2600.0;
const G: f64 = 9.81;
const PHI: f64 = 30.0;
const SIZE: f64 = 0.025;
const BASE_TOP: f64 = 0.025;

/// A 0.05 m cube of tetrahedra on a fixed 0.15 x 0.05 x 0.025 m base (z up), sliding
/// along x at `v0`; returns the simulation and the block's nodes.
fn scene(v0: f64, threads: usize) -> (Simulation<Dim3>, Vec<u32>) {
    let base = builders::cuboid([0.0, 0.0, 0.0], [0.15, 0.05, BASE_TOP], SIZE).unwrap();
    let block = builders::cuboid([0.025, 0.0, BASE_TOP], [0.05, 0.05, 0.05], SIZE).unwrap();
    let (mesh, bodies) = builders::union(&[&base, &block]).unwrap();
    // Element viscous damping 1 (the manual's quasi-static value), as in the 2D scene: it
    // calms the block's bouncing on the contact penalty.
    let rock = LinearElastic::new(E, 0.25, RHO)
        .unwrap()
        .with_damping(1.0)
        .unwrap();
    let mut sim = Simulation::builder(mesh, Backend::cpu(threads).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(Contact::new(10.0 * E).friction(PHI, 10.0 * E))
        .physics(Boundary::new().fix(Range::cuboid(
            [-1.0, -1.0, -1.0],
            [1.0, 1.0, BASE_TOP - 1e-9],
        )))
        .gravity([0.0, 0.0, -G])
        .build()
        .unwrap();
    let block = bodies[1].clone();
    for &n in &block {
        sim.state.v[3 * n as usize] = v0;
    }
    (sim, block)
}

#[test]
fn block_3d_stops_at_the_coulomb_distance() {
    let v0 = 0.5;
    let tan = PHI.to_radians().tan();
    let expected = v0 * v0 / (2.0 * G * tan);
    let (mut sim, block) = scene(v0, 2);
    let mean = |s: &Simulation<Dim3>, k: usize| {
        block
            .iter()
            .map(|&n| {
                let x = if k == 0 {
                    s.mesh().node(n as usize)[0] + s.state.u[3 * n as usize]
                } else {
                    s.state.v[3 * n as usize]
                };
                x
            })
            .sum::<f64>()
            / block.len() as f64
    };
    let x0 = mean(&sim, 0);
    let t_stop = v0 / (G * tan);
    while sim.state.time < 1.5 * t_stop {
        sim.step().unwrap();
        if sim.state.time > 0.5 * t_stop && mean(&sim, 1).abs() < 1e-3 * v0 {
            break;
        }
    }
    let distance = mean(&sim, 0) - x0;
    let error = (distance - expected).abs() / expected;
    // The block stayed on the base and did not drift sideways.
    let ys: Vec<f64> = block
        .iter()
        .map(|&n| sim.state.u[3 * n as usize + 1])
        .collect();
    let drift = ys.iter().map(|y| y.abs()).fold(0.0, f64::max);
    eprintln!(
        "3D sliding block: v0 {v0} m/s, distance {distance:.5} m vs {expected:.5} m ({:.2} %), stopped at t = {:.4} s (t_stop {t_stop:.4}), {} steps, {} elements, sideways drift {drift:.2e} m",
        100.0 * error,
        sim.state.time,
        sim.state.step,
        sim.mesh().n_elements()
    );
    eprintln!(
        "time step {:.3e} s, limited by {:?}",
        sim.dt(),
        sim.time_step_limit()
    );
    assert!(
        sim.state.time < 1.5 * t_stop,
        "the block did not stop by 1.5 t_stop"
    );
    assert!(error <= 0.03, "stopping distance error {error}");
    assert!(drift < 0.01 * SIZE, "sideways drift {drift}");
}

#[test]
fn frictional_contact_3d_restores_bit_for_bit() {
    let (mut a, block) = scene(0.5, 2);
    a.run(400).unwrap();
    let snap = a.snapshot_bytes().unwrap();
    a.run(400).unwrap();
    let (mut b, _) = scene(0.5, 2);
    b.restore_bytes(&snap).unwrap();
    b.run(400).unwrap();
    assert!(a
        .state
        .u
        .iter()
        .zip(&b.state.u)
        .all(|(x, y)| x.to_bits() == y.to_bits()));
    assert!(a
        .state
        .v
        .iter()
        .zip(&b.state.v)
        .all(|(x, y)| x.to_bits() == y.to_bits()));
    // The block is still sliding (the state mattered).
    assert!(block.iter().any(|&n| a.state.v[3 * n as usize] > 0.1));
}
