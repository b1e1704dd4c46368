//! Histories: probes sampled during a run and written to CSV.

use std::io::Write;
use std::path::Path;

use pcdc_mesh::Dim;

use crate::{ComputeError, Simulation};

/// A user function sampled by [`Probe::Custom`].
pub type ProbeFn<D> = Box<dyn Fn(&Simulation<D>) -> f64 + Send + Sync>;

/// A quantity sampled by a [`History`].
pub enum Probe<D: Dim> {
    /// Simulation time (s).
    Time,
    /// Displacement component `comp` of node `node` (m).
    NodeDisplacement {
        /// Node index.
        node: u32,
        /// Component (0 = x, 1 = y, 2 = z).
        comp: usize,
    },
    /// Velocity component of a node (m/s).
    NodeVelocity {
        /// Node index.
        node: u32,
        /// Component.
        comp: usize,
    },
    /// Component `comp` of a field at entity `index`.
    Field {
        /// Field name.
        field: String,
        /// Entity index.
        index: u32,
        /// Component within the entity.
        comp: usize,
    },
    /// Kinetic energy (J).
    KineticEnergy,
    /// Stored (e.g. strain) energy (J).
    StoredEnergy,
    /// Any quantity computed from the simulation.
    Custom(ProbeFn<D>),
}

/// Probes sampled into columns, written as CSV (one header line, one row per sample).
pub struct History<D: Dim> {
    columns: Vec<(String, Probe<D>)>,
    rows: Vec<Vec<f64>>,
}

impl<D: Dim> Default for History<D> {
    fn default() -> Self {
        History {
            columns: Vec::new(),
            rows: Vec::new(),
        }
    }
}

impl<D: Dim> History<D> {
    /// An empty history.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a column.
    pub fn probe(mut self, name: impl Into<String>, probe: Probe<D>) -> Self {
        self.columns.push((name.into(), probe));
        self
    }

    /// Checks probes against the simulation (node and entity indices, field names).
    pub fn validate(&self, sim: &Simulation<D>) -> Result<(), ComputeError> {
        for (name, p) in &self.columns {
            match p {
                Probe::NodeDisplacement { node, comp } | Probe::NodeVelocity { node, comp }
                    if *node as usize >= sim.n_nodes() || *comp >= D::D =>
                {
                    return Err(ComputeError::param(
                        format!("probe '{name}'"),
                        format!("node {node} comp {comp}"),
                        format!(
                            "out of range ({} nodes, {} components)",
                            sim.n_nodes(),
                            D::D
                        ),
                    ));
                }
                Probe::Field { field, index, comp } => {
                    let id = sim.state.fields.id(field)?;
                    let spec = sim.state.fields.spec(id);
                    let n = sim.state.fields.get(id).len() / spec.components.max(1);
                    if *index as usize >= n || *comp >= spec.components {
                        return Err(ComputeError::param(
                            format!("probe '{name}'"),
                            format!("index {index} comp {comp}"),
                            format!(
                                "field '{field}' has {n} entities x {} components",
                                spec.components
                            ),
                        ));
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// Samples every probe now (the probes are checked at the first sample).
    pub fn sample(&mut self, sim: &Simulation<D>) -> Result<(), ComputeError> {
        if self.rows.is_empty() {
            self.validate(sim)?;
        }
        let d = D::D;
        let mut row = Vec::with_capacity(self.columns.len());
        for (_, p) in &self.columns {
            row.push(match p {
                Probe::Time => sim.state.time,
                Probe::NodeDisplacement { node, comp } => sim.state.u[*node as usize * d + comp],
                Probe::NodeVelocity { node, comp } => sim.state.v[*node as usize * d + comp],
                Probe::Field { field, index, comp } => {
                    let id = sim.state.fields.id(field)?;
                    let c = sim.state.fields.spec(id).components;
                    sim.state.fields.get(id)[*index as usize * c + comp]
                }
                Probe::KineticEnergy => sim.kinetic_energy(),
                Probe::StoredEnergy => sim.stored_energy(),
                Probe::Custom(f) => f(sim),
            });
        }
        self.rows.push(row);
        Ok(())
    }

    /// Column names.
    pub fn names(&self) -> Vec<&str> {
        self.columns.iter().map(|c| c.0.as_str()).collect()
    }

    /// Sampled values of column `i`.
    pub fn column(&self, i: usize) -> Vec<f64> {
        self.rows.iter().map(|r| r[i]).collect()
    }

    /// Sampled rows.
    pub fn rows(&self) -> &[Vec<f64>] {
        &self.rows
    }

    /// Writes the history as CSV (creating parent directories).
    pub fn write_csv(&self, path: impl AsRef<Path>) -> Result<(), ComputeError> {
        let path = path.as_ref();
        let io = |source| ComputeError::Io {
            path: path.display().to_string(),
            source,
        };
        if let Some(dir) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(io)?;
        }
        let mut w = std::io::BufWriter::new(std::fs::File::create(path).map_err(io)?);
        writeln!(w, "{}", self.names().join(",")).map_err(io)?;
        for r in &self.rows {
            let line: Vec<String> = r.iter().map(|v| format!("{v:e}")).collect();
            writeln!(w, "{}", line.join(",")).map_err(io)?;
        }
        w.flush().map_err(io)
    }
}
