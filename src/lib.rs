//! # pcdc
//!
//! Facade of the pcdc-rs SDK for continuum–discontinuum geomechanics by the combined
//! finite–discrete element method (FDEM): re-exports the crates and holds the PNG
//! plotting used by the validation scenes.

#![warn(missing_docs)]
// Index loops mirror the tensor notation of the manual's equations.
#![allow(clippy::needless_range_loop)]

pub use pcdc_compute as compute;
pub use pcdc_mech as mech;
pub use pcdc_mesh as mesh;

pub mod plot;
pub mod report;
pub mod scenes;
