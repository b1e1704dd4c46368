//! Validation scene: transient conduction into a half-space after a step of the surface
//! temperature (issue 17; Carslaw & Jaeger 1959, §2.5).
//!
//! A granite bar (k = 3 W/(m·K), C_s = 800 J/(kg·K), ρ = 2700 kg/m³, κ = 1.39e-6 m²/s)
//! of length 1 m along x, initially at T0 = 20 °C, its face x = 0 held at Ts = 120 °C
//! from t = 0, every other face adiabatic. While the heated layer is thin against the
//! length (2√(κt) = 0.25 m at the last time) the bar is a half-space:
//!
//! T(x, t) = T0 + (Ts − T0) erfc(x / (2√(κt))).
//!
//! The error is the largest |T − T_exact| / (Ts − T0) over every node at t = t_end/4
//! and t_end (t_end = 0.25² / (4κ) ≈ 3.1 h); tolerance 2 %. 2D: a 1 × 0.1 m strip of
//! right triangles; 3D: a 1 × 0.1 × 0.1 m bar of Kuhn tetrahedra. The thermal physics
//! runs alone (`Thermal::heat_only`), its step the stable step with the engine's safety
//! factor.

use std::time::Instant;

use pcdc_compute::{names, Backend, Simulation};
use pcdc_mesh::{builders, Dim, Mesh, Range};
use pcdc_thermal::{HeatMaterial, Thermal};

use crate::report::SceneError;

/// Tolerance on the temperature error, as a fraction of Ts − T0.
pub const TOL: f64 = 0.02;
/// Initial temperature (°C).
pub const T0: f64 = 20.0;
/// Surface temperature (°C).
pub const TS: f64 = 120.0;
/// Conductivity (W/(m·K)), specific heat (J/(kg·K)), density (kg/m³).
pub const K: f64 = 3.0;
const CAPACITY: f64 = 800.0;
const DENSITY: f64 = 2700.0;
/// Penetration depth 2√(κ t_end) at the last time (m).
pub const DEPTH: f64 = 0.25;

/// Thermal diffusivity κ (m²/s).
pub fn kappa() -> f64 {
    K / (DENSITY * CAPACITY)
}

/// The last comparison time (s).
pub fn t_end() -> f64 {
    DEPTH * DEPTH / (4.0 * kappa())
}

/// T(x, t) of the half-space (°C).
pub fn exact(x: f64, t: f64) -> f64 {
    T0 + (TS - T0) * erfc(x / (2.0 * (kappa() * t).sqrt()))
}

/// erfc to 1.2e-7 (Chebyshev fit of Numerical Recipes, §6.2).
pub fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * poly.exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

/// Scene parameters.
#[derive(Clone, Debug)]
pub struct Params {
    /// Element size (m).
    pub size: f64,
}

/// The element sizes of the example and the report, 2D (m).
pub const SIZES_2D: [f64; 3] = [0.04, 0.02, 0.01];
/// The element sizes of the example and the report, 3D (m).
pub const SIZES_3D: [f64; 3] = [0.05, 0.04, 0.025];

/// Outcome of a run.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Largest |T − T_exact| / (Ts − T0) at both times.
    pub error: f64,
    /// Elements.
    pub elements: usize,
    /// Thermal steps.
    pub steps: u64,
    /// The thermal step (s).
    pub dt: f64,
    /// Wall time (s).
    pub wall_s: f64,
    /// x (m) and T (°C) of every node at t_end.
    pub x: Vec<f64>,
    /// See `x`.
    pub t: Vec<f64>,
}

fn run_on<D: Dim>(backend: &Backend, mesh: Mesh<D>, surface: &str) -> Result<Outcome, SceneError> {
    let start = Instant::now();
    let elements = mesh.n_elements();
    let rock = HeatMaterial::new(K, CAPACITY, DENSITY)?;
    let heat = Thermal::new()
        .material(Range::All, rock)
        .initial_temperature(T0)
        .temperature(Range::group(surface), TS)
        .heat_only();
    let mut sim = Simulation::builder(mesh, backend.clone())
        .physics(heat)
        .build()?;
    let mut error = 0.0f64;
    for t_cmp in [0.25 * t_end(), t_end()] {
        while sim.kinematics().time < t_cmp * (1.0 - 1e-12) {
            sim.step()?;
        }
        let time = sim.kinematics().time;
        let temp = sim.field(names::TEMPERATURE)?;
        for (n, &t) in temp.iter().enumerate() {
            let x = sim.mesh().node(n)[0];
            error = error.max((t - exact(x, time)).abs() / (TS - T0));
        }
    }
    let temp = sim.field(names::TEMPERATURE)?.to_vec();
    let x = (0..temp.len()).map(|n| sim.mesh().node(n)[0]).collect();
    Ok(Outcome {
        error,
        elements,
        steps: sim.kinematics().step,
        dt: sim.dt(),
        wall_s: start.elapsed().as_secs_f64(),
        x,
        t: temp,
    })
}

/// The 2D strip (1 × 0.1 m) with elements of `p.size`.
pub fn run_2d(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 0.1, p.size)?;
    run_on(backend, mesh, "left")
}

/// The 3D bar (1 × 0.1 × 0.1 m) with elements of `p.size`.
pub fn run_3d(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    let mesh = builders::cuboid([0.0; 3], [1.0, 0.1, 0.1], p.size)?;
    run_on(backend, mesh, "xmin")
}
