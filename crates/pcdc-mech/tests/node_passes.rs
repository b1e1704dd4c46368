//! The fused node pass (pcdc-compute) gives the bits of the two-pass order.
//!
//! A composition whose physics all name their kinematic nodes (elements: none; boundary
//! conditions: their nodes) runs gather, velocity update, position update and watchdog
//! in one pass; adding a physics that keeps the default `KinematicNodes::Any` brings back
//! the two passes. Both must give the same displacements and velocities bit for bit,
//! with gravity, local damping, a prescribed velocity, a fixed support and a line
//! constraint, and the watchdog must name the same step and node.

use pcdc_compute::{
    Backend, ComputeError, ForceContext, InitContext, KinematicNodes, Physics, Simulation,
};
use pcdc_mech::{Boundary, Constraint, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim2, Range};

/// A physics without forces that declares the given kinematic nodes.
struct Declares(KinematicNodes);

impl Physics<Dim2> for Declares {
    fn name(&self) -> &str {
        "declares"
    }
    fn init(&mut self, _ctx: &mut InitContext<'_, Dim2>) -> Result<(), ComputeError> {
        Ok(())
    }
    fn compute_forces(&mut self, _ctx: &mut ForceContext<'_, Dim2>) -> Result<(), ComputeError> {
        Ok(())
    }
    fn kinematic_nodes(&self) -> KinematicNodes {
        self.0.clone()
    }
}

fn plate(two_pass: bool, threads: usize, dt: Option<f64>) -> Simulation<Dim2> {
    let mesh = builders::rectangle(0.0, 0.0, 0.4, 0.1, 0.02).unwrap();
    let rock = LinearElastic::new(1e9, 0.25, 2000.0)
        .unwrap()
        .with_damping(0.05)
        .unwrap();
    let mut b = Simulation::builder(mesh, Backend::cpu(threads).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(
            Boundary::new()
                .fix(Range::group("left"))
                .constraint(Range::group("bottom"), Constraint::Line([1.0, 0.0, 0.0]))
                .velocity(Range::group("right"), [Some(0.5.into()), None, None]),
        )
        .gravity([0.0, -9.81, 0.0])
        .local_damping(0.1);
    if two_pass {
        // Keeps the default's answer: the two-pass order.
        b = b.physics(Declares(KinematicNodes::Any));
    }
    if let Some(dt) = dt {
        b = b.time_step(dt);
    }
    b.build().unwrap()
}

fn bits(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn fused_and_two_pass_steps_agree_bit_for_bit() {
    for threads in [1, 2] {
        let mut fused = plate(false, threads, None);
        let mut two = plate(true, threads, None);
        assert!(fused.fuses_node_passes() && !two.fuses_node_passes());
        assert_eq!(fused.dt(), two.dt());
        fused.run(400).unwrap();
        two.run(400).unwrap();
        assert_eq!(
            bits(&fused.state.u),
            bits(&two.state.u),
            "{threads} threads"
        );
        assert_eq!(
            bits(&fused.state.v),
            bits(&two.state.v),
            "{threads} threads"
        );
        assert_eq!(bits(fused.node_force()), bits(two.node_force()));
        // Something moved, and the held nodes obey their conditions.
        assert!(fused.state.u.iter().any(|&u| u.abs() > 1e-6));
    }
}

#[test]
fn the_watchdog_names_the_same_step_and_node_in_both_orders() {
    // Far above the stable step: the plate blows up.
    let dt = 50.0 * plate(false, 1, None).dt();
    let mut fused = plate(false, 1, Some(dt));
    let mut two = plate(true, 1, Some(dt));
    let (a, b) = (fused.run(5000), two.run(5000));
    let (Err(a), Err(b)) = (a, b) else {
        panic!("both runs must diverge");
    };
    assert!(matches!(a, ComputeError::Diverged { .. }), "{a}");
    assert_eq!(a.to_string(), b.to_string());
    assert_eq!(fused.state.step, two.state.step);
    assert_eq!(bits(&fused.state.u), bits(&two.state.u));
}

#[test]
fn a_kinematic_node_out_of_range_is_an_error_naming_the_physics() {
    let mesh = builders::rectangle(0.0, 0.0, 0.4, 0.1, 0.02).unwrap();
    let rock = LinearElastic::new(1e9, 0.25, 2000.0).unwrap();
    let err = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(Declares(KinematicNodes::Nodes(vec![1_000_000])))
        .build()
        .err()
        .expect("refused");
    let msg = err.to_string();
    assert!(msg.contains("declares") && msg.contains("1000000"), "{msg}");
}
