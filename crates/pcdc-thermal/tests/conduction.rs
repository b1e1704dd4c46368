//! Conduction against closed forms and the properties every conduction must keep:
//! energy conserved with adiabatic boundaries and balanced with heat supplied, uniform
//! temperature unchanged, heat from hot to cold without new extremes.

use pcdc_compute::{names, Backend, ComputeError, Simulation};
use pcdc_mesh::{builders, Dim, Mesh, Range};
use pcdc_thermal::{heat_content, HeatMaterial, Thermal, HEAT_CAPACITY, HEAT_FLUX, HEAT_SUPPLIED};
use proptest::prelude::*;

/// erfc to 1.2e-7 (Numerical Recipes' Chebyshev fit).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let r = t
        * (-z * z - 1.265_512_23
            + t * (1.000_023_68
                + t * (0.374_091_96
                    + t * (0.096_784_18
                        + t * (-0.186_288_06
                            + t * (0.278_868_07
                                + t * (-1.135_203_98
                                    + t * (1.488_515_87
                                        + t * (-0.822_152_23 + t * 0.170_872_77)))))))))
            .exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

fn run_to<D: Dim>(sim: &mut Simulation<D>, t_end: f64) {
    while sim.kinematics().time < t_end - 1e-12 * t_end {
        sim.step().unwrap();
    }
}

/// Largest |T − T_exact| / |T_s − T_0| over the nodes, half-space after a surface step
/// at x = 0 (T = T0 + (Ts − T0) erfc(x / (2√(κt)))).
fn half_space_error<D: Dim>(mesh: Mesh<D>, surface: &str, k: f64, rho_c: f64, t_end: f64) -> f64 {
    let (t0, ts) = (10.0, 110.0);
    let mat = HeatMaterial::new(k, rho_c / 1000.0, 1000.0).unwrap();
    let heat = Thermal::new()
        .material(Range::All, mat)
        .initial_temperature(t0)
        .temperature(Range::group(surface), ts)
        .heat_only();
    let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(heat)
        .build()
        .unwrap();
    run_to(&mut sim, t_end);
    let time = sim.kinematics().time;
    let kappa = k / rho_c;
    let temp = sim.field(names::TEMPERATURE).unwrap();
    let mut worst = 0.0f64;
    for (n, &t) in temp.iter().enumerate() {
        let x = sim.mesh().node(n)[0];
        let exact = t0 + (ts - t0) * erfc(x / (2.0 * (kappa * time).sqrt()));
        worst = worst.max((t - exact).abs() / (ts - t0));
    }
    eprintln!(
        "half-space: {} nodes, {} steps to t = {time:e} s (dt {:e}), max error {worst:e}",
        temp.len(),
        sim.kinematics().step,
        sim.dt()
    );
    worst
}

#[test]
fn half_space_2d_matches_erfc() {
    // 2√(κt) = 0.2 m on a 1 m bar of 1 cm elements: the far end stays at T0.
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 0.05, 0.01).unwrap();
    let err = half_space_error(mesh, "left", 2.0, 2.0, 0.01);
    assert!(err < 0.02, "2D half-space error {err}");
}

#[test]
fn half_space_3d_matches_erfc() {
    let mesh = builders::cuboid([0.0; 3], [0.6, 0.04, 0.04], 0.02).unwrap();
    let err = half_space_error(mesh, "xmin", 1.0, 1.0, 0.01);
    assert!(err < 0.02, "3D half-space error {err}");
}

#[test]
fn result_does_not_depend_on_the_unit_system() {
    // The same problem in metres/seconds and in millimetres/milliseconds (k in
    // W/(mm·K) scaled accordingly): the normalised error is the same to rounding.
    let m = builders::rectangle(0.0, 0.0, 1.0, 0.05, 0.02).unwrap();
    let mm = builders::rectangle(0.0, 0.0, 1000.0, 50.0, 20.0).unwrap();
    // κ = k/(ρC): 1 m²/s = 1e6 mm²/s = 1e3 mm²/ms; t = 0.01 s = 10 ms.
    let a = half_space_error(m, "left", 1.0, 1.0, 0.01);
    let b = half_space_error(mm, "left", 1e3, 1.0, 10.0);
    assert!((a - b).abs() < 1e-9, "{a} vs {b}");
}

fn sim_with(
    mesh: Mesh<pcdc_mesh::Dim2>,
    heat: Thermal,
) -> Result<Simulation<pcdc_mesh::Dim2>, ComputeError> {
    Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(heat.heat_only())
        .build()
}

fn granite() -> HeatMaterial {
    HeatMaterial::new(3.0, 800.0, 2700.0).unwrap()
}

#[test]
fn uniform_temperature_stays_uniform_and_flux_is_zero() {
    let mesh = builders::plate_with_hole(1.0, 1.0, 0.2, 0.05, 0.2).unwrap();
    let mut sim = sim_with(
        mesh,
        Thermal::new()
            .material(Range::All, granite())
            .initial_temperature(300.0),
    )
    .unwrap();
    sim.run(50).unwrap();
    assert!(sim
        .field(names::TEMPERATURE)
        .unwrap()
        .iter()
        .all(|&t| (t - 300.0).abs() <= 1e-12 * 300.0));
    assert!(sim
        .field(HEAT_FLUX)
        .unwrap()
        .iter()
        .all(|&q| q.abs() < 1e-9));
}

#[test]
fn convection_cools_towards_the_environment_and_balances() {
    let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.02).unwrap();
    let mut sim = sim_with(
        mesh,
        Thermal::new()
            .material(Range::All, granite())
            .initial_temperature(80.0)
            .convection(Range::group("left"), 50.0, 20.0)
            .heat_flux(Range::group("right"), 200.0),
    )
    .unwrap();
    let cap = sim.field(HEAT_CAPACITY).unwrap().to_vec();
    let q0 = heat_content(&cap, sim.field(names::TEMPERATURE).unwrap());
    sim.run(400).unwrap();
    let temp = sim.field(names::TEMPERATURE).unwrap();
    assert!(temp.iter().all(|&t| t < 80.0 + 1.0 && t > 20.0));
    let supplied: f64 = sim.field(HEAT_SUPPLIED).unwrap().iter().sum();
    let q1 = heat_content(&cap, temp);
    assert!(
        supplied < 0.0,
        "convection at 50 W/m²K out-cools 200 W/m² in"
    );
    assert!(
        (q1 - q0 - supplied).abs() <= 1e-10 * q0.abs(),
        "balance {} vs {supplied}",
        q1 - q0
    );
}

#[test]
fn stable_step_is_reported_with_its_node() {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 0.1, 0.05).unwrap();
    let sim = sim_with(mesh, Thermal::new().material(Range::All, granite())).unwrap();
    let limit = sim.time_step_limit().unwrap();
    assert_eq!(limit.physics, "thermal");
    // Right triangles of legs h: the corner-node bound is of the order h²/(4κ).
    let kappa = granite().diffusivity();
    let h2k = 0.05f64.powi(2) / kappa;
    assert!(
        limit.dt > 0.1 * h2k && limit.dt < 1.0 * h2k,
        "{} vs h²/κ {h2k}",
        limit.dt
    );
}

#[test]
fn bad_input_is_refused_with_names() {
    let msg = |r: Result<HeatMaterial, ComputeError>| r.unwrap_err().to_string();
    assert!(msg(HeatMaterial::new(0.0, 800.0, 2700.0)).contains("conductivity"));
    assert!(msg(HeatMaterial::new(3.0, -1.0, 2700.0)).contains("capacity"));
    assert!(msg(HeatMaterial::new(3.0, 800.0, 0.0)).contains("density"));
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 0.1, 0.05).unwrap();
    let err = sim_with(
        mesh.clone(),
        Thermal::new()
            .material(Range::All, granite())
            .convection(Range::group("left"), -1.0, 20.0),
    )
    .err()
    .unwrap()
    .to_string();
    assert!(err.contains("transfer coefficient"), "{err}");
    let err = sim_with(mesh.clone(), Thermal::new())
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("HeatMaterial"), "{err}");
    let json = r#"{"conductivity":{"isotropic":-2.0},"capacity":800.0,"density":2700.0}"#;
    assert!(serde_json::from_str::<HeatMaterial>(json).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Adiabatic boundaries: the heat content is conserved to rounding, the
    /// temperatures stay within the initial bounds (no new extremes on right
    /// triangles), and heat flows down the gradient.
    #[test]
    fn conduction_conserves_and_flows_hot_to_cold(
        temps in proptest::collection::vec(-50.0f64..150.0, 6..7),
        steps in 1u64..40,
    ) {
        let mesh = builders::rectangle(0.0, 0.0, 0.3, 0.2, 0.05).unwrap();
        let t_of = move |x: &[f64]| {
            let i = ((x[0] / 0.05).round() as usize).min(temps.len() - 1);
            temps[i] + 10.0 * x[1]
        };
        let mut sim = sim_with(
            mesh,
            Thermal::new().material(Range::All, granite()).initial_temperature_fn(t_of),
        )
        .unwrap();
        let cap = sim.field(HEAT_CAPACITY).unwrap().to_vec();
        let t0 = sim.field(names::TEMPERATURE).unwrap().to_vec();
        let (lo, hi) = t0.iter().fold((f64::MAX, f64::MIN), |(a, b), &t| (a.min(t), b.max(t)));
        let q0 = heat_content(&cap, &t0);
        let scale: f64 = cap.iter().zip(&t0).map(|(c, t)| (c * t).abs()).sum();
        sim.step().unwrap();
        // Hot to cold: q · ∇T ≤ 0 in every element (k positive definite).
        let flux = sim.field(HEAT_FLUX).unwrap().to_vec();
        for e in 0..sim.mesh().n_elements() {
            let nodes = sim.mesh().element(e).to_vec();
            let x: Vec<&[f64]> = nodes.iter().map(|&n| sim.mesh().node(n as usize)).collect();
            let t: Vec<f64> = nodes.iter().map(|&n| t0[n as usize]).collect();
            // ∇T of the linear triangle.
            let (a, b) = ([x[1][0] - x[0][0], x[1][1] - x[0][1]], [x[2][0] - x[0][0], x[2][1] - x[0][1]]);
            let det = a[0] * b[1] - a[1] * b[0];
            let (d1, d2) = (t[1] - t[0], t[2] - t[0]);
            let g = [(d1 * b[1] - d2 * a[1]) / det, (d2 * a[0] - d1 * b[0]) / det];
            prop_assert!(flux[2 * e] * g[0] + flux[2 * e + 1] * g[1] <= 1e-9);
        }
        sim.run(steps).unwrap();
        let t = sim.field(names::TEMPERATURE).unwrap();
        let q = heat_content(&cap, t);
        prop_assert!((q - q0).abs() <= 1e-13 * scale, "{q} vs {q0}");
        for &v in t {
            prop_assert!(v >= lo - 1e-9 && v <= hi + 1e-9, "{v} outside [{lo}, {hi}]");
        }
    }
}

/// The output helpers: the energy balance closes, a VTU step with the thermal arrays is
/// written.
#[test]
fn output_writes_vtu_and_balances() {
    let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.05).unwrap();
    let mut sim = sim_with(
        mesh,
        Thermal::new()
            .material(Range::All, granite())
            .initial_temperature(20.0)
            .heat_flux(Range::group("left"), 1e3),
    )
    .unwrap();
    let t0 = sim.field(names::TEMPERATURE).unwrap().to_vec();
    sim.run(20).unwrap();
    let b = pcdc_thermal::output::energy_balance(&sim, &t0).unwrap();
    assert!(b.supplied > 0.0 && b.relative() < 1e-12, "{b:?}");
    let dir = std::env::temp_dir().join(format!("pcdc_thermal_vtu_{}", std::process::id()));
    let mut series = pcdc_mesh::vtu::PvdSeries::new(&dir, "heat").unwrap();
    let path = pcdc_thermal::output::write_step(&sim, &mut series).unwrap();
    // Binary appended data: the array names are in the XML head.
    let text = String::from_utf8_lossy(&std::fs::read(&path).unwrap()).into_owned();
    assert!(text.contains("Name=\"temperature\"") && text.contains("Name=\"heat_flux\""));
    std::fs::remove_dir_all(&dir).ok();
}

/// `heat_only` with a mechanics would add unit masses to the mechanics' nodes: refused.
#[test]
fn heat_only_with_a_mechanics_is_refused() {
    let mesh = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.05).unwrap();
    let rock = pcdc_mech::LinearElastic::new(30e9, 0.25, 2700.0).unwrap();
    let err = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(pcdc_mech::Mechanics::new().material(Range::All, rock))
        .physics(Thermal::new().material(Range::All, granite()).heat_only())
        .build()
        .err()
        .expect("refused")
        .to_string();
    assert!(err.contains("heat_only"), "{err}");
}
