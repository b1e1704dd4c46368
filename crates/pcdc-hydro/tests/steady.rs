//! Steady flow (`Hydro::steady_flow`): closed forms, agreement with the transient flow at
//! its end, and the inputs it refuses.

use pcdc_compute::{Backend, Simulation};
use pcdc_hydro::fields::{CHANNEL_FLUX, FLOW_NODES, FLOW_PRESSURE};
use pcdc_hydro::{Aperture, Coupling, FlowModel, Fluid, Hydro};
use pcdc_mesh::{builders, split_nodes, Dim, Range};

fn linear_patch<D: Dim>(mesh: pcdc_mesh::Mesh<D>, field: impl Fn(&[f64]) -> f64) -> f64 {
    let split = split_nodes(&mesh, &Range::All).unwrap();
    let model = FlowModel::new(Fluid::water(), Aperture::new(1e-6, 1e-9, 1e-3).unwrap());
    let mut flow = Hydro::new(model)
        .coupling(Coupling::FlowOnly)
        .rock_permeability(1e-14)
        .steady_flow();
    // Pressures held on the boundary nodes; the interior follows from the solve.
    let bb = mesh.bounding_box();
    let net = pcdc_hydro::Network::build(&split, None, &[]).unwrap();
    for n in 0..split.n_nodes() {
        if net.mesh_flow[n] == pcdc_hydro::Network::NONE {
            continue; // a corner no joint reaches
        }
        let x = split.node(n);
        let on = (0..D::D).any(|k| (x[k] - bb.0[k]).abs() < 1e-9 || (x[k] - bb.1[k]).abs() < 1e-9);
        if on {
            let mut c = [0.0; 3];
            c[..D::D].copy_from_slice(x);
            flow = flow.pressure(
                Range::Ball {
                    center: c,
                    radius: 1e-6,
                },
                field(x),
            );
        }
    }
    let sim = Simulation::builder(split, Backend::cpu(1).unwrap())
        .physics(flow)
        .time_step(1.0)
        .build()
        .unwrap();
    let p = sim.field(FLOW_PRESSURE).unwrap();
    let set = sim.entity_set(FLOW_NODES).unwrap();
    (0..set.len())
        .map(|l| (p[l] - field(sim.mesh().node(set.entity(l)[0] as usize))).abs() / 1e6)
        .fold(0.0, f64::max)
}

/// Darcy flow through the calibrated intact network: a linear pressure is the steady
/// state exactly (patch test), in 2D and 3D.
#[test]
fn steady_linear_pressure_is_exact_in_2d_and_3d() {
    let f2 = |x: &[f64]| 1e6 * (1.0 + 0.5 * x[0] - 0.2 * x[1]);
    let e2 = linear_patch(builders::rectangle(0.0, 0.0, 1.0, 0.6, 0.15).unwrap(), f2);
    assert!(e2 < 1e-10, "2D: {e2}");
    let f3 = |x: &[f64]| 1e6 * (1.0 + 0.5 * x[0] - 0.2 * x[1] + 0.3 * x[2]);
    let e3 = linear_patch(
        builders::cuboid([0.0; 3], [1.0, 0.5, 0.5], 0.25).unwrap(),
        f3,
    );
    assert!(e3 < 1e-10, "3D: {e3}");
}

/// A fracture fed at its middle by a rate R, both ends at zero pressure: each half
/// carries R/2, so p_mid = (R/2)(L/2)·12 μ_d/δ³ and the flux is ±R/2. The transient
/// flow run to its end agrees with the steady solve.
#[test]
fn fed_fracture_matches_the_closed_form_and_the_transient_end() {
    let (l, delta, rate) = (1.0, 1e-4, 1e-6);
    let mesh = split_nodes(
        &builders::rectangle(0.0, -0.1, l, 0.2, 0.05).unwrap(),
        &Range::All,
    )
    .unwrap();
    let fluid = Fluid::water();
    let hydro = || {
        Hydro::new(FlowModel::new(fluid, Aperture::fixed(delta).unwrap()))
            .coupling(Coupling::FlowOnly)
            .network_on(Range::plane([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1e-9))
            .pressure(Range::rect(-1e-6, -1e-6, 1e-6, 1e-6), 0.0)
            .pressure(Range::rect(l - 1e-6, -1e-6, l + 1e-6, 1e-6), 0.0)
            .rate(Range::rect(0.5 - 1e-6, -1e-6, 0.5 + 1e-6, 1e-6), rate)
    };
    let steady = Simulation::builder(mesh.clone(), Backend::cpu(1).unwrap())
        .physics(hydro().steady_flow())
        .time_step(1.0)
        .build()
        .unwrap();
    assert!(
        steady.field_stages().is_empty(),
        "steady flow is never stepped"
    );
    let p = steady.field(FLOW_PRESSURE).unwrap();
    let p_mid = 0.5 * rate * 0.5 * l * 12.0 * fluid.dynamic_viscosity() / delta.powi(3);
    let set = steady.entity_set(FLOW_NODES).unwrap();
    let mut worst: f64 = 0.0;
    for (l_node, &pl) in p.iter().enumerate().take(set.len()) {
        let x = steady.mesh().node(set.entity(l_node)[0] as usize)[0];
        let exact = p_mid * (1.0 - (x - 0.5).abs() / 0.5);
        worst = worst.max((pl - exact).abs() / p_mid);
    }
    assert!(worst < 1e-10, "pressure error {worst}");
    let q = steady.field(CHANNEL_FLUX).unwrap();
    for c in q.chunks(2) {
        assert!((c[0].abs() - 0.5 * rate).abs() < 1e-9 * rate, "flux {c:?}");
    }
    let mut transient = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(hydro())
        .build()
        .unwrap();
    let mut last = transient.field(FLOW_PRESSURE).unwrap().to_vec();
    for _ in 0..2000 {
        transient.run(500).unwrap();
        let now = transient.field(FLOW_PRESSURE).unwrap();
        let change = now
            .iter()
            .zip(&last)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        last.copy_from_slice(now);
        if change < 1e-9 * p_mid {
            break;
        }
    }
    let gap = last
        .iter()
        .zip(p)
        .map(|(a, b)| (a - b).abs() / p_mid)
        .fold(0.0, f64::max);
    assert!(gap < 1e-5, "transient end vs steady: {gap}");
}

#[test]
fn steady_flow_refuses_what_would_make_it_transient_or_undetermined() {
    let mesh = split_nodes(
        &builders::rectangle(0.0, 0.0, 1.0, 0.2, 0.1).unwrap(),
        &Range::All,
    )
    .unwrap();
    let model = || FlowModel::new(Fluid::water(), Aperture::fixed(1e-4).unwrap());
    let left = Range::rect(-1e-6, -1e-6, 1e-6, 0.3);
    let build = |h: Hydro| {
        Simulation::builder(mesh.clone(), Backend::cpu(1).unwrap())
            .physics(h)
            .time_step(1.0)
            .build()
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    let e = build(
        Hydro::new(model())
            .steady_flow()
            .pressure(left.clone(), 1e5),
    );
    assert!(e.contains("FlowOnly"), "{e}");
    let e = build(
        Hydro::new(model())
            .coupling(Coupling::FlowOnly)
            .steady_flow()
            .rate(left.clone(), 1e-6),
    );
    assert!(e.contains("no pressure condition"), "{e}");
    let e = build(
        Hydro::new(model())
            .coupling(Coupling::FlowOnly)
            .steady_flow()
            .pressure(
                left.clone(),
                pcdc_compute::TimeValue::Table(
                    pcdc_compute::Table::new("p", &[(0.0, 0.0), (1.0, 1e5)]).unwrap(),
                ),
            ),
    );
    assert!(e.contains("constant"), "{e}");
    // Pumping out more than the held node can supply drives the pressure below zero.
    let e = build(
        Hydro::new(model())
            .coupling(Coupling::FlowOnly)
            .steady_flow()
            .pressure(left, 0.0)
            .rate(Range::rect(1.0 - 1e-6, -1e-6, 1.0 + 1e-6, 0.3), -1e-6),
    );
    assert!(e.contains("negative"), "{e}");
}
