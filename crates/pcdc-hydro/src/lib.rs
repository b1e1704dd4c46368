//! # pcdc-hydro
//!
//! Fluid flow in fractures for pcdc-rs (manual 7.5, `hydr-p-m`): a flow channel on every
//! joint of a split mesh, broken or intact (intact ones carry a virtual aperture
//! calibrated to the rock mass permeability), a flow node at every original vertex
//! shared by all the element nodes split from it, the cubic law with saturation,
//! compressible storage, Carter leak-off, pressure, water-level and injection
//! conditions with time tables, and the coupling to the solid: the pressure loads both
//! faces of each joint, the joints' opening changes the apertures and volumes.
//!
//! ```text
//! Network   channels on joints, flow nodes at master vertices      (network)
//! Geometry  midplane, opening ō, aperture δ (79), weights, volumes (flow)
//! Flux      Q_ij = k w_ij (ψ_i − ψ_j), k = δ³ f(s̄)/(12 μ_d)        (flow; 74–83)
//! Storage   W ← W + Δt ΣQ, p = K_f (W/V − 1) or s = W/V            (flow; 84–85)
//! Leak-off  4 A C_leak (√(t+Δt−t_i) − √(t−t_i)) f(s̄)               (model; 86–88)
//! Coupling  ∫ N_k p dA on both faces, equal and opposite            (physics; 7.5.2)
//! ```
//!
//! ## Equations implemented (manual 7.5.1–7.5.2; corrections marked)
//!
//! * **(74)** gradient of the total head φ_h = z + p/(ρ_f g) in a channel: the exact
//!   gradient of the linear interpolant over the channel's nodes (written with the
//!   piezometric pressure ψ = p − ρ_f g·x = ρ_f g φ_h, so gravity may point anywhere).
//! * **(75)** cubic law, unit-width flux q = −(δ³/(12 μ_d)) ∇ψ.
//! * **(76)** \[CORRECTED\] μ_d = μ_k ρ_f (printed `μ_k = μ_d ρ_f`); the input viscosity
//!   is kinematic.
//! * **(77)** \[CORRECTED\] hydraulic conductivity k_f = δ² ρ_f g/(12 μ_d) (printed without
//!   μ_d); used through (75).
//! * **(78)** mean velocity v = q/δ (the output flux divided by the aperture).
//! * **(79)** δ = δ⁰ + ō clamped to [δ_min, δ_max], ō the mean normal opening of the
//!   joint's node pairs, computed from the current positions.
//! * **(80)–(81)** saturation weighting q·f(s̄), f(s) = s²(3 − 2s), s̄ the channel's mean.
//! * **(82)** \[CORRECTED\] nodal inflow ΔQ_l = −(1/N) q·n^(l) s^(l) (the printed extra
//!   factor δ is dimensionally wrong), evaluated edge by edge as Q_ij = k w_ij (ψ_i − ψ_j)
//!   with the linear-element weights w (2D: 1/L; 3D: the cotangent weights), which is
//!   the same sum and conserves volume exactly.
//! * **(83)** ΔQ_l summed over the channels of node l, gather-style in a fixed order.
//! * **(84)–(85)** \[CORRECTED\] storage in conservative form: the fluid content W of each
//!   node is updated by ΔQ Δt, and p = K_f (W/V − 1) (saturated) or s = W/V, p = 0
//!   (draining); to first order this is eq. 84 and the mass-conserving eq. 85 (whose
//!   printed form has K_f where the net inflow belongs).
//! * **(86)–(88)** \[CORRECTED\] Carter leak-off from the time a joint breaks, on both
//!   walls, integrated exactly over each step, weighted by f(s̄), subtracted from the
//!   nodes' inflow as a volume (the printed eq. 88 adds a volume to a rate); see
//!   [`LeakOff`].
//! * **(80)** \[CORRECTED\] the volume shares weight each edge by f(s) of the node its
//!   flow leaves (upstream), not the channel mean, so an empty node stops draining
//!   ([`flow::upstream_weight`]); the output flux and leak-off keep f(s̄).
//! * **Intact rock** \[NOT IN MANUAL: the manual says the virtual aperture is
//!   calibrated, not how\] with [`Hydro::rock_permeability`] the intact network is the
//!   linear finite-element discretisation of isotropic Darcy flow: through one aperture
//!   per edge in 2D, through calibrated edge weights per face in 3D, blending into the
//!   cubic law of the joint's own geometry as it opens ([`calibration`]).
//! * **Table 11** conditions: pressure, free surface (hydrostatic below the water level,
//!   \[NOT IN MANUAL\] a seepage face above it: p ≤ 0 held, outflow only) and flow rate,
//!   each constant or a time table.
//! * **Coupling (7.5.2)** \[NOT IN MANUAL: the integration rule\] the linear pressure on a
//!   channel is integrated consistently over the joint's two faces, ∫ N_k p dA, and
//!   applied along the midplane normal, equal and opposite.
//!
//! ## Stable steps \[NOT IN MANUAL: derived\]
//!
//! The explicit storage update is stable for Δt_f ≤ min_l V_l / (K_f Σ_c |k w|)
//! (Gershgorin on the nodal Laplacian). In flow-only mode this bound is taken at the
//! fixed apertures; when the flow follows the solid, at the aperture range's worst case,
//! min_c 12 μ_d A_c / (N K_f δ_max² Σ_j |w_kj|) (so δ_max bounds the step, as the manual
//! says; with calibrated weights the larger of δ_r² |ŵ| and its value at δ_max). In two-way coupling the fluid stiffens the joints by about K_f/δ per unit face
//! area; the mechanical step is limited accordingly (at δ_min), and
//! [`Hydro::bulk_modulus_scale`] trades transient accuracy for speed. Both are reported
//! with the limiting flow node or channel (`Simulation::time_step_limit`,
//! `Simulation::field_stages`).
//!
//! ## Mass balance
//!
//! Injected = stored change + leaked + outflow, to rounding, at any step
//! ([`mass_balance`]): conditions and leak-off are booked per flow node in
//! [`fields::FLOW_BALANCE`].

#![warn(missing_docs)]
#![allow(clippy::needless_range_loop)]

mod balance;
pub mod calibration;
pub mod fields;
pub mod flow;
mod gpu;
mod model;
pub mod network;
pub mod output;
mod physics;
mod steady;

pub use balance::{balance_probes, mass_balance, MassBalance};
pub use model::{saturation_weight, Aperture, FlowModel, Fluid, LeakOff};
pub use network::Network;
pub use physics::{Coupling, Hydro};
