//! The canonical FDEM composition in one call: elements, an intrinsic cohesive joint on
//! every interface of the mesh, and contact that ignores bonded neighbours until their
//! joint breaks (manual 7.2–7.4).
//!
//! Split the FDEM region's nodes first ([`pcdc_mesh::split_nodes`]: the mesh then
//! carries its interfaces), then compose the group with
//! [`pcdc_compute::SimulationBuilder::group`]:
//!
//! ```
//! use pcdc::cohesive::IntrinsicCzmParams;
//! use pcdc::compute::{Backend, Simulation};
//! use pcdc::contact::Contact;
//! use pcdc::fdem::Fdem;
//! use pcdc::mech::LinearElastic;
//! use pcdc::mesh::{builders, split_nodes, Range};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let mesh = split_nodes(&builders::rectangle(0.0, 0.0, 0.1, 0.05, 0.01)?, &Range::All)?;
//! let rock = LinearElastic::new(30e9, 0.25, 2600.0)?;
//! let joints = IntrinsicCzmParams {
//!     friction_deg: 30.0,
//!     cohesion: 10e6,
//!     tensile_strength: 2e6,
//!     gf1: 0.5,
//!     gf2: 5.0,
//!     penalty_open: 300e9,
//!     penalty_shear: 300e9,
//!     penalty_overlap: 3000e9,
//! }
//! .build()?;
//! let sim = Simulation::builder(mesh, Backend::cpu(0)?)
//!     .group(Fdem::new(rock, joints, Contact::new(300e9).friction(30.0, 300e9)))
//!     .build()?;
//! assert_eq!(sim.physics_names(), ["mechanics", "cohesive joints", "contact"]);
//! # Ok(())
//! # }
//! ```

use pcdc_cohesive::{CohesiveJoints, JointModel, BROKEN_FACE};
use pcdc_compute::{Physics, PhysicsGroup};
use pcdc_contact::Contact;
use pcdc_mech::{ConstitutiveModel, Mechanics};
use pcdc_mesh::{Dim, Range};

/// Elements, cohesive joints on every interface of the mesh and contact, wired: the
/// contact's bonded pairs are the mesh's interfaces, released when the joints' broken
/// flag ([`BROKEN_FACE`]) is set. Runs in that order (joints write the flags that contact
/// reads in the same step).
pub struct Fdem {
    mechanics: Mechanics,
    joints: CohesiveJoints,
    contact: Contact,
}

impl Fdem {
    /// `rock` on every element, `joint` on every interface, and `contact` (its penalty,
    /// friction and damping as built; its bonded pairs are set here).
    pub fn new(
        rock: impl ConstitutiveModel + 'static,
        joint: impl JointModel + 'static,
        contact: Contact,
    ) -> Self {
        Fdem {
            mechanics: Mechanics::new().material(Range::All, rock),
            joints: CohesiveJoints::new().model(Range::All, joint),
            contact: contact.bonded_interfaces(BROKEN_FACE),
        }
    }

    /// Another material on the elements of `range` (later assignments win, as in
    /// [`Mechanics::material`]), e.g. steel platens.
    pub fn material(mut self, range: Range, model: impl ConstitutiveModel + 'static) -> Self {
        self.mechanics = self.mechanics.material(range, model);
        self
    }

    /// Another joint model on the joints in `range` (as [`CohesiveJoints::model`]).
    pub fn joint_model(mut self, range: Range, model: impl JointModel + 'static) -> Self {
        self.joints = self.joints.model(range, model);
        self
    }

    /// Assigns a constitutive model to the listed elements (e.g. a class of a
    /// heterogeneous modulus, `pcdc_mesh::property::classes`); later assignments
    /// override earlier ones.
    pub fn material_for(
        mut self,
        elements: Vec<u32>,
        model: impl ConstitutiveModel + 'static,
    ) -> Self {
        self.mechanics = self.mechanics.material_for(elements, model);
        self
    }

    /// Assigns a joint model to the listed joints (indices into the mesh's
    /// interfaces, e.g. a class of a heterogeneous strength); later assignments
    /// override earlier ones.
    pub fn joint_model_for(mut self, joints: Vec<u32>, model: impl JointModel + 'static) -> Self {
        self.joints = self.joints.model_for(joints, model);
        self
    }
}

impl<D: Dim> PhysicsGroup<D> for Fdem {
    fn into_physics(self) -> Vec<Box<dyn Physics<D>>> {
        vec![
            Box::new(self.mechanics),
            Box::new(self.joints),
            Box::new(self.contact),
        ]
    }
}
