//! What bolts cost in an FDEM tunnel scene: the `tunnel_bolts` scene (a circular
//! opening of radius 1 m in rock under 10 MPa in-situ stress, jointed with intrinsic
//! cohesive joints and contact within 2.5 m of the axis, elastic beyond; element size
//! 0.1 m at the wall) alone, with one radial bolt per 50 elements and one per 500
//! (1.5 m from the wall, 10 segments each, face plates). One iteration is
//! `run(CPU_STEPS)` on a freshly built scene (the build is not timed), so that every
//! row times the same steps from the same state: the scene evolves as the wall
//! pressure falls, and a scene advanced by criterion's own iteration count would
//! compare different states. Criterion reports element-steps/s; the bolted rows'
//! difference to the row alone is the bolts' cost (issue 18: under 5 % with one bolt
//! per 50 elements). 1 thread and all threads.
//!
//! Run: `cargo bench --bench bolted_tunnel`.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use pcdc_compute::Backend;
use pcdc_validation::scenes::tunnel_bolts::{bolt_pattern, simulation};

/// Steps per measured iteration.
const CPU_STEPS: u64 = 200;

/// Element size at the wall (m).
const SIZE: f64 = 0.1;

fn bench(c: &mut Criterion) {
    let all = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let mut threads = vec![1];
    if all > 1 {
        threads.push(all);
    }
    let mut g = c.benchmark_group("bolted_tunnel");
    g.sample_size(10);
    g.measurement_time(std::time::Duration::from_secs(8));
    for &t in &threads {
        let backend = Backend::cpu(t).unwrap();
        let ne = simulation(&backend, SIZE, None)
            .unwrap()
            .mesh()
            .n_elements();
        g.throughput(Throughput::Elements(ne as u64 * CPU_STEPS));
        for per in [None, Some(50), Some(500)] {
            let bolts = per.map(|p| (ne / p).max(1));
            if t == 1 {
                if let Some(n) = bolts {
                    eprintln!(
                        "bolted_tunnel: {ne} elements, {n} bolts ({} segments)",
                        10 * n
                    );
                }
            }
            let what = per.map_or("alone".to_string(), |p| format!("bolt_per_{p}"));
            g.bench_function(format!("fdem_tunnel_{ne}_{what}_threads_{t}"), |b| {
                b.iter_batched(
                    || simulation(&backend, SIZE, bolts.map(|n| bolt_pattern(n).unwrap())).unwrap(),
                    |mut sim| sim.run(CPU_STEPS).unwrap(),
                    BatchSize::PerIteration,
                )
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
