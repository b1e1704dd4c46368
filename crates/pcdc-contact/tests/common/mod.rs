//! Shared by tests/broad_phase.rs and benches/broad_phase.rs: parry's BVH as the
//! reference broad phase, and element boxes of a mesh at rest.

use parry2d_f64::bounding_volume::Aabb;
use parry2d_f64::math::Vector;
use parry2d_f64::partitioning::{Bvh, BvhBuildStrategy};
use pcdc_compute::Kinematics;
use pcdc_contact::element_boxes;
use pcdc_mesh::{Dim2, Mesh};
use rayon::prelude::*;

/// Candidate lists from parry's BVH (binned build, one AABB query per element) with the
/// same boxes and node-sharing exclusion as `grid_candidates`.
pub fn bvh_candidates(boxes: &[[f64; 4]], conn: &[u32]) -> Vec<Vec<u32>> {
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

/// Element boxes of `mesh` in its reference position, inflated by `margin` (m).
pub fn boxes_at_rest(mesh: &Mesh<Dim2>, margin: f64) -> Vec<[f64; 4]> {
    let u = vec![0.0; mesh.coords().len()];
    let mass = vec![1.0; mesh.n_nodes()];
    let kin = Kinematics {
        mesh,
        coords: mesh.coords(),
        mass: &mass,
        u: &u,
        v: &u,
        time: 0.0,
        dt: 1.0,
        step: 0,
        damping: false,
    };
    element_boxes(&kin, margin)
}
