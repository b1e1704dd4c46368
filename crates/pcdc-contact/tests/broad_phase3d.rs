//! The 3D grid broad phase finds exactly the pairs an all-pairs box test finds, on the
//! dense-grid path and on the sorted-key path for scattered bodies.

use pcdc_compute::Kinematics;
use pcdc_contact::{element_boxes_3d, grid_candidates_3d};
use pcdc_mesh::{builders, Dim3, Mesh};

fn boxes_at_rest(mesh: &Mesh<Dim3>, margin: f64) -> Vec<[f64; 6]> {
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
    element_boxes_3d(&kin, margin)
}

/// Every pair of overlapping boxes that shares no node, by brute force.
fn all_pairs(boxes: &[[f64; 6]], conn: &[u32]) -> Vec<Vec<u32>> {
    (0..boxes.len())
        .map(|e| {
            (0..boxes.len())
                .filter(|&f| {
                    let (a, b) = (boxes[e], boxes[f]);
                    f != e
                        && (0..3).all(|k| a[k] <= b[k + 3] && b[k] <= a[k + 3])
                        && !conn[4 * f..4 * f + 4]
                            .iter()
                            .any(|n| conn[4 * e..4 * e + 4].contains(n))
                })
                .map(|f| f as u32)
                .collect()
        })
        .collect()
}

#[test]
fn grid_3d_and_brute_force_agree() {
    let a = builders::cuboid([0.0, 0.0, 0.0], [0.1, 0.06, 0.05], 0.02).unwrap();
    let b = builders::cuboid([0.05, 0.03, 0.04], [0.08, 0.05, 0.05], 0.013).unwrap();
    let (mesh, _) = builders::union(&[&a, &b]).unwrap();
    let boxes = boxes_at_rest(&mesh, 0.002);
    let grid = grid_candidates_3d(&boxes, mesh.elements());
    let pairs: usize = grid.iter().map(|l| l.len()).sum();
    assert!(
        pairs > mesh.n_elements(),
        "the scene should have many candidate pairs"
    );
    assert_eq!(grid, all_pairs(&boxes, mesh.elements()));
}

#[test]
fn scattered_3d_bodies_agree_too() {
    let a = builders::cuboid([0.0, 0.0, 0.0], [0.05, 0.05, 0.05], 0.02).unwrap();
    let b = builders::cuboid([0.03, 0.02, 0.01], [0.05, 0.05, 0.05], 0.017).unwrap();
    let c = builders::cuboid([300.0, -200.0, 500.0], [0.05, 0.05, 0.05], 0.025).unwrap();
    let (mesh, _) = builders::union(&[&a, &b, &c]).unwrap();
    let boxes = boxes_at_rest(&mesh, 0.001);
    let grid = grid_candidates_3d(&boxes, mesh.elements());
    assert!(grid.iter().map(|l| l.len()).sum::<usize>() > 0);
    assert_eq!(grid, all_pairs(&boxes, mesh.elements()));
}
