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
