//! Output of the bolts: a `.vtu`/`.pvd` series of line cells (one per segment, at the
//! bolt nodes' current positions) that ParaView opens beside the solid's series, and the
//! axial force along a bolt for CSV histories.

use std::path::Path;

use pcdc_compute::{ComputeError, Simulation};
use pcdc_mesh::vtu::{Cells, DataArray, PvdSeries, VTK_LINE};
use pcdc_mesh::Dim;

use crate::fields::*;

fn sets<D: Dim>(
    sim: &Simulation<D>,
) -> Result<(&pcdc_compute::EntitySet, &pcdc_compute::EntitySet), ComputeError> {
    let missing =
        |name: &str| ComputeError::param("bolts", name, "the simulation composes no bolts");
    Ok((
        sim.entity_set(BOLT_NODES)
            .ok_or_else(|| missing(BOLT_NODES))?,
        sim.entity_set(BOLT_SEGMENTS)
            .ok_or_else(|| missing(BOLT_SEGMENTS))?,
    ))
}

/// A `.pvd` series of the bolts: points are bolt nodes (grout force `grout_force` N,
/// `slip` m, `host_element`: the element the node is grouted to), cells are segments (`axial_force` N, `plastic_elongation` m, `state`: 0
/// elastic, 1 yielded in tension, 2 in compression, 3 broken).
pub struct BoltSeries {
    series: PvdSeries,
}

impl BoltSeries {
    /// A series `<dir>/<base_name>.pvd` (files `<base_name>_NNNNNN.vtu`).
    pub fn new(dir: impl AsRef<Path>, base_name: &str) -> Result<Self, ComputeError> {
        Ok(BoltSeries {
            series: PvdSeries::new(dir, base_name)?,
        })
    }

    /// Writes the bolts' current state as the next step.
    pub fn write_step<D: Dim>(&mut self, sim: &Simulation<D>) -> Result<(), ComputeError> {
        let (nodes, segments) = sets(sim)?;
        let d = D::D;
        let x = sim.positions();
        let mut points = Vec::with_capacity(nodes.len() * d);
        for &n in nodes.nodes() {
            points.extend_from_slice(&x[n as usize * d..(n as usize + 1) * d]);
        }
        let first = nodes.nodes().first().copied().unwrap_or(0);
        let conn: Vec<u32> = segments.nodes().iter().map(|&n| n - first).collect();
        let cells = Cells {
            points: &points,
            connectivity: &conn,
            nodes_per_cell: 2,
            cell_type: VTK_LINE,
        };
        let state: Vec<i32> = sim.field(BOLT_STATE)?.iter().map(|&s| s as i32).collect();
        let host: Vec<i32> = sim.field(BOLT_HOST)?.iter().map(|&e| e as i32).collect();
        self.series.write_cells_step::<D>(
            sim.kinematics().time,
            &cells,
            &[
                DataArray::Scalar {
                    name: "grout_force",
                    values: sim.field(BOLT_GROUT_FORCE)?,
                },
                DataArray::Scalar {
                    name: "slip",
                    values: sim.field(BOLT_SLIP)?,
                },
                DataArray::Int {
                    name: "host_element",
                    values: &host,
                },
            ],
            &[
                DataArray::Scalar {
                    name: "axial_force",
                    values: sim.field(BOLT_AXIAL_FORCE)?,
                },
                DataArray::Scalar {
                    name: "plastic_elongation",
                    values: sim.field(BOLT_PLASTIC_ELONGATION)?,
                },
                DataArray::Int {
                    name: "state",
                    values: &state,
                },
            ],
        )?;
        Ok(())
    }

    /// Path of the `.pvd` file.
    pub fn pvd_path(&self) -> std::path::PathBuf {
        self.series.pvd_path()
    }
}

/// The axial force along bolt `b` of `bolts` (as composed in `sim`): per segment, the
/// distance of its midpoint from the head (m, reference) and its axial force (N; per
/// unit thickness in 2D). For a CSV history: one row per output time.
pub fn axial_force_profile<D: Dim>(
    sim: &Simulation<D>,
    bolts: &crate::Bolts,
    b: usize,
) -> Result<Vec<(f64, f64)>, ComputeError> {
    let bolt = bolts
        .bolts()
        .get(b)
        .ok_or_else(|| ComputeError::param("bolt index", b, "no such bolt"))?;
    let f = sim.field(BOLT_AXIAL_FORCE)?;
    let range = bolts.segment_range(b).unwrap_or(0..0);
    if range.end > f.len() {
        return Err(ComputeError::param(
            "bolts",
            bolt.name(),
            "not the bolts composed in this simulation",
        ));
    }
    Ok(range
        .enumerate()
        .map(|(i, s)| (bolt.arc_length(i) + 0.5 * bolt.segment_length(i), f[s]))
        .collect())
}

/// A CSV history of the axial force along one bolt: a header with every segment's
/// distance from the head (m), then one row per call of [`AxialForceCsv::record`]: the
/// time (s) and every segment's axial force (N; per unit thickness in 2D).
pub struct AxialForceCsv {
    file: std::io::BufWriter<std::fs::File>,
    path: std::path::PathBuf,
    bolt: usize,
}

impl AxialForceCsv {
    /// Creates `path` for bolt `b` of `bolts` (as composed in `sim`) and writes the header.
    pub fn new<D: Dim>(
        path: impl AsRef<Path>,
        sim: &Simulation<D>,
        bolts: &crate::Bolts,
        b: usize,
    ) -> Result<Self, ComputeError> {
        use std::io::Write;
        let path = path.as_ref().to_path_buf();
        let io = |e: std::io::Error| ComputeError::Io {
            path: path.display().to_string(),
            source: e,
        };
        let profile = axial_force_profile(sim, bolts, b)?;
        let mut file = std::io::BufWriter::new(std::fs::File::create(&path).map_err(io)?);
        let header: Vec<String> = profile
            .iter()
            .map(|(x, _)| format!("F_at_{x:.6}_m"))
            .collect();
        writeln!(file, "time_s,{}", header.join(",")).map_err(io)?;
        Ok(AxialForceCsv {
            file,
            path,
            bolt: b,
        })
    }

    /// Appends the current time and axial forces.
    pub fn record<D: Dim>(
        &mut self,
        sim: &Simulation<D>,
        bolts: &crate::Bolts,
    ) -> Result<(), ComputeError> {
        use std::io::Write;
        let io = |e: std::io::Error| ComputeError::Io {
            path: self.path.display().to_string(),
            source: e,
        };
        let profile = axial_force_profile(sim, bolts, self.bolt)?;
        let row: Vec<String> = profile.iter().map(|(_, f)| format!("{f:e}")).collect();
        writeln!(self.file, "{:e},{}", sim.kinematics().time, row.join(",")).map_err(io)?;
        self.file.flush().map_err(io)
    }
}
