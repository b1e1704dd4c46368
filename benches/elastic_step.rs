//! Elastic step throughput (element-steps per second) on the CPU backend, 1 thread and
//! all threads, for about 200k triangles (the standard benchmark block of
//! docs/design-targets.md, 0.05 x 0.10 m of right triangles, E = 30 GPa, nu = 0.25,
//! rho = 2600, bottom fixed in y, top pushed at 0.05 m/s; nodes are shared here because
//! the per-triangle nodes and joints of the full scene arrive with pcdc-cohesive) and
//! about 200k tetrahedra.
//!
//! GPU rows (when an adapter exists, f64 and f32): one iteration is `run(GPU_STEPS)`,
//! which includes one upload and one read-back of the state, so the rate is per
//! element-step with the transfers amortised over GPU_STEPS steps. On lavapipe (Mesa's
//! software Vulkan) these rows prove that the path works, not GPU speed.
//!
//! Run: `cargo bench --bench elastic_step`. Throughput is reported by criterion as
//! elements/s (= element-steps/s).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pcdc_compute::{Backend, Precision, Simulation};
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim, Mesh, Range};

/// Steps per measured GPU iteration.
const GPU_STEPS: u64 = 20;

fn sim<D: Dim>(mesh: Mesh<D>, backend: Backend, bottom: &str, top: &str) -> Simulation<D> {
    let rock = LinearElastic::new(30e9, 0.25, 2600.0).unwrap();
    let y = if D::D == 2 { 1 } else { 2 };
    let mut push = [None, None, None];
    push[y] = Some((-0.05).into());
    let mut hold = [None, None, None];
    hold[y] = Some(0.0.into());
    Simulation::builder(mesh, backend)
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(
            Boundary::new()
                .velocity(Range::group(bottom), hold)
                .velocity(Range::group(top), push),
        )
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
    let mut g = c.benchmark_group("elastic_step");
    g.sample_size(10);
    g.measurement_time(std::time::Duration::from_secs(8));
    // 2D: 0.05 x 0.10 m, h = 0.05/224 -> 224 x 448 cells x 2 = 200 704 triangles.
    let tri = builders::rectangle(0.0, 0.0, 0.05, 0.10, 0.05 / 224.0).unwrap();
    // 3D: cubes of 0.05/26 m, 6 tetrahedra each: 206 856 tetrahedra.
    let tet = builders::cuboid([0.0; 3], [0.05, 0.05, 0.0962], 0.05 / 26.0).unwrap();
    for &t in &threads {
        let mut s2 = sim(tri.clone(), Backend::cpu(t).unwrap(), "bottom", "top");
        g.throughput(Throughput::Elements(s2.mesh().n_elements() as u64));
        g.bench_function(
            format!("tri3_{}k_threads_{t}", s2.mesh().n_elements() / 1000),
            |b| b.iter(|| s2.step().unwrap()),
        );
        let mut s3 = sim(tet.clone(), Backend::cpu(t).unwrap(), "zmin", "zmax");
        g.throughput(Throughput::Elements(s3.mesh().n_elements() as u64));
        g.bench_function(
            format!("tet4_{}k_threads_{t}", s3.mesh().n_elements() / 1000),
            |b| b.iter(|| s3.step().unwrap()),
        );
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
        g.throughput(Throughput::Elements(tri.n_elements() as u64 * GPU_STEPS));
        let mut s2 = sim(tri.clone(), gpu.clone(), "bottom", "top");
        let per = |b: Option<u64>, n: usize| b.unwrap_or(0) as f64 / n as f64;
        eprintln!(
            "{} {}: {:.0} bytes per element-step (Tri3), adapter {}",
            name,
            p.name(),
            per(s2.gpu_bytes_per_step(), tri.n_elements()),
            gpu.as_gpu().expect("a GPU backend").adapter_name()
        );
        g.bench_function(
            format!("tri3_{}k_{name}_{}", tri.n_elements() / 1000, p.name()),
            |b| b.iter(|| s2.run(GPU_STEPS).unwrap()),
        );
        g.throughput(Throughput::Elements(tet.n_elements() as u64 * GPU_STEPS));
        let mut s3 = sim(tet.clone(), gpu, "zmin", "zmax");
        eprintln!(
            "{} {}: {:.0} bytes per element-step (Tet4)",
            name,
            p.name(),
            per(s3.gpu_bytes_per_step(), tet.n_elements())
        );
        g.bench_function(
            format!("tet4_{}k_{name}_{}", tet.n_elements() / 1000, p.name()),
            |b| b.iter(|| s3.run(GPU_STEPS).unwrap()),
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
