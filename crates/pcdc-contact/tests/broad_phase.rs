//! The sorted-grid broad phase finds exactly the pairs a BVH (parry) finds.

use parry2d_f64::bounding_volume::Aabb;
use parry2d_f64::math::Vector;
use parry2d_f64::partitioning::{Bvh, BvhBuildStrategy};
use pcdc_compute::Kinematics;
use pcdc_contact::{element_boxes, grid_candidates};
use pcdc_mesh::builders;

/// Candidate lists from parry's BVH with the same boxes and node-sharing exclusion.
pub fn bvh_candidates(boxes: &[[f64; 4]], conn: &[u32]) -> Vec<Vec<u32>> {
    let aabbs: Vec<Aabb> = boxes
        .iter()
        .map(|b| Aabb::new(Vector::new(b[0], b[1]), Vector::new(b[2], b[3])))
        .collect();
    let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &aabbs);
    (0..boxes.len())
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

#[test]
fn grid_and_bvh_agree() {
    // Two overlapping plates with distorted meshes.
    let a = builders::plate_with_hole(0.5, 0.5, 0.1, 0.01, 0.05).unwrap();
    let b = builders::rectangle(0.3, 0.2, 0.6, 0.5, 0.04).unwrap();
    let (mesh, _) = builders::union(&[&a, &b]).unwrap();
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
    let boxes = element_boxes(&kin, 0.002);
    let grid = grid_candidates(&boxes, mesh.elements());
    let bvh = bvh_candidates(&boxes, mesh.elements());
    let pairs: usize = grid.iter().map(|l| l.len()).sum();
    assert!(
        pairs > mesh.n_elements(),
        "the scene should have many candidate pairs"
    );
    assert_eq!(grid, bvh);
}

/// Bodies far apart take the sparse (sorted-key) path of the grid: same answer.
#[test]
fn scattered_bodies_agree_too() {
    let a = builders::rectangle(0.0, 0.0, 0.1, 0.1, 0.01).unwrap();
    let b = builders::rectangle(0.05, 0.05, 0.1, 0.1, 0.013).unwrap();
    let c = builders::rectangle(500.0, 300.0, 0.1, 0.1, 0.01).unwrap();
    let (mesh, _) = builders::union(&[&a, &b, &c]).unwrap();
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
    let boxes = element_boxes(&kin, 0.001);
    let grid = grid_candidates(&boxes, mesh.elements());
    assert!(grid.iter().map(|l| l.len()).sum::<usize>() > 0);
    assert_eq!(grid, bvh_candidates(&boxes, mesh.elements()));
}
