//! Linear elasticity: constructors, setters and deserialisation share one check.

use pcdc_compute::{Backend, Simulation};
use pcdc_mech::{ConstitutiveModel, LinearElastic, Mechanics, Sym6};
use pcdc_mesh::{builders, Range};

use crate::{case, run};

/// A plugin model that reports whatever it is given.
#[derive(Debug)]
struct Plugin {
    density: f64,
    modulus: f64,
    damping: f64,
}

impl ConstitutiveModel for Plugin {
    fn name(&self) -> &str {
        "plugin"
    }
    fn density(&self) -> f64 {
        self.density
    }
    fn young(&self) -> f64 {
        self.modulus
    }
    fn wave_modulus(&self) -> f64 {
        self.modulus
    }
    fn damp_factor(&self) -> f64 {
        self.damping
    }
    fn update(&self, _: &Sym6, _: &Sym6, _: &mut Sym6, _: &mut [f64]) {}
}

/// Builds a 2D simulation with the plugin model.
fn with_plugin(density: f64, modulus: f64, damping: f64) -> Result<(), pcdc_compute::ComputeError> {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    let model = Plugin {
        density,
        modulus,
        damping,
    };
    Simulation::builder(mesh, Backend::cpu(1)?)
        .physics(Mechanics::new().material(Range::All, model))
        .build()
        .map(|_| ())
}

fn json(text: &'static str) -> Result<LinearElastic, serde_json::Error> {
    serde_json::from_str(text)
}

fn rock() -> LinearElastic {
    LinearElastic::new(30e9, 0.25, 2600.0).unwrap()
}

#[test]
fn bad_materials_are_named_errors() {
    run(
        "materials",
        vec![
            case("negative E", "Young's modulus E (young) = -1", || {
                LinearElastic::new(-1.0, 0.25, 2600.0)
            }),
            case("NaN E", "Young's modulus E (young) = NaN", || {
                LinearElastic::new(f64::NAN, 0.25, 2600.0)
            }),
            case("ν = 0.5", "Poisson's ratio ν (poisson) = 0.5", || {
                LinearElastic::new(30e9, 0.5, 2600.0)
            }),
            case("ν = -1", "Poisson's ratio ν (poisson) = -1", || {
                LinearElastic::new(30e9, -1.0, 2600.0)
            }),
            case("ν = 0.7", "bulk and shear moduli are positive", || {
                LinearElastic::new(30e9, 0.7, 2600.0)
            }),
            case("zero density", "density ρ (density) = 0", || {
                LinearElastic::new(30e9, 0.25, 0.0)
            }),
            case(
                "negative damping",
                "damping factor D_f (damp_factor) = -1",
                || rock().with_damping(-1.0),
            ),
            case("friction 90°", "friction angle (friction) = 90", || {
                rock().with_contact(90.0, None)
            }),
            case(
                "negative contact penalty",
                "contact penalty (contact_penalty) = -1",
                || rock().with_contact(30.0, Some(-1.0)),
            ),
            case("negative bulk modulus", "bulk modulus K = -1", || {
                LinearElastic::from_bulk_shear(-1.0, 1e9, 2600.0)
            }),
            case("zero shear modulus", "shear modulus G = 0", || {
                LinearElastic::from_bulk_shear(1e9, 0.0, 2600.0)
            }),
            case("json: ν = 0.5", "(poisson) = 0.5", || {
                json(r#"{"young":30e9,"poisson":0.5,"density":2600}"#)
            }),
            case("json: E < 0", "(young) = -30000000000", || {
                json(r#"{"young":-30e9,"poisson":0.25,"density":2600}"#)
            }),
            case("json: negative damping", "(damp_factor) = -0.5", || {
                json(r#"{"young":30e9,"poisson":0.25,"density":2600,"damp_factor":-0.5}"#)
            }),
            case("json: unknown key", "unknown field `poison`", || {
                json(r#"{"young":30e9,"poison":0.25,"density":2600}"#)
            }),
            case("json: missing density", "missing field `density`", || {
                json(r#"{"young":30e9,"poisson":0.25}"#)
            }),
            case(
                "plugin: NaN density",
                "density of material 0 (plugin) = NaN",
                || with_plugin(f64::NAN, 1e10, 0.0),
            ),
            case(
                "plugin: negative wave modulus",
                "wave modulus of material 0 (plugin) = -1",
                || with_plugin(2600.0, -1.0, 0.0),
            ),
            case(
                "plugin: infinite damping",
                "damping factor of material 0 (plugin) = inf",
                || with_plugin(2600.0, 1e10, f64::INFINITY),
            ),
        ],
    );
}

#[test]
fn auxetic_materials_are_accepted() {
    // ν < 0 keeps K and G positive; it is a material, not an error.
    let m = LinearElastic::new(30e9, -0.3, 2600.0).unwrap();
    assert!(m.bulk() > 0.0 && m.shear() > 0.0);
    let back: LinearElastic = serde_json::from_str(&serde_json::to_string(&m).unwrap()).unwrap();
    assert_eq!(back, m);
}
