//! Errors of the compute layer.

/// Errors raised while building or running a simulation.
#[derive(Debug, thiserror::Error)]
#[allow(missing_docs)] // fields are named after what they hold; variants are documented
pub enum ComputeError {
    /// A parameter has an invalid value.
    #[error("invalid parameter {name} = {value}: {reason}")]
    InvalidParameter {
        name: String,
        value: String,
        reason: String,
    },
    /// A time table is empty, unsorted or holds a non-finite value.
    #[error("table {name}: {reason}")]
    InvalidTable { name: String, reason: String },
    /// A mesh-level error (selection, output).
    #[error(transparent)]
    Mesh(#[from] pcdc_mesh::MeshError),
    /// Two physics declare the same field with different layouts.
    #[error("field '{name}' declared twice with different layouts ({a} and {b})")]
    FieldConflict { name: String, a: String, b: String },
    /// Two physics own the same field (e.g. the same physics composed twice).
    #[error("field '{field}' has two owners: physics '{first}' and physics '{second}' (a field has exactly one owner; compose each physics once)")]
    FieldOwnedTwice {
        field: String,
        first: String,
        second: String,
    },
    /// A physics uses a field that no composed physics owns.
    #[error("physics '{physics}' {verb} field '{field}', but no composed physics owns it (compose the physics that provides it)")]
    FieldWithoutOwner {
        field: String,
        physics: String,
        verb: &'static str,
    },
    /// A physics reads a field's current value before the physics that writes it runs.
    #[error("physics '{reader}' reads field '{field}' of the current step but runs before physics '{writer}', which writes it: add '{writer}' first (or read the previous step's value with read_lagged)")]
    FieldReadBeforeWrite {
        field: String,
        reader: String,
        writer: String,
    },
    /// A physics that may be composed only once was composed twice.
    #[error("physics '{0}' is composed twice; it may be composed only once (give one instance all its materials and ranges)")]
    DuplicatePhysics(String),
    /// A field was requested that no composed physics declared.
    #[error("no field named '{0}' (declared fields: {1})")]
    UnknownField(String, String),
    /// The run diverged: NaN, infinity or runaway displacement.
    #[error("divergence at step {step} (t = {time:e} s): {what} at {entity}. Hint: {hint}")]
    Diverged {
        step: u64,
        time: f64,
        what: String,
        entity: String,
        hint: String,
    },
    /// The energy watchdog stopped the run: the total energy exceeds the initial energy
    /// plus the external work by more than the tolerance (see [`crate::EnergyBalance`]).
    #[error("energy growth at step {step} (t = {time:e} s): total energy exceeds the initial energy plus the external work by {excess:e} J, more than {tolerance} of the reference {reference:e} J; injected by {physics}{}. Hint: a force that acts where it should not (e.g. between faces that have separated), a penalty too stiff for the time step, or a time step above the stable one", if entity.is_empty() { String::new() } else { format!(" at {entity}") })]
    EnergyGrowth {
        step: u64,
        time: f64,
        excess: f64,
        reference: f64,
        tolerance: f64,
        physics: String,
        entity: String,
    },
    /// No physics limits the time step and none was given.
    #[error("no stable time step: no composed physics reports one; set it with SimulationBuilder::time_step")]
    NoTimeStep,
    /// Static relaxation did not converge.
    #[error("static relaxation did not converge in {steps} steps (unbalanced-force ratio {ratio:e} > tolerance {tol:e}). Hint: raise max_steps or check that the model is fully supported")]
    NotConverged { steps: u64, ratio: f64, tol: f64 },
    /// A physics cannot take part in the direct (linear) static solve.
    #[error("direct static solve unavailable: {0}")]
    NotLinear(String),
    /// The sparse factorisation failed (singular or indefinite stiffness).
    #[error("sparse solve failed: {0}. Hint: the model may be under-constrained (rigid-body motion); add constraints")]
    Solver(String),
    /// A snapshot does not fit the simulation it is restored into.
    #[error("snapshot mismatch: {0}")]
    SnapshotMismatch(String),
    /// A snapshot is damaged: truncated, padded, failing its checksum, or holding values
    /// that no run can produce.
    #[error("corrupt snapshot: {0}")]
    SnapshotCorrupt(String),
    /// A snapshot was written in a format version this build does not read.
    #[error("snapshot format version {found} is not supported: this build reads version {supported}. Hint: restore it with the pcdc version that wrote it, or re-run the scene to make a new snapshot")]
    SnapshotVersion { found: u32, supported: u32 },
    /// An input/output error, with the path.
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    /// Snapshot (de)serialisation failed.
    #[error("snapshot encoding: {0}")]
    Encoding(String),
    /// The GPU backend failed (no adapter, limits, shader or device error).
    #[error("GPU backend: {0}")]
    Gpu(String),
    /// A composed physics (or one of its models) has no GPU kernel.
    #[error("physics '{physics}' cannot run on the GPU backend: {reason}. Hint: use the CPU backend (--backend cpu) or give the model a WGSL body")]
    NoGpuKernel { physics: String, reason: String },
    /// A physics-specific error.
    #[error("{physics}: {message}")]
    Physics { physics: String, message: String },
}

impl ComputeError {
    /// Shorthand for [`ComputeError::InvalidParameter`].
    pub fn param(name: impl Into<String>, value: impl ToString, reason: impl Into<String>) -> Self {
        ComputeError::InvalidParameter {
            name: name.into(),
            value: value.to_string(),
            reason: reason.into(),
        }
    }

    /// Shorthand for [`ComputeError::Physics`].
    pub fn physics(physics: impl Into<String>, message: impl Into<String>) -> Self {
        ComputeError::Physics {
            physics: physics.into(),
            message: message.into(),
        }
    }
}
