//! Validation scene 4: energy of an undamped free vibration.
//!
//! A free elastic block (no supports, no damping; E = 30 GPa, ν = 0.25, ρ = 2600 kg/m³)
//! is released at rest from the smooth strained state u_x = A sin(π x / L), u_y = 0
//! (A = 1e-4 L), which excites mainly its first extensional mode. The total energy
//! E = strain energy + kinetic energy is followed over ten periods T = 2 L / c_p of
//! that mode. Central differences conserve energy up to a bounded O((ω dt)²)
//! oscillation, so the drift max |E(t) − E(0)| / E(0) must stay below 0.5 %.
//! Kinetic energy is the leapfrog's discrete kinetic energy ½ Σ m v(t−dt/2)·v(t+dt/2),
//! which matches the strain energy of the positions at t (for a linear system their sum
//! is exactly the quantity central differences conserve).

use std::time::Instant;

use pcdc_compute::{Backend, Simulation};
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim, Mesh, Range};

use crate::report::SceneError;

/// Tolerance on the relative energy drift.
pub const TOL: f64 = 0.005;
const E: f64 = 30e9;
const NU: f64 = 0.25;
const RHO: f64 = 2600.0;

/// Scene parameters.
#[derive(Clone, Debug)]
pub struct Params {
    /// Element size (m) for the 1 m × 0.25 m block.
    pub size: f64,
    /// Number of periods.
    pub periods: f64,
}

impl Params {
    /// Full size.
    pub fn full() -> Self {
        Params {
            size: 0.01,
            periods: 10.0,
        }
    }
    /// Reduced size for tests.
    pub fn reduced() -> Self {
        Params {
            size: 0.05,
            periods: 10.0,
        }
    }
}

/// Outcome of a run.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Relative drift max |E − E0| / E0.
    pub drift: f64,
    /// Elements.
    pub elements: usize,
    /// Steps.
    pub steps: u64,
    /// Wall time (s).
    pub wall_s: f64,
    /// Time samples divided by the period.
    pub t_over_period: Vec<f64>,
    /// Total energy samples divided by E0.
    pub energy: Vec<f64>,
    /// Strain energy samples divided by E0.
    pub strain_energy: Vec<f64>,
}

fn run_on<D: Dim>(backend: &Backend, mesh: Mesh<D>, p: &Params) -> Result<Outcome, SceneError> {
    let start = Instant::now();
    let (lo, hi) = mesh.bounding_box();
    let length = hi[0] - lo[0];
    let rock = LinearElastic::new(E, NU, RHO)?;
    let mut sim = Simulation::builder(mesh, backend.clone())
        .physics(Mechanics::new().material(Range::All, rock))
        .build()?;
    let d = D::D;
    let x0 = sim.mesh().coords().to_vec();
    for (n, x) in x0.chunks_exact(d).enumerate() {
        sim.state.u[n * d] = 1e-4 * length * (std::f64::consts::PI * (x[0] - lo[0]) / length).sin();
    }
    let c = (rock_modulus() / RHO).sqrt();
    let period = 2.0 * length / c;
    let mass = sim.mass().to_vec();
    let mut v_prev = sim.state.v.clone();
    let (mut ts, mut es, mut ss) = (Vec::new(), Vec::new(), Vec::new());
    let mut e0 = None;
    let mut drift = 0.0f64;
    while sim.state.time < p.periods * period {
        let t = sim.state.time;
        sim.step()?;
        // The stress field now belongs to the positions at t; velocities straddle t.
        let se = sim.stored_energy();
        let ke: f64 = 0.5
            * sim
                .state
                .v
                .chunks_exact(d)
                .zip(v_prev.chunks_exact(d))
                .zip(&mass)
                .map(|((a, b), m)| m * (0..d).map(|k| a[k] * b[k]).sum::<f64>())
                .sum::<f64>();
        v_prev.copy_from_slice(&sim.state.v);
        let total = se + ke;
        let e0v = *e0.get_or_insert(total);
        drift = drift.max((total - e0v).abs() / e0v);
        ts.push(t / period);
        es.push(total / e0v);
        ss.push(se / e0v);
    }
    Ok(Outcome {
        drift,
        elements: sim.mesh().n_elements(),
        steps: sim.state.step,
        wall_s: start.elapsed().as_secs_f64(),
        t_over_period: ts,
        energy: es,
        strain_energy: ss,
    })
}

fn rock_modulus() -> f64 {
    E * (1.0 - NU) / ((1.0 + NU) * (1.0 - 2.0 * NU))
}

/// The 2D block 1 m × 0.25 m, on `backend`.
pub fn run_2d(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    run_on(
        backend,
        builders::rectangle(0.0, 0.0, 1.0, 0.25, p.size)?,
        p,
    )
}

/// The 3D block 1 m × 0.25 m × 0.25 m (element size 2.5× the 2D one), on `backend`.
pub fn run_3d(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    run_on(
        backend,
        builders::cuboid([0.0; 3], [1.0, 0.25, 0.25], 2.5 * p.size)?,
        p,
    )
}

/// The 3D block of [`run_3d`] meshed with Hex8 cells of the same size.
pub fn run_3d_hex8(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    run_on(
        backend,
        builders::cuboid_hexes([0.0; 3], [1.0, 0.25, 0.25], 2.5 * p.size)?,
        p,
    )
}
