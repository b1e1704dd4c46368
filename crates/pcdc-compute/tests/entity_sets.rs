//! Named entity sets: the mesh's interfaces are the set `joints`; a physics declares its
//! own sets with node connectivity and fields on them; bad sets are build errors.

use pcdc_compute::{
    names, Backend, Components, ComputeError, EntitySet, FieldKey, FieldStore, FieldUse,
    ForceContext, InitContext, Physics, Place, Simulation,
};
use pcdc_mesh::{builders, split_nodes, Dim2, Mesh, Range};

const FLOW: FieldKey = FieldKey::new("channel_flow", Place::Set("channels"), Components::Fixed(2));

/// Declares a set of channels (node pairs) and a field on it; unit masses.
struct Channels {
    nodes: Vec<u32>,
}

impl Physics<Dim2> for Channels {
    fn name(&self) -> &str {
        "channels"
    }
    fn entity_sets(&self, _mesh: &Mesh<Dim2>) -> Vec<EntitySet> {
        vec![EntitySet::new("channels", 2, self.nodes.clone()).unwrap()]
    }
    fn fields(&self, _mesh: &Mesh<Dim2>) -> Vec<FieldUse> {
        vec![FLOW.own::<Dim2>()]
    }
    fn init(&mut self, ctx: &mut InitContext<'_, Dim2>) -> Result<(), ComputeError> {
        // The physics' own set is there at init, with its connectivity.
        let set = ctx.entity_set("channels").expect("the set declared above");
        assert_eq!(set.nodes(), &self.nodes[..]);
        Ok(())
    }
    fn add_mass(&self, _m: &Mesh<Dim2>, _f: &FieldStore, mass: &mut [f64], _s: Option<f64>) {
        mass.iter_mut().for_each(|m| *m += 1.0);
    }
    fn compute_forces(&mut self, _ctx: &mut ForceContext<'_, Dim2>) -> Result<(), ComputeError> {
        Ok(())
    }
}

fn build(mesh: Mesh<Dim2>, p: Channels) -> Result<Simulation<Dim2>, ComputeError> {
    Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .time_step(1e-3)
        .physics(p)
        .build()
}

#[test]
fn a_physics_set_carries_its_fields_and_connectivity() {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    let sim = build(
        mesh,
        Channels {
            nodes: vec![0, 1, 1, 2, 2, 3],
        },
    )
    .unwrap();
    let set = sim.entity_set("channels").unwrap();
    assert_eq!((set.len(), set.entity(1)), (3, &[1u32, 2][..]));
    assert_eq!(sim.field(FLOW).unwrap().len(), 3 * 2);
    // An unsplit mesh has an empty joint set.
    assert!(sim.entity_set(names::JOINTS).unwrap().is_empty());
}

#[test]
fn the_mesh_interfaces_are_the_joint_set() {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    let mesh = split_nodes(&mesh, &Range::All).unwrap();
    let n = mesh.interfaces().len();
    assert!(n > 0);
    let sim = build(mesh, Channels { nodes: vec![0, 1] }).unwrap();
    let joints = sim.entity_set(names::JOINTS).unwrap();
    assert_eq!(joints.len(), n);
    assert_eq!(joints.nodes(), sim.mesh().interfaces().nodes());
}

#[test]
fn bad_sets_are_errors() {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    // A node beyond the mesh.
    let e = build(
        mesh.clone(),
        Channels {
            nodes: vec![0, 999],
        },
    )
    .err()
    .expect("a node beyond the mesh must not build")
    .to_string();
    assert!(e.contains("entity set 'channels'"), "{e}");
    // A ragged node list.
    assert!(EntitySet::new("x", 2, vec![0, 1, 2]).is_err());
    assert!(EntitySet::new("x", 0, vec![]).is_err());
    // A field on a set nobody declares.
    struct Orphan;
    impl Physics<Dim2> for Orphan {
        fn name(&self) -> &str {
            "orphan"
        }
        fn fields(&self, _mesh: &Mesh<Dim2>) -> Vec<FieldUse> {
            vec![FieldKey::new("x", Place::Set("nowhere"), Components::Fixed(1)).own::<Dim2>()]
        }
        fn init(&mut self, _ctx: &mut InitContext<'_, Dim2>) -> Result<(), ComputeError> {
            Ok(())
        }
        fn compute_forces(&mut self, _: &mut ForceContext<'_, Dim2>) -> Result<(), ComputeError> {
            Ok(())
        }
    }
    let e = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .time_step(1e-3)
        .physics(Orphan)
        .build()
        .err()
        .expect("a field on an unknown set must not build")
        .to_string();
    assert!(e.contains("nowhere"), "{e}");
}
