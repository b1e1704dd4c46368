//! Restore-and-continue of a contact scene on the GPU equals the uninterrupted GPU run
//! bit for bit: the restored state (displacements, velocities, the candidate reference
//! positions) is uploaded at the next run and the device rebuilds its own candidate
//! lists (nothing read from the snapshot indexes device memory). Frictionless, because
//! the pair history lives on the device and restarts at zero after a GPU restore.
//! Without a GPU adapter the test skips (and fails with PCDC_REQUIRE_GPU=1).

use pcdc_compute::gpu::gpu_test_backend;
use pcdc_compute::{Backend, Precision, Simulation};
use pcdc_contact::Contact;
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim2, Range};

/// Two elastic blocks 2 mm apart, the left one moving at 2 m/s towards the right one.
fn impact(gpu: &Backend) -> Simulation<Dim2> {
    let a = builders::rectangle(0.0, 0.0, 0.1, 0.1, 0.02).unwrap();
    let b = builders::rectangle(0.102, 0.03, 0.1, 0.1, 0.02).unwrap();
    let mesh = builders::union(&[&a, &b]).unwrap().0;
    let rock = LinearElastic::new(1e9, 0.25, 1000.0).unwrap();
    let mut sim = Simulation::builder(mesh, gpu.clone())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(Contact::new(1e10))
        .build()
        .unwrap();
    let x = sim.mesh().coords().to_vec();
    for n in 0..sim.mesh().n_nodes() {
        if x[2 * n] < 0.101 {
            sim.state.v[2 * n] = 2.0;
        }
    }
    sim
}

#[test]
fn gpu_contact_restore_continues_bit_for_bit() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let mut a = impact(&gpu);
    // 3 ms: the gap closes after 1 ms; the snapshot is taken during contact.
    let half = (1.5e-3 / a.dt()).ceil() as u64;
    a.run(half).unwrap();
    let snap = a.snapshot_bytes().unwrap();
    a.run(half).unwrap();
    let mut b = impact(&gpu);
    b.restore_bytes(&snap).unwrap();
    b.run(half).unwrap();
    // The blocks touched: the struck block moves.
    assert!(a.state.v.iter().step_by(2).any(|&v| v > 0.1 && v < 1.9));
    let same = |x: &[f64], y: &[f64]| x.iter().zip(y).all(|(p, q)| p.to_bits() == q.to_bits());
    assert!(same(&a.state.u, &b.state.u));
    assert!(same(&a.state.v, &b.state.v));
}
