//! Save/restore of a frictional contact scene continues bit for bit: the candidate lists
//! and accumulated slips are fields and travel with the snapshot (u, v and every field
//! compared).

use pcdc_compute::{Backend, Simulation};
use pcdc_contact::{Contact, CONTACT_HISTORY};
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim2, Range};

fn scene() -> Simulation<Dim2> {
    let base = builders::rectangle(0.0, 0.0, 0.4, 0.05, 0.025).unwrap();
    let block = builders::rectangle(0.05, 0.05, 0.1, 0.05, 0.025).unwrap();
    let off = base.n_nodes() as u32;
    let mesh = builders::union(&[&base, &block]).unwrap().0;
    let rock = LinearElastic::new(1e8, 0.25, 1000.0)
        .unwrap()
        .with_damping(1.0)
        .unwrap();
    let mut sim = Simulation::builder(mesh, Backend::cpu(2).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(Contact::new(1e9).friction(30.0, 1e9))
        .physics(Boundary::new().fix(Range::rect(-1.0, -1.0, 1.0, 0.05 - 1e-9)))
        .gravity([0.0, -9.81, 0.0])
        .build()
        .unwrap();
    for n in off..sim.mesh().n_nodes() as u32 {
        sim.state.v[2 * n as usize] = 1.0;
    }
    sim
}

#[test]
fn frictional_contact_restores_bit_for_bit() {
    let mut a = scene();
    a.run(3000).unwrap();
    let snap = a.snapshot_bytes().unwrap();
    a.run(3000).unwrap();
    let mut b = scene();
    b.restore_bytes(&snap).unwrap();
    b.run(3000).unwrap();
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
    // Every field too (reference positions, candidate lists, pair histories).
    for spec in a.state.fields.specs() {
        let (x, y) = (a.field(&spec.name).unwrap(), b.field(&spec.name).unwrap());
        assert!(
            x.iter().zip(y).all(|(p, q)| p.to_bits() == q.to_bits()),
            "field {}",
            spec.name
        );
    }
    // The block is still sliding mid-test (the state mattered).
    assert!(a.state.v.iter().step_by(2).any(|&v| v > 0.1));
    // The snapshot held a friction history.
    let mut s = scene();
    s.restore_bytes(&snap).unwrap();
    assert!(s.field(CONTACT_HISTORY).unwrap().iter().any(|&h| h != 0.0));
    // Truncated contact state is an error, not a panic.
    let mut c = scene();
    assert!(c.restore_bytes(&snap[..snap.len() - 3]).is_err());
}
