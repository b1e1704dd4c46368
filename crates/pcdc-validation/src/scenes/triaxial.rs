//! Validation scene: drained triaxial compression and direct tension of one block of
//! Mohr–Coulomb rock (manual 7.2.4, table 2; issue 16).
//!
//! Block (SI units): 0.05 × 0.1 m in plane strain (Tri3) or 0.05 × 0.1 × 0.05 m (Tet4),
//! y the axial direction. Rock of our choice: E = 20 GPa, ν = 0.25, ρ = 2500 kg/m³,
//! c = 5 MPa, φ = 30°, ψ = 10°, σ_t = 2 MPa (below c / tan φ = 8.7 MPa, so not capped).
//! Symmetry planes carry the block: the faces x = 0, y = 0 (and z = 0) hold their normal
//! velocity at zero; the other lateral faces carry the confining stress −σ3 (a face
//! normal stress), the top face moves at −v (ramped over the first 5 % of the run).
//! Every element starts at the isotropic stress −σ3 (σzz too in plane strain), so the
//! block is in equilibrium before loading. Local (Cundall) damping 0.8, FLAC's default
//! for static runs, keeps the loading quasi-static: each run lasts 16 ms, about 440
//! P-wave transits of the block. The loading rate shows in the plateau: on the reduced
//! plane-strain block at σ3 = 0 the error was 5.6e-3 over 8 ms, 2.9e-3 over 16 ms and
//! 1.4e-3 over 32 ms (a lateral stress of inertia and damping: mean σxx −29 kPa at the
//! end of the 8 ms run, −10 kPa of the 32 ms one).
//! At σ3 = 10 MPa a second part, of the opposite sign, shows once the rate part is small
//! (−0.19 % in 2D over 32 ms, −0.27 % in 3D over 16 ms): the element stress is the co-rotated Biot stress (force per reference area),
//! the confining face stress a Cauchy traction on the current, shorter face, and the two
//! differ by the strain (0.6 % axial at the end of the run). Small-strain plasticity has
//! no such difference; it stays well inside the tolerance.
//!
//! Closed forms (compression magnitudes; N_φ = (1 + sin φ)/(1 − sin φ), eq. 31):
//! * the axial stress on the plastic plateau is σ1 = σ3 N_φ + 2c √N_φ (eq. 29 corrected)
//!   for σ3 = 0, 2, 5, 10 MPa; in plane strain σzz stays the intermediate stress, so the
//!   same formula holds;
//! * on the plateau the stresses are constant, so the strain increments are plastic and
//!   their ratio follows the flow rule (eq. 32): dε_v / dε_a = N_ψ − 1 (ε_a axial
//!   shortening, ε_v volume increase; one shear plane in plane strain, the pyramid's edge
//!   σ2 = σ3 in 3D, the same ratio);
//! * in direct tension (σ3 = 0, the top moving up) the axial stress plateaus at σ_t
//!   (eq. 30) and the flow is along the axis only (associated, eq. 33): dε_v/dε_a = 1.
//!
//! Errors: the largest relative error of the plateau stress over the four confinements
//! and the tension test (tolerance [`TOL`]), and the relative error of the dilatancy
//! ratio (tolerance [`DILATANCY_TOL`]). The plateau is the mean over the last 30 % of the
//! axial strain, the dilatancy ratio a least-squares slope over the same window.

use std::time::Instant;

use pcdc_compute::{Backend, Simulation, Table};
use pcdc_mech::mohr_coulomb::state;
use pcdc_mech::{output, Boundary, FaceStress, LinearElastic, Mechanics, MohrCoulomb};
use pcdc_mesh::vtu::PvdSeries;
use pcdc_mesh::{builders, Dim, Dim2, Dim3, Mesh, Range};

use crate::report::SceneError;

/// Young's modulus (Pa).
pub const E: f64 = 20e9;
/// Poisson's ratio.
pub const NU: f64 = 0.25;
/// Cohesion c (Pa).
pub const COHESION: f64 = 5e6;
/// Friction angle φ (degrees).
pub const FRICTION: f64 = 30.0;
/// Dilation angle ψ (degrees).
pub const DILATION: f64 = 10.0;
/// Tensile strength σ_t (Pa).
pub const TENSILE: f64 = 2e6;
/// Confining stresses σ3 (Pa, compression magnitudes).
pub const CONFINEMENTS: [f64; 4] = [0.0, 2e6, 5e6, 10e6];
/// Tolerance on the plateau stresses (relative).
pub const TOL: f64 = 0.01;
/// Tolerance on the dilatancy ratio dε_v/dε_a (relative).
pub const DILATANCY_TOL: f64 = 0.02;
/// Block width (m) and height (m).
pub const WIDTH: f64 = 0.05;
/// See [`WIDTH`].
pub const HEIGHT: f64 = 0.1;
/// Duration of each loading run (s).
const DURATION: f64 = 16e-3;
/// Axial strain at the end of a run, as a multiple of the elastic strain at yield.
const STRAIN_MULTIPLE: f64 = 3.0;
/// Samples per run.
const SAMPLES: usize = 400;

pub use super::Dimension;

/// Scene parameters.
#[derive(Clone, Debug)]
pub struct Params {
    /// Element size (m).
    pub size: f64,
    /// Plane strain or 3D.
    pub dim: Dimension,
    /// Folder for a VTU/PVD series of the σ3 = 10 MPa run (ParaView), if any.
    pub vtu_dir: Option<std::path::PathBuf>,
}

impl Params {
    /// Full size: 5 mm elements (2D) or 12.5 mm (3D).
    pub fn full(dim: Dimension) -> Self {
        Params {
            size: if dim == Dimension::Two { 0.005 } else { 0.0125 },
            dim,
            vtu_dir: None,
        }
    }
    /// Reduced size for tests: 12.5 mm elements (2D) or 25 mm (3D).
    pub fn reduced(dim: Dimension) -> Self {
        Params {
            size: if dim == Dimension::Two { 0.0125 } else { 0.025 },
            dim,
            vtu_dir: None,
        }
    }
}

/// One loading run.
#[derive(Clone, Debug)]
pub struct Curve {
    /// σ3 (Pa, compression magnitude); `None` for the tension test.
    pub confinement: Option<f64>,
    /// Axial strain samples (compression positive in compression runs, extension
    /// positive in the tension run).
    pub axial_strain: Vec<f64>,
    /// Axial stress samples (Pa, same sign convention).
    pub axial_stress: Vec<f64>,
    /// Volumetric strain samples (volume increase positive).
    pub volumetric_strain: Vec<f64>,
    /// The plateau stress (Pa).
    pub plateau: f64,
    /// The closed form of the plateau (Pa).
    pub expected: f64,
    /// The plateau's dilatancy ratio dε_v/dε_a.
    pub dilatancy: f64,
    /// Its closed form: N_ψ − 1 in compression, 1 in tension.
    pub dilatancy_expected: f64,
    /// Elements that have yielded (any plastic flag in the past).
    pub yielded: usize,
    /// Steps.
    pub steps: u64,
}

impl Curve {
    /// Relative error of the plateau.
    pub fn error(&self) -> f64 {
        (self.plateau - self.expected).abs() / self.expected
    }
    /// Relative error of the dilatancy ratio.
    pub fn dilatancy_error(&self) -> f64 {
        (self.dilatancy - self.dilatancy_expected).abs() / self.dilatancy_expected
    }
}

/// Outcome of the scene: four compression runs and one tension run.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The runs, compression first (in [`CONFINEMENTS`] order), tension last.
    pub curves: Vec<Curve>,
    /// Largest relative plateau error.
    pub error: f64,
    /// Largest relative error of the dilatancy ratio over the runs.
    pub dilatancy_error: f64,
    /// Elements.
    pub elements: usize,
    /// Steps of all runs.
    pub steps: u64,
    /// Wall time (s).
    pub wall_s: f64,
}

/// The rock.
pub fn rock() -> Result<MohrCoulomb, SceneError> {
    let e = LinearElastic::new(E, NU, 2500.0)?;
    Ok(MohrCoulomb::new(e, COHESION, FRICTION, DILATION, TENSILE)?)
}

/// N = (1 + sin a)/(1 − sin a), a in degrees (eq. 31).
pub fn n_of(deg: f64) -> f64 {
    let s = deg.to_radians().sin();
    (1.0 + s) / (1.0 - s)
}

/// The closed-form axial stress at yield for confinement σ3 (Pa).
pub fn yield_stress(confinement: f64) -> f64 {
    let n = n_of(FRICTION);
    confinement * n + 2.0 * COHESION * n.sqrt()
}

/// Runs the four compression tests and the tension test.
pub fn run(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    let start = Instant::now();
    let mut curves = Vec::new();
    let mut elements = 0;
    for conf in CONFINEMENTS.map(Some).into_iter().chain([None]) {
        let vtu = (conf == Some(10e6)).then_some(p.vtu_dir.as_ref()).flatten();
        let (c, ne) = match p.dim {
            Dimension::Two => {
                let mesh = builders::rectangle(0.0, 0.0, WIDTH, HEIGHT, p.size)?;
                load::<Dim2>(mesh, backend, conf, vtu)?
            }
            Dimension::Three => {
                let mesh = builders::cuboid([0.0; 3], [WIDTH, HEIGHT, WIDTH], p.size)?;
                load::<Dim3>(mesh, backend, conf, vtu)?
            }
        };
        elements = ne;
        curves.push(c);
    }
    let error = curves.iter().map(Curve::error).fold(0.0, f64::max);
    let dilatancy_error = curves
        .iter()
        .map(Curve::dilatancy_error)
        .fold(0.0, f64::max);
    Ok(Outcome {
        steps: curves.iter().map(|c| c.steps).sum(),
        curves,
        error,
        dilatancy_error,
        elements,
        wall_s: start.elapsed().as_secs_f64(),
    })
}

/// One run: confinement σ3 (compression) or the tension test (`None`).
fn load<D: Dim>(
    mesh: Mesh<D>,
    backend: &Backend,
    confinement: Option<f64>,
    vtu_dir: Option<&std::path::PathBuf>,
) -> Result<(Curve, usize), SceneError> {
    let d = D::D;
    let (names, lateral): (Vec<&str>, Vec<&str>) = if d == 2 {
        (vec!["left", "bottom"], vec!["right"])
    } else {
        (vec!["xmin", "ymin", "zmin"], vec!["xmax", "zmax"])
    };
    let top = if d == 2 { "top" } else { "ymax" };
    let s3 = confinement.unwrap_or(0.0);
    let (expected, yield_strain, sign) = match confinement {
        Some(s3) => (yield_stress(s3), (yield_stress(s3) - s3) / E, -1.0),
        None => (TENSILE, TENSILE / E, 1.0),
    };
    let strain_end = STRAIN_MULTIPLE * yield_strain;
    let v = strain_end * HEIGHT / DURATION;
    let ramp = 0.05 * DURATION;
    // Displacement at the end of a linear ramp then constant speed: v (T − ramp/2).
    let v = v * DURATION / (DURATION - 0.5 * ramp);
    let speed = Table::new("platen velocity", &[(0.0, 0.0), (ramp, sign * v)])?;
    let mut boundary = Boundary::new();
    for (axis, name) in names.iter().enumerate() {
        let mut c = [None, None, None];
        c[axis] = Some(0.0.into());
        boundary = boundary.velocity(Range::group(*name), c);
    }
    let mut c = [None, None, None];
    c[1] = Some(speed.into());
    boundary = boundary.velocity(Range::group(top), c);
    if s3 > 0.0 {
        for name in &lateral {
            boundary = boundary.face_stress(
                Range::group(*name),
                FaceStress {
                    normal: Some((-s3).into()),
                    ..Default::default()
                },
            );
        }
    }
    let mut s0 = [0.0; 6];
    s0[..3].fill(-s3);
    let mut sim = Simulation::builder(mesh, backend.clone())
        .local_damping(0.8)
        .physics(
            Mechanics::new()
                .material(Range::All, rock()?)
                .initial_stress(Range::All, s0),
        )
        .physics(boundary)
        .build()?;
    let ne = sim.mesh().n_elements();
    let top_nodes = sim.mesh().select_nodes(&Range::group(top))?;
    let volume: Vec<f64> = (0..ne).map(|e| sim.mesh().element_measure(e)).collect();
    let vtot: f64 = volume.iter().sum();
    let mut series = vtu_dir
        .map(|dir| PvdSeries::new(dir, "triaxial"))
        .transpose()?;
    let n_steps = (DURATION / sim.dt()).ceil() as u64;
    let every = (n_steps / SAMPLES as u64).max(1);
    let (mut ea, mut sa, mut ev) = (Vec::new(), Vec::new(), Vec::new());
    let nsym = D::NSYM;
    while sim.state.time < DURATION {
        sim.run(every)?;
        let u_top = top_nodes
            .iter()
            .map(|&n| sim.state.u[n as usize * d + 1])
            .sum::<f64>()
            / top_nodes.len() as f64;
        let stress = sim.field("stress")?;
        let strain = sim.field("strain")?;
        let (mut syy, mut tr) = (0.0, 0.0);
        for e in 0..ne {
            syy += volume[e] * stress[e * nsym + 1];
            tr += volume[e] * (0..d).map(|k| strain[e * nsym + k]).sum::<f64>();
        }
        ea.push(sign * u_top / HEIGHT);
        sa.push(sign * syy / vtot);
        ev.push(tr / vtot);
        if let Some(series) = series.as_mut() {
            if ea.len() % (SAMPLES / 20) == 0 {
                output::write_step(series, &sim)?;
            }
        }
    }
    if let Some(series) = series.as_mut() {
        output::write_step(series, &sim)?;
    }
    // The plateau: the last 30 % of the axial strain.
    let from = ea
        .iter()
        .position(|&x| x >= 0.7 * strain_end)
        .ok_or_else(|| {
            SceneError::Measurement(format!(
                "the axial strain never reached the plateau window (last {:e})",
                ea.last().copied().unwrap_or(0.0)
            ))
        })?;
    let window = from..ea.len();
    if window.len() < 10 {
        return Err(SceneError::Measurement(format!(
            "only {} samples on the plateau",
            window.len()
        )));
    }
    let plateau = sa[window.clone()].iter().sum::<f64>() / window.len() as f64;
    let dilatancy = slope(&ea[window.clone()], &ev[window]);
    let history = sim.field("model_state")?;
    let nstate = history.len() / ne;
    let yielded = (0..ne)
        .filter(|&e| {
            history[e * nstate + state::SHEAR_PAST] > 0.0
                || history[e * nstate + state::TENSION_PAST] > 0.0
        })
        .count();
    Ok((
        Curve {
            confinement,
            axial_strain: ea,
            axial_stress: sa,
            volumetric_strain: ev,
            plateau,
            expected,
            dilatancy,
            dilatancy_expected: if confinement.is_some() {
                n_of(DILATION) - 1.0
            } else {
                1.0
            },
            yielded,
            steps: sim.state.step,
        },
        ne,
    ))
}

/// Least-squares slope of y against x.
fn slope(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
    }
    sxy / sxx
}
