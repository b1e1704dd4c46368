//! Validation scene 3: the P-wave speed in a bar on rollers.
//!
//! A bar (length L = 1 m, plane strain in 2D, square section in 3D) whose side faces are
//! on rollers (no lateral displacement) is hit at x = 0 by a velocity step v0 = 0.1 m/s
//! held from t = 0. With the rollers the front travels at the P-wave speed
//! c = sqrt(E(1−ν)/(ρ(1+ν)(1−2ν))). The scene records the time at which the mean
//! particle velocity of two cross-sections (x = L/4 and x = 3L/4) first reaches v0/2 and
//! takes c_num = (L/2) / (t2 − t1). E = 30 GPa, ν = 0.25, ρ = 2600 kg/m³, undamped.
//! Tolerance 2 %.

use std::time::Instant;

use pcdc_compute::{Backend, Simulation};
use pcdc_mech::{Boundary, Constraint, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim, Range};

use crate::report::SceneError;

/// Tolerance on the relative error of the wave speed.
pub const TOL: f64 = 0.02;
const E: f64 = 30e9;
const NU: f64 = 0.25;
const RHO: f64 = 2600.0;
const V0: f64 = 0.1;
const LENGTH: f64 = 1.0;

/// Scene parameters.
#[derive(Clone, Debug)]
pub struct Params {
    /// Element size (m).
    pub size: f64,
}

impl Params {
    /// Full size (5 mm elements).
    pub fn full() -> Self {
        Params { size: 0.005 }
    }
    /// Reduced size for tests (2 cm elements).
    pub fn reduced() -> Self {
        Params { size: 0.02 }
    }
}

/// Outcome of a run.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Analytic P-wave speed (m/s).
    pub c_exact: f64,
    /// Measured speed (m/s).
    pub c_num: f64,
    /// Relative error.
    pub error: f64,
    /// Elements.
    pub elements: usize,
    /// Steps run.
    pub steps: u64,
    /// Wall time (s).
    pub wall_s: f64,
    /// Time samples (s).
    pub t: Vec<f64>,
    /// Mean x-velocity at the first probe section (m/s).
    pub v1: Vec<f64>,
    /// Mean x-velocity at the second probe section (m/s).
    pub v2: Vec<f64>,
}

/// Analytic P-wave speed (m/s).
pub fn c_exact() -> f64 {
    (E * (1.0 - NU) / (RHO * (1.0 + NU) * (1.0 - 2.0 * NU))).sqrt()
}

fn run_on<D: Dim>(
    backend: &Backend,
    mesh: pcdc_mesh::Mesh<D>,
    side_groups: &[&str],
) -> Result<Outcome, SceneError> {
    let start = Instant::now();
    let rock = LinearElastic::new(E, NU, RHO)?;
    let mut bc = Boundary::new().velocity(
        Range::group(if D::D == 2 { "left" } else { "xmin" }),
        [Some(V0.into()), None, None],
    );
    for g in side_groups {
        let normal = match *g {
            "bottom" | "top" | "ymin" | "ymax" => [0.0, 1.0, 0.0],
            _ => [0.0, 0.0, 1.0],
        };
        bc = bc.constraint(Range::group(*g), Constraint::Plane(normal));
    }
    let mut sim = Simulation::builder(mesh, backend.clone())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(bc)
        .build()?;
    let d = D::D;
    let section = |sim: &Simulation<D>, x: f64| -> Result<Vec<u32>, SceneError> {
        let (lo, hi) = sim.mesh().edge_length_range();
        let tol = lo.min(hi);
        let nodes = sim
            .mesh()
            .select_nodes(&Range::plane([x, 0.0, 0.0], [1.0, 0.0, 0.0], tol))?;
        if nodes.is_empty() {
            return Err(SceneError::Measurement(format!("no nodes at x = {x}")));
        }
        // Keep only the plane of nodes closest to x.
        let best = nodes
            .iter()
            .map(|&n| (sim.mesh().node(n as usize)[0] - x).abs())
            .fold(f64::INFINITY, f64::min);
        Ok(nodes
            .into_iter()
            .filter(|&n| (sim.mesh().node(n as usize)[0] - x).abs() <= best + 1e-12)
            .collect())
    };
    let (s1, s2) = (section(&sim, 0.25 * LENGTH)?, section(&sim, 0.75 * LENGTH)?);
    let x1 = sim.mesh().node(s1[0] as usize)[0];
    let x2 = sim.mesh().node(s2[0] as usize)[0];
    let mean_v = |sim: &Simulation<D>, s: &[u32]| {
        s.iter().map(|&n| sim.state.v[n as usize * d]).sum::<f64>() / s.len() as f64
    };
    let c = c_exact();
    let t_end = (x2 + 0.1 * LENGTH) / c;
    let (mut t, mut v1, mut v2) = (Vec::new(), Vec::new(), Vec::new());
    let (mut t1, mut t2) = (None, None);
    let mut prev = (0.0, 0.0, 0.0);
    while sim.state.time < t_end {
        sim.step()?;
        // Velocities are at the half step.
        let th = sim.state.time - 0.5 * sim.dt();
        let (a, b) = (mean_v(&sim, &s1), mean_v(&sim, &s2));
        let cross = |p: f64, q: f64, tp: f64| tp + (0.5 * V0 - p) / (q - p) * (th - tp);
        if t1.is_none() && a >= 0.5 * V0 {
            t1 = Some(cross(prev.1, a, prev.0));
        }
        if t2.is_none() && b >= 0.5 * V0 {
            t2 = Some(cross(prev.2, b, prev.0));
        }
        prev = (th, a, b);
        t.push(th);
        v1.push(a);
        v2.push(b);
    }
    let (t1, t2) = match (t1, t2) {
        (Some(a), Some(b)) => (a, b),
        _ => {
            return Err(SceneError::Measurement(
                "the wave front did not reach both probes".into(),
            ))
        }
    };
    let c_num = (x2 - x1) / (t2 - t1);
    Ok(Outcome {
        c_exact: c,
        c_num,
        error: (c_num - c).abs() / c,
        elements: sim.mesh().n_elements(),
        steps: sim.state.step,
        wall_s: start.elapsed().as_secs_f64(),
        t,
        v1,
        v2,
    })
}

/// The 2D bar (height 0.1 m), rollers on top and bottom, on `backend`.
pub fn run_2d(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    let mesh = builders::rectangle(0.0, 0.0, LENGTH, 0.1, p.size)?;
    run_on(backend, mesh, &["bottom", "top"])
}

/// The 3D bar (section 0.05 × 0.05 m, coarser: 2× the 2D size), rollers on the four
/// sides, on `backend`.
pub fn run_3d(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    let mesh = builders::cuboid([0.0; 3], [LENGTH, 0.05, 0.05], 2.0 * p.size)?;
    run_on(backend, mesh, &["ymin", "ymax", "zmin", "zmax"])
}

/// The 3D bar of [`run_3d`] meshed with Hex8 cells of the same size.
pub fn run_3d_hex8(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    let mesh = builders::cuboid_hexes([0.0; 3], [LENGTH, 0.05, 0.05], 2.0 * p.size)?;
    run_on(backend, mesh, &["ymin", "ymax", "zmin", "zmax"])
}
