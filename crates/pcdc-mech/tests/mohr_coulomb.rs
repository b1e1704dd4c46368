//! Mohr–Coulomb with tension cut-off: the return mapping's properties (manual 7.2.4).

use pcdc_mech::mohr_coulomb::{state, Surfaces, MC_STATE};
use pcdc_mech::principal::principal;
use pcdc_mech::{ConstitutiveModel, LinearElastic, ModelInput, MohrCoulomb, Softening, Sym6};
use proptest::prelude::*;

fn model(c: f64, phi: f64, psi: f64, st: f64) -> MohrCoulomb {
    let e = LinearElastic::new(10e9, 0.25, 2600.0).unwrap();
    MohrCoulomb::new(e, c, phi, psi, st).unwrap()
}

fn add(a: &[f64; 3], b: &[f64; 3], f: f64) -> [f64; 3] {
    [a[0] + f * b[0], a[1] + f * b[1], a[2] + f * b[2]]
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[test]
fn uniaxial_compression_yields_at_two_c_root_n() {
    let m = model(5e6, 30.0, 10.0, 2e6);
    // N_φ = 3 at 30°: UCS = 2c√3.
    assert!((m.ucs() - 2.0 * 5e6 * 3f64.sqrt()).abs() < 1e-6);
    let s = m.surfaces();
    let r = s.return_map(&[-2.0 * m.ucs(), 0.0, 0.0]).expect("plastic");
    assert!(s.plane(0, &r.stress).abs() < 1e-6, "{:?}", r.stress);
    assert!(r.shear > 0.0 && r.tension == 0.0);
}

/// Found by CI's proptest (`edge_returns_recover_both_multipliers`): a trial past the
/// compression edge with the edge's multiplier the larger has σ2 > σ3 in its labels, and
/// the shear plane's first try once judged it by σ3 alone, inside, so no return came.
/// Whether a trial is outside is the composite function's answer in any order.
#[test]
fn an_unordered_trial_outside_is_returned() {
    for poisson in [-0.05, 0.0, 0.25, 0.45] {
        for (phi, psi, st) in [(52.5, 48.3, 0.0), (30.0, 10.0, 1e5), (10.0, 0.0, 0.0)] {
            let e = LinearElastic::new(1e9, poisson, 2500.0).unwrap();
            let m = MohrCoulomb::new(e, 1e5, phi, psi, st).unwrap();
            let s = m.surfaces();
            let s3 = s.st - 0.25 * s.kc;
            let on = [s.n_phi * s3 - s.kc, s3, s3];
            let (l0, l1) = (1e-6 * s.kc / s.a1, 7e-3 * s.kc / s.a1);
            let g0 = s.elastic(&s.potential_gradient(0));
            let g1 = s.elastic(&s.potential_gradient(1));
            let trial = add(&add(&on, &g0, l0), &g1, l1);
            assert!(
                trial[1] > trial[2],
                "the case needs labels out of order: {trial:?}"
            );
            assert!(s.composite(&trial) > 0.0, "{trial:?}");
            let r = s.return_map(&trial).expect("outside, so returned");
            assert!(s.composite(&r.stress) <= 1e-9 * s.kc, "{:?}", r.stress);
        }
    }
}

#[test]
fn triaxial_yield_follows_sigma3_n_phi_plus_ucs() {
    // Yield at σ1 = σ3 N_φ + 2c√N_φ in compression magnitudes, for several confinements.
    let m = model(2e6, 35.0, 0.0, 1e6);
    let s = m.surfaces();
    for conf in [0.0, 2e6, 5e6, 10e6] {
        let yield_at = conf * s.n_phi + s.kc;
        // Just inside and just outside along the axial stress.
        let inside = [-(yield_at * (1.0 - 1e-9)), -conf, -conf];
        assert!(s.return_map(&inside).is_none(), "confinement {conf}");
        let outside = [-(yield_at * 1.01), -conf, -conf];
        let r = s.return_map(&outside).expect("plastic");
        assert!(s.composite(&r.stress).abs() <= 1e-6, "{:?}", r.stress);
    }
}

#[test]
fn tension_returns_sigma3_to_the_tensile_strength() {
    let m = model(5e6, 30.0, 10.0, 1e6);
    let s = m.surfaces();
    let r = s.return_map(&[0.0, 0.0, 3e6]).expect("plastic");
    assert!((r.stress[2] - 1e6).abs() < 1e-6, "{:?}", r.stress);
    assert!(r.tension > 0.0 && r.shear == 0.0);
    // The digest's tension correction: σ1, σ2 move by λ α2 with λ = (σ_t − σ3)/α1.
    let l = (1e6 - 3e6) / s.a1;
    assert!((r.stress[0] - l * s.a2).abs() < 1e-6);
}

#[test]
fn tensile_strength_is_capped_at_c_cot_phi() {
    let m = model(1e6, 45.0, 0.0, 5e6);
    assert!((m.tensile_effective() - 1e6).abs() < 1e-6);
    assert!(m.tensile_is_capped());
    assert!(!model(1e6, 45.0, 0.0, 0.5e6).tensile_is_capped());
    assert_eq!(model(1e6, 0.0, 0.0, 5e6).tensile_effective(), 5e6);
}

#[test]
fn elastic_states_are_untouched_and_flags_follow_yield() {
    let m = model(5e6, 30.0, 10.0, 1e6);
    let e = m.elastic().clone();
    let de: Sym6 = [1e-5, -2e-5, 0.0, 3e-6, 0.0, 0.0];
    let mut a: Sym6 = [-1e6, -2e6, -1.5e6, 1e5, 0.0, 0.0];
    let mut b = a;
    let mut st = [0.0; MC_STATE];
    m.update(&[0.0; 6], &de, &mut a, &mut st);
    e.update(&[0.0; 6], &de, &mut b, &mut []);
    assert_eq!(a, b);
    assert_eq!(st, [0.0; MC_STATE]);
    // A large shear strain yields; "now" clears on the next elastic step, "past" stays.
    let big: Sym6 = [-5e-3, 5e-3, 0.0, 0.0, 0.0, 0.0];
    m.update(&[0.0; 6], &big, &mut a, &mut st);
    assert_eq!((st[state::SHEAR_NOW], st[state::SHEAR_PAST]), (1.0, 1.0));
    assert!(st[state::SHEAR_STRAIN] > 0.0);
    m.update(&[0.0; 6], &[0.0; 6], &mut a, &mut st);
    assert_eq!((st[state::SHEAR_NOW], st[state::SHEAR_PAST]), (0.0, 1.0));
}

#[test]
fn bad_parameters_are_refused_by_name() {
    let e = LinearElastic::new(10e9, 0.25, 2600.0).unwrap();
    let msg = |r: Result<MohrCoulomb, pcdc_mech::MechError>| r.unwrap_err().to_string();
    assert!(msg(MohrCoulomb::new(e.clone(), -1.0, 30.0, 0.0, 0.0)).contains("cohesion"));
    assert!(msg(MohrCoulomb::new(e.clone(), 1.0, 90.0, 0.0, 0.0)).contains("friction"));
    assert!(msg(MohrCoulomb::new(e.clone(), 1.0, 30.0, 31.0, 0.0)).contains("dilation"));
    assert!(msg(MohrCoulomb::new(e.clone(), 1.0, 30.0, 0.0, f64::NAN)).contains("tensile"));
    assert!(msg(MohrCoulomb::new(e, 0.0, 0.0, 0.0, 0.0)).contains("cohesion"));
    // The same check on deserialisation.
    let json = r#"{"elastic":{"young":1e9,"poisson":0.2,"density":2000},
                   "cohesion":1e6,"friction":20,"dilation":25,"tensile":0}"#;
    let err = serde_json::from_str::<MohrCoulomb>(json)
        .unwrap_err()
        .to_string();
    assert!(err.contains("dilation"), "{err}");
}

fn params() -> impl Strategy<Value = MohrCoulomb> {
    (
        1e9..1e11f64,
        -0.3..0.45f64,
        0.0..1.0f64,
        0.0..60.0f64,
        0.0..1.0f64,
        0.0..2.0f64,
    )
        .prop_map(|(young, nu, c, phi, psi_frac, st)| {
            let e = LinearElastic::new(young, nu, 2500.0).unwrap();
            // c from 0.1 to 10 MPa (nonzero: a strength scale for the tolerances).
            let c = 1e5 * 100f64.powf(c);
            MohrCoulomb::new(e, c, phi, psi_frac * phi, st * c).unwrap()
        })
}

fn tensor(scale: f64) -> impl Strategy<Value = Sym6> {
    prop::array::uniform6(-1.0..1.0f64).prop_map(move |t| t.map(|v| v * scale))
}

proptest! {
    /// The corrected stress never lies outside the yield surface, and the plastic
    /// dissipation σ:Δεᵖ is non-negative.
    #[test]
    fn returned_stress_is_admissible_and_dissipates(m in params(), t in tensor(1.0)) {
        let s = m.surfaces();
        let scale = 20.0 * s.kc;
        let trial = principal(&t.map(|v| v * scale)).values;
        if let Some(r) = s.return_map(&trial) {
            prop_assert!(s.composite(&r.stress) <= 1e-9 * scale,
                "{:?} -> {:?}: {}", trial, r.stress, s.composite(&r.stress));
            prop_assert!(dot(&r.stress, &r.plastic_strain) >= -1e-12 * scale * r.plastic_strain.iter().map(|v| v.abs()).sum::<f64>());
            prop_assert!(r.shear >= 0.0 && r.tension >= 0.0);
            // The correction is the elastic image of the plastic strain.
            let d = s.elastic(&r.plastic_strain);
            for i in 0..3 {
                prop_assert!((trial[i] - r.stress[i] - d[i]).abs() <= 1e-9 * scale);
            }
        } else {
            prop_assert!(s.composite(&trial) <= 0.0);
        }
    }

    /// A point inside the shear face or inside the tension face, pushed out by λ along
    /// the elastic image of that plane's potential gradient, returns to itself with
    /// plastic strain λ ∇g: the correction is along the potential's gradient.
    #[test]
    fn correction_is_along_the_potential_gradient(
        m in params(), u in 0.05..0.95f64, w in 0.05..0.95f64, l in 1e-6..1e-2f64
    ) {
        let s = m.surfaces();
        let lambda = l * s.kc / s.a1;
        // Shear face: σ3 below σ_t, σ1 on the plane, σ2 strictly between.
        let s3 = s.st - (0.2 + u) * s.kc;
        let s1 = s.n_phi * s3 - s.kc;
        let on = [s1, s1 + w * (s3 - s1), s3];
        let g = s.potential_gradient(0);
        let r = s.return_map(&add(&on, &s.elastic(&g), lambda)).expect("outside");
        for i in 0..3 {
            prop_assert!((r.stress[i] - on[i]).abs() <= 1e-9 * s.kc, "{:?} vs {:?}", r.stress, on);
            prop_assert!((r.plastic_strain[i] - lambda * g[i]).abs() <= 1e-8 * lambda);
        }
        prop_assert_eq!(r.tension, 0.0);
        // Tension face: σ3 = σ_t, σ1 above the shear–tension corner, σ2 between.
        let corner = s.n_phi * s.st - s.kc;
        prop_assume!(s.st - corner > 1e-6 * s.kc);
        let s1 = corner + (0.1 + 0.8 * u) * (s.st - corner);
        let on = [s1, s1 + 0.9 * w * (s.st - s1), s.st];
        let g = s.potential_gradient(3);
        let r = s.return_map(&add(&on, &s.elastic(&g), lambda)).expect("outside");
        for i in 0..3 {
            prop_assert!((r.stress[i] - on[i]).abs() <= 1e-9 * s.kc, "{:?} vs {:?}", r.stress, on);
            prop_assert!((r.plastic_strain[i] - lambda * g[i]).abs() <= 1e-8 * lambda);
        }
        prop_assert_eq!(r.shear, 0.0);
    }

    /// A point on an edge of the pyramid (σ2 = σ3, triaxial compression, or σ2 = σ1,
    /// extension), pushed out along both planes' elastic images by λ0, λ1, returns to
    /// itself with plastic strain λ0 ∇g0 + λ1 ∇g_edge: the closed-form edge returns.
    #[test]
    fn edge_returns_recover_both_multipliers(
        m in params(), u in 0.05..0.95f64, l0 in 1e-6..1e-2f64, l1 in 1e-6..1e-2f64,
        compression in any::<bool>()
    ) {
        let s = m.surfaces();
        let (l0, l1) = (l0 * s.kc / s.a1, l1 * s.kc / s.a1);
        let s3 = s.st - (0.2 + u) * s.kc;
        let s1 = s.n_phi * s3 - s.kc;
        let (on, edge) = if compression { ([s1, s3, s3], 1) } else { ([s1, s1, s3], 2) };
        let (g0, g1) = (s.potential_gradient(0), s.potential_gradient(edge));
        let trial = add(&add(&on, &s.elastic(&g0), l0), &s.elastic(&g1), l1);
        let r = s.return_map(&trial).expect("outside");
        for i in 0..3 {
            prop_assert!((r.stress[i] - on[i]).abs() <= 1e-9 * s.kc, "{:?} vs {:?}", r.stress, on);
            let ep = l0 * g0[i] + l1 * g1[i];
            prop_assert!((r.plastic_strain[i] - ep).abs() <= 1e-8 * (l0 + l1), "{:?}", r.plastic_strain);
        }
        prop_assert!((r.shear - (l0 + l1)).abs() <= 1e-8 * (l0 + l1));
        prop_assert_eq!(r.tension, 0.0);
    }

    /// The decomposition-free elastic bound never calls a plastic state elastic.
    #[test]
    fn surely_elastic_is_never_wrong(m in params(), t in tensor(1.0), k in 0.1..30.0f64) {
        let s = m.surfaces();
        let t = t.map(|v| v * k * s.kc);
        if s.surely_elastic(&t) {
            prop_assert!(s.composite(&principal(&t).values) <= 0.0, "{:?}", t);
        }
    }

    /// With ψ = 0 the shear planes' plastic flow keeps the volume.
    #[test]
    fn zero_dilation_keeps_plastic_volume(m in params(), t in tensor(1.0)) {
        let m = MohrCoulomb::new(m.elastic().clone(), m.cohesion(), m.friction(), 0.0, m.tensile()).unwrap();
        let s = m.surfaces();
        let trial = principal(&t.map(|v| v * 20.0 * s.kc)).values;
        if let Some(r) = s.return_map(&trial) {
            let vol: f64 = r.shear_strain.iter().sum();
            let size: f64 = r.shear_strain.iter().map(|v| v.abs()).sum();
            prop_assert!(vol.abs() <= 1e-12 * size.max(f64::MIN_POSITIVE));
        }
    }

    /// Through the full tensor update: the result is admissible, keeps the trial's
    /// principal axes, and in plane strain keeps yz = xz = 0.
    #[test]
    fn tensor_update_is_admissible_and_coaxial(m in params(), t in tensor(1.0), plane in any::<bool>()) {
        let kc = m.surfaces().kc;
        let e = m.elastic().clone();
        let mut de: Sym6 = t.map(|v| v * 20.0 * kc / e.young());
        if plane {
            de[2] = 0.0;
            de[4] = 0.0;
            de[5] = 0.0;
        }
        let mut sig = [0.0; 6];
        let mut trial = [0.0; 6];
        e.update(&[0.0; 6], &de, &mut trial, &mut []);
        let mut st = [0.0; MC_STATE];
        m.update(&[0.0; 6], &de, &mut sig, &mut st);
        let p = principal(&sig);
        let s: Surfaces = m.surfaces();
        let scale = 20.0 * kc + trial.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        prop_assert!(s.composite(&p.values) <= 1e-9 * scale);
        // Coaxial: σ and the trial commute (σ T = T σ).
        let mat = |v: &Sym6| [[v[0], v[3], v[5]], [v[3], v[1], v[4]], [v[5], v[4], v[2]]];
        let (a, b) = (mat(&sig), mat(&trial));
        for i in 0..3 {
            for j in 0..3 {
                let ab: f64 = (0..3).map(|k| a[i][k] * b[k][j]).sum();
                let ba: f64 = (0..3).map(|k| b[i][k] * a[k][j]).sum();
                prop_assert!((ab - ba).abs() <= 1e-9 * scale * scale);
            }
        }
        if plane {
            prop_assert_eq!((sig[4], sig[5]), (0.0, 0.0));
        }
        let yielded = st[state::SHEAR_NOW] + st[state::TENSION_NOW] > 0.0;
        prop_assert_eq!(yielded, s.composite(&principal(&trial).values) > 0.0);
    }
}

#[test]
fn serde_round_trip_keeps_the_model() {
    let m = model(3e6, 35.0, 5.0, 1e6);
    let json = serde_json::to_string(&m).unwrap();
    let back: MohrCoulomb = serde_json::from_str(&json).unwrap();
    assert_eq!(back, m);
    assert_eq!(back.surfaces(), m.surfaces());
}

fn tab(points: &[(f64, f64)]) -> Option<pcdc_compute::Table> {
    Some(pcdc_compute::Table::new("softening", points).unwrap())
}

fn softening_model() -> MohrCoulomb {
    model(4e6, 35.0, 10.0, 2e6)
        .with_softening(Softening {
            cohesion: tab(&[(0.0, 4e6), (1e-3, 1e6)]),
            friction: tab(&[(0.0, 35.0), (2e-3, 30.0)]),
            dilation: tab(&[(0.0, 10.0), (1e-3, 0.0)]),
            tensile: tab(&[(0.0, 2e6), (5e-4, 0.0)]),
        })
        .unwrap()
}

#[test]
fn softening_interpolates_the_strengths() {
    let m = softening_model();
    // At κ = 0 the model's own strengths.
    assert_eq!(m.surfaces_at(0.0, 0.0), m.surfaces());
    // Half way along the cohesion table, a quarter along the friction table.
    let s = m.surfaces_at(5e-4, 2.5e-4);
    let n = |deg: f64| {
        let s = deg.to_radians().sin();
        (1.0 + s) / (1.0 - s)
    };
    let n_phi = n(33.75);
    assert!((s.n_phi - n_phi).abs() < 1e-12 * n_phi);
    assert!((s.n_psi - n(5.0)).abs() < 1e-12);
    assert!((s.kc - 2.0 * 2.5e6 * n_phi.sqrt()).abs() < 1e-6);
    assert!((s.st - 1e6).abs() < 1e-6);
    // Beyond the ends, the last values; the residual cut-off is zero.
    let r = m.surfaces_at(1.0, 1.0);
    assert!((r.kc - 2.0 * 1e6 * n(30.0).sqrt()).abs() < 1e-6);
    assert_eq!(r.st, 0.0);
    assert!((r.n_psi - 1.0).abs() < 1e-15);
}

#[test]
fn softening_lowers_the_strength_along_a_shear_path() {
    // Simple shear in plane strain under confinement: the peak is reached once, then the
    // stress falls with κ_s towards the residual strength, and every step's stress lies
    // on the surface of the κ it started from.
    let m = softening_model();
    let mut sig: Sym6 = [-5e6, -5e6, -5e6, 0.0, 0.0, 0.0];
    let mut st = [0.0; MC_STATE];
    let de: Sym6 = [0.0, 0.0, 0.0, 2e-5, 0.0, 0.0];
    let mut peak: f64 = 0.0;
    let mut last = 0.0;
    for _ in 0..400 {
        let k0 = (st[state::SHEAR_STRAIN], st[state::TENSION_STRAIN]);
        m.update(&[0.0; 6], &de, &mut sig, &mut st);
        let s = m.surfaces_at(k0.0, k0.1);
        let p = principal(&sig);
        assert!(s.composite(&p.values) <= 1e-9 * 1e7, "{:?}", p.values);
        peak = peak.max(sig[3]);
        last = sig[3];
    }
    assert!(
        st[state::SHEAR_STRAIN] > 2e-3,
        "κ_s = {}",
        st[state::SHEAR_STRAIN]
    );
    // Residual: c = 1 MPa, φ = 30°: on the shear plane at σ1, σ3 of the last state.
    let res = m.surfaces_at(1.0, 1.0);
    let p = principal(&sig).values;
    assert!(res.plane(0, &p).abs() <= 1e-6 * res.kc, "{p:?}");
    // The peak: pure shear at mean stress p = −5 MPa on the peak surface,
    // τ = (2c√N_φ − p (N_φ − 1)) / (N_φ + 1) (dilation raises |p| slightly at the peak).
    let s0 = m.surfaces();
    let tau = (s0.kc + 5e6 * (s0.n_phi - 1.0)) / (s0.n_phi + 1.0);
    assert!(
        (peak - tau).abs() < 0.02 * tau,
        "peak {peak}, closed form {tau}"
    );
    assert!(last < 0.7 * peak, "peak {peak}, last {last}");
}

#[test]
fn bad_softening_tables_are_refused_by_name() {
    let m = model(4e6, 35.0, 10.0, 2e6);
    let err = |s: Softening| m.clone().with_softening(s).unwrap_err().to_string();
    let e = err(Softening {
        cohesion: tab(&[(0.0, 4e6), (1e-3, -1.0)]),
        ..Default::default()
    });
    assert!(e.contains("cohesion") && e.contains("point 1"), "{e}");
    let e = err(Softening {
        friction: tab(&[(0.0, 35.0), (1e-3, 90.0)]),
        ..Default::default()
    });
    assert!(e.contains("friction") && e.contains("degrees"), "{e}");
    let e = err(Softening {
        tensile: tab(&[(-1e-3, 1e6), (1e-3, 0.0)]),
        ..Default::default()
    });
    assert!(e.contains("tensile") && e.contains("plastic strain"), "{e}");
    // And on deserialisation.
    let json = r#"{"elastic":{"young":1e9,"poisson":0.2,"density":2000},
                   "cohesion":1e6,"friction":20,"tensile":0,
                   "softening":{"dilation":{"t":[0,1e-3],"v":[5,-1]}}}"#;
    let e = serde_json::from_str::<MohrCoulomb>(json)
        .unwrap_err()
        .to_string();
    assert!(e.contains("dilation"), "{e}");
}

#[test]
fn serde_round_trip_keeps_the_softening() {
    let m = softening_model();
    let json = serde_json::to_string(&m).unwrap();
    let back: MohrCoulomb = serde_json::from_str(&json).unwrap();
    assert_eq!(back, m);
    assert_eq!(back.surfaces_at(3e-4, 1e-4), m.surfaces_at(3e-4, 1e-4));
}

/// The plastic history reaches ParaView: `output::write_step` writes one cell array per
/// history variable, with the values of the `model_state` field.
#[test]
fn vtu_step_shows_the_plastic_state() {
    use pcdc_compute::{Backend, Simulation};
    use pcdc_mech::{output, Mechanics};
    use pcdc_mesh::vtu::{PvdSeries, VtuEncoding};
    use pcdc_mesh::{builders, Range};
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.25).unwrap();
    // An initial deviatoric stress far beyond the strength of the upper half.
    let upper = Range::HalfSpace {
        point: [0.0, 0.5, 0.0],
        normal: [0.0, 1.0, 0.0],
    };
    let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(
            Mechanics::new()
                .material(Range::All, model(5e6, 30.0, 0.0, 1e6))
                .initial_stress(upper, [-60e6, 0.0, -20e6, 0.0, 0.0, 0.0]),
        )
        .build()
        .unwrap();
    sim.run(1).unwrap();
    let dir = std::env::temp_dir().join(format!("pcdc-mc-vtu-{}", std::process::id()));
    let mut series = PvdSeries::new(&dir, "mc")
        .unwrap()
        .with_encoding(VtuEncoding::Ascii);
    let path = output::write_step(&mut series, &sim).unwrap();
    let xml = std::fs::read_to_string(&path).unwrap();
    let history = sim.field("model_state").unwrap().to_vec();
    let ne = sim.mesh().n_elements();
    let values = |name: &str| -> Vec<f64> {
        let at = xml.find(&format!("Name=\"{name}\"")).expect(name);
        let body = &xml[at..];
        let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
        body.split_whitespace()
            .map(|v| v.parse().unwrap())
            .collect()
    };
    for k in 0..MC_STATE {
        let want: Vec<f64> = (0..ne).map(|e| history[e * MC_STATE + k]).collect();
        assert_eq!(values(&format!("model_state_{k}")), want, "variable {k}");
    }
    let shear_past = values("model_state_1");
    let yielded = shear_past.iter().filter(|&&v| v == 1.0).count();
    assert!(yielded > 0 && yielded < ne, "{yielded} of {ne} yielded");
    std::fs::remove_dir_all(&dir).ok();
}

proptest! {
    /// The run update (3D decompositions in lanes, plane ones apart, returns that end on
    /// the shear plane at the first try straight from the decomposition, the others'
    /// search without a second first try) gives every element
    /// what the one-element update gives it, bit for bit: runs of any length, plane and
    /// 3D, elastic and yielding elements mixed, with softening (surfaces per element)
    /// and without, and a state stride wider than the model's.
    #[test]
    fn update_many_is_the_one_element_update_bit_for_bit(
        soft in any::<bool>(),
        elements in prop::collection::vec(
            (tensor(20e6), tensor(2e-3), any::<bool>(), 0.0..2e-3f64),
            1..40,
        ),
    ) {
        let m = if soft { softening_model() } else { model(4e6, 35.0, 10.0, 2e6) };
        let stride = MC_STATE + 2;
        let n = elements.len();
        let (mut s1, mut s2) = (Vec::new(), Vec::new());
        let (mut st1, mut st2) = (vec![0.0; n * stride], vec![0.0; n * stride]);
        let mut des = Vec::new();
        for (i, (sig, de, plane, kappa)) in elements.iter().enumerate() {
            let (mut sig, mut de) = (*sig, *de);
            if *plane {
                (sig[4], sig[5], de[2], de[4], de[5]) = (0.0, 0.0, 0.0, 0.0, 0.0);
            }
            s1.push(sig);
            s2.push(sig);
            des.push(de);
            st1[i * stride + state::SHEAR_STRAIN] = *kappa;
            st1[i * stride + stride - 1] = 7.0; // beyond the model's values: untouched
        }
        st2.clone_from(&st1);
        for i in 0..n {
            m.update(&des[i], &des[i], &mut s1[i], &mut st1[i * stride..(i + 1) * stride]);
        }
        let inputs: Vec<_> = des.iter().map(|d| ModelInput::new(d, d, &[])).collect();
        m.update_many(&inputs, &mut s2, &mut st2, stride);
        for i in 0..n {
            prop_assert_eq!(s1[i].map(f64::to_bits), s2[i].map(f64::to_bits), "element {}", i);
        }
        prop_assert_eq!(
            st1.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            st2.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
    }
}

#[test]
fn update_many_leaves_elements_beyond_the_shortest_slice_alone() {
    // A caller's slices of unequal length: no panic, the extra elements untouched.
    let m = model(1e6, 30.0, 5.0, 0.5e6);
    let de = [-1e-3, 0.0, 0.0, 2e-4, 1e-4, 0.0];
    let inputs = vec![ModelInput::new(&de, &de, &[]); 3];
    let mut stresses = vec![[0.0; 6]; 3];
    let mut states = vec![0.0; 2 * MC_STATE + 1];
    m.update_many(&inputs, &mut stresses, &mut states, MC_STATE);
    assert_ne!(stresses[1], [0.0; 6]);
    assert_eq!(stresses[2], [0.0; 6]);
    assert_eq!(states[2 * MC_STATE], 0.0);
}

/// Plane trials in every class a run meets side by side (the run update takes them
/// [`pcdc_mech::principal::LANES`] at a time): surely elastic, inside but near the
/// surface, onto the shear plane with σzz below, between and above the in-plane values,
/// onto an edge, into tension and the apex (the general search), equal in-plane values
/// (no in-plane direction) and a NaN; whatever the class of its neighbours, each element
/// gets what the one-element update gives it, bit for bit, with and without softening,
/// in runs of every length up to 40 (so lane groups of 1 to 8, full and partial).
#[test]
fn plane_runs_of_every_class_match_the_one_element_update() {
    let turned = |p: [f64; 3], deg: f64| -> Sym6 {
        let (c, s) = (deg.to_radians().cos(), deg.to_radians().sin());
        // In-plane values p[0], p[1] on axes turned by `deg`, σzz = p[2].
        [
            p[0] * c * c + p[1] * s * s,
            p[0] * s * s + p[1] * c * c,
            p[2],
            (p[0] - p[1]) * c * s,
            0.0,
            0.0,
        ]
    };
    let trials: Vec<(Sym6, Sym6)> = vec![
        (turned([-1e6, -2e6, -1.5e6], 10.0), [0.0; 6]),
        (turned([-5e6, -14e6, -6e6], 20.0), [0.0; 6]),
        (turned([-8e6, -40e6, -10e6], 30.0), [0.0; 6]),
        (turned([-8e6, -40e6, -30e6], 40.0), [0.0; 6]),
        (turned([-8e6, -40e6, -50e6], 50.0), [0.0; 6]),
        (turned([-8e6, -40e6, -40e6], 60.0), [0.0; 6]),
        (turned([-40e6, -40e6, -8e6], 0.0), [0.0; 6]),
        (turned([3e6, -1e6, -2e6], 70.0), [0.0; 6]),
        (turned([3e6, 3e6, 3e6], 80.0), [0.0; 6]),
        (
            turned([-9e6, -9e6, -9e6], 0.0),
            [-1e-3, -1e-3, 0.0, 0.0, 0.0, 0.0],
        ),
        (
            turned([-8e6, -30e6, -10e6], 15.0),
            [-4e-4, 1e-4, 0.0, 2e-4, 0.0, 0.0],
        ),
        (
            turned([-8e6, -30e6, -10e6], 25.0),
            [f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0],
        ),
    ];
    for soft in [false, true] {
        let m = if soft {
            softening_model()
        } else {
            model(4e6, 35.0, 10.0, 2e6)
        };
        for n in 1..=40 {
            // Element i takes trial (i * 7 + n) mod the trial count: every class beside
            // every other as n changes.
            let pick: Vec<_> = (0..n).map(|i| trials[(i * 7 + n) % trials.len()]).collect();
            let (mut s1, mut s2): (Vec<Sym6>, Vec<Sym6>) = (
                pick.iter().map(|t| t.0).collect(),
                pick.iter().map(|t| t.0).collect(),
            );
            let kappa = |i: usize| if soft { 2e-4 * (i % 5) as f64 } else { 0.0 };
            let mut st1 = vec![0.0; n * MC_STATE];
            for i in 0..n {
                st1[i * MC_STATE + state::SHEAR_STRAIN] = kappa(i);
            }
            let mut st2 = st1.clone();
            for (i, (_, de)) in pick.iter().enumerate() {
                m.update(
                    de,
                    de,
                    &mut s1[i],
                    &mut st1[i * MC_STATE..(i + 1) * MC_STATE],
                );
            }
            let inputs: Vec<_> = pick
                .iter()
                .map(|(_, de)| ModelInput::new(de, de, &[]))
                .collect();
            m.update_many(&inputs, &mut s2, &mut st2, MC_STATE);
            for i in 0..n {
                assert_eq!(
                    s1[i].map(f64::to_bits),
                    s2[i].map(f64::to_bits),
                    "soft {soft}, run of {n}, element {i}"
                );
            }
            assert_eq!(
                st1.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                st2.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                "soft {soft}, run of {n}"
            );
            if n == 40 {
                // The run met the classes it is meant to: untouched, shear alone,
                // tension.
                let flags: Vec<_> = st1
                    .chunks(MC_STATE)
                    .map(|s| (s[state::SHEAR_NOW], s[state::TENSION_NOW]))
                    .collect();
                assert!(flags.contains(&(0.0, 0.0)), "soft {soft}: {flags:?}");
                assert!(flags.contains(&(1.0, 0.0)), "soft {soft}: {flags:?}");
                assert!(flags.iter().any(|f| f.1 == 1.0), "soft {soft}: {flags:?}");
            }
        }
    }
}
