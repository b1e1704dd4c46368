//! The bolts on the GPU against the CPU (f64, to 1e-12): a 2D block hanging from a
//! pretensioned, plated bolt pulled at its head, with yield, bond slip and damping, and
//! a 3D block with an inclined bolt (the confinement reads the host's rotation); every
//! WGSL module validates with naga, in f64 and f32.

use pcdc_bolt::{Bolt, BoltMaterial, BoltNodes, BoltProperties, Bolts};
use pcdc_bolt::{BOLT_AXIAL_FORCE, BOLT_GROUT_FORCE, BOLT_SLIP, BOLT_STATE};
use pcdc_compute::gpu::{gpu_test_backend, offline_kernel_sources, validate_wgsl};
use pcdc_compute::{Backend, Physics, Precision, Simulation, Table};
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim, Dim2, Dim3, Mesh, Range};

fn props() -> BoltProperties {
    BoltProperties {
        // Weak enough that the bolt yields and the grout slips within the run.
        tensile_yield_force: 3e3,
        cohesion_rock_grout: 1e5,
        pretension: 1e3,
        damping_factor: 0.3,
        ..BoltProperties::steel_rebar(0.02)
    }
}

fn physics<D: Dim>(head: [f64; 3], tail: [f64; 3], pull: [f64; 3]) -> Vec<Box<dyn Physics<D>>> {
    let bolt = Bolt::straight("B", head, tail, 9, BoltMaterial::new(props()).unwrap())
        .unwrap()
        .free_length(0.2)
        .unwrap()
        .face_plate(1e8)
        .unwrap();
    let bolts = Bolts::new().bolt(bolt).unwrap();
    let v = |x: f64| {
        Some(pcdc_compute::TimeValue::Table(
            Table::new("v", &[(0.0, 0.0), (1e-3, x)]).unwrap(),
        ))
    };
    let bc = bolts
        .boundary()
        .velocity(
            "B",
            BoltNodes::Head,
            [
                v(pull[0]),
                v(pull[1]),
                if D::D == 3 { v(pull[2]) } else { None },
            ],
        )
        .unwrap()
        .force(
            "B",
            BoltNodes::Node(4),
            [Some(100.0.into()), Some((-50.0).into()), None],
        )
        .unwrap()
        .acceleration("B", BoltNodes::Node(6), [None, Some(2.0.into()), None])
        .unwrap();
    let rock = LinearElastic::new(10e9, 0.25, 2500.0).unwrap();
    vec![
        Box::new(Mechanics::new().material(Range::All, rock)),
        Box::new(Boundary::new().fix(Range::group(if D::D == 2 { "bottom" } else { "zmin" }))),
        Box::new(bolts),
        Box::new(bc),
    ]
}

fn run<D: Dim>(
    mesh: &Mesh<D>,
    backend: Backend,
    p: Vec<Box<dyn Physics<D>>>,
    steps: u64,
) -> Simulation<D> {
    let mut b = Simulation::builder(mesh.clone(), backend).gravity([0.0, -9.81, 0.0]);
    for x in p {
        b = b.boxed_physics(x);
    }
    let mut sim = b.build().unwrap();
    sim.run(steps).unwrap();
    sim
}

fn compare<D: Dim>(c: &Simulation<D>, g: &Simulation<D>, what: &str) {
    let close = |a: &[f64], b: &[f64], name: &str, tol: f64| {
        let scale = a.iter().map(|x| x.abs()).fold(0.0, f64::max).max(1e-300);
        let worst = a
            .iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        eprintln!("{what} {name}: largest difference {:e} of {scale:e}", worst);
        for (i, (x, y)) in a.iter().zip(b).enumerate() {
            assert!(
                (x - y).abs() <= tol * scale,
                "{what} {name}[{i}]: cpu {x} gpu {y} (scale {scale})"
            );
        }
    };
    close(&c.state.u, &g.state.u, "u", 1e-12);
    close(&c.state.v, &g.state.v, "v", 1e-12);
    for f in [BOLT_AXIAL_FORCE, BOLT_GROUT_FORCE, BOLT_SLIP, BOLT_STATE] {
        close(c.field(f).unwrap(), g.field(f).unwrap(), f.name(), 1e-12);
    }
}

fn meshes() -> (Mesh<Dim2>, Mesh<Dim3>) {
    (
        builders::rectangle(0.0, 0.0, 1.0, 0.6, 0.1).unwrap(),
        builders::cuboid([0.0; 3], [0.6, 0.6, 1.0], 0.2).unwrap(),
    )
}

#[test]
fn bolts_on_the_gpu_match_the_cpu_2d_and_3d() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let (m2, m3) = meshes();
    let (h2, t2, p2) = ([0.0, 0.31, 0.0], [0.83, 0.17, 0.0], [-5.0, 1.25, 0.0]);
    let c = run(
        &m2,
        Backend::cpu(1).unwrap(),
        physics::<Dim2>(h2, t2, p2),
        400,
    );
    let g = run(&m2, gpu.clone(), physics::<Dim2>(h2, t2, p2), 400);
    // The run reaches what it is meant to test.
    let state = c.field(BOLT_STATE).unwrap();
    assert!(state.contains(&1.0), "a segment yields: {state:?}");
    assert!(
        c.field(BOLT_SLIP).unwrap().iter().any(|s| *s != 0.0),
        "the grout slips"
    );
    compare(&c, &g, "2D");
    let (h3, t3, p3) = ([0.27, 0.33, 1.0], [0.35, 0.21, 0.15], [0.2, -0.3, 2.0]);
    let c = run(
        &m3,
        Backend::cpu(1).unwrap(),
        physics::<Dim3>(h3, t3, p3),
        300,
    );
    let g = run(&m3, gpu, physics::<Dim3>(h3, t3, p3), 300);
    compare(&c, &g, "3D");
}

#[test]
fn bolt_wgsl_validates_with_naga() {
    let (m2, m3) = meshes();
    for p in [Precision::F64, Precision::F32] {
        let mut all = offline_kernel_sources::<Dim2>(
            &m2,
            physics([0.0, 0.31, 0.0], [0.83, 0.17, 0.0], [0.1, 0.0, 0.0]),
            p,
        )
        .unwrap();
        all.extend(
            offline_kernel_sources::<Dim3>(
                &m3,
                physics([0.27, 0.33, 1.0], [0.35, 0.21, 0.15], [0.0, 0.0, 0.1]),
                p,
            )
            .unwrap(),
        );
        let bolt: Vec<_> = all.iter().filter(|(l, _)| l.starts_with("bolt")).collect();
        // Segments, nodes, hosts, and three conditions, in 2D and 3D.
        assert_eq!(
            bolt.len(),
            12,
            "{:?}",
            bolt.iter().map(|b| &b.0).collect::<Vec<_>>()
        );
        for (label, src) in bolt {
            if let Err(e) = validate_wgsl(src) {
                panic!("{label} ({}) does not validate:\n{e}", p.name());
            }
        }
    }
}
