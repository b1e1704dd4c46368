//! Elements bonded through a face (a cohesive joint in FDEM regions) do not contact each
//! other until the bond's broken flag is set; then the pair pushes apart.

use pcdc_compute::{
    Backend, Components, ComputeError, FieldKey, FieldUse, ForceContext, InitContext, Physics,
    Place, Simulation,
};
use pcdc_contact::Contact;
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{split_nodes, Dim2, Mesh, Range};

const FLAG: FieldKey = FieldKey::new("bond_broken", Place::Face, Components::Fixed(1));

/// Declares the broken-bond face field (what pcdc-cohesive publishes as `broken_face`).
struct BondFlags;

impl Physics<Dim2> for BondFlags {
    fn name(&self) -> &str {
        "bond flags"
    }
    fn fields(&self, _mesh: &Mesh<Dim2>) -> Vec<FieldUse> {
        vec![FLAG.own::<Dim2>()]
    }
    fn init(&mut self, _ctx: &mut InitContext<'_, Dim2>) -> Result<(), ComputeError> {
        Ok(())
    }
    fn compute_forces(&mut self, _ctx: &mut ForceContext<'_, Dim2>) -> Result<(), ComputeError> {
        Ok(())
    }
}

/// Two triangles of a unit square, each with its own nodes, overlapping across their
/// common diagonal after B is pushed into A.
fn scene(contact: bool) -> (Simulation<Dim2>, u32) {
    let coords = vec![0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0];
    let mesh = Mesh::<Dim2>::new(coords, vec![0, 1, 2, 3, 4, 5]).unwrap();
    let face = (0..mesh.faces().len() as u32)
        .find(|&f| {
            let n = mesh.face(f as usize);
            n.contains(&1) && n.contains(&2)
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
    for n in 3..6 {
        sim.state.u[2 * n] = -0.05;
        sim.state.u[2 * n + 1] = -0.05;
    }
    (sim, face)
}

#[test]
fn bonded_pair_has_no_contact_until_broken() {
    let (mut plain, _) = scene(false);
    let f_plain = plain.evaluate_forces().unwrap().to_vec();
    let (mut sim, face) = scene(true);
    let f_bonded = sim.evaluate_forces().unwrap().to_vec();
    assert_eq!(f_plain, f_bonded, "an intact bond must hide the contact");
    let id = sim.state.fields.id(FLAG).unwrap();
    sim.state.fields.get_mut(id)[face as usize] = 1.0;
    let f_broken = sim.evaluate_forces().unwrap().to_vec();
    // Contact pushes B (nodes 3-5) back along +x+y, and A the opposite way.
    let push_b: f64 = (3..6).map(|n| f_broken[2 * n] - f_plain[2 * n]).sum();
    let push_a: f64 = (0..3).map(|n| f_broken[2 * n] - f_plain[2 * n]).sum();
    assert!(push_b > 0.0, "broken bond: contact force on B {push_b}");
    assert!(
        (push_a + push_b).abs() <= 1e-9 * push_b,
        "action = reaction: {push_a} vs {push_b}"
    );
}

/// The same two triangles made by splitting a square with shared nodes: the split mesh
/// carries one interface between them, and `bonded_interfaces` reads the bond from it
/// (no list, no dependency on pcdc-cohesive), bit for bit as the list would.
#[test]
fn the_mesh_interfaces_are_the_bonds() {
    let square = Mesh::<Dim2>::new(
        vec![0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![0, 1, 2, 1, 3, 2],
    )
    .unwrap();
    let mesh = split_nodes(&square, &Range::All).unwrap();
    let joint = mesh.interfaces().get(0).unwrap();
    assert_eq!(mesh.interfaces().len(), 1);
    assert_eq!(joint.elements, [0, 1]);
    let face = joint.faces[0];
    let forces = |contact: Contact, broken: bool| -> Vec<f64> {
        let rock = LinearElastic::new(1e9, 0.25, 1000.0).unwrap();
        let mut sim = Simulation::builder(mesh.clone(), Backend::cpu(1).unwrap())
            .physics(Mechanics::new().material(Range::All, rock))
            .physics(BondFlags)
            .physics(contact)
            .build()
            .unwrap();
        // Element 1 (nodes 3-5 after the split) pushed into element 0.
        assert_eq!(sim.mesh().element(1), &[3, 4, 5]);
        for n in 3..6 {
            sim.state.u[2 * n] = -0.05;
            sim.state.u[2 * n + 1] = -0.05;
        }
        if broken {
            let id = sim.state.fields.id(FLAG).unwrap();
            sim.state.fields.get_mut(id)[face as usize] = 1.0;
        }
        sim.evaluate_forces().unwrap().to_vec()
    };
    for broken in [false, true] {
        let listed = forces(
            Contact::new(1e10).bonded_pairs(&[0, 1], &[face], FLAG),
            broken,
        );
        let from_mesh = forces(Contact::new(1e10).bonded_interfaces(FLAG), broken);
        assert!(
            listed
                .iter()
                .zip(&from_mesh)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "broken {broken}: {listed:?} vs {from_mesh:?}"
        );
    }
    // The bond hides the contact until it breaks.
    assert_ne!(
        forces(Contact::new(1e10).bonded_interfaces(FLAG), false),
        forces(Contact::new(1e10).bonded_interfaces(FLAG), true)
    );
    // A mesh without interfaces declares no bonds: contact acts at once.
    let (mut plain, _) = scene(false);
    let f_plain = plain.evaluate_forces().unwrap().to_vec();
    let (unsplit, _) = scene(false);
    let rock = LinearElastic::new(1e9, 0.25, 1000.0).unwrap();
    let mut sim = Simulation::builder(unsplit.mesh().clone(), Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(BondFlags)
        .physics(Contact::new(1e10).bonded_interfaces(FLAG))
        .build()
        .unwrap();
    sim.state.u.copy_from_slice(&plain.state.u);
    assert_ne!(sim.evaluate_forces().unwrap().to_vec(), f_plain);
}

#[test]
fn bad_bond_input_is_an_error() {
    let coords = vec![0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0];
    let mesh = Mesh::<Dim2>::new(coords, vec![0, 1, 2, 3, 4, 5]).unwrap();
    let rock = LinearElastic::new(1e9, 0.25, 1000.0).unwrap();
    for (el, fa, field) in [
        (vec![0, 1], vec![99], FLAG.name()),
        (vec![0, 7], vec![0], FLAG.name()),
        (vec![0, 1, 1], vec![0], FLAG.name()),
        (vec![0, 1], vec![0], "no_such_field"),
    ] {
        let r = Simulation::builder(mesh.clone(), Backend::cpu(1).unwrap())
            .physics(Mechanics::new().material(Range::All, rock.clone()))
            .physics(BondFlags)
            .physics(Contact::new(1e10).bonded_pairs(&el, &fa, field))
            .build();
        assert!(r.is_err(), "{el:?} {fa:?} {field} accepted");
    }
}
