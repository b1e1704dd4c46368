//! Re-locating bolt nodes: a bolt pulled several element lengths out of a fixed block
//! slides through the rock; each node is re-found in the element it has reached, its
//! grout force and slip go on unchanged (the plateau at the bond strength holds), action
//! equals reaction; the GPU re-locates as the CPU does (f64, to 1e-12), in 2D and 3D.

use pcdc_bolt::{barycentric, Bolt, BoltMaterial, BoltNodes, BoltProperties, Bolts};
use pcdc_bolt::{BOLT_ANCHOR, BOLT_GROUT_FORCE, BOLT_HOST, BOLT_SLIP};
use pcdc_compute::gpu::gpu_test_backend;
use pcdc_compute::{Backend, Precision, Simulation, Table, TimeValue};
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim, Dim2, Dim3, Mesh, Range};

/// A weakly grouted rebar (no friction: the bond does not depend on the confinement).
fn material() -> BoltMaterial {
    BoltMaterial::new(BoltProperties {
        friction_rock_grout: 0.0,
        friction_grout_bolt: 0.0,
        cohesion_rock_grout: 0.2e6,
        // Damps the bar's waves (on the segments' relative axial velocity: a sliding bolt
        // is not braked), so that the pull is close to quasi-static.
        damping_factor: 0.5,
        ..BoltProperties::steel_rebar(0.025)
    })
    .unwrap()
}

/// A block held fixed with a bolt from `head` to `tail` in `segments`, its head pulled
/// out along the bolt at `speed` (m/s, reached after 1 ms); with `hold_y` every bolt
/// node is held at y velocity 0; with `fixed` the hosts are kept.
fn scene<D: Dim>(
    mesh: Mesh<D>,
    backend: Backend,
    (head, tail): ([f64; 3], [f64; 3]),
    segments: usize,
    speed: f64,
    hold_y: bool,
    fixed: bool,
) -> Simulation<D> {
    let bolt = Bolt::straight("B", head, tail, segments, material()).unwrap();
    let mut bolts = Bolts::new().bolt(bolt).unwrap();
    if fixed {
        bolts = bolts.fixed_hosts();
    }
    let len: f64 = (0..3)
        .map(|k| (tail[k] - head[k]).powi(2))
        .sum::<f64>()
        .sqrt();
    let v = |k: usize| {
        (k < D::D).then(|| {
            let x = speed * (head[k] - tail[k]) / len;
            TimeValue::Table(Table::new("pull", &[(0.0, 0.0), (1e-3, x)]).unwrap())
        })
    };
    let mut pull = bolts
        .boundary()
        .velocity("B", BoltNodes::Head, [v(0), v(1), v(2)])
        .unwrap();
    if hold_y {
        pull = pull
            .velocity("B", BoltNodes::All, [None, Some(0.0.into()), None])
            .unwrap();
    }
    Simulation::builder(mesh, backend)
        .physics(
            Mechanics::new().material(Range::All, LinearElastic::new(30e9, 0.25, 2700.0).unwrap()),
        )
        .physics(Boundary::new().fix(Range::All))
        .physics(bolts)
        .physics(pull)
        .local_damping(0.3)
        .build()
        .unwrap()
}

/// The smallest barycentric weight of bolt node `i` (simulation node `node`) in its
/// current host, at the current positions.
fn weight_in_host<D: Dim>(sim: &Simulation<D>, i: usize, node: usize) -> f64 {
    let d = D::D;
    let kin = sim.kinematics();
    let e = sim.field(BOLT_HOST).unwrap()[i] as usize;
    let mut x = vec![0.0; (d + 1) * d];
    for (q, &n) in sim.mesh().element(e).iter().enumerate() {
        x[q * d..q * d + d].copy_from_slice(&kin.position(n as usize)[..d]);
    }
    let w = barycentric(d, &x, &kin.position(node)[..d]);
    w[..=d].iter().cloned().fold(f64::INFINITY, f64::min)
}

#[test]
fn a_bolt_pulled_through_the_rock_is_re_found_where_it_is() {
    // 2D, elements 5 cm across; the bolt, off the mesh lines, slides 15 cm (three
    // elements) out. Held laterally: a bolt dragged at its bond strength over such a
    // distance can start to flutter sideways (the grout force follows the bolt's axis;
    // seen with and without re-location), which this test is not about.
    let mesh = builders::rectangle(0.0, 0.0, 1.3, 0.4, 0.05).unwrap();
    let ends = ([0.3, 0.2137, 0.0], [1.2, 0.2137, 0.0]);
    let mut sim = scene(mesh, Backend::cpu(1).unwrap(), ends, 9, 2.0, true, false);
    let hosts0 = sim.field(BOLT_HOST).unwrap().to_vec();
    let first = sim.mesh().n_nodes();
    let n = hosts0.len();
    let capacity = material().bond_strength(0.0) * 0.9;
    while sim.kinematics().time < 0.076 {
        sim.run(200).unwrap();
        // Once every node slides the grout carries the bond strength along the whole
        // bolt, through every change of host.
        if sim.kinematics().time > 0.02 {
            let total: f64 = sim.field(BOLT_GROUT_FORCE).unwrap().iter().sum();
            assert!(
                ((-total - capacity) / capacity).abs() < 1e-9,
                "t = {}: {total} vs {capacity}",
                sim.kinematics().time
            );
        }
    }
    let hosts = sim.field(BOLT_HOST).unwrap();
    let moved = (0..n).filter(|&i| hosts[i] != hosts0[i]).count();
    assert!(moved == n, "{moved} of {n} nodes changed host");
    for i in 0..n {
        let w = weight_in_host(&sim, i, first + i);
        assert!(w >= -0.05, "node {i} lies outside its host: weight {w}");
    }
    // Action equals reaction through the re-located hosts.
    let f = sim.evaluate_forces().unwrap().to_vec();
    let scale = f.iter().map(|v| v.abs()).fold(0.0, f64::max);
    let (fx, fy) = f
        .chunks(2)
        .fold((0.0, 0.0), |(a, b), c| (a + c[0], b + c[1]));
    assert!(
        fx.abs() <= 1e-9 * scale && fy.abs() <= 1e-9 * scale,
        "{fx} {fy} of {scale}"
    );
    // The slip is the node's whole displacement along the bolt less the grout's elastic
    // part, across the re-locations (the rock is fixed): slip = u_x − f / (K_b,r,s l), with the
    // grout evaluated just now at these displacements.
    let kin = sim.kinematics();
    let (slip, grout) = (
        sim.field(BOLT_SLIP).unwrap(),
        sim.field(BOLT_GROUT_FORCE).unwrap(),
    );
    let k = material().properties().shear_stiffness;
    for i in 0..n {
        let l = if i == 0 || i == n - 1 { 0.05 } else { 0.1 };
        let ux = kin.u[(first + i) * 2];
        let expect = ux - grout[i] / (k * l);
        assert!(
            (slip[i] - expect).abs() < 1e-9 * ux.abs(),
            "node {i}: slip {} vs {expect}",
            slip[i]
        );
        assert!(ux < -0.14, "node {i} slid {ux} m");
    }
}

#[test]
fn fixed_hosts_stay_where_they_were_found() {
    // The same pull with re-location off: every node keeps its reference host (and
    // lies far outside it at the end), the grout still carries the bond strength.
    let mesh = builders::rectangle(0.0, 0.0, 1.3, 0.4, 0.05).unwrap();
    let ends = ([0.3, 0.2137, 0.0], [1.2, 0.2137, 0.0]);
    let mut sim = scene(mesh, Backend::cpu(1).unwrap(), ends, 9, 2.0, true, true);
    let hosts0 = sim.field(BOLT_HOST).unwrap().to_vec();
    sim.run_until(0.076).unwrap();
    assert_eq!(sim.field(BOLT_HOST).unwrap(), &hosts0[..]);
    let first = sim.mesh().n_nodes();
    assert!(weight_in_host(&sim, 5, first + 5) < -1.0);
    let total: f64 = sim.field(BOLT_GROUT_FORCE).unwrap().iter().sum();
    let capacity = material().bond_strength(0.0) * 0.9;
    assert!(((-total - capacity) / capacity).abs() < 1e-9, "{total}");
}

#[test]
fn forged_grout_points_are_refused_on_restore() {
    let mesh = builders::rectangle(0.0, 0.0, 1.3, 0.4, 0.05).unwrap();
    let ends = ([0.3, 0.213, 0.0], [1.2, 0.171, 0.0]);
    let mut sim = scene(mesh, Backend::cpu(1).unwrap(), ends, 9, 5.0, false, false);
    sim.run(10).unwrap();
    let good = sim.snapshot_bytes().unwrap();
    // Forged with a valid checksum: written from a simulation whose field was edited.
    for (value, at) in [(1e6, 0), (0.5, 0), (f64::NAN, 1), (-1.0, 2 * 2 + 2)] {
        let mut other = scene(
            builders::rectangle(0.0, 0.0, 1.3, 0.4, 0.05).unwrap(),
            Backend::cpu(1).unwrap(),
            ends,
            9,
            5.0,
            false,
            false,
        );
        other.restore_bytes(&good).unwrap();
        let id = other.state.fields.id(BOLT_ANCHOR).unwrap();
        other.state.fields.get_mut(id)[at] = value;
        let forged = other.snapshot_bytes().unwrap();
        let err = sim.restore_bytes(&forged).unwrap_err().to_string();
        assert!(err.contains("bolt node 0"), "{value} at {at}: {err}");
    }
    sim.restore_bytes(&good).unwrap();
}

fn compare<D: Dim>(c: &Simulation<D>, g: &Simulation<D>, what: &str) {
    let close = |a: &[f64], b: &[f64], name: &str| {
        let scale = a.iter().map(|x| x.abs()).fold(0.0, f64::max).max(1e-300);
        let worst = a
            .iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        eprintln!("{what} {name}: largest difference {worst:e} of {scale:e}");
        assert!(worst <= 1e-12 * scale, "{what} {name}: {worst} of {scale}");
    };
    close(&c.state.u, &g.state.u, "u");
    for f in [BOLT_GROUT_FORCE, BOLT_SLIP, BOLT_ANCHOR] {
        close(c.field(f).unwrap(), g.field(f).unwrap(), f.name());
    }
    assert_eq!(c.field(BOLT_HOST).unwrap(), g.field(BOLT_HOST).unwrap());
}

#[test]
fn the_gpu_re_locates_as_the_cpu_2d_and_3d() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let m2: Mesh<Dim2> = builders::rectangle(0.0, 0.0, 1.0, 0.3, 0.1).unwrap();
    let e2 = ([0.3, 0.163, 0.0], [0.9, 0.121, 0.0]);
    gpu_against_cpu(&m2, &gpu, e2, 6, 20.0, false, "2D");
    gpu_against_cpu(&m2, &gpu, e2, 6, 20.0, true, "2D, fixed hosts");
    let m3: Mesh<Dim3> = builders::cuboid([0.0; 3], [0.6, 0.6, 1.0], 0.2).unwrap();
    let e3 = ([0.27, 0.33, 0.9], [0.35, 0.21, 0.15]);
    gpu_against_cpu(&m3, &gpu, e3, 5, 40.0, false, "3D");
}

/// The pull of [`scene`] for 1 500 steps on the CPU and on `gpu`: some node changes host
/// (none with `fixed` hosts), and both backends agree ([`compare`]).
fn gpu_against_cpu<D: Dim>(
    mesh: &Mesh<D>,
    gpu: &Backend,
    ends: ([f64; 3], [f64; 3]),
    segments: usize,
    speed: f64,
    fixed: bool,
    what: &str,
) {
    let build = |b: Backend| scene(mesh.clone(), b, ends, segments, speed, false, fixed);
    let hosts0 = build(Backend::cpu(1).unwrap())
        .field(BOLT_HOST)
        .unwrap()
        .to_vec();
    let run = |b: Backend| {
        let mut s = build(b);
        s.run(1500).unwrap();
        s
    };
    let (c, g) = (run(Backend::cpu(1).unwrap()), run(gpu.clone()));
    let moved = c.field(BOLT_HOST).unwrap() != &hosts0[..];
    assert_eq!(moved, !fixed, "{what}: nodes re-located");
    compare(&c, &g, what);
}

/// The pull of the first test seen from the bolt: the rock moves at 2 m/s along the
/// bolt, the bolt's head held. The hosts are found from current positions, so the rock
/// sliding past a held bolt re-locates its nodes as the bolt sliding through held rock
/// does: the same hosts, grout forces and slips.
#[test]
fn rock_moving_past_a_held_bolt_re_locates_it_as_a_bolt_pulled_through_rock() {
    let mesh = builders::rectangle(0.0, 0.0, 1.3, 0.4, 0.05).unwrap();
    let ends = ([0.3, 0.2137, 0.0], [1.2, 0.2137, 0.0]);
    let ramp = |v: f64| TimeValue::Table(Table::new("ramp", &[(0.0, 0.0), (1e-3, v)]).unwrap());
    let mut pulled = scene(
        mesh.clone(),
        Backend::cpu(1).unwrap(),
        ends,
        9,
        2.0,
        true,
        false,
    );
    let bolts = Bolts::new()
        .bolt(Bolt::straight("B", ends.0, ends.1, 9, material()).unwrap())
        .unwrap();
    let held = bolts
        .boundary()
        .velocity("B", BoltNodes::Head, [Some(0.0.into()), None, None])
        .unwrap()
        .velocity("B", BoltNodes::All, [None, Some(0.0.into()), None])
        .unwrap();
    let mut moving = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(
            Mechanics::new().material(Range::All, LinearElastic::new(30e9, 0.25, 2700.0).unwrap()),
        )
        .physics(Boundary::new().velocity(Range::All, [Some(ramp(2.0)), Some(0.0.into()), None]))
        .physics(bolts)
        .physics(held)
        .local_damping(0.3)
        .build()
        .unwrap();
    assert_eq!(pulled.dt(), moving.dt());
    pulled.run(19_000).unwrap();
    moving.run(19_000).unwrap();
    let hosts = moving.field(BOLT_HOST).unwrap();
    assert_eq!(pulled.field(BOLT_HOST).unwrap(), hosts);
    let first = moving.mesh().n_nodes();
    for i in 0..hosts.len() {
        let w = weight_in_host(&moving, i, first + i);
        assert!(w >= -0.05, "node {i} lies outside its host: weight {w}");
    }
    for f in [BOLT_GROUT_FORCE, BOLT_SLIP] {
        let (a, b) = (pulled.field(f).unwrap(), moving.field(f).unwrap());
        let scale = a.iter().map(|x| x.abs()).fold(0.0, f64::max);
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-9 * scale, "{f}: {x} vs {y}");
        }
    }
    // It slid: every node changed host.
    let slip = moving.field(BOLT_SLIP).unwrap();
    assert!(slip.iter().all(|s| *s < -0.13), "{slip:?}");
}

/// An inclined bolt, free to move sideways, dragged three elements at its bond strength:
/// with the grout's lateral damping (D_b,f = 0.5) it stays on the plateau all the way
/// (without it the nodes began to swing sideways after 6 000 to 12 000 steps and the
/// grout forces changed sign: a follower force's flutter, see the crate docs).
#[test]
fn an_inclined_bolt_dragged_at_its_bond_strength_does_not_flutter() {
    let mesh = builders::rectangle(0.0, 0.0, 1.3, 0.4, 0.05).unwrap();
    let ends = ([0.3, 0.213, 0.0], [1.2, 0.171, 0.0]);
    let mut sim = scene(mesh, Backend::cpu(1).unwrap(), ends, 9, 2.0, false, false);
    let length = (0.9f64 * 0.9 + 0.042 * 0.042).sqrt();
    let capacity = material().bond_strength(0.0) * length;
    let first = sim.mesh().n_nodes();
    let mut swing: f64 = 0.0;
    while sim.kinematics().time < 0.076 {
        sim.run(200).unwrap();
        if sim.kinematics().time > 0.02 {
            let total: f64 = sim.field(BOLT_GROUT_FORCE).unwrap().iter().sum();
            assert!(
                ((-total - capacity) / capacity).abs() < 1e-9,
                "t = {}: {total} vs {capacity}",
                sim.kinematics().time
            );
        }
        // Sideways displacement of each node off the bolt's line.
        let (a, b) = (ends.0, ends.1);
        let (ex, ey) = ((b[0] - a[0]) / length, (b[1] - a[1]) / length);
        for i in 0..10 {
            let u = &sim.kinematics().u[(first + i) * 2..(first + i) * 2 + 2];
            swing = swing.max((-ey * u[0] + ex * u[1]).abs());
        }
    }
    assert!(swing < 1e-4, "sideways {swing} m");
    let slip = sim.field(BOLT_SLIP).unwrap();
    assert!(slip.iter().all(|s| *s < -0.13), "{slip:?}");
}

/// The first test's pull on an unstructured mesh (a disc of rings of triangles), in SI
/// and in millimetre–newton–second–tonne units: every node is re-found inside its host
/// in both, the hosts are the same, and the grout forces and slips agree after
/// conversion (re-location uses barycentric weights and element heights only, so no
/// unit and no mesh pattern is built in).
#[test]
fn re_location_is_the_same_on_an_unstructured_mesh_in_any_units() {
    // l: length unit (m), s: stress unit (Pa), m: mass unit (kg); force unit s l².
    let run = |l: f64, s: f64, m: f64| {
        let f = s * l * l;
        let mesh = builders::disc([0.7 / l, 0.2 / l], 0.6 / l, 0.05 / l).unwrap();
        let p = BoltProperties::steel_rebar(0.025);
        let props = BoltProperties {
            density: p.density / (m / (l * l * l)),
            young: p.young / s,
            diameter: p.diameter / l,
            tensile_yield_force: p.tensile_yield_force / f,
            compressive_yield_force: p.compressive_yield_force / f,
            shear_stiffness: p.shear_stiffness / s,
            grout_thickness: p.grout_thickness / l,
            cohesion_rock_grout: 0.2e6 / s,
            cohesion_grout_bolt: p.cohesion_grout_bolt / s,
            friction_rock_grout: 0.0,
            friction_grout_bolt: 0.0,
            damping_factor: 0.5,
            // One bolt per metre of thickness (the default is one per length unit).
            spacing: Some(1.0 / l),
            ..p
        };
        let (head, tail) = ([0.3 / l, 0.2137 / l, 0.0], [1.2 / l, 0.2137 / l, 0.0]);
        let bolts = Bolts::new()
            .bolt(Bolt::straight("B", head, tail, 9, BoltMaterial::new(props).unwrap()).unwrap())
            .unwrap();
        let ramp = TimeValue::Table(Table::new("pull", &[(0.0, 0.0), (1e-3, -2.0 / l)]).unwrap());
        let pull = bolts
            .boundary()
            .velocity("B", BoltNodes::Head, [Some(ramp), None, None])
            .unwrap()
            .velocity("B", BoltNodes::All, [None, Some(0.0.into()), None])
            .unwrap();
        let rock = LinearElastic::new(30e9 / s, 0.25, 2700.0 / (m / (l * l * l))).unwrap();
        let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
            .physics(Mechanics::new().material(Range::All, rock))
            .physics(Boundary::new().fix(Range::All))
            .physics(bolts)
            .physics(pull)
            .local_damping(0.3)
            .build()
            .unwrap();
        let hosts0 = sim.field(BOLT_HOST).unwrap().to_vec();
        sim.run_until(0.076).unwrap();
        let first = sim.mesh().n_nodes();
        for i in 0..hosts0.len() {
            let w = weight_in_host(&sim, i, first + i);
            assert!(w >= -0.05, "node {i} lies outside its host: weight {w}");
        }
        let hosts = sim.field(BOLT_HOST).unwrap().to_vec();
        assert!(hosts.iter().zip(&hosts0).all(|(a, b)| a != b), "{hosts:?}");
        let per_m = f / l;
        let grout: Vec<f64> = sim
            .field(BOLT_GROUT_FORCE)
            .unwrap()
            .iter()
            .map(|g| g * per_m)
            .collect();
        let slip: Vec<f64> = sim
            .field(BOLT_SLIP)
            .unwrap()
            .iter()
            .map(|x| x * l)
            .collect();
        (hosts, grout, slip)
    };
    let si = run(1.0, 1.0, 1.0);
    let mm = run(1e-3, 1e6, 1e3);
    assert_eq!(si.0, mm.0, "hosts");
    for (what, a, b) in [("grout force", &si.1, &mm.1), ("slip", &si.2, &mm.2)] {
        let scale = a.iter().map(|v| v.abs()).fold(0.0, f64::max);
        let worst = a
            .iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        assert!(worst <= 1e-9 * scale, "{what}: {worst} of {scale}");
    }
    assert!(si.2.iter().all(|s| *s < -0.13), "slid: {:?}", si.2);
}
