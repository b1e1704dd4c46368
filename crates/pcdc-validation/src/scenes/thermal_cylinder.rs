//! Validation scene 13: steady conduction through a hollow cylinder and its plane-strain
//! thermal stresses (manual 7.6.9, eq. 114–116; 115–116 corrected in the digest §8.10).
//!
//! A ring r_i = 0.1 m to r_o = 0.3 m of granite (k = 3 W/(m·K), C_s = 800 J/(kg·K),
//! ρ = 2700 kg/m³; E = 30 GPa, ν = 0.25, α = 8e-6 1/K), its inner surface held at
//! T_i = 100 °C and its outer at T_o = 20 °C, stress-free at T_ref = T_o.
//!
//! * **(114)** T(r) = (T_i − T_o) ln(r_o/r) / ln(r_o/r_i) + T_o.
//! * **(115)–(116)** \[CORRECTED\] with c = E α (T_i − T_o) / (2 (1 − ν) ln(r_o/r_i))
//!   and k = r_i² / (r_o² − r_i²):
//!   σ_r = c [−ln(r_o/r) − k (1 − r_o²/r²) ln(r_o/r_i)],
//!   σ_θ = c [1 − ln(r_o/r) − k (1 + r_o²/r²) ln(r_o/r_i)] (plane strain, tension
//!   positive).
//!
//! Two stages, as FLAC and the manual run it: the heat alone to steady state
//! (`Thermal::heat_only`, until no temperature moves by more than 1e-9 (T_i − T_o) in
//! 100 steps), then the mechanics (`pcdc_mech::ThermalStrain` around linear elasticity)
//! relaxed to equilibrium with the thermal physics holding that field; the thermal stage
//! is scheduled automatically against the mechanical step (one thermal step every n
//! mechanical steps, n reported) and does not move the steady field.
//!
//! Errors: the largest |T − T_exact| / (T_i − T_o) over the nodes (2 %) and the largest
//! |σ − σ_exact| of σ_r and σ_θ over the interior nodes, from the volume-weighted nodal
//! average of the constant-strain element stresses (as in the Kirsch scene; element
//! centroids scatter by ±10 % of max |σ_θ| at 2 cm), divided by max |σ_θ| (5 %).

use std::time::Instant;

use pcdc_compute::{names, Backend, Simulation};
use pcdc_mech::{output, LinearElastic, Mechanics, ThermalStrain};
use pcdc_mesh::{builders, Range};
use pcdc_thermal::{HeatMaterial, Thermal};

use crate::report::SceneError;

/// Tolerance on the temperature, as a fraction of T_i − T_o.
pub const TOL_T: f64 = 0.02;
/// Tolerance on the stresses, as a fraction of max |σ_θ|.
pub const TOL_S: f64 = 0.05;
/// Inner and outer radius (m).
pub const R_IN: f64 = 0.1;
/// See [`R_IN`].
pub const R_OUT: f64 = 0.3;
/// Inner and outer temperature (°C).
pub const T_IN: f64 = 100.0;
/// See [`T_IN`].
pub const T_OUT: f64 = 20.0;
pub(crate) const K: f64 = 3.0;
pub(crate) const CAPACITY: f64 = 800.0;
pub(crate) const DENSITY: f64 = 2700.0;
pub(crate) const YOUNG: f64 = 30e9;
pub(crate) const POISSON: f64 = 0.25;
/// Linear expansion coefficient (1/K).
pub const ALPHA: f64 = 8e-6;
const MAX_STEPS: u64 = 2_000_000;

/// Scene parameters.
#[derive(Clone, Debug)]
pub struct Params {
    /// Element size at the inner surface (m), growing linearly to twice that at the
    /// outer one.
    pub size: f64,
}

/// The element sizes at the inner surface of the example and the report (m): r_i/20,
/// r_i/28, r_i/40. Measured (CPU): r_i/10 misses the stress tolerance, 6.0 % at the
/// first interior node ring, where σ_θ is steepest.
pub const SIZES: [f64; 3] = [0.005, 0.0035, 0.0025];

/// Steady temperature (°C), eq. 114.
pub fn temperature(r: f64) -> f64 {
    (T_IN - T_OUT) * (R_OUT / r).ln() / (R_OUT / R_IN).ln() + T_OUT
}

/// Plane-strain (σ_r, σ_θ) (Pa), eq. 115–116 corrected.
pub fn stresses(r: f64) -> (f64, f64) {
    let ln = (R_OUT / R_IN).ln();
    let c = YOUNG * ALPHA * (T_IN - T_OUT) / (2.0 * (1.0 - POISSON) * ln);
    let k = R_IN * R_IN / (R_OUT * R_OUT - R_IN * R_IN);
    let q = R_OUT * R_OUT / (r * r);
    let l = (R_OUT / r).ln();
    (
        c * (-l - k * (1.0 - q) * ln),
        c * (1.0 - l - k * (1.0 + q) * ln),
    )
}

/// Outcome of a run.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Temperature error (fraction of T_i − T_o).
    pub error_t: f64,
    /// Stress error (fraction of max |σ_θ|).
    pub error_s: f64,
    /// Elements.
    pub elements: usize,
    /// Thermal steps to steady state plus relaxation steps.
    pub steps: u64,
    /// Mechanical steps per thermal step chosen by the automatic schedule.
    pub every: String,
    /// Wall time (s).
    pub wall_s: f64,
    /// Radius (m), σ_r and σ_θ (Pa) of every interior node (nodal averages).
    pub r: Vec<f64>,
    /// See `r`.
    pub sr: Vec<f64>,
    /// See `r`.
    pub st: Vec<f64>,
}

/// Runs the scene on `backend`.
pub fn run(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    let start = Instant::now();
    let mesh = builders::ring([0.0, 0.0], R_IN, R_OUT, p.size, 2.0 * p.size)?;
    let elements = mesh.n_elements();
    let rock = HeatMaterial::new(K, CAPACITY, DENSITY)?;
    let heat = || {
        Thermal::new()
            .material(Range::All, rock)
            .temperature(Range::group("inner"), T_IN)
            .temperature(Range::group("outer"), T_OUT)
    };
    // Stage 1: heat alone to steady state.
    let mut sim = Simulation::builder(mesh.clone(), backend.clone())
        .physics(heat().initial_temperature(T_OUT).heat_only())
        .build()?;
    let dt_range = T_IN - T_OUT;
    let mut last = sim.field(names::TEMPERATURE)?.to_vec();
    loop {
        sim.run(100)?;
        let t = sim.field(names::TEMPERATURE)?;
        let change = t
            .iter()
            .zip(&last)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        last.copy_from_slice(t);
        if change <= 1e-9 * dt_range {
            break;
        }
        if sim.kinematics().step >= MAX_STEPS {
            return Err(SceneError::Measurement(format!(
                "no thermal steady state after {MAX_STEPS} steps (last change {change:e})"
            )));
        }
    }
    let thermal_steps = sim.kinematics().step;
    let mut error_t = 0.0f64;
    for (n, &t) in last.iter().enumerate() {
        let x = mesh.node(n);
        let r = (x[0] * x[0] + x[1] * x[1]).sqrt();
        error_t = error_t.max((t - temperature(r)).abs() / dt_range);
    }
    // Stage 2: equilibrium under the steady temperature.
    let elastic = LinearElastic::new(YOUNG, POISSON, DENSITY)?;
    let model = ThermalStrain::new(elastic, ALPHA, T_OUT)?;
    let mut sim = Simulation::builder(mesh, backend.clone())
        .physics(Mechanics::new().material(Range::All, model))
        .physics(heat().initial_temperature_nodes(last))
        .build()?;
    let every = sim
        .field_stages()
        .iter()
        .map(|s| format!("{:?}", s.cycle))
        .collect::<Vec<_>>()
        .join(", ");
    let report = sim.relax(&super::relax_options(backend))?;
    let stress = output::global_stress(&sim)?;
    // Constant-strain elements: compared at the nodes through the volume-weighted nodal
    // average (as the Kirsch scene), on the interior nodes, where it is two-sided.
    let nodal = output::nodal_average(sim.mesh(), &stress, 3);
    let (mut r, mut sr, mut st) = (Vec::new(), Vec::new(), Vec::new());
    let mut worst = 0.0f64;
    let scale = stresses(R_IN).1.abs().max(stresses(R_OUT).1.abs());
    for n in 0..sim.mesh().n_nodes() {
        let x = sim.mesh().node(n);
        let rc = (x[0] * x[0] + x[1] * x[1]).sqrt();
        if !(R_IN * (1.0 + 1e-9)..=R_OUT * (1.0 - 1e-9)).contains(&rc) {
            continue;
        }
        let (co, si) = (x[0] / rc, x[1] / rc);
        let (xx, yy, xy) = (nodal[3 * n], nodal[3 * n + 1], nodal[3 * n + 2]);
        let s_r = xx * co * co + yy * si * si + 2.0 * xy * co * si;
        let s_t = xx * si * si + yy * co * co - 2.0 * xy * co * si;
        let (er, et) = stresses(rc);
        worst = worst.max((s_r - er).abs()).max((s_t - et).abs());
        r.push(rc);
        sr.push(s_r);
        st.push(s_t);
    }
    Ok(Outcome {
        error_t,
        error_s: worst / scale,
        elements,
        steps: thermal_steps + report.steps,
        every,
        wall_s: start.elapsed().as_secs_f64(),
        r,
        sr,
        st,
    })
}
