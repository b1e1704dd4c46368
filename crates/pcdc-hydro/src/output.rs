//! Output of the flow network for ParaView: its own `.vtu`/`.pvd` series (line cells in
//! 2D, triangle cells in 3D, at the flow nodes' current positions) with pressure,
//! peak pressure, saturation and content on the points and aperture and flux on the cells. The solid's
//! series can carry the pressure of every mesh node from
//! [`pcdc_compute::names::PORE_PRESSURE`].

use std::collections::HashMap;
use std::path::Path;

use pcdc_compute::{ComputeError, Simulation};
use pcdc_mesh::vtu::{Cells, DataArray, PvdSeries, VTK_LINE, VTK_TRIANGLE};
use pcdc_mesh::Dim;

use crate::fields::{
    CHANNEL_APERTURE, CHANNEL_FLUX, FLOW_BALANCE, FLOW_CHANNELS, FLOW_NODES, FLOW_PEAK_PRESSURE,
    FLOW_PRESSURE, FLOW_SATURATION, FLOW_STORED,
};

/// The network's points (current positions of the flow nodes, stride D) and its
/// channels' connectivity in flow-node indices.
pub fn network_cells<D: Dim>(sim: &Simulation<D>) -> Result<(Vec<f64>, Vec<u32>), ComputeError> {
    let missing = |name: &str| {
        ComputeError::param(
            "flow network",
            name,
            "the simulation composes no hydro physics",
        )
    };
    let nodes = sim
        .entity_set(FLOW_NODES)
        .ok_or_else(|| missing(FLOW_NODES))?;
    let channels = sim
        .entity_set(FLOW_CHANNELS)
        .ok_or_else(|| missing(FLOW_CHANNELS))?;
    let joints = sim.mesh().interfaces();
    let of_master: HashMap<u32, u32> = nodes
        .nodes()
        .iter()
        .enumerate()
        .map(|(l, &n)| (joints.master_of(n), l as u32))
        .collect();
    let positions = sim.positions();
    let d = D::D;
    let mut points = Vec::with_capacity(nodes.len() * d);
    for &n in nodes.nodes() {
        points.extend_from_slice(&positions[n as usize * d..(n as usize + 1) * d]);
    }
    let mut conn = Vec::with_capacity(channels.nodes().len());
    for &n in channels.nodes() {
        let l = of_master
            .get(&joints.master_of(n))
            .ok_or_else(|| ComputeError::param("flow channel node", n, "has no flow node"))?;
        conn.push(*l);
    }
    Ok((points, conn))
}

/// A `.pvd` series of the flow network.
pub struct NetworkSeries {
    series: PvdSeries,
}

impl NetworkSeries {
    /// A series `<dir>/<base_name>.pvd` (files `<base_name>_NNNNNN.vtu`).
    pub fn new(dir: impl AsRef<Path>, base_name: &str) -> Result<Self, ComputeError> {
        Ok(NetworkSeries {
            series: PvdSeries::new(dir, base_name)?,
        })
    }

    /// Writes the network's current state as the next step of the series.
    pub fn write_step<D: Dim>(&mut self, sim: &Simulation<D>) -> Result<(), ComputeError> {
        self.write_step_with(sim, &[], &[])
    }

    /// [`NetworkSeries::write_step`] with more arrays on the flow nodes (`points`) and
    /// channels (`cells`) from other physics, e.g. the fluid temperature of
    /// `pcdc_thermal::output::fluid_point_arrays`.
    pub fn write_step_with<D: Dim>(
        &mut self,
        sim: &Simulation<D>,
        points: &[DataArray<'_>],
        cells: &[DataArray<'_>],
    ) -> Result<(), ComputeError> {
        let (extra_points, extra_cells) = (points, cells);
        let (points, conn) = network_cells(sim)?;
        let cells = Cells {
            points: &points,
            connectivity: &conn,
            nodes_per_cell: D::NODES_PER_FACE,
            cell_type: if D::D == 2 { VTK_LINE } else { VTK_TRIANGLE },
        };
        let p = sim.field(FLOW_PRESSURE)?;
        let peak = sim.field(FLOW_PEAK_PRESSURE)?;
        let s = sim.field(FLOW_SATURATION)?;
        let (dw, bal) = (sim.field(FLOW_STORED)?, sim.field(FLOW_BALANCE)?);
        let w: Vec<f64> = dw.iter().enumerate().map(|(l, x)| bal[4 * l] + x).collect();
        let a = sim.field(CHANNEL_APERTURE)?;
        let q = sim.field(CHANNEL_FLUX)?;
        let mut point_arrays = vec![
            DataArray::Scalar {
                name: "pressure",
                values: p,
            },
            DataArray::Scalar {
                name: "peak_pressure",
                values: peak,
            },
            DataArray::Scalar {
                name: "saturation",
                values: s,
            },
            DataArray::Scalar {
                name: "content",
                values: &w,
            },
        ];
        point_arrays.extend_from_slice(extra_points);
        let mut cell_arrays = vec![
            DataArray::Scalar {
                name: "aperture",
                values: a,
            },
            DataArray::Vector {
                name: "flux",
                values: q,
            },
        ];
        cell_arrays.extend_from_slice(extra_cells);
        self.series.write_cells_step::<D>(
            sim.kinematics().time,
            &cells,
            &point_arrays,
            &cell_arrays,
        )?;
        Ok(())
    }

    /// Path of the `.pvd` file.
    pub fn pvd_path(&self) -> std::path::PathBuf {
        self.series.pvd_path()
    }
}
