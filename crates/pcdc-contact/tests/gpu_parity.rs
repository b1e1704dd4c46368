//! CPU–GPU parity of the contact physics (2D and 3D): one scene body, instantiated for
//! `Backend::cpu(1)` and the GPU backend.
//!
//! Scenes: (1) two elastic blocks collide obliquely, one spinning, with Coulomb friction
//! (the stick and slip branches run) and contact damping (loading cap and unloading
//! curve), over enough steps that the candidate lists are rebuilt many times and pair
//! histories are carried across rebuilds; (2) an FDEM block (every triangle with its own
//! nodes, cohesive joints between them, declared as bonded pairs) hits a second block
//! hard enough that joints break and their faces become contact faces; (3) two
//! tetrahedral blocks collide obliquely, one spinning about two axes, with friction and
//! damping, under a small skin so the candidate lists are rebuilt several times while
//! the blocks touch, and again with element-surface contact (per-element friction and
//! penalty).
//!
//! Measured and compared: displacement and velocity (f64: max |Δu| / max |u| ≤ 1e-12).
//! Fracture amplifies any rounding difference: in the FDEM scene the CPU is also run
//! with its initial velocities perturbed by 1e-15 (relative), and the bar is four times
//! the drift that causes (as in the cohesive parity tests).
//! Without a GPU adapter the tests skip (and fail with PCDC_REQUIRE_GPU=1).

use pcdc_cohesive::{CohesiveJoints, IntrinsicCzmParams, BROKEN_FACE};
use pcdc_compute::gpu::gpu_test_backend;
use pcdc_compute::{Backend, Precision, Simulation};
use pcdc_contact::{Contact, CONTACT_REFERENCE};
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{builders, split_nodes, Dim2, Dim3, Mesh, Range};

const E: f64 = 1e9;
/// Impact speed of the FDEM block (m/s).
const SPEED: f64 = 3.0;

fn two_blocks(gap: f64) -> Mesh<Dim2> {
    let a = builders::rectangle(0.0, 0.0, 0.1, 0.1, 0.02).unwrap();
    let b = builders::rectangle(0.1 + gap, 0.03, 0.1, 0.1, 0.02).unwrap();
    builders::union(&[&a, &b]).unwrap().0
}

struct Outcome {
    u: Vec<f64>,
    v: Vec<f64>,
    broken: usize,
}

/// Scene 1: oblique, spinning, frictional and damped impact.
fn impact(backend: Backend) -> Outcome {
    let mesh = two_blocks(0.002);
    let rock = LinearElastic::new(E, 0.25, 1000.0).unwrap();
    let contact = Contact::new(10.0 * E)
        .friction(30.0, 50.0 * E)
        .damping(2e6, 2.0);
    let mut sim = Simulation::builder(mesh, backend)
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(contact)
        .build()
        .unwrap();
    let x = sim.mesh().coords().to_vec();
    // Left block: 2 m/s to the right, 0.5 m/s up, spinning at 20 rad/s about its centre.
    for n in 0..sim.mesh().n_nodes() {
        if x[2 * n] < 0.101 {
            let (rx, ry) = (x[2 * n] - 0.05, x[2 * n + 1] - 0.05);
            sim.state.v[2 * n] = 2.0 - 20.0 * ry;
            sim.state.v[2 * n + 1] = 0.5 + 20.0 * rx;
        }
    }
    // Approach (1 ms), contact with sliding, rebound; in two runs (state carried over).
    let steps = (3e-3 / sim.dt()).ceil() as u64;
    sim.run(steps / 2).unwrap();
    sim.run(steps - steps / 2).unwrap();
    Outcome {
        u: sim.state.u.clone(),
        v: sim.state.v.clone(),
        broken: 0,
    }
}

/// Scene 2: an FDEM block with bonded pairs hits a second block; joints break.
fn fdem(backend: Backend, perturb: f64) -> Outcome {
    let a = builders::rectangle(0.0, 0.0, 0.06, 0.06, 0.01).unwrap();
    let b = builders::rectangle(0.061, -0.02, 0.04, 0.1, 0.01).unwrap();
    let mesh = builders::union(&[&a, &b]).unwrap().0;
    let left = Range::rect(-1.0, -1.0, 0.0605, 1.0);
    let split = split_nodes(&mesh, &left).unwrap();
    let czm = IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 4e6,
        tensile_strength: 2e6,
        gf1: 0.01,
        gf2: 0.1,
        penalty_open: 10.0 * E,
        penalty_shear: 10.0 * E,
        penalty_overlap: 10.0 * E,
    }
    .build()
    .unwrap();
    let joints = CohesiveJoints::new().model(Range::All, czm);
    let contact = Contact::new(10.0 * E)
        .friction(20.0, 10.0 * E)
        .bonded_interfaces(BROKEN_FACE);
    let rock = LinearElastic::new(E, 0.25, 1000.0).unwrap();
    let mut sim = Simulation::builder(split.clone(), backend)
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(joints)
        .physics(contact)
        .build()
        .unwrap();
    let x = sim.mesh().coords().to_vec();
    for n in 0..sim.mesh().n_nodes() {
        if x[2 * n] < 0.0605 {
            sim.state.v[2 * n] = SPEED * (1.0 + perturb * (n as f64 * 0.618_033_988_7).fract());
        }
    }
    let steps = (1e-3 / sim.dt()).ceil() as u64;
    sim.run(steps).unwrap();
    let broken = sim
        .field(BROKEN_FACE)
        .unwrap()
        .iter()
        .filter(|&&f| f != 0.0)
        .count();
    Outcome {
        u: sim.state.u.clone(),
        v: sim.state.v.clone(),
        broken,
    }
}

/// Scene 3 (3D): two tetrahedral blocks, the left one moving obliquely and spinning about
/// z and y, collide with Coulomb friction and contact damping; the skin is small (0.2 mm)
/// so the candidate lists are rebuilt several times while they touch. `chunk`: run in
/// two `run()` calls (half the steps, then the rest) when `None`; otherwise in calls of
/// `chunk` steps, counting the broad-phase builds from the reference-position field
/// after each call (exact for `chunk` = 1). `surface`: the law is element-surface
/// contact (table 1) with friction and penalty varying by element instead. Returns the
/// outcome, the builds counted and the mean velocity of the struck block.
fn impact_3d(backend: Backend, chunk: Option<u64>, surface: bool) -> (Outcome, usize, [f64; 3]) {
    let a = builders::cuboid([0.0; 3], [0.04; 3], 0.02).unwrap();
    let b = builders::cuboid([0.0401, 0.012, 0.007], [0.04; 3], 0.02).unwrap();
    let (mesh, bodies) = builders::union(&[&a, &b]).unwrap();
    let ne = mesh.n_elements();
    let rock = LinearElastic::new(E, 0.25, 1000.0).unwrap();
    let contact = if surface {
        let friction = (0..ne).map(|e| 15.0 + 5.0 * (e % 4) as f64).collect();
        let penalty = (0..ne).map(|e| (5.0 + 3.0 * (e % 3) as f64) * E).collect();
        Contact::new(10.0 * E).surface_defaults(friction, penalty)
    } else {
        Contact::new(10.0 * E)
            .friction(30.0, 50.0 * E)
            .damping(2e6, 2.0)
    };
    let contact = contact.skin(2e-4);
    let mut sim: Simulation<Dim3> = Simulation::builder(mesh, backend)
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(contact)
        .build()
        .unwrap();
    let x = sim.mesh().coords().to_vec();
    // Left block: (3, 0.6, -0.4) m/s, spinning at 25 rad/s about y and 40 rad/s about z
    // through its centre.
    let w = [0.0, 25.0, 40.0];
    for &n in &bodies[0] {
        let n = n as usize;
        let r = [x[3 * n] - 0.02, x[3 * n + 1] - 0.02, x[3 * n + 2] - 0.02];
        sim.state.v[3 * n] = 3.0 + w[1] * r[2] - w[2] * r[1];
        sim.state.v[3 * n + 1] = 0.6 + w[2] * r[0] - w[0] * r[2];
        sim.state.v[3 * n + 2] = -0.4 + w[0] * r[1] - w[1] * r[0];
    }
    // Approach (0.1 mm at 3 m/s), contact with sliding, rebound.
    let steps = (IMPACT_3D_TIME / sim.dt()).ceil() as u64;
    let calls: Vec<u64> = match chunk {
        None => vec![steps / 2, steps - steps / 2],
        Some(c) => (0..steps.div_ceil(c))
            .map(|i| c.min(steps - i * c))
            .collect(),
    };
    let mut builds = 0;
    let mut last: Option<Vec<f64>> = None;
    for n in calls {
        sim.run(n).unwrap();
        let r = sim.field(CONTACT_REFERENCE).unwrap();
        if last
            .as_deref()
            .is_none_or(|l| l.iter().zip(r).any(|(p, q)| p.to_bits() != q.to_bits()))
        {
            builds += 1;
        }
        last = Some(r.to_vec());
    }
    // Mean velocity of the struck (right) block: the impact pushes it along x, friction
    // drags it along y and z.
    let struck: [f64; 3] = std::array::from_fn(|d| {
        let sum: f64 = bodies[1]
            .iter()
            .map(|&n| sim.state.v[3 * n as usize + d])
            .sum();
        sum / bodies[1].len() as f64
    });
    let out = Outcome {
        u: sim.state.u.clone(),
        v: sim.state.v.clone(),
        broken: 0,
    };
    (out, builds, struck)
}

/// Duration of scene 3 (s).
const IMPACT_3D_TIME: f64 = 1.8e-4;

fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// Compares displacement and velocity (each relative to its largest magnitude); `tol`
/// bounds (u, v).
fn compare(name: &str, cpu: &Outcome, gpu: &Outcome, tol: (f64, f64)) {
    let du = max_diff(&cpu.u, &gpu.u) / max_abs(&cpu.u);
    let dv = max_diff(&cpu.v, &gpu.v) / max_abs(&cpu.v);
    println!(
        "{name}: max|du|/max|u| = {du:.2e}, max|dv|/max|v| = {dv:.2e}, broken faces cpu {} gpu {}",
        cpu.broken, gpu.broken
    );
    assert!(
        du <= tol.0 && dv <= tol.1,
        "{name}: du {du:e}, dv {dv:e} above {tol:?}"
    );
}

#[test]
fn frictional_damped_impact_matches_cpu_f64() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let cpu = impact(Backend::cpu(1).unwrap());
    let reads = gpu.as_gpu().expect("a GPU backend").readbacks();
    let dev = impact(gpu.clone());
    // One read-back per run() call.
    assert_eq!(gpu.as_gpu().expect("a GPU backend").readbacks() - reads, 2);
    compare("impact f64", &cpu, &dev, (1e-12, 1e-11));
}

#[test]
fn fdem_block_breaking_on_impact_matches_cpu_f64() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let cpu = fdem(Backend::cpu(1).unwrap(), 0.0);
    assert!(
        cpu.broken > 0,
        "no joint broke: the scene does not test bonded pairs"
    );
    // Fracture amplifies rounding: the CPU itself, with the initial velocities perturbed
    // by 1e-15 (relative), drifts this far; the bar is four times that drift.
    let perturbed = fdem(Backend::cpu(1).unwrap(), 1e-15);
    let drift_u = max_diff(&cpu.u, &perturbed.u) / max_abs(&cpu.u);
    let drift_v = max_diff(&cpu.v, &perturbed.v) / max_abs(&cpu.v);
    println!("fdem: CPU drift under a 1e-15 perturbation: u {drift_u:.2e}, v {drift_v:.2e}");
    let dev = fdem(gpu, 0.0);
    assert_eq!(cpu.broken, dev.broken);
    compare(
        "fdem f64",
        &cpu,
        &dev,
        ((4.0 * drift_u).max(1e-12), (4.0 * drift_v).max(1e-11)),
    );
}

#[test]
fn impact_f32_is_close() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F32)) else {
        return;
    };
    let cpu = impact(Backend::cpu(1).unwrap());
    let dev = impact(gpu);
    // Measured and printed; bounded loosely (single precision, a frictional impact).
    compare("impact f32", &cpu, &dev, (2e-2, 2e-2));
}

/// A rebuild that finds more candidates than the capacity stops the run with the same
/// error on both backends, naming the first such element (the CPU checks it too: the
/// lists are fields of fixed capacity on both).
#[test]
fn candidate_overflow_is_an_error_naming_the_element() {
    let overflow = |backend: Backend| {
        let mesh = two_blocks(0.002);
        let rock = LinearElastic::new(E, 0.25, 1000.0).unwrap();
        let mut sim = Simulation::builder(mesh, backend)
            .physics(Mechanics::new().material(Range::All, rock))
            .physics(Contact::new(10.0 * E).capacity(2))
            .build()
            .unwrap();
        sim.run(1).unwrap_err().to_string()
    };
    let cpu = overflow(Backend::cpu(1).unwrap());
    assert!(
        cpu.contains("element") && cpu.contains("Contact::capacity"),
        "{cpu}"
    );
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    assert_eq!(overflow(gpu), cpu);
}

#[test]
fn tet_blocks_frictional_damped_impact_matches_cpu_f64() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let (cpu, _, struck) = impact_3d(Backend::cpu(1).unwrap(), None, false);
    // The same run step by step on the CPU: the scene does rebuild the lists during it.
    let (stepped, builds, _) = impact_3d(Backend::cpu(1).unwrap(), Some(1), false);
    assert_eq!(stepped.u, cpu.u, "the CPU depends on how the run is split");
    println!("impact 3d: {builds} broad-phase builds, struck block at {struck:.3?} m/s");
    // The blocks did collide, and friction dragged the struck block sideways.
    assert!(struck[0] > 0.3, "no impact: {struck:?}");
    assert!(struck[1].hypot(struck[2]) > 0.01, "no friction: {struck:?}");
    assert!(
        builds >= 4,
        "only {builds} broad-phase builds: raise the speed or lower the skin"
    );
    let reads = gpu.as_gpu().expect("a GPU backend").readbacks();
    let (dev, _, _) = impact_3d(gpu.clone(), None, false);
    assert_eq!(gpu.as_gpu().expect("a GPU backend").readbacks() - reads, 2);
    compare("impact 3d f64", &cpu, &dev, (1e-12, 1e-11));
}

#[test]
fn tet_blocks_impact_f32_is_close() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F32)) else {
        return;
    };
    let (cpu, _, _) = impact_3d(Backend::cpu(1).unwrap(), None, false);
    let (dev, _, _) = impact_3d(gpu, None, false);
    // Measured and printed; bounded loosely (single precision, a frictional impact).
    compare("impact 3d f32", &cpu, &dev, (2e-2, 2e-2));
}

/// Element-surface contact (table 1) in 3D: the per-pair penalty and friction of
/// `SurfaceContact` go through the same splice on the GPU.
#[test]
fn tet_blocks_surface_contact_matches_cpu_f64() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let (cpu, _, struck) = impact_3d(Backend::cpu(1).unwrap(), None, true);
    println!("surface contact 3d: struck block at {struck:.3?} m/s");
    assert!(struck[0] > 0.3, "no impact: {struck:?}");
    let (dev, _, _) = impact_3d(gpu, None, true);
    compare("surface contact 3d f64", &cpu, &dev, (1e-12, 1e-11));
}
