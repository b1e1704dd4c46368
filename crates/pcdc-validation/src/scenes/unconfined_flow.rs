//! Validation scene 10: steady unconfined flow with a free surface, Dupuit (manual 7.5.6).
//!
//! A block L = 8 m long and 4 m high (the size of OpenFDEM's version of the test) whose
//! every joint is a channel of the intact rock, calibrated to a rock mass permeability
//! k = 1e-14 m² ([`Hydro::rock_permeability`]); water, gravity 9.81 m/s², flow only.
//! Water levels h_l = 4 m on the upstream face x = 0 and h_r = 1 m on the downstream
//! face x = L (hydrostatic below them, no condition above, [`Hydro::head`]); the base
//! and the top are closed. The block starts dry and fills. At steady state the free
//! surface follows the Dupuit parabola (Harr 1962; manual eq. 90 corrected, the printed
//! form drops the x)
//!
//! y(x) = sqrt(h_l² − (h_l² − h_r²) x / L),
//!
//! and the discharge per unit thickness is Q = K (h_l² − h_r²)/(2 L), K = k ρ_f g / μ_d
//! (the Dupuit–Charny formula, exact for the full two-dimensional problem).
//!
//! The free surface is read along each vertical line of flow nodes from the highest
//! node under pressure, extrapolated hydrostatically: y = z + p/(ρ_f g) (the manual's
//! "the free surface lies above the node"). The error is the largest |y − y_Dupuit| / h_l
//! over the lines; tolerance 5 %. The discharge error is reported beside it.
//!
//! Measured (`cargo run --release --example unconfined_flow`, 0.5, 0.25 and 0.125 m):
//! the surface is off by 4.5, 5.2 and 5.0 % of h_l, largest near the outlet, and does not
//! shrink with the element: the computed surface lies above the parabola all along, as
//! the two-dimensional solution does (Dupuit neglects vertical flow and the seepage face
//! above h_r), so this tolerance is met with no margin and the middle size misses it by
//! 0.2 %. The discharge, for which the closed form is exact, is off by 10, 5 and 2.5 %:
//! exactly h (h_l − h_r)/(h_l² − h_r²), the Dupuit–Charny discharge with both water
//! levels raised by half an element (the wet node on the free surface conducts over
//! half an element above it), first order in h.
//!
//! The fluid bulk modulus is scaled by 1e-5 ([`Hydro::bulk_modulus_scale`]): the steady
//! state does not depend on it (a test runs two scales), and at full K_f the filling of
//! the unsaturated network would be some K_f/(ρ_f g h_l) ≈ 5e4 times slower than the
//! compressive transient that sets the step. Scaled 1e-4 and 1e-5 gave the same
//! printed errors in 6 times fewer steps for 1e-5.

use std::time::Instant;

use pcdc_compute::{Backend, Simulation};
use pcdc_hydro::fields::{FLOW_BALANCE, FLOW_NODES, FLOW_PRESSURE, FLOW_SATURATION};
use pcdc_hydro::{mass_balance, Aperture, Coupling, FlowModel, Fluid, Hydro};
use pcdc_mesh::{builders, split_nodes, Range};

use crate::report::SceneError;

/// Tolerance on the free-surface error, as a fraction of h_l.
pub const TOL: f64 = 0.05;
/// Block length (m).
pub const LENGTH: f64 = 8.0;
/// Block height (m).
pub const HEIGHT: f64 = 4.0;
/// Upstream water level (m).
pub const H_L: f64 = 4.0;
/// Downstream water level (m).
pub const H_R: f64 = 1.0;
/// Gravity (m/s²).
pub const G: f64 = 9.81;
/// Rock mass permeability (m²) of the intact channels.
pub const PERMEABILITY: f64 = 1e-14;
/// The factor on K_f (steady state: no effect on the result).
pub const BULK_SCALE: f64 = 1e-5;
const MAX_STEPS: u64 = 5_000_000;

/// Scene parameters.
#[derive(Clone, Debug)]
pub struct Params {
    /// Element size (m).
    pub size: f64,
    /// The factor on K_f ([`BULK_SCALE`] by default).
    pub bulk_scale: f64,
}

/// The element sizes of the report and the example (m).
pub const SIZES: [f64; 3] = [0.5, 0.25, 0.125];

impl Params {
    /// Full size (12.5 cm elements).
    pub fn full() -> Self {
        Params::sized(0.125)
    }
    /// Reduced size for tests (50 cm elements).
    pub fn reduced() -> Self {
        Params::sized(0.5)
    }
    /// Elements of `size` (m), K_f scaled by [`BULK_SCALE`].
    pub fn sized(size: f64) -> Self {
        Params {
            size,
            bulk_scale: BULK_SCALE,
        }
    }
}

/// Outcome of a run.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Largest |y − y_Dupuit| / h_l over the vertical lines.
    pub error: f64,
    /// Relative error of the steady discharge against Q = K (h_l² − h_r²)/(2 L).
    pub discharge_error: f64,
    /// Elements.
    pub elements: usize,
    /// Flow channels.
    pub channels: usize,
    /// Steps to steady state.
    pub steps: u64,
    /// Physical time to steady state (s).
    pub time: f64,
    /// Wall time (s).
    pub wall_s: f64,
    /// Mass-balance residual relative to the through-flow.
    pub balance: f64,
    /// x (m) and free-surface height y (m) of every vertical line.
    pub x: Vec<f64>,
    /// See `x`.
    pub y: Vec<f64>,
}

/// The Dupuit free surface y(x) (m), eq. 90 corrected.
pub fn exact(x: f64) -> f64 {
    (H_L * H_L - (H_L * H_L - H_R * H_R) * x / LENGTH).sqrt()
}

/// The Dupuit–Charny discharge per unit thickness (m²/s).
pub fn discharge(fluid: &Fluid) -> f64 {
    let conductivity = PERMEABILITY * fluid.density * G / fluid.dynamic_viscosity();
    conductivity * (H_L * H_L - H_R * H_R) / (2.0 * LENGTH)
}

/// The 2D block on `backend`.
pub fn run(backend: &Backend, params: &Params) -> Result<Outcome, SceneError> {
    let p = params;
    let size = p.size;
    let start = Instant::now();
    let mesh = builders::rectangle(0.0, 0.0, LENGTH, HEIGHT, p.size)?;
    let elements = mesh.n_elements();
    let mesh = split_nodes(&mesh, &Range::All)?;
    let fluid = Fluid::water();
    let model = FlowModel::new(fluid, Aperture::new(1e-5, 1e-9, 1e-3)?);
    let eps = 1e-3 * p.size;
    let left = Range::rect(-eps, -eps, eps, HEIGHT + eps);
    let right = Range::rect(LENGTH - eps, -eps, LENGTH + eps, HEIGHT + eps);
    let flow = Hydro::new(model)
        .coupling(Coupling::FlowOnly)
        .gravity([0.0, -G, 0.0])
        .rock_permeability(PERMEABILITY)
        .bulk_modulus_scale(p.bulk_scale)
        .initially_dry()
        .head(left, H_L)
        .head(right, H_R);
    let mut sim = Simulation::builder(mesh, backend.clone())
        .physics(flow)
        .build()?;
    let set = sim
        .entity_set(FLOW_NODES)
        .ok_or_else(|| SceneError::Measurement("no flow nodes".into()))?;
    let xy: Vec<[f64; 2]> = (0..set.len())
        .map(|l| {
            let x = sim.mesh().node(set.entity(l)[0] as usize);
            [x[0], x[1]]
        })
        .collect();
    let outlet: Vec<usize> = (0..xy.len()).filter(|&l| xy[l][0] > LENGTH - eps).collect();
    let rho_g = fluid.density * G;
    // Steady when, over a window, no pressure moves by more than `quiet` ρ g h_l and
    // no saturation by more than `quiet` (1e-9; in f32 1e-5, above its rounding noise).
    let quiet = match backend.precision_kind() {
        pcdc_compute::Precision::F64 => 1e-9,
        _ => 1e-5,
    };
    let window = 1000;
    let mut last_p = sim.field(FLOW_PRESSURE)?.to_vec();
    let mut last_s = sim.field(FLOW_SATURATION)?.to_vec();
    let outflow = |sim: &Simulation<_>| -> Result<f64, SceneError> {
        let b = sim.field(FLOW_BALANCE)?;
        Ok(-outlet.iter().map(|&l| b[4 * l + 2]).sum::<f64>())
    };
    let mut last_out = (outflow(&sim)?, 0.0);
    let (q_num, steps) = loop {
        sim.run(window)?;
        let steps = sim.kinematics().step;
        let (p, s) = (sim.field(FLOW_PRESSURE)?, sim.field(FLOW_SATURATION)?);
        let change = |a: &[f64], b: &[f64]| {
            a.iter()
                .zip(b)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max)
        };
        let (dp, ds) = (change(p, &last_p), change(s, &last_s));
        last_p.copy_from_slice(p);
        last_s.copy_from_slice(s);
        let (out, t) = (outflow(&sim)?, sim.kinematics().time);
        let q_out = (out - last_out.0) / (t - last_out.1);
        last_out = (out, t);
        if dp <= quiet * rho_g * H_L && ds <= quiet {
            break (q_out, steps);
        }
        if steps >= MAX_STEPS {
            return Err(SceneError::Measurement(format!(
                "no steady state after {steps} steps (dp {dp:e} Pa, ds {ds:e}, size {size})"
            )));
        }
    };
    let pressure = sim.field(FLOW_PRESSURE)?;
    // Each vertical line: the highest node under pressure, extrapolated hydrostatically.
    let columns = (LENGTH / p.size).round() as usize;
    let mut line = vec![(f64::NEG_INFINITY, 0.0); columns + 1];
    for (l, &[x, z]) in xy.iter().enumerate() {
        let i = (x / LENGTH * columns as f64).round() as usize;
        if pressure[l] > 0.0 && z > line[i].0 {
            line[i] = (z, z + pressure[l] / rho_g);
        }
    }
    let x: Vec<f64> = (0..=columns)
        .map(|i| LENGTH * i as f64 / columns as f64)
        .collect();
    let y: Vec<f64> = line.iter().map(|&(_, y)| y).collect();
    let error = x
        .iter()
        .zip(&y)
        .map(|(&x, &y)| (y - exact(x)).abs() / H_L)
        .fold(0.0, f64::max);
    let b = mass_balance(&sim)?;
    let channels = sim
        .entity_set(pcdc_hydro::fields::FLOW_CHANNELS)
        .map_or(0, |s| s.len());
    Ok(Outcome {
        error,
        discharge_error: (q_num - discharge(&fluid)).abs() / discharge(&fluid),
        elements,
        channels,
        steps,
        time: sim.kinematics().time,
        wall_s: start.elapsed().as_secs_f64(),
        balance: b.relative(),
        x,
        y,
    })
}
