//! The standard FDEM benchmark scene (docs/design-targets.md, with its speed targets): a
//! 0.05 x 0.10 m block of right triangles, every triangle with its own nodes, an
//! intrinsic cohesive joint on every interior edge (penalties 10 E, overlap 100 E,
//! Ts = 2 MPa, c = 10 MPa), E = 30 GPa, nu = 0.25, rho = 2600, bottom fixed in y, top
//! pushed at 0.05 m/s, dt = 0.05 h / c_p; 10k, 50k and 200k triangles, 1 thread and all
//! threads. Rows `..._joints_...` leave contact out; rows `..._contact_...` are the
//! full scene with contact on (penalty 10 E, friction 30° with shear penalty 10 E,
//! bonded neighbours excluded until their joint breaks), 10k and 50k triangles.
//!
//! GPU rows (when an adapter exists, f64 and f32; joints only and with contact): one
//! iteration is `run(GPU_STEPS)`,
//! which includes one upload and one read-back of the state, so the rate is per
//! triangle-step with the transfers amortised over GPU_STEPS steps. On a software adapter
//! (Mesa's lavapipe) only the 10k mesh runs, and its rows prove that the path works, not
//! GPU speed.
//!
//! Run: `cargo bench --bench fdem_step`. Criterion reports elements/s = triangle-steps/s;
//! joint-steps/s = triangle-steps/s x joints/triangles (about 1.5), printed once per mesh.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pcdc_cohesive::{CohesiveJoints, IntrinsicCzmParams};
use pcdc_compute::{Backend, Precision, Simulation};
use pcdc_contact::Contact;
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, split_nodes, Dim2, Range};

const E: f64 = 30e9;

/// Steps per measured GPU iteration.
const GPU_STEPS: u64 = 20;

fn scene(cells_x: usize, backend: Backend) -> Simulation<Dim2> {
    scene_with(cells_x, backend, false)
}

fn scene_with(cells_x: usize, backend: Backend, contact: bool) -> Simulation<Dim2> {
    let h = 0.05 / cells_x as f64;
    let mesh = builders::rectangle(0.0, 0.0, 0.05, 0.10, h).unwrap();
    let split = split_nodes(&mesh, &Range::All).unwrap();
    let czm = IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 10e6,
        tensile_strength: 2e6,
        gf1: 0.5,
        gf2: 5.0,
        penalty_open: 10.0 * E,
        penalty_shear: 10.0 * E,
        penalty_overlap: 100.0 * E,
    }
    .build()
    .unwrap();
    let rock = LinearElastic::new(E, 0.25, 2600.0).unwrap();
    let c_p = ((rock.lambda() + 2.0 * rock.shear()) / 2600.0).sqrt();
    let mut b = Simulation::builder(split, backend)
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(CohesiveJoints::new().model(Range::All, czm));
    if contact {
        b = b.physics(
            Contact::new(10.0 * E)
                .friction(30.0, 10.0 * E)
                .bonded_interfaces(pcdc_cohesive::BROKEN_FACE),
        );
    }
    b.physics(
        Boundary::new()
            .velocity(Range::group("bottom"), [None, Some(0.0.into()), None])
            .velocity(Range::group("top"), [None, Some((-0.05).into()), None]),
    )
    .time_step(0.05 * h / c_p)
    .build()
    .unwrap()
}

fn bench(c: &mut Criterion) {
    let all = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let mut threads = vec![1];
    if all > 1 {
        threads.push(all);
    }
    let mut g = c.benchmark_group("fdem_step");
    g.sample_size(10);
    g.measurement_time(std::time::Duration::from_secs(6));
    // nx x 2nx cells of 2 triangles: 50 -> 10k, 112 -> 50k, 224 -> 201k.
    for nx in [50, 112, 224] {
        for &t in &threads {
            let mut sim = scene(nx, Backend::cpu(t).unwrap());
            let n = sim.mesh().n_elements();
            if t == 1 {
                let joints = sim.field(pcdc_cohesive::JOINT_DAMAGE).unwrap().len();
                eprintln!("fdem_step: {n} triangles, {joints} joints ({:.3} joints per triangle), {:.0} B per triangle in the simulation state", joints as f64 / n as f64, sim.state_bytes() as f64 / n as f64);
            }
            g.throughput(Throughput::Elements(n as u64));
            g.bench_function(format!("tri3_{}k_joints_threads_{t}", n / 1000), |b| {
                b.iter(|| sim.step().unwrap())
            });
        }
    }
    // The full scene with contact (CPU).
    for nx in [50, 112] {
        for &t in &threads {
            let mut sim = scene_with(nx, Backend::cpu(t).unwrap(), true);
            let n = sim.mesh().n_elements();
            if t == 1 {
                // The candidate lists the contact physics builds (default skin: half the
                // smallest edge); each element evaluates each of its pairs once per step.
                let (lo, _) = sim.mesh().edge_length_range();
                let kin = sim.kinematics();
                let boxes = pcdc_contact::element_boxes(&kin, 0.25 * lo);
                let lists = pcdc_contact::grid_candidates(&boxes, sim.mesh().elements());
                let evals: usize = lists.iter().map(|l| l.len()).sum();
                // The contact state (lists and histories) is in fields of a fixed
                // capacity per element, so it counts in the simulation state.
                let cap = sim.field(pcdc_contact::CONTACT_CANDIDATES).unwrap().len() / n;
                eprintln!(
                    "fdem_step contact: {n} triangles, {:.2} candidate pairs per triangle-step, bonded ones (~3) skipped (pairs/s = triangle-steps/s x this); capacity {cap} candidates per triangle, {:.0} B per triangle in the simulation state",
                    evals as f64 / n as f64,
                    sim.state_bytes() as f64 / n as f64
                );
            }
            g.throughput(Throughput::Elements(n as u64));
            g.bench_function(format!("tri3_{}k_contact_threads_{t}", n / 1000), |b| {
                b.iter(|| sim.step().unwrap())
            });
        }
    }
    for p in [Precision::F64, Precision::F32] {
        let gpu = match Backend::gpu(Some(p)) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("no GPU rows in {}: {e}", p.name());
                continue;
            }
        };
        let name = if gpu.as_gpu().expect("a GPU backend").is_software() {
            "lavapipe"
        } else {
            "gpu"
        };
        let sizes: &[usize] = if gpu.as_gpu().expect("a GPU backend").is_software() {
            &[50]
        } else {
            &[50, 112, 224]
        };
        for &nx in sizes {
            let mut sim = scene(nx, gpu.clone());
            let n = sim.mesh().n_elements();
            eprintln!(
                "fdem_step {name} {}: {n} triangles, {:.0} bytes per triangle-step, adapter {}",
                p.name(),
                sim.gpu_bytes_per_step().unwrap_or(0) as f64 / n as f64,
                gpu.as_gpu().expect("a GPU backend").adapter_name()
            );
            g.throughput(Throughput::Elements(n as u64 * GPU_STEPS));
            g.bench_function(
                format!("tri3_{}k_joints_{name}_{}", n / 1000, p.name()),
                |b| b.iter(|| sim.run(GPU_STEPS).unwrap()),
            );
            // The full scene with contact on the device.
            let mut sim = scene_with(nx, gpu.clone(), true);
            g.bench_function(
                format!("tri3_{}k_contact_{name}_{}", n / 1000, p.name()),
                |b| b.iter(|| sim.run(GPU_STEPS).unwrap()),
            );
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
