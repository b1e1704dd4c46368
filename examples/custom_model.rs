//! A user-defined constitutive model on both backends.
//!
//! `DamageElastic` is isotropic elasticity with scalar damage and linear softening:
//! the equivalent strain κ_eq = √(ε:ε) drives the history variable κ = max κ_eq, the
//! damage is d = κ_f (κ − κ₀) / (κ (κ_f − κ₀)) clamped to [0, 1] once κ > κ₀, and
//! σ = (1 − d)(λ tr ε I + 2μ ε). The CPU code is `ConstitutiveModel::update`; the GPU
//! code is the WGSL body returned by `ConstitutiveModel::wgsl`, which repeats the same
//! operations in the same order so that f64 results agree to rounding.
//!
//! The scene: a 0.10 × 0.05 m plate, left edge held, right edge pulled at 0.2 m/s until
//! the plate has softened. It runs on the CPU, then on the GPU (when an adapter exists),
//! and reports the largest relative displacement difference between the two.
//!
//! Run: `cargo run --release --example custom_model` (both backends; GPU skipped with a
//! message when no adapter exists), `-- --backend cpu` (CPU only), `-- --backend gpu`
//! (GPU required), `-- --backend gpu --precision f32` (GPU in f32). In f64 the two runs
//! agree to rounding (measured on lavapipe: identical). In f32 they do not, and the line
//! says so (pass=false): once the plate softens, the damage localises in whichever
//! elements round first, so f32 rounding picks a different crack path — a bifurcation,
//! not an f32 bug; compare f32 runs with each other, not with the f64 CPU, after the peak.

#[path = "common/cli.rs"]
mod cli;

use std::time::Instant;

use pcdc::compute::{Backend, BackendKind, Simulation};
use pcdc::mech::{double_dot, Boundary, ConstitutiveModel, Mechanics, Sym6, WgslModel};
use pcdc::mesh::{builders, Range};
use pcdc_validation::report::{self, ResultLine};

const ABOUT: &str =
    "A user-defined constitutive model (damage elasticity) on both backends, CPU and GPU compared";

/// Isotropic damage-elasticity with linear softening (one history variable: κ).
#[derive(Clone, Debug)]
struct DamageElastic {
    /// Young's modulus E (Pa).
    young: f64,
    /// Poisson's ratio ν.
    poisson: f64,
    /// Density ρ (kg/m³).
    density: f64,
    /// Equivalent strain at damage onset κ₀.
    kappa0: f64,
    /// Equivalent strain at full damage κ_f.
    kappa_f: f64,
}

impl DamageElastic {
    fn lame(&self) -> (f64, f64) {
        let (e, nu) = (self.young, self.poisson);
        (
            e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            e / (2.0 * (1.0 + nu)),
        )
    }

    fn damage(&self, kappa: f64) -> f64 {
        if kappa > self.kappa0 {
            f64::min(
                1.0,
                (self.kappa_f * (kappa - self.kappa0)) / (kappa * (self.kappa_f - self.kappa0)),
            )
        } else {
            0.0
        }
    }
}

/// The GPU version of `update`, operation for operation.
const DAMAGE_ELASTIC_WGSL: &str = r#"
let l = param(p, 0u);
let mu = param(p, 1u);
let k0 = param(p, 2u);
let kf = param(p, 3u);
let eq = sqrt(strain[0] * strain[0] + strain[1] * strain[1] + strain[2] * strain[2]
    + 2.0 * (strain[3] * strain[3] + strain[4] * strain[4] + strain[5] * strain[5]));
let kappa = max((*state)[0], eq);
(*state)[0] = kappa;
var d = Real(0.0);
if kappa > k0 {
    d = min(Real(1.0), (kf * (kappa - k0)) / (kappa * (kf - k0)));
}
let w = 1.0 - d;
let tr = strain[0] + strain[1] + strain[2];
return Sym(
    w * (l * tr + 2.0 * mu * strain[0]),
    w * (l * tr + 2.0 * mu * strain[1]),
    w * (l * tr + 2.0 * mu * strain[2]),
    w * (2.0 * mu * strain[3]),
    w * (2.0 * mu * strain[4]),
    w * (2.0 * mu * strain[5]),
);
"#;

impl ConstitutiveModel for DamageElastic {
    fn name(&self) -> &str {
        "damage-elastic (example)"
    }
    fn density(&self) -> f64 {
        self.density
    }
    fn young(&self) -> f64 {
        self.young
    }
    fn wave_modulus(&self) -> f64 {
        let (l, m) = self.lame();
        l + 2.0 * m
    }
    fn damp_factor(&self) -> f64 {
        0.0
    }
    fn n_state(&self) -> usize {
        1
    }
    fn update(&self, strain: &Sym6, _dstrain: &Sym6, stress: &mut Sym6, state: &mut [f64]) {
        let (l, mu) = self.lame();
        let s = strain;
        let eq = (s[0] * s[0]
            + s[1] * s[1]
            + s[2] * s[2]
            + 2.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]))
            .sqrt();
        debug_assert!((eq * eq - double_dot(s, s)).abs() <= 1e-12 * eq * eq + 1e-300);
        let kappa = f64::max(state[0], eq);
        state[0] = kappa;
        let w = 1.0 - self.damage(kappa);
        let tr = s[0] + s[1] + s[2];
        *stress = [
            w * (l * tr + 2.0 * mu * s[0]),
            w * (l * tr + 2.0 * mu * s[1]),
            w * (l * tr + 2.0 * mu * s[2]),
            w * (2.0 * mu * s[3]),
            w * (2.0 * mu * s[4]),
            w * (2.0 * mu * s[5]),
        ];
    }
    fn wgsl(&self) -> Option<WgslModel> {
        let (l, mu) = self.lame();
        Some(WgslModel {
            key: "example_damage_elastic".into(),
            body: DAMAGE_ELASTIC_WGSL.into(),
            params: vec![l, mu, self.kappa0, self.kappa_f],
            ..Default::default()
        })
    }
}

/// Outcome of one run: displacement, largest κ, steps, elements, wall time.
pub(crate) struct Run {
    pub(crate) u: Vec<f64>,
    pub(crate) max_damage: f64,
    pub(crate) steps: u64,
    pub(crate) elements: usize,
    pub(crate) wall_s: f64,
}

/// Runs the scene on `backend` (also called by `tests/custom_model.rs`).
pub(crate) fn run(backend: Backend) -> Result<Run, Box<dyn std::error::Error>> {
    let model = DamageElastic {
        young: 20e9,
        poisson: 0.2,
        density: 2500.0,
        kappa0: 1e-4,
        kappa_f: 1e-3,
    };
    let mesh = builders::rectangle(0.0, 0.0, 0.10, 0.05, 0.0025)?;
    let elements = mesh.n_elements();
    let mut sim = Simulation::builder(mesh, backend)
        .physics(Mechanics::new().material(Range::All, model.clone()))
        .physics(
            Boundary::new()
                .velocity(
                    Range::group("left"),
                    [Some(0.0.into()), Some(0.0.into()), None],
                )
                .velocity(Range::group("right"), [Some(0.2.into()), None, None]),
        )
        .build()?;
    // Pull to 0.3 mm (3e-3 mean strain, beyond full damage near the edges).
    let t_end = 3e-4 / 0.2;
    let start = Instant::now();
    sim.run_until(t_end)?;
    let wall_s = start.elapsed().as_secs_f64();
    let kappa = sim.field("model_state")?;
    let max_damage = kappa.iter().map(|&k| model.damage(k)).fold(0.0, f64::max);
    Ok(Run {
        u: sim.state.u.clone(),
        max_damage,
        steps: sim.kinematics().step,
        elements,
        wall_s,
    })
}

fn main() {
    report::finish(
        (|| -> Result<Vec<ResultLine>, Box<dyn std::error::Error>> {
            let args = cli::command("custom_model", ABOUT).get_matches();
            let choice = cli::choice(&args)?;
            let cpu_backend = Backend::cpu(0)?;
            let cpu = run(cpu_backend.clone())?;
            println!(
                "cpu: {} elements, {} steps, {:.2} s, largest damage {:.3}",
                cpu.elements, cpu.steps, cpu.wall_s, cpu.max_damage
            );
            let gpu_backend = match (choice.kind, Backend::gpu(choice.precision)) {
                (_, Ok(b)) => b,
                (BackendKind::Gpu, Err(e)) => return Err(e.into()),
                (BackendKind::Cpu, Err(e)) => {
                    println!("GPU run skipped: {e}");
                    return Ok(vec![]);
                }
            };
            // `--backend cpu` given explicitly: the CPU run alone.
            if choice.kind == BackendKind::Cpu
                && args.value_source("backend") != Some(clap::parser::ValueSource::DefaultValue)
            {
                return Ok(vec![]);
            }
            let gpu = run(gpu_backend.clone())?;
            println!(
                "gpu ({}, {}): {} steps, {:.2} s, largest damage {:.3}",
                gpu_backend.as_gpu().expect("a GPU backend").adapter_name(),
                gpu_backend.precision(),
                gpu.steps,
                gpu.wall_s,
                gpu.max_damage
            );
            let scale = cpu.u.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let diff = cpu
                .u
                .iter()
                .zip(&gpu.u)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            let tol = if gpu_backend.precision_kind() == pcdc::compute::Precision::F64 {
                1e-12
            } else {
                1e-2
            };
            if cpu.max_damage < 0.5 {
                return Err(format!(
                    "the plate did not soften (largest damage {})",
                    cpu.max_damage
                )
                .into());
            }
            Ok(vec![ResultLine::new(
                &gpu_backend,
                "custom_model",
                "gpu_cpu_displacement_rel_diff",
                diff / scale,
                tol,
                gpu.elements,
                gpu.steps,
                gpu.wall_s,
            )])
        })(),
    )
}
