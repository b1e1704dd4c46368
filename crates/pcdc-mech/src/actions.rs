//! Resets between stages (manual 7.2.8): node velocity, node displacement and element
//! state. Also used to give nodes an initial velocity.

use pcdc_compute::{names, Simulation};
use pcdc_compute::{Components, FieldKey, Place};
use pcdc_mesh::{Dim, Range};

use crate::MechError;

/// Name of the node field that stores the displacement at the last reset.
pub const DISPLACEMENT_RESET: FieldKey =
    FieldKey::new("displacement_reset", Place::Node, Components::Vector);

/// Sets the velocity (m/s) of every node in `range` (first `D` components used; on a 2D
/// mesh a non-zero z component is an error, as it would be ignored).
pub fn set_velocity<D: Dim>(
    sim: &mut Simulation<D>,
    range: &Range,
    velocity: [f64; 3],
) -> Result<usize, MechError> {
    if velocity.iter().any(|v| !v.is_finite()) {
        return Err(MechError::param(
            "velocity",
            format!("{velocity:?}"),
            "must be finite",
        ));
    }
    let d = D::D;
    if d == 2 && velocity[2] != 0.0 {
        return Err(MechError::param(
            "velocity z component",
            velocity[2],
            "is non-zero, but the mesh is 2D",
        ));
    }
    let nodes = sim.mesh().select_nodes(range)?;
    for &n in &nodes {
        sim.state.v[n as usize * d..(n as usize + 1) * d].copy_from_slice(&velocity[..d]);
    }
    Ok(nodes.len())
}

/// Zeroes the velocity of every node in `range`.
pub fn reset_velocity<D: Dim>(sim: &mut Simulation<D>, range: &Range) -> Result<usize, MechError> {
    set_velocity(sim, range, [0.0; 3])
}

/// Resets the reported displacement of the nodes in `range` to zero without moving them:
/// the current displacement is remembered in the `displacement_reset` field (declared by
/// [`crate::Mechanics`]) and subtracted by [`crate::output::displacement`].
pub fn reset_displacement<D: Dim>(
    sim: &mut Simulation<D>,
    range: &Range,
) -> Result<usize, MechError> {
    let nodes = sim.mesh().select_nodes(range)?;
    let id = sim.state.fields.id(DISPLACEMENT_RESET)?;
    let d = D::D;
    let u = sim.state.u.clone();
    let off = sim.state.fields.get_mut(id);
    for &n in &nodes {
        let i = n as usize * d;
        off[i..i + d].copy_from_slice(&u[i..i + d]);
    }
    Ok(nodes.len())
}

/// Resets the stress and the constitutive history variables of the elements in `range`
/// to zero (the current shape becomes stress-free).
pub fn reset_element_state<D: Dim>(
    sim: &mut Simulation<D>,
    range: &Range,
) -> Result<usize, MechError> {
    let elems = sim.mesh().select_elements(range)?;
    let fields = &mut sim.state.fields;
    let stress = fields.id(names::STRESS)?;
    let state = fields.id(names::MODEL_STATE)?;
    let ns = fields.spec(state).components;
    let nsym = D::NSYM;
    for &e in &elems {
        let e = e as usize;
        fields.get_mut(stress)[e * nsym..(e + 1) * nsym].fill(0.0);
        fields.get_mut(state)[e * ns..(e + 1) * ns].fill(0.0);
    }
    if D::D == 2 {
        let zz = fields.id(names::STRESS_ZZ)?;
        for &e in &elems {
            fields.get_mut(zz)[e as usize] = 0.0;
        }
    }
    Ok(elems.len())
}

/// Switches the elements in `range` to the null model (manual 7.2.8, `element c-model
/// null`): they lose their stiffness, mass, gravity and stress (stress, strain and
/// history are zeroed), and mesh nodes left with no live element drop out
/// ([`pcdc_compute::Simulation::refresh_mass`]); the stable step is recomputed from the
/// live elements. The remaining elements keep their stresses, so the unloading comes
/// from the missing internal forces, as in an excavation. Returns the number of
/// elements switched (already null ones included).
///
/// Joints to a null element become free faces: the damage of every interface with a
/// null side is set to 1 (`names::JOINT_DAMAGE`, when a joint physics declares it), so
/// the joint transfers no force from then on and its faces count as broken; contact
/// treats null elements as sealed (it reads `element_null` on both backends), so
/// nothing touches them.
pub fn set_null<D: Dim>(sim: &mut Simulation<D>, range: &Range) -> Result<usize, MechError> {
    let elems = sim.mesh().select_elements(range)?;
    let id = sim.state.fields.id(names::ELEMENT_NULL)?;
    let null = sim.state.fields.get_mut(id);
    for &e in &elems {
        null[e as usize] = 1.0;
    }
    reset_element_state(sim, range)?;
    let strain = sim.state.fields.id(names::STRAIN)?;
    let nsym = D::NSYM;
    let s = sim.state.fields.get_mut(strain);
    for &e in &elems {
        s[e as usize * nsym..(e as usize + 1) * nsym].fill(0.0);
    }
    if let Ok(id) = sim.state.fields.id(names::JOINT_DAMAGE) {
        let mut is_null = vec![false; sim.mesh().n_elements()];
        for &e in &elems {
            is_null[e as usize] = true;
        }
        let sides: Vec<bool> = (sim.mesh().interfaces().elements().chunks_exact(2))
            .map(|p| is_null[p[0] as usize] || is_null[p[1] as usize])
            .collect();
        let damage = sim.state.fields.get_mut(id);
        for (j, &hit) in sides.iter().enumerate() {
            if hit && j < damage.len() {
                damage[j] = 1.0;
            }
        }
    }
    sim.refresh_mass()?;
    Ok(elems.len())
}
