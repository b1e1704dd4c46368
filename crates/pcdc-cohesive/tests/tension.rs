//! A fully split bar pulled apart breaks when its mean stress reaches the tensile
//! strength (2D and 3D), with results independent of the thread count.

use pcdc_cohesive::{CohesiveJoints, IntrinsicCzm, IntrinsicCzmParams, JOINT_DAMAGE};
use pcdc_compute::{Backend, Simulation};
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, split_nodes, Dim, Mesh, Range};

const E: f64 = 30e9;
const TS: f64 = 2e6;

fn czm() -> IntrinsicCzm {
    IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 10e6,
        tensile_strength: TS,
        gf1: 0.5,
        gf2: 5.0,
        penalty_open: 10.0 * E,
        penalty_shear: 10.0 * E,
        penalty_overlap: 100.0 * E,
    }
    .build()
    .unwrap()
}

/// Pulls the `top` group up at `v` with `bottom` held in the pull direction; returns the
/// peak mean stress (Pa) on the bottom section and the number of broken joints.
fn pull<D: Dim>(
    mesh: Mesh<D>,
    bottom: &str,
    top: &str,
    area: f64,
    threads: usize,
) -> (f64, usize, Vec<f64>) {
    pull_with(mesh, bottom, top, area, threads, 3)
}

fn pull_with<D: Dim>(
    mesh: Mesh<D>,
    bottom: &str,
    top: &str,
    area: f64,
    threads: usize,
    gauss_3d: usize,
) -> (f64, usize, Vec<f64>) {
    let split = split_nodes(&mesh, &Range::All).unwrap();
    let axis = D::D - 1;
    let mut up = [None, None, None];
    up[axis] = Some(0.02.into());
    let mut hold = [None, None, None];
    hold[axis] = Some(0.0.into());
    let rock = LinearElastic::new(E, 0.25, 2600.0)
        .unwrap()
        .with_damping(0.3)
        .unwrap();
    let mut sim = Simulation::builder(split.clone(), Backend::cpu(threads).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(
            CohesiveJoints::new()
                .model(Range::All, czm())
                .gauss_points_3d(gauss_3d),
        )
        .physics(
            Boundary::new()
                .velocity(Range::group(bottom), hold)
                .velocity(Range::group(top), up),
        )
        .build()
        .unwrap();
    let bottom_nodes = sim.mesh().select_nodes(&Range::group(bottom)).unwrap();
    let mut peak = 0.0f64;
    let mut history = Vec::new();
    for _ in 0..200_000 {
        sim.step().unwrap();
        let f: f64 = bottom_nodes
            .iter()
            .map(|&n| sim.node_force()[n as usize * D::D + axis])
            .sum();
        // Tension pulls the held bottom nodes up: the gathered force there is the
        // reaction's opposite, positive in tension.
        let stress = f / area;
        peak = peak.max(stress);
        history.push(stress);
        if peak > 0.0
            && stress < 0.05 * peak
            && sim.field(JOINT_DAMAGE).unwrap().iter().any(|&d| d >= 1.0)
        {
            break;
        }
    }
    let broken = sim
        .field(JOINT_DAMAGE)
        .unwrap()
        .iter()
        .filter(|&&d| d >= 1.0)
        .count();
    (peak, broken, history)
}

#[test]
fn bar_2d_breaks_at_the_tensile_strength() {
    let mesh = builders::rectangle(0.0, 0.0, 0.02, 0.04, 0.005).unwrap();
    let (peak, broken, _) = pull(mesh, "bottom", "top", 0.02, 2);
    eprintln!("2D peak {:.3} MPa, broken joints {broken}", peak / 1e6);
    assert!(broken > 0);
    assert!((peak - TS).abs() < 0.10 * TS, "peak {peak} vs Ts {TS}");
}

#[test]
fn bar_3d_breaks_at_the_tensile_strength() {
    let mesh = builders::cuboid([0.0; 3], [0.01, 0.01, 0.02], 0.005).unwrap();
    let (peak, broken, _) = pull(mesh, "zmin", "zmax", 1e-4, 2);
    eprintln!("3D peak {:.3} MPa, broken joints {broken}", peak / 1e6);
    assert!(broken > 0);
    assert!((peak - TS).abs() < 0.10 * TS, "peak {peak} vs Ts {TS}");
}

#[test]
fn seven_point_gauss_rule_in_3d_agrees() {
    let mesh = builders::cuboid([0.0; 3], [0.01, 0.01, 0.02], 0.005).unwrap();
    let (p3, _, _) = pull_with(mesh.clone(), "zmin", "zmax", 1e-4, 2, 3);
    let (p7, broken, _) = pull_with(mesh, "zmin", "zmax", 1e-4, 2, 7);
    assert!(broken > 0);
    assert!((p7 - TS).abs() < 0.10 * TS, "7-point peak {p7}");
    assert!((p7 - p3).abs() < 0.02 * TS, "3-point {p3} vs 7-point {p7}");
}

/// A user-defined joint model plugs in through the trait: a linear elastic-brittle
/// joint that breaks at a fixed opening.
#[test]
fn user_joint_model_plugs_in() {
    use pcdc_cohesive::{JointModel, Traction};
    #[derive(Debug)]
    struct Brittle {
        stiffness: f64,
        break_opening: f64,
    }
    impl JointModel for Brittle {
        fn name(&self) -> &str {
            "brittle"
        }
        fn n_state(&self) -> usize {
            1
        }
        fn traction(&self, o: f64, slip: &[f64], _h: f64, state: &mut [f64]) -> Traction {
            if o > self.break_opening {
                state[0] = 1.0;
            }
            let intact = state[0] < 1.0;
            let normal = if !intact && o > 0.0 {
                0.0
            } else {
                self.stiffness * o
            };
            let mut shear = [0.0; 3];
            if intact {
                for (k, s) in slip.iter().enumerate() {
                    shear[k] = self.stiffness * s;
                }
            }
            Traction { normal, shear }
        }
        fn max_stiffness(&self, _h: f64) -> f64 {
            self.stiffness
        }
        fn is_broken(&self, state: &[f64]) -> bool {
            state[0] >= 1.0
        }
    }
    let mesh = builders::rectangle(0.0, 0.0, 0.02, 0.04, 0.005).unwrap();
    let split = split_nodes(&mesh, &Range::All).unwrap();
    let k = 10.0 * E / 0.005;
    let brittle = Brittle {
        stiffness: k,
        break_opening: 1e6 / k,
    };
    let mut sim = Simulation::builder(split.clone(), Backend::cpu(1).unwrap())
        .physics(
            Mechanics::new().material(
                Range::All,
                LinearElastic::new(E, 0.25, 2600.0)
                    .unwrap()
                    .with_damping(0.3)
                    .unwrap(),
            ),
        )
        .physics(CohesiveJoints::new().model(Range::All, brittle))
        .physics(
            Boundary::new()
                .velocity(Range::group("bottom"), [None, Some(0.0.into()), None])
                .velocity(Range::group("top"), [None, Some(0.02.into()), None]),
        )
        .build()
        .unwrap();
    let bottom = sim.mesh().select_nodes(&Range::group("bottom")).unwrap();
    let mut peak = 0.0f64;
    while sim.field(JOINT_DAMAGE).unwrap().iter().all(|&d| d < 1.0) && sim.state.step < 100_000 {
        sim.step().unwrap();
        let f: f64 = bottom
            .iter()
            .map(|&n| sim.node_force()[n as usize * 2 + 1])
            .sum();
        peak = peak.max(f / 0.02);
    }
    // Breaks at the opening where its traction reaches 1 MPa.
    assert!((peak - 1e6).abs() < 0.1e6, "peak {peak}");
}

#[test]
fn undamped_joints_limit_the_time_step() {
    let mesh = builders::rectangle(0.0, 0.0, 0.02, 0.04, 0.005).unwrap();
    let split = split_nodes(&mesh, &Range::All).unwrap();
    let sim = Simulation::builder(split, Backend::cpu(1).unwrap())
        .physics(
            Mechanics::new().material(Range::All, LinearElastic::new(E, 0.25, 2600.0).unwrap()),
        )
        .physics(CohesiveJoints::new().model(Range::All, czm()))
        .build()
        .unwrap();
    let limit = sim.time_step_limit().unwrap();
    assert_eq!(
        limit.entity.kind,
        pcdc_compute::EntityKind::Joint,
        "{limit:?}"
    );
    assert_eq!(limit.physics, "cohesive joints");
}

#[test]
fn joint_forces_identical_for_any_thread_count() {
    let mesh = builders::rectangle(0.0, 0.0, 0.02, 0.04, 0.005).unwrap();
    let (_, _, a) = pull(mesh.clone(), "bottom", "top", 0.02, 1);
    let (_, _, b) = pull(mesh, "bottom", "top", 0.02, 2);
    assert_eq!(a.len(), b.len());
    assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
}

#[test]
fn a_pre_existing_fracture_carries_no_tension() {
    use pcdc_cohesive::{joints_on_fractures, Fracture, MohrCoulombJointParams};
    let mesh = builders::rectangle(0.0, 0.0, 0.02, 0.04, 0.005).unwrap();
    let split = split_nodes(&mesh, &Range::All).unwrap();
    let on_crack = joints_on_fractures(
        &split,
        &[Fracture::Segment {
            a: [0.0, 0.02],
            b: [0.02, 0.02],
        }],
    )
    .unwrap();
    assert_eq!(on_crack.len(), 4);
    let fracture = MohrCoulombJointParams {
        friction_deg: 30.0,
        cohesion: 0.0,
        penalty_normal: 100.0 * E,
        penalty_shear: 10.0 * E,
    }
    .build()
    .unwrap();
    let rock = LinearElastic::new(E, 0.25, 2600.0)
        .unwrap()
        .with_damping(0.3)
        .unwrap();
    let mut sim = Simulation::builder(split.clone(), Backend::cpu(2).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(
            CohesiveJoints::new()
                .model(Range::All, czm())
                .model_for(on_crack.clone(), fracture),
        )
        .physics(
            Boundary::new()
                .velocity(Range::group("bottom"), [None, Some(0.0.into()), None])
                .velocity(Range::group("top"), [None, Some(0.02.into()), None]),
        )
        .build()
        .unwrap();
    let bottom = sim.mesh().select_nodes(&Range::group("bottom")).unwrap();
    let mut peak = 0.0f64;
    for _ in 0..3000 {
        sim.step().unwrap();
        let f: f64 = bottom
            .iter()
            .map(|&n| sim.node_force()[n as usize * 2 + 1])
            .sum();
        peak = peak.max(f / 0.02);
    }
    // Only inertia of the lower half is felt; far below the intact strength.
    assert!(peak < 0.05 * TS, "peak {peak}");
    let damage = sim.field(JOINT_DAMAGE).unwrap();
    assert!(on_crack.iter().all(|&j| damage[j as usize] == 1.0));
    let broken = sim.field(pcdc_cohesive::BROKEN_FACE).unwrap();
    assert_eq!(
        broken.iter().filter(|&&b| b == 1.0).count(),
        2 * on_crack.len()
    );
}
