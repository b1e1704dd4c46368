//! 3D: tetrahedra bonded through a face do not contact each other until the bond's
//! broken flag is set; then the pair pushes apart (the 3D form of tests/bonded.rs).

use pcdc_compute::{
    Backend, Components, ComputeError, FieldKey, FieldUse, ForceContext, InitContext, Physics,
    Place, Simulation,
};
use pcdc_contact::Contact;
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{Dim3, Mesh, Range};

const FLAG: FieldKey = FieldKey::new("bond_broken", Place::Face, Components::Fixed(1));

/// Declares the broken-bond face field (what pcdc-cohesive publishes as `broken_face`).
struct BondFlags;

impl Physics<Dim3> for BondFlags {
    fn name(&self) -> &str {
        "bond flags"
    }
    fn fields(&self, _mesh: &Mesh<Dim3>) -> Vec<FieldUse> {
        vec![FLAG.own::<Dim3>()]
    }
    fn init(&mut self, _ctx: &mut InitContext<'_, Dim3>) -> Result<(), ComputeError> {
        Ok(())
    }
    fn compute_forces(&mut self, _ctx: &mut ForceContext<'_, Dim3>) -> Result<(), ComputeError> {
        Ok(())
    }
}

/// Two tetrahedra on either side of the plane x + y + z = 1, each with its own nodes,
/// overlapping across their common face after B is pushed into A.
fn scene(contact: bool) -> (Simulation<Dim3>, u32) {
    let coords = vec![
        0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, // A
        1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, // B
    ];
    let mesh = Mesh::<Dim3>::new_reoriented(coords, (0..8).collect()).unwrap();
    // The face of A on the common plane (its nodes 1, 2, 3).
    let face = (0..mesh.faces().len() as u32)
        .find(|&f| {
            let n = mesh.face(f as usize);
            [1, 2, 3].iter().all(|k| n.contains(k))
        })
        .unwrap();
    let rock = LinearElastic::new(1e9, 0.25, 1000.0).unwrap();
    let mut b = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(BondFlags);
    if contact {
        b = b.physics(Contact::new(1e10).bonded_pairs(&[0, 1], &[face], FLAG));
    }
    let mut sim = b.build().unwrap();
    for n in 4..8 {
        for d in 0..3 {
            sim.state.u[3 * n + d] = -0.03;
        }
    }
    (sim, face)
}

#[test]
fn bonded_tets_have_no_contact_until_broken() {
    let (mut plain, _) = scene(false);
    let f_plain = plain.evaluate_forces().unwrap().to_vec();
    let (mut sim, face) = scene(true);
    let f_bonded = sim.evaluate_forces().unwrap().to_vec();
    assert_eq!(f_plain, f_bonded, "an intact bond must hide the contact");
    let id = sim.state.fields.id(FLAG).unwrap();
    sim.state.fields.get_mut(id)[face as usize] = 1.0;
    let f_broken = sim.evaluate_forces().unwrap().to_vec();
    // Contact pushes B (nodes 4-7) back along +x+y+z, and A the opposite way.
    let along = |nodes: std::ops::Range<usize>| -> f64 {
        nodes
            .flat_map(|n| (0..3).map(move |d| 3 * n + d))
            .map(|i| f_broken[i] - f_plain[i])
            .sum()
    };
    let (push_a, push_b) = (along(0..4), along(4..8));
    assert!(push_b > 0.0, "broken bond: contact force on B {push_b}");
    assert!(
        (push_a + push_b).abs() <= 1e-9 * push_b,
        "action = reaction: {push_a} vs {push_b}"
    );
}
