//! The coupled step against mechanics alone, and the fluid stage alone, in
//! channel-steps/s: the benchmark block of right triangles (own nodes, a cohesive joint
//! on every interior edge) with water injected at its centre, two-way coupled, K_f
//! scaled to 1 % (so one fluid step per mechanical step: the schedule is printed).
//!
//! Run: `cargo bench -p pcdc-hydro --bench hydro_step`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pcdc_cohesive::{CohesiveJoints, IntrinsicCzmParams};
use pcdc_compute::{Backend, Simulation};
use pcdc_hydro::{Aperture, Coupling, FlowModel, Fluid, Hydro};
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{builders, split_nodes, Dim2, Range};

const STEPS: u64 = 10;

fn scene(size: f64, flow: Option<Coupling>, threads: usize) -> Simulation<Dim2> {
    let mesh = split_nodes(
        &builders::rectangle(0.0, 0.0, 0.05, 0.1, size).unwrap(),
        &Range::All,
    )
    .unwrap();
    let rock = LinearElastic::new(30e9, 0.25, 2600.0)
        .unwrap()
        .with_damping(0.1)
        .unwrap();
    let czm = IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 2e7,
        tensile_strength: 1e7,
        gf1: 10.0,
        gf2: 100.0,
        penalty_open: 3e11,
        penalty_shear: 3e11,
        penalty_overlap: 3e12,
    }
    .build()
    .unwrap();
    let mut b = Simulation::builder(mesh, Backend::cpu(threads).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(CohesiveJoints::new().model(Range::All, czm));
    if let Some(c) = flow {
        let model = FlowModel::new(Fluid::water(), Aperture::new(1e-6, 1e-7, 1e-4).unwrap());
        b = b.physics(Hydro::new(model).coupling(c).bulk_modulus_scale(0.01).rate(
            Range::Ball {
                center: [0.025, 0.05, 0.0],
                radius: 0.6 * size,
            },
            1e-6,
        ));
    }
    b.build().unwrap()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("hydro_step");
    g.sample_size(10);
    for (name, size) in [("10k", 0.05 / 50.0), ("50k", 0.05 / 112.0)] {
        for threads in [1, 2] {
            let mech = scene(size, None, threads);
            let n = mech.mesh().n_elements() as u64;
            g.throughput(Throughput::Elements(n * STEPS));
            let mut sim = mech;
            g.bench_function(format!("tri3_{name}_mechanics_threads_{threads}"), |b| {
                b.iter(|| sim.run(STEPS).unwrap())
            });
            let mut sim = scene(size, Some(Coupling::TwoWay), threads);
            let channels = sim.entity_set("flow_channels").unwrap().len() as u64;
            if threads == 1 {
                eprintln!(
                    "{name}: {n} triangles, {channels} channels, mechanical step {:e} s ({:?}), fluid stage {:?}",
                    sim.dt(),
                    sim.time_step_limit().map(|l| l.entity),
                    sim.field_stages().iter().map(|s| s.cycle).collect::<Vec<_>>()
                );
            }
            g.bench_function(format!("tri3_{name}_two_way_threads_{threads}"), |b| {
                b.iter(|| sim.run(STEPS).unwrap())
            });
            // The same, counted in channel-steps.
            g.throughput(Throughput::Elements(channels * STEPS));
            let mut sim = scene(size, Some(Coupling::TwoWay), threads);
            g.bench_function(
                format!("tri3_{name}_two_way_channels_threads_{threads}"),
                |b| b.iter(|| sim.run(STEPS).unwrap()),
            );
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
