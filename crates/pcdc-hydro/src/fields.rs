//! The fields and entity sets of the flow network: what a snapshot keeps, what the GPU
//! holds, and what output and other physics read.
//!
//! Flow node `l` is entity `l` of the set [`FLOW_NODES`] (one mesh node standing for the
//! vertex); channel `c` is entity `c` of [`FLOW_CHANNELS`] (its joint's side-A nodes).
//! The fluid also owns the shared node field [`pcdc_compute::names::PORE_PRESSURE`]:
//! every split copy of a vertex carries its flow node's pressure (0 off the network).

use pcdc_compute::{Components, FieldKey, Place};

/// Shared with other physics (fluid heat reads them): declared in
/// [`pcdc_compute::names`]. The flux is q = −(δ³ f(s̄)/(12 μ_d)) ∇ψ (eq. 75, 80), the
/// aperture δ of eq. 79.
pub use pcdc_compute::names::{
    CHANNEL_APERTURE, CHANNEL_FLUX, FLOW_CHANNELS, FLOW_NODES, FLOW_SATURATION,
};

/// Change of each flow node's fluid content since the start, W − W₀ (m³ at zero
/// pressure; m² per unit thickness in 2D): the state the storage equation updates
/// (eq. 84–85 in conservative form; W₀ is in [`FLOW_BALANCE`]). Kept as a change so that
/// the mass balance sums changes, not contents.
pub const FLOW_STORED: FieldKey =
    FieldKey::new("flow_stored", Place::Set(FLOW_NODES), Components::Fixed(1));
/// Fluid pressure p of each flow node (Pa, ≥ 0).
pub const FLOW_PRESSURE: FieldKey = FieldKey::new(
    "flow_pressure",
    Place::Set(FLOW_NODES),
    Components::Fixed(1),
);
/// The highest pressure each flow node has reached since the start (Pa), updated at
/// every fluid step: at an injection node, the breakdown pressure, whatever the output
/// interval.
pub const FLOW_PEAK_PRESSURE: FieldKey = FieldKey::new(
    "flow_peak_pressure",
    Place::Set(FLOW_NODES),
    Components::Fixed(1),
);
/// Mass-balance terms of each flow node (m³), 4 per node: initial content W₀, volume
/// injected by rate conditions, volume that pressure and head conditions added (negative:
/// outflow), volume lost to leak-off. See [`crate::mass_balance`].
pub const FLOW_BALANCE: FieldKey =
    FieldKey::new("flow_balance", Place::Set(FLOW_NODES), Components::Fixed(4));
/// Time each channel has been leaking, t − t_i (s; −1: not yet): it starts at 0 when
/// the channel's joint breaks (pre-existing fractures: at the start of the run) and
/// grows by every fluid step (leak-off only). Kept as an age, not a start time, so the
/// GPU needs no clock.
pub const CHANNEL_LEAK_AGE: FieldKey = FieldKey::new(
    "channel_leak_age",
    Place::Set(FLOW_CHANNELS),
    Components::Fixed(1),
);
