//! Output of the heat: VTU steps for ParaView, the energy balance.
//!
//! A heat-only run writes its own steps with [`write_step`]. A coupled run writes the
//! mechanics' step (`pcdc_mech::output::write_step_with`) and hands it the arrays of
//! [`point_arrays`]/[`cell_arrays`] (temperature and heat supplied on the nodes, heat
//! flux on the elements). Histories of a node's temperature go through
//! `pcdc_compute::History` with `Probe::Field { field: "temperature", .. }`.

use std::path::PathBuf;

use pcdc_compute::{names, ComputeError, Simulation};
use pcdc_mesh::vtu::{DataArray, PvdSeries};
use pcdc_mesh::Dim;

use crate::{
    heat_content, FLUID_HEAT_BALANCE, FLUID_HEAT_CAPACITY, FLUID_TEMPERATURE, HEAT_CAPACITY,
    HEAT_FLUX, HEAT_SUPPLIED,
};

/// The energy balance of the heat since the start (J; J/m in 2D):
/// Σ C_l (T_l − T_l⁰) against Σ supplied_l.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnergyBalance {
    /// Change of the heat content Σ C_l (T_l − T_l⁰).
    pub stored: f64,
    /// Heat supplied through the faces and the temperature conditions.
    pub supplied: f64,
}

impl EnergyBalance {
    /// |stored − supplied| over the larger of the two magnitudes (0 when both are 0).
    pub fn relative(&self) -> f64 {
        let scale = self.stored.abs().max(self.supplied.abs());
        if scale == 0.0 {
            0.0
        } else {
            (self.stored - self.supplied).abs() / scale
        }
    }
}

/// The balance of a simulation with the thermal physics, against the temperatures
/// `initial` it started from (node order: keep a copy of the `temperature` field after
/// the build). With fluid heat ([`crate::Thermal::fluid`]) the fluid's heat content
/// and [`FLUID_HEAT_BALANCE`] are included (the fluid's start is kept in that field).
pub fn energy_balance<D: Dim>(
    sim: &Simulation<D>,
    initial: &[f64],
) -> Result<EnergyBalance, ComputeError> {
    let cap = sim.field(HEAT_CAPACITY)?;
    let t = sim.field(names::TEMPERATURE)?;
    if initial.len() != t.len() {
        return Err(ComputeError::param(
            "initial temperatures",
            initial.len(),
            format!("must give one value per node ({})", t.len()),
        ));
    }
    let mut stored = heat_content(cap, t) - heat_content(cap, initial);
    let mut supplied: f64 = sim.field(HEAT_SUPPLIED)?.iter().sum();
    if let Ok(tf) = sim.field(FLUID_TEMPERATURE) {
        let bal = sim.field(FLUID_HEAT_BALANCE)?;
        stored += heat_content(sim.field(FLUID_HEAT_CAPACITY)?, tf);
        for b in bal.chunks_exact(4) {
            stored -= b[0];
            supplied += b[1] + b[2] + b[3];
        }
    }
    Ok(EnergyBalance { stored, supplied })
}

/// The node arrays: `temperature` (K or °C) and `heat_supplied` (J).
pub fn point_arrays<D: Dim>(sim: &Simulation<D>) -> Result<[DataArray<'_>; 2], ComputeError> {
    Ok([
        DataArray::Scalar {
            name: "temperature",
            values: sim.field(names::TEMPERATURE)?,
        },
        DataArray::Scalar {
            name: "heat_supplied",
            values: sim.field(HEAT_SUPPLIED)?,
        },
    ])
}

/// The flow-node array `fluid_temperature` (K or °C), for
/// `pcdc_hydro::output::NetworkSeries::write_step_with`.
pub fn fluid_point_arrays<D: Dim>(sim: &Simulation<D>) -> Result<[DataArray<'_>; 1], ComputeError> {
    Ok([DataArray::Scalar {
        name: "fluid_temperature",
        values: sim.field(FLUID_TEMPERATURE)?,
    }])
}

/// The element array: `heat_flux` (W/m², vector).
pub fn cell_arrays<D: Dim>(sim: &Simulation<D>) -> Result<[DataArray<'_>; 1], ComputeError> {
    Ok([DataArray::Vector {
        name: "heat_flux",
        values: sim.field(HEAT_FLUX)?,
    }])
}

/// Writes one step of a heat-only run to `series` (reference positions; the
/// arrays of [`point_arrays`] and [`cell_arrays`]); returns the file written.
pub fn write_step<D: Dim>(
    sim: &Simulation<D>,
    series: &mut PvdSeries,
) -> Result<PathBuf, ComputeError> {
    let points = point_arrays(sim)?;
    let cells = cell_arrays(sim)?;
    Ok(series.write_step(sim.kinematics().time, sim.mesh(), None, &points, &cells)?)
}
