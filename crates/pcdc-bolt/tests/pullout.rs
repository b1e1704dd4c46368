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
