//! Interfaces between elements: node splitting (manual chapter 4, items 3-5) and the
//! face-joint topology it leaves, as mesh data that every physics reads.
//!
//! [`split_nodes`] gives the elements of FDEM regions their own (slave) nodes and puts an
//! interface (a face-joint of the manual) on every interior face that touches such an
//! element; pure-FEM regions keep shared nodes. The split mesh carries its
//! [`Interfaces`] ([`crate::Mesh::interfaces`]): per interface the two elements, their
//! local faces, the two faces of the split mesh and the matched node pairs, plus the
//! master-node map that takes every node of the split mesh back to the original node it
//! was copied from. Cohesive joints integrate forces over the interfaces, contact keeps
//! bonded neighbours apart until an interface breaks, fluid flows along them and bolts
//! cross them, all from the same list, so no physics crate depends on another for it.

use std::collections::HashMap;

use crate::{Dim, Mesh, MeshError, Range, NO_NEIGHBOR};

/// The interfaces (face-joints) of a split mesh and its master-node map.
///
/// Interface `j` joins element `elements()[2j]` (side A) to element `elements()[2j+1]`
/// (side B) across their local faces `local_faces()[2j..2j+2]`, which are the faces
/// `faces()[2j..2j+2]` of the mesh. Its nodes are `nodes()[j*2*NPF..(j+1)*2*NPF]`
/// (`NPF` = [`Interfaces::nodes_per_side`], 2 in 2D, 3 in 3D): first side A's nodes in the
/// order of A's outward face, then side B's copies of the same original nodes in the same
/// order, so that node `k` of side A and node `k` of side B are a pair that starts at the
/// same position (4 nodes per interface in 2D, 6 in 3D).
///
/// Interfaces are ordered by the face of the original mesh they were cut along; a mesh
/// that was never split has none (and an empty master map).
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Interfaces {
    /// Nodes per side (the mesh's nodes per face); set by the mesh that holds them.
    #[serde(skip)]
    npf: usize,
    /// Interface nodes, stride `2 * NPF`: side A, then side B's matching copies.
    nodes: Vec<u32>,
    /// Elements on sides A and B, stride 2.
    elements: Vec<u32>,
    /// Local face index of each side's element, stride 2.
    local_faces: Vec<u8>,
    /// Faces of the mesh on sides A and B, stride 2.
    faces: Vec<u32>,
    /// Per node of the mesh, the original (master) node it copies; empty when the mesh
    /// was not split.
    master: Vec<u32>,
}

/// One interface of [`Interfaces`], by value and slices into its arrays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Interface<'a> {
    /// Elements on sides A and B.
    pub elements: [u32; 2],
    /// Local face index of sides A and B in their elements.
    pub local_faces: [u8; 2],
    /// Faces of the mesh on sides A and B.
    pub faces: [u32; 2],
    /// Side A's nodes, in the order of A's outward face.
    pub side_a: &'a [u32],
    /// Side B's nodes, matched to side A's position by position.
    pub side_b: &'a [u32],
}

impl<'a> Interface<'a> {
    /// The node pairs `(side A node, side B node)` that start at the same position.
    pub fn node_pairs(&self) -> impl ExactSizeIterator<Item = (u32, u32)> + 'a {
        self.side_a.iter().copied().zip(self.side_b.iter().copied())
    }
}

impl Interfaces {
    /// No interfaces, for a mesh with `npf` nodes per face.
    pub(crate) fn none(npf: usize) -> Self {
        Interfaces {
            npf,
            ..Interfaces::default()
        }
    }

    /// Number of interfaces.
    #[inline]
    pub fn len(&self) -> usize {
        self.elements.len() / 2
    }

    /// Whether there are no interfaces.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.elements.is_empty()
    }

    /// Nodes per side (the mesh's nodes per face: 2 in 2D, 3 in 3D).
    #[inline]
    pub fn nodes_per_side(&self) -> usize {
        self.npf
    }

    /// Nodes per interface: both sides, `2 * nodes_per_side()` (4 in 2D, 6 in 3D).
    #[inline]
    pub fn nodes_per_joint(&self) -> usize {
        2 * self.npf
    }

    /// Interface connectivity, stride [`Interfaces::nodes_per_joint`]: per interface side
    /// A's nodes, then side B's matching nodes.
    #[inline]
    pub fn nodes(&self) -> &[u32] {
        &self.nodes
    }

    /// Nodes of interface `j`: side A's, then side B's.
    #[inline]
    pub fn joint_nodes(&self, j: usize) -> &[u32] {
        let s = 2 * self.npf;
        &self.nodes[j * s..(j + 1) * s]
    }

    /// Elements on sides A and B, stride 2.
    #[inline]
    pub fn elements(&self) -> &[u32] {
        &self.elements
    }

    /// Local face index of sides A and B in their elements, stride 2.
    #[inline]
    pub fn local_faces(&self) -> &[u8] {
        &self.local_faces
    }

    /// Faces of the mesh on sides A and B, stride 2 (both are boundary faces of the split
    /// mesh; a face field on them, e.g. a broken flag, is seen by face-based physics).
    #[inline]
    pub fn faces(&self) -> &[u32] {
        &self.faces
    }

    /// Per node, the original (master) node it was copied from by [`split_nodes`]; empty
    /// when the mesh was not split.
    #[inline]
    pub fn master(&self) -> &[u32] {
        &self.master
    }

    /// The original node of node `n` (`n` itself in a mesh that was not split).
    #[inline]
    pub fn master_of(&self, n: u32) -> u32 {
        self.master.get(n as usize).copied().unwrap_or(n)
    }

    /// Whether the mesh was made by [`split_nodes`] (it has a master-node map, even when
    /// no interface was cut).
    #[inline]
    pub fn is_split(&self) -> bool {
        !self.master.is_empty()
    }

    /// Interface `j`, or `None` beyond the last.
    pub fn get(&self, j: usize) -> Option<Interface<'_>> {
        if j >= self.len() {
            return None;
        }
        let (nodes, npf) = (self.joint_nodes(j), self.npf);
        Some(Interface {
            elements: [self.elements[2 * j], self.elements[2 * j + 1]],
            local_faces: [self.local_faces[2 * j], self.local_faces[2 * j + 1]],
            faces: [self.faces[2 * j], self.faces[2 * j + 1]],
            side_a: &nodes[..npf],
            side_b: &nodes[npf..],
        })
    }

    /// The interfaces in order.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = Interface<'_>> {
        (0..self.len()).map(|j| self.get(j).expect("index below len"))
    }

    /// Checks the interfaces against the mesh that is to hold them (array lengths, element,
    /// local face, face and node indices, each side's nodes and face belonging to its
    /// element's local face, matched pairs sharing their master node) and sets the nodes
    /// per side. Errors name the first offending interface.
    pub(crate) fn check<D: Dim>(&mut self, mesh: &Mesh<D>) -> Result<(), MeshError> {
        let npf = D::NODES_PER_FACE;
        self.npf = npf;
        let nj = self.len();
        let bad = |m: String| Err(MeshError::Inconsistent(format!("interfaces: {m}")));
        if self.elements.len() % 2 != 0
            || self.local_faces.len() != 2 * nj
            || self.faces.len() != 2 * nj
            || self.nodes.len() != 2 * npf * nj
        {
            return bad(format!(
                "{} elements, {} local faces, {} faces and {} nodes do not fit {nj} interfaces of {} nodes",
                self.elements.len(),
                self.local_faces.len(),
                self.faces.len(),
                self.nodes.len(),
                2 * npf
            ));
        }
        let (nn, ne, nf) = (mesh.n_nodes(), mesh.n_elements(), mesh.faces().len());
        if !self.master.is_empty() && self.master.len() != nn {
            return bad(format!(
                "the master map has {} entries for {nn} nodes",
                self.master.len()
            ));
        }
        if let Some(n) = self.master.iter().position(|&m| m as usize >= nn) {
            return bad(format!(
                "node {n} has master node {}, beyond the original nodes (at most {nn})",
                self.master[n]
            ));
        }
        let sorted = |it: &mut dyn Iterator<Item = u32>| {
            let mut k = [u32::MAX; 3];
            for (i, n) in it.enumerate().take(3) {
                k[i] = n;
            }
            k.sort_unstable();
            k
        };
        for j in 0..nj {
            let nodes = &self.nodes[j * 2 * npf..(j + 1) * 2 * npf];
            for s in 0..2 {
                let (e, lf, f) = (
                    self.elements[2 * j + s] as usize,
                    self.local_faces[2 * j + s] as usize,
                    self.faces[2 * j + s] as usize,
                );
                if e >= ne || lf >= D::FACES_PER_ELEM || f >= nf {
                    return bad(format!(
                        "interface {j} side {s}: element {e}, local face {lf}, face {f} \
                         (the mesh has {ne} elements of {} faces, and {nf} faces)",
                        D::FACES_PER_ELEM
                    ));
                }
                let side = &nodes[s * npf..(s + 1) * npf];
                if let Some(&n) = side.iter().find(|&&n| n as usize >= nn) {
                    return bad(format!(
                        "interface {j} has node {n}, but the mesh has {nn} nodes"
                    ));
                }
                let conn = mesh.element(e);
                let local = sorted(&mut D::face_local_nodes(lf).iter().map(|&l| conn[l]));
                let faces = mesh.faces();
                let of_element = faces.owner[f] as usize == e
                    || (faces.neighbor[f] != NO_NEIGHBOR && faces.neighbor[f] as usize == e);
                if sorted(&mut side.iter().copied()) != local
                    || sorted(&mut mesh.face(f).iter().copied()) != local
                    || !of_element
                {
                    return bad(format!(
                        "interface {j} side {s}: nodes {side:?} and face {f} are not local face \
                         {lf} of element {e}"
                    ));
                }
            }
            if !self.master.is_empty() {
                if let Some(k) = (0..npf).find(|&k| {
                    self.master[nodes[k] as usize] != self.master[nodes[npf + k] as usize]
                }) {
                    return bad(format!(
                        "interface {j}: nodes {} and {} are paired but copy different original nodes",
                        nodes[k],
                        nodes[npf + k]
                    ));
                }
            }
        }
        Ok(())
    }
}

fn face_key(nodes: impl Iterator<Item = u32>) -> [u32; 3] {
    let mut k = [u32::MAX; 3];
    for (i, n) in nodes.enumerate() {
        k[i] = n;
    }
    k.sort_unstable();
    k
}

/// Splits the nodes of the elements in `fdem` (selected by centroid) and puts an
/// interface on every interior face with at least one FDEM element on either side
/// (never inside a Quad4/Hex8 cell, whose simplices keep sharing its nodes);
/// returns the split mesh, which carries the interfaces and the master-node map
/// ([`crate::Mesh::interfaces`]).
///
/// Elements keep their index and node order; an FDEM cell's nodes are numbered
/// consecutively in cell order, a node of pure-FEM elements once, where first met.
/// Groups carry over: node groups to every copy, element groups unchanged, face groups
/// to the corresponding faces of the split mesh (both sides for interior faces).
/// Interfaces follow the faces of the original mesh in order; side A is the face's
/// owner.
///
/// A mesh that was split already (it has a master-node map) is refused: split the
/// original mesh once, with the union of the regions.
pub fn split_nodes<D: Dim>(mesh: &Mesh<D>, fdem: &Range) -> Result<Mesh<D>, MeshError> {
    if mesh.interfaces().is_split() {
        return Err(MeshError::AlreadySplit {
            interfaces: mesh.interfaces().len(),
            hint: "split the original mesh once, with all FDEM regions in the range",
        });
    }
    let (d, npe, npf) = (D::D, D::NODES_PER_ELEM, D::NODES_PER_FACE);
    let ne = mesh.n_elements();
    let mut is_fdem = vec![false; ne];
    for e in mesh.select_elements(fdem)? {
        is_fdem[e as usize] = true;
    }
    let mut master: Vec<u32> = Vec::with_capacity(ne * npe);
    let mut shared = vec![u32::MAX; mesh.n_nodes()];
    let mut conn = Vec::with_capacity(ne * npe);
    // A Quad4/Hex8 cell is split as one piece: its simplices keep sharing its nodes.
    let mut cell_nodes = Vec::with_capacity(mesh.cells().all_nodes().len());
    let mut local: Vec<(u32, u32)> = Vec::with_capacity(8);
    for c in 0..mesh.n_cells() {
        let els = mesh.cell_elements(c);
        let fdem_cell = is_fdem[els.start];
        local.clear();
        for &n in mesh.cell_nodes(c) {
            let new = if fdem_cell {
                master.push(n);
                master.len() as u32 - 1
            } else {
                if shared[n as usize] == u32::MAX {
                    master.push(n);
                    shared[n as usize] = master.len() as u32 - 1;
                }
                shared[n as usize]
            };
            local.push((n, new));
            cell_nodes.push(new);
        }
        for e in els {
            for &n in mesh.element(e) {
                let new = local.iter().find(|p| p.0 == n).expect("a cell node").1;
                conn.push(new);
            }
        }
    }
    let mut coords = Vec::with_capacity(master.len() * d);
    for &m in &master {
        coords.extend_from_slice(mesh.node(m as usize));
    }
    let mut split = Mesh::<D>::new(coords, conn)?;
    if !mesh.cells().is_empty() {
        split.set_cells(mesh.cells().with_nodes(cell_nodes));
    }
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
    let mut joints = Interfaces::none(npf);
    let mut face_map: Vec<Vec<u32>> = vec![Vec::new(); faces.len()];
    for f in 0..faces.len() {
        let a = faces.owner[f] as usize;
        let la = faces.owner_local[f] as usize;
        let fa = new_face_of(a, la);
        face_map[f].push(fa);
        let b = faces.neighbor[f];
        if b == NO_NEIGHBOR {
            continue;
        }
        let b = b as usize;
        let orig = mesh.face(f);
        let lb = local_face(mesh, b, orig);
        let fb = new_face_of(b, lb);
        if fb != fa {
            face_map[f].push(fb);
        }
        if (is_fdem[a] || is_fdem[b]) && mesh.cell_of(a) != mesh.cell_of(b) {
            joints.nodes.extend(orig.iter().map(|&n| copy_of(a, n)));
            joints.nodes.extend(orig.iter().map(|&n| copy_of(b, n)));
            joints.elements.extend_from_slice(&[a as u32, b as u32]);
            joints.local_faces.extend_from_slice(&[la as u8, lb as u8]);
            joints.faces.extend_from_slice(&[fa, fb]);
        }
    }
    debug_assert_eq!(joints.nodes.len(), joints.len() * 2 * npf);
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
    joints.master = master;
    split.set_interfaces(joints)?;
    Ok(split)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builders;

    fn check_joints<D: Dim>(m: &Mesh<D>) {
        let d = D::D;
        let s = m.interfaces();
        assert_eq!(s.nodes_per_side(), D::NODES_PER_FACE);
        for (j, i) in s.iter().enumerate() {
            for (a, b) in i.node_pairs() {
                // Same original node, same position, different copies when split.
                assert_eq!(s.master()[a as usize], s.master()[b as usize]);
                assert_eq!(m.node(a as usize), m.node(b as usize));
            }
            // Side normals are opposite.
            let (fa, fb) = (i.faces[0] as usize, i.faces[1] as usize);
            let (mut na, mut nb) = ([0.0; 3], [0.0; 3]);
            m.face_measure_normal(fa, &mut na[..d]);
            m.face_measure_normal(fb, &mut nb[..d]);
            let dot: f64 = (0..d).map(|k| na[k] * nb[k]).sum();
            assert!(
                (dot + 1.0).abs() < 1e-12,
                "joint {j}: normals {na:?} {nb:?}"
            );
            // Local faces are the sides' faces.
            for s in 0..2 {
                let f = i.faces[s] as usize;
                assert_eq!(m.faces().owner[f], i.elements[s]);
                assert_eq!(m.faces().owner_local[f], i.local_faces[s]);
            }
        }
        assert_eq!(s.iter().len(), s.len());
        assert!(s.get(s.len()).is_none());
    }

    #[test]
    fn full_split_2d() {
        let m = builders::rectangle(0.0, 0.0, 1.0, 0.5, 0.1).unwrap();
        let interior = m.faces().len() - m.faces().boundary.len();
        let s = split_nodes(&m, &Range::All).unwrap();
        let j = s.interfaces();
        assert_eq!(s.n_nodes(), 3 * m.n_elements());
        assert_eq!(j.len(), interior);
        assert_eq!(j.nodes().len(), 4 * interior);
        assert_eq!(j.nodes_per_joint(), 4);
        assert_eq!(s.outer_boundary().len(), m.faces().boundary.len());
        assert_eq!(
            s.faces().boundary.len(),
            s.outer_boundary().len() + 2 * interior
        );
        check_joints(&s);
        // Groups follow: the top face group stays on the top boundary.
        let top = &s.groups().faces["top"];
        assert_eq!(top.len(), m.groups().faces["top"].len());
        for &f in top {
            let mut c = [0.0; 2];
            s.face_centroid(f as usize, &mut c);
            assert!((c[1] - 0.5).abs() < 1e-12);
        }
        let left = &s.groups().nodes["left"];
        assert!(left.iter().all(|&n| s.node(n as usize)[0].abs() < 1e-12));
        assert!(left.len() > m.groups().nodes["left"].len());
        // The outer boundary is the original one.
        for &f in &s.outer_boundary() {
            let mut c = [0.0; 2];
            s.face_centroid(f as usize, &mut c);
            assert!(
                c[0].abs() < 1e-12
                    || (c[0] - 1.0).abs() < 1e-12
                    || c[1].abs() < 1e-12
                    || (c[1] - 0.5).abs() < 1e-12
            );
        }
    }

    #[test]
    fn partial_split_keeps_fem_nodes_shared() {
        let m = builders::rectangle(0.0, 0.0, 1.0, 0.5, 0.1).unwrap();
        let s = split_nodes(&m, &Range::rect(0.0, 0.0, 0.5, 0.5)).unwrap();
        let fdem = m
            .select_elements(&Range::rect(0.0, 0.0, 0.5, 0.5))
            .unwrap()
            .len();
        assert!(s.n_nodes() < 3 * m.n_elements());
        assert!(s.n_nodes() >= 3 * fdem);
        // Joints only on faces touching an FDEM element.
        for i in s.interfaces().iter() {
            let mut c = [[0.0; 2]; 2];
            m.element_centroid(i.elements[0] as usize, &mut c[0]);
            m.element_centroid(i.elements[1] as usize, &mut c[1]);
            assert!(c[0][0] <= 0.5 || c[1][0] <= 0.5);
        }
        check_joints(&s);
    }

    #[test]
    fn full_split_3d() {
        let m = builders::cuboid([0.0; 3], [1.0, 1.0, 1.0], 0.5).unwrap();
        let interior = m.faces().len() - m.faces().boundary.len();
        let s = split_nodes(&m, &Range::All).unwrap();
        assert_eq!(s.n_nodes(), 4 * m.n_elements());
        assert_eq!(s.interfaces().len(), interior);
        assert_eq!(s.interfaces().nodes().len(), 6 * interior);
        assert_eq!(s.interfaces().nodes_per_joint(), 6);
        check_joints(&s);
    }

    #[test]
    fn no_fdem_region_means_no_joints() {
        let m = builders::rectangle(0.0, 0.0, 1.0, 0.5, 0.1).unwrap();
        assert!(!m.interfaces().is_split());
        assert_eq!(m.interfaces().master_of(7), 7);
        let s = split_nodes(&m, &Range::rect(5.0, 5.0, 6.0, 6.0)).unwrap();
        assert!(s.interfaces().is_empty());
        assert!(s.interfaces().is_split());
        assert_eq!(s.n_nodes(), m.n_nodes());
        assert_eq!(s.outer_boundary(), s.faces().boundary);
    }

    #[test]
    fn a_split_mesh_is_not_split_again_nor_joined() {
        let m = builders::rectangle(0.0, 0.0, 1.0, 0.5, 0.25).unwrap();
        let s = split_nodes(&m, &Range::All).unwrap();
        let e = split_nodes(&s, &Range::All).unwrap_err();
        assert!(matches!(e, MeshError::AlreadySplit { .. }), "{e}");
        assert!(e.to_string().contains("already split"), "{e}");
        let e = builders::union(&[&m, &s]).unwrap_err();
        assert!(matches!(e, MeshError::AlreadySplit { .. }), "{e}");
    }

    #[test]
    fn interfaces_survive_serialisation_and_are_checked() {
        let m = builders::rectangle(0.0, 0.0, 0.5, 0.5, 0.25).unwrap();
        let s = split_nodes(&m, &Range::All).unwrap();
        let json = serde_json::to_string(&s).unwrap();
        let back: Mesh<crate::Dim2> = serde_json::from_str(&json).unwrap();
        assert_eq!(back.interfaces(), s.interfaces());
        // A mesh written before interfaces existed reads with none.
        let plain = serde_json::to_string(&m).unwrap();
        let cut = plain.replace(
            ",\"interfaces\":{\"nodes\":[],\"elements\":[],\"local_faces\":[],\"faces\":[],\"master\":[]}",
            "",
        );
        assert_ne!(cut, plain);
        let old: Mesh<crate::Dim2> = serde_json::from_str(&cut).unwrap();
        assert!(old.interfaces().is_empty() && !old.interfaces().is_split());
        // Tampered interfaces are errors naming the interface.
        let j0 = s.interfaces().get(0).unwrap();
        for (from, to, what) in [
            (
                format!("\"elements\":[{},", j0.elements[0]),
                format!("\"elements\":[{},", s.n_elements() + 5),
                "interface 0 side 0",
            ),
            (
                format!("\"local_faces\":[{},", j0.local_faces[0]),
                format!("\"local_faces\":[{},", (j0.local_faces[0] + 1) % 3),
                "interface 0 side 0",
            ),
            (
                "\"master\":[".to_string(),
                "\"master\":[9999,".to_string(),
                "master map has",
            ),
        ] {
            let at = json.find("\"interfaces\"").unwrap();
            let (head, tail) = json.split_at(at);
            assert!(tail.contains(&from), "{from}: {tail}");
            let bad = format!("{head}{}", tail.replacen(&from, &to, 1));
            let e = serde_json::from_str::<Mesh<crate::Dim2>>(&bad).unwrap_err();
            assert!(e.to_string().contains(what), "{to}: {e}");
        }
    }
}
