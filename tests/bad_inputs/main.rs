//! The bad-input suite of issue 12: every case feeds a bad input through a real entry
//! point (constructor, serde deserialisation, Gmsh text, scene TOML, simulation build)
//! and requires a clear error whose message names the problem, never a panic.
//!
//! Each area module lists its cases as lines `case(label, expected substring, call)` and
//! runs them with [`run`], which prints the number of cases. All cases run under a 1 GiB
//! memory limit (`pcdc_mesh::memory::set_memory_limit`), so that the memory-guard cases
//! do not depend on the machine.

mod boundary;
mod contact;
mod gmsh;
mod joints;
mod materials;
mod mesh;
mod ranges;
mod scene_files;
mod snapshots;
mod tables;

use std::fmt::Display;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// One bad-input case: a label, a substring its error message must contain, and the call
/// (its result mapped to the error message).
pub struct Case {
    label: &'static str,
    expect: &'static str,
    call: Box<dyn FnOnce() -> Result<(), String>>,
}

/// A case from a call returning any `Result` whose error is `Display`.
pub fn case<T, E: Display>(
    label: &'static str,
    expect: &'static str,
    call: impl FnOnce() -> Result<T, E> + 'static,
) -> Case {
    Case {
        label,
        expect,
        call: Box::new(move || call().map(|_| ()).map_err(|e| e.to_string())),
    }
}

/// Runs the cases of one area; fails listing every case that panicked, succeeded, or
/// gave a message without its expected substring. Returns the number of cases.
pub fn run(area: &str, cases: Vec<Case>) -> usize {
    pcdc_mesh::memory::set_memory_limit(Some(1 << 30));
    let n = cases.len();
    let mut failures = Vec::new();
    for c in cases {
        match catch_unwind(AssertUnwindSafe(c.call)) {
            Err(_) => failures.push(format!("{}: panicked", c.label)),
            Ok(Ok(())) => failures.push(format!("{}: accepted, expected an error", c.label)),
            Ok(Err(msg)) if !msg.contains(c.expect) => {
                failures.push(format!("{}: message lacks '{}': {msg}", c.label, c.expect))
            }
            Ok(Err(_)) => {}
        }
    }
    println!("bad inputs, {area}: {n} cases");
    assert!(failures.is_empty(), "{area}:\n{}", failures.join("\n"));
    n
}
