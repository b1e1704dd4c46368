//! A light physics run beside an earlier one (`Physics::runs_beside`): paired only with a
//! physics that shares no field with it (nor does any physics between them), never on
//! one thread; the run gives the one-thread result bit for bit, and the light physics'
//! fields are back in the store for the physics after it.

use pcdc_compute::{
    Backend, Components, ComputeError, FieldId, FieldKey, FieldStore, FieldUse, ForceContext,
    InitContext, Physics, Place, Simulation,
};
use pcdc_mesh::{builders, Dim2, Mesh};
use rayon::prelude::*;

const A: FieldKey = FieldKey::new("a", Place::Node, Components::Fixed(1));
const B: FieldKey = FieldKey::new("b", Place::Node, Components::Fixed(1));
const C: FieldKey = FieldKey::new("c", Place::Node, Components::Fixed(1));

/// A spring from every node to its rest position (stiffness `k`, a slot per node); counts
/// its calls in its first owned field per node, and adds the node's first declared read
/// field to its force.
struct Spring {
    name: &'static str,
    k: f64,
    light: bool,
    uses: Vec<FieldUse>,
    ids: Vec<FieldId>,
}

fn spring(name: &'static str, k: f64, light: bool, uses: Vec<FieldUse>) -> Spring {
    Spring {
        name,
        k,
        light,
        uses,
        ids: Vec::new(),
    }
}

impl Physics<Dim2> for Spring {
    fn name(&self) -> &str {
        self.name
    }
    fn fields(&self, _mesh: &Mesh<Dim2>) -> Vec<FieldUse> {
        self.uses.clone()
    }
    fn runs_beside(&self) -> bool {
        self.light
    }
    fn init(&mut self, ctx: &mut InitContext<'_, Dim2>) -> Result<(), ComputeError> {
        let nodes: Vec<u32> = (0..ctx.mesh.n_nodes() as u32).collect();
        ctx.register_slots(&nodes)?;
        self.ids = self
            .uses
            .iter()
            .map(|u| ctx.fields.id(&u.name))
            .collect::<Result<_, _>>()?;
        Ok(())
    }
    fn add_mass(&self, _m: &Mesh<Dim2>, _f: &FieldStore, mass: &mut [f64], _s: Option<f64>) {
        mass.iter_mut().for_each(|m| *m += 1.0);
    }
    fn compute_forces(&mut self, ctx: &mut ForceContext<'_, Dim2>) -> Result<(), ComputeError> {
        let (k, u) = (self.k, ctx.kin.u);
        let extra = self
            .uses
            .iter()
            .zip(&self.ids)
            .find(|(use_, _)| use_.access != pcdc_compute::FieldAccess::Own)
            .map(|(_, id)| ctx.fields.get(*id).to_vec());
        ctx.slots.par_chunks_mut(2).enumerate().for_each(|(n, f)| {
            let e = extra.as_ref().map_or(0.0, |x| x[n]);
            f[0] = -k * u[2 * n] + e;
            f[1] = -k * u[2 * n + 1] - 1.0;
        });
        if let Some((_, id)) = self
            .uses
            .iter()
            .zip(&self.ids)
            .find(|(use_, _)| use_.access == pcdc_compute::FieldAccess::Own)
        {
            ctx.fields.get_mut(*id).iter_mut().for_each(|c| *c += 1.0);
        }
        Ok(())
    }
}

fn build(threads: usize, physics: Vec<Spring>) -> Simulation<Dim2> {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.25).unwrap();
    let mut b = Simulation::builder(mesh, Backend::cpu(threads).unwrap()).time_step(1e-2);
    for p in physics {
        b = b.physics(p);
    }
    b.build().unwrap()
}

fn three(read_c: bool, reader_after: bool) -> Vec<Spring> {
    let mut light_uses = vec![B.own::<Dim2>()];
    if read_c {
        light_uses.push(C.read_lagged::<Dim2>());
    }
    let mut v = vec![
        spring("heavy", 3.0, false, vec![A.own::<Dim2>()]),
        spring("other", 2.0, false, vec![C.own::<Dim2>()]),
        spring("light", 1.0, true, light_uses),
    ];
    if reader_after {
        v.push(spring("reader", 0.5, false, vec![B.read::<Dim2>()]));
    }
    v
}

#[test]
fn a_light_physics_pairs_with_the_earliest_physics_it_shares_no_field_with() {
    assert_eq!(
        build(2, three(false, false)).physics_beside(),
        vec![("heavy", "light")]
    );
    // It reads a field of the physics just before it: no pair at all.
    assert!(build(2, three(true, false)).physics_beside().is_empty());
    // One thread: none.
    assert!(build(1, three(false, false)).physics_beside().is_empty());
}

#[test]
fn beside_gives_the_one_thread_result_and_returns_the_fields() {
    let (mut one, mut two) = (build(1, three(false, true)), build(2, three(false, true)));
    assert_eq!(two.physics_beside(), vec![("heavy", "light")]);
    one.run(50).unwrap();
    two.run(50).unwrap();
    assert_eq!(one.state.u, two.state.u);
    assert_eq!(one.state.v, two.state.v);
    // The light physics counted its 50 calls in its own field, which the reader after it
    // found in the store (it adds it to its x force: the x displacements moved).
    let b = two.field(B).unwrap();
    assert!(b.iter().all(|&c| c == 50.0), "{b:?}");
    assert_eq!(two.field(A).unwrap(), one.field(A).unwrap());
    assert!(two.state.u.iter().step_by(2).any(|&x| x != 0.0));
}
