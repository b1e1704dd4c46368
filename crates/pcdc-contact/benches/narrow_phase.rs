//! Narrow phase: the pair potential's force for pairs whose boxes overlap, in pairs/s.
//! Three sets of 4 096 pairs each (a fixed pseudo-random sequence, the same every run):
//! `touching`, triangles (tetrahedra) of about unit size whose centres lie within half a
//! size of each other, so most overlap; `corner`, right triangles of a mesh cell and a
//! neighbour sharing only a corner (the candidates of an FDEM mesh that pass the box
//! test, and must be rejected cheaply); the same for tetrahedra of a cube.
//!
//! Run: `cargo bench -p pcdc-contact --bench narrow_phase`.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use pcdc_contact::{tet_pair_force, triangle_pair_force};

const PAIRS: usize = 4096;

/// A small linear congruential generator: the same pairs every run, no dependency.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A counter-clockwise triangle of circumradius about `r` around (cx, cy).
fn triangle(rng: &mut Lcg, cx: f64, cy: f64, r: f64) -> [[f64; 2]; 3] {
    let rot = std::f64::consts::TAU * rng.next();
    std::array::from_fn(|k| {
        let a = rot + std::f64::consts::FRAC_PI_3 * 2.0 * k as f64 + 0.3 * (rng.next() - 0.5);
        let rr = r * (0.8 + 0.4 * rng.next());
        [cx + rr * a.cos(), cy + rr * a.sin()]
    })
}

/// A tetrahedron of size about `r` around `c`.
fn tetrahedron(rng: &mut Lcg, c: [f64; 3], r: f64) -> [[f64; 3]; 4] {
    let base = [
        [1.0, 1.0, 1.0],
        [1.0, -1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
    ];
    std::array::from_fn(|k| {
        std::array::from_fn(|d| c[d] + r * (base[k][d] + 0.3 * (rng.next() - 0.5)))
    })
}

fn bench(c: &mut Criterion) {
    let mut rng = Lcg(12345);
    let p = 1e10;
    let tri_touching: Vec<_> = (0..PAIRS)
        .map(|_| {
            let a = triangle(&mut rng, 0.0, 0.0, 1.0);
            let (cx, cy) = (rng.next() - 0.5, rng.next() - 0.5);
            let b = triangle(&mut rng, cx, cy, 1.0);
            (a, b)
        })
        .collect();
    // Two right triangles of neighbouring cells that share only the corner (1, 1).
    let tri_corner: Vec<_> = (0..PAIRS)
        .map(|_| {
            let e = 1e-9 * rng.next();
            let a = [[0.0, 0.0], [1.0, 0.0], [1.0 + e, 1.0]];
            let b = [[1.0 + e, 1.0], [2.0, 1.0], [2.0, 2.0]];
            (a, b)
        })
        .collect();
    let tet_touching: Vec<_> = (0..PAIRS)
        .map(|_| {
            let a = tetrahedron(&mut rng, [0.0; 3], 1.0);
            let o = [rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5];
            (a, tetrahedron(&mut rng, o, 1.0))
        })
        .collect();
    // Two tetrahedra of neighbouring cubes sharing only the corner (1, 1, 1).
    let tet_corner: Vec<_> = (0..PAIRS)
        .map(|_| {
            let e = 1e-9 * rng.next();
            let a = [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [1.0 + e, 1.0, 1.0],
            ];
            let b = [
                [1.0 + e, 1.0, 1.0],
                [2.0, 1.0, 1.0],
                [2.0, 2.0, 1.0],
                [2.0, 2.0, 2.0],
            ];
            (a, b)
        })
        .collect();
    let touching = tri_touching
        .iter()
        .filter(|(a, b)| triangle_pair_force(a, b, p) != Default::default())
        .count();
    eprintln!("narrow_phase: {touching} of {PAIRS} triangle pairs touching");
    let mut g = c.benchmark_group("narrow_phase");
    g.sample_size(20);
    g.throughput(Throughput::Elements(PAIRS as u64));
    g.bench_function("triangle_touching", |b| {
        b.iter(|| {
            for (x, y) in &tri_touching {
                black_box(triangle_pair_force(black_box(x), black_box(y), p));
            }
        })
    });
    g.bench_function("triangle_corner", |b| {
        b.iter(|| {
            for (x, y) in &tri_corner {
                black_box(triangle_pair_force(black_box(x), black_box(y), p));
            }
        })
    });
    g.bench_function("tet_touching", |b| {
        b.iter(|| {
            for (x, y) in &tet_touching {
                black_box(tet_pair_force(black_box(x), black_box(y), p));
            }
        })
    });
    g.bench_function("tet_corner", |b| {
        b.iter(|| {
            for (x, y) in &tet_corner {
                black_box(tet_pair_force(black_box(x), black_box(y), p));
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
