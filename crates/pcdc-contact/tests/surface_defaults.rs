//! Contact without a contact law takes each element's surface friction and penalty
//! (manual table 1): a block sliding on a base with the material's friction angle and
//! the default penalty 10 E moves exactly as with the explicit `contact-m-c` law of the
//! same parameters, and two materials combine by the smaller value.

use pcdc_compute::{Backend, Simulation};
use pcdc_contact::Contact;
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim2, Mesh, Range};

const E: f64 = 1e8;
const BASE_TOP: f64 = 0.05;

fn block_on_base() -> Mesh<Dim2> {
    let base = builders::rectangle(0.0, 0.0, 0.4, BASE_TOP, 0.025).unwrap();
    let block = builders::rectangle(0.05, BASE_TOP, 0.1, 0.05, 0.025).unwrap();
    builders::union(&[&base, &block]).unwrap().0
}

/// Slides the block at 1 m/s for 2000 steps; returns the displacement field.
fn slide(mech: Mechanics, contact: Contact) -> Vec<f64> {
    let mut sim = Simulation::builder(block_on_base(), Backend::cpu(1).unwrap())
        .physics(mech)
        .physics(contact)
        .physics(Boundary::new().fix(Range::rect(-1.0, -1.0, 1e3, BASE_TOP - 1e-9)))
        .gravity([0.0, -9.81, 0.0])
        .build()
        .unwrap();
    let block = sim
        .mesh()
        .select_nodes(&Range::rect(-1.0, BASE_TOP + 1e-9, 1e3, 1.0))
        .unwrap();
    for &n in &block {
        sim.state.v[2 * n as usize] = 1.0;
    }
    sim.run(2000).unwrap();
    // The block has slid (friction has not stopped it yet) and slowed down.
    let vx: f64 = block
        .iter()
        .map(|&n| sim.state.v[2 * n as usize])
        .sum::<f64>()
        / block.len() as f64;
    assert!(vx > 0.0 && vx < 0.99, "block speed {vx}");
    sim.state.u.clone()
}

fn rock(friction: f64) -> LinearElastic {
    LinearElastic::new(E, 0.25, 1000.0)
        .unwrap()
        .with_damping(1.0)
        .unwrap()
        .with_contact(friction, None)
        .unwrap()
}

#[test]
fn table_1_defaults_equal_the_explicit_law() {
    let mech = || Mechanics::new().material(Range::All, rock(30.0));
    let props = mech().surface_properties(&block_on_base()).unwrap();
    assert!(props.penalty.iter().all(|&p| p == 10.0 * E));
    let defaults = slide(
        mech(),
        Contact::new(1.0).surface_defaults(props.friction_deg, props.penalty),
    );
    let explicit = slide(mech(), Contact::new(10.0 * E).friction(30.0, 10.0 * E));
    assert_eq!(defaults, explicit);
}

#[test]
fn two_surfaces_take_the_smaller_friction() {
    let base = Range::rect(-1.0, -1.0, 1e3, BASE_TOP);
    let mech = || {
        Mechanics::new()
            .material(Range::All, rock(30.0))
            .material(base.clone(), rock(10.0))
    };
    let props = mech().surface_properties(&block_on_base()).unwrap();
    let defaults = slide(
        mech(),
        Contact::new(1.0).surface_defaults(props.friction_deg, props.penalty),
    );
    let explicit = slide(mech(), Contact::new(10.0 * E).friction(10.0, 10.0 * E));
    assert_eq!(defaults, explicit);
}

#[test]
fn bad_surface_data_is_an_error() {
    let mech = Mechanics::new().material(Range::All, rock(30.0));
    let err = Simulation::builder(block_on_base(), Backend::cpu(1).unwrap())
        .physics(mech)
        .physics(Contact::new(1.0).surface_defaults(vec![30.0; 3], vec![1e9; 3]))
        .build()
        .err()
        .expect("wrong length must fail")
        .to_string();
    assert!(err.contains("surface contact properties"), "{err}");
    assert!(LinearElastic::new(E, 0.25, 1000.0)
        .unwrap()
        .with_contact(95.0, None)
        .unwrap_err()
        .to_string()
        .contains("friction angle"));
}
