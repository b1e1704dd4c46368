//! Validation: a circular opening in Mohr–Coulomb rock under hydrostatic in-situ stress
//! (Salençon's closed form, the classic check of FLAC's Mohr–Coulomb; manual 7.2.4).
//!
//! Rock (FLAC's verification values): E = 6.778 GPa, ν = 0.21, c = 3.45 MPa, φ = 30°,
//! ψ = 0°, σ_t = 1 MPa, ρ = 2500 kg/m³; in-situ stress p0 = 30 MPa (compression), the
//! opening of radius a = 1 m unsupported. The ring of the Kirsch scene (outer radius
//! 25 a, graded from the hole, three single-dof supports; [`super::kirsch::mesh`])
//! starts at σ = −p0 I everywhere (σzz too) with the traction −p0 on the outer boundary;
//! the pressure on the hole wall falls from p0 to 0 in [`STAGES`] equal stages, each
//! relaxed to equilibrium (the wall stress is a face stress following a table of the
//! simulation time, which the scene sets between relaxations).
//!
//! Closed form (compression positive; N_φ = (1 + sin φ)/(1 − sin φ), σ_c = 2c√N_φ):
//! plastic radius R_p = a [2 (p0 (N_φ − 1) + σ_c) / ((1 + N_φ) σ_c)]^{1/(N_φ − 1)};
//! for a ≤ r ≤ R_p, σr = σ_c/(N_φ − 1) ((r/a)^{N_φ−1} − 1) and σθ = σ_c/(N_φ − 1)
//! (N_φ (r/a)^{N_φ−1} − 1); for r ≥ R_p, σr = p0 − (p0 − σ_re)(R_p/r)², σθ = p0 +
//! (p0 − σ_re)(R_p/r)², σ_re = (2 p0 − σ_c)/(1 + N_φ). The stresses do not depend on ψ.
//!
//! Errors: the nodal-averaged σr and σθ along θ = 0 for 1.1 a ≤ r ≤ 5 a against the
//! closed form, max difference over max σθ (tolerance [`TOL`]); the plastic radius, the
//! largest centroid radius of the elements that yielded in shear within 10° of θ = 0,
//! against R_p (tolerance [`RADIUS_TOL`], relative).

use std::time::Instant;

use pcdc_compute::{Backend, Simulation, Table};
use pcdc_mech::mohr_coulomb::{state, MC_STATE};
use pcdc_mech::{output, Boundary, FaceStress, LinearElastic, Mechanics, MohrCoulomb};
use pcdc_mesh::Range;

use crate::report::SceneError;
use crate::scenes::kirsch;

/// In-situ stress p0 (Pa, compression).
pub const P0: f64 = 30e6;
/// Cohesion (Pa).
pub const COHESION: f64 = 3.45e6;
/// Friction angle (degrees).
pub const FRICTION: f64 = 30.0;
/// Tolerance on the stresses (relative to max σθ).
pub const TOL: f64 = 0.05;
/// Tolerance on the plastic radius (relative).
pub const RADIUS_TOL: f64 = 0.05;
/// Unloading stages of the wall pressure.
pub const STAGES: usize = 10;

/// Scene parameters.
#[derive(Clone, Debug)]
pub struct Params {
    /// Element size at the hole, as a fraction of a (the ring grades to 2.5 a).
    pub size_at_hole: f64,
    /// Folder for a VTU/PVD file of the solution, if any.
    pub vtu_dir: Option<std::path::PathBuf>,
}

impl Params {
    /// Full size: a/40 at the hole.
    pub fn full() -> Self {
        Params {
            size_at_hole: 0.025,
            vtu_dir: None,
        }
    }
    /// Reduced: a/20 at the hole.
    pub fn reduced() -> Self {
        Params {
            size_at_hole: 0.05,
            vtu_dir: None,
        }
    }
}

/// Outcome.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Stress error (relative to max σθ on the samples).
    pub error: f64,
    /// Measured plastic radius (m).
    pub plastic_radius: f64,
    /// Closed-form plastic radius (m).
    pub plastic_radius_exact: f64,
    /// Sample radii over a, σθ and σr there (Pa, compression positive).
    pub r_over_a: Vec<f64>,
    /// See `r_over_a`.
    pub sigma_theta: Vec<f64>,
    /// See `r_over_a`.
    pub sigma_r: Vec<f64>,
    /// Elements.
    pub elements: usize,
    /// Relaxation steps.
    pub steps: u64,
    /// Wall time (s).
    pub wall_s: f64,
}

impl Outcome {
    /// Relative error of the plastic radius.
    pub fn radius_error(&self) -> f64 {
        (self.plastic_radius - self.plastic_radius_exact).abs() / self.plastic_radius_exact
    }
}

fn n_phi() -> f64 {
    let s = FRICTION.to_radians().sin();
    (1.0 + s) / (1.0 - s)
}

/// Salençon's plastic radius for a = 1 (m).
pub fn plastic_radius() -> f64 {
    let (n, sc) = (n_phi(), 2.0 * COHESION * n_phi().sqrt());
    (2.0 * (P0 * (n - 1.0) + sc) / ((1.0 + n) * sc)).powf(1.0 / (n - 1.0))
}

/// The closed-form σθ, σr at r (m; a = 1), compression positive (Pa).
pub fn exact(r: f64) -> (f64, f64) {
    let (n, sc) = (n_phi(), 2.0 * COHESION * n_phi().sqrt());
    let rp = plastic_radius();
    if r <= rp {
        let q = r.powf(n - 1.0);
        let k = sc / (n - 1.0);
        (k * (n * q - 1.0), k * (q - 1.0))
    } else {
        let sre = (2.0 * P0 - sc) / (1.0 + n);
        let q = (rp / r).powi(2);
        (P0 + (P0 - sre) * q, P0 - (P0 - sre) * q)
    }
}

/// Runs the scene.
pub fn run(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    let start = Instant::now();
    let a = 1.0;
    let mesh = kirsch::mesh(&kirsch::Params {
        radius: a,
        size_at_hole: p.size_at_hole,
        vtu_dir: None,
        element: crate::scenes::Element::Simplex,
    })?;
    let e = LinearElastic::new(6.778e9, 0.21, 2500.0)?;
    let rock = MohrCoulomb::new(e, COHESION, FRICTION, 0.0, 1e6)?;
    let wall = Table::new("wall pressure", &[(0.0, -P0), (1.0, 0.0)])?;
    let mut sim = Simulation::builder(mesh, backend.clone())
        .physics(
            Mechanics::new()
                .material(Range::All, rock)
                .initial_stress(Range::All, [-P0, -P0, -P0, 0.0, 0.0, 0.0]),
        )
        .physics(kirsch::supports(
            Boundary::new()
                .face_stress(
                    Range::group("outer"),
                    FaceStress {
                        normal: Some((-P0).into()),
                        ..Default::default()
                    },
                )
                .face_stress(
                    Range::group("inner"),
                    FaceStress {
                        normal: Some(wall.into()),
                        ..Default::default()
                    },
                ),
        ))
        .build()?;
    let opts = super::relax_options(backend);
    let mut steps = 0;
    for k in 1..=STAGES {
        sim.state.time = k as f64 / STAGES as f64;
        steps += sim.relax(&opts)?.steps;
    }
    let stress = output::global_stress(&sim)?;
    if let Some(dir) = &p.vtu_dir {
        let mut series = pcdc_mesh::vtu::PvdSeries::new(dir, "tunnel")?;
        output::write_step(&mut series, &sim)?;
    }
    let samples = kirsch::samples_on_axis(&sim, &stress, a)?;
    let mesh = sim.mesh();
    let scale = samples.iter().map(|s| exact(s.0).0).fold(0.0, f64::max);
    let error = samples
        .iter()
        .map(|&(r, st, sr)| {
            let (et, er) = exact(r);
            (st - et).abs().max((sr - er).abs())
        })
        .fold(0.0, f64::max)
        / scale;
    let history = sim.field("model_state")?;
    let mut c = [0.0; 2];
    let mut measured: f64 = 0.0;
    for e in 0..mesh.n_elements() {
        mesh.element_centroid(e, &mut c);
        let (r, theta) = (c[0].hypot(c[1]), c[1].atan2(c[0]).abs());
        if theta <= 10f64.to_radians() && history[e * MC_STATE + state::SHEAR_PAST] > 0.0 {
            measured = measured.max(r);
        }
    }
    Ok(Outcome {
        error,
        plastic_radius: measured,
        plastic_radius_exact: plastic_radius(),
        r_over_a: samples.iter().map(|s| s.0).collect(),
        sigma_theta: samples.iter().map(|s| s.1).collect(),
        sigma_r: samples.iter().map(|s| s.2).collect(),
        elements: mesh.n_elements(),
        steps,
        wall_s: start.elapsed().as_secs_f64(),
    })
}
