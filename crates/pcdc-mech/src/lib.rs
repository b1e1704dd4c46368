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
//! | eq. 12 | `σ(t+Δt) = H(σ(t), ε, Δε, history)` (and coupling inputs) | [`ConstitutiveModel::update`], [`ConstitutiveModel::update_with`], [`ConstitutiveModel::update_many`] (a run of elements at once on the CPU) |
//! | eq. 13–14 | nodal forces from the element stress, `f_a = −V₀ R σ ∇N_a` | `Mechanics` |
//! | eq. 15–16 | body force and lumped mass `ρV/(N+1)` per node | `Mechanics`, gravity in `Simulation` |
//! | eq. 17–19 | viscous stress `σ_v = D_f C ε̇`, `C = 2L√(ρE)`, L = mean edge length | `Mechanics` |
//! | eq. 20–24 | isotropic linear elasticity, λ and μ from E, ν (or K, G) | [`LinearElastic`] |
//! | eq. 25–33 (29 \[CORRECTED\]), table 2 | Mohr–Coulomb with tension cut-off, non-associated shear flow, return mapping over the pyramid's planes, edges and the shear–tension corner (CPU and WGSL); strain softening of c, φ, ψ, σ_t \[NOT IN MANUAL\] | [`MohrCoulomb`], [`Softening`], [`mohr_coulomb`], [`principal`] |
//! | eq. 34–48 (47–48 \[CORRECTED\]), table 3 | Burgers creep in deviatoric tensor form, Crank–Nicolson, with a creep clock and creep steps relaxed to equilibrium | [`Burgers`], [`CreepClock`], [`creep_step`], [`burgers`] |
//! | 7.2.8 | null model (excavation: no stiffness, mass, gravity or stress; nodes without a live element drop out), stage resets, geostatic initial stress (K0, depth gradient, principal values at an angle) | [`set_null`], [`reset_velocity`], [`reset_displacement`], [`reset_element_state`], [`InitialStress`] |
//! | tables 4–7 | velocity/acceleration, force, face stress, move constraints | [`Boundary`] |
//! | chapter 4 (element types) | Quad4/Hex8 cells, also mixed with Tri3/Tet4: Marti–Cundall mixed discretisation over the cell's simplices (cell-mean volumetric strain and pressure, B̄ stiffness, mass lumped equally on the cell's nodes) \[NOT IN MANUAL: the manual does not say how its quadrilaterals are integrated\] | [`mixed`] |
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

//!
//! ## Coupling inputs for plugin models
//!
//! A [`ConstitutiveModel`] that depends on another physics' field (temperature for a
//! thermal strain, pore pressure for effective stress) names the fields in
//! [`ConstitutiveModel::coupling`] (well-known keys: `pcdc_compute::names::TEMPERATURE`,
//! K, and `names::PORE_PRESSURE`, Pa, both node fields) and overrides
//! [`ConstitutiveModel::update_with`], whose [`ModelInput::coupling`] holds the fields'
//! values at the element in declaration order (node field: mean of the element's node
//! values; element field: the element's value). [`Mechanics`] then reads those fields
//! (lagged: the value they hold when its forces stage runs, at most one step old, so the
//! owner may be composed before or after it); the physics that owns them must be
//! composed too, or the build fails with
//! [`pcdc_compute::ComputeError::FieldWithoutOwner`]. On the GPU the model's WGSL body
//! receives the same values as `coupling[i]` ([`WgslModel`]). A model that asks for
//! nothing costs nothing: no field is declared or allocated, nothing is gathered and
//! the element kernel is unchanged.
//!
//! ```
//! use pcdc_compute::{names, FieldKey};
//! use pcdc_mech::{ConstitutiveModel, LinearElastic, ModelInput, Sym6};
//!
//! /// Thermo-elasticity, incremental: σ += C:Δε − 3Kα ΔT I, with the temperature of the
//! /// previous update kept as history variable 0 (initially T0).
//! #[derive(Debug)]
//! struct ThermoElastic {
//!     elastic: LinearElastic,
//!     /// Linear expansion coefficient α (1/K).
//!     alpha: f64,
//!     /// Reference temperature T0 (K).
//!     t0: f64,
//! }
//!
//! impl ConstitutiveModel for ThermoElastic {
//!     fn name(&self) -> &str { "thermo-elastic" }
//!     fn density(&self) -> f64 { self.elastic.density() }
//!     fn young(&self) -> f64 { self.elastic.young() }
//!     fn wave_modulus(&self) -> f64 { self.elastic.wave_modulus() }
//!     fn damp_factor(&self) -> f64 { self.elastic.damp_factor() }
//!     fn n_state(&self) -> usize { 1 }
//!     fn init_state_into(&self, state: &mut [f64]) { state[0] = self.t0; }
//!     fn coupling(&self) -> &[FieldKey] { &[names::TEMPERATURE] }
//!     /// Without coupling inputs: the temperature stays at T0.
//!     fn update(&self, strain: &Sym6, dstrain: &Sym6, stress: &mut Sym6, state: &mut [f64]) {
//!         self.elastic.update(strain, dstrain, stress, state);
//!     }
//!     fn update_with(&self, input: &ModelInput<'_>, stress: &mut Sym6, state: &mut [f64]) {
//!         let t = input.coupling[0];
//!         let th = 3.0 * self.elastic.bulk() * self.alpha * (t - state[0]);
//!         state[0] = t;
//!         let ds = self.elastic.stress_of(input.dstrain);
//!         for k in 0..6 {
//!             stress[k] += ds[k] - if k < 3 { th } else { 0.0 };
//!         }
//!     }
//! }
//!
//! let m = ThermoElastic { elastic: LinearElastic::new(30e9, 0.25, 2600.0)?, alpha: 1e-5, t0: 293.15 };
//! let (mut stress, mut state) = ([0.0; 6], [293.15]);
//! // Clamped (no strain), heated by 100 K: σ = −3Kα ΔT = −E α ΔT / (1 − 2ν) = −60 MPa.
//! m.update_with(&ModelInput::new(&[0.0; 6], &[0.0; 6], &[393.15]), &mut stress, &mut state);
//! assert!((stress[0] + 60e6).abs() < 1e-6 * 60e6);
//! # Ok::<(), pcdc_mech::MechError>(())
//! ```

#![warn(missing_docs)]
// Index loops mirror the tensor notation of the manual's equations.
#![allow(clippy::needless_range_loop)]

pub mod actions;
mod boundary;
pub mod burgers;
mod error;
pub mod initial_stress;
pub mod kinematics;
mod mechanics;
pub mod mixed;
mod model;
pub mod mohr_coulomb;
pub mod output;
pub mod principal;
pub mod servo;
pub mod thermal_strain;

pub use actions::{
    reset_displacement, reset_element_state, reset_velocity, set_null, set_velocity,
};
pub use boundary::{Boundary, Components, Constraint, FaceStress, ACCEL_VELOCITY};
pub use burgers::{creep_step, creep_time, Burgers, CreepClock, CREEP_CLOCK};
pub use error::MechError;
pub use initial_stress::InitialStress;
pub use mechanics::{Mechanics, SurfaceProperties};
pub use model::{double_dot, ConstitutiveModel, LinearElastic, ModelInput, Sym6, WgslModel};
pub use mohr_coulomb::{MohrCoulomb, Softening};
pub use servo::{ServoGains, StressServo};
pub use thermal_strain::ThermalStrain;
