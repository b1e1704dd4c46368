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
