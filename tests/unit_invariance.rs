//! Unit invariance: the same physical scene written in SI, in mm–N–s and (a large one)
//! in km–MN–s gives the same dimensionless results to rounding. The scene exercises
//! elements, cohesive joints that break, contact and friction: an FDEM block slides on
//! a fixed base under gravity, spinning, and hits a fixed wall hard enough to fracture.
//!
//! A unit system is a length unit λ (m), a force unit F (N) and a time unit T (s);
//! every input is divided by its unit: lengths by λ, stresses and penalties by F/λ²,
//! densities by F T²/λ⁴, velocities by λ/T, accelerations by λ/T², fracture energies by
//! F/λ. Before the friction law was made dimensionally consistent (τ = P_t δ_s / h,
//! manual eq. 59 corrected), the mm run slid differently from the SI run.

use pcdc::cohesive::{CohesiveJoints, IntrinsicCzmParams, BROKEN_FACE, JOINT_DAMAGE};
use pcdc::compute::{Backend, Simulation};
use pcdc::contact::Contact;
use pcdc::mech::{Boundary, LinearElastic, Mechanics};
use pcdc::mesh::{builders, split_nodes, Dim, Range};

/// A unit system: length (m), force (N) and time (s) units.
#[derive(Clone, Copy, Debug)]
struct Units {
    length: f64,
    force: f64,
    time: f64,
}

impl Units {
    const SI: Units = Units {
        length: 1.0,
        force: 1.0,
        time: 1.0,
    };
    const MM_N_S: Units = Units {
        length: 1e-3,
        force: 1.0,
        time: 1.0,
    };
    const KM_MN_S: Units = Units {
        length: 1e3,
        force: 1e6,
        time: 1.0,
    };
    fn stress(&self) -> f64 {
        self.force / (self.length * self.length)
    }
    fn density(&self) -> f64 {
        self.force * self.time * self.time / self.length.powi(4)
    }
    fn velocity(&self) -> f64 {
        self.length / self.time
    }
    fn acceleration(&self) -> f64 {
        self.length / (self.time * self.time)
    }
    fn energy_per_area(&self) -> f64 {
        self.force / self.length
    }
}

/// Dimensionless outcome: node positions / scene size, velocities / v0, broken joints,
/// kinetic energy / initial kinetic energy, time / (size / v0).
struct Outcome {
    x: Vec<f64>,
    v: Vec<f64>,
    broken: usize,
    kinetic: f64,
    time: f64,
    steps: u64,
}

/// The scene of physical size `scale` × (0.3 m long base), written in units `u`, run for
/// `steps` steps, with the initial speed scaled by 1 + `eps` (the scene's sensitivity).
fn run_perturbed(scale: f64, u: Units, steps: u64, eps: f64) -> Outcome {
    let len = |x: f64| scale * x / u.length;
    let e = 30e9 / u.stress();
    let size = len(0.01);
    let base = builders::rectangle(len(0.0), len(0.0), len(0.3), len(0.02), len(0.02)).unwrap();
    let wall = builders::rectangle(len(0.2), len(0.02), len(0.02), len(0.08), len(0.02)).unwrap();
    let block = builders::rectangle(len(0.08), len(0.02), len(0.06), len(0.03), size).unwrap();
    let mesh = builders::union(&[&base, &wall, &block]).unwrap().0;
    let fdem = Range::rect(len(0.079), len(0.0201), len(0.141), len(0.051));
    let split = split_nodes(&mesh, &fdem.clone()).unwrap();
    let rock = LinearElastic::new(e, 0.25, 2600.0 / u.density()).unwrap();
    let czm = IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 4e6 / u.stress(),
        tensile_strength: 1e6 / u.stress(),
        gf1: 1.0 * scale / u.energy_per_area(),
        gf2: 5.0 * scale / u.energy_per_area(),
        penalty_open: 10.0 * e,
        penalty_shear: 10.0 * e,
        penalty_overlap: 10.0 * e,
    }
    .build()
    .unwrap();
    let contact = Contact::new(10.0 * e)
        .friction(30.0, 10.0 * e)
        .bonded_interfaces(BROKEN_FACE);
    // The base below its top face and the wall behind its front face are held.
    let fixed = Range::rect(len(-1.0), len(-1.0), len(1.0), len(0.0199)).or(Range::rect(
        len(0.2001),
        len(-1.0),
        len(1.0),
        len(1.0),
    ));
    let mut sim = Simulation::builder(split, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(CohesiveJoints::new().model(Range::All, czm))
        .physics(contact)
        .physics(Boundary::new().fix(fixed))
        .gravity([0.0, -9.81 / u.acceleration(), 0.0])
        .build()
        .unwrap();
    let v0 = 6.0 / u.velocity() * (1.0 + eps);
    let (cx, cy) = (len(0.11), len(0.035));
    let omega = 40.0 / scale * u.time;
    let mut in_block: Vec<usize> = sim
        .mesh()
        .select_elements(&fdem)
        .unwrap()
        .iter()
        .flat_map(|&e| sim.mesh().element(e as usize).to_vec())
        .map(|n| n as usize)
        .collect();
    in_block.sort_unstable();
    in_block.dedup();
    for &n in &in_block {
        let x = sim.mesh().node(n).to_vec();
        sim.state.v[2 * n] = v0 - omega * (x[1] - cy);
        sim.state.v[2 * n + 1] = omega * (x[0] - cx);
    }
    finish(&mut sim, steps, v0, len(0.3))
}

/// Runs `steps` steps and returns the dimensionless outcome (positions over the scene
/// size `l0`, velocities over the initial speed `v0`).
fn finish<D: Dim>(sim: &mut Simulation<D>, steps: u64, v0: f64, l0: f64) -> Outcome {
    let ke0 = sim.kinetic_energy();
    sim.run(steps).unwrap();
    Outcome {
        x: sim.positions().iter().map(|x| x / l0).collect(),
        v: sim.state.v.iter().map(|v| v / v0).collect(),
        broken: sim
            .field(JOINT_DAMAGE)
            .unwrap()
            .iter()
            .filter(|&&d| d >= 1.0)
            .count(),
        kinetic: sim.kinetic_energy() / ke0,
        time: sim.state.time * v0 / l0,
        steps: sim.state.step,
    }
}

/// Largest difference of two arrays relative to the largest magnitude of the first.
fn rel(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

/// Runs the scene in SI and in `other`, and in SI with the initial speed perturbed by
/// 1e-15 (relative): the scene fractures and collides, so rounding differences grow;
/// "the same to rounding" means no further apart than that perturbation takes the SI
/// run (with a factor 100 of margin), and the same joints broken.
fn compare(scale: f64, other: Units, steps: u64) {
    compare_runs(&format!("scale {scale}"), other, |u, eps| {
        run_perturbed(scale, u, steps, eps)
    });
}

/// The comparison itself, for a scene `run(units, eps)`.
fn compare_runs(label: &str, other: Units, run: impl Fn(Units, f64) -> Outcome) {
    let a = run(Units::SI, 0.0);
    let b = run(other, 0.0);
    let c = run(Units::SI, 1e-15);
    let (dx, dv) = (rel(&a.x, &b.x), rel(&a.v, &b.v));
    let (px, pv) = (rel(&a.x, &c.x), rel(&a.v, &c.v));
    println!(
        "{label}, units {other:?}: broken {} / {}, KE/KE0 {:.9} / {:.9}, |dx| {dx:.2e} (perturbed SI {px:.2e}), |dv| {dv:.2e} ({pv:.2e})",
        a.broken, b.broken, a.kinetic, b.kinetic
    );
    assert_eq!(a.steps, b.steps);
    assert!(
        (a.time - b.time).abs() <= 1e-12 * a.time,
        "time {} vs {}",
        a.time,
        b.time
    );
    assert!(a.broken > 0, "the scene must fracture");
    assert_eq!(a.broken, b.broken, "broken joints differ");
    let dk = (a.kinetic - c.kinetic).abs();
    assert!(
        (a.kinetic - b.kinetic).abs() <= (100.0 * dk).max(1e-12),
        "KE ratio {} vs {} (perturbed SI {})",
        a.kinetic,
        b.kinetic,
        c.kinetic
    );
    assert!(dx <= (100.0 * px).max(1e-13), "positions differ by {dx:e}");
    assert!(dv <= (100.0 * pv).max(1e-10), "velocities differ by {dv:e}");
}

#[test]
fn si_and_mm_n_s_agree() {
    compare(1.0, Units::MM_N_S, 1000);
}

#[test]
fn large_scene_si_and_km_mn_s_agree() {
    compare(1000.0, Units::KM_MN_S, 1000);
}

/// The 3D counterpart: an FDEM cube of tetrahedra (cohesive joints on its interior
/// faces), spinning, is driven into a fixed base and slides on it with friction, in SI
/// and in mm–N–s.
fn run_3d(u: Units, steps: u64, eps: f64) -> Outcome {
    let len = |x: f64| x / u.length;
    let e = 1e8 / u.stress();
    let base = builders::cuboid([0.0; 3], [len(0.15), len(0.06), len(0.02)], len(0.02)).unwrap();
    let block = builders::cuboid(
        [len(0.02), len(0.01), len(0.02)],
        [len(0.04), len(0.04), len(0.04)],
        len(0.02),
    )
    .unwrap();
    let (mesh, bodies) = builders::union(&[&base, &block]).unwrap();
    let fdem = Range::cuboid([len(0.0199), len(0.0099), len(0.0201)], [len(0.0601); 3]);
    let split = split_nodes(&mesh, &fdem).unwrap();
    let rock = LinearElastic::new(e, 0.25, 2600.0 / u.density()).unwrap();
    let czm = IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 4e4 / u.stress(),
        tensile_strength: 1e4 / u.stress(),
        gf1: 1.0 / u.energy_per_area(),
        gf2: 5.0 / u.energy_per_area(),
        penalty_open: 10.0 * e,
        penalty_shear: 10.0 * e,
        penalty_overlap: 10.0 * e,
    }
    .build()
    .unwrap();
    let contact = Contact::new(10.0 * e)
        .friction(30.0, 10.0 * e)
        .bonded_interfaces(BROKEN_FACE);
    let fixed = Range::cuboid([len(-1.0); 3], [len(1.0), len(1.0), len(0.0199)]);
    let mut sim = Simulation::builder(split, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(CohesiveJoints::new().model(Range::All, czm))
        .physics(contact)
        .physics(Boundary::new().fix(fixed))
        .gravity([0.0, 0.0, -9.81 / u.acceleration()])
        .build()
        .unwrap();
    let v0 = 2.0 / u.velocity() * (1.0 + eps);
    let omega = 60.0 * u.time;
    let (cx, cy) = (len(0.04), len(0.03));
    let mut in_block: Vec<usize> = sim
        .mesh()
        .select_elements(&fdem)
        .unwrap()
        .iter()
        .flat_map(|&el| sim.mesh().element(el as usize).to_vec())
        .map(|n| n as usize)
        .collect();
    in_block.sort_unstable();
    in_block.dedup();
    assert!(!in_block.is_empty() && bodies.len() == 2);
    for &n in &in_block {
        let x = sim.mesh().node(n).to_vec();
        sim.state.v[3 * n] = v0 - omega * (x[1] - cy);
        sim.state.v[3 * n + 1] = omega * (x[0] - cx);
        // Driven into the base: the impact fractures the cube.
        sim.state.v[3 * n + 2] = -1.5 * v0;
    }
    finish(&mut sim, steps, v0, len(0.15))
}

#[test]
fn three_d_si_and_mm_n_s_agree() {
    compare_runs("3D", Units::MM_N_S, |u, eps| run_3d(u, 600, eps));
}
