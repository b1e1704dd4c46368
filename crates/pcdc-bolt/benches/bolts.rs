//! Bolt throughput and cost in a tunnel scene: a circular opening (radius 1 m) in a
//! 8 × 8 m plate of elastic rock under gravity, alone and with a radial bolt pattern of
//! one bolt per 50 elements and one per 500 (bolts 2 m long from the wall, 10 segments
//! each, fully grouted, a face plate at the head), and one per 50 with fixed hosts (no
//! re-location). Criterion reports element-steps/s for
//! the rock alone and with bolts (the difference is the bolts' cost), and
//! bolt-segment-steps/s for the bolts in the same run; CPU with 1 thread and all threads, GPU (f64, f32) when
//! an adapter exists (one iteration = `run(GPU_STEPS)`).
//!
//! Run: `cargo bench -p pcdc-bolt --bench bolts`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pcdc_bolt::{Bolt, BoltMaterial, BoltProperties, Bolts};
use pcdc_compute::{Backend, Precision, Simulation};
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim2, Mesh, Range};

/// Steps per measured GPU iteration.
const GPU_STEPS: u64 = 20;

fn tunnel() -> Mesh<Dim2> {
    builders::plate_with_hole(4.0, 4.0, 1.0, 0.04, 0.12).unwrap()
}

/// Radial bolts of 10 segments: `per` elements per bolt; `fixed`: no re-location.
fn pattern(mesh: &Mesh<Dim2>, per: usize, fixed: bool) -> Bolts {
    let n = (mesh.n_elements() / per).max(1);
    let rebar = BoltMaterial::new(BoltProperties::steel_rebar(0.025)).unwrap();
    let mut bolts = Bolts::new();
    for i in 0..n {
        let a = 2.0 * std::f64::consts::PI * (i as f64 + 0.5) / n as f64;
        let (c, s) = (a.cos(), a.sin());
        let bolt = Bolt::straight(
            format!("B{i}"),
            [c * 1.0, s * 1.0, 0.0],
            [c * 3.0, s * 3.0, 0.0],
            10,
            rebar,
        )
        .unwrap()
        .face_plate(1e8)
        .unwrap();
        bolts = bolts.bolt(bolt).unwrap();
    }
    if fixed {
        bolts = bolts.fixed_hosts();
    }
    bolts
}

fn sim(mesh: &Mesh<Dim2>, backend: Backend, bolts: Option<usize>, fixed: bool) -> Simulation<Dim2> {
    let rock = LinearElastic::new(20e9, 0.25, 2600.0).unwrap();
    let mut b = Simulation::builder(mesh.clone(), backend)
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(Boundary::new().fix(Range::group("bottom")))
        .gravity([0.0, -9.81, 0.0]);
    if let Some(per) = bolts {
        b = b.physics(pattern(mesh, per, fixed));
    }
    b.build().unwrap()
}

fn bench(c: &mut Criterion) {
    let all = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let mut threads = vec![1];
    if all > 1 {
        threads.push(all);
    }
    let mesh = tunnel();
    let ne = mesh.n_elements();
    let mut g = c.benchmark_group("bolts");
    g.sample_size(10);
    g.measurement_time(std::time::Duration::from_secs(5));
    let k = ne / 1000;
    for &t in &threads {
        g.throughput(Throughput::Elements(ne as u64));
        let mut s = sim(&mesh, Backend::cpu(t).unwrap(), None, false);
        g.bench_function(format!("tunnel_{k}k_rock_threads_{t}"), |b| {
            b.iter(|| s.step().unwrap())
        });
        // One bolt per 50 elements, and one bolt segment per 50 elements (a bolt per
        // 500 elements).
        for per in [50, 500] {
            let segments = 10 * (ne / per).max(1);
            g.throughput(Throughput::Elements(ne as u64));
            let mut s = sim(&mesh, Backend::cpu(t).unwrap(), Some(per), false);
            g.bench_function(format!("tunnel_{k}k_bolt_per_{per}_threads_{t}"), |b| {
                b.iter(|| s.step().unwrap())
            });
            g.throughput(Throughput::Elements(segments as u64));
            g.bench_function(
                format!("tunnel_{k}k_bolt_per_{per}_segments_{segments}_threads_{t}"),
                |b| b.iter(|| s.step().unwrap()),
            );
        }
        // Without re-location: slots on the hosts' nodes only (the segments span about
        // five elements each near the wall, whose nodes re-location gives slots).
        g.throughput(Throughput::Elements(ne as u64));
        let mut s = sim(&mesh, Backend::cpu(t).unwrap(), Some(50), true);
        g.bench_function(format!("tunnel_{k}k_bolt_per_50_fixed_threads_{t}"), |b| {
            b.iter(|| s.step().unwrap())
        });
    }
    for p in [Precision::F64, Precision::F32] {
        let Some(gpu) = pcdc_compute::gpu::gpu_test_backend(Some(p)) else {
            continue;
        };
        for bolts in [None, Some(50), Some(500)] {
            g.throughput(Throughput::Elements(ne as u64 * GPU_STEPS));
            let mut s = sim(&mesh, gpu.clone(), bolts, false);
            let what = bolts.map_or("rock".to_string(), |p| format!("bolt_per_{p}"));
            g.bench_function(format!("tunnel_{k}k_{what}_gpu_{}", p.name()), |b| {
                b.iter(|| s.run(GPU_STEPS).unwrap())
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
