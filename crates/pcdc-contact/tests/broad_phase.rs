//! The grid broad phase finds exactly the pairs a BVH (parry) finds.

mod common;

use common::{boxes_at_rest, bvh_candidates};
use pcdc_contact::grid_candidates;
use pcdc_mesh::builders;

#[test]
fn grid_and_bvh_agree() {
    // Two overlapping plates with graded meshes (dense grid path).
    let a = builders::plate_with_hole(0.5, 0.5, 0.1, 0.01, 0.05).unwrap();
    let b = builders::rectangle(0.3, 0.2, 0.6, 0.5, 0.04).unwrap();
    let (mesh, _) = builders::union(&[&a, &b]).unwrap();
    let boxes = boxes_at_rest(&mesh, 0.002);
    let grid = grid_candidates(&boxes, mesh.elements());
    let pairs: usize = grid.iter().map(|l| l.len()).sum();
    assert!(
        pairs > mesh.n_elements(),
        "the scene should have many candidate pairs"
    );
    assert_eq!(grid, bvh_candidates(&boxes, mesh.elements()));
}

/// Bodies far apart take the sparse (sorted-key) path of the grid: same answer.
#[test]
fn scattered_bodies_agree_too() {
    let a = builders::rectangle(0.0, 0.0, 0.1, 0.1, 0.01).unwrap();
    let b = builders::rectangle(0.05, 0.05, 0.1, 0.1, 0.013).unwrap();
    let c = builders::rectangle(500.0, 300.0, 0.1, 0.1, 0.01).unwrap();
    let (mesh, _) = builders::union(&[&a, &b, &c]).unwrap();
    let boxes = boxes_at_rest(&mesh, 0.001);
    let grid = grid_candidates(&boxes, mesh.elements());
    assert!(grid.iter().map(|l| l.len()).sum::<usize>() > 0);
    assert_eq!(grid, bvh_candidates(&boxes, mesh.elements()));
}
