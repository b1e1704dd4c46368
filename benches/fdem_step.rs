//! The standard FDEM benchmark scene (docs/design-targets.md, with its speed targets): a
//! 0.05 x 0.10 m block of right triangles, every triangle with its own nodes, an
//! intrinsic cohesive joint on every interior edge (penalties 10 E, overlap 100 E,
//! Ts = 2 MPa, c = 10 MPa), E = 30 GPa, nu = 0.25, rho = 2600, bottom fixed in y, top
//! pushed at 0.05 m/s, dt = 0.05 h / c_p; 10k, 50k and 200k triangles, 1 thread and all
//! threads. Rows `..._joints_...` leave contact out; rows `..._contact_...` are the
//! full scene with contact on (penalty 10 E, friction 30° with shear penalty 10 E,
//! bonded neighbours excluded until their joint breaks), 10k, 50k and 200k triangles.
//!
//! GPU rows (when an adapter exists, f64 and f32; joints only and with contact): one
//! iteration is `run(GPU_STEPS)`,
//! which includes one upload and one read-back of the state, so the rate is per
//! triangle-step with the transfers amortised over GPU_STEPS steps. On a software adapter
//! (Mesa's lavapipe) only the 10k mesh runs, and its rows prove that the path works, not
//! GPU speed.
//!
//! CPU rows: one iteration is `run(CPU_STEPS)` (the rate of steps inside a run, as
//! the examples and most scenes advance). Rows `..._step_calls` call `step()` once per
//! iteration instead: each call hands the step to the backend's pool and back, and on
//! an unpinned 2-core VM the pool's worker then changes core from step to step, so
//! these rows show what that costs (docs/performance.md).
//!
//! Run: `cargo bench --bench fdem_step`. Criterion reports elements/s = triangle-steps/s;
//! joint-steps/s = triangle-steps/s x joints/triangles (about 1.5), printed once per mesh.
//!
//! 3D rows `tet4_...`: the cuboid of tetrahedra of `pcdc_validation::scenes::benchmark`
//! (12 000 and 49 152 tetrahedra, joints on every interior face), joints only and with
//! contact, 1 thread and all threads.
//!
//! The scenes are built by `pcdc_validation::scenes::benchmark` (also used by the
//! `step_profile` example).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pcdc_compute::{Backend, Precision, Simulation};
use pcdc_mesh::Dim2;
use pcdc_validation::scenes::benchmark::{fdem_block_2d, fdem_cuboid_3d};

/// Steps per measured GPU iteration.
const GPU_STEPS: u64 = 20;

/// Steps per measured CPU iteration.
const CPU_STEPS: u64 = 10;

fn scene(cells_x: usize, backend: Backend) -> Simulation<Dim2> {
    scene_with(cells_x, backend, false)
}

fn scene_with(cells_x: usize, backend: Backend, contact: bool) -> Simulation<Dim2> {
    fdem_block_2d(cells_x, backend, contact).unwrap()
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
            g.throughput(Throughput::Elements(n as u64 * CPU_STEPS));
            g.bench_function(format!("tri3_{}k_joints_threads_{t}", n / 1000), |b| {
                b.iter(|| sim.run(CPU_STEPS).unwrap())
            });
            if nx == 50 && t == 1 {
                g.throughput(Throughput::Elements(n as u64));
                g.bench_function("tri3_10k_joints_threads_1_step_calls", |b| {
                    b.iter(|| sim.step().unwrap())
                });
            }
        }
    }
    // The full scene with contact (CPU).
    for nx in [50, 112, 224] {
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
                    "fdem_step contact: {n} triangles, {:.2} broad-phase candidates per triangle (in intact rock all are skipped before the narrow phase: sealed elements, intact vertices, intact bonds); capacity {cap} candidates per triangle, {:.0} B per triangle in the simulation state",
                    evals as f64 / n as f64,
                    sim.state_bytes() as f64 / n as f64
                );
            }
            g.throughput(Throughput::Elements(n as u64 * CPU_STEPS));
            g.bench_function(format!("tri3_{}k_contact_threads_{t}", n / 1000), |b| {
                b.iter(|| sim.run(CPU_STEPS).unwrap())
            });
            if nx == 50 && t == 1 {
                g.throughput(Throughput::Elements(n as u64));
                g.bench_function("tri3_10k_contact_threads_1_step_calls", |b| {
                    b.iter(|| sim.step().unwrap())
                });
            }
        }
    }
    // The 3D scene (tetrahedra, joints on every interior face, with and without contact).
    for cells in [10, 16] {
        for contact in [false, true] {
            for &t in &threads {
                let mut sim = fdem_cuboid_3d(cells, Backend::cpu(t).unwrap(), contact).unwrap();
                let n = sim.mesh().n_elements();
                let what = if contact { "contact" } else { "joints" };
                if t == 1 {
                    let joints = sim.field(pcdc_cohesive::JOINT_DAMAGE).unwrap().len();
                    eprintln!("fdem_step 3D {what}: {n} tetrahedra, {joints} joints ({:.3} per tetrahedron), {:.0} B per tetrahedron in the simulation state", joints as f64 / n as f64, sim.state_bytes() as f64 / n as f64);
                }
                g.throughput(Throughput::Elements(n as u64 * CPU_STEPS));
                g.bench_function(format!("tet4_{}k_{what}_threads_{t}", n / 1000), |b| {
                    b.iter(|| sim.run(CPU_STEPS).unwrap())
                });
            }
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
