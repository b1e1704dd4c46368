//! Validation scenes, specified in `docs/validation-scenes.md`: each runs a model,
//! compares it with a closed form and returns the measured error. Examples run them at
//! full size and print the `RESULT` line; tests run them at reduced size and assert the
//! same tolerance.
//!
//! [`benchmark`] holds the standard FDEM benchmark scenes of the speed measurements.
//!
//! The laboratory tests [`ucs`] and [`brazilian`] share one platen-test set-up
//! ([`platen_test`]) and can be written as TOML scene files ([`file`](mod@file)); their upper
//! bounds and memory guard are in [`limits`].

pub mod benchmark;
pub mod block_sliding;
pub mod brazilian;
pub mod creep;
pub mod direct_tension;
pub mod file;
pub mod fracture_flow;
pub mod fragmentation;
pub mod injection;
pub mod kirsch;
pub mod limits;
pub mod platen_test;
pub mod radial_flow;
pub mod triaxial;
pub mod tunnel;
pub mod ucs;
pub mod unconfined_flow;
pub mod vibration_energy;
pub mod wave_speed;

/// Plane strain (Tri3) or 3D (Tet4), for the scenes that run both ([`triaxial`],
/// [`creep`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dimension {
    /// Plane strain, Tri3.
    Two,
    /// 3D, Tet4.
    Three,
}
