//! The Brazilian (indirect tensile) test: a rock disc compressed along a diameter between
//! two steel platens, plane strain.
//!
//! Disc (SI units): diameter 0.05 m, 2 mm elements (unstructured by default,
//! [`DiscPattern`]), every element
//! with its own nodes and an intrinsic cohesive joint on every interior face, with the
//! joints, rock, platens and contact of the UCS scene ([`crate::scenes::ucs`]). The
//! platens touch the disc's lowest and highest nodes and move towards each other.
//!
//! The indirect tensile strength is σ_t = 2 P / (π D t) with P the peak load and
//! t = 1 m (plane strain, per unit thickness: P is in N/m). It is compared with the
//! joints' T_s: the ratio must lie in 0.7–1.5. No closed form ties the two in FDEM
//! (the disc fails through the joints of a mesh that does not follow the stress, the
//! contact zones crush, and the elastic solution behind 2P/(πD) ignores both), and
//! FDEM studies of the test calibrated with cohesive joints report Brazilian strengths
//! of the order of T_s rather than equal to it; the band admits that spread and still
//! catches a joint law or load measurement that is off by a large factor.

use serde::{Deserialize, Serialize};

use pcdc_compute::Backend;
use pcdc_mesh::builders;

use super::platen_test::{
    self, positive, BrokenCount, ContactParams, Crack, JointParams, Loading, Output, ParamError,
    Platens, Progress, Rock, Sample,
};
use crate::report::SceneError;

/// The accepted band of σ_t / T_s.
pub const RATIO_BAND: (f64, f64) = (0.7, 1.5);

/// The disc's size and mesh.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DiscSize {
    /// Diameter D (m).
    pub diameter: f64,
    /// Element size (m).
    pub mesh_size: f64,
    /// Triangulation.
    pub pattern: DiscPattern,
    /// Seed of the unstructured mesh.
    pub seed: u64,
}

impl Default for DiscSize {
    /// D = 50 mm, 2 mm elements, unstructured, seed 0.
    fn default() -> Self {
        DiscSize {
            diameter: 0.05,
            mesh_size: 0.002,
            pattern: DiscPattern::Unstructured,
            seed: 0,
        }
    }
}

/// How the disc is triangulated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DiscPattern {
    /// Concentric rings of nodes stitched into bands ([`builders::disc`]).
    Rings,
    /// An unstructured quality mesh ([`pcdc_mesh::mesher::disc`]). The default.
    #[default]
    Unstructured,
}

/// The disc's mesh (one body), centre (0, D/2).
pub fn specimen(p: &Params) -> Result<pcdc_mesh::Mesh<pcdc_mesh::Dim2>, SceneError> {
    let d = p.disc.diameter;
    Ok(match p.disc.pattern {
        DiscPattern::Rings => builders::disc([0.0, 0.5 * d], 0.5 * d, p.disc.mesh_size)?,
        DiscPattern::Unstructured => {
            pcdc_mesh::mesher::disc([0.0, 0.5 * d], 0.5 * d, p.disc.mesh_size, p.disc.seed)?
        }
    })
}

/// The scene tag of a Brazilian scene file (`scene = "brazilian"`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BrazilianTag {
    /// The Brazilian test.
    #[default]
    Brazilian,
}

/// All parameters of the Brazilian scene; the TOML form is `scenes/brazilian.toml`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// Scene tag (`"brazilian"`).
    pub scene: BrazilianTag,
    /// Disc size and mesh.
    pub disc: DiscSize,
    /// Steel platens.
    pub platens: Platens,
    /// Rock elasticity and damping.
    pub rock: Rock,
    /// Cohesive joints.
    pub joints: JointParams,
    /// Contact.
    pub contact: ContactParams,
    /// Loading.
    pub loading: Loading,
    /// Outputs.
    pub output: Output,
}

impl Default for Params {
    /// Full size: D = 50 mm, 2 mm mesh, platens 10 × 56 mm; each platen at 0.02 m/s,
    /// ramped over 0.1 ms (about 7 P-wave transits of the disc); stop once the load has
    /// fallen to half its peak.
    fn default() -> Self {
        Params {
            scene: BrazilianTag::Brazilian,
            disc: DiscSize::default(),
            platens: Platens::default(),
            rock: Rock::default(),
            joints: JointParams::default(),
            contact: ContactParams::default(),
            loading: Loading {
                platen_velocity: 0.02,
                ramp_time: 1e-4,
                stop_fraction: 0.5,
                max_closure: 0.01,
                record_every: 50,
            },
            output: Output {
                dir: "out/brazilian".into(),
                frames: 30,
            },
        }
    }
}

impl Params {
    /// The full-size scene (same as [`Default`]).
    pub fn full() -> Self {
        Self::default()
    }

    /// Reduced size for tests: 4 mm elements, platens at 0.04 m/s, no VTU output.
    pub fn reduced() -> Self {
        let mut p = Self::default();
        p.disc.mesh_size = 0.004;
        p.loading.platen_velocity = 0.04;
        p.loading.ramp_time = 5e-5;
        p.loading.record_every = 25;
        p.output.frames = 0;
        p
    }

    /// Checks every value; the error names the key as written in a scene file.
    pub fn validate(&self) -> Result<(), ParamError> {
        platen_test::dimension("disc.diameter", self.disc.diameter)?;
        positive("disc.mesh_size", self.disc.mesh_size)?;
        if self.disc.mesh_size > 0.5 * self.disc.diameter {
            return Err(ParamError {
                key: "disc.mesh_size".into(),
                value: self.disc.mesh_size,
                reason: "must not exceed the disc's radius",
            });
        }
        platen_test::validate_common(
            &self.rock,
            &self.platens,
            &self.joints,
            &self.contact,
            &self.loading,
            &self.output,
        )
    }

    /// Refuses a scene whose mesh (disc and platens at `disc.mesh_size`) would need more
    /// memory than the [limit](pcdc_mesh::memory); see
    /// [`check_scene_memory`](crate::scenes::limits::check_scene_memory).
    pub fn check_memory(&self) -> Result<(), pcdc_mesh::MeshError> {
        let r = 0.5 * self.disc.diameter;
        let area = std::f64::consts::PI * r * r + 2.0 * self.platens.width * self.platens.height;
        crate::scenes::limits::check_scene_memory("disc.mesh_size", self.disc.mesh_size, area)
    }
}

/// What the Brazilian test measured.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Peak load per unit thickness P (N/m).
    pub peak_load: f64,
    /// Indirect tensile strength σ_t = 2 P / (π D) (Pa).
    pub tensile_strength: f64,
    /// σ_t / T_s.
    pub ratio: f64,
    /// Platen closure at the peak (m).
    pub closure_at_peak: f64,
    /// Kinetic energy of the disc over the elastic strain energy at the peak.
    pub ke_ratio: f64,
    /// The load history.
    pub samples: Vec<Sample>,
    /// Index of the peak sample.
    pub peak_index: usize,
    /// Broken joints by mode.
    pub broken: BrokenCount,
    /// Where the joints broke.
    pub cracks: Vec<Crack>,
    /// Elements (disc and platens).
    pub elements: usize,
    /// Elements of the disc.
    pub disc_elements: usize,
    /// Joints.
    pub joints: usize,
    /// Steps.
    pub steps: u64,
    /// Time step (s).
    pub dt: f64,
    /// What limits the time step.
    pub dt_limit: String,
    /// Wall time (s).
    pub wall_s: f64,
    /// The VTU series, if written.
    pub pvd: Option<std::path::PathBuf>,
}

impl Outcome {
    /// The RESULT metric, ≤ 1 exactly when σ_t / T_s lies in [0.7, 1.5]:
    /// max(0.7 / ratio, ratio / 1.5).
    pub fn band_metric(&self) -> f64 {
        (RATIO_BAND.0 / self.ratio).max(self.ratio / RATIO_BAND.1)
    }
}

/// Runs the Brazilian test on `backend` (cloned into the simulation); `progress` is
/// called at every recorded sample.
pub fn run(
    backend: &Backend,
    p: &Params,
    progress: &mut dyn FnMut(&Progress),
) -> Result<Outcome, SceneError> {
    p.validate()?;
    p.check_memory()?;
    let d = p.disc.diameter;
    let specimen = specimen(p)?;
    let raw = platen_test::run(
        backend,
        &platen_test::Setup {
            specimen,
            size: p.disc.mesh_size,
            rock: &p.rock,
            platens: &p.platens,
            joints: &p.joints,
            contact: &p.contact,
            loading: &p.loading,
            output: &p.output,
            name: "brazilian",
            confinement: None,
            heterogeneity: None,
        },
        progress,
    )?;
    let k = raw.peak_index;
    let peak = raw.samples.get(k).copied().unwrap_or_default();
    let sigma_t = 2.0 * peak.load / (std::f64::consts::PI * d);
    Ok(Outcome {
        peak_load: peak.load,
        tensile_strength: sigma_t,
        ratio: sigma_t / p.joints.tensile_strength,
        closure_at_peak: peak.closure,
        ke_ratio: peak.kinetic / peak.strain_energy,
        samples: raw.samples,
        peak_index: k,
        broken: raw.broken,
        cracks: raw.cracks,
        elements: raw.elements,
        disc_elements: raw.specimen_elements,
        joints: raw.joints,
        steps: raw.steps,
        dt: raw.dt,
        dt_limit: raw.dt_limit,
        wall_s: raw.wall_s,
        pvd: raw.pvd,
    })
}

/// Writes the load history as CSV (`time_s, closure_m, load_n_per_m, kinetic_j,
/// strain_energy_j`).
pub fn write_csv(out: &Outcome, path: &std::path::Path) -> std::io::Result<()> {
    platen_test::write_csv(
        path,
        "time_s,platen_closure_m,load_n_per_m,kinetic_energy_j_per_m,strain_energy_j_per_m",
        out.samples
            .iter()
            .map(|s| vec![s.time, s.closure, s.load, s.kinetic, s.strain_energy]),
    )
}

/// Writes the outputs of a finished Brazilian run into `p.output.dir` (the load history
/// CSV `brazilian_load.csv`, the PNG `brazilian_load.png` of load against platen
/// closure, the crack map `brazilian_cracks.png` when joints broke), prints the summary
/// and returns the RESULT line (metric [`Outcome::band_metric`], tol 1).
pub fn report(
    backend: &Backend,
    p: &Params,
    out: &Outcome,
) -> Result<crate::report::ResultLine, SceneError> {
    let dir = &p.output.dir;
    std::fs::create_dir_all(dir)?;
    let csv = dir.join("brazilian_load.csv");
    write_csv(out, &csv)?;
    let d = p.disc.diameter;
    let closure_um: Vec<f64> = out.samples.iter().map(|s| s.closure * 1e6).collect();
    let load_kn: Vec<f64> = out.samples.iter().map(|s| s.load / 1e3).collect();
    let xmax = closure_um.iter().cloned().fold(0.0, f64::max);
    // The load at which 2P/(πD) equals T_s.
    let p_ts = p.joints.tensile_strength * std::f64::consts::PI * d / 1e3;
    let png = dir.join("brazilian_load.png");
    crate::plot::Plot::new(
        "Brazilian test: load against platen closure (plane strain, per metre)",
        "platen closure (µm)",
        "load P (kN/m)",
    )
    .points(
        format!("FDEM ({} mm mesh)", p.disc.mesh_size * 1e3),
        closure_um,
        load_kn,
    )
    .line(
        "P at which 2P/(πD) = Ts",
        vec![0.0, xmax.max(1.0)],
        vec![0.5 * p_ts, 0.5 * p_ts],
    )
    .save_png(&png)?;
    let outline: Vec<[f64; 2]> = (0..=72)
        .map(|i| {
            let a = i as f64 * std::f64::consts::TAU / 72.0;
            [0.5 * d * a.cos(), 0.5 * d + 0.5 * d * a.sin()]
        })
        .collect();
    let cracks_png = dir.join("brazilian_cracks.png");
    let drew = super::ucs::crack_map(
        &out.cracks,
        &cracks_png,
        "Brazilian test: broken joints (undeformed positions)",
        &outline,
    )?;
    println!(
        "Brazilian test: disc D = {:.0} mm = {} m, mesh {} m, platens {} x {} m; plane strain, t = 1 m (per unit thickness)",
        d * 1e3,
        d,
        p.disc.mesh_size,
        p.platens.height,
        p.platens.width
    );
    println!(
        "joints: Ts = {} MPa, c = {} MPa, phi = {} deg; each platen at {} m/s; dt = {:.3e} s (limited by {})",
        p.joints.tensile_strength / 1e6,
        p.joints.cohesion / 1e6,
        p.joints.friction_deg,
        p.loading.platen_velocity,
        out.dt,
        out.dt_limit
    );
    println!("{:<44} {:>14}", "quantity", "value");
    let row = |name: &str, value: String| println!("{name:<44} {value:>14}");
    row("peak load P (kN/m)", format!("{:.3}", out.peak_load / 1e3));
    row(
        "indirect tensile strength 2P/(pi D) (MPa)",
        format!("{:.3}", out.tensile_strength / 1e6),
    );
    row(
        "sigma_t / Ts (band 0.7-1.5)",
        format!(
            "{:.3} {}",
            out.ratio,
            if out.band_metric() <= 1.0 {
                "ok"
            } else {
                "OUT"
            }
        ),
    );
    row(
        "platen closure at peak (um)",
        format!("{:.2}", out.closure_at_peak * 1e6),
    );
    row(
        "broken joints (of all)",
        format!("{} / {}", out.broken.total(), out.joints),
    );
    row("  tensile (mode I)", format!("{}", out.broken.tensile));
    row("  shear (mode II)", format!("{}", out.broken.shear));
    row("  mixed (I-II)", format!("{}", out.broken.mixed));
    row(
        "kinetic / strain energy at peak (max 1 %)",
        format!("{:.3e}", out.ke_ratio),
    );
    row(
        "elements (disc + platens)",
        format!("{} ({})", out.elements, out.disc_elements),
    );
    row("steps", format!("{}", out.steps));
    row("wall time (s)", format!("{:.1}", out.wall_s));
    if out.ke_ratio > super::ucs::KE_RATIO_MAX {
        println!(
            "WARNING: kinetic energy is {:.2} % of the strain energy at the peak: lower loading.platen_velocity",
            100.0 * out.ke_ratio
        );
    }
    println!("load history: {} and {}", csv.display(), png.display());
    if drew {
        println!("crack map: {}", cracks_png.display());
    }
    if let Some(pvd) = &out.pvd {
        println!(
            "VTU series (ParaView; cells: joint_damage_max, broken_joints, stress, strain, sigma_1, sigma_min): {}",
            pvd.display()
        );
    }
    Ok(crate::report::ResultLine::new(
        backend,
        "brazilian",
        "sigma_t_over_ts_band",
        out.band_metric(),
        1.0,
        out.elements,
        out.steps,
        out.wall_s,
    ))
}
