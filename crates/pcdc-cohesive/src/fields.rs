//! Typed keys of the fields [`crate::CohesiveJoints`] owns, for other physics to read
//! (declare the use with [`FieldKey::read`] or [`FieldKey::read_lagged`]) and for output
//! (`Simulation::field(key)`; on the GPU backend they come back with every read-back).
//! The joint kinematics ([`JOINT_OPENING`], [`JOINT_SLIDING`], [`JOINT_NORMAL`]) are the
//! shared keys of `pcdc_compute::names`, re-exported here, so that a physics crate
//! reads them without depending on this one.
//!
//! The per-joint fields hold one value set per joint, in the order of the mesh's
//! interfaces ([`pcdc_mesh::Mesh::interfaces`]): joint `j` is interface `j`, whose
//! elements, faces and node pairs the mesh gives. They are written every step by the
//! kernel that computes the joint forces (CPU and GPU alike), from the positions at
//! which the forces are evaluated: the displacement at the start of the step (after a
//! step they belong to the displacement one step before `state.u`, like the damage).
//!
//! Kinematics of joint `j` (manual 7.4.1, at the current positions x = X + u): the
//! midplane of its two sides (the mean of each node pair) gives the unit normal n,
//! pointing from side A to side B, and the gap at the face centroid is the mean of the
//! node-pair gaps, δ̄ = (1/NPF) Σ_k (x_B,k − x_A,k) (for linear faces the centroid
//! value equals the face average, whatever the Gauss rule). Then
//!
//! * opening o = δ̄ · n (m): positive when the sides are apart, negative when they
//!   overlap;
//! * sliding s = δ̄ − o n (m): the tangential relative displacement of side B against
//!   side A as a vector in global axes (D components, orthogonal to n). A vector is
//!   published rather than 1 (2D) or 2 (3D) components in a tangent basis because a
//!   triangle face has no natural basis (any choice would turn with the node order),
//!   and hydraulic dilation and bolts work in global axes; its length |s| is the
//!   sliding distance;
//! * normal n (D components, unit; zero for a joint whose midplane has collapsed).
//!
//! These are relative displacements from the state at which the sides coincided (after
//! [`pcdc_mesh::split_nodes`] both sides start at the same positions). They are written
//! for broken joints too (their forces are zero): then they describe the face pair as
//! long as its faces stay near each other, which is what flow in an open fracture
//! needs; once fragments have separated far they mean little.

use pcdc_compute::names::JOINTS;
use pcdc_compute::{Components, FieldKey, Place};

/// Joint history, `NGAUSS × n_state` values per joint (model state per Gauss point).
pub const JOINT_STATE: FieldKey =
    FieldKey::new("joint_state", Place::Set(JOINTS), Components::Declared);
/// Face field: 1 on both faces of a broken joint, else 0 (what contact reads).
pub const BROKEN_FACE: FieldKey = FieldKey::new("broken_face", Place::Face, Components::Fixed(1));
// The joint kinematics and damage are read by physics that must not depend on this crate (fluid
// flow, bolts): their keys are the shared ones of pcdc-compute.
pub use pcdc_compute::names::{JOINT_DAMAGE, JOINT_NORMAL, JOINT_OPENING, JOINT_SLIDING};
