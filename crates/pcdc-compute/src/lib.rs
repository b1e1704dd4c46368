//! # pcdc-compute
//!
//! The engine of pcdc-rs: a run-time [`Backend`] (a CPU pool, rayon, deterministic for
//! any thread count; or a GPU device, wgpu with device-resident fields, f64 or f32 from
//! one WGSL template, see [`gpu`], behind the cargo feature `gpu`, on by default),
//! field storage that allocates only what the composed physics declare
//! ([`FieldStore`]), the [`Physics`] trait, the [`Simulation`] with explicit
//! central-difference integration (manual 7.1 eq. i-v) with lumped mass and gravity, a
//! stable time step with a safety factor and a report of the limiting entity, static
//! mode by dynamic relaxation or a direct sparse solve (manual 7.2.7 "dynamic off"), time
//! [`Table`]s, [`History`] probes to CSV, a divergence watchdog, an energy balance with
//! an energy watchdog ([`EnergyBalance`]: the work of every force source, each physics'
//! inferred dissipation, a stop naming the physics and entity that inject energy) and
//! save/restore
//! ([`snapshot`]: versioned, checksummed and fingerprinted, so a damaged or foreign
//! snapshot is an error).
//!
//! Assembly uses no float atomics on either backend: each physics writes forces into its
//! own slots, registered once per node; each node sums its slots in registration order.

#![warn(missing_docs)]
// Index loops mirror the tensor notation of the manual's equations.
#![allow(clippy::needless_range_loop)]

mod backend;
mod beside;
pub mod coupling;
mod energy;
mod entity_set;
mod error;
mod field;
mod fingerprint;
pub mod gpu;
mod history;
mod node_pass;
mod physics;
mod simulation;
pub mod snapshot;
mod stages;
mod statics;
mod table;

pub use backend::{Backend, BackendChoice, BackendKind, CpuBackend, Precision};
pub use energy::{EnergyBalance, PhysicsEnergy, ENERGY_CHECK_EVERY};
pub use entity_set::EntitySet;
pub use error::ComputeError;
pub use field::{
    names, Components, FieldAccess, FieldId, FieldKey, FieldSpec, FieldStore, FieldUse, Location,
    Place,
};
pub use fingerprint::Fingerprint;
#[cfg(feature = "gpu")]
pub use gpu::WgpuBackend;
pub use history::{History, Probe};
pub use physics::{
    DofConstraint, Entity, EntityKind, FieldContext, FieldSchedule, ForceContext, InitContext,
    KinematicNodes, Kinematics, NodeBlock, Physics, PhysicsGroup, SlotBlock, StableStep, SubCycle,
    VelocityContext,
};
pub use simulation::{Simulation, SimulationBuilder, State, DEFAULT_SAFETY};
pub use stages::{FieldStage, MAX_SUBCYCLE};
pub use statics::{StaticOptions, StaticReport};
pub use table::{Control, Table, TimeValue};
