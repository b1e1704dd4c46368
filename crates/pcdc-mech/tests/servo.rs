//! Servo-controlled walls in 3D: a true-triaxial test of an elastic cube. Two pairs of
//! servo walls hold σx and σy while the top platen shortens the cube along z; the
//! walls must hold their stresses within 1 % through the loading, and the cube's
//! response must match the closed form of a true-triaxial elastic test:
//! with σx, σy held, dσz / dεz = E and dεx / dεz = dεy / dεz = −ν.

use pcdc_compute::{Backend, Simulation};
use pcdc_mech::{Boundary, LinearElastic, Mechanics, ServoGains, StressServo};
use pcdc_mesh::{builders, Dim3, Mesh, Range};

const SIDE: f64 = 0.02;
const YOUNG: f64 = 30e9;
const POISSON: f64 = 0.25;
const DENSITY: f64 = 2700.0;
/// σx and σy held by the servos (Pa, compression positive): a true-triaxial state.
const SIGMA_X: f64 = 10e6;
const SIGMA_Y: f64 = 5e6;

/// One record window: mean strains (x, y, z) and the platen's mean stress (Pa).
type Row = ([f64; 3], f64);

fn face_nodes(mesh: &Mesh<Dim3>, group: &str) -> Vec<u32> {
    mesh.groups().nodes[group].clone()
}

fn mean(sim: &Simulation<Dim3>, nodes: &[u32], axis: usize) -> f64 {
    nodes
        .iter()
        .map(|&n| sim.state.u[3 * n as usize + axis])
        .sum::<f64>()
        / nodes.len() as f64
}

#[test]
fn true_triaxial_servo_walls_hold_two_stresses_and_match_the_closed_form() {
    let mesh = builders::cuboid([0.0; 3], [SIDE; 3], SIDE / 4.0).unwrap();
    let rock = LinearElastic::new(YOUNG, POISSON, DENSITY)
        .unwrap()
        .with_damping(1.0)
        .unwrap();
    let m = YOUNG * (1.0 - POISSON) / ((1.0 + POISSON) * (1.0 - 2.0 * POISSON));
    let z = (m * DENSITY).sqrt();
    // Response: about four P-wave transits of the cube.
    let tau = 4.0 * SIDE / (m / DENSITY).sqrt();
    let gains = ServoGains::for_specimen(m, SIDE, tau, z);
    let area = SIDE * SIDE;
    let servo = |g: &str, axis, inward, target| {
        StressServo::new(face_nodes(&mesh, g), axis, inward, area, target, gains, 1.0).unwrap()
    };
    let mut walls = [
        servo("xmin", 0, 1.0, SIGMA_X),
        servo("xmax", 0, -1.0, SIGMA_X),
        servo("ymin", 1, 1.0, SIGMA_Y),
        servo("ymax", 1, -1.0, SIGMA_Y),
        // The platen: servo-controlled to σy while consolidating, then driven.
        servo("zmax", 2, -1.0, SIGMA_Y),
    ];
    let boundary = Boundary::new()
        .velocity(Range::group("zmin"), [None, None, Some(0.0.into())])
        .velocity(
            Range::group("xmin"),
            [Some(walls[0].velocity()), None, None],
        )
        .velocity(
            Range::group("xmax"),
            [Some(walls[1].velocity()), None, None],
        )
        .velocity(
            Range::group("ymin"),
            [None, Some(walls[2].velocity()), None],
        )
        .velocity(
            Range::group("ymax"),
            [None, Some(walls[3].velocity()), None],
        )
        .velocity(
            Range::group("zmax"),
            [None, None, Some(walls[4].velocity())],
        );
    let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(boundary)
        .build()
        .unwrap();
    let dt = sim.dt();
    let window = ((0.25 * tau / dt).ceil() as u64).max(1);
    // Consolidation: every wall to its target within 0.1 % over a window.
    let mut acc = [0.0f64; 5];
    let mut count = 0u64;
    let mut consolidated = false;
    for _ in 0..(400.0 * tau / dt) as u64 {
        sim.run(1).unwrap();
        for (a, w) in acc.iter_mut().zip(walls.iter_mut()) {
            *a += w.update(&sim);
        }
        count += 1;
        if count == window {
            let ok = acc
                .iter()
                .zip(&walls)
                .all(|(a, w)| (a / count as f64 - w.target()).abs() <= 1e-3 * w.target());
            (acc, count) = ([0.0; 5], 0);
            if ok {
                consolidated = true;
                break;
            }
        }
    }
    assert!(consolidated, "the walls did not reach their stresses");
    let (zmax, zmin) = (
        face_nodes(sim.mesh(), "zmax"),
        face_nodes(sim.mesh(), "zmin"),
    );
    let (xmin, xmax) = (
        face_nodes(sim.mesh(), "xmin"),
        face_nodes(sim.mesh(), "xmax"),
    );
    let (ymin, ymax) = (
        face_nodes(sim.mesh(), "ymin"),
        face_nodes(sim.mesh(), "ymax"),
    );
    let strains = |sim: &Simulation<Dim3>| {
        [
            (mean(sim, &xmax, 0) - mean(sim, &xmin, 0)) / SIDE,
            (mean(sim, &ymax, 1) - mean(sim, &ymin, 1)) / SIDE,
            (mean(sim, &zmax, 2) - mean(sim, &zmin, 2)) / SIDE,
        ]
    };
    // Loading: the platen shortens the cube at a strain rate of 2/s, ramped over 8 τ;
    // the side walls keep σx, σy with a feed-forward of the elastic expansion
    // ν ε̇ L / 2 per wall (the PI corrects the estimate).
    let rate = 2.0;
    let ramp = 8.0 * tau;
    let start = sim.state.time;
    let e0 = strains(&sim)[2];
    // Per window: mean strains and mean platen stress.
    let mut rows: Vec<Row> = Vec::new();
    let (mut worst, mut acc, mut strain_acc, mut count) =
        ([0.0f64; 4], [0.0f64; 5], [0.0f64; 3], 0u64);
    while strains(&sim)[2] - e0 > -1e-3 {
        let ramped = ((sim.state.time - start) / ramp).min(1.0);
        walls[4].drive(rate * ramped * SIDE);
        for w in &mut walls[..4] {
            w.set_feed_forward(-POISSON * rate * ramped * 0.5 * SIDE);
        }
        sim.run(1).unwrap();
        for (k, w) in walls[..4].iter_mut().enumerate() {
            acc[k] += w.update(&sim);
        }
        acc[4] += walls[4].stress(&sim);
        for (a, e) in strain_acc.iter_mut().zip(strains(&sim)) {
            *a += e;
        }
        count += 1;
        if count == window {
            for k in 0..4 {
                let mean = acc[k] / count as f64;
                let dev = (mean - walls[k].target()).abs() / walls[k].target();
                worst[k] = worst[k].max(dev);
            }
            if sim.state.time - start > 2.0 * ramp {
                rows.push((strain_acc.map(|a| a / count as f64), acc[4] / count as f64));
            }
            (acc, strain_acc, count) = ([0.0; 5], [0.0; 3], 0);
        }
        assert!(sim.state.time - start < 0.01, "the loading did not finish");
    }
    eprintln!(
        "largest deviations over windows of {window} steps: xmin {:.3} %, xmax {:.3} %, ymin {:.3} %, ymax {:.3} %",
        100.0 * worst[0],
        100.0 * worst[1],
        100.0 * worst[2],
        100.0 * worst[3]
    );
    for (k, d) in worst.iter().enumerate() {
        assert!(*d <= 0.01, "wall {k} off by {:.3} %", 100.0 * d);
    }
    // Closed form: least-squares slopes against εz over the loading after the ramp
    // (compression shortens: εz falls, σz rises).
    assert!(rows.len() >= 10, "{} windows", rows.len());
    let slope = |y: &dyn Fn(&Row) -> f64| {
        let n = rows.len() as f64;
        let mx = rows.iter().map(|r| r.0[2]).sum::<f64>() / n;
        let my = rows.iter().map(y).sum::<f64>() / n;
        let sxy: f64 = rows.iter().map(|r| (r.0[2] - mx) * (y(r) - my)).sum();
        let sxx: f64 = rows.iter().map(|r| (r.0[2] - mx).powi(2)).sum();
        sxy / sxx
    };
    let young = -slope(&|r| r.1);
    let (nux, nuy) = (-slope(&|r| r.0[0]), -slope(&|r| r.0[1]));
    eprintln!("E = {young:.4e} Pa, nu_x = {nux:.4}, nu_y = {nuy:.4}");
    assert!((young - YOUNG).abs() <= 0.01 * YOUNG, "E = {young}");
    assert!((nux - POISSON).abs() <= 0.01 * POISSON, "nu_x = {nux}");
    assert!((nuy - POISSON).abs() <= 0.01 * POISSON, "nu_y = {nuy}");
}
