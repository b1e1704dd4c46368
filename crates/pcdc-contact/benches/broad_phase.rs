//! Broad phase: our sorted uniform grid against parry's BVH (binned SAH build + one
//! AABB query per element), same element boxes, same node-sharing exclusion, same sorted
//! lists (checked here and in tests/broad_phase.rs). Meshes: right-triangle blocks of
//! 10k, 50k and 200k triangles, every box inflated by half the default skin.
//!
//! Run: `cargo bench -p pcdc-contact --bench broad_phase`. Throughput: elements/s for a
//! full rebuild of all candidate lists.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use parry2d_f64::bounding_volume::Aabb;
use parry2d_f64::math::Vector;
use parry2d_f64::partitioning::{Bvh, BvhBuildStrategy};
use pcdc_compute::{Backend, CpuBackend, Kinematics};
use pcdc_contact::{element_boxes, grid_candidates};
use pcdc_mesh::builders;
use rayon::prelude::*;

fn bvh_candidates(boxes: &[[f64; 4]], conn: &[u32]) -> Vec<Vec<u32>> {
    let aabbs: Vec<Aabb> = boxes
        .iter()
        .map(|b| Aabb::new(Vector::new(b[0], b[1]), Vector::new(b[2], b[3])))
        .collect();
    let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &aabbs);
    (0..boxes.len())
        .into_par_iter()
        .map(|e| {
            let mine = &conn[3 * e..3 * e + 3];
            let mut list: Vec<u32> = bvh
                .intersect_aabb(&aabbs[e])
                .filter(|&f| {
                    let f = f as usize;
                    f != e && !conn[3 * f..3 * f + 3].iter().any(|n| mine.contains(n))
                })
                .collect();
            list.sort_unstable();
            list
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("broad_phase");
    g.sample_size(10);
    let all = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    for nx in [50usize, 112, 224] {
        let h = 0.05 / nx as f64;
        let mesh = builders::rectangle(0.0, 0.0, 0.05, 0.10, h).unwrap();
        let u = vec![0.0; mesh.coords().len()];
        let mass = vec![1.0; mesh.n_nodes()];
        let kin = Kinematics {
            mesh: &mesh,
            mass: &mass,
            u: &u,
            v: &u,
            time: 0.0,
            dt: 1.0,
            step: 0,
            damping: false,
        };
        let boxes = element_boxes(&kin, 0.25 * h);
        let conn = mesh.elements();
        assert_eq!(grid_candidates(&boxes, conn), bvh_candidates(&boxes, conn));
        let n = mesh.n_elements();
        g.throughput(Throughput::Elements(n as u64));
        for threads in [1, all] {
            let pool = CpuBackend::new(threads).unwrap();
            g.bench_function(format!("grid_{}k_threads_{threads}", n / 1000), |b| {
                b.iter(|| pool.install(|| grid_candidates(&boxes, conn)))
            });
            g.bench_function(format!("parry_bvh_{}k_threads_{threads}", n / 1000), |b| {
                b.iter(|| pool.install(|| bvh_candidates(&boxes, conn)))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
