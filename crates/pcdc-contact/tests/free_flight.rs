//! Hard case: fragments in free flight. Nine small blocks are thrown at each other with
//! random velocities and spins of up to 300 rad/s (several full turns in the run),
//! with a normal penalty of 100 E and no damping. Nothing blows up, momentum is kept
//! to rounding, energy does not grow, and no node sinks deeper than 1 % of the element
//! size into another fragment at any sampled time.

use pcdc_compute::{Backend, Simulation};
use pcdc_contact::Contact;
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim2, Range};

const E: f64 = 1e8;
const H: f64 = 0.01;

fn noise(i: usize) -> f64 {
    let x = (i as u64 + 7).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let x = (x ^ (x >> 29)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    ((x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// Depth of point `p` inside the fragment made of `tris` with boundary `edges` (0 when
/// outside): the distance to the nearest boundary edge.
fn depth(p: [f64; 2], tris: &[[[f64; 2]; 3]], edges: &[[[f64; 2]; 2]]) -> f64 {
    let inside = tris.iter().any(|t| {
        let s = |a: [f64; 2], b: [f64; 2]| {
            (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
        };
        let (d0, d1, d2) = (s(t[0], t[1]), s(t[1], t[2]), s(t[2], t[0]));
        (d0 > 0.0 && d1 > 0.0 && d2 > 0.0) || (d0 < 0.0 && d1 < 0.0 && d2 < 0.0)
    });
    if !inside {
        return 0.0;
    }
    edges
        .iter()
        .map(|[a, b]| {
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let t =
                (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
            ((p[0] - a[0] - t * dx).powi(2) + (p[1] - a[1] - t * dy).powi(2)).sqrt()
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn spinning_fragments_stay_stable_and_apart() {
    // A 3 x 3 grid of 0.03 m blocks, 5 mm apart.
    let mut blocks = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            let (x0, y0) = (0.035 * i as f64, 0.035 * j as f64);
            blocks.push(builders::rectangle(x0, y0, 0.03, 0.03, H).unwrap());
        }
    }
    let (mesh, bodies) = builders::union(&blocks.iter().collect::<Vec<_>>()).unwrap();
    let rock = LinearElastic::new(E, 0.25, 1000.0).unwrap();
    let mut sim = Simulation::builder(mesh, Backend::cpu(2).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(Contact::new(100.0 * E))
        .build()
        .unwrap();
    let body_of: Vec<usize> = {
        let mut b = vec![0; sim.mesh().n_nodes()];
        for (k, nodes) in bodies.iter().enumerate() {
            for &n in nodes {
                b[n as usize] = k;
            }
        }
        b
    };
    let x0 = sim.mesh().coords().to_vec();
    for (k, nodes) in bodies.iter().enumerate() {
        let c = nodes.iter().fold([0.0; 2], |c, &n| {
            [c[0] + x0[2 * n as usize], c[1] + x0[2 * n as usize + 1]]
        });
        let c = [c[0] / nodes.len() as f64, c[1] / nodes.len() as f64];
        // Towards the centre of the grid plus noise, and a spin.
        let v = [
            -20.0 * (c[0] - 0.05) + 1.5 * noise(3 * k),
            -20.0 * (c[1] - 0.05) + 1.5 * noise(3 * k + 1),
        ];
        let w = 300.0 * noise(3 * k + 2);
        for &n in nodes {
            let n = n as usize;
            let (rx, ry) = (x0[2 * n] - c[0], x0[2 * n + 1] - c[1]);
            sim.state.v[2 * n] = v[0] - w * ry;
            sim.state.v[2 * n + 1] = v[1] + w * rx;
        }
    }
    let momentum = |s: &Simulation<Dim2>| {
        s.state
            .v
            .chunks_exact(2)
            .zip(s.mass())
            .fold([0.0; 2], |p, (v, m)| [p[0] + m * v[0], p[1] + m * v[1]])
    };
    let p0 = momentum(&sim);
    let e0 = sim.kinetic_energy() + sim.stored_energy();
    let scale: f64 = sim.mass().iter().sum::<f64>() * 3.0;
    let mut worst = 0.0f64;
    for _ in 0..40 {
        sim.run(1000).unwrap();
        // Interpenetration: every node against every other fragment.
        let x = sim.positions();
        let conn = sim.mesh().elements().to_vec();
        let mut tris: Vec<Vec<[[f64; 2]; 3]>> = vec![Vec::new(); bodies.len()];
        for t in conn.chunks_exact(3) {
            let p = |n: u32| [x[2 * n as usize], x[2 * n as usize + 1]];
            tris[body_of[t[0] as usize]].push([p(t[0]), p(t[1]), p(t[2])]);
        }
        let mut edges: Vec<Vec<[[f64; 2]; 2]>> = vec![Vec::new(); bodies.len()];
        for f in sim.mesh().select_boundary_faces(&Range::All).unwrap() {
            let nn = sim.mesh().face(f as usize);
            let p = |n: u32| [x[2 * n as usize], x[2 * n as usize + 1]];
            edges[body_of[nn[0] as usize]].push([p(nn[0]), p(nn[1])]);
        }
        for n in 0..sim.mesh().n_nodes() {
            for b in 0..bodies.len() {
                if b != body_of[n] {
                    worst = worst.max(depth([x[2 * n], x[2 * n + 1]], &tris[b], &edges[b]));
                }
            }
        }
    }
    let p1 = momentum(&sim);
    let e1 = sim.kinetic_energy() + sim.stored_energy();
    eprintln!(
        "t = {:.1} ms: energy {e0:.4e} -> {e1:.4e} J ({:+.2} %), momentum drift {:.1e}, deepest node {:.2e} m ({:.2} % of h)",
        1e3 * sim.state.time,
        100.0 * (e1 - e0) / e0,
        ((p1[0] - p0[0]).abs() + (p1[1] - p0[1]).abs()) / scale,
        worst,
        100.0 * worst / H
    );
    assert!((p1[0] - p0[0]).abs() <= 1e-10 * scale && (p1[1] - p0[1]).abs() <= 1e-10 * scale);
    assert!(e1 <= 1.02 * e0, "energy grew: {e0} -> {e1}");
    assert!(
        worst <= 0.01 * H,
        "a node sank {worst} m into another fragment"
    );
}
