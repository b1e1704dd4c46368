//! Validation scenes of `VALIDATION.md`: each runs a model, compares it with a closed
//! form and returns the measured error. Examples run them at full size and print the
//! `RESULT` line; tests run them at reduced size and assert the same tolerance.

pub mod block_sliding;
pub mod direct_tension;
pub mod kirsch;
pub mod vibration_energy;
pub mod wave_speed;
