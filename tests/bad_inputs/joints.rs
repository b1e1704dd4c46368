//! Joint models: the intrinsic cohesive zone model and Mohr-Coulomb joints, built and
//! deserialised.

use pcdc_cohesive::{IntrinsicCzm, IntrinsicCzmParams, MohrCoulombJoint, MohrCoulombJointParams};

use crate::{case, run};

fn czm(
    ts: f64,
    c: f64,
    gf1: f64,
    phi: f64,
    p_ov: f64,
) -> Result<IntrinsicCzm, pcdc_cohesive::CohesiveError> {
    IntrinsicCzmParams {
        friction_deg: phi,
        cohesion: c,
        tensile_strength: ts,
        gf1,
        gf2: 5.0,
        penalty_open: 3e11,
        penalty_shear: 3e11,
        penalty_overlap: p_ov,
    }
    .build()
}

const CZM_JSON: &str = r#"{"friction_deg":30.0,"cohesion":1e7,"tensile_strength":2e6,"gf1":0.5,"gf2":5.0,"penalty_open":3e11,"penalty_shear":3e11,"penalty_overlap":3e12}"#;

fn czm_json(from: &str, to: &str) -> Result<IntrinsicCzm, serde_json::Error> {
    assert!(CZM_JSON.contains(from), "{from}");
    serde_json::from_str(&CZM_JSON.replacen(from, to, 1))
}

fn mc_toml(text: &'static str) -> Result<MohrCoulombJoint, toml::de::Error> {
    toml::from_str(text)
}

#[test]
fn bad_joints_are_named_errors() {
    run(
        "joints",
        vec![
            case("negative T_s", "tensile strength Ts = -1", || {
                czm(-1.0, 1e7, 0.5, 30.0, 3e12)
            }),
            case("zero cohesion", "cohesion c = 0", || {
                czm(2e6, 0.0, 0.5, 30.0, 3e12)
            }),
            case("NaN G_f1", "Gf1 = NaN", || {
                czm(2e6, 1e7, f64::NAN, 30.0, 3e12)
            }),
            case("friction 90°", "friction angle = 90", || {
                czm(2e6, 1e7, 0.5, 90.0, 3e12)
            }),
            case(
                "infinite overlap penalty",
                "overlap penalty P_overlap = inf",
                || czm(2e6, 1e7, 0.5, 30.0, f64::INFINITY),
            ),
            case(
                "json: negative T_s",
                "tensile strength Ts = -2000000",
                || czm_json("\"tensile_strength\":2e6", "\"tensile_strength\":-2e6"),
            ),
            case("json: negative friction", "friction angle = -5", || {
                czm_json("\"friction_deg\":30.0", "\"friction_deg\":-5.0")
            }),
            case(
                "json: unknown key",
                "unknown field `penalty_normal`",
                || czm_json("\"penalty_open\"", "\"penalty_normal\""),
            ),
            case("json: missing key", "missing field `gf2`", || {
                czm_json("\"gf2\":5.0,", "")
            }),
            case(
                "mohr-coulomb: negative friction",
                "friction angle = -1",
                || {
                    MohrCoulombJointParams {
                        friction_deg: -1.0,
                        cohesion: 0.0,
                        penalty_normal: 1e10,
                        penalty_shear: 1e10,
                    }
                    .build()
                },
            ),
            case(
                "mohr-coulomb: negative cohesion",
                "residual cohesion = -1",
                || {
                    MohrCoulombJointParams {
                        friction_deg: 30.0,
                        cohesion: -1.0,
                        penalty_normal: 1e10,
                        penalty_shear: 1e10,
                    }
                    .build()
                },
            ),
            case(
                "mohr-coulomb: zero normal penalty",
                "normal penalty P_n = 0",
                || {
                    MohrCoulombJointParams {
                        friction_deg: 30.0,
                        cohesion: 0.0,
                        penalty_normal: 0.0,
                        penalty_shear: 1e10,
                    }
                    .build()
                },
            ),
            case(
                "mohr-coulomb toml: NaN shear penalty",
                "shear penalty P_t = NaN",
                || {
                    mc_toml("friction_deg = 30.0\ncohesion = 0.0\npenalty_normal = 1e10\npenalty_shear = nan\n")
                },
            ),
        ],
    );
}

/// The null model does not yet reach joints: excavating in a jointed scene is refused
/// with the reason, not run with joints to null elements still holding.
#[test]
fn null_model_in_a_jointed_scene_is_refused() {
    use pcdc::compute::{Backend, Simulation};
    use pcdc_cohesive::CohesiveJoints;
    use pcdc_mech::{set_null, LinearElastic, Mechanics};
    use pcdc_mesh::{builders, split_nodes, Range};
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.25).unwrap();
    let split = split_nodes(&mesh, &Range::All).unwrap();
    let rock = LinearElastic::new(1e9, 0.25, 2000.0).unwrap();
    let mut sim = Simulation::builder(split, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(CohesiveJoints::new().model(Range::All, czm(1e6, 2e6, 1.0, 30.0, 1e12).unwrap()))
        .build()
        .unwrap();
    let err = set_null(&mut sim, &Range::All).unwrap_err().to_string();
    assert!(
        err.contains("cohesive joints") && err.contains("null"),
        "{err}"
    );
}
