//! Validation scene 14: heat exchange between a fracture's flowing fluid and the rock,
//! Lauwerier (1955) (manual 7.6.11; eq. 117–118 corrected in the digest).
//!
//! A granite block 20 m long (x) and 40 m high (y) with an open fracture of aperture
//! δ = 1 mm on its mid-line y = 0, from a (x = 0) to b (x = 20 m). A steady flow of
//! water at mean velocity v = 1 mm/s runs from a to b (pressures held at both ends,
//! `Hydro::steady_flow`). Rock and fluid start at T_i = 20 °C; from t = 0 the fluid at a
//! is held at T_a = 80 °C. With τ = t − x/v, κ = k/(ρ_s C_s) and the fluid's
//! ρ_f C_f, Lauwerier's solution (perfect contact between fluid and wall, conduction in
//! the rock normal to the fracture only, no conduction along the fracture) is
//!
//! fluid: (T − T_i)/(T_a − T_i) = erfc( k x / (ρ_f C_f v δ √(κ τ)) ),
//! rock at |y|: (T − T_i)/(T_a − T_i) = erfc( (k x / (ρ_f C_f v δ) + |y|/2) / √(κ τ) ).
//!
//! Compared: the fluid temperature at every flow node of ab and the rock temperature at
//! every node of cd (y = 5 m), at 50 and 150 days; error = the largest |T − T_exact| over
//! them divided by T_a − T_i, tolerance 5 % (VALIDATION.md scene 14).
//!
//! The model's assumptions are the solution's: the rock conducts across the fracture
//! only (anisotropic k, k_xx = k_yy/1000, as OpenGeoSys runs this benchmark), the fluid
//! does not conduct along the channel (k_f = 0), and fluid and wall are close to
//! Lauwerier's perfect contact with h_sf = 200 W/(m²·K) (the wall flux, about
//! 0.7 W/m² per kelvin of T_a − T_i at 50 days, leaves a fluid–wall difference of
//! 0.4 % of T_a − T_i; measured at 0.5 m: h_sf = 2000 moves the error from 5.35 % to
//! 5.22 % at a tenth of the step). The block's far faces are adiabatic; at y = ±20 m the
//! closed form's rock excess is below 0.1 % at 150 days. The heat runs alone on the
//! settled flow (`Thermal::heat_only`, its own stable step).
//!
//! Measured (CPU, f64): 1.0 m 9.2 %, 0.5 m 5.35 %, then [`SIZES`] 3.6 %, 3.0 %, 2.5 %:
//! first order in the element size along the fracture, the order of the upwind
//! advection the manual prescribes (eq. 104–105); sizes down to 0.5 m miss the 5 %.
//! The sizes divide 5 m so that a line of nodes lies on cd.

use std::time::Instant;

use pcdc_compute::{names, Backend, Simulation};
use pcdc_hydro::{Aperture, Coupling, FlowModel, Fluid, Hydro};
use pcdc_mesh::{builders, split_nodes, Range};
use pcdc_thermal::{Conductivity, FluidHeat, HeatMaterial, JointHeat, Thermal, FLUID_TEMPERATURE};

use crate::report::SceneError;
use crate::scenes::half_space_conduction::erfc;

/// Tolerance, a fraction of T_a − T_i.
pub const TOL: f64 = 0.05;
/// Block length along the fracture (m) and half-height (m).
pub const LENGTH: f64 = 20.0;
/// See [`LENGTH`].
pub const HALF_HEIGHT: f64 = 20.0;
/// Fracture aperture δ (m).
pub const APERTURE: f64 = 1e-3;
/// Mean fluid velocity v (m/s).
pub const VELOCITY: f64 = 1e-3;
/// Initial and inlet temperatures (°C).
pub const T_I: f64 = 20.0;
/// See [`T_I`].
pub const T_A: f64 = 80.0;
/// Rock conductivity across the fracture k (W/(m·K)), specific heat (J/(kg·K)),
/// density (kg/m³).
pub const K: f64 = 3.0;
const CAPACITY: f64 = 800.0;
const DENSITY: f64 = 2700.0;
/// Solid–fluid transfer coefficient h_sf (W/(m²·K)).
pub const TRANSFER: f64 = 200.0;
/// Distance of the rock line cd from the fracture (m).
pub const Y_CD: f64 = 5.0;
/// Comparison times (s): 50 and 150 days.
pub const TIMES: [f64; 2] = [50.0 * 86400.0, 150.0 * 86400.0];
/// Element sizes of the example and the report (m).
pub const SIZES: [f64; 3] = [0.3125, 0.25, 0.2];

/// Rock diffusivity across the fracture κ = k/(ρ_s C_s) (m²/s).
pub fn kappa() -> f64 {
    K / (DENSITY * CAPACITY)
}

/// The water of the scene.
pub fn water() -> FluidHeat {
    // k_f = 0: Lauwerier leaves out conduction along the fracture.
    FluidHeat::new(0.0, 4186.0, 1000.0, TRANSFER).expect("valid constants")
}

/// Lauwerier's temperature (°C) at distance x along the fracture and |y| from it, time
/// t, for the fluid velocity `v` (|y| = 0: the fluid).
pub fn exact(x: f64, y: f64, t: f64, v: f64) -> f64 {
    let tau = t - x / v;
    if tau <= 0.0 {
        return T_I;
    }
    let a = K * x / (water().volumetric_capacity() * v * APERTURE) + 0.5 * y.abs();
    T_I + (T_A - T_I) * erfc(a / (kappa() * tau).sqrt())
}

/// Scene parameters.
#[derive(Clone, Debug)]
pub struct Params {
    /// Element size (m).
    pub size: f64,
}

/// Temperatures along a line at one time.
#[derive(Clone, Debug)]
pub struct Profile {
    /// Time (s).
    pub time: f64,
    /// x (m) and T (°C) of the fluid nodes of ab, by x.
    pub fluid: Vec<(f64, f64)>,
    /// x (m) and T (°C) of the rock nodes of cd, by x.
    pub rock: Vec<(f64, f64)>,
}

/// Outcome of a run.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Largest |T − T_exact| / (T_a − T_i), fluid and rock, both times.
    pub error: f64,
    /// The fluid's part of `error`.
    pub error_fluid: f64,
    /// The rock's part of `error`.
    pub error_rock: f64,
    /// The mean velocity of the solved flow (m/s).
    pub velocity: f64,
    /// Elements.
    pub elements: usize,
    /// Thermal steps.
    pub steps: u64,
    /// The thermal step (s).
    pub dt: f64,
    /// Wall time (s).
    pub wall_s: f64,
    /// Profiles at the comparison times.
    pub profiles: Vec<Profile>,
}

/// Runs the scene with elements of `p.size` on `backend`.
pub fn run(backend: &Backend, p: &Params) -> Result<Outcome, SceneError> {
    let start = Instant::now();
    let mesh = builders::rectangle(0.0, -HALF_HEIGHT, LENGTH, 2.0 * HALF_HEIGHT, p.size)?;
    let elements = mesh.n_elements();
    // Joints only around the fracture: its channels and their walls.
    let band = Range::rect(-1.0, -1.01 * p.size, LENGTH + 1.0, 1.01 * p.size);
    let mesh = split_nodes(&mesh, &band)?;
    let fluid = Fluid::water();
    let eps = 1e-6 * p.size;
    let inlet = Range::rect(-eps, -eps, eps, eps);
    let outlet = Range::rect(LENGTH - eps, -eps, LENGTH + eps, eps);
    // Cubic law: v = δ² Δp / (12 μ_d L).
    let dp = 12.0 * fluid.dynamic_viscosity() * VELOCITY * LENGTH / (APERTURE * APERTURE);
    let flow = Hydro::new(FlowModel::new(fluid, Aperture::fixed(APERTURE)?))
        .coupling(Coupling::FlowOnly)
        .network_on(Range::plane([0.0; 3], [0.0, 1.0, 0.0], eps))
        .pressure(inlet.clone(), dp)
        .pressure(outlet, 0.0)
        .steady_flow();
    let rock = HeatMaterial::with_conductivity(
        Conductivity::Anisotropic([K / 1000.0, K, 0.0, 0.0, 0.0, 0.0]),
        CAPACITY,
        DENSITY,
    )?;
    let heat = Thermal::new()
        .material(Range::All, rock)
        .initial_temperature(T_I)
        .joints(JointHeat::Conducting)
        .fluid(water())
        .fluid_temperature(inlet, T_A)
        .heat_only();
    let mut sim = Simulation::builder(mesh, backend.clone())
        .physics(flow)
        .physics(heat)
        .build()?;
    // The velocity the flow solve gives (the closed form takes it).
    let q = sim.field(names::CHANNEL_FLUX)?;
    let velocity = q.chunks(2).map(|c| c[0]).sum::<f64>() / (q.len() / 2) as f64 / APERTURE;
    let flow_nodes: Vec<u32> = sim
        .entity_set(names::FLOW_NODES)
        .ok_or_else(|| SceneError::Measurement("no flow network".into()))?
        .nodes()
        .to_vec();
    let cd: Vec<usize> = (0..sim.mesh().n_nodes())
        .filter(|&n| (sim.mesh().node(n)[1] - Y_CD).abs() < eps)
        .collect();
    let (mut error_fluid, mut error_rock) = (0.0f64, 0.0f64);
    let mut profiles = Vec::new();
    for t_cmp in TIMES {
        while sim.kinematics().time < t_cmp * (1.0 - 1e-12) {
            sim.step()?;
        }
        let time = sim.kinematics().time;
        let tf = sim.field(FLUID_TEMPERATURE)?;
        let ts = sim.field(names::TEMPERATURE)?;
        let mut fluid: Vec<(f64, f64)> = flow_nodes
            .iter()
            .zip(tf)
            .map(|(&n, &t)| (sim.mesh().node(n as usize)[0], t))
            .collect();
        let mut rock: Vec<(f64, f64)> =
            cd.iter().map(|&n| (sim.mesh().node(n)[0], ts[n])).collect();
        fluid.sort_by(|a, b| a.0.total_cmp(&b.0));
        rock.sort_by(|a, b| a.0.total_cmp(&b.0));
        for &(x, t) in &fluid {
            error_fluid = error_fluid.max((t - exact(x, 0.0, time, velocity)).abs() / (T_A - T_I));
        }
        for &(x, t) in &rock {
            error_rock = error_rock.max((t - exact(x, Y_CD, time, velocity)).abs() / (T_A - T_I));
        }
        profiles.push(Profile { time, fluid, rock });
    }
    Ok(Outcome {
        error: error_fluid.max(error_rock),
        error_fluid,
        error_rock,
        velocity,
        elements,
        steps: sim.kinematics().step,
        dt: sim.dt(),
        wall_s: start.elapsed().as_secs_f64(),
        profiles,
    })
}
