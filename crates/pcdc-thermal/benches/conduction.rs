//! Conduction throughput (node-steps per second): the thermal physics alone
//! (`Thermal::heat_only`, one thermal step per step, the engine's node pass included)
//! on the CPU backend with 1 thread and all threads, and on the GPU (f64 and f32, one
//! iteration = `run(GPU_STEPS)` with one upload and one read-back) when an adapter
//! exists. Blocks: about 200k triangles (the standard 0.05 × 0.10 m benchmark block)
//! and about 200k tetrahedra, a held temperature on one face and convection on the
//! opposite one.
//!
//! Run: `cargo bench -p pcdc-thermal --bench conduction`; criterion reports
//! elements/s, which here are nodes/s (= node-steps/s).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pcdc_compute::{Backend, Precision, Simulation};
use pcdc_mesh::{builders, Dim, Mesh, Range};
use pcdc_thermal::{HeatMaterial, Thermal};

/// Steps per measured GPU iteration.
const GPU_STEPS: u64 = 20;

fn sim<D: Dim>(mesh: Mesh<D>, backend: Backend, hot: &str, cold: &str) -> Simulation<D> {
    let rock = HeatMaterial::new(3.0, 800.0, 2700.0).unwrap();
    let heat = Thermal::new()
        .material(Range::All, rock)
        .initial_temperature(20.0)
        .temperature(Range::group(hot), 200.0)
        .convection(Range::group(cold), 30.0, 20.0)
        .heat_only();
    Simulation::builder(mesh, backend)
        .physics(heat)
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
    let mut g = c.benchmark_group("conduction");
    g.sample_size(10);
    g.measurement_time(std::time::Duration::from_secs(6));
    let tri = builders::rectangle(0.0, 0.0, 0.05, 0.10, 0.000_224).unwrap();
    let tet = builders::cuboid([0.0; 3], [0.05, 0.05, 0.10], 0.002).unwrap();
    let (n2, n3) = (tri.n_nodes(), tet.n_nodes());
    let (e2, e3) = (tri.n_elements() / 1000, tet.n_elements() / 1000);
    for &t in &threads {
        g.throughput(Throughput::Elements(n2 as u64));
        let mut s = sim(tri.clone(), Backend::cpu(t).unwrap(), "left", "right");
        g.bench_function(format!("tri3_{e2}k_threads_{t}"), |b| {
            b.iter(|| s.step().unwrap())
        });
        g.throughput(Throughput::Elements(n3 as u64));
        let mut s = sim(tet.clone(), Backend::cpu(t).unwrap(), "xmin", "xmax");
        g.bench_function(format!("tet4_{e3}k_threads_{t}"), |b| {
            b.iter(|| s.step().unwrap())
        });
    }
    for precision in [Precision::F64, Precision::F32] {
        let gpu = match Backend::gpu(Some(precision)) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("no GPU rows in {}: {e}", precision.name());
                continue;
            }
        };
        let name = if gpu.as_gpu().expect("a GPU backend").is_software() {
            "lavapipe"
        } else {
            "gpu"
        };
        let p = format!("{name}_{}", precision.name());
        g.throughput(Throughput::Elements(n2 as u64 * GPU_STEPS));
        let mut s = sim(tri.clone(), gpu.clone(), "left", "right");
        g.bench_function(format!("tri3_{e2}k_{p}"), |b| {
            b.iter(|| s.run(GPU_STEPS).unwrap())
        });
        g.throughput(Throughput::Elements(n3 as u64 * GPU_STEPS));
        let mut s = sim(tet.clone(), gpu, "xmin", "xmax");
        g.bench_function(format!("tet4_{e3}k_{p}"), |b| {
            b.iter(|| s.run(GPU_STEPS).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
