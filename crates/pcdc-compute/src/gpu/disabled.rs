//! Without the `gpu` feature no simulation holds a device run: `GpuRun` has no values,
//! so every device branch of the simulation is statically dead and needs no cfg.

use pcdc_mesh::Dim;

use crate::{ComputeError, Simulation};

/// The device state of a simulation; uninhabited in builds without the `gpu` feature.
pub(crate) enum GpuRun {}

impl GpuRun {
    pub(crate) fn run<D: Dim>(
        &mut self,
        _: &mut Simulation<D>,
        _: u64,
    ) -> Result<(), ComputeError> {
        match *self {}
    }

    pub(crate) fn evaluate<D: Dim>(
        &mut self,
        _: &mut Simulation<D>,
        _: bool,
    ) -> Result<Option<Vec<f64>>, ComputeError> {
        match *self {}
    }

    pub(crate) fn bytes_per_step(&self) -> u64 {
        match *self {}
    }

    pub(crate) fn kernel_labels(&self) -> Vec<String> {
        match *self {}
    }
}
