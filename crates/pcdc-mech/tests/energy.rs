//! The energy balance and the energy watchdog (pcdc-compute), on elastic bodies.
//!
//! * The balance closes: an elastic cantilever under gravity, a face traction and a
//!   prescribed velocity, with element and local damping, keeps total energy equal to
//!   the initial energy plus the external work to 1e-3 of the reference energy; the
//!   damping shows as positive dissipation and the loads as external work.
//! * The watchdog stops a run whose physics injects energy (a negative damper), naming
//!   the step, the physics and an entity.
//! * The GPU (f64) accumulates the same balance as the CPU.

use pcdc_compute::gpu::gpu_test_backend;
use pcdc_compute::{
    Backend, ComputeError, EnergyBalance, FieldStore, ForceContext, InitContext, Physics,
    Precision, Simulation, SlotBlock,
};
use pcdc_mech::{Boundary, FaceStress, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim, Dim2, Mesh, Range};

/// A 0.4 × 0.1 m cantilever: left end held, a downward traction on the right end, the
/// bottom-left corner region pulled at a prescribed speed, gravity, damping.
fn cantilever(backend: Backend, steps: u64) -> EnergyBalance {
    let mesh = builders::rectangle(0.0, 0.0, 0.4, 0.1, 0.02).unwrap();
    let rock = LinearElastic::new(1e9, 0.25, 2000.0)
        .unwrap()
        .with_damping(0.05)
        .unwrap();
    let mut sim = Simulation::builder(mesh, backend)
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(
            Boundary::new()
                .fix(Range::group("left"))
                .face_stress(Range::group("right"), FaceStress::normal(-2e5))
                .velocity(
                    Range::rect(0.39, 0.09, 0.41, 0.11),
                    [Some(0.05.into()), None, None],
                ),
        )
        .gravity([0.0, -9.81, 0.0])
        .local_damping(0.05)
        .track_energy()
        .build()
        .unwrap();
    sim.run(steps).unwrap();
    sim.evaluate_energy().unwrap().unwrap().clone()
}

/// Undamped, supports only (no prescribed motion): the supports do no work, the
/// external work is that of gravity and the traction, and the elements dissipate
/// nothing (to the O(ω Δt) phase error of the half-step kinetic energy).
#[test]
fn supports_do_no_work_and_an_elastic_body_dissipates_nothing() {
    let mesh = builders::rectangle(0.0, 0.0, 0.4, 0.1, 0.02).unwrap();
    let rock = LinearElastic::new(1e9, 0.25, 2000.0).unwrap();
    let mut sim = Simulation::builder(mesh, Backend::cpu(0).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(
            Boundary::new()
                .fix(Range::group("left"))
                .face_stress(Range::group("right"), FaceStress::normal(-2e5)),
        )
        .gravity([0.0, -9.81, 0.0])
        .track_energy()
        .build()
        .unwrap();
    sim.run(3000).unwrap();
    let b = sim.evaluate_energy().unwrap().unwrap().clone();
    let mech = &b.physics[0];
    println!("{b:#?}");
    assert!(b.kinematic_work.abs() <= 1e-9 * b.external_work, "{b:?}");
    assert!(mech.dissipated().abs() <= 1e-2 * mech.stored, "{mech:?}");
    assert!((b.kinetic + mech.stored - b.external_work).abs() <= 1e-2 * b.external_work);
}

#[test]
fn the_balance_closes_on_a_loaded_damped_cantilever() {
    let b = cantilever(Backend::cpu(0).unwrap(), 3000);
    let reference = (b.initial + b.external_work).max(b.total());
    println!("{b:#?}\nexcess {:e} of {:e}", b.excess(), reference);
    assert!(reference > 0.0);
    assert!(
        b.excess().abs() <= 1e-3 * reference,
        "excess {}",
        b.excess()
    );
    let mech = &b.physics[0];
    assert!(mech.stored > 0.0 && mech.dissipated() > 0.0, "{mech:?}");
    assert!(b.physics[1].applies_loads);
    assert!(b.local_damping > 0.0);
    assert!(b.external_work > 0.0);
    // The corner pulled at 0.05 m/s against the body does positive work.
    assert!(b.kinematic_work > 0.0, "{}", b.kinematic_work);
}

/// Test physics: a negative damper, f = +c m v at every node (creates energy).
struct AntiDamper {
    c: f64,
    slots: Option<SlotBlock>,
}

impl<D: Dim> Physics<D> for AntiDamper {
    fn name(&self) -> &str {
        "anti-damper"
    }
    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        let nodes: Vec<u32> = (0..ctx.mesh.n_nodes() as u32).collect();
        self.slots = Some(ctx.register_slots(&nodes)?);
        Ok(())
    }
    fn compute_forces(&mut self, ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        for (i, f) in ctx.slots.iter_mut().enumerate() {
            *f = self.c * ctx.kin.mass[i / D::D] * ctx.kin.v[i];
        }
        Ok(())
    }
    fn slot_entity(&self, slot: usize) -> Option<String> {
        Some(format!("damper of node {slot}"))
    }
    fn add_mass(&self, _: &Mesh<D>, _: &FieldStore, _: &mut [f64], _: Option<f64>) {}
}

#[test]
fn the_watchdog_names_a_physics_that_injects_energy() {
    let mesh: Mesh<Dim2> = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.02).unwrap();
    let rock = LinearElastic::new(1e9, 0.25, 2000.0).unwrap();
    let mut sim = Simulation::builder(mesh, Backend::cpu(0).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(AntiDamper {
            c: 50.0,
            slots: None,
        })
        .energy_watchdog(0.01)
        .build()
        .unwrap();
    for v in sim.state.v.iter_mut().step_by(2) {
        *v = 1.0;
    }
    let err = sim.run(100_000).unwrap_err();
    let msg = err.to_string();
    println!("{msg}");
    match err {
        ComputeError::EnergyGrowth {
            step,
            physics,
            entity,
            ..
        } => {
            assert_eq!(physics, "anti-damper");
            assert!(entity.contains("damper of node"), "{entity}");
            // e^(c t) passes 1 % after t = ln(1.01)/c ≈ 2e-4 s: within a few checks.
            assert!(step < 20_000, "stopped late, at step {step}");
        }
        other => panic!("expected an energy growth error, got {other}"),
    }
    assert!(
        msg.contains("energy growth") && msg.contains("anti-damper"),
        "{msg}"
    );
}

#[test]
fn a_tolerance_that_is_not_positive_is_an_error() {
    let mesh: Mesh<Dim2> = builders::rectangle(0.0, 0.0, 0.2, 0.1, 0.05).unwrap();
    let rock = LinearElastic::new(1e9, 0.25, 2000.0).unwrap();
    for tol in [0.0, -1.0, f64::NAN] {
        let err = Simulation::builder(mesh.clone(), Backend::cpu(0).unwrap())
            .physics(Mechanics::new().material(Range::All, rock.clone()))
            .energy_watchdog(tol)
            .build()
            .err()
            .expect("bad tolerance");
        assert!(err.to_string().contains("energy_watchdog"), "{err}");
    }
}

#[test]
fn gpu_f64_accumulates_the_cpu_balance() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let steps = 1000;
    let c = cantilever(Backend::cpu(0).unwrap(), steps);
    let g = cantilever(gpu, steps);
    let scale = (c.initial + c.external_work).max(c.total());
    let close = |a: f64, b: f64, what: &str| {
        assert!(
            (a - b).abs() <= 1e-9 * scale,
            "{what}: cpu {a:e}, gpu {b:e}"
        );
    };
    close(c.external_work, g.external_work, "external work");
    close(c.local_damping, g.local_damping, "local damping");
    close(c.kinetic, g.kinetic, "kinetic");
    for (a, b) in c.physics.iter().zip(&g.physics) {
        close(a.absorbed, b.absorbed, &a.name);
        close(a.stored, b.stored, &a.name);
    }
    close(c.excess(), g.excess(), "excess");
}
