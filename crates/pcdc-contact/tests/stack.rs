//! Hard case: a stack of three blocks dropped onto a fixed base under gravity comes to
//! rest, with the interpenetration bounded by the penalty.

use pcdc_compute::{Backend, Simulation};
use pcdc_contact::Contact;
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim2, Mesh, Range};

const E: f64 = 1e8;
const G: f64 = 9.81;

/// A base 0.3 x 0.05 m and three 0.1 x 0.05 m blocks stacked with 1 mm gaps.
fn stack() -> (Mesh<Dim2>, Vec<Vec<u32>>) {
    let mut bodies = vec![builders::rectangle(0.0, 0.0, 0.3, 0.05, 0.025).unwrap()];
    for k in 0..3 {
        bodies.push(
            builders::rectangle(
                0.1 + 0.005 * k as f64,
                0.051 + 0.051 * k as f64,
                0.1,
                0.05,
                0.025,
            )
            .unwrap(),
        );
    }
    builders::union(&bodies.iter().collect::<Vec<_>>()).unwrap()
}

#[test]
fn stack_settles_under_gravity() {
    let (mesh, bodies) = stack();
    let h = 0.025;
    let rock = LinearElastic::new(E, 0.25, 1000.0)
        .unwrap()
        .with_damping(1.0)
        .unwrap();
    let mut sim = Simulation::builder(mesh, Backend::cpu(2).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(Contact::new(100.0 * E).friction(30.0, 100.0 * E))
        .physics(Boundary::new().fix(Range::rect(-1.0, -1.0, 1.0, 0.05 - 1e-9)))
        .gravity([0.0, -G, 0.0])
        .build()
        .unwrap();
    let mass = sim.mass().to_vec();
    let height = |s: &Simulation<Dim2>| -> f64 {
        bodies[1..]
            .iter()
            .flatten()
            .map(|&n| {
                mass[n as usize]
                    * G
                    * (s.mesh().node(n as usize)[1] + s.state.u[2 * n as usize + 1])
            })
            .sum()
    };
    let pe0 = height(&sim);
    let mut settled = false;
    for _ in 0..400 {
        sim.run(500).unwrap();
        let released = pe0 - height(&sim);
        if released > 0.0 && sim.kinetic_energy() < 1e-6 * released {
            settled = true;
            break;
        }
    }
    let released = pe0 - height(&sim);
    eprintln!(
        "t = {:.3} s: kinetic {:.3e} J, potential released {:.3e} J",
        sim.state.time,
        sim.kinetic_energy(),
        released
    );
    assert!(
        settled,
        "kinetic energy {} vs released {}",
        sim.kinetic_energy(),
        released
    );
    // Interpenetration: each block's lowest node is no more than 1 % of h below the top
    // of the body beneath (initial gaps of 1 mm are closed).
    let lowest = |b: &Vec<u32>| {
        b.iter()
            .map(|&n| sim.mesh().node(n as usize)[1] + sim.state.u[2 * n as usize + 1])
            .fold(f64::INFINITY, f64::min)
    };
    let highest = |b: &Vec<u32>| {
        b.iter()
            .map(|&n| sim.mesh().node(n as usize)[1] + sim.state.u[2 * n as usize + 1])
            .fold(f64::NEG_INFINITY, f64::max)
    };
    for k in 1..4 {
        let overlap = highest(&bodies[k - 1]) - lowest(&bodies[k]);
        eprintln!("body {k}: overlap with the body below {overlap:.3e} m");
        assert!(overlap < 0.01 * h, "body {k} penetrates {overlap} m");
        assert!(overlap > -1e-4, "body {k} floats {} m above", -overlap);
    }
}
