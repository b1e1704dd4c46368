//! Field ownership: one owner per field, no use without an owner, readers after
//! writers, unique physics once: each a build error that names the field and physics.

use pcdc_compute::{
    Backend, Components, ComputeError, FieldKey, FieldStore, FieldUse, ForceContext, InitContext,
    Physics, Place, Simulation,
};
use pcdc_mesh::{builders, Dim2, Mesh};

const HEAT: FieldKey = FieldKey::new("heat", Place::Node, Components::Fixed(1));

/// A physics that lumps a unit mass on every node and uses fields as told.
struct Probe {
    name: &'static str,
    uses: Vec<FieldUse>,
    unique: bool,
}

impl Probe {
    fn new(name: &'static str, uses: Vec<FieldUse>) -> Self {
        Probe {
            name,
            uses,
            unique: false,
        }
    }
}

impl Physics<Dim2> for Probe {
    fn name(&self) -> &str {
        self.name
    }
    fn fields(&self, _mesh: &Mesh<Dim2>) -> Vec<FieldUse> {
        self.uses.clone()
    }
    fn unique(&self) -> bool {
        self.unique
    }
    fn init(&mut self, _ctx: &mut InitContext<'_, Dim2>) -> Result<(), ComputeError> {
        Ok(())
    }
    fn add_mass(&self, _m: &Mesh<Dim2>, _f: &FieldStore, mass: &mut [f64], _s: Option<f64>) {
        mass.iter_mut().for_each(|m| *m += 1.0);
    }
    fn compute_forces(&mut self, _ctx: &mut ForceContext<'_, Dim2>) -> Result<(), ComputeError> {
        Ok(())
    }
}

fn build(physics: Vec<Probe>) -> Result<Simulation<Dim2>, ComputeError> {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    // No physics here limits the step: give one.
    let mut b = Simulation::builder(mesh, Backend::cpu(1).unwrap()).time_step(1e-3);
    for p in physics {
        b = b.physics(p);
    }
    b.build()
}

#[test]
fn one_owner_builds_and_allocates_the_field_once() {
    let sim = build(vec![
        Probe::new("heat source", vec![HEAT.own::<Dim2>().initial(20.0)]),
        Probe::new("heat reader", vec![HEAT.read::<Dim2>()]),
    ])
    .unwrap();
    let heat = sim.field(HEAT).unwrap();
    assert_eq!(heat.len(), sim.mesh().n_nodes());
    assert!(heat.iter().all(|&t| t == 20.0));
}

#[test]
fn two_owners_are_an_error_naming_both() {
    let err = build(vec![
        Probe::new("first", vec![HEAT.own::<Dim2>()]),
        Probe::new("second", vec![HEAT.own::<Dim2>()]),
    ])
    .err()
    .expect("two owners must not build");
    assert!(
        matches!(&err, ComputeError::FieldOwnedTwice { field, first, second }
            if field == "heat" && first == "first" && second == "second"),
        "{err}"
    );
}

#[test]
fn a_use_without_owner_is_an_error() {
    for access in [
        HEAT.read::<Dim2>(),
        HEAT.write::<Dim2>(),
        HEAT.read_lagged::<Dim2>(),
    ] {
        let err = build(vec![Probe::new("lonely", vec![access])])
            .err()
            .expect("no owner must not build");
        assert!(
            matches!(&err, ComputeError::FieldWithoutOwner { field, physics, .. }
                if field == "heat" && physics == "lonely"),
            "{err}"
        );
    }
}

#[test]
fn a_reader_before_the_writer_is_an_error_unless_lagged() {
    let err = build(vec![
        Probe::new("reader", vec![HEAT.read::<Dim2>()]),
        Probe::new("owner", vec![HEAT.own::<Dim2>()]),
    ])
    .err()
    .expect("read before write must not build");
    assert!(
        matches!(&err, ComputeError::FieldReadBeforeWrite { reader, writer, .. }
            if reader == "reader" && writer == "owner"),
        "{err}"
    );
    build(vec![
        Probe::new("reader", vec![HEAT.read_lagged::<Dim2>()]),
        Probe::new("owner", vec![HEAT.own::<Dim2>()]),
    ])
    .expect("a lagged read has no order constraint");
}

#[test]
fn a_reader_expecting_another_layout_is_an_error() {
    let vector_heat = FieldKey::new("heat", Place::Node, Components::Vector);
    let err = build(vec![
        Probe::new("owner", vec![HEAT.own::<Dim2>()]),
        Probe::new("reader", vec![vector_heat.read::<Dim2>()]),
    ])
    .err()
    .expect("layout mismatch must not build");
    assert!(matches!(err, ComputeError::FieldConflict { .. }), "{err}");
}

#[test]
fn a_unique_physics_composed_twice_is_an_error() {
    let unique = || Probe {
        unique: true,
        ..Probe::new("solo", Vec::new())
    };
    let err = build(vec![unique(), unique()])
        .err()
        .expect("unique twice must not build");
    assert!(
        matches!(&err, ComputeError::DuplicatePhysics(name) if name == "solo"),
        "{err}"
    );
    build(vec![
        Probe::new("twice", Vec::new()),
        Probe::new("twice", Vec::new()),
    ])
    .expect("a physics that is not unique may be composed twice");
}
