//! # pcdc-thermal
//!
//! Heat for pcdc-rs (manual 7.6): explicit conduction in the solid on every element
//! type (Quad4/Hex8 cells conduct through their simplices), temperature, heat-flux and
//! convection conditions with time tables, conduction across the joints of a split
//! mesh until they break, and the coupling to the mechanics through the shared node
//! field `names::TEMPERATURE`, which `pcdc_mech::ThermalStrain` turns into thermal
//! stress for any constitutive model.
//!
//! ```text
//! Element   ∇T = Σ_a T_a ∇N_a, q = −k ∇T, R_a = Ω ∇N_a · q         (conduction; 93–98)
//! Faces     q_n A / N, h (T_env − T_l) A / N per face node           (boundary; 100–101)
//! Node      T_l ← T_l + Δt (Σ R + face heat) / C_l, C_l = Σ ρ C_s Ω / N  (physics; 94, 99)
//! Joints    split copies joined by conducting joints share one T      (physics; JointHeat)
//! Fluid     channel conduction, upwind advection, wall exchange      (fluid; 102–110)
//! ```
//!
//! ## Equations implemented (manual 7.6.1–7.6.2, 7.6.8; corrections marked)
//!
//! * **(93)** Fourier's law q_i = −k_ij ∂T/∂x_j, k isotropic or a positive definite
//!   tensor ([`Conductivity`]).
//! * **(95)** the element gradient of the linear temperature field, written with the
//!   shape-function gradients ∇N_a (the same field as the manual's face sum
//!   −(1/(Ω N_dim)) Σ_f T_f n^(f) s^(f)).
//! * **(96)–(98)** the nodal heat rate R_a = −(1/N_dim) q·n^(a) s^(a) = Ω ∇N_a · q (the
//!   face opposite node a has n^(a) s^(a) = −N_dim Ω ∇N_a): heat flows from hot to cold,
//!   and Σ_a R_a = 0 in every element.
//! * **(94), (99)** \[CORRECTED\] T_l(t+Δt) = T_l(t) + Δt ΔQ_l / (C_s m_l) (printed as
//!   ΔQ Δt / C, without the nodal mass), with the lumped capacity C_l = C_s m_l =
//!   Σ_e ρ C_s Ω_e / N_e, summed over the thermal node's split copies.
//! * **(100)–(101)** convection ΔQ = h (T_env − T_Γ) A, shared 1/N per face node with
//!   T_Γ the node's own temperature \[NOT IN MANUAL: the lumped choice of the digest\];
//!   heat flux likewise (a density in W/m², see [`Thermal::heat_flux`]).
//! * **Stable step** \[NOT IN MANUAL\] Δt ≤ min_l 2 C_l / Σ_b |K_lb| (Gershgorin on
//!   C⁻¹K with K_ab = Σ_e Ω ∇N_a·k∇N_b, convection h A/N on the diagonal); for an
//!   equilateral triangle of side h this is h²/(4κ)·… of the digest's estimate, and the
//!   limiting node is reported (`Simulation::field_stages`).
//! * **Joints** \[NOT IN MANUAL\] see [`JointHeat`]: intact joints conduct as rock,
//!   broken ones insulate.
//!
//! Units: SI. In 2D every extensive quantity is per metre of thickness (capacity J/(m·K),
//! rates W/m); a flux density stays W/m². Temperatures in K or °C (only differences
//! enter; use one scale for every input).
//!
//! ## Energy balance
//!
//! [`HEAT_CAPACITY`] and [`HEAT_SUPPLIED`] close it: Σ_l C_l (T_l − T_l⁰) = Σ_l
//! supplied_l, to rounding (conduction only moves heat between nodes).
//!
//! ## Heat in the fracture fluid (eq. 102–110)
//!
//! With [`Thermal::fluid`] and the fluid physics (`pcdc_hydro::Hydro`) composed, every
//! flow node carries a fluid temperature ([`FLUID_TEMPERATURE`]): conduction along the
//! channels (102), upwind advection with the channels' fluxes (103–108, \[CORRECTED\]
//! with the aperture), exchange h_sf A f(s)/N with each of the channel's two walls
//! (109–110, \[CORRECTED\] share 1/N), fluid temperature conditions (table 15). Exchange
//! and advection are point-implicit in the fluid node (a millimetre of water holds too
//! little heat for an explicit step), which keeps the fluid temperatures within their
//! inflow, wall and initial bounds at any step; the solid and fluid energy balance closes
//! to rounding ([`output::energy_balance`]). The network is read through the shared keys
//! of `pcdc_compute::names` (no dependency on `pcdc-hydro`); `Hydro::steady_flow` gives
//! the settled flow that a slow heat problem runs on (the Lauwerier scene).
//!
//! ## GPU
//!
//! Kernels in `shaders/thermal.wgsl`, the CPU's arithmetic in the same order, parity to
//! 1e-12 in f64 (fluid heat included). With [`JointHeat::FollowDamage`] on a split mesh
//! the device finds the thermal nodes per original vertex every step from the damage
//! (at most 64 split copies per vertex; more is refused with `ComputeError::NoGpuKernel`).
//!
//! ## Contact across broken joints (eq. 111–112)
//!
//! With [`Thermal::contact_conductance`] a broken joint whose faces still touch
//! (opening in [−L/2, 0], sliding below L/2, from the cohesive joints) carries
//! (1/N) h_c A (T_m − T_l) between its node pairs \[NOT IN MANUAL: node pairs of the
//! joint for the manual's element temperatures\]; an open crack insulates. Contacts
//! between faces that were never joined carry no heat yet.

#![warn(missing_docs)]
#![allow(clippy::needless_range_loop)]

mod boundary;
mod conduction;
mod contact;
pub mod fields;
mod fluid;
mod gpu;
mod material;
pub mod output;
mod physics;

pub use fields::{
    FLUID_HEAT_BALANCE, FLUID_HEAT_CAPACITY, FLUID_TEMPERATURE, HEAT_CAPACITY, HEAT_FLUX,
    HEAT_SUPPLIED,
};
pub use fluid::FluidHeat;
pub use material::{Conductivity, HeatMaterial};
pub use physics::{JointHeat, Thermal};

/// Heat content Σ_l C_l T_l (J; J/m in 2D) of the nodal temperatures `temperature`
/// with the capacities `capacity` (the fields [`pcdc_compute::names::TEMPERATURE`] and
/// [`HEAT_CAPACITY`]).
pub fn heat_content(capacity: &[f64], temperature: &[f64]) -> f64 {
    capacity.iter().zip(temperature).map(|(c, t)| c * t).sum()
}
