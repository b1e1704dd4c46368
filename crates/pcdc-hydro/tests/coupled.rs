//! Two-way coupling with elements and cohesive joints: the pressure loads the joints'
//! faces equal and opposite, injection opens them, and volume is conserved.

use pcdc_cohesive::{CohesiveJoints, IntrinsicCzmParams};
use pcdc_compute::{Backend, Simulation, SubCycle, Table};
use pcdc_hydro::fields::{CHANNEL_APERTURE, FLOW_PEAK_PRESSURE, FLOW_PRESSURE};
use pcdc_hydro::{mass_balance, Aperture, FlowModel, Fluid, Hydro};
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{builders, split_nodes, Dim2, Mesh, Range};

fn rock() -> LinearElastic {
    LinearElastic::new(10e9, 0.25, 2600.0)
        .unwrap()
        .with_damping(0.5)
        .unwrap()
}

fn joints(tensile: f64) -> CohesiveJoints {
    let czm = IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 2.0 * tensile,
        tensile_strength: tensile,
        gf1: 1.0,
        gf2: 10.0,
        penalty_open: 1e11,
        penalty_shear: 1e11,
        penalty_overlap: 1e12,
    }
    .build()
    .unwrap();
    CohesiveJoints::new().model(Range::All, czm)
}

fn block() -> Mesh<Dim2> {
    split_nodes(
        &builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.02).unwrap(),
        &Range::All,
    )
    .unwrap()
}

fn model() -> FlowModel {
    FlowModel::new(Fluid::water(), Aperture::new(1e-5, 1e-6, 1e-3).unwrap())
}

#[test]
fn pressure_loads_both_faces_equal_and_opposite() {
    let p0 = 1e6;
    let mut sim = Simulation::builder(block(), Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock()))
        .physics(joints(1e7))
        .physics(Hydro::new(model()).initial_pressure(p0))
        .build()
        .unwrap();
    // At rest the elements and joints exert nothing: the forces are the fluid's.
    let f = sim.evaluate_forces().unwrap().to_vec();
    let (fx, fy) = (
        f.iter().step_by(2).sum::<f64>(),
        f.iter().skip(1).step_by(2).sum::<f64>(),
    );
    let scale: f64 = f.iter().map(|x| x.abs()).sum();
    assert!(scale > 0.0);
    assert!(
        fx.abs() <= 1e-12 * scale && fy.abs() <= 1e-12 * scale,
        "{fx} {fy} of {scale}"
    );
    // On one joint: side B's nodes carry p L along the normal, side A's the opposite.
    let mesh = sim.mesh().clone();
    let joint = mesh.interfaces().get(0).unwrap();
    let (a0, a1) = (
        mesh.node(joint.side_a[0] as usize),
        mesh.node(joint.side_a[1] as usize),
    );
    let len = ((a1[0] - a0[0]).powi(2) + (a1[1] - a0[1]).powi(2)).sqrt();
    // Each node belongs to several joints: compare the hydro slots through a run-free
    // check, the sum over the element of side B of its nodes' forces (uniform pressure on
    // a closed triangle whose three edges are all channels balances to zero).
    let elem = joint.elements[1] as usize;
    let on_elem: [f64; 2] = std::array::from_fn(|k| {
        mesh.element(elem)
            .iter()
            .map(|&n| f[n as usize * 2 + k])
            .sum::<f64>()
    });
    let interior = mesh
        .interfaces()
        .iter()
        .filter(|j| j.elements.contains(&(elem as u32)))
        .count()
        == 3;
    if interior {
        assert!(on_elem[0].abs() < 1e-9 * p0 * len && on_elem[1].abs() < 1e-9 * p0 * len);
    }
    // A corner element with one channel face: the net force is p L on that face.
    let corner = (0..mesh.n_elements())
        .find(|&e| {
            mesh.interfaces()
                .iter()
                .filter(|j| j.elements.contains(&(e as u32)))
                .count()
                == 1
        })
        .expect("a corner triangle");
    let net: [f64; 2] = std::array::from_fn(|k| {
        mesh.element(corner)
            .iter()
            .map(|&n| f[n as usize * 2 + k])
            .sum::<f64>()
    });
    let j = mesh
        .interfaces()
        .iter()
        .find(|j| j.elements.contains(&(corner as u32)))
        .unwrap();
    let (b0, b1) = (
        mesh.node(j.side_a[0] as usize),
        mesh.node(j.side_a[1] as usize),
    );
    let lj = ((b1[0] - b0[0]).powi(2) + (b1[1] - b0[1]).powi(2)).sqrt();
    let mag = (net[0] * net[0] + net[1] * net[1]).sqrt();
    assert!(
        (mag - p0 * lj).abs() <= 1e-9 * p0 * lj,
        "{mag} vs {}",
        p0 * lj
    );
}

#[test]
fn injection_opens_joints_and_conserves_volume() {
    let flow = Hydro::new(model())
        .bulk_modulus_scale(0.01)
        .rate(Range::rect(0.099, 0.039, 0.101, 0.041), 2e-6);
    let mut sim = Simulation::builder(block(), Backend::cpu(2).unwrap())
        .physics(Mechanics::new().material(Range::All, rock()))
        .physics(joints(1e7))
        .physics(flow)
        .build()
        .unwrap();
    let limit = sim.time_step_limit().unwrap().clone();
    let stage = sim.field_stages()[0].clone();
    assert!(stage.limit.is_some());
    sim.run(400).unwrap();
    let b = mass_balance(&sim).unwrap();
    assert!(b.injected > 0.0);
    assert!(b.relative().abs() < 1e-12, "{b:?}");
    let a = sim.field(CHANNEL_APERTURE).unwrap();
    let widest = a.iter().cloned().fold(0.0, f64::max);
    assert!(
        widest > 1e-5,
        "the pressure opened a joint: widest {widest} (limit {limit:?}, {stage:?})"
    );
}

#[test]
fn peak_pressure_is_the_maximum_over_every_fluid_step() {
    const SCALE: f64 = 1e-3;
    // Injection for the first 100 steps' worth of time, then none while the ends drain:
    // the pressure rises and falls, and the peak must keep its highest value, not the
    // last nor one seen only at an output interval. K_f is scaled so far down that the
    // fluid steps no more often than the solid (every fluid step is seen here).
    let probe = Simulation::builder(block(), Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock()))
        .physics(joints(1e7))
        .physics(Hydro::new(model()).bulk_modulus_scale(SCALE))
        .build()
        .unwrap();
    let stop = 100.0 * probe.dt();
    let rate = Table::new("rate", &[(0.0, 2e-6), (stop, 2e-6), (1.01 * stop, 0.0)]).unwrap();
    let flow = Hydro::new(model())
        .bulk_modulus_scale(SCALE)
        .rate(Range::rect(0.099, 0.039, 0.101, 0.041), rate)
        .pressure(Range::group("left"), 0.0)
        .pressure(Range::group("right"), 0.0);
    let mut sim = Simulation::builder(block(), Backend::cpu(2).unwrap())
        .physics(Mechanics::new().material(Range::All, rock()))
        .physics(joints(1e7))
        .physics(flow)
        .build()
        .unwrap();
    let cycle = sim.field_stages()[0].cycle;
    assert!(matches!(cycle, SubCycle::Every(_)), "{cycle:?}");
    let mut seen = sim.field(FLOW_PRESSURE).unwrap().to_vec();
    for _ in 0..600 {
        sim.step().unwrap();
        for (m, &p) in seen.iter_mut().zip(sim.field(FLOW_PRESSURE).unwrap()) {
            *m = m.max(p);
        }
    }
    let (p, peak) = (
        sim.field(FLOW_PRESSURE).unwrap(),
        sim.field(FLOW_PEAK_PRESSURE).unwrap(),
    );
    assert_eq!(peak, &seen[..]);
    let fell = p
        .iter()
        .zip(peak)
        .filter(|(p, m)| **p < 0.5 * **m && **m > 0.0)
        .count();
    assert!(
        fell > 0,
        "the pressure fell somewhere after the injection stopped"
    );
}
