//! Thermally driven cracking of a ring with weak joints (manual 7.6.10, T-M coupling with
//! cracking; the manual's example is qualitative, this scene adds the closed-form onset).
//!
//! A granite ring r_i = 0.02 m to r_o = 0.06 m (heat: k = 3 W/(m·K), C_s = 800
//! J/(kg·K), ρ = 2700 kg/m³; elasticity E = 30 GPa, ν = 0.25, α = 8e-6 1/K, plane
//! strain, stress-free at T_ref = T_o = 20 °C) is split into elements joined by intrinsic
//! cohesive joints on every interior face (weak: T_s = 2 MPa, c = 6 MPa, φ = 30°,
//! G_f1 = 10 N/m, G_f2 = 50 N/m, penalties 10 E open and shear, 100 E overlap). Its
//! inner surface is heated from T_o to T_o + 3 ΔT_c over three diffusion times L²/κ
//! (L = r_o − r_i), then held for one more, while the outer surface stays at T_o. The
//! heat flows through the intact joints and not through broken ones
//! (`JointHeat::FollowDamage`), so the cracks insulate.
//!
//! **Closed form** (Timoshenko & Goodier §152, plane strain with ε_zz = 0, free
//! surfaces, any axisymmetric θ(r) = T(r) − T_ref):
//! σ_θ(r) = E α / ((1 − ν) r²) · [ (r² + r_i²)/(r_o² − r_i²) I(r_o) + I(r) − θ(r) r² ],
//! I(r) = ∫_{r_i}^{r} θ s ds. At the outer surface, where θ = 0, it reduces to
//! σ_θ(r_o) = E α (θ̄ − θ(r_o)) / (1 − ν) with θ̄ the area mean: the outer surface is
//! where the hoop tension is largest, and the first crack is expected there, radial,
//! when σ_θ(r_o) reaches T_s. (In the steady state this is eq. 116 at r = r_o:
//! ΔT_c = T_s · 2 (1 − ν) ln(r_o/r_i) / (E α [1 − 2 k ln(r_o/r_i)]),
//! k = r_i²/(r_o² − r_i²), 18.9 K here.)
//!
//! The scene evaluates σ_θ(r_o) of the closed form from the computed temperature field
//! (element areas times element-mean temperatures) at the step where the first joint
//! starts to soften (damage > 0): the closed-form normal traction on that joint,
//! σ_n = σ_θ cos² β + σ_r sin² β at its midpoint radius (β its angle to the radial
//! direction), must be within 10 % of T_s, ε = |σ_n/T_s − 1|, and the joint must lie
//! within two element sizes of the radius where the closed-form σ_θ peaks (r_o). The
//! traction is taken at the joint, not at r_o: a joint's midpoint lies half an element
//! inside, where σ_θ is lower by a first-order amount (σ_θ(r_o)/T_s at the onset is
//! also reported: measured 1.12, 1.11, 1.06 at 4, 3, 2 mm). The conduction itself is
//! validated by scene 13 and the half-space; this scene tests the coupling to cracking.
//!
//! **Quasi-static loading by density scaling.** Heat diffuses across the ring in
//! L²/κ ≈ 1150 s, while an elastic wave crosses it in 10 µs: stepping the true inertia
//! over the heating would take 10⁹ steps. As FLAC and PFC do for quasi-static
//! problems, the mechanical density is scaled so that a P wave crosses the ring wall
//! [`Params::transits`] times (default 400) during the heating ramp; local damping 0.3
//! removes the kinetic energy. The thermal stage is scheduled automatically against
//! the resulting mechanical step. The example shows the onset does not move when the
//! loading is made twice as slow.

use std::time::Instant;

use pcdc_cohesive::{CohesiveJoints, IntrinsicCzmParams, JOINT_DAMAGE};
use pcdc_compute::{names, Backend, Simulation, Table};
use pcdc_mech::{LinearElastic, Mechanics, ThermalStrain};
use pcdc_mesh::{builders, split_nodes, Dim2, Range};
use pcdc_thermal::{HeatMaterial, JointHeat, Thermal};

use crate::report::SceneError;
// The granite of scene 13 (heat and elasticity).
use crate::scenes::thermal_cylinder::{ALPHA, CAPACITY, DENSITY, K, POISSON, YOUNG};

/// Tolerance on |σ_n/T_s − 1| at the onset (σ_n the closed-form normal traction on the
/// first joint to soften).
pub const TOL: f64 = 0.10;
/// Inner and outer radius (m).
pub const R_IN: f64 = 0.02;
/// See [`R_IN`].
pub const R_OUT: f64 = 0.06;
/// Outer (and initial, and reference) temperature (°C).
pub const T_OUT: f64 = 20.0;
/// Tensile strength of the joints (Pa).
pub const TS: f64 = 2e6;
/// Joint penalties over E: 100 E keeps the joints' elastic compliance (2 h / P_open at
/// the peak traction, eq. 65) at 2 % of the elements'; 10 E relieved a fifth of the hoop
/// strain and delayed the onset accordingly.
const PENALTY: f64 = 100.0;
/// Local damping (Cundall's, `SimulationBuilder::local_damping`). It lags a slowly
/// loaded system: measured at 4 mm and 400 transits, σθ(r_o)/T_s at the onset was
/// 1.12, 1.17 and 1.28 with 0.3, 0.7 and 0.9; 0.3 and 0.1 agree to 1 %, and with none
/// the joints shatter early under the ringing of the sub-cycled thermal load.
const LOCAL_DAMPING: f64 = 0.3;
/// Inner temperature rise at the end of the ramp, in units of [`delta_t_crit`].
const OVERHEAT: f64 = 3.0;
/// Ramp and hold durations, in diffusion times L²/κ.
const RAMP_DIFFUSION_TIMES: f64 = 3.0;
const HOLD_DIFFUSION_TIMES: f64 = 1.0;
/// Steps between damage checks.
const CHECK_EVERY: u64 = 10;
/// Crack-pattern snapshots (evenly spaced in time, the last at the end).
const SNAPSHOTS: usize = 4;

/// Element sizes of the example and the report (m): (r_o − r_i)/10, /13, /20.
pub const SIZES: [f64; 3] = [0.004, 0.003, 0.002];

/// Scene parameters.
#[derive(Clone, Debug)]
pub struct Params {
    /// Element size (m), uniform.
    pub size: f64,
    /// P-wave transits of the ring wall during the heating ramp, which set the density
    /// scaling (more is slower loading, closer to quasi-static, more steps).
    pub transits: f64,
}

impl Params {
    /// The default loading rate at `size`.
    pub fn new(size: f64) -> Self {
        Params {
            size,
            transits: 400.0,
        }
    }
}

/// The steady inner-minus-outer temperature difference at which σ_θ(r_o) (eq. 116)
/// reaches T_s (K).
pub fn delta_t_crit() -> f64 {
    let ln = (R_OUT / R_IN).ln();
    let k = R_IN * R_IN / (R_OUT * R_OUT - R_IN * R_IN);
    TS * 2.0 * (1.0 - POISSON) * ln / (YOUNG * ALPHA * (1.0 - 2.0 * k * ln))
}

/// Diffusion time L²/κ of the ring wall (s).
pub fn diffusion_time() -> f64 {
    let kappa = K / (DENSITY * CAPACITY);
    (R_OUT - R_IN).powi(2) / kappa
}

/// Broken joints at one time.
#[derive(Clone, Debug)]
pub struct Snapshot {
    /// Time (s).
    pub time: f64,
    /// Inner surface temperature rise above T_o (K).
    pub inner_rise: f64,
    /// Midpoints (x, y) of the broken joints (damage 1) (m).
    pub broken: Vec<[f64; 2]>,
    /// Joints softening (0 < damage < 1).
    pub softening: usize,
}

/// Outcome of a run.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Closed-form normal traction on the first softening joint (its radius and
    /// direction) of the computed temperature field at the onset, over T_s.
    pub onset_ratio: f64,
    /// Closed-form σ_θ(r_o) at the onset over T_s.
    pub outer_ratio: f64,
    /// |onset_ratio − 1|.
    pub error: f64,
    /// Inner temperature rise at the onset over [`delta_t_crit`] (above 1: the heating
    /// leads the steady profile).
    pub onset_rise: f64,
    /// Radius of the first softening joint's midpoint (m).
    pub onset_radius: f64,
    /// Angle between the first softening joint and the radial direction (degrees).
    pub onset_tilt_deg: f64,
    /// Radius where the closed-form σ_θ of the onset temperature field is largest (m).
    pub peak_radius: f64,
    /// Whether the first softening joint lies within two sizes of [`Outcome::peak_radius`].
    pub located: bool,
    /// Elements and joints.
    pub elements: usize,
    /// See `elements`.
    pub joints: usize,
    /// Mechanical steps.
    pub steps: u64,
    /// Thermal schedule chosen by the engine.
    pub every: String,
    /// Mechanical density after scaling (kg/m³).
    pub scaled_density: f64,
    /// Wall time (s).
    pub wall_s: f64,
    /// Time (s), σ_θ(r_o)/T_s of the closed form, joints with damage > 0, sampled.
    pub history: Vec<[f64; 3]>,
    /// Crack pattern over time.
    pub snapshots: Vec<Snapshot>,
}

impl Outcome {
    /// Whether the scene passes: onset within [`TOL`] at the right place.
    pub fn passes(&self) -> bool {
        self.error <= TOL && self.located
    }
}

/// Runs the scene on `backend`.
pub fn run(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    let start = Instant::now();
    if !(p.size > 0.0 && p.transits >= 1.0) {
        return Err(SceneError::Measurement(format!(
            "size {} m and transits {} must be positive (transits ≥ 1)",
            p.size, p.transits
        )));
    }
    let mesh = builders::ring([0.0, 0.0], R_IN, R_OUT, p.size, p.size)?;
    let split = split_nodes(&mesh, &Range::All)?;
    let joints = split.interfaces().clone();
    let t_ramp = RAMP_DIFFUSION_TIMES * diffusion_time();
    let t_end = t_ramp + HOLD_DIFFUSION_TIMES * diffusion_time();
    let rise = OVERHEAT * delta_t_crit();
    let inner = Table::new(
        "inner temperature",
        &[(0.0, T_OUT), (t_ramp, T_OUT + rise), (t_end, T_OUT + rise)],
    )?;
    // Density scaling: a P wave crosses the wall `transits` times during the ramp.
    let modulus = YOUNG * (1.0 - POISSON) / ((1.0 + POISSON) * (1.0 - 2.0 * POISSON));
    let wave = p.transits * (R_OUT - R_IN) / t_ramp;
    let scaled_density = modulus / (wave * wave);
    let elastic = LinearElastic::new(YOUNG, POISSON, scaled_density)?;
    let czm = IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 6e6,
        tensile_strength: TS,
        gf1: 10.0,
        gf2: 50.0,
        penalty_open: PENALTY * YOUNG,
        penalty_shear: PENALTY * YOUNG,
        penalty_overlap: PENALTY * YOUNG,
    }
    .build()?;
    let mut sim = Simulation::builder(split, backend.clone())
        .local_damping(LOCAL_DAMPING)
        .physics(Mechanics::new().material(Range::All, ThermalStrain::new(elastic, ALPHA, T_OUT)?))
        .physics(CohesiveJoints::new().model(Range::All, czm))
        .physics(
            Thermal::new()
                .material(Range::All, HeatMaterial::new(K, CAPACITY, DENSITY)?)
                .initial_temperature(T_OUT)
                .temperature(Range::group("inner"), inner.clone())
                .temperature(Range::group("outer"), T_OUT)
                .joints(JointHeat::FollowDamage),
        )
        .build()?;
    let every = sim
        .field_stages()
        .iter()
        .map(|s| format!("{:?}", s.cycle))
        .collect::<Vec<_>>()
        .join(", ");
    let geometry = ElementRings::new(sim.mesh());
    let mut history = Vec::new();
    let mut snapshots = Vec::new();
    let mut onset: Option<(f64, f64, f64, [f64; 2], f64, f64)> = None;
    let snapshot_every = t_end / SNAPSHOTS as f64;
    let mut next_snapshot = snapshot_every;
    let max_steps = 50_000_000u64;
    loop {
        sim.run(CHECK_EVERY)?;
        let time = sim.kinematics().time;
        let damage = sim.field(JOINT_DAMAGE)?;
        let active = damage.iter().filter(|&&d| d > 0.0).count();
        if onset.is_none() && active > 0 {
            let profile = geometry.hoop_stress(sim.field(names::TEMPERATURE)?);
            let first = damage
                .iter()
                .enumerate()
                .filter(|(_, &d)| d > 0.0)
                .max_by(|a, b| a.1.total_cmp(b.1))
                .map(|(j, _)| j)
                .expect("a joint with damage");
            let (mid, tilt) = joint_geometry(sim.mesh(), &joints, first);
            let r = (mid[0] * mid[0] + mid[1] * mid[1]).sqrt();
            let pair = [
                joints.elements()[2 * first],
                joints.elements()[2 * first + 1],
            ];
            let traction = geometry.joint_traction(sim.field(names::TEMPERATURE)?, r, tilt, pair);
            onset = Some((
                traction / TS,
                profile.outer / TS,
                inner.eval(time) - T_OUT,
                mid,
                tilt,
                profile.peak_radius,
            ));
        }
        if history.len() < 4000 || sim.kinematics().step % (CHECK_EVERY * 50) == 0 {
            let profile = geometry.hoop_stress(sim.field(names::TEMPERATURE)?);
            history.push([time, profile.outer / TS, active as f64]);
        }
        if time >= next_snapshot - 1e-9 * t_end {
            snapshots.push(snapshot(&sim, &joints, time, inner.eval(time) - T_OUT)?);
            next_snapshot += snapshot_every;
        }
        if time >= t_end - 1e-9 * t_end || sim.kinematics().step >= max_steps {
            break;
        }
    }
    let Some((ratio, outer_ratio, rise_at_onset, mid, tilt, peak_radius)) = onset else {
        return Err(SceneError::Measurement(format!(
            "no joint softened by t = {t_end:.0} s (inner rise {rise:.1} K)"
        )));
    };
    let onset_radius = (mid[0] * mid[0] + mid[1] * mid[1]).sqrt();
    Ok(Outcome {
        onset_ratio: ratio,
        outer_ratio,
        error: (ratio - 1.0).abs(),
        onset_rise: rise_at_onset / delta_t_crit(),
        onset_radius,
        onset_tilt_deg: tilt,
        peak_radius,
        located: (onset_radius - peak_radius).abs() <= 2.0 * p.size,
        elements: sim.mesh().n_elements(),
        joints: joints.len(),
        steps: sim.kinematics().step,
        every,
        scaled_density,
        wall_s: start.elapsed().as_secs_f64(),
        history,
        snapshots,
    })
}

/// Midpoint of joint `j` and its angle to the radial direction (degrees, 0 = radial).
fn joint_geometry(
    mesh: &pcdc_mesh::Mesh<Dim2>,
    joints: &pcdc_mesh::Interfaces,
    j: usize,
) -> ([f64; 2], f64) {
    let n = &joints.nodes()[4 * j..4 * j + 2];
    let (a, b) = (mesh.node(n[0] as usize), mesh.node(n[1] as usize));
    let mid = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    let (tx, ty) = (b[0] - a[0], b[1] - a[1]);
    let r = (mid[0] * mid[0] + mid[1] * mid[1]).sqrt();
    let cos = ((tx * mid[0] + ty * mid[1]) / (r * (tx * tx + ty * ty).sqrt())).abs();
    (mid, cos.min(1.0).acos().to_degrees())
}

fn snapshot(
    sim: &Simulation<Dim2>,
    joints: &pcdc_mesh::Interfaces,
    time: f64,
    inner_rise: f64,
) -> Result<Snapshot, SceneError> {
    let damage = sim.field(JOINT_DAMAGE)?;
    let broken = (0..joints.len())
        .filter(|&j| damage[j] >= 1.0)
        .map(|j| joint_geometry(sim.mesh(), joints, j).0)
        .collect();
    Ok(Snapshot {
        time,
        inner_rise,
        broken,
        softening: damage.iter().filter(|&&d| d > 0.0 && d < 1.0).count(),
    })
}

/// The elements sorted by centroid radius, with their areas, for the closed-form
/// stresses of an axisymmetric temperature field.
struct ElementRings {
    /// (centroid radius, area, element) ascending in radius.
    rings: Vec<(f64, f64, usize)>,
    nodes: Vec<[u32; 3]>,
}

/// The closed-form σ_θ of one temperature field.
struct HoopProfile {
    /// σ_θ(r_o) (Pa).
    outer: f64,
    /// Radius of the largest σ_θ over the element centroids and r_o (m).
    peak_radius: f64,
}

impl ElementRings {
    fn new(mesh: &pcdc_mesh::Mesh<Dim2>) -> Self {
        let mut c = [0.0; 2];
        let mut rings: Vec<(f64, f64, usize)> = (0..mesh.n_elements())
            .map(|e| {
                mesh.element_centroid(e, &mut c);
                (
                    (c[0] * c[0] + c[1] * c[1]).sqrt(),
                    mesh.element_measure(e),
                    e,
                )
            })
            .collect();
        rings.sort_by(|a, b| a.0.total_cmp(&b.0));
        let nodes = (0..mesh.n_elements())
            .map(|e| {
                let n = mesh.element(e);
                [n[0], n[1], n[2]]
            })
            .collect();
        ElementRings { rings, nodes }
    }

    /// θ = T − T_ref of element `e` (mean of its nodes).
    fn theta(&self, temperature: &[f64], e: usize) -> f64 {
        self.nodes[e]
            .iter()
            .map(|&n| temperature[n as usize] - T_OUT)
            .sum::<f64>()
            / 3.0
    }

    /// I(r) = ∫_{r_i}^{r} θ s ds = (1/2π) Σ area · θ_e over the elements whose centroid
    /// lies inside r (half the share of an element at r, a midpoint rule), and I(r_o).
    fn integrals(&self, temperature: &[f64]) -> Vec<f64> {
        let two_pi = 2.0 * std::f64::consts::PI;
        let mut inside = 0.0;
        let mut out = Vec::with_capacity(self.rings.len() + 1);
        for &(_, a, e) in &self.rings {
            let share = a * self.theta(temperature, e) / two_pi;
            out.push(inside + 0.5 * share);
            inside += share;
        }
        out.push(inside);
        out
    }

    /// Plane-strain σ_r and σ_θ (Pa) at radius r where θ(r) = `theta`, given I(r) and
    /// I(r_o):
    /// σ_r = E α / ((1 − ν) r²) [ (r² − r_i²)/(r_o² − r_i²) I(r_o) − I(r) ],
    /// σ_θ = E α / ((1 − ν) r²) [ (r² + r_i²)/(r_o² − r_i²) I(r_o) + I(r) − θ r² ].
    fn closed_form(r: f64, theta: f64, i_r: f64, i_o: f64) -> (f64, f64) {
        let scale = YOUNG * ALPHA / ((1.0 - POISSON) * r * r);
        let span = R_OUT * R_OUT - R_IN * R_IN;
        (
            scale * ((r * r - R_IN * R_IN) / span * i_o - i_r),
            scale * ((r * r + R_IN * R_IN) / span * i_o + i_r - theta * r * r),
        )
    }

    /// The closed-form σ_θ at r_o (where θ = 0: σ_θ = E α θ̄ / (1 − ν), θ̄ the area
    /// mean) and where it peaks.
    fn hoop_stress(&self, temperature: &[f64]) -> HoopProfile {
        let integrals = self.integrals(temperature);
        let i_o = *integrals.last().expect("I(r_o)");
        let outer = Self::closed_form(R_OUT, 0.0, i_o, i_o).1;
        let (mut best, mut peak_radius) = (outer, R_OUT);
        for (k, &(r, _, e)) in self.rings.iter().enumerate() {
            let s = Self::closed_form(r, self.theta(temperature, e), integrals[k], i_o).1;
            if s > best {
                best = s;
                peak_radius = r;
            }
        }
        HoopProfile { outer, peak_radius }
    }

    /// The closed-form normal traction (Pa) on a joint at radius r whose line is
    /// `tilt_deg` from radial, between elements `pair`: σ_θ cos² + σ_r sin², with θ the
    /// mean of the two elements and I(r) interpolated between the element rings.
    fn joint_traction(&self, temperature: &[f64], r: f64, tilt_deg: f64, pair: [u32; 2]) -> f64 {
        let integrals = self.integrals(temperature);
        let i_o = *integrals.last().expect("I(r_o)");
        let k = self.rings.partition_point(|&(rc, _, _)| rc < r);
        let i_r = if k == 0 {
            0.0
        } else if k == self.rings.len() {
            i_o
        } else {
            let (r0, r1) = (self.rings[k - 1].0, self.rings[k].0);
            let w = if r1 > r0 { (r - r0) / (r1 - r0) } else { 0.5 };
            integrals[k - 1] + w * (integrals[k] - integrals[k - 1])
        };
        let theta = 0.5
            * (self.theta(temperature, pair[0] as usize)
                + self.theta(temperature, pair[1] as usize));
        let (sr, st) = Self::closed_form(r, theta, i_r, i_o);
        let c = tilt_deg.to_radians().cos();
        st * c * c + sr * (1.0 - c * c)
    }
}
