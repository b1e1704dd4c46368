//! Heat in the fracture fluid: energy balance of solid + fluid, no overshoot of the
//! upwind advection, the inputs it refuses.

use pcdc_compute::{names, Backend, ComputeError, FieldSchedule, Simulation, SubCycle};
use pcdc_hydro::{Aperture, Coupling, FlowModel, Fluid, Hydro};
use pcdc_mesh::{builders, split_nodes, Dim, Dim2, Dim3, Mesh, Range};
use pcdc_thermal::output::energy_balance;
use pcdc_thermal::{
    FluidHeat, HeatMaterial, JointHeat, Thermal, FLUID_HEAT_BALANCE, FLUID_HEAT_CAPACITY,
    FLUID_TEMPERATURE, HEAT_SUPPLIED,
};
use proptest::prelude::*;

const L: f64 = 2.0;

fn fracture_mesh() -> Mesh<Dim2> {
    split_nodes(
        &builders::rectangle(0.0, -0.5, L, 1.0, 0.125).unwrap(),
        &Range::All,
    )
    .unwrap()
}

fn inlet() -> Range {
    Range::rect(-1e-6, -1e-6, 1e-6, 1e-6)
}

/// Flow along the fracture y = 0 from x = 0 to x = L under `dp` (Pa), aperture 1 mm.
fn hydro(dp: f64, steady: bool) -> Hydro {
    let h = Hydro::new(FlowModel::new(
        Fluid::water(),
        Aperture::fixed(1e-3).unwrap(),
    ))
    .coupling(Coupling::FlowOnly)
    .network_on(Range::plane([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1e-9))
    .pressure(inlet(), dp)
    .pressure(Range::rect(L - 1e-6, -1e-6, L + 1e-6, 1e-6), 0.0);
    if steady {
        h.steady_flow()
    } else {
        h
    }
}

fn thermal(t0: f64, t_in: f64, h_sf: f64) -> Thermal {
    Thermal::new()
        .material(Range::All, HeatMaterial::new(3.0, 800.0, 2700.0).unwrap())
        .initial_temperature(t0)
        .joints(JointHeat::Conducting)
        .fluid(FluidHeat::water(h_sf).unwrap())
        .fluid_temperature(inlet(), t_in)
}

fn build(h: Hydro, t: Thermal) -> Result<Simulation<Dim2>, ComputeError> {
    Simulation::builder(fracture_mesh(), Backend::cpu(1).unwrap())
        .physics(h)
        .physics(t)
        .build()
}

/// Solid + fluid heat content changes by exactly what the conditions, the faces and the
/// flow across the network's boundary brought: on a steady flow with a held inlet
/// temperature and convection on the top face, and on a transient flow filling a dry
/// fracture (the fluid's capacity grows).
#[test]
fn solid_and_fluid_energy_balance_closes_to_rounding() {
    let heat = thermal(20.0, 80.0, 500.0)
        .convection(Range::group("top"), 5.0, 0.0)
        .heat_only();
    let mut sim = build(hydro(24.0, true), heat).unwrap();
    let t0 = sim.field(names::TEMPERATURE).unwrap().to_vec();
    sim.run(300).unwrap();
    let b = energy_balance(&sim, &t0).unwrap();
    assert!(b.stored.abs() > 1e3, "heat moved: {b:?}");
    assert!(b.relative() < 1e-12, "steady flow: {b:?}");
    let tf = sim.field(FLUID_TEMPERATURE).unwrap();
    assert!(
        tf.iter().any(|&t| t > 21.0),
        "the inlet heat advected: {tf:?}"
    );

    // A dry fracture filling from the inlet: the fluid's capacity changes every step.
    let flow = hydro(2e4, false).initially_dry();
    let heat = thermal(20.0, 80.0, 500.0).schedule(FieldSchedule::Fixed(SubCycle::Every(20)));
    let mut sim = build(flow, heat).unwrap();
    let t0 = sim.field(names::TEMPERATURE).unwrap().to_vec();
    sim.run(2000).unwrap();
    let s = sim.field(names::FLOW_SATURATION).unwrap();
    assert!(
        s.iter().any(|&s| s > 0.0 && s < 1.0),
        "partly filled: {s:?}"
    );
    let b = energy_balance(&sim, &t0).unwrap();
    assert!(b.stored.abs() > 0.0, "{b:?}");
    assert!(b.relative() < 1e-11, "filling fracture: {b:?}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 8, ..ProptestConfig::default() })]
    /// Upwind advection with exchange keeps every fluid and solid temperature within
    /// the initial and inlet temperatures, whatever the flow rate and transfer
    /// coefficient (no overshoot).
    #[test]
    fn fluid_and_solid_stay_within_initial_and_inlet_bounds(
        t0 in -20.0f64..60.0, t_in in -20.0f64..120.0,
        dp in 0.1f64..1e3, h_sf in 0.0f64..1e5,
    ) {
        let heat = thermal(t0, t_in, h_sf).heat_only();
        let mut sim = build(hydro(dp, true), heat).unwrap();
        sim.run(100).unwrap();
        let (lo, hi) = (t0.min(t_in), t0.max(t_in));
        let tol = 1e-9 * hi.abs().max(lo.abs()).max(1.0);
        for &t in sim.field(FLUID_TEMPERATURE).unwrap().iter().chain(sim.field(names::TEMPERATURE).unwrap()) {
            prop_assert!(t >= lo - tol && t <= hi + tol, "{t} outside [{lo}, {hi}]");
        }
    }
}

#[test]
fn fluid_heat_without_a_flow_network_is_refused() {
    let mesh = fracture_mesh();
    let heat = thermal(20.0, 80.0, 10.0).heat_only();
    let e = Simulation::builder(mesh.clone(), Backend::cpu(1).unwrap())
        .physics(heat)
        .build()
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.contains("pcdc_hydro::Hydro"), "{e}");
    let heat = Thermal::new()
        .material(Range::All, HeatMaterial::new(3.0, 800.0, 2700.0).unwrap())
        .joints(JointHeat::Conducting)
        .fluid_temperature(inlet(), 50.0)
        .heat_only();
    let e = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(heat)
        .build()
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.contains("Thermal::fluid"), "{e}");
    // A condition off the network names itself.
    let heat = thermal(20.0, 80.0, 10.0)
        .fluid_temperature(Range::rect(0.9, 0.4, 1.1, 0.6), 50.0)
        .heat_only();
    let e = build(hydro(24.0, true), heat)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.contains("fluid temperature condition 1"), "{e}");
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-300);
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

fn fluid_fields<D: Dim>(sim: &Simulation<D>) -> Vec<Vec<f64>> {
    [
        names::TEMPERATURE.name(),
        FLUID_TEMPERATURE.name(),
        FLUID_HEAT_CAPACITY.name(),
        FLUID_HEAT_BALANCE.name(),
        HEAT_SUPPLIED.name(),
    ]
    .iter()
    .map(|n| sim.field(n).unwrap().to_vec())
    .collect()
}

/// A 3D block with a fracture plane z = 0.25 m carrying a steady flow along x.
fn block_3d() -> (Mesh<Dim3>, Hydro, Thermal) {
    let mesh = split_nodes(
        &builders::cuboid([0.0; 3], [1.0, 0.5, 0.5], 0.125).unwrap(),
        &Range::All,
    )
    .unwrap();
    let inlet = Range::Box {
        min: [-1e-6, -1e-6, 0.25 - 1e-6],
        max: [1e-6, 0.5 + 1e-6, 0.25 + 1e-6],
    };
    let outlet = Range::Box {
        min: [1.0 - 1e-6, -1e-6, 0.25 - 1e-6],
        max: [1.0 + 1e-6, 0.5 + 1e-6, 0.25 + 1e-6],
    };
    let flow = Hydro::new(FlowModel::new(
        Fluid::water(),
        Aperture::fixed(1e-3).unwrap(),
    ))
    .coupling(Coupling::FlowOnly)
    .network_on(Range::plane([0.0, 0.0, 0.25], [0.0, 0.0, 1.0], 1e-9))
    .pressure(inlet.clone(), 12.0)
    .pressure(outlet, 0.0)
    .steady_flow();
    let heat = Thermal::new()
        .material(Range::All, HeatMaterial::new(3.0, 800.0, 2700.0).unwrap())
        .initial_temperature(20.0)
        .joints(JointHeat::Conducting)
        .fluid(FluidHeat::water(300.0).unwrap())
        .fluid_temperature(inlet, 80.0)
        .convection(Range::group("zmax"), 5.0, 0.0)
        .heat_only();
    (mesh, flow, heat)
}

fn parity<D: Dim>(
    mesh: Mesh<D>,
    flow: impl Fn() -> Hydro,
    heat: impl Fn() -> Thermal,
    steps: u64,
    label: &str,
) {
    let Some(gpu) = pcdc_compute::gpu::gpu_test_backend(Some(pcdc_compute::Precision::F64)) else {
        return;
    };
    let run = |backend: Backend| {
        let mut sim = Simulation::builder(mesh.clone(), backend)
            .physics(flow())
            .physics(heat())
            .build()
            .unwrap();
        let t0 = sim.field(names::TEMPERATURE).unwrap().to_vec();
        sim.run(steps).unwrap();
        let b = energy_balance(&sim, &t0).unwrap();
        (fluid_fields(&sim), b)
    };
    let (cpu, bc) = run(Backend::cpu(1).unwrap());
    let (dev, bg) = run(gpu);
    let d: Vec<f64> = cpu.iter().zip(&dev).map(|(a, b)| rel_diff(a, b)).collect();
    println!(
        "{label}: solid T, fluid T, capacity, balance, supplied: {d:?}; balance {:.1e}/{:.1e}",
        bc.relative(),
        bg.relative()
    );
    assert!(d.iter().all(|&x| x <= 1e-12), "{label}: {d:?}");
    assert!(bg.relative() < 1e-11, "{label} GPU balance: {bg:?}");
}

/// Fluid heat on the device: the CPU's arithmetic in the same order, f64 parity to
/// 1e-12 on a steady 2D fracture, a 3D fracture plane, and a dry 2D fracture filling
/// (transient flow kernels, capacity changing every step).
#[test]
fn fluid_heat_gpu_matches_cpu_2d_3d_and_filling() {
    parity(
        fracture_mesh(),
        || hydro(24.0, true),
        || {
            thermal(20.0, 80.0, 500.0)
                .convection(Range::group("top"), 5.0, 0.0)
                .heat_only()
        },
        200,
        "2D steady fracture",
    );
    let (m3, _, _) = block_3d();
    parity(
        m3,
        || block_3d().1,
        || block_3d().2,
        100,
        "3D fracture plane",
    );
    parity(
        fracture_mesh(),
        || hydro(2e4, false).initially_dry(),
        || thermal(20.0, 80.0, 500.0).schedule(FieldSchedule::Fixed(SubCycle::Every(20))),
        2000,
        "2D filling fracture",
    );
}

/// Every fluid heat kernel validates in naga, 2D and 3D, f64 and f32.
#[test]
fn fluid_heat_kernels_validate_in_naga() {
    use pcdc_compute::gpu::{offline_kernel_sources, validate_wgsl};
    for p in [pcdc_compute::Precision::F64, pcdc_compute::Precision::F32] {
        let m2 = fracture_mesh();
        let s2 = offline_kernel_sources::<_>(
            &m2,
            vec![
                Box::new(hydro(24.0, true)),
                Box::new(thermal(20.0, 80.0, 500.0).heat_only()),
            ],
            p,
        )
        .unwrap();
        let (m3, f3, h3) = block_3d();
        let s3 = offline_kernel_sources::<_>(&m3, vec![Box::new(f3), Box::new(h3)], p).unwrap();
        let fluid: Vec<_> = s2
            .iter()
            .chain(&s3)
            .filter(|(l, _)| l.starts_with("thermal fluid"))
            .collect();
        assert_eq!(fluid.len(), 6, "three fluid kernels in 2D and 3D");
        for (label, src) in fluid {
            if let Err(e) = validate_wgsl(src) {
                panic!("{label} ({}) does not validate:\n{e}", p.name());
            }
        }
    }
}
