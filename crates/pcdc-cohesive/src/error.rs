//! Errors of the cohesive crate.

/// Errors raised by joint models and fracture mapping.
#[derive(Debug, thiserror::Error)]
#[allow(missing_docs)] // fields are named after what they hold; variants are documented
pub enum CohesiveError {
    /// A joint parameter is invalid.
    #[error("invalid joint parameter {name} = {value}: {reason}")]
    InvalidParameter {
        name: &'static str,
        value: f64,
        reason: &'static str,
    },
    /// A mesh-level error.
    #[error(transparent)]
    Mesh(#[from] pcdc_mesh::MeshError),
}
