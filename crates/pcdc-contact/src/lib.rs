//! # pcdc-contact
//!
//! Contact between finite elements for the pcdc-rs FDEM SDK (manual 7.3), after
//! Munjiza's potential contact: the exact 2D normal contact force between two
//! overlapping triangles ([`triangle_pair_force`], eq. 52-58), the [`ContactModel`]
//! plugin trait with the built-in `contact-m-c` law ([`MohrCoulombContact`]: Coulomb
//! friction with a shear penalty, eq. 59-60, and damping after An and Tannant, eq. 61),
//! and the [`Contact`] physics (sorted-grid broad phase with a skin, deterministic
//! element-centric assembly, bonded-neighbour exclusion for FDEM regions).

#![warn(missing_docs)]
// Index loops mirror the formulas.
#![allow(clippy::needless_range_loop)]

mod model;
mod physics;
mod potential2d;

pub use model::{ContactDamping, ContactModel, ContactStress, Friction, MohrCoulombContact};
pub use physics::{element_boxes, grid_candidates, Contact, CONTACT_REFERENCE};
pub use potential2d::{potential, triangle_pair_force, PairForce2};
