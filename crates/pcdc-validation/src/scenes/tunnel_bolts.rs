//! A circular tunnel in jointed rock under in-situ stress, with and without a radial
//! bolt pattern (issue 18). No closed form: the scene compares wall convergence, broken
//! joints and bolt forces between the two runs.
//!
//! The ring of the Kirsch scene (opening a = 1 m, outer radius 25 a, graded from the
//! wall; plane strain) of elastic rock (E = 10 GPa, ν = 0.25) starts at σ = −p0 I
//! (p0 = 10 MPa, σzz too) with the traction −p0 on its outer boundary. Within r ≤ 2.5 a
//! the rock is jointed: split into FDEM elements with intrinsic cohesive joints
//! (T_s = 1 MPa, c = 2 MPa, φ = 30°, G_f1 = 10 N/m, G_f2 = 50 N/m) and contact
//! (φ = 30°) once they break. The wall pressure falls from p0 to 0 over
//! [`RELEASE`] seconds (about 10 P-wave transits of the ring's outer radius), then the
//! rock settles for [`HOLD`] seconds, local damping 0.5. The bolted run has 12 radial
//! bolts (25 mm rebar, 1.5 m from the wall, 10 segments, face plates, rows 1 m apart out
//! of plane), installed before the release (pre-reinforcement).
//!
//! Measured per run: the mean and largest radial convergence of the wall (m), the broken
//! joints (damage 1), and for the bolted run the largest and mean peak axial force of the
//! bolts (N per m of tunnel, i.e. per bolt row).

use std::time::Instant;

use pcdc_bolt::{Bolt, BoltMaterial, BoltProperties, Bolts, BOLT_AXIAL_FORCE};
use pcdc_cohesive::{CohesiveJoints, IntrinsicCzmParams, BROKEN_FACE, JOINT_DAMAGE};
use pcdc_compute::{Backend, Simulation, Table};
use pcdc_contact::Contact;
use pcdc_mech::{Boundary, FaceStress, LinearElastic, Mechanics};
use pcdc_mesh::{split_nodes, Dim2, Range};

use crate::report::SceneError;
use crate::scenes::kirsch;

/// In-situ stress p0 (Pa, compression).
pub const P0: f64 = 10e6;
/// Opening radius (m) and radius of the jointed zone (m).
pub const RADIUS: f64 = 1.0;
/// See [`RADIUS`].
pub const JOINTED: f64 = 2.5;
/// Release time of the wall pressure (s) and settling time after it (s).
pub const RELEASE: f64 = 0.05;
/// See [`RELEASE`].
pub const HOLD: f64 = 0.03;
/// Number of bolts and their length from the wall (m).
pub const BOLTS: usize = 12;
/// See [`BOLTS`].
pub const BOLT_LENGTH: f64 = 1.5;
/// Element sizes at the wall, relative to the radius (example and report).
pub const SIZES: [f64; 3] = [0.1, 0.075, 0.05];

const YOUNG: f64 = 10e9;

/// Scene parameters.
#[derive(Clone, Debug)]
pub struct Params {
    /// Element size at the wall (m).
    pub size: f64,
    /// Whether the bolt pattern is installed.
    pub bolted: bool,
}

/// Outcome of one run.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Mean radial convergence of the wall nodes (m, inward positive).
    pub mean_convergence: f64,
    /// Largest radial convergence of a wall node (m).
    pub max_convergence: f64,
    /// Wall convergence against the polar angle: (angle rad, u_r m), by angle.
    pub wall: Vec<(f64, f64)>,
    /// Broken joints at the end.
    pub broken: usize,
    /// Joints in the jointed zone.
    pub joints: usize,
    /// Largest axial force in any bolt segment during the run (N/m), 0 unbolted.
    pub bolt_max: f64,
    /// Mean over the bolts of their largest axial force at the end (N/m).
    pub bolt_mean: f64,
    /// Axial force along bolt 0 at the end: (distance from the head m, N/m).
    pub profile: Vec<(f64, f64)>,
    /// Elements.
    pub elements: usize,
    /// Steps.
    pub steps: u64,
    /// Wall time (s).
    pub wall_s: f64,
}

/// `n` radial bolts evenly around the wall (25 mm rebar, [`BOLT_LENGTH`] from the wall,
/// 10 segments, face plates, rows 1 m apart out of plane); the scene uses [`BOLTS`].
pub fn bolt_pattern(n: usize) -> Result<Bolts, SceneError> {
    let rebar = BoltMaterial::new(BoltProperties {
        spacing: Some(1.0),
        ..BoltProperties::steel_rebar(0.025)
    })?;
    let mut bolts = Bolts::new();
    for i in 0..n {
        // Offset from the axes so that no bolt lies on the supports' symmetry lines.
        let a = 2.0 * std::f64::consts::PI * (i as f64 + 0.5) / n as f64;
        let (c, s) = (a.cos(), a.sin());
        let r1 = RADIUS + BOLT_LENGTH;
        bolts = bolts.bolt(
            Bolt::straight(
                format!("B{i}"),
                [c * RADIUS, s * RADIUS, 0.0],
                [c * r1, s * r1, 0.0],
                10,
                rebar,
            )?
            .face_plate(1e8)?,
        )?;
    }
    Ok(bolts)
}

/// The scene's simulation at element size `size` (m) at the wall, with `bolts` if
/// given (e.g. [`bolt_pattern`]); also used by the `bolted_tunnel` bench.
pub fn simulation(
    backend: &Backend,
    size: f64,
    bolts: Option<Bolts>,
) -> Result<Simulation<Dim2>, SceneError> {
    let mesh = kirsch::mesh(&kirsch::Params {
        radius: RADIUS,
        size_at_hole: size / RADIUS,
        vtu_dir: None,
        element: crate::scenes::Element::Simplex,
    })?;
    let mesh = split_nodes(
        &mesh,
        &Range::Ball {
            center: [0.0; 3],
            radius: JOINTED,
        },
    )?;
    let rock = LinearElastic::new(YOUNG, 0.25, 2600.0)?;
    let joint = IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 2e6,
        tensile_strength: 1e6,
        gf1: 10.0,
        gf2: 50.0,
        penalty_open: 10.0 * YOUNG,
        penalty_shear: 10.0 * YOUNG,
        penalty_overlap: 10.0 * YOUNG,
    }
    .build()?;
    let wall_pressure = Table::new("wall pressure", &[(0.0, -P0), (RELEASE, 0.0)])?;
    let mut builder = Simulation::builder(mesh, backend.clone())
        .physics(
            Mechanics::new()
                .material(Range::All, rock)
                .initial_stress(Range::All, [-P0, -P0, -P0, 0.0, 0.0, 0.0]),
        )
        .physics(CohesiveJoints::new().model(Range::All, joint))
        .physics(
            Contact::new(10.0 * YOUNG)
                .friction(30.0, 10.0 * YOUNG)
                .bonded_interfaces(BROKEN_FACE),
        )
        .physics(kirsch::supports(
            Boundary::new()
                .face_stress(Range::group("outer"), FaceStress::normal(-P0))
                .face_stress(Range::group("inner"), FaceStress::normal(wall_pressure)),
        ))
        .local_damping(0.5);
    if let Some(bolts) = bolts {
        builder = builder.physics(bolts);
    }
    Ok(builder.build()?)
}

/// Runs the scene once.
pub fn run(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    let start = Instant::now();
    let layout = if p.bolted {
        Some(bolt_pattern(BOLTS)?)
    } else {
        None
    };
    let mut sim = simulation(backend, p.size, layout.clone())?;
    let elements = sim.mesh().n_elements();
    let joints = sim.mesh().interfaces().len();
    let mut bolt_max: f64 = 0.0;
    let t_end = RELEASE + HOLD;
    let chunks = 40;
    for k in 1..=chunks {
        sim.run_until(t_end * k as f64 / chunks as f64)?;
        if p.bolted {
            let f = sim.field(BOLT_AXIAL_FORCE)?;
            bolt_max = bolt_max.max(f.iter().fold(0.0f64, |m, v| m.max(v.abs())));
        }
    }
    // Wall convergence: inward radial displacement of the wall nodes.
    let inner = sim.mesh().select_nodes(&Range::group("inner"))?;
    let mut wall: Vec<(f64, f64)> = inner
        .iter()
        .map(|&n| {
            let x = sim.mesh().node(n as usize);
            let r = (x[0] * x[0] + x[1] * x[1]).sqrt();
            let u = &sim.state.u[2 * n as usize..2 * n as usize + 2];
            (x[1].atan2(x[0]), -(u[0] * x[0] + u[1] * x[1]) / r)
        })
        .collect();
    wall.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mean_convergence = wall.iter().map(|w| w.1).sum::<f64>() / wall.len().max(1) as f64;
    let max_convergence = wall.iter().map(|w| w.1).fold(f64::NEG_INFINITY, f64::max);
    let broken = sim
        .field(JOINT_DAMAGE)?
        .iter()
        .filter(|&&d| d >= 1.0)
        .count();
    let (bolt_mean, profile) = match &layout {
        Some(b) => {
            let f = sim.field(BOLT_AXIAL_FORCE)?;
            let mean = (0..BOLTS)
                .map(|i| {
                    b.segment_range(i)
                        .unwrap_or(0..0)
                        .map(|s| f[s].abs())
                        .fold(0.0f64, f64::max)
                })
                .sum::<f64>()
                / BOLTS as f64;
            (mean, pcdc_bolt::output::axial_force_profile(&sim, b, 0)?)
        }
        None => (0.0, Vec::new()),
    };
    Ok(Outcome {
        mean_convergence,
        max_convergence,
        wall,
        broken,
        joints,
        bolt_max,
        bolt_mean,
        profile,
        elements,
        steps: sim.kinematics().step,
        wall_s: start.elapsed().as_secs_f64(),
    })
}
