//! Burgers creep (manual 7.2.5): the tensor update against the closed forms, its limits
//! and its parameter checks.

use pcdc_mech::burgers::{state, BURGERS_STATE};
use pcdc_mech::{Burgers, ConstitutiveModel, LinearElastic, ModelInput, Sym6};
use proptest::prelude::*;

fn model(gm: f64, gk: f64, ek: f64, em: f64) -> Burgers {
    // K = 2 G_M (ν = 2/7), G_M given.
    let e = LinearElastic::from_bulk_shear(2.0 * gm, gm, 2500.0).unwrap();
    Burgers::new(e, gk, ek, em).unwrap()
}

/// Creep under a constant pure-shear deviator s (xx = s, yy = −s) from rest, emulating
/// the equilibrium of each creep step: Newton on the strain increment so that the
/// update returns s (the update is linear: one secant step is exact). Returns e_xx at
/// the end of each step.
fn creep(m: &Burgers, s: f64, dt: f64, steps: usize) -> Vec<f64> {
    let mut st = vec![0.0; BURGERS_STATE];
    m.init_state_into(&mut st);
    let mut strain: Sym6 = [0.0; 6];
    let mut stress: Sym6 = [0.0; 6];
    // Load instantly (elastic) at step index 0, Δt_c = 0.
    let load =
        |m: &Burgers, strain: &mut Sym6, stress: &mut Sym6, st: &mut [f64], clock: [f64; 2]| {
            // The update is affine in e_xx = −e_yy: two probes give the slope.
            let eval = |x: f64, st: &mut Vec<f64>, stress: &Sym6| {
                let mut t = *strain;
                t[0] += x;
                t[1] -= x;
                let de = [x, -x, 0.0, 0.0, 0.0, 0.0];
                let mut sig = *stress;
                let mut probe = st.to_vec();
                m.update_with(&ModelInput::new(&t, &de, &clock), &mut sig, &mut probe);
                *st = probe;
                sig[0]
            };
            let mut a = st.to_vec();
            let f0 = eval(0.0, &mut a, stress);
            let mut b = st.to_vec();
            let f1 = eval(1e-6, &mut b, stress);
            let x = (s - f0) / ((f1 - f0) / 1e-6);
            let mut c = st.to_vec();
            eval(x, &mut c, stress);
            let mut t = *strain;
            t[0] += x;
            t[1] -= x;
            let de = [x, -x, 0.0, 0.0, 0.0, 0.0];
            m.update_with(&ModelInput::new(&t, &de, &clock), stress, st);
            *strain = t;
        };
    load(m, &mut strain, &mut stress, &mut st, [0.0, 0.0]);
    let mut out = Vec::new();
    for k in 0..steps {
        // Creep step k + 1, then end it (index + 1 with Δt_c = 0), as creep_step does.
        load(
            m,
            &mut strain,
            &mut stress,
            &mut st,
            [(2 * k + 1) as f64, dt],
        );
        out.push(strain[0]);
        load(
            m,
            &mut strain,
            &mut stress,
            &mut st,
            [(2 * k + 2) as f64, 0.0],
        );
    }
    out
}

#[test]
fn creep_follows_the_closed_form_to_second_order() {
    let m = model(1e9, 2e9, 4e14, 2e15);
    let s = 1e6;
    let tk = m.kelvin_viscosity() / m.kelvin_shear();
    let t_end = 5.0 * tk;
    let mut errors = Vec::new();
    for n in [10, 20, 40] {
        let dt = t_end / n as f64;
        let e = creep(&m, s, dt, n);
        let scale = m.creep_strain(s, t_end);
        let err = e
            .iter()
            .enumerate()
            .map(|(k, &v)| (v - m.creep_strain(s, (k + 1) as f64 * dt)).abs())
            .fold(0.0f64, f64::max)
            / scale;
        errors.push(err);
    }
    eprintln!("creep errors at 10, 20, 40 steps: {errors:?}");
    assert!(errors[2] < 2e-3, "{errors:?}");
    for w in errors.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!(order > 1.9, "order {order} from {errors:?}");
    }
}

#[test]
fn bad_parameters_are_refused_by_name() {
    let e = LinearElastic::new(10e9, 0.25, 2600.0).unwrap();
    let msg = |r: Result<Burgers, pcdc_mech::MechError>| r.unwrap_err().to_string();
    assert!(msg(Burgers::new(e.clone(), 0.0, 1e12, 1e12)).contains("Kelvin shear"));
    assert!(msg(Burgers::new(e.clone(), 1e9, -1.0, 1e12)).contains("Kelvin viscosity"));
    assert!(msg(Burgers::new(e.clone(), 1e9, 1e12, 0.0)).contains("Maxwell viscosity"));
    assert!(msg(Burgers::new(e.clone(), 1e9, 1e12, f64::NAN)).contains("Maxwell viscosity"));
    let b = Burgers::new(e, 1e9, 1e12, 1e12).unwrap();
    assert!(msg(b
        .clone()
        .with_kelvin_strain([1e-3, 0.0, 0.0, 0.0, 0.0, 0.0]))
    .contains("trace"));
    assert!(b
        .with_kelvin_strain([1e-3, -1e-3, 0.0, 2e-4, 0.0, 0.0])
        .is_ok());
    let json = r#"{"elastic":{"young":1e9,"poisson":0.2,"density":2000},
                   "kelvin_shear":1e9,"kelvin_viscosity":-5,"maxwell_viscosity":1e12}"#;
    let err = serde_json::from_str::<Burgers>(json)
        .unwrap_err()
        .to_string();
    assert!(err.contains("Kelvin viscosity"), "{err}");
}

proptest! {
    /// Without a creep step the model is elastic with K and G_M (as LinearElastic).
    #[test]
    fn no_creep_step_is_elastic(t in prop::array::uniform6(-1e-3..1e-3f64), gm in 1e8..1e10f64) {
        let m = model(gm, 3.0 * gm, 1e13, 1e14);
        let mut st = vec![0.0; BURGERS_STATE];
        m.init_state_into(&mut st);
        let mut a: Sym6 = [1e5, -2e5, 3e5, 4e4, 0.0, -1e4];
        let mut b = a;
        m.update_with(&ModelInput::new(&t, &t, &[0.0, 0.0]), &mut a, &mut st);
        m.elastic().update(&t, &t, &mut b, &mut []);
        for k in 0..6 {
            prop_assert!((a[k] - b[k]).abs() <= 1e-9 * (1.0 + b[k].abs()), "{a:?} vs {b:?}");
        }
    }

    /// The mean stress is elastic whatever the creep step.
    #[test]
    fn mean_stress_does_not_creep(v in -1e-3..1e-3f64, dt in 1.0..1e5f64) {
        let m = model(1e9, 2e9, 1e13, 1e14);
        let mut st = vec![0.0; BURGERS_STATE];
        m.init_state_into(&mut st);
        let mut sig: Sym6 = [-1e6; 6];
        sig[3] = 0.0; sig[4] = 0.0; sig[5] = 0.0;
        let de = [v, v, v, 0.0, 0.0, 0.0];
        m.update_with(&ModelInput::new(&de, &de, &[1.0, dt]), &mut sig, &mut st);
        let mean = (sig[0] + sig[1] + sig[2]) / 3.0;
        let k = m.elastic().bulk();
        prop_assert!((mean - (-1e6 + 3.0 * k * v)).abs() <= 1e-6 * (1e6 + (3.0 * k * v).abs()));
    }

    /// Maxwell limit: with a stiff, fast Kelvin body the creep is s/(2G_M) + s t/(2η_M),
    /// which Crank–Nicolson integrates exactly.
    #[test]
    fn stiff_kelvin_gives_maxwell(gm in 1e8..1e10f64, tm in 1e2..1e5f64, n in 2usize..20) {
        let m = model(gm, 1e9 * gm, 1e-3 * gm, tm * gm);
        let s = 1e6;
        let dt = tm / 10.0;
        let e = creep(&m, s, dt, n);
        let t = n as f64 * dt;
        let exact = s / (2.0 * gm) + s * t / (2.0 * tm * gm);
        prop_assert!((e[n - 1] - exact).abs() <= 1e-6 * exact, "{} vs {exact}", e[n - 1]);
    }

    /// Kelvin limit: with η_M → ∞ the strain tends to s/(2G_M) + s/(2G_K): the Kelvin
    /// body's final strain, reached to second order.
    #[test]
    fn stiff_maxwell_dashpot_gives_kelvin(gm in 1e8..1e10f64, ratio in 0.2..5.0f64) {
        let gk = ratio * gm;
        let tk = 100.0;
        let m = model(gm, gk, tk * gk, 1e30);
        let s = 1e6;
        let e = creep(&m, s, tk / 5.0, 100);
        let exact = s / (2.0 * gm) + s / (2.0 * gk);
        prop_assert!((e[99] - exact).abs() <= 1e-6 * exact, "{} vs {exact}", e[99]);
    }
}

#[test]
fn initial_kelvin_strain_is_the_state() {
    let b = model(1e9, 2e9, 1e13, 1e14)
        .with_kelvin_strain([1e-4, -1e-4, 0.0, 5e-5, 0.0, 0.0])
        .unwrap();
    let mut st = vec![0.0; BURGERS_STATE];
    b.init_state_into(&mut st);
    assert_eq!(
        st[state::KELVIN..state::KELVIN + 6],
        [1e-4, -1e-4, 0.0, 5e-5, 0.0, 0.0]
    );
}
