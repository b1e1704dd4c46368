//! Node splitting (manual chapter 4, items 3-5): elements of FDEM regions get their own
//! (slave) nodes and every interior face that touches such an element becomes a
//! face-joint; pure-FEM regions keep shared nodes. A master-node map takes every new
//! node back to the original node it was copied from, for output and coupling.

use std::collections::HashMap;

use pcdc_mesh::{Dim, Mesh, Range};

use crate::CohesiveError;

/// The face-joints of a split mesh.
///
/// Joint `j` has nodes `nodes[j*2*NPF..(j+1)*2*NPF]`: first side A's nodes in the order
/// of A's outward face, then side B's copies of the same original nodes in the same
/// order, so that node k of side A and node k of side B start at the same position
/// (4 nodes in 2D, 6 in 3D).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Joints {
    /// Joint nodes, stride `2 * NODES_PER_FACE`.
    pub nodes: Vec<u32>,
    /// Elements on sides A and B, stride 2.
    pub elements: Vec<u32>,
    /// Faces of the split mesh on sides A and B, stride 2.
    pub faces: Vec<u32>,
}

impl Joints {
    /// Number of joints.
    pub fn len(&self) -> usize {
        self.elements.len() / 2
    }

    /// Whether there are no joints.
    pub fn is_empty(&self) -> bool {
        self.elements.is_empty()
    }
}

/// A mesh after node splitting.
#[derive(Clone, Debug)]
pub struct SplitMesh<D: Dim> {
    /// The split mesh (FDEM elements with their own nodes).
    pub mesh: Mesh<D>,
    /// For every node of the split mesh, the original (master) node it copies.
    pub master: Vec<u32>,
    /// The face-joints.
    pub joints: Joints,
    /// Faces of the split mesh that lie on the original outer boundary (ascending);
    /// the other boundary faces of the split mesh are joint sides.
    pub outer_boundary: Vec<u32>,
}

fn face_key(nodes: impl Iterator<Item = u32>) -> [u32; 3] {
    let mut k = [u32::MAX; 3];
    for (i, n) in nodes.enumerate() {
        k[i] = n;
    }
    k.sort_unstable();
    k
}

/// Splits the nodes of the elements in `fdem` (by centroid) and creates a face-joint on
/// every interior face with at least one FDEM element on either side. Groups carry
/// over: node groups to every copy, element groups unchanged, face groups to the
/// corresponding faces of the split mesh (both sides for interior faces).
pub fn split_nodes<D: Dim>(mesh: &Mesh<D>, fdem: &Range) -> Result<SplitMesh<D>, CohesiveError> {
    let (d, npe, npf) = (D::D, D::NODES_PER_ELEM, D::NODES_PER_FACE);
    let ne = mesh.n_elements();
    let mut is_fdem = vec![false; ne];
    for e in mesh.select_elements(fdem)? {
        is_fdem[e as usize] = true;
    }
    let mut master: Vec<u32> = Vec::with_capacity(ne * npe);
    let mut shared = vec![u32::MAX; mesh.n_nodes()];
    let mut conn = Vec::with_capacity(ne * npe);
    for e in 0..ne {
        for &n in mesh.element(e) {
            let new = if is_fdem[e] {
                master.push(n);
                master.len() as u32 - 1
            } else {
                if shared[n as usize] == u32::MAX {
                    master.push(n);
                    shared[n as usize] = master.len() as u32 - 1;
                }
                shared[n as usize]
            };
            conn.push(new);
        }
    }
    let mut coords = Vec::with_capacity(master.len() * d);
    for &m in &master {
        coords.extend_from_slice(mesh.node(m as usize));
    }
    let mut split = Mesh::<D>::new(coords, conn)?;
    // Faces of the split mesh by their node set.
    let new_faces: HashMap<[u32; 3], u32> = (0..split.faces().len())
        .map(|f| (face_key(split.face(f).iter().copied()), f as u32))
        .collect();
    let local_face = |m: &Mesh<D>, e: usize, orig_nodes: &[u32]| -> usize {
        (0..D::FACES_PER_ELEM)
            .find(|&lf| {
                let ln = D::face_local_nodes(lf);
                let mut a: Vec<u32> = ln.iter().map(|&l| m.element(e)[l]).collect();
                let mut b = orig_nodes.to_vec();
                a.sort_unstable();
                b.sort_unstable();
                a == b
            })
            .expect("a face of the element")
    };
    let copy_of = |e: usize, orig: u32| -> u32 {
        let pos = mesh
            .element(e)
            .iter()
            .position(|&n| n == orig)
            .expect("node of the element");
        split.element(e)[pos]
    };
    let new_face_of = |e: usize, lf: usize| -> u32 {
        let ln = D::face_local_nodes(lf);
        new_faces[&face_key(ln.iter().map(|&l| split.element(e)[l]))]
    };
    let faces = mesh.faces();
    let mut joints = Joints::default();
    let mut face_map: Vec<Vec<u32>> = vec![Vec::new(); faces.len()];
    for f in 0..faces.len() {
        let a = faces.owner[f] as usize;
        let la = faces.owner_local[f] as usize;
        let fa = new_face_of(a, la);
        face_map[f].push(fa);
        let b = faces.neighbor[f];
        if b == pcdc_mesh::NO_NEIGHBOR {
            continue;
        }
        let b = b as usize;
        let orig = mesh.face(f);
        let fb = new_face_of(b, local_face(mesh, b, orig));
        if fb != fa {
            face_map[f].push(fb);
        }
        if is_fdem[a] || is_fdem[b] {
            joints.nodes.extend(orig.iter().map(|&n| copy_of(a, n)));
            joints.nodes.extend(orig.iter().map(|&n| copy_of(b, n)));
            joints.elements.extend_from_slice(&[a as u32, b as u32]);
            joints.faces.extend_from_slice(&[fa, fb]);
        }
    }
    debug_assert_eq!(joints.nodes.len(), joints.len() * 2 * npf);
    let mut outer_boundary: Vec<u32> = faces
        .boundary
        .iter()
        .map(|&f| face_map[f as usize][0])
        .collect();
    outer_boundary.sort_unstable();
    // Carry the groups over.
    let mut copies: Vec<Vec<u32>> = vec![Vec::new(); mesh.n_nodes()];
    for (new, &m) in master.iter().enumerate() {
        copies[m as usize].push(new as u32);
    }
    let groups = mesh.groups().clone();
    for (name, nodes) in groups.nodes {
        split.add_node_group(
            name,
            nodes
                .iter()
                .flat_map(|&n| copies[n as usize].iter().copied())
                .collect(),
        )?;
    }
    for (name, elems) in groups.elements {
        split.add_element_group(name, elems)?;
    }
    for (name, fs) in groups.faces {
        split.add_face_group(
            name,
            fs.iter()
                .flat_map(|&f| face_map[f as usize].iter().copied())
                .collect(),
        )?;
    }
    Ok(SplitMesh {
        mesh: split,
        master,
        joints,
        outer_boundary,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use pcdc_mesh::builders;

    fn check_joints<D: Dim>(s: &SplitMesh<D>) {
        let npf = D::NODES_PER_FACE;
        let d = D::D;
        for j in 0..s.joints.len() {
            let n = &s.joints.nodes[j * 2 * npf..(j + 1) * 2 * npf];
            for k in 0..npf {
                // Same original node, same position, different copies when split.
                assert_eq!(s.master[n[k] as usize], s.master[n[npf + k] as usize]);
                assert_eq!(s.mesh.node(n[k] as usize), s.mesh.node(n[npf + k] as usize));
            }
            // Side normals are opposite.
            let (fa, fb) = (
                s.joints.faces[2 * j] as usize,
                s.joints.faces[2 * j + 1] as usize,
            );
            let (mut na, mut nb) = ([0.0; 3], [0.0; 3]);
            s.mesh.face_measure_normal(fa, &mut na[..d]);
            s.mesh.face_measure_normal(fb, &mut nb[..d]);
            let dot: f64 = (0..d).map(|k| na[k] * nb[k]).sum();
            assert!(
                (dot + 1.0).abs() < 1e-12,
                "joint {j}: normals {na:?} {nb:?}"
            );
        }
    }

    #[test]
    fn full_split_2d() {
        let m = builders::rectangle(0.0, 0.0, 1.0, 0.5, 0.1).unwrap();
        let interior = m.faces().len() - m.faces().boundary.len();
        let s = split_nodes(&m, &Range::All).unwrap();
        assert_eq!(s.mesh.n_nodes(), 3 * m.n_elements());
        assert_eq!(s.joints.len(), interior);
        assert_eq!(s.joints.nodes.len(), 4 * interior);
        assert_eq!(s.outer_boundary.len(), m.faces().boundary.len());
        assert_eq!(
            s.mesh.faces().boundary.len(),
            s.outer_boundary.len() + 2 * interior
        );
        check_joints(&s);
        // Groups follow: the top face group stays on the top boundary.
        let top = &s.mesh.groups().faces["top"];
        assert_eq!(top.len(), m.groups().faces["top"].len());
        for &f in top {
            let mut c = [0.0; 2];
            s.mesh.face_centroid(f as usize, &mut c);
            assert!((c[1] - 0.5).abs() < 1e-12);
        }
        let left = &s.mesh.groups().nodes["left"];
        assert!(left
            .iter()
            .all(|&n| s.mesh.node(n as usize)[0].abs() < 1e-12));
        assert!(left.len() > m.groups().nodes["left"].len());
    }

    #[test]
    fn partial_split_keeps_fem_nodes_shared() {
        let m = builders::rectangle(0.0, 0.0, 1.0, 0.5, 0.1).unwrap();
        let s = split_nodes(&m, &Range::rect(0.0, 0.0, 0.5, 0.5)).unwrap();
        let fdem = m
            .select_elements(&Range::rect(0.0, 0.0, 0.5, 0.5))
            .unwrap()
            .len();
        assert!(s.mesh.n_nodes() < 3 * m.n_elements());
        assert!(s.mesh.n_nodes() >= 3 * fdem);
        // Joints only on faces touching an FDEM element.
        for j in 0..s.joints.len() {
            let (a, b) = (
                s.joints.elements[2 * j] as usize,
                s.joints.elements[2 * j + 1] as usize,
            );
            let mut c = [[0.0; 2]; 2];
            m.element_centroid(a, &mut c[0]);
            m.element_centroid(b, &mut c[1]);
            assert!(c[0][0] <= 0.5 || c[1][0] <= 0.5);
        }
        check_joints(&s);
    }

    #[test]
    fn full_split_3d() {
        let m = builders::cuboid([0.0; 3], [1.0, 1.0, 1.0], 0.5).unwrap();
        let interior = m.faces().len() - m.faces().boundary.len();
        let s = split_nodes(&m, &Range::All).unwrap();
        assert_eq!(s.mesh.n_nodes(), 4 * m.n_elements());
        assert_eq!(s.joints.len(), interior);
        assert_eq!(s.joints.nodes.len(), 6 * interior);
        check_joints(&s);
    }

    #[test]
    fn no_fdem_region_means_no_joints() {
        let m = builders::rectangle(0.0, 0.0, 1.0, 0.5, 0.1).unwrap();
        let s = split_nodes(&m, &Range::rect(5.0, 5.0, 6.0, 6.0)).unwrap();
        assert!(s.joints.is_empty());
        assert_eq!(s.mesh.n_nodes(), m.n_nodes());
    }
}
