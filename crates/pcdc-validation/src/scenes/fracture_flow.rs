//! Validation scene 11: transient flow along one open fracture (manual 7.5.7).
//!
//! A straight fracture of aperture δ = 0.1 mm and length L = 1 m along the mid-plane of a
//! rigid, impermeable specimen (flow only: the fracture's joints are the only channels;
//! 2D: a 1 × 0.2 m rectangle, fracture y = 0; 3D: a 1 × 0.2 × 0.2 m cuboid of
//! tetrahedra, fracture plane z = 0), water (ρ_f = 1000 kg/m³, K_f = 2.2 GPa,
//! μ_k = 1e-6 m²/s), initially at p = 0; p_A = 1 MPa is held at x = 0 from t = 0 and the
//! end x = L is closed. With D = K_f δ²/(12 μ_d), T = D t/L² and ξ = 1 − x/L
//! (manual eq. 91–92 corrected):
//!
//! p(x, t) = p_A [1 + (4/π) Σ_{n≥0} (−1)^{n+1}/(2n+1) exp(−(2n+1)² π² T/4) cos((2n+1) π ξ/2)].
//!
//! The error is the largest |p − p_exact| / p_A at x = L/2 and x = L over the sample
//! times T = 0.05, 0.1, 0.2, 0.5, 1; tolerance 5 %.

use std::time::Instant;

use pcdc_compute::{Backend, Simulation};
use pcdc_hydro::fields::{FLOW_NODES, FLOW_PRESSURE};
use pcdc_hydro::{mass_balance, Aperture, Coupling, FlowModel, Fluid, Hydro};
use pcdc_mesh::{builders, split_nodes, Dim, Mesh, Range};

use crate::report::SceneError;

/// Tolerance on the pressure error, as a fraction of p_A.
pub const TOL: f64 = 0.05;
/// Fracture length (m).
pub const LENGTH: f64 = 1.0;
/// Fracture aperture (m).
pub const APERTURE: f64 = 1e-4;
/// Pressure held at x = 0 (Pa).
pub const P_A: f64 = 1e6;
/// The dimensionless times compared.
pub const SAMPLES: [f64; 5] = [0.05, 0.1, 0.2, 0.5, 1.0];

/// Scene parameters.
#[derive(Clone, Debug)]
pub struct Params {
    /// Channel (element) size along the fracture (m).
    pub size: f64,
}

impl Params {
    /// Full size (1.25 cm channels, 80 along the fracture).
    pub fn full() -> Self {
        Params { size: 0.0125 }
    }
    /// Reduced size for tests (5 cm channels).
    pub fn reduced() -> Self {
        Params { size: 0.05 }
    }
}

/// Outcome of a run.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Largest |p − p_exact| / p_A over the samples.
    pub error: f64,
    /// Elements of the specimen mesh.
    pub elements: usize,
    /// Flow channels.
    pub channels: usize,
    /// Steps run.
    pub steps: u64,
    /// Wall time (s).
    pub wall_s: f64,
    /// Mass-balance residual relative to the inflow.
    pub balance: f64,
    /// Dimensionless time of every recorded step.
    pub t: Vec<f64>,
    /// p / p_A at x = L/2.
    pub p_mid: Vec<f64>,
    /// p / p_A at x = L.
    pub p_end: Vec<f64>,
}

/// The fluid: water.
pub fn fluid() -> Fluid {
    Fluid::water()
}

/// The fracture's diffusivity D = K_f δ² / (12 μ_d) (m²/s).
pub fn diffusivity() -> f64 {
    let f = fluid();
    f.bulk_modulus * APERTURE * APERTURE / (12.0 * f.dynamic_viscosity())
}

/// p / p_A at distance `x` from the held end at dimensionless time `t_dimless` (eq. 91–92
/// corrected).
pub fn exact(x: f64, t_dimless: f64) -> f64 {
    if t_dimless <= 0.0 {
        return if x == 0.0 { 1.0 } else { 0.0 };
    }
    let xi = 1.0 - x / LENGTH;
    let pi = std::f64::consts::PI;
    let mut sum = 0.0;
    for n in 0..400 {
        let m = (2 * n + 1) as f64;
        let term = (-m * m * pi * pi * t_dimless / 4.0).exp();
        if term < 1e-18 {
            break;
        }
        let sign = if n % 2 == 0 { -1.0 } else { 1.0 };
        sum += sign / m * term * (m * pi * xi / 2.0).cos();
    }
    1.0 + 4.0 / pi * sum
}

fn run_on<D: Dim>(backend: &Backend, mesh: Mesh<D>, plane: Range) -> Result<Outcome, SceneError> {
    run_scaled(backend, mesh, plane, 1.0)
}

/// The 2D scene with the fluid's bulk modulus scaled by `scale`
/// ([`Hydro::bulk_modulus_scale`]), compared at the same physical times with the
/// unscaled closed form: the measured cost of the speed-up in accuracy.
pub fn run_2d_bulk_scaled(
    backend: &Backend,
    p: &Params,
    scale: f64,
) -> Result<Outcome, SceneError> {
    let mesh = builders::rectangle(0.0, -0.1, LENGTH, 0.2, p.size)?;
    run_scaled(
        backend,
        mesh,
        Range::plane([0.0; 3], [0.0, 1.0, 0.0], 1e-9),
        scale,
    )
}

fn run_scaled<D: Dim>(
    backend: &Backend,
    mesh: Mesh<D>,
    plane: Range,
    bulk_scale: f64,
) -> Result<Outcome, SceneError> {
    let start = Instant::now();
    let elements = mesh.n_elements();
    let mesh = split_nodes(&mesh, &Range::All)?;
    let model = FlowModel::new(fluid(), Aperture::fixed(APERTURE)?);
    // Held end: the fracture's nodes at x = 0.
    let end = Range::plane([0.0; 3], [1.0, 0.0, 0.0], 1e-9).and(plane.clone());
    let flow = Hydro::new(model)
        .coupling(Coupling::FlowOnly)
        .bulk_modulus_scale(bulk_scale)
        .network_on(plane)
        .pressure(end, P_A);
    let mut sim = Simulation::builder(mesh, backend.clone())
        .physics(flow)
        .build()?;
    let probes = [probe(&sim, 0.5 * LENGTH)?, probe(&sim, LENGTH)?];
    let d = diffusivity();
    let scale = d / (LENGTH * LENGTH);
    let (mut t, mut p_mid, mut p_end) = (vec![0.0], vec![0.0], vec![0.0]);
    let mut error: f64 = 0.0;
    for &ts in &SAMPLES {
        while sim.kinematics().time * scale < ts * (1.0 - 1e-12) {
            sim.step()?;
            let p = sim.field(FLOW_PRESSURE)?;
            t.push(sim.kinematics().time * scale);
            p_mid.push(mean(p, &probes[0].1) / P_A);
            p_end.push(mean(p, &probes[1].1) / P_A);
        }
        let tn = sim.kinematics().time * scale;
        let p = sim.field(FLOW_PRESSURE)?;
        for (x, nodes) in &probes {
            error = error.max((mean(p, nodes) / P_A - exact(*x, tn)).abs());
        }
    }
    let b = mass_balance(&sim)?;
    let channels = sim
        .entity_set(pcdc_hydro::fields::FLOW_CHANNELS)
        .map_or(0, |s| s.len());
    Ok(Outcome {
        error,
        elements,
        channels,
        steps: sim.kinematics().step,
        wall_s: start.elapsed().as_secs_f64(),
        balance: b.relative(),
        t,
        p_mid,
        p_end,
    })
}

/// The flow nodes at distance `x` from the held end (a line of them in 3D), and that
/// distance.
fn probe<D: Dim>(sim: &Simulation<D>, x: f64) -> Result<(f64, Vec<usize>), SceneError> {
    let set = sim
        .entity_set(FLOW_NODES)
        .ok_or_else(|| SceneError::Measurement("no flow nodes".into()))?;
    let xs: Vec<f64> = (0..set.len())
        .map(|l| sim.mesh().node(set.entity(l)[0] as usize)[0])
        .collect();
    let best = xs
        .iter()
        .map(|&xl| (xl - x).abs())
        .fold(f64::INFINITY, f64::min);
    let nodes: Vec<usize> = (0..xs.len())
        .filter(|&l| (xs[l] - x).abs() <= best + 1e-12)
        .collect();
    Ok((xs[nodes[0]], nodes))
}

fn mean(p: &[f64], nodes: &[usize]) -> f64 {
    nodes.iter().map(|&l| p[l]).sum::<f64>() / nodes.len() as f64
}

/// The 2D specimen (1 × 0.2 m, fracture y = 0) on `backend`.
pub fn run_2d(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    let mesh = builders::rectangle(0.0, -0.1, LENGTH, 0.2, p.size)?;
    run_on(backend, mesh, Range::plane([0.0; 3], [0.0, 1.0, 0.0], 1e-9))
}

/// The 3D specimen (1 × 0.2 × 0.2 m of tetrahedra, 2× the 2D size, fracture z = 0) on
/// `backend`.
pub fn run_3d(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    let mesh = builders::cuboid([0.0, -0.1, -0.1], [LENGTH, 0.2, 0.2], 2.0 * p.size)?;
    run_on(backend, mesh, Range::plane([0.0; 3], [0.0, 0.0, 1.0], 1e-9))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_limits() {
        assert_eq!(exact(0.3, 0.0), 0.0);
        assert!((exact(0.0, 0.01) - 1.0).abs() < 1e-12);
        assert!((exact(LENGTH, 50.0) - 1.0).abs() < 1e-12);
        // Early on the far end has not felt the step yet.
        assert!(exact(LENGTH, 0.01).abs() < 1e-6);
    }
}
