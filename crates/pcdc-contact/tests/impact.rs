//! Two elastic blocks collide head-on without friction or damping: linear momentum is
//! conserved to rounding and the energy comes back after separation.

use pcdc_compute::{Backend, Simulation};
use pcdc_contact::Contact;
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim2, Mesh, Range};

const E: f64 = 1e9;

/// Two 0.1 m squares, 2 mm apart, as one mesh of two bodies.
fn two_blocks() -> Mesh<Dim2> {
    let a = builders::rectangle(0.0, 0.0, 0.1, 0.1, 0.02).unwrap();
    let b = builders::rectangle(0.102, 0.0, 0.1, 0.1, 0.02).unwrap();
    builders::union(&[&a, &b]).unwrap().0
}

fn run(threads: usize) -> (Simulation<Dim2>, f64, f64, f64) {
    run_with(threads, Contact::new(10.0 * E))
}

fn run_with(threads: usize, contact: Contact) -> (Simulation<Dim2>, f64, f64, f64) {
    let mesh = two_blocks();
    let rock = LinearElastic::new(E, 0.25, 1000.0).unwrap();
    let mut sim = Simulation::builder(mesh, Backend::cpu(threads).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(contact)
        .build()
        .unwrap();
    let left = sim
        .mesh()
        .select_nodes(&Range::rect(-1.0, -1.0, 0.101, 1.0))
        .unwrap();
    for (n, v) in sim.state.v.chunks_exact_mut(2).enumerate() {
        v[0] = if left.binary_search(&(n as u32)).is_ok() {
            1.0
        } else {
            -1.0
        };
    }
    let momentum = |s: &Simulation<Dim2>| {
        s.state
            .v
            .chunks_exact(2)
            .zip(s.mass())
            .map(|(v, m)| m * v[0])
            .sum::<f64>()
    };
    let p0 = momentum(&sim);
    let e0 = sim.kinetic_energy();
    // Approach (1 mm each side at 1 m/s), contact and separation.
    sim.run_until(3e-3).unwrap();
    let p1 = momentum(&sim);
    (sim, p0, p1, e0)
}

#[test]
fn head_on_impact_conserves_momentum_and_energy() {
    let (sim, p0, p1, e0) = run(2);
    let scale = sim.mass().iter().sum::<f64>() * 1.0;
    assert!((p1 - p0).abs() <= 1e-10 * scale, "momentum {p0} -> {p1}");
    // Bodies have separated and fly apart.
    let left = sim
        .mesh()
        .select_nodes(&Range::rect(-1.0, -1.0, 0.101, 1.0))
        .unwrap();
    let vl: f64 = left
        .iter()
        .map(|&n| sim.state.v[2 * n as usize])
        .sum::<f64>()
        / left.len() as f64;
    assert!(vl < 0.0, "left block should bounce back, mean vx = {vl}");
    let e1 = sim.kinetic_energy() + sim.stored_energy();
    eprintln!("momentum {p0:e} -> {p1:e} (rel {:.1e}); energy {e0:e} -> {e1:e} ({:+.3} %); mean rebound {vl:.4} m/s", (p1 - p0).abs() / scale, 100.0 * (e1 - e0) / e0);
    assert!((e1 - e0).abs() < 0.02 * e0, "energy {e0} -> {e1}");
}

#[test]
fn contact_is_deterministic_across_thread_counts() {
    let (a, ..) = run(1);
    let (b, ..) = run(2);
    assert!(a
        .state
        .u
        .iter()
        .zip(&b.state.u)
        .all(|(x, y)| x.to_bits() == y.to_bits()));
}

/// With contact damping (eq. 61, b = 3, T above every contact stress) the same impact
/// keeps its momentum but loses energy: the unloading branch lies below the loading one.
/// b = 1 with T above every stress is the undamped law and returns the energy.
#[test]
fn contact_damping_dissipates_and_b1_does_not() {
    let energy = |s: &Simulation<Dim2>| s.kinetic_energy() + s.stored_energy();
    let (sim, p0, p1, e0) = run_with(2, Contact::new(10.0 * E).damping(1e12, 3.0));
    let scale = sim.mass().iter().sum::<f64>();
    assert!((p1 - p0).abs() <= 1e-10 * scale, "momentum {p0} -> {p1}");
    let e_damped = energy(&sim);
    let (sim1, _, _, _) = run_with(2, Contact::new(10.0 * E).damping(1e12, 1.0));
    let e_b1 = energy(&sim1);
    eprintln!(
        "energy kept: b = 3: {:.2} %, b = 1: {:.3} %",
        100.0 * e_damped / e0,
        100.0 * e_b1 / e0
    );
    assert!(e_damped < 0.9 * e0, "damped impact kept {e_damped} of {e0}");
    assert!(
        (e_b1 - e0).abs() < 0.02 * e0,
        "b = 1 should not dissipate: {e0} -> {e_b1}"
    );
    // A capped contact (T below the peak trial stress) also stays stable and bounded.
    let (sim_t, _, _, _) = run_with(2, Contact::new(10.0 * E).damping(1e6, 2.0));
    let e_t = energy(&sim_t);
    assert!(e_t.is_finite() && e_t <= e0 * 1.02, "capped: {e0} -> {e_t}");
}

#[test]
fn contact_damping_parameters_are_checked() {
    let mesh = two_blocks();
    let rock = LinearElastic::new(E, 0.25, 1000.0).unwrap();
    for (t, b) in [(-1.0, 2.0), (1e6, 0.5), (1e6, f64::NAN)] {
        let r = Simulation::builder(mesh.clone(), Backend::cpu(1).unwrap())
            .physics(Mechanics::new().material(Range::All, rock.clone()))
            .physics(Contact::new(10.0 * E).damping(t, b))
            .build();
        let err = r
            .err()
            .expect("invalid damping must be refused")
            .to_string();
        assert!(err.contains("damping"), "{err}");
    }
}

/// A user contact law through the plugin trait: a "no-tension, capped" law that limits
/// the normal stress to 1 MPa. The bodies still bounce apart, momentum is kept, and a
/// pass-through law gives exactly the built-in frictionless result.
#[test]
fn user_contact_model_plugs_in() {
    use pcdc_contact::{ContactModel, ContactStress};
    #[derive(Debug)]
    struct Capped(f64);
    impl ContactModel for Capped {
        fn name(&self) -> &str {
            "capped (test)"
        }
        fn normal_penalty(&self) -> f64 {
            10.0 * E
        }
        fn update(&self, s_try: f64, _dslip: f64, _h: f64, _state: &mut [f64]) -> ContactStress {
            ContactStress {
                normal: s_try.min(self.0),
                shear: 0.0,
            }
        }
    }
    let (same, _, _, _) = run_with(1, Contact::new(1.0).with_model(Capped(f64::INFINITY)));
    let (built_in, _, _, _) = run_with(1, Contact::new(10.0 * E));
    assert_eq!(same.state.u, built_in.state.u);
    let (capped, p0, p1, _) = run_with(1, Contact::new(1.0).with_model(Capped(1e6)));
    let scale = capped.mass().iter().sum::<f64>();
    assert!((p1 - p0).abs() <= 1e-10 * scale);
    assert_ne!(capped.state.u, built_in.state.u);
}

/// The friction spring (eq. 59 corrected, τ = P_t δ_s / h) enters the contact stable
/// step: a shear penalty above three normal penalties (the normal potential's node
/// stiffness) lowers the contact limit as 1/√P_t; below it, the normal penalty governs.
#[test]
fn a_stiff_friction_spring_lowers_the_contact_time_step() {
    let limit = |contact: Contact| {
        let rock = LinearElastic::new(E, 0.25, 1000.0).unwrap();
        let sim = Simulation::builder(two_blocks(), Backend::cpu(1).unwrap())
            .physics(Mechanics::new().material(Range::All, rock))
            .physics(contact)
            .build()
            .unwrap();
        let l = sim.time_step_limit().unwrap().clone();
        assert_eq!(l.physics, "contact", "{l:?}");
        l.dt
    };
    let p = 1000.0 * E; // well above the elements' own limit
    let plain = limit(Contact::new(p));
    let soft = limit(Contact::new(p).friction(30.0, p));
    let stiff = limit(Contact::new(p).friction(30.0, 12.0 * p));
    assert_eq!(plain, soft, "a shear penalty below 3 P_n changes nothing");
    let ratio = plain / stiff;
    assert!(
        (ratio - 2.0).abs() < 1e-12,
        "dt ratio {ratio}, expected sqrt(12/3) = 2"
    );
}
