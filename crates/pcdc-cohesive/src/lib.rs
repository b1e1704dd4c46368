//! # pcdc-cohesive
//!
//! Fracture for the pcdc-rs FDEM SDK (manual 7.4): joint constitutive models behind the
//! [`JointModel`] plugin trait, starting with the intrinsic cohesive zone model
//! [`IntrinsicCzm`] (eq. 63-73: penalties, peak opening and slip, damage D, softening
//! f(D) with A = 0.63, B = 1.8, C = 6.0, Mohr-Coulomb shear strength, unloading along
//! the secant, softening lengths from G_f1 and G_f2), integrated over the face-joints of
//! a mesh split by [`pcdc_mesh::split_nodes`] (the mesh carries them as its
//! [`pcdc_mesh::Interfaces`], which every physics reads).
//!
//! The joint models ([`IntrinsicCzm`], [`MohrCoulombJoint`]) are built from parameter
//! structs with named fields ([`IntrinsicCzmParams`], [`MohrCoulombJointParams`]) and
//! are immutable afterwards (read accessors only); building and deserialisation share
//! one check, so a model read from a file is validated and its cached derived constants
//! are always built from the parameters it holds.
//!
//! [`CohesiveJoints`] publishes per joint, for other physics to read, the normal opening,
//! the sliding vector and the unit normal ([`fields`]), computed with the joint forces.
//!
//! Joints run on both backends: [`CohesiveJoints`] has a GPU kernel into which each
//! model's WGSL body ([`JointModel::wgsl`], [`WgslJointModel`]) is spliced; the built-in
//! models provide one, and the softening curve uses the hand-written [`portable_exp`] on
//! both backends so that f64 results agree to rounding.
//!
//! A joint model that needs another physics' field (fluid pressure in the joint,
//! temperature) names it in [`JointModel::coupling`] (e.g.
//! `pcdc_compute::names::PORE_PRESSURE`) and overrides [`JointModel::traction_with`]:
//! [`JointInput::coupling`] holds the values at the joint (node field: mean of the
//! joint's face nodes on both sides; element field: mean of its two elements), the same
//! at every Gauss point, and its WGSL body reads them as `coupling[i]`. The physics that
//! owns the field must be composed (else
//! [`pcdc_compute::ComputeError::FieldWithoutOwner`]); [`CohesiveJoints`] reads it
//! lagged, so a fluid physics that reads the joints' openings may run after them.
//! Models that ask for nothing cost nothing: no field, no gather, the kernel unchanged.

#![warn(missing_docs)]
// Index loops mirror the tensor notation of the manual's equations.
#![allow(clippy::needless_range_loop)]

mod error;
pub mod fields;
pub mod fractures;
mod joints;
mod model;

pub use error::CohesiveError;
pub use fields::{
    BROKEN_FACE, JOINT_DAMAGE, JOINT_NORMAL, JOINT_OPENING, JOINT_SLIDING, JOINT_STATE,
};
pub use fractures::{joints_on_fractures, Distribution, Fracture, FractureNetwork};
pub use joints::CohesiveJoints;
pub use model::{
    czm_state, portable_exp, softening, softening_integral, FailureMode, IntrinsicCzm,
    IntrinsicCzmParams, JointInput, JointModel, MohrCoulombJoint, MohrCoulombJointParams, Traction,
    WgslJointModel, SOFTENING_A, SOFTENING_B, SOFTENING_C,
};
