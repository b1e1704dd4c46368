//! The thermal physics' fields: what a snapshot keeps, what output and other physics
//! read. The temperature itself is the shared key
//! [`pcdc_compute::names::TEMPERATURE`] (one value per mesh node, K or °C: only
//! differences enter the equations, so either scale works if used throughout).

use pcdc_compute::{Components, FieldKey, Place};

/// Conductive heat flux q = −k ∇T of each element (W/m², D components), from the last
/// thermal step.
pub const HEAT_FLUX: FieldKey = FieldKey::new("heat_flux", Place::Element, Components::Vector);

/// Heat each node has received from outside the body since the start (J; J/m in 2D):
/// through face fluxes and convection, and what the temperature conditions put in or
/// took out to hold their values. With [`crate::heat_content`] it closes the
/// energy balance: Σ C_l (T_l − T_l⁰) = Σ supplied_l, to rounding.
pub const HEAT_SUPPLIED: FieldKey =
    FieldKey::new("heat_supplied", Place::Node, Components::Fixed(1));

/// Lumped heat capacity of each node, C_l = Σ_e ρ C_s Ω_e / N_e (J/K; J/(m·K) in 2D;
/// eq. 94), written once at init: Σ_l C_l T_l is the heat content.
pub const HEAT_CAPACITY: FieldKey =
    FieldKey::new("heat_capacity", Place::Node, Components::Fixed(1));

/// Temperature of each flow node's fluid (K or °C), with
/// [`crate::Thermal::fluid`] (entity set [`pcdc_compute::names::FLOW_NODES`] of the
/// fluid physics).
pub const FLUID_TEMPERATURE: FieldKey = FieldKey::new(
    "fluid_temperature",
    Place::Set(pcdc_compute::names::FLOW_NODES),
    Components::Fixed(1),
);

/// Heat capacity of each flow node's fluid at the last thermal step,
/// C_l = ρ_f C_f s_l V_l (J/K; J/(m·K) in 2D): Σ_l C_l T_l is the fluid's heat content.
pub const FLUID_HEAT_CAPACITY: FieldKey = FieldKey::new(
    "fluid_heat_capacity",
    Place::Set(pcdc_compute::names::FLOW_NODES),
    Components::Fixed(1),
);

/// Heat balance of each flow node's fluid (J; J/m in 2D), 4 per node: the heat content
/// C⁰T⁰ at the start, the heat the fluid temperature conditions put in to hold their
/// values, the advected heat (summed over the network: what the flow carried across
/// its boundary and into storage), and T ΔC as the fluid volume changed. With the
/// solid's it closes the energy balance (`crate::output::energy_balance`).
pub const FLUID_HEAT_BALANCE: FieldKey = FieldKey::new(
    "fluid_heat_balance",
    Place::Set(pcdc_compute::names::FLOW_NODES),
    Components::Fixed(4),
);
