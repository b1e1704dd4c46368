//! Upper bounds of the platen-test scenes ([`crate::scenes::ucs`],
//! [`crate::scenes::brazilian`]) and the memory guard of the mesh a scene would build.
//!
//! The lower bounds (positive sizes, ν < 0.5, ...) come from physics; the upper bounds
//! below catch values that are physically absurd for a laboratory rock test, almost
//! always a unit mistake (mm typed as m, MPa as Pa), before a run allocates or loads
//! anything. Each bound is generous: about ten times beyond what a real test uses.
//!
//! Memory: a scene estimates its elements (specimen and platens) from the mesh size and
//! refuses a request whose FDEM state would exceed the memory limit of
//! [`pcdc_mesh::memory`] (by default half the machine's memory; settable with
//! [`pcdc_mesh::memory::set_memory_limit`] or the `PCDC_MEMORY_LIMIT` environment
//! variable), with the estimate in bytes in the message.

use pcdc_mesh::MeshError;

use super::platen_test::ParamError;

/// Largest specimen or platen dimension (m): laboratory specimens are 25–150 mm; 10 m
/// leaves room for scaled studies and rejects millimetres typed as metres (a "50 m"
/// disc).
pub const MAX_SAMPLE_SIZE: f64 = 10.0;

/// Largest platen speed (m/s): quasi-static tests load at µm/s to mm/s and the scenes
/// already accelerate to 0.02–0.2 m/s; beyond 10 m/s the test is an impact (the
/// specimen is no longer near equilibrium), not a strength test.
pub const MAX_PLATEN_VELOCITY: f64 = 10.0;

/// Longest loading ramp (s): the explicit time step of a laboratory specimen is
/// 1e-8–1e-7 s, so 1 s is already 1e7–1e8 steps of ramp alone.
pub const MAX_RAMP_TIME: f64 = 1.0;

/// Largest Young's modulus (Pa): 10 TPa, about ten times diamond's (1.2 TPa); rejects
/// moduli given in kPa-scaled units by mistake.
pub const MAX_MODULUS: f64 = 1e13;

/// Largest density (kg/m³): 1e5, about four times osmium's (22 590), the densest element.
pub const MAX_DENSITY: f64 = 1e5;

/// Largest joint cohesion or tensile strength (Pa): 10 GPa, ten times beyond the
/// strongest rocks' compressive strength (about 0.5 GPa); rejects MPa typed as kPa·1e6.
pub const MAX_STRENGTH: f64 = 1e10;

/// Largest fracture energy G_f1, G_f2 (N/m): rocks have 10–1000 N/m; 1e6 N/m is far
/// beyond any brittle material.
pub const MAX_FRACTURE_ENERGY: f64 = 1e6;

/// Largest penalty as a multiple of the rock's E: the manual uses 10–100 E; 1e4 E would
/// shrink the stable time step a hundredfold for no gain in accuracy.
pub const MAX_PENALTY_FACTOR: f64 = 1e4;

/// Bytes per element of an FDEM platen-test simulation used by the memory guard: the
/// design budget is about 1.7 kB per triangle with its own nodes, joints and contact
/// (`docs/performance.md`), rounded up to 2 KiB.
pub const FDEM_BYTES_PER_ELEMENT: f64 = 2048.0;

/// Area of the equilateral triangle of edge `size` (m²): the smallest element area the
/// scene meshes use for a mesh size `size`, so `area / element_area(size)` bounds the
/// element count from above.
pub fn element_area(size: f64) -> f64 {
    0.75f64.sqrt() / 2.0 * size * size
}

/// Checks that `value` is at most `max`.
pub(crate) fn at_most(
    key: &str,
    value: f64,
    max: f64,
    reason: &'static str,
) -> Result<(), ParamError> {
    if value <= max {
        Ok(())
    } else {
        Err(ParamError {
            key: key.into(),
            value,
            reason,
        })
    }
}

/// Refuses a scene whose mesh (about `area / element_area(mesh_size)` elements over the
/// meshed `area`, m²) would need more FDEM memory than the limit; the error names `key`
/// and the estimate in bytes.
pub fn check_scene_memory(key: &str, mesh_size: f64, area: f64) -> Result<(), MeshError> {
    let elements = area / element_area(mesh_size);
    pcdc_mesh::memory::check_memory(
        key,
        mesh_size,
        format!("the FDEM scene of about {elements:.3e} elements"),
        elements * FDEM_BYTES_PER_ELEMENT,
    )
}
