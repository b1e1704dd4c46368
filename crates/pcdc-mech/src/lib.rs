//! # pcdc-mech
//!
//! Element mechanics for the pcdc-rs FDEM SDK (manual 7.2): the [`Mechanics`] physics
//! (constant-strain Tri3/Tet4 with objective co-rotated kinematics, viscous damping
//! eq. 17-19, lumped mass eq. 16), the [`ConstitutiveModel`] plugin trait with
//! [`LinearElastic`] (eq. 20-24), the mechanical [`Boundary`] conditions of 7.2.6
//! (velocities, accelerations, forces, face stresses, move constraints), initial stress,
//! and the resets of 7.2.8.
//!
//! ## Input checks
//!
//! [`LinearElastic`] keeps its parameters private and checks them in its constructors,
//! setters and deserialisation alike (E, ρ positive and finite; −1 < ν < 0.5, i.e. bulk
//! and shear moduli positive, auxetic ν < 0 allowed; D_f ≥ 0). [`Boundary`] checks its
//! items when the simulation is built: finite constants, constraint directions non-zero
//! in the mesh's dimension, and no z component or σ_zz prescribed on a 2D mesh (it would
//! be ignored silently; the constant 0 is accepted, as ignoring it changes nothing). Errors name the parameter and its value.
//!
//! ## Equations implemented
//!
//! | manual | what | where |
//! | --- | --- | --- |
//! | 7.1 i–v | explicit central differences `v += dt F/m`, `u += dt v` | `pcdc_compute::Simulation` |
//! | eq. 1–11 | constant element strain; here its large-rotation form: `F = D_s D_m⁻¹`, `F = R U`, `ε = U − I` | [`kinematics`] |
//! | eq. 12 | `σ(t+Δt) = H(σ(t), ε, Δε, history)` | [`ConstitutiveModel::update`] |
//! | eq. 13–14 | nodal forces from the element stress, `f_a = −V₀ R σ ∇N_a` | `Mechanics` |
//! | eq. 15–16 | body force and lumped mass `ρV/(N+1)` per node | `Mechanics`, gravity in `Simulation` |
//! | eq. 17–19 | viscous stress `σ_v = D_f C ε̇`, `C = 2L√(ρE)`, L = mean edge length | `Mechanics` |
//! | eq. 20–24 | isotropic linear elasticity, λ and μ from E, ν (or K, G) | [`LinearElastic`] |
//! | tables 4–7 | velocity/acceleration, force, face stress, move constraints | [`Boundary`] |
//!
//! The stable step of an element is `κ h / c_p` with h its smallest height, c_p the
//! P-wave speed and κ = 0.8 (Tri3) or 0.45 (Tet4) from the element eigenvalues; with
//! damping it is reduced to `(2/ω)(√(1+ξ²) − ξ)`.
//!
//! ```
//! use pcdc_compute::{Backend, Simulation};
//! use pcdc_mech::{Boundary, LinearElastic, Mechanics};
//! use pcdc_mesh::{Range, builders};
//!
//! let mesh = builders::rectangle(0.0, 0.0, 1.0, 0.5, 0.1).unwrap();
//! let rock = LinearElastic::new(30e9, 0.25, 2600.0).unwrap();
//! let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
//!     .physics(Mechanics::new().material(Range::All, rock))
//!     .physics(Boundary::new().fix(Range::group("bottom")))
//!     .gravity([0.0, -9.81, 0.0])
//!     .build()
//!     .unwrap();
//! sim.run(10).unwrap();
//! ```

#![warn(missing_docs)]
// Index loops mirror the tensor notation of the manual's equations.
#![allow(clippy::needless_range_loop)]

pub mod actions;
mod boundary;
mod error;
pub mod kinematics;
mod mechanics;
mod model;
pub mod output;

pub use actions::{reset_displacement, reset_element_state, reset_velocity, set_velocity};
pub use boundary::{Boundary, Components, Constraint, FaceStress, ACCEL_VELOCITY};
pub use error::MechError;
pub use mechanics::{Mechanics, SurfaceProperties};
pub use model::{double_dot, ConstitutiveModel, LinearElastic, Sym6, WgslModel};
