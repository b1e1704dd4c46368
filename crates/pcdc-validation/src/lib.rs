//! # pcdc-validation
//!
//! The validation scenes of pcdc-rs (`docs/validation-scenes.md`): each builds a model
//! with the SDK, compares it with a closed form or a measured band and reports one
//! [`report::ResultLine`]; the UCS and Brazilian tests also read scene files (TOML,
//! [`scenes::file`]) and draw PNG plots ([`plot`]); [`table`] runs every scene at three
//! mesh sizes on every backend for `docs/validation.md`.
//!
//! This crate is separate from the SDK so that `cargo add pcdc` brings the SDK only
//! (no plotting, fonts or TOML). The examples and tests of the repository use it.

#![warn(missing_docs)]
// Index loops mirror the tensor notation of the manual's equations.
#![allow(clippy::needless_range_loop)]

pub mod calibration;
pub mod plot;
pub mod report;
pub mod scenes;
pub mod table;
