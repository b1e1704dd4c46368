//! Flow-only runs against closed forms and the mass balance.

use pcdc_compute::{Backend, Simulation, SubCycle};
use pcdc_hydro::fields::{FLOW_PRESSURE, FLOW_SATURATION};
use pcdc_hydro::{mass_balance, Aperture, Coupling, FlowModel, Fluid, Hydro};
use pcdc_mesh::{builders, split_nodes, Dim2, Range};

/// Carslaw & Jaeger (manual eq. 91–92 corrected): p held at x = 0, no flow at x = L,
/// p = 0 at t = 0; T = D t / L², ξ = 1 − x/L.
fn fracture_closed_form(p_a: f64, x: f64, l: f64, t_dimless: f64) -> f64 {
    let xi = 1.0 - x / l;
    let mut sum = 0.0;
    for n in 0..200 {
        let m = (2 * n + 1) as f64;
        let sign = if n % 2 == 0 { -1.0 } else { 1.0 };
        sum += sign / m
            * (-m * m * std::f64::consts::PI.powi(2) * t_dimless / 4.0).exp()
            * (m * std::f64::consts::PI * xi / 2.0).cos();
    }
    p_a * (1.0 + 4.0 / std::f64::consts::PI * sum)
}

/// The flow node nearest to `x` along the fracture y = 0.
fn node_at(sim: &Simulation<Dim2>, x: f64) -> usize {
    let set = sim.entity_set(pcdc_hydro::fields::FLOW_NODES).unwrap();
    let mesh = sim.mesh();
    (0..set.len())
        .min_by(|&a, &b| {
            let da = (mesh.node(set.entity(a)[0] as usize)[0] - x).abs();
            let db = (mesh.node(set.entity(b)[0] as usize)[0] - x).abs();
            da.total_cmp(&db)
        })
        .unwrap()
}

#[test]
fn transient_flow_along_one_fracture_matches_the_closed_form() {
    let (l, h, delta, p_a) = (1.0, 0.05, 1e-4, 1e6);
    let mesh = split_nodes(
        &builders::rectangle(0.0, -0.1, l, 0.2, h).unwrap(),
        &Range::All,
    )
    .unwrap();
    let fluid = Fluid::water();
    let model = FlowModel::new(fluid, Aperture::fixed(delta).unwrap());
    let flow = Hydro::new(model)
        .coupling(Coupling::FlowOnly)
        .network_on(Range::plane([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1e-9))
        .pressure(Range::rect(-1e-6, -1e-6, 1e-6, 1e-6), p_a);
    let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(flow)
        .build()
        .unwrap();
    let stage = sim.field_stages()[0].clone();
    assert_eq!(stage.cycle, SubCycle::Every(1));
    let diffusivity = fluid.bulk_modulus * delta * delta / (12.0 * fluid.dynamic_viscosity());
    let (mid, end) = (node_at(&sim, 0.5 * l), node_at(&sim, l));
    let mut worst: f64 = 0.0;
    for t_dimless in [0.05, 0.1, 0.2, 0.5, 1.0] {
        sim.run_until(t_dimless * l * l / diffusivity).unwrap();
        let t = sim.kinematics().time * diffusivity / (l * l);
        let p = sim.field(FLOW_PRESSURE).unwrap();
        for (node, x) in [(mid, 0.5 * l), (end, l)] {
            let exact = fracture_closed_form(p_a, x, l, t);
            worst = worst.max((p[node] - exact).abs() / p_a);
        }
    }
    assert!(worst < 0.02, "worst error {worst} of p_A");
    let b = mass_balance(&sim).unwrap();
    assert!(b.boundary > 0.0, "fluid entered through the held node");
    assert!(b.relative().abs() < 1e-12, "{b:?}");
}

#[test]
fn a_closed_network_conserves_and_relaxes_to_uniform_pressure() {
    // Gravity-free, closed, every joint a channel: pressure from a local injection
    // spreads and the injected volume is all stored.
    let mesh = split_nodes(
        &builders::rectangle(0.0, 0.0, 0.4, 0.2, 0.05).unwrap(),
        &Range::All,
    )
    .unwrap();
    let model = FlowModel::new(Fluid::water(), Aperture::fixed(2e-5).unwrap());
    let flow = Hydro::new(model)
        .coupling(Coupling::FlowOnly)
        .rate(Range::rect(0.19, 0.09, 0.21, 0.11), 1e-7);
    let mut sim = Simulation::builder(mesh, Backend::cpu(2).unwrap())
        .physics(flow)
        .build()
        .unwrap();
    let mut history = pcdc_compute::History::new();
    for (name, probe) in pcdc_hydro::balance_probes() {
        history = history.probe(name, probe);
    }
    for _ in 0..3 {
        sim.run(1000).unwrap();
        history.sample(&sim).unwrap();
    }
    let injected = history.column(0);
    assert!(injected.windows(2).all(|w| w[1] > w[0]), "{injected:?}");
    assert!(history
        .column(4)
        .iter()
        .all(|r| r.abs() <= 1e-12 * injected[2]));
    let b = mass_balance(&sim).unwrap();
    assert!(b.injected > 0.0);
    assert!(b.relative().abs() < 1e-12, "{b:?}");
    assert!((b.change - b.injected).abs() <= 1e-12 * b.injected);
    let p = sim.field(FLOW_PRESSURE).unwrap();
    assert!(p.iter().all(|&x| x > 0.0));
    let s = sim.field(FLOW_SATURATION).unwrap();
    assert!(s.iter().all(|&x| x == 1.0));
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let run = |threads| {
        let mesh = split_nodes(
            &builders::rectangle(0.0, 0.0, 2.0, 1.0, 0.02).unwrap(),
            &Range::All,
        )
        .unwrap();
        let model = FlowModel::new(Fluid::water(), Aperture::fixed(1e-5).unwrap());
        let flow = Hydro::new(model)
            .coupling(Coupling::FlowOnly)
            .gravity([0.0, -9.81, 0.0])
            .head(Range::rect(-0.01, -0.01, 0.01, 1.01), 0.8)
            .pressure(Range::rect(1.99, -0.01, 2.01, 1.01), 0.0);
        let mut sim = Simulation::builder(mesh, Backend::cpu(threads).unwrap())
            .physics(flow)
            .build()
            .unwrap();
        sim.run(50).unwrap();
        sim.field(FLOW_PRESSURE).unwrap().to_vec()
    };
    assert_eq!(run(1), run(2));
}

/// Calibrated to a rock mass permeability, the intact 2D network is the linear finite
/// element discretisation of Darcy flow: on a ring mesh (graded, unstructured) with a
/// linear pressure held on both boundaries it carries that field exactly (the patch
/// test). A uniform virtual aperture does not.
#[test]
fn calibrated_network_passes_the_patch_test() {
    let mesh = builders::ring([0.0, 0.0], 0.3, 1.0, 0.05, 0.15).unwrap();
    let field = |x: &[f64]| 1e6 * (1.0 + 0.5 * x[0] - 0.2 * x[1]);
    let split = split_nodes(&mesh, &Range::All).unwrap();
    let mut boundary: Vec<u32> = mesh.groups().nodes["inner"].clone();
    boundary.extend_from_slice(&mesh.groups().nodes["outer"]);
    let run = |calibrated: bool| {
        let model = FlowModel::new(Fluid::water(), Aperture::new(1e-6, 1e-9, 1e-3).unwrap());
        let mut flow = Hydro::new(model).coupling(Coupling::FlowOnly);
        for &n in &boundary {
            let x = mesh.node(n as usize);
            let at = Range::Ball {
                center: [x[0], x[1], 0.0],
                radius: 1e-6,
            };
            flow = flow.pressure(at, field(x));
        }
        if calibrated {
            flow = flow.rock_permeability(1e-14);
        }
        let mut sim = Simulation::builder(split.clone(), Backend::cpu(1).unwrap())
            .physics(flow)
            .build()
            .unwrap();
        let mut last = sim.field(FLOW_PRESSURE).unwrap().to_vec();
        for _ in 0..5000 {
            sim.run(200).unwrap();
            let p = sim.field(FLOW_PRESSURE).unwrap();
            let change = p
                .iter()
                .zip(&last)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            last.copy_from_slice(p);
            if change < 1e-6 {
                break;
            }
        }
        let set = sim.entity_set(pcdc_hydro::fields::FLOW_NODES).unwrap();
        (0..set.len())
            .map(|l| (last[l] - field(sim.mesh().node(set.entity(l)[0] as usize))).abs() / 1e6)
            .fold(0.0, f64::max)
    };
    let calibrated = run(true);
    let uniform = run(false);
    assert!(calibrated < 1e-6, "calibrated network: {calibrated}");
    assert!(
        uniform > 1e-3,
        "a uniform aperture on a graded mesh: {uniform}"
    );
}

/// The same fracture in SI and in millimetre–newton–second units (tonnes, MPa, mm²/s)
/// gives the same step and the same p/p_A: no unit system is built in.
#[test]
fn results_do_not_depend_on_the_unit_system() {
    let run = |l: f64, delta: f64, fluid: Fluid, p_a: f64| {
        let mesh = split_nodes(
            &builders::rectangle(0.0, -0.1 * l, l, 0.2 * l, 0.05 * l).unwrap(),
            &Range::All,
        )
        .unwrap();
        let e = 1e-6 * l;
        let flow = Hydro::new(FlowModel::new(fluid, Aperture::fixed(delta).unwrap()))
            .coupling(Coupling::FlowOnly)
            .network_on(Range::plane([0.0; 3], [0.0, 1.0, 0.0], e))
            .pressure(Range::rect(-e, -e, e, e), p_a);
        let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
            .physics(flow)
            .build()
            .unwrap();
        sim.run(300).unwrap();
        let p: Vec<f64> = sim
            .field(FLOW_PRESSURE)
            .unwrap()
            .iter()
            .map(|p| p / p_a)
            .collect();
        (sim.dt(), p)
    };
    let (dt_si, p_si) = run(1.0, 1e-4, Fluid::water(), 1e6);
    let mm = Fluid::new(1e-9, 2200.0, 1.0).unwrap();
    let (dt_mm, p_mm) = run(1000.0, 0.1, mm, 1.0);
    assert!((dt_si - dt_mm).abs() <= 1e-12 * dt_si, "{dt_si} vs {dt_mm}");
    let worst = p_si
        .iter()
        .zip(&p_mm)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(p_si.iter().any(|&x| x > 0.1));
    assert!(worst < 1e-9, "p/p_A differs by {worst}");
}

/// Above a water level the face is a seepage face: a saturated node there is held at
/// p = 0 and its excess leaves (booked as outflow), a dry one stays dry; below it the
/// pressure is hydrostatic.
#[test]
fn water_level_has_a_seepage_face_above_it() {
    let mesh = split_nodes(
        &builders::rectangle(0.0, 0.0, 0.4, 0.2, 0.05).unwrap(),
        &Range::All,
    )
    .unwrap();
    let model = FlowModel::new(Fluid::water(), Aperture::fixed(1e-4).unwrap());
    let level = 0.05;
    let flow = Hydro::new(model)
        .coupling(Coupling::FlowOnly)
        .gravity([0.0, -9.81, 0.0])
        .bulk_modulus_scale(1e-4)
        .initial_pressure(3e3)
        .head(Range::rect(0.39, -0.01, 0.41, 0.21), level);
    let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(flow)
        .build()
        .unwrap();
    sim.run(200).unwrap();
    let set = sim.entity_set("flow_nodes").unwrap();
    let p = sim.field(FLOW_PRESSURE).unwrap();
    let s = sim.field(FLOW_SATURATION).unwrap();
    let mut above = 0;
    for l in 0..set.len() {
        let x = sim.mesh().node(set.entity(l)[0] as usize);
        if x[0] > 0.39 {
            if x[1] > level + 1e-9 {
                above += 1;
                assert_eq!(p[l], 0.0, "seepage node at {x:?}");
                assert!(s[l] <= 1.0);
            } else {
                let hydro = 1000.0 * 9.81 * (level - x[1]);
                assert!(
                    (p[l] - hydro).abs() <= 1e-9 * hydro.max(1.0),
                    "{} vs {hydro}",
                    p[l]
                );
            }
        }
    }
    assert_eq!(above, 3);
    let b = mass_balance(&sim).unwrap();
    assert!(b.boundary < 0.0, "the block drained: {b:?}");
    assert!(b.relative().abs() < 1e-12, "{b:?}");
}
