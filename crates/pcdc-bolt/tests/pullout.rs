//! A fully grouted bolt pulled from a block held fixed (a rigid host): the axial force
//! along it against the closed form F(x) = F0 sinh(β(L − x)) / sinh(βL), β = √(K / E A);
//! pulled further, the peak load is the bond strength times the length; action equals
//! reaction between the bolt and its hosts.

use pcdc_bolt::{Bolt, BoltMaterial, BoltNodes, BoltProperties, Bolts, BOLT_AXIAL_FORCE};
use pcdc_compute::{Backend, Simulation, StaticOptions};
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim2, Range};

const L: f64 = 2.0; // m
const K: f64 = 2.5e8; // N/m/m

fn rebar() -> BoltProperties {
    BoltProperties {
        shear_stiffness: K,
        ..BoltProperties::steel_rebar(0.025)
    }
}

fn pull(
    props: BoltProperties,
    segments: usize,
    head: BoltNodes,
    force: f64,
) -> (Simulation<Dim2>, Bolts) {
    let mesh = builders::rectangle(-0.1, -0.1, L + 0.2, 0.2, 0.05).unwrap();
    let bolt = Bolt::straight(
        "B1",
        [0.0, 0.0, 0.0],
        [L, 0.0, 0.0],
        segments,
        BoltMaterial::new(props).unwrap(),
    )
    .unwrap();
    let bolts = Bolts::new().bolt(bolt).unwrap();
    let load = bolts
        .boundary()
        .force("B1", head, [Some((-force).into()), None, None])
        .unwrap();
    let sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(
            Mechanics::new().material(Range::All, LinearElastic::new(30e9, 0.25, 2700.0).unwrap()),
        )
        .physics(Boundary::new().fix(Range::All))
        .physics(bolts.clone())
        .physics(load)
        .build()
        .unwrap();
    (sim, bolts)
}

#[test]
fn elastic_pullout_matches_the_closed_form() {
    let f0 = 50e3;
    let n = 40;
    let (mut sim, bolts) = pull(rebar(), n, BoltNodes::Head, f0);
    sim.relax(&StaticOptions {
        tolerance: 1e-9,
        ..StaticOptions::default()
    })
    .unwrap();
    let m = BoltMaterial::new(rebar()).unwrap();
    let beta = (K / (m.properties().young * m.area())).sqrt();
    let profile = pcdc_bolt::output::axial_force_profile(&sim, &bolts, 0).unwrap();
    let mut worst: f64 = 0.0;
    for (x, f) in &profile {
        let exact = f0 * (beta * (L - x)).sinh() / (beta * L).sinh();
        worst = worst.max((f - exact).abs() / f0);
    }
    assert!(worst < 0.01, "largest error {worst} of F0");
    // Nothing slipped: the bond is not reached.
    assert!(sim
        .field(pcdc_bolt::BOLT_SLIP)
        .unwrap()
        .iter()
        .all(|s| *s == 0.0));
    assert_eq!(sim.field(BOLT_AXIAL_FORCE).unwrap().len(), n);
}

#[test]
fn pulled_to_failure_the_peak_is_bond_strength_times_length() {
    // The head pulled out slowly: once every node has slipped the grout carries its
    // full strength everywhere, S_b L in all (no confinement: friction plays no part).
    let props = BoltProperties {
        friction_rock_grout: 0.0,
        friction_grout_bolt: 0.0,
        cohesion_rock_grout: 0.5e6,
        ..rebar()
    };
    let m = BoltMaterial::new(props).unwrap();
    let capacity = m.bond_strength(0.0) * L;
    assert!(
        capacity < props.tensile_yield_force,
        "the bolt must not yield first"
    );
    let mesh = builders::rectangle(-0.1, -0.1, L + 0.2, 0.2, 0.05).unwrap();
    let bolts = Bolts::new()
        .bolt(Bolt::straight("B1", [0.0; 3], [L, 0.0, 0.0], 20, m).unwrap())
        .unwrap();
    let pull = bolts
        .boundary()
        .velocity("B1", BoltNodes::Head, [Some((-0.05).into()), None, None])
        .unwrap();
    let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(
            Mechanics::new().material(Range::All, LinearElastic::new(30e9, 0.25, 2700.0).unwrap()),
        )
        .physics(Boundary::new().fix(Range::All))
        .physics(bolts)
        .physics(pull)
        .local_damping(0.3)
        .build()
        .unwrap();
    let mut peak: f64 = 0.0;
    while sim.kinematics().time < 0.08 {
        sim.run(100).unwrap();
        let grout: f64 = sim.field(pcdc_bolt::BOLT_GROUT_FORCE).unwrap().iter().sum();
        peak = peak.max(-grout);
    }
    assert!(
        ((peak - capacity) / capacity).abs() < 1e-9,
        "{peak} vs {capacity}"
    );
    assert!(sim
        .field(pcdc_bolt::BOLT_SLIP)
        .unwrap()
        .iter()
        .all(|s| *s < 0.0));
}

#[test]
fn action_equals_reaction_between_bolt_and_host() {
    // A free (unfixed) block: after some steps of a pull, the bolts' forces on bolt and
    // host nodes sum to zero exactly, whatever the host positions.
    let mesh = builders::rectangle(-0.1, -0.1, L + 0.2, 0.2, 0.05).unwrap();
    let bolt = Bolt::straight(
        "B1",
        [0.013, 0.007, 0.0],
        [L - 0.011, -0.031, 0.0],
        17,
        BoltMaterial::new(rebar()).unwrap(),
    )
    .unwrap();
    let bolts = Bolts::new().bolt(bolt).unwrap();
    let load = bolts
        .boundary()
        .velocity(
            "B1",
            BoltNodes::Head,
            [Some((-0.5).into()), Some(0.2.into()), None],
        )
        .unwrap();
    let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(
            Mechanics::new().material(Range::All, LinearElastic::new(30e9, 0.25, 2700.0).unwrap()),
        )
        .physics(bolts)
        .physics(load)
        .build()
        .unwrap();
    sim.run(300).unwrap();
    let f = sim.evaluate_forces().unwrap().to_vec();
    // The mechanics' element forces sum to zero on their own; so must the total.
    let (fx, fy) = f
        .chunks(2)
        .fold((0.0, 0.0), |(a, b), c| (a + c[0], b + c[1]));
    let scale = f.iter().map(|v| v.abs()).fold(0.0, f64::max);
    assert!(
        fx.abs() <= 1e-9 * scale && fy.abs() <= 1e-9 * scale,
        "{fx} {fy} of {scale}"
    );
}

/// The same bolted plate in SI and in millimetre–newton–second units (tonnes, MPa,
/// N/mm): a pretensioned, plated, damped bolt row (spacing 1.5 m) in elastic rock,
/// pulled at its head past the bond so that the grout slips and the head segments yield.
/// Same step, same forces per bolt, same slip and displacements after conversion: no
/// unit system is built into the bolts. The bolt's nodes lie on element edges (x on the
/// mesh's columns): before hosts within rounding of a tie went to the lowest index, the
/// two unit systems grouted some of them to different elements, whose different stresses
/// gave a different confinement (0.2 % in slip).
#[test]
fn results_do_not_depend_on_the_unit_system() {
    // `l`: metres per length unit; `s`: pascals per stress unit; `m`: kg per mass unit.
    let run = |l: f64, s: f64, m: f64| {
        let f = s * l * l; // newtons per force unit (1 in both systems)
        let mesh = builders::rectangle(0.0, 0.0, 2.0 / l, 0.4 / l, 0.05 / l).unwrap();
        let area = std::f64::consts::PI * 0.025f64.powi(2) / 4.0;
        let props = BoltProperties {
            density: 7850.0 / (m / (l * l * l)),
            young: 200e9 / s,
            diameter: 0.025 / l,
            tensile_yield_force: 300e6 * area / f,
            compressive_yield_force: 300e6 * area / f,
            tension_failure_strain: 0.1,
            shear_stiffness: 1e9 / (f / (l * l)),
            normal_stiffness: Some(5e8 / (f / (l * l))),
            grout_thickness: 0.01 / l,
            cohesion_rock_grout: 0.2e6 / s,
            cohesion_grout_bolt: 5e6 / s,
            friction_rock_grout: 30.0,
            friction_grout_bolt: 30.0,
            spacing: Some(1.5 / l),
            pretension: 20e3 / f,
            damping_factor: 0.1,
        };
        let bolt = Bolt::straight(
            "B",
            [0.1 / l, 0.2 / l, 0.0],
            [1.9 / l, 0.23 / l, 0.0],
            12,
            BoltMaterial::new(props).unwrap(),
        )
        .unwrap()
        .free_length(0.3 / l)
        .unwrap()
        .face_plate(1e8 / (f / l))
        .unwrap();
        let bolts = Bolts::new().bolt(bolt).unwrap();
        let pull = bolts
            .boundary()
            .force(
                "B",
                BoltNodes::Head,
                [Some((-150e3 / f).into()), None, None],
            )
            .unwrap();
        let rock = LinearElastic::new(20e9 / s, 0.25, 2600.0 / (m / (l * l * l))).unwrap();
        let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
            .physics(Mechanics::new().material(Range::All, rock))
            .physics(Boundary::new().fix(Range::group("right")))
            .physics(bolts)
            .physics(pull)
            .build()
            .unwrap();
        sim.run(400).unwrap();
        // Per unit thickness in 2D: forces per length unit, converted to N/m.
        let per_m = f / l;
        let field = |name, scale: f64| -> Vec<f64> {
            sim.field(name).unwrap().iter().map(|v| v * scale).collect()
        };
        (
            sim.dt(),
            field(BOLT_AXIAL_FORCE, per_m),
            field(pcdc_bolt::BOLT_GROUT_FORCE, per_m),
            field(pcdc_bolt::BOLT_SLIP, l),
            field(pcdc_bolt::BOLT_STATE, 1.0),
            sim.state.u.iter().map(|u| u * l).collect::<Vec<f64>>(),
        )
    };
    let si = run(1.0, 1.0, 1.0);
    let mm = run(1e-3, 1e6, 1e3);
    assert!(
        (si.0 - mm.0).abs() <= 1e-12 * si.0,
        "dt {} vs {}",
        si.0,
        mm.0
    );
    let compare = |what: &str, a: &[f64], b: &[f64]| {
        let scale = a.iter().map(|v| v.abs()).fold(0.0, f64::max);
        assert!(scale > 0.0, "{what} is all zero");
        let worst = a
            .iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        assert!(
            worst <= 1e-9 * scale,
            "{what}: differs by {worst} of {scale}"
        );
    };
    compare("axial force", &si.1, &mm.1);
    compare("grout force", &si.2, &mm.2);
    compare("slip", &si.3, &mm.3);
    compare("displacement", &si.5, &mm.5);
    assert_eq!(si.4, mm.4, "segment states");
    // The run reaches what it is meant to test: slip and a yielded segment.
    assert!(si.3.iter().any(|s| s.abs() > 1e-6), "no slip: {:?}", si.3);
    assert!(si.4.contains(&1.0), "no segment yields: {:?}", si.4);
}
