//! # pcdc
//!
//! Facade of the pcdc-rs SDK for continuum–discontinuum geomechanics by the combined
//! finite–discrete element method (FDEM): re-exports the crates ([`mesh`], [`compute`],
//! [`mech`], [`cohesive`], [`contact`], [`hydro`], [`thermal`], [`bolt`]) and composes them: [`fdem::Fdem`] is the
//! canonical FDEM composition in one call. The validation scenes, their RESULT lines,
//! scene files and plots live in the separate crate `pcdc-validation`, so adding `pcdc`
//! brings the SDK only. The cargo feature `gpu` (on by default) brings the GPU backend.
//!
//! A static scene in a few lines (the README's example):
//!
//! ```
//! use pcdc::compute::{Backend, Simulation, StaticOptions};
//! use pcdc::mech::{Boundary, FaceStress, LinearElastic, Mechanics, output};
//! use pcdc::mesh::{Range, builders};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let mesh = builders::rectangle(0.0, 0.0, 1.0, 2.0, 0.25)?;
//! let rock = LinearElastic::new(30e9, 0.25, 2600.0)?.with_damping(1.0)?;
//! let mut sim = Simulation::builder(mesh, Backend::cpu(0)?)
//!     .physics(Mechanics::new().material(Range::All, rock))
//!     .physics(
//!         Boundary::new()
//!             .fix(Range::group("bottom"))
//!             .face_stress(Range::group("top"), FaceStress::normal(-1e6)), // 1 MPa pressure
//!     )
//!     .gravity([0.0, -9.81, 0.0])
//!     .build()?;
//! sim.solve_linear(&StaticOptions::default())?; // or sim.relax(..), or sim.run(steps)
//! let stress = output::global_stress(&sim)?; // Pa, tension positive
//! assert!(stress.iter().all(|s| s.is_finite()));
//! # Ok(())
//! # }
//! ```

#![warn(missing_docs)]
// Index loops mirror the tensor notation of the manual's equations.
#![allow(clippy::needless_range_loop)]

pub use pcdc_bolt as bolt;
pub use pcdc_cohesive as cohesive;
pub use pcdc_compute as compute;
pub use pcdc_contact as contact;
pub use pcdc_hydro as hydro;
pub use pcdc_mech as mech;
pub use pcdc_mesh as mesh;
pub use pcdc_thermal as thermal;

pub mod fdem;
