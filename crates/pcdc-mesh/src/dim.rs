//! Type-level spatial dimension.
//!
//! One code base serves 2D (plane strain, Tri3) and 3D (Tet4): every mesh, field and
//! physics is generic over `D: Dim`, so both dimensions build and test in one `cargo test`.

use std::fmt::Debug;

/// The element type of a cell (manual chapter 4, item 2).
///
/// The computational elements of a [`crate::Mesh`] are simplices (Tri3 in 2D, Tet4 in
/// 3D); a Quad4 or Hex8 cell is stored as the simplices it is cut into (see
/// [`crate::cells`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum ElementKind {
    /// Three-node triangle, nodes counter-clockwise.
    Tri3,
    /// Four-node tetrahedron, positive volume (nodes 1, 2, 3 counter-clockwise seen from node 4).
    Tet4,
    /// Four-node quadrilateral, nodes counter-clockwise (Gmsh type 3).
    Quad4,
    /// Eight-node hexahedron in Gmsh/VTK order: nodes 0-3 the bottom face counter-clockwise
    /// seen from the top, nodes 4-7 above them (Gmsh type 5).
    Hex8,
}

impl ElementKind {
    /// VTK cell type id (5 = VTK_TRIANGLE, 10 = VTK_TETRA, 9 = VTK_QUAD,
    /// 12 = VTK_HEXAHEDRON).
    pub fn vtk_cell_type(self) -> u8 {
        match self {
            ElementKind::Tri3 => 5,
            ElementKind::Tet4 => 10,
            ElementKind::Quad4 => 9,
            ElementKind::Hex8 => 12,
        }
    }

    /// Number of nodes (3, 4, 4, 8).
    pub fn n_nodes(self) -> usize {
        match self {
            ElementKind::Tri3 => 3,
            ElementKind::Tet4 | ElementKind::Quad4 => 4,
            ElementKind::Hex8 => 8,
        }
    }

    /// Space dimension of the cell (2 or 3).
    pub fn dim(self) -> usize {
        match self {
            ElementKind::Tri3 | ElementKind::Quad4 => 2,
            ElementKind::Tet4 | ElementKind::Hex8 => 3,
        }
    }

    /// Whether the cell is a simplex (one computational element).
    pub fn is_simplex(self) -> bool {
        matches!(self, ElementKind::Tri3 | ElementKind::Tet4)
    }
}

/// A spatial dimension with its simplex element.
pub trait Dim: Copy + Clone + Debug + Default + PartialEq + Send + Sync + 'static {
    /// Number of space dimensions (2 or 3).
    const D: usize;
    /// Nodes per element (3 for Tri3, 4 for Tet4).
    const NODES_PER_ELEM: usize;
    /// Nodes per element face (2 for an edge, 3 for a triangle).
    const NODES_PER_FACE: usize;
    /// Faces per element (3 or 4).
    const FACES_PER_ELEM: usize;
    /// Components of a symmetric tensor: 3 in 2D (xx, yy, xy), 6 in 3D (xx, yy, zz, xy, yz, xz).
    const NSYM: usize;
    /// The element kind of this dimension.
    const ELEMENT: ElementKind;
    /// Short name, "2d" or "3d".
    const NAME: &'static str;

    /// Local node indices of local face `f` of an element, ordered so that the face
    /// normal points out of the element (manual chapter 4, items 4-5).
    fn face_local_nodes(f: usize) -> &'static [usize];

    /// Signed measure (area or volume) of the simplex with the given vertex coordinates
    /// (`NODES_PER_ELEM * D` values). Positive for a correctly oriented element.
    fn signed_measure(x: &[f64]) -> f64;

    /// Measure (length or area) of a face with the given vertex coordinates and its
    /// outward unit normal written into `normal` (length `D`).
    fn face_measure_normal(x: &[f64], normal: &mut [f64]) -> f64;
}

/// Two dimensions: plane strain, Tri3 elements.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Dim2;

/// Three dimensions: Tet4 elements.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Dim3;

const TRI_FACES: [[usize; 2]; 3] = [[0, 1], [1, 2], [2, 0]];
const TET_FACES: [[usize; 3]; 4] = [[0, 2, 1], [1, 2, 3], [0, 1, 3], [0, 3, 2]];

impl Dim for Dim2 {
    const D: usize = 2;
    const NODES_PER_ELEM: usize = 3;
    const NODES_PER_FACE: usize = 2;
    const FACES_PER_ELEM: usize = 3;
    const NSYM: usize = 3;
    const ELEMENT: ElementKind = ElementKind::Tri3;
    const NAME: &'static str = "2d";

    fn face_local_nodes(f: usize) -> &'static [usize] {
        &TRI_FACES[f]
    }

    fn signed_measure(x: &[f64]) -> f64 {
        0.5 * ((x[2] - x[0]) * (x[5] - x[1]) - (x[4] - x[0]) * (x[3] - x[1]))
    }

    fn face_measure_normal(x: &[f64], normal: &mut [f64]) -> f64 {
        // Edge a -> b of a counter-clockwise triangle: the outward normal is the edge
        // direction turned clockwise.
        let (dx, dy) = (x[2] - x[0], x[3] - x[1]);
        let len = (dx * dx + dy * dy).sqrt();
        if len > 0.0 {
            // One division for both components (the joint loop's hot path).
            let inv = 1.0 / len;
            normal[0] = dy * inv;
            normal[1] = -dx * inv;
        } else {
            normal[0] = 0.0;
            normal[1] = 0.0;
        }
        len
    }
}

impl Dim for Dim3 {
    const D: usize = 3;
    const NODES_PER_ELEM: usize = 4;
    const NODES_PER_FACE: usize = 3;
    const FACES_PER_ELEM: usize = 4;
    const NSYM: usize = 6;
    const ELEMENT: ElementKind = ElementKind::Tet4;
    const NAME: &'static str = "3d";

    fn face_local_nodes(f: usize) -> &'static [usize] {
        &TET_FACES[f]
    }

    fn signed_measure(x: &[f64]) -> f64 {
        let a = [x[3] - x[0], x[4] - x[1], x[5] - x[2]];
        let b = [x[6] - x[0], x[7] - x[1], x[8] - x[2]];
        let c = [x[9] - x[0], x[10] - x[1], x[11] - x[2]];
        (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]))
            / 6.0
    }

    fn face_measure_normal(x: &[f64], normal: &mut [f64]) -> f64 {
        let a = [x[3] - x[0], x[4] - x[1], x[5] - x[2]];
        let b = [x[6] - x[0], x[7] - x[1], x[8] - x[2]];
        let n = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        // One division for the three components.
        let inv = if len > 0.0 { 1.0 / len } else { 0.0 };
        for k in 0..3 {
            normal[k] = n[k] * inv;
        }
        0.5 * len
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tet_faces_point_outward() {
        let x = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        assert!((Dim3::signed_measure(&x) - 1.0 / 6.0).abs() < 1e-15);
        let centroid = [0.25, 0.25, 0.25];
        for f in 0..4 {
            let ln = Dim3::face_local_nodes(f);
            let mut fx = [0.0; 9];
            for (k, &l) in ln.iter().enumerate() {
                fx[3 * k..3 * k + 3].copy_from_slice(&x[3 * l..3 * l + 3]);
            }
            let mut n = [0.0; 3];
            Dim3::face_measure_normal(&fx, &mut n);
            let d: f64 = (0..3).map(|k| (fx[k] - centroid[k]) * n[k]).sum();
            assert!(d > 0.0, "face {f} normal points inward");
        }
    }

    #[test]
    fn tri_faces_point_outward() {
        let x = [0.0, 0.0, 1.0, 0.0, 0.0, 1.0];
        assert!((Dim2::signed_measure(&x) - 0.5).abs() < 1e-15);
        let c = [1.0 / 3.0, 1.0 / 3.0];
        for f in 0..3 {
            let ln = Dim2::face_local_nodes(f);
            let fx = [
                x[2 * ln[0]],
                x[2 * ln[0] + 1],
                x[2 * ln[1]],
                x[2 * ln[1] + 1],
            ];
            let mut n = [0.0; 2];
            Dim2::face_measure_normal(&fx, &mut n);
            assert!((fx[0] - c[0]) * n[0] + (fx[1] - c[1]) * n[1] > 0.0);
        }
    }
}
