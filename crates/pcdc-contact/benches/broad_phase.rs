//! Broad phase: our sorted uniform grid against parry's BVH (binned SAH build + one
//! AABB query per element), same element boxes, same node-sharing exclusion, same sorted
//! lists (checked here and in tests/broad_phase.rs). Meshes: right-triangle blocks of
//! 10k, 50k and 200k triangles, every box inflated by half the default skin.
//!
//! Run: `cargo bench -p pcdc-contact --bench broad_phase`. Throughput: elements/s for a
//! full rebuild of all candidate lists.

#[path = "../tests/common/mod.rs"]
mod common;

use common::{boxes_at_rest, bvh_candidates};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pcdc_compute::Backend;
use pcdc_contact::grid_candidates;
use pcdc_mesh::builders;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("broad_phase");
    g.sample_size(10);
    let all = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    for nx in [50usize, 112, 224] {
        let h = 0.05 / nx as f64;
        let mesh = builders::rectangle(0.0, 0.0, 0.05, 0.10, h).unwrap();
        let boxes = boxes_at_rest(&mesh, 0.25 * h);
        let conn = mesh.elements();
        assert_eq!(grid_candidates(&boxes, conn), bvh_candidates(&boxes, conn));
        let n = mesh.n_elements();
        g.throughput(Throughput::Elements(n as u64));
        for threads in [1, all] {
            let pool = Backend::cpu(threads).unwrap();
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
