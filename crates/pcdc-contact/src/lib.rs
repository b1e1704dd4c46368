//! # pcdc-contact
//!
//! Contact between finite elements for the pcdc-rs FDEM SDK (manual 7.3), after
//! Munjiza's potential contact. This first part holds the 2D narrow phase: the exact
//! normal contact force between two overlapping triangles ([`triangle_pair_force`]).
//! Broad phase, friction, damping and the contact physics follow.

#![warn(missing_docs)]
// Index loops mirror the formulas.
#![allow(clippy::needless_range_loop)]

mod physics;
mod potential2d;

pub use physics::{Contact, ContactDamping, Friction, CONTACT_REFERENCE};
pub use potential2d::{potential, triangle_pair_force, PairForce2};
