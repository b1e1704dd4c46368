//! Where contact cannot happen: pairs inside intact rock.
//!
//! Two elements glued to each other by intact cohesive joints cannot interpenetrate
//! beyond the joints' own overlap penalty, so contact between them is work without
//! effect. The contact physics skips, on both backends:
//!
//! 1. pairs bonded through a face whose joint is intact (as before, from
//!    [`crate::Contact::bonded_pairs`] / [`crate::Contact::bonded_interfaces`]);
//! 2. pairs that share a vertex (the same master node of the split mesh) whose fan is
//!    **intact**: the bonds around the vertex, with the faces of elements that share the
//!    node itself, connect all elements of the fan, and no bond at the vertex is broken;
//! 3. every pair with a **sealed** element: one whose vertices are all **closed**, i.e.
//!    intact and with every element face at the vertex glued (by a bond or shared by two
//!    elements of a continuous region). A sealed element is surrounded by glued elements
//!    at every face and every corner; another element reaches it only through them.
//!
//! The rules are symmetric in the two elements, so both elements of a pair agree on
//! whether it is evaluated and action equals reaction. Bonds only ever break, so a pair
//! that is skipped was skipped since the start and its history is empty.
//!
//! Static data (the vertex of every element corner, the bond faces at every vertex, the
//! fan's connectivity and completeness) is derived once from the mesh and the bonds; the
//! per-vertex flags are recomputed every step from the broken-bond field (one pass over
//! the vertices, a gather, deterministic).

use pcdc_mesh::{Dim, Mesh, NO_NEIGHBOR};
use rayon::prelude::*;

/// Vertex flag: the fan is connected by glued faces and none of its bonds is broken.
pub(crate) const INTACT: u32 = 1;
/// Vertex flag: intact, and every element face at the vertex is glued.
pub(crate) const CLOSED: u32 = 2;

/// Static flag: the fan's elements are connected through glued faces.
const CONNECTED: u32 = 1;
/// Static flag: every element face at the vertex is glued.
const COMPLETE: u32 = 2;

/// The vertex topology of the bonded regions (see the module docs).
#[derive(Clone, Debug, Default)]
pub(crate) struct BondedRegions {
    /// Nodes per element.
    npe: usize,
    /// Per element corner (stride `npe`), its vertex (dense index).
    pub elem_vertex: Vec<u32>,
    /// Per vertex, CSR pointers into `vertex_faces`.
    pub vertex_ptr: Vec<u32>,
    /// The broken-field faces of the bonds at each vertex.
    pub vertex_faces: Vec<u32>,
    /// Per vertex, [`CONNECTED`] | [`COMPLETE`] bits.
    pub vertex_static: Vec<u32>,
    /// Per vertex, this step's [`INTACT`] | [`CLOSED`] bits.
    pub flags: Vec<u32>,
}

/// Union-find root with path halving.
fn root(parent: &mut [u32], mut a: u32) -> u32 {
    while parent[a as usize] != a {
        let p = parent[parent[a as usize] as usize];
        parent[a as usize] = p;
        a = p;
    }
    a
}

impl BondedRegions {
    /// Derives the vertex topology of `mesh` with bonds `elements` (two per bond) across
    /// the faces `faces` (one per bond, the index checked in the broken field). Vertices
    /// are the mesh's master nodes (the nodes themselves when the mesh was not split).
    pub fn new<D: Dim>(mesh: &Mesh<D>, elements: &[u32], faces: &[u32]) -> Self {
        let npe = D::NODES_PER_ELEM;
        let ne = mesh.n_elements();
        let interfaces = mesh.interfaces();
        // Dense vertex ids of the master nodes, in order of first appearance.
        let mut dense = vec![u32::MAX; mesh.n_nodes()];
        let mut nv = 0u32;
        let elem_vertex: Vec<u32> = mesh
            .elements()
            .iter()
            .map(|&n| {
                let m = interfaces.master_of(n) as usize;
                if dense[m] == u32::MAX {
                    dense[m] = nv;
                    nv += 1;
                }
                dense[m]
            })
            .collect();
        let nv = nv as usize;
        let vertices = |e: usize| &elem_vertex[e * npe..(e + 1) * npe];
        // Glued faces: bonds (deduplicated) and faces shared by two elements.
        let mut bonds: Vec<(u32, u32, u32)> = elements
            .chunks_exact(2)
            .zip(faces)
            .map(|(p, &face)| (p[0].min(p[1]), p[0].max(p[1]), face))
            .filter(|&(a, b, _)| a != b)
            .collect();
        bonds.sort_unstable();
        bonds.dedup_by_key(|b| (b.0, b.1));
        let f = mesh.faces();
        let shared = f
            .neighbor
            .iter()
            .zip(&f.owner)
            .filter(|(&nb, _)| nb != NO_NEIGHBOR)
            .map(|(&nb, &ow)| (ow, nb));
        // Per vertex: glued face incidences (two per glued face), bonds' faces, and the
        // element pairs glued at it.
        let mut covered = vec![0usize; nv];
        let mut per_vertex: Vec<Vec<u32>> = vec![Vec::new(); nv];
        let mut glued_pairs: Vec<(u32, u32, u32)> = Vec::new();
        let shared_at = |a: u32, b: u32| -> Vec<u32> {
            vertices(a as usize)
                .iter()
                .filter(|v| vertices(b as usize).contains(v))
                .copied()
                .collect()
        };
        for &(a, b, face) in &bonds {
            for v in shared_at(a, b) {
                covered[v as usize] += 2;
                per_vertex[v as usize].push(face);
                glued_pairs.push((v, a, b));
            }
        }
        for (a, b) in shared {
            for v in shared_at(a, b) {
                covered[v as usize] += 2;
                glued_pairs.push((v, a, b));
            }
        }
        // Element face incidences per vertex: each corner lies on D faces of its element.
        let mut incidences = vec![0usize; nv];
        let mut fan: Vec<Vec<u32>> = vec![Vec::new(); nv];
        for e in 0..ne {
            for &v in vertices(e) {
                incidences[v as usize] += D::D;
                fan[v as usize].push(e as u32);
            }
        }
        // Connectivity of each fan through its glued pairs (union-find over elements).
        let mut parent: Vec<u32> = (0..ne as u32).collect();
        glued_pairs.sort_unstable();
        let mut connected = vec![true; nv];
        let mut k = 0;
        for v in 0..nv {
            let start = k;
            while k < glued_pairs.len() && glued_pairs[k].0 as usize == v {
                let (_, a, b) = glued_pairs[k];
                let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                parent[ra.max(rb) as usize] = ra.min(rb);
                k += 1;
            }
            let r0 = root(&mut parent, fan[v][0]);
            connected[v] = fan[v].iter().all(|&e| root(&mut parent, e) == r0);
            // Reset the touched elements for the next vertex.
            for &e in &fan[v] {
                parent[e as usize] = e;
            }
            for g in &glued_pairs[start..k] {
                parent[g.1 as usize] = g.1;
                parent[g.2 as usize] = g.2;
            }
        }
        let vertex_static: Vec<u32> = (0..nv)
            .map(|v| {
                let mut s = 0;
                if connected[v] {
                    s |= CONNECTED;
                }
                if covered[v] == incidences[v] {
                    s |= COMPLETE;
                }
                s
            })
            .collect();
        let mut vertex_ptr = vec![0u32; nv + 1];
        let mut vertex_faces = Vec::new();
        for (v, list) in per_vertex.iter_mut().enumerate() {
            list.sort_unstable();
            vertex_faces.extend_from_slice(list);
            vertex_ptr[v + 1] = vertex_faces.len() as u32;
        }
        BondedRegions {
            npe,
            elem_vertex,
            vertex_ptr,
            vertex_faces,
            vertex_static,
            flags: vec![0; nv],
        }
    }

    /// Number of vertices.
    pub fn n_vertices(&self) -> usize {
        self.vertex_static.len()
    }

    /// This step's vertex flags from the broken-bond field (0 = bond intact).
    pub fn update(&mut self, broken: &[f64]) {
        let (ptr, faces, stat) = (&self.vertex_ptr, &self.vertex_faces, &self.vertex_static);
        self.flags
            .par_iter_mut()
            .enumerate()
            .with_min_len(4096)
            .for_each(|(v, flag)| {
                *flag = vertex_flags(stat[v], || {
                    faces[ptr[v] as usize..ptr[v + 1] as usize]
                        .iter()
                        .all(|&f| broken[f as usize] == 0.0)
                });
            });
    }

    /// Whether every vertex of element `e` is closed (see the module docs).
    #[inline]
    pub fn sealed(&self, e: usize) -> bool {
        self.elem_vertex[e * self.npe..(e + 1) * self.npe]
            .iter()
            .all(|&v| self.flags[v as usize] & CLOSED != 0)
    }

    /// Whether elements `e` and `f` share an intact vertex.
    #[inline]
    pub fn share_intact_vertex(&self, e: usize, f: usize) -> bool {
        let vf = &self.elem_vertex[f * self.npe..(f + 1) * self.npe];
        self.elem_vertex[e * self.npe..(e + 1) * self.npe]
            .iter()
            .any(|v| vf.contains(v) && self.flags[*v as usize] & INTACT != 0)
    }
}

/// A vertex's flags from its static bits and whether all its bonds hold.
#[inline]
fn vertex_flags(stat: u32, bonds_hold: impl FnOnce() -> bool) -> u32 {
    if stat & CONNECTED == 0 || !bonds_hold() {
        return 0;
    }
    if stat & COMPLETE != 0 {
        INTACT | CLOSED
    } else {
        INTACT
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pcdc_mesh::{builders, split_nodes, Dim2, Dim3, Range};

    fn regions<D: Dim>(mesh: &Mesh<D>) -> BondedRegions {
        let i = mesh.interfaces();
        let faces: Vec<u32> = i.faces().iter().step_by(2).copied().collect();
        BondedRegions::new(mesh, i.elements(), &faces)
    }

    /// In an intact split block, interior elements are sealed, boundary ones are not,
    /// and all corner neighbours share an intact vertex; breaking one bond opens the
    /// vertices of its face, unseals the elements around them and lets the pairs that
    /// share only those vertices through.
    #[test]
    fn intact_block_then_one_broken_bond() {
        let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.25).unwrap();
        let split = split_nodes(&mesh, &Range::All).unwrap();
        let mut r = regions(&split);
        let nf = split.faces().len();
        r.update(&vec![0.0; nf]);
        let ne = split.n_elements();
        let on_boundary = |e: usize| {
            split.element(e).iter().any(|&n| {
                let m = split.interfaces().master_of(n) as usize;
                let x = mesh.coords()[2 * m];
                let y = mesh.coords()[2 * m + 1];
                x.min(y) < 1e-9 || x.max(y) > 1.0 - 1e-9
            })
        };
        for e in 0..ne {
            assert_eq!(r.sealed(e), !on_boundary(e), "element {e}");
        }
        // Every pair sharing a vertex is skipped.
        for e in 0..ne {
            for f in 0..ne {
                let share = r.elem_vertex[3 * e..3 * e + 3]
                    .iter()
                    .any(|v| r.elem_vertex[3 * f..3 * f + 3].contains(v));
                if e != f && share {
                    assert!(r.share_intact_vertex(e, f));
                }
            }
        }
        // Break the bond of one interior interface: its vertices open.
        let i = split.interfaces();
        let j = (0..i.len())
            .find(|&j| {
                let [a, b] = i.get(j).unwrap().elements;
                !on_boundary(a as usize) && !on_boundary(b as usize)
            })
            .unwrap();
        let mut broken = vec![0.0; nf];
        broken[i.faces()[2 * j] as usize] = 1.0;
        r.update(&broken);
        let [a, b] = i.get(j).unwrap().elements;
        assert!(!r.sealed(a as usize) && !r.sealed(b as usize));
        assert!(!r.share_intact_vertex(a as usize, b as usize));
        // An element that touches neither vertex of the broken face stays sealed.
        let face_vertices: Vec<u32> = i
            .get(j)
            .unwrap()
            .side_a
            .iter()
            .map(|&n| dense_of(&r, &split, n))
            .collect();
        for e in 0..ne {
            let touches = r.elem_vertex[3 * e..3 * e + 3]
                .iter()
                .any(|v| face_vertices.contains(v));
            if !on_boundary(e) && !touches {
                assert!(r.sealed(e), "element {e}");
            }
            if touches {
                assert!(!r.sealed(e), "element {e}");
            }
        }
    }

    /// The dense vertex of node `n` (through any element corner that holds it).
    fn dense_of<D: Dim>(r: &BondedRegions, mesh: &Mesh<D>, n: u32) -> u32 {
        let k = mesh.elements().iter().position(|&m| m == n).unwrap();
        r.elem_vertex[k]
    }

    /// Without bonds nothing is skipped; in an unsplit (continuous) mesh interior
    /// elements are sealed by their shared faces.
    #[test]
    fn no_bonds_and_continuous_meshes() {
        let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.25).unwrap();
        let split = split_nodes(&mesh, &Range::All).unwrap();
        let mut r = BondedRegions::new(&split, &[], &[]);
        r.update(&vec![0.0; split.faces().len()]);
        for e in 0..split.n_elements() {
            assert!(!r.sealed(e));
            for f in 0..split.n_elements() {
                assert!(!r.share_intact_vertex(e, f) || e == f);
            }
        }
        let mut c = BondedRegions::new(&mesh, &[], &[]);
        c.update(&[]);
        assert!((0..mesh.n_elements()).any(|e| c.sealed(e)));
    }

    /// 3D: interior tetrahedra of an intact split cuboid are sealed, boundary ones not.
    #[test]
    fn intact_cuboid_3d() {
        let mesh = builders::cuboid([0.0; 3], [1.0; 3], 0.25).unwrap();
        let split = split_nodes(&mesh, &Range::All).unwrap();
        let mut r = regions(&split);
        r.update(&vec![0.0; split.faces().len()]);
        let mut sealed = 0;
        for e in 0..split.n_elements() {
            let on_boundary = split.element(e).iter().any(|&n| {
                let m = split.interfaces().master_of(n) as usize;
                (0..3).any(|k| {
                    let x = mesh.coords()[3 * m + k];
                    !(1e-9..=1.0 - 1e-9).contains(&x)
                })
            });
            assert_eq!(r.sealed(e), !on_boundary, "tet {e}");
            sealed += r.sealed(e) as usize;
        }
        assert!(sealed > 0);
        // Two tetrahedra pinched at one vertex only are not connected through it.
        let coords = vec![
            0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, -1.0,
            0.0, 0.0, 0.0, -1.0,
        ];
        let pinch = Mesh::<Dim3>::new_reoriented(coords, vec![0, 1, 2, 3, 0, 4, 5, 6]).unwrap();
        let mut p = BondedRegions::new(&pinch, &[], &[]);
        p.update(&[]);
        assert!(!p.share_intact_vertex(0, 1));
    }

    /// Meshes that are not a structured pattern (a disc and a plate with a hole, graded,
    /// 2D; a cylinder, 3D): an element is sealed exactly when none of its corners lies
    /// on the boundary of the original mesh, and all elements sharing a corner share an
    /// intact vertex.
    #[test]
    fn sealed_iff_away_from_the_boundary_on_graded_meshes() {
        fn check<D: Dim>(mesh: &Mesh<D>) {
            let f = mesh.faces();
            let mut on_boundary = vec![false; mesh.n_nodes()];
            for (i, &nb) in f.neighbor.iter().enumerate() {
                if nb == NO_NEIGHBOR {
                    for &n in mesh.face(i) {
                        on_boundary[n as usize] = true;
                    }
                }
            }
            let split = split_nodes(mesh, &Range::All).unwrap();
            let mut r = regions(&split);
            r.update(&vec![0.0; split.faces().len()]);
            let npe = D::NODES_PER_ELEM;
            let master = |n: u32| split.interfaces().master_of(n) as usize;
            let mut sealed = 0;
            for e in 0..split.n_elements() {
                let touches = split.element(e).iter().any(|&n| on_boundary[master(n)]);
                assert_eq!(r.sealed(e), !touches, "element {e}");
                sealed += r.sealed(e) as usize;
            }
            assert!(sealed > 0);
            for e in 0..split.n_elements().min(200) {
                for g in 0..split.n_elements() {
                    let share = r.elem_vertex[npe * e..npe * (e + 1)]
                        .iter()
                        .any(|v| r.elem_vertex[npe * g..npe * (g + 1)].contains(v));
                    assert_eq!(r.share_intact_vertex(e, g), share, "{e} {g}");
                }
            }
        }
        check(&builders::disc([0.0, 0.0], 1.0, 0.15).unwrap());
        check(&builders::plate_with_hole(1.0, 1.0, 0.2, 0.05, 0.2).unwrap());
        check(&builders::cylinder(0.5, 1.0, 0.25).unwrap());
    }

    /// Two triangles touching only at a vertex (no glued face) are not connected there.
    #[test]
    fn pinched_triangles_are_not_connected() {
        let coords = vec![0.0, 0.0, 1.0, 0.0, 0.0, 1.0, -1.0, 0.0, 0.0, -1.0];
        let mesh = Mesh::<Dim2>::new(coords, vec![0, 1, 2, 0, 3, 4]).unwrap();
        let mut r = BondedRegions::new(&mesh, &[], &[]);
        r.update(&[]);
        assert!(!r.share_intact_vertex(0, 1));
        assert!(!r.sealed(0) && !r.sealed(1));
    }
}
