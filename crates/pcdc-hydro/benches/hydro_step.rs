//! The coupled step against mechanics alone, and the fluid stage alone, in
//! channel-steps/s: the benchmark block of right triangles (own nodes, a cohesive joint
//! on every interior edge) with water injected at its centre, two-way coupled, K_f
//! scaled to 1 % (so one fluid step per mechanical step: the schedule is printed); and
//! the injection scene of validation scene 12 (a disc under anisotropic in-situ stress,
//! cohesive joints everywhere, water injected at the centre with leak-off), coupled and
//! without its fluid.
//!
//! Run: `cargo bench -p pcdc-hydro --bench hydro_step`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pcdc_cohesive::{CohesiveJoints, IntrinsicCzmParams};
use pcdc_compute::{Backend, Simulation};
use pcdc_hydro::{Aperture, Coupling, FlowModel, Fluid, Hydro, LeakOff};
use pcdc_mech::{Boundary, FaceStress, LinearElastic, Mechanics};
use pcdc_mesh::{builders, split_nodes, Dim2, Range};

const STEPS: u64 = 10;
/// Steps run before the injection scene is timed, with and without its fluid alike (the
/// fracture has started in the coupled run).
const WARM: u64 = 2000;

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

/// Validation scene 12's set-up (`pcdc_validation::scenes::injection`), with or without
/// its fluid, after `warm` steps.
fn injection(size: f64, fluid: bool, threads: usize, warm: u64) -> Simulation<Dim2> {
    let mesh = split_nodes(&builders::disc([0.0, 0.0], 0.5, size).unwrap(), &Range::All).unwrap();
    let stress = [-8e6, -4e6, 0.0, 0.0, 0.0, 0.0];
    let rock = LinearElastic::new(10e9, 0.25, 2600.0)
        .unwrap()
        .with_damping(0.5)
        .unwrap();
    let czm = IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 4e6,
        tensile_strength: 2e6,
        gf1: 5.0,
        gf2: 50.0,
        penalty_open: 1e11,
        penalty_shear: 1e11,
        penalty_overlap: 1e12,
    }
    .build()
    .unwrap();
    let mut b = Simulation::builder(mesh, Backend::cpu(threads).unwrap())
        .physics(
            Mechanics::new()
                .material(Range::All, rock)
                .initial_stress(Range::All, stress),
        )
        .physics(Boundary::new().face_stress(Range::group("boundary"), FaceStress::tensor(stress)))
        .physics(CohesiveJoints::new().model(Range::All, czm));
    if fluid {
        let leak = LeakOff {
            pore_pressure: 0.0,
            permeability: 1e-18,
            pore_compressibility: 1e-9,
            porosity: 0.01,
        };
        let model = FlowModel::new(Fluid::water(), Aperture::new(1e-6, 1e-6, 2e-4).unwrap())
            .with_leak_off(leak);
        b = b.physics(
            Hydro::new(model)
                .rock_permeability(1e-16)
                .bulk_modulus_scale(0.01)
                .rate(
                    Range::Ball {
                        center: [0.0; 3],
                        radius: 1e-3 * size,
                    },
                    4e-4,
                ),
        );
    }
    let mut sim = b.build().unwrap();
    sim.run(warm).unwrap();
    sim
}

fn bench_injection(c: &mut Criterion) {
    let mut g = c.benchmark_group("injection_step");
    g.sample_size(10);
    for (name, size) in [("4k", 0.02), ("16k", 0.01)] {
        for threads in [1, 2] {
            let mut mech = injection(size, false, threads, WARM);
            let n = mech.mesh().n_elements() as u64;
            g.throughput(Throughput::Elements(n * STEPS));
            g.bench_function(format!("disc_{name}_mechanics_threads_{threads}"), |b| {
                b.iter(|| mech.run(STEPS).unwrap())
            });
            let mut sim = injection(size, true, threads, WARM);
            let channels = sim.entity_set("flow_channels").unwrap().len() as u64;
            if threads == 1 {
                eprintln!(
                    "disc {name}: {n} triangles, {channels} channels, mechanical step {:e} s ({:?}), fluid stage {:?}",
                    sim.dt(),
                    sim.time_step_limit().map(|l| l.entity),
                    sim.field_stages().iter().map(|s| s.cycle).collect::<Vec<_>>()
                );
            }
            g.bench_function(format!("disc_{name}_two_way_threads_{threads}"), |b| {
                b.iter(|| sim.run(STEPS).unwrap())
            });
            g.throughput(Throughput::Elements(channels * STEPS));
            g.bench_function(
                format!("disc_{name}_two_way_channels_threads_{threads}"),
                |b| b.iter(|| sim.run(STEPS).unwrap()),
            );
        }
    }
    g.finish();
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

criterion_group!(benches, bench, bench_injection);
criterion_main!(benches);
