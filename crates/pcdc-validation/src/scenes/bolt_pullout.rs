//! Validation scene 15 and its failure companion: a fully grouted rock bolt pulled from
//! a rigid block (manual 7.9; VALIDATION.md scene 15).
//!
//! **Elastic pull-out.** A steel rebar (D_b = 25 mm, E_b = 200 GPa, A_b = π D_b²/4) of
//! length L = 2 m is grouted along its whole length in a block whose nodes are held
//! fixed (a rigid host), with grout shear stiffness K = 2.5·10⁸ N/m/m. A force F0 =
//! 30 kN pulls its head (x = 0) out. The bar's equilibrium E_b A_b u'' = K u with a free
//! tail gives the axial force
//!
//! F(x) = F0 sinh(β (L − x)) / sinh(β L), β = √(K / (E_b A_b)) (βL = 3.19 here).
//!
//! Compared at every segment's midpoint after static relaxation (unbalanced-force ratio
//! 10⁻⁹; 10⁻⁵ in f32); error = the largest |F − F_exact| / F0, tolerance 3 %. The bond is far from
//! its strength (peak grout shear β F0 coth(βL) = 48 kN/m against 71 kN/m: no slip).
//!
//! **Pull-out to failure.** The same rebar, L = 1 m, in a block under an isotropic
//! initial stress of −1 MPa (the confinement σ_n of eq. 146–147 comes from the host's
//! stress), pulled at its head at a constant 0.05 m/s (quasi-static: 500 axial transits
//! of the bolt during the pull, local damping 0.3) to 5 mm, several times the
//! displacement at which the whole length slips. The pull-out load (the sum of the
//! grout forces, what the rock carries) must peak at S_b L (eq. 144–147 with σ_n = 1 MPa:
//! S_b = min(π (D_b + 2 T_g)(C_r,g + σ_n tan φ_r,g), π D_b (C_b,g + σ_n tan φ_b,g)))
//! within 2 %, below the bar's yield force, and stay on that plateau to the end of the
//! pull (the grout has no softening).

use std::time::Instant;

use pcdc_bolt::{Bolt, BoltMaterial, BoltNodes, BoltProperties, Bolts};
use pcdc_bolt::{BOLT_AXIAL_FORCE, BOLT_GROUT_FORCE, BOLT_SLIP};
use pcdc_compute::{Backend, Simulation, StaticOptions};
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Range};

use crate::report::SceneError;

/// Tolerance of the elastic pull-out, a fraction of F0.
pub const TOL: f64 = 0.03;
/// Tolerance of the pull-out peak, a fraction of S_b L.
pub const TOL_PEAK: f64 = 0.02;
/// Bolt length of the elastic pull-out (m).
pub const LENGTH: f64 = 2.0;
/// Bolt length of the pull-out to failure (m).
pub const LENGTH_FAILURE: f64 = 1.0;
/// Grout shear stiffness K (N/m/m).
pub const STIFFNESS: f64 = 2.5e8;
/// Pull force of the elastic pull-out (N).
pub const F0: f64 = 30e3;
/// Confining stress of the pull-out to failure (Pa, compression positive).
pub const CONFINEMENT: f64 = 1e6;
/// Head velocity of the pull-out to failure (m/s) and its final displacement (m).
pub const PULL_VELOCITY: f64 = 0.05;
/// See [`PULL_VELOCITY`].
pub const PULL_DISTANCE: f64 = 5e-3;
/// Segment lengths of the example and the report (m).
pub const SIZES: [f64; 3] = [0.1, 0.05, 0.025];

/// The rebar of both scenes.
pub fn rebar() -> BoltProperties {
    BoltProperties {
        shear_stiffness: STIFFNESS,
        cohesion_rock_grout: 0.5e6,
        cohesion_grout_bolt: 3e6,
        ..BoltProperties::steel_rebar(0.025)
    }
}

/// β = √(K / (E_b A_b)) (1/m).
pub fn beta() -> f64 {
    let m = BoltMaterial::new(rebar()).expect("valid rebar");
    (STIFFNESS / (m.properties().young * m.area())).sqrt()
}

/// The closed-form axial force at distance `x` from the head (N).
pub fn exact(x: f64) -> f64 {
    let b = beta();
    F0 * (b * (LENGTH - x)).sinh() / (b * LENGTH).sinh()
}

/// The bond capacity S_b L of the failure scene (N).
pub fn capacity() -> f64 {
    BoltMaterial::new(rebar())
        .expect("valid rebar")
        .bond_strength(CONFINEMENT)
        * LENGTH_FAILURE
}

/// Scene parameters.
#[derive(Clone, Debug)]
pub struct Params {
    /// Bolt segment length (m).
    pub size: f64,
}

/// Outcome of the elastic pull-out.
#[derive(Clone, Debug)]
pub struct Elastic {
    /// Largest |F − F_exact| / F0.
    pub error: f64,
    /// Distance from the head (m) and axial force (N) of every segment.
    pub profile: Vec<(f64, f64)>,
    /// Bolt segments.
    pub segments: usize,
    /// Relaxation steps.
    pub steps: u64,
    /// Wall time (s).
    pub wall_s: f64,
}

/// Outcome of the pull-out to failure.
#[derive(Clone, Debug)]
pub struct Failure {
    /// Peak pull-out load over S_b L.
    pub peak_ratio: f64,
    /// The larger of |peak_ratio − 1| and the drop from the peak at the end of the pull
    /// (1 − end_ratio): the peak and the plateau.
    pub error: f64,
    /// Load at the end of the pull over the peak.
    pub end_ratio: f64,
    /// Largest axial force in the bolt over its tensile yield force.
    pub axial_ratio: f64,
    /// Head displacement (m) and pull-out load (N), sampled along the pull.
    pub curve: Vec<(f64, f64)>,
    /// Bolt segments.
    pub segments: usize,
    /// Steps.
    pub steps: u64,
    /// Wall time (s).
    pub wall_s: f64,
}

impl Elastic {
    /// Whether the scene passes.
    pub fn pass(&self) -> bool {
        self.error <= TOL
    }
}

impl Failure {
    /// Whether the scene passes: the peak within [`TOL_PEAK`], the bolt below yield, and
    /// the load still on the plateau at the end.
    pub fn pass(&self) -> bool {
        self.error <= TOL_PEAK && self.axial_ratio < 1.0
    }
}

fn segments(length: f64, size: f64) -> Result<usize, SceneError> {
    if !(size > 0.0 && size <= length) {
        return Err(SceneError::Measurement(format!(
            "segment length {size} m must lie in (0, {length}] m"
        )));
    }
    Ok((length / size).round().max(1.0) as usize)
}

/// The block: rigid (all nodes held), 0.2 m high, around the bolt on y = 0.
fn block(length: f64) -> Result<pcdc_mesh::Mesh<pcdc_mesh::Dim2>, SceneError> {
    Ok(builders::rectangle(-0.1, -0.1, length + 0.2, 0.2, 0.05)?)
}

/// Runs the elastic pull-out with segments of `p.size` on `backend`.
pub fn run_elastic(backend: &Backend, p: &Params) -> Result<Elastic, SceneError> {
    let start = Instant::now();
    let n = segments(LENGTH, p.size)?;
    let bolt = Bolt::straight(
        "rebar",
        [0.0; 3],
        [LENGTH, 0.0, 0.0],
        n,
        BoltMaterial::new(rebar())?,
    )?;
    let bolts = Bolts::new().bolt(bolt)?;
    let pull =
        bolts
            .boundary()
            .force("rebar", BoltNodes::Head, [Some((-F0).into()), None, None])?;
    let layout = bolts.clone();
    let rock = LinearElastic::new(30e9, 0.25, 2700.0)?;
    let mut sim = Simulation::builder(block(LENGTH)?, backend.clone())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(Boundary::new().fix(Range::All))
        .physics(bolts)
        .physics(pull)
        .build()?;
    // f32 cannot balance forces below about 1e-5 of their gross sum.
    let tolerance = if backend.precision_kind() == pcdc_compute::Precision::F32 {
        1e-5
    } else {
        1e-9
    };
    let report = sim.relax(&StaticOptions {
        tolerance,
        max_steps: 2_000_000,
        ..StaticOptions::default()
    })?;
    let profile = pcdc_bolt::output::axial_force_profile(&sim, &layout, 0)?;
    let error = profile
        .iter()
        .map(|&(x, f)| (f - exact(x)).abs() / F0)
        .fold(0.0, f64::max);
    if sim.field(BOLT_SLIP)?.iter().any(|s| *s != 0.0) {
        return Err(SceneError::Measurement(
            "the grout slipped in the elastic pull-out".into(),
        ));
    }
    Ok(Elastic {
        error,
        profile,
        segments: n,
        steps: report.steps,
        wall_s: start.elapsed().as_secs_f64(),
    })
}

/// Runs the pull-out to failure with segments of `p.size` on `backend`.
pub fn run_failure(backend: &Backend, p: &Params) -> Result<Failure, SceneError> {
    let start = Instant::now();
    let n = segments(LENGTH_FAILURE, p.size)?;
    let props = rebar();
    let bolt = Bolt::straight(
        "rebar",
        [0.0; 3],
        [LENGTH_FAILURE, 0.0, 0.0],
        n,
        BoltMaterial::new(props)?,
    )?;
    let bolts = Bolts::new().bolt(bolt)?;
    let pull = bolts.boundary().velocity(
        "rebar",
        BoltNodes::Head,
        [Some((-PULL_VELOCITY).into()), None, None],
    )?;
    let rock = LinearElastic::new(30e9, 0.25, 2700.0)?;
    let s = -CONFINEMENT;
    let mut sim = Simulation::builder(block(LENGTH_FAILURE)?, backend.clone())
        .physics(
            Mechanics::new()
                .material(Range::All, rock)
                .initial_stress(Range::All, [s, s, s, 0.0, 0.0, 0.0]),
        )
        .physics(Boundary::new().fix(Range::All))
        .physics(bolts)
        .physics(pull)
        .local_damping(0.3)
        .build()?;
    let t_end = PULL_DISTANCE / PULL_VELOCITY;
    let samples = 200;
    let mut curve = Vec::with_capacity(samples + 1);
    let mut peak: f64 = 0.0;
    let mut axial_peak: f64 = 0.0;
    let head = sim.mesh().n_nodes();
    for i in 1..=samples {
        sim.run_until(t_end * i as f64 / samples as f64)?;
        let load = -sim.field(BOLT_GROUT_FORCE)?.iter().sum::<f64>();
        let axial = sim
            .field(BOLT_AXIAL_FORCE)?
            .iter()
            .fold(0.0f64, |m, f| m.max(f.abs()));
        peak = peak.max(load);
        axial_peak = axial_peak.max(axial);
        curve.push((-sim.state.u[2 * head], load));
    }
    let cap = capacity();
    let end = curve.last().map_or(0.0, |c| c.1);
    let end_ratio = end / peak;
    Ok(Failure {
        peak_ratio: peak / cap,
        error: (peak / cap - 1.0).abs().max(1.0 - end_ratio),
        end_ratio,
        axial_ratio: axial_peak / props.tensile_yield_force,
        curve,
        segments: n,
        steps: sim.kinematics().step,
        wall_s: start.elapsed().as_secs_f64(),
    })
}
