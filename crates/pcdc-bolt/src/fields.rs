//! The bolts' entity sets and fields.

use pcdc_compute::{Components, FieldKey, Place};

/// The entity set of bolt segments (two bolt nodes each, every bolt's segments in
/// order, head first).
pub const BOLT_SEGMENTS: &str = "bolt_segments";
/// The entity set of bolt nodes (one node each, every bolt's nodes in order, head
/// first).
pub const BOLT_NODES: &str = "bolt_nodes";

/// Axial force of each segment (N, tension positive; per unit thickness in 2D), without
/// the damping force.
pub const BOLT_AXIAL_FORCE: FieldKey = FieldKey::new(
    "bolt_axial_force",
    Place::Set(BOLT_SEGMENTS),
    Components::Fixed(1),
);
/// Plastic elongation of each segment (m; a pretensioned segment starts negative).
pub const BOLT_PLASTIC_ELONGATION: FieldKey = FieldKey::new(
    "bolt_plastic_elongation",
    Place::Set(BOLT_SEGMENTS),
    Components::Fixed(1),
);
/// State of each segment: 0 elastic, 1 at the tensile yield force, 2 at the
/// compressive yield force, 3 broken (`crate::SegmentState`).
pub const BOLT_STATE: FieldKey = FieldKey::new(
    "bolt_state",
    Place::Set(BOLT_SEGMENTS),
    Components::Fixed(1),
);
/// Grout shear force at each bolt node along the bolt (N, on the host; per unit
/// thickness in 2D): positive when the bolt node has moved towards the tail relative
/// to the rock.
pub const BOLT_GROUT_FORCE: FieldKey = FieldKey::new(
    "bolt_grout_force",
    Place::Set(BOLT_NODES),
    Components::Fixed(1),
);
/// Slip of each bolt node along the bolt once the bond was exceeded (m).
pub const BOLT_SLIP: FieldKey =
    FieldKey::new("bolt_slip", Place::Set(BOLT_NODES), Components::Fixed(1));
/// Velocity of bolt nodes with a prescribed acceleration, integrated (m/s).
pub const BOLT_BC_VELOCITY: FieldKey = FieldKey::new(
    "bolt_bc_velocity",
    Place::Set(BOLT_NODES),
    Components::Vector,
);
/// The host element of each bolt node (element index as a number): the element its
/// grout pulls on, found in the reference mesh and re-found when the node leaves it
/// (see the crate docs, "Re-locating"). Exact as a number up to 2²⁴ elements on an
/// f32 GPU backend (the kernels do not read it back: it is output).
pub const BOLT_HOST: FieldKey =
    FieldKey::new("bolt_host", Place::Set(BOLT_NODES), Components::Fixed(1));
/// Where each bolt node is grouted ([`anchor_len`] values per node): the index of its
/// host within the node's candidate hosts, the barycentric weights of the grout point
/// in the host (D + 1), the constant offset of the node from that point in the
/// displacement form of the relative displacement (m, D), the distance along the axis
/// (m) within which the node is surely still inside its host, and the node's axial
/// displacement against the rock carried over from its earlier grout points (m: at each
/// re-location the axial part of its relative displacement moves here, so that the
/// grout's δ, force and slip go on unchanged). State of the bolts: read it for
/// diagnostics, do not write it.
pub const BOLT_ANCHOR: FieldKey =
    FieldKey::new("bolt_anchor", Place::Set(BOLT_NODES), Components::Declared);

/// Values per bolt node of [`BOLT_ANCHOR`] in `d` dimensions: 2d + 4.
pub const fn anchor_len(d: usize) -> usize {
    2 * d + 4
}
