//! The fields and entity sets of the flow network: what a snapshot keeps, what the GPU
//! holds, and what output and other physics read.
//!
//! Flow node `l` is entity `l` of the set [`FLOW_NODES`] (one mesh node standing for the
//! vertex); channel `c` is entity `c` of [`FLOW_CHANNELS`] (its joint's side-A nodes).
//! The fluid also owns the shared node field [`pcdc_compute::names::PORE_PRESSURE`]:
//! every split copy of a vertex carries its flow node's pressure (0 off the network).

use pcdc_compute::{Components, FieldKey, Place};

/// Entity set of the flow nodes.
pub const FLOW_NODES: &str = "flow_nodes";
/// Entity set of the flow channels.
pub const FLOW_CHANNELS: &str = "flow_channels";

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
/// Saturation s of each flow node (-, in [0, 1]).
pub const FLOW_SATURATION: FieldKey = FieldKey::new(
    "flow_saturation",
    Place::Set(FLOW_NODES),
    Components::Fixed(1),
);
/// Mass-balance terms of each flow node (m³), 4 per node: initial content W₀, volume
/// injected by rate conditions, volume that pressure and head conditions added (negative:
/// outflow), volume lost to leak-off. See [`crate::mass_balance`].
pub const FLOW_BALANCE: FieldKey =
    FieldKey::new("flow_balance", Place::Set(FLOW_NODES), Components::Fixed(4));
/// Hydraulic aperture δ of each channel (m), eq. 79, at the last fluid step.
pub const CHANNEL_APERTURE: FieldKey = FieldKey::new(
    "channel_aperture",
    Place::Set(FLOW_CHANNELS),
    Components::Fixed(1),
);
/// Time each channel has been leaking, t − t_i (s; −1: not yet): it starts at 0 when
/// the channel's joint breaks (pre-existing fractures: at the start of the run) and
/// grows by every fluid step (leak-off only). Kept as an age, not a start time, so the
/// GPU needs no clock.
pub const CHANNEL_LEAK_AGE: FieldKey = FieldKey::new(
    "channel_leak_age",
    Place::Set(FLOW_CHANNELS),
    Components::Fixed(1),
);
/// Mean flux q = −(δ³ f(s̄)/(12 μ_d)) ∇ψ of each channel (m²/s: volume per unit time
/// and unit width), a vector in global axes in the channel's plane (eq. 75, 80), at the
/// last fluid step. Mean velocity v = q/δ (eq. 78).
pub const CHANNEL_FLUX: FieldKey = FieldKey::new(
    "channel_flux",
    Place::Set(FLOW_CHANNELS),
    Components::Vector,
);
