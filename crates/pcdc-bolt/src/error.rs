//! Errors of the bolt crate: every one names the bolt (or the parameter) it is about.

use pcdc_compute::ComputeError;

/// An error in a bolt's definition or placement.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BoltError {
    /// A property or geometric value out of range.
    #[error("invalid bolt parameter {name} = {value}: {reason}")]
    InvalidParameter {
        /// The parameter (and the bolt, once known).
        name: String,
        /// Its value, as given.
        value: String,
        /// What it must be.
        reason: String,
    },
    /// A bolt whose geometry cannot be built.
    #[error("bolt '{bolt}': {reason}")]
    Geometry {
        /// The bolt's name.
        bolt: String,
        /// What is wrong.
        reason: String,
    },
    /// A bolt node that lies in no element of the mesh.
    #[error("bolt '{bolt}': node {node} at {position:?} lies outside the mesh (every bolt node is grouted to the element that holds it)")]
    OutsideMesh {
        /// The bolt's name.
        bolt: String,
        /// Node index along the bolt (0 = head).
        node: usize,
        /// Its reference position (m).
        position: Vec<f64>,
    },
    /// An error of the engine.
    #[error(transparent)]
    Compute(#[from] ComputeError),
}

impl BoltError {
    /// An invalid parameter.
    pub fn param(name: impl Into<String>, value: impl ToString, reason: impl Into<String>) -> Self {
        BoltError::InvalidParameter {
            name: name.into(),
            value: value.to_string(),
            reason: reason.into(),
        }
    }
}

impl From<BoltError> for ComputeError {
    fn from(e: BoltError) -> Self {
        match e {
            BoltError::Compute(c) => c,
            BoltError::InvalidParameter {
                name,
                value,
                reason,
            } => ComputeError::InvalidParameter {
                name,
                value,
                reason,
            },
            other => ComputeError::physics(crate::NAME, other.to_string()),
        }
    }
}
