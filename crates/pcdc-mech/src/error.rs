//! Errors of the mechanics crate.

/// Errors raised by mechanical models, physics and boundary conditions.
#[derive(Debug, thiserror::Error)]
#[allow(missing_docs)] // fields are named after what they hold; variants are documented
pub enum MechError {
    /// A material or boundary parameter is invalid.
    #[error("invalid parameter {name} = {value}: {reason}")]
    InvalidParameter {
        name: String,
        value: String,
        reason: String,
    },
    /// A range matched nothing where something is required.
    #[error("{what}: the range {range} selects no {entity}")]
    EmptyRange {
        what: String,
        range: String,
        entity: &'static str,
    },
    /// Mesh-level error.
    #[error(transparent)]
    Mesh(#[from] pcdc_mesh::MeshError),
    /// Compute-level error.
    #[error(transparent)]
    Compute(#[from] pcdc_compute::ComputeError),
}

impl MechError {
    /// Shorthand for [`MechError::InvalidParameter`].
    pub fn param(name: impl Into<String>, value: impl ToString, reason: impl Into<String>) -> Self {
        MechError::InvalidParameter {
            name: name.into(),
            value: value.to_string(),
            reason: reason.into(),
        }
    }
}

impl MechError {
    /// This error as a [`pcdc_compute::ComputeError`] raised by the physics named
    /// `physics`: compute and mesh errors pass through unchanged, the others become
    /// [`pcdc_compute::ComputeError::Physics`] with their message prefixed by
    /// `physics` (e.g. "mechanical boundary: invalid parameter ..."), so that the user
    /// sees which part of the scene is wrong.
    pub fn in_physics(self, physics: &str) -> pcdc_compute::ComputeError {
        match self {
            MechError::Compute(c) => c,
            MechError::Mesh(m) => pcdc_compute::ComputeError::Mesh(m),
            other => pcdc_compute::ComputeError::physics(physics, other.to_string()),
        }
    }
}

/// Errors of [`crate::Mechanics`] (the `?` conversion): named "mechanics". Other
/// physics of this crate name themselves with [`MechError::in_physics`].
impl From<MechError> for pcdc_compute::ComputeError {
    fn from(e: MechError) -> Self {
        e.in_physics("mechanics")
    }
}
