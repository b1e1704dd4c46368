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
