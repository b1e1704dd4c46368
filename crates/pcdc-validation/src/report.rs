//! The `RESULT` line every validation scene ends with (its format and each example's
//! metrics: `docs/design-targets.md`), the backend choice of the validation examples,
//! and output folders.

use std::fmt;
use std::path::PathBuf;

use pcdc_compute::Backend;

/// One machine-readable result line:
/// `RESULT case=<name> metric=<name> value=<number> tol=<number> pass=<bool> elements=<n>
/// steps=<n> wall_s=<seconds> backend=<cpu|gpu> precision=<f64|f32>`.
#[derive(Clone, Debug, PartialEq)]
pub struct ResultLine {
    /// Scene name.
    pub case: String,
    /// Name of the error metric.
    pub metric: String,
    /// Measured value of the metric.
    pub value: f64,
    /// Tolerance.
    pub tol: f64,
    /// Elements in the model.
    pub elements: usize,
    /// Steps (explicit steps, relaxation steps or solver iterations).
    pub steps: u64,
    /// Wall-clock time of the solve (s).
    pub wall_s: f64,
    /// Backend name (`cpu` or `gpu`).
    pub backend: String,
    /// Floating-point precision (`f64` or `f32`).
    pub precision: String,
}

impl ResultLine {
    /// A result measured on `backend`: `backend=` and `precision=` are the backend's own
    /// ([`Backend::kind`], [`Backend::precision`]).
    #[allow(clippy::too_many_arguments)] // the fields of the line, in its order
    pub fn new(
        backend: &Backend,
        case: &str,
        metric: &str,
        value: f64,
        tol: f64,
        elements: usize,
        steps: u64,
        wall_s: f64,
    ) -> Self {
        ResultLine {
            case: case.into(),
            metric: metric.into(),
            value,
            tol,
            elements,
            steps,
            wall_s,
            backend: backend.kind().name().into(),
            precision: backend.precision().into(),
        }
    }

    /// Whether the value is within tolerance.
    pub fn pass(&self) -> bool {
        self.value.is_finite() && self.value <= self.tol
    }
}

impl fmt::Display for ResultLine {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Plain decimals for ordinary tolerances (0.03), exponent form for tiny ones (1e-12).
        let tol = if self.tol != 0.0 && self.tol.abs() < 1e-3 {
            format!("{:e}", self.tol)
        } else {
            format!("{}", self.tol)
        };
        write!(
            f,
            "RESULT case={} metric={} value={:.6e} tol={} pass={} elements={} steps={} wall_s={:.3} backend={} precision={}",
            self.case,
            self.metric,
            self.value,
            tol,
            self.pass(),
            self.elements,
            self.steps,
            self.wall_s,
            self.backend,
            self.precision
        )
    }
}

/// Ends a validation example: prints its RESULT lines last and exits with status 0 when
/// all pass, 2 when one fails, and 1 (after printing the error) when the run failed.
pub fn finish(result: Result<Vec<ResultLine>, Box<dyn std::error::Error>>) -> ! {
    match result {
        Ok(lines) => {
            for l in &lines {
                println!("{l}");
            }
            std::process::exit(if lines.iter().all(ResultLine::pass) {
                0
            } else {
                2
            })
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1)
        }
    }
}

/// `out/<case>` under the current directory, created if missing.
pub fn out_dir(case: &str) -> std::io::Result<PathBuf> {
    let dir = PathBuf::from("out").join(case);
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}

/// Errors of the validation scenes.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// Mesh error.
    #[error(transparent)]
    Mesh(#[from] pcdc_mesh::MeshError),
    /// Compute error.
    #[error(transparent)]
    Compute(#[from] pcdc_compute::ComputeError),
    /// Mechanics error.
    #[error(transparent)]
    Mech(#[from] pcdc_mech::MechError),
    /// Cohesive error.
    #[error(transparent)]
    Cohesive(#[from] pcdc_cohesive::CohesiveError),
    /// A bolt error.
    #[error(transparent)]
    Bolt(#[from] pcdc_bolt::BoltError),
    /// Plot error.
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
    /// Input/output error.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// The scene could not measure what it compares (e.g. a probe saw no wave front).
    #[error("{0}")]
    Measurement(String),
}
