//! Validation scenes, specified in `docs/validation-scenes.md`: each runs a model,
//! compares it with a closed form and returns the measured error. Examples run them at
//! full size and print the `RESULT` line; tests run them at reduced size and assert the
//! same tolerance.
//!
//! [`benchmark`] holds the standard FDEM benchmark scenes of the speed measurements.
//!
//! The laboratory tests [`ucs`] and [`brazilian`] share one platen-test set-up
//! ([`platen_test`]) and can be written as TOML scene files ([`file`](mod@file)); their upper
//! bounds and memory guard are in [`limits`].

pub mod benchmark;
pub mod biaxial;
pub mod block_sliding;
pub mod bolt_pullout;
pub mod bolted_shear;
pub mod brazilian;
pub mod creep;
pub mod direct_tension;
pub mod file;
pub mod fracture_flow;
pub mod fragmentation;
pub mod half_space_conduction;
pub mod injection;
pub mod kirsch;
pub mod lauwerier;
pub mod limits;
pub mod platen_test;
pub mod radial_flow;
pub mod slope_excavation;
pub mod thermal_cracking;
pub mod thermal_cylinder;
pub mod triaxial;
pub mod tunnel;
pub mod tunnel_bolts;
pub mod ucs;
pub mod unconfined_flow;
pub mod vibration_energy;
pub mod wave_speed;

/// The dynamic-relaxation options of the static scenes ([`kirsch`], [`tunnel`],
/// [`slope_excavation`]): an unbalanced-force ratio of 1e-6, 1e-5 in f32 (whose force
/// noise of ~1e-7 the ratio, net over gross, amplifies; the f32 error is then reported
/// as measured), at most 400 000 steps, checked every 50.
pub fn relax_options(backend: &pcdc_compute::Backend) -> pcdc_compute::StaticOptions {
    pcdc_compute::StaticOptions {
        tolerance: if backend.precision_kind() == pcdc_compute::Precision::F32 {
            1e-5
        } else {
            1e-6
        },
        max_steps: 400_000,
        check_every: 50,
    }
}

/// Plane strain (Tri3) or 3D (Tet4), for the scenes that run both ([`triaxial`],
/// [`creep`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dimension {
    /// Plane strain, Tri3.
    Two,
    /// 3D, Tet4.
    Three,
}

/// The cells a scene meshes with (`--element` in the examples): simplices, or the
/// Quad4/Hex8 cells of the mixed discretisation ([`pcdc_mech::mixed`]), or a Tri3/Quad4
/// mix.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Element {
    /// Tri3 in 2D, Tet4 in 3D (the default).
    #[default]
    Simplex,
    /// Quad4 cells (2D).
    Quad4,
    /// Quad4 and Tri3 cells in one mesh (2D).
    Mixed,
    /// Hex8 cells (3D).
    Hex8,
}

impl Element {
    /// Short name: `simplex`, `quad4`, `mixed`, `hex8`.
    pub fn name(self) -> &'static str {
        match self {
            Element::Simplex => "simplex",
            Element::Quad4 => "quad4",
            Element::Mixed => "mixed",
            Element::Hex8 => "hex8",
        }
    }

    /// Parses an `--element` value: `tri3`, `tet4` or `simplex` (the same choice), `quad4`,
    /// `mixed`, `hex8`.
    pub fn parse(s: &str) -> Result<Self, crate::report::SceneError> {
        match s {
            "simplex" | "tri3" | "tet4" => Ok(Element::Simplex),
            "quad4" => Ok(Element::Quad4),
            "mixed" => Ok(Element::Mixed),
            "hex8" => Ok(Element::Hex8),
            _ => Err(crate::report::SceneError::Measurement(format!(
                "unknown element '{s}': expected tri3, tet4, quad4, mixed or hex8"
            ))),
        }
    }
}
