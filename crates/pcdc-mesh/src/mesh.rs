//! The struct-of-arrays mesh: nodes, one simplex element block, faces and groups.

use std::collections::{BTreeMap, HashMap};
use std::marker::PhantomData;

use crate::{Cells, Dim, ElementKind, Interfaces, MeshError, Range};

/// Marker for "no neighbouring element" in [`Faces::neighbor`].
pub const NO_NEIGHBOR: u32 = u32::MAX;

/// Largest accepted coordinate magnitude (m): 1e100, far beyond any physical length
/// (the observable universe is about 1e27 m), and small enough that element measures
/// (products of up to three coordinate differences) cannot overflow.
pub const MAX_COORD: f64 = 1e100;

/// Relative threshold under which an element counts as degenerate: its measure is
/// compared with `DEGENERATE_REL * (longest edge)^D`.
pub const DEGENERATE_REL: f64 = 1e-10;

/// All unique element faces (edges in 2D, triangles in 3D) with their adjacency.
///
/// Face `i` has nodes `nodes[i*NPF..(i+1)*NPF]`, ordered so that its normal points out of
/// its `owner` element. `neighbor[i]` is the element on the other side, or [`NO_NEIGHBOR`]
/// for a boundary face.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Faces {
    /// Face nodes, stride `NODES_PER_FACE`, outward for the owner.
    pub nodes: Vec<u32>,
    /// Element owning the face (the first one met in element order).
    pub owner: Vec<u32>,
    /// Local face index within the owner.
    pub owner_local: Vec<u8>,
    /// Element on the other side, or [`NO_NEIGHBOR`].
    pub neighbor: Vec<u32>,
    /// Indices of the boundary faces, ascending.
    pub boundary: Vec<u32>,
}

impl Faces {
    /// Number of faces.
    pub fn len(&self) -> usize {
        self.owner.len()
    }

    /// Whether there are no faces.
    pub fn is_empty(&self) -> bool {
        self.owner.is_empty()
    }
}

/// Named groups of nodes, elements and faces (PCDC's "ranges" by set/group).
///
/// Each group is a sorted list of unique indices. Group names are free text; a common
/// convention is `set/group` when an entity must belong to groups in several sets.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Groups {
    /// Node groups.
    pub nodes: BTreeMap<String, Vec<u32>>,
    /// Element groups.
    pub elements: BTreeMap<String, Vec<u32>>,
    /// Face groups (indices into [`Faces`]).
    pub faces: BTreeMap<String, Vec<u32>>,
}

/// A mesh of one simplex element type (Tri3 in 2D, Tet4 in 3D), stored as structure of
/// arrays: `coords` with stride `D`, `elements` with stride `NODES_PER_ELEM`, indices `u32`.
///
/// Deserialising a mesh runs the checks of [`Mesh::new`] on its nodes and elements,
/// rebuilds the faces and requires the stored ones to equal them (an error names the first
/// difference), and checks every group index as [`Mesh::add_node_group`] and its siblings
/// do, and the interfaces of a split mesh as [`Mesh::interfaces`] describes them: a mesh
/// file edited by hand or corrupted is an error, never a panic later. A mesh serialised
/// without interfaces (written before they existed) reads as a mesh that was not split.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(bound = "", try_from = "RawMesh")]
pub struct Mesh<D: Dim> {
    coords: Vec<f64>,
    elements: Vec<u32>,
    faces: Faces,
    groups: Groups,
    interfaces: Interfaces,
    #[serde(default, skip_serializing_if = "Cells::is_empty")]
    cells: Cells,
    #[serde(skip)]
    _dim: PhantomData<D>,
}

/// The serialised form of a [`Mesh`], checked by `TryFrom` before it becomes one.
#[derive(serde::Deserialize)]
struct RawMesh {
    coords: Vec<f64>,
    elements: Vec<u32>,
    faces: Faces,
    groups: Groups,
    #[serde(default)]
    interfaces: Interfaces,
    #[serde(default)]
    cells: Cells,
}

impl<D: Dim> TryFrom<RawMesh> for Mesh<D> {
    type Error = MeshError;

    fn try_from(raw: RawMesh) -> Result<Self, MeshError> {
        let mut mesh = Mesh::<D>::new(raw.coords, raw.elements)?;
        if !raw.cells.is_empty() {
            mesh.cells = raw.cells.checked::<D>(&mesh.coords, &mesh.elements)?;
        }
        check_faces(&raw.faces, &mesh.faces)?;
        for (name, v) in raw.groups.nodes {
            mesh.add_node_group(name, v)?;
        }
        for (name, v) in raw.groups.elements {
            mesh.add_element_group(name, v)?;
        }
        for (name, v) in raw.groups.faces {
            mesh.add_face_group(name, v)?;
        }
        mesh.set_interfaces(raw.interfaces)?;
        Ok(mesh)
    }
}

/// Compares stored faces with the faces rebuilt from the elements; names the first
/// difference.
fn check_faces(stored: &Faces, built: &Faces) -> Result<(), MeshError> {
    fn first_diff<T: PartialEq + std::fmt::Debug>(
        field: &str,
        a: &[T],
        b: &[T],
    ) -> Result<(), MeshError> {
        if a.len() != b.len() {
            return Err(MeshError::Inconsistent(format!(
                "faces.{field} has {} entries, but the elements give {}",
                a.len(),
                b.len()
            )));
        }
        match a.iter().zip(b).position(|(x, y)| x != y) {
            Some(i) => Err(MeshError::Inconsistent(format!(
                "faces.{field}[{i}] = {:?}, but the elements give {:?}",
                a[i], b[i]
            ))),
            None => Ok(()),
        }
    }
    first_diff("nodes", &stored.nodes, &built.nodes)?;
    first_diff("owner", &stored.owner, &built.owner)?;
    first_diff("owner_local", &stored.owner_local, &built.owner_local)?;
    first_diff("neighbor", &stored.neighbor, &built.neighbor)?;
    first_diff("boundary", &stored.boundary, &built.boundary)
}

impl<D: Dim> Mesh<D> {
    /// Builds a mesh and checks it: array lengths, finite coordinates of magnitude at most
    /// [`MAX_COORD`], node indices,
    /// repeated nodes, inverted and degenerate elements, dangling nodes, manifold faces.
    ///
    /// `coords` holds `D` values per node (m); `elements` holds `NODES_PER_ELEM` node
    /// indices per element, counter-clockwise (Tri3) or positively oriented (Tet4).
    pub fn new(coords: Vec<f64>, elements: Vec<u32>) -> Result<Self, MeshError> {
        Self::build(coords, elements, false)
    }

    /// Like [`Mesh::new`] but swaps two nodes of every inverted element instead of
    /// failing (for generated or imported meshes whose orientation is arbitrary).
    pub fn new_reoriented(coords: Vec<f64>, elements: Vec<u32>) -> Result<Self, MeshError> {
        Self::build(coords, elements, true)
    }

    fn build(coords: Vec<f64>, mut elements: Vec<u32>, reorient: bool) -> Result<Self, MeshError> {
        let (d, npe) = (D::D, D::NODES_PER_ELEM);
        if coords.len() % d != 0 {
            return Err(MeshError::CoordLength {
                len: coords.len(),
                dim: d,
            });
        }
        if elements.len() % npe != 0 {
            return Err(MeshError::ConnectivityLength {
                len: elements.len(),
                per_elem: npe,
            });
        }
        if elements.is_empty() {
            return Err(MeshError::Empty);
        }
        let n_nodes = coords.len() / d;
        check_coords(&coords, d)?;
        let measure_name = if d == 2 { "area" } else { "volume" };
        let mut used = vec![false; n_nodes];
        let mut x = vec![0.0; npe * d];
        for (e, conn) in elements.chunks_exact_mut(npe).enumerate() {
            for (a, &n) in conn.iter().enumerate() {
                if n as usize >= n_nodes {
                    return Err(MeshError::BadNodeIndex {
                        element: e,
                        node: n,
                        n_nodes,
                    });
                }
                if conn[..a].contains(&n) {
                    return Err(MeshError::RepeatedNode {
                        element: e,
                        node: n,
                    });
                }
            }
            for (a, &n) in conn.iter().enumerate() {
                x[a * d..(a + 1) * d]
                    .copy_from_slice(&coords[n as usize * d..(n as usize + 1) * d]);
                used[n as usize] = true;
            }
            let mut measure = D::signed_measure(&x);
            let mut longest = 0.0f64;
            for a in 0..npe {
                for b in a + 1..npe {
                    let l2: f64 = (0..d).map(|k| (x[a * d + k] - x[b * d + k]).powi(2)).sum();
                    longest = longest.max(l2.sqrt());
                }
            }
            let threshold = DEGENERATE_REL * longest.powi(d as i32);
            if measure.is_nan() || measure.abs() <= threshold {
                return Err(MeshError::DegenerateElement {
                    element: e,
                    measure,
                    threshold,
                    measure_name,
                });
            }
            if measure < 0.0 {
                if !reorient {
                    return Err(MeshError::InvertedElement {
                        element: e,
                        measure,
                        measure_name,
                    });
                }
                conn.swap(0, 1);
                measure = -measure;
            }
        }
        if let Some(node) = used.iter().position(|u| !u) {
            return Err(MeshError::DanglingNode { node });
        }
        let faces = build_faces::<D>(&elements)?;
        Ok(Mesh {
            coords,
            elements,
            faces,
            groups: Groups::default(),
            interfaces: Interfaces::none(D::NODES_PER_FACE),
            cells: Cells::default(),
            _dim: PhantomData,
        })
    }

    /// Builds a mesh from cells of any kind of this dimension (Tri3 and Quad4 in 2D, Tet4
    /// and Hex8 in 3D, mixed freely): `kinds` holds one kind per cell, `conn` the cells'
    /// nodes concatenated, each in the order of its kind ([`ElementKind`]). Quad4 and Hex8
    /// cells are cut into simplices as [`crate::cells`] describes; the cell table is kept
    /// ([`Mesh::cells`]). Besides the checks of [`Mesh::new`], each cell is checked and an
    /// error names it ([`MeshError::BadCell`]): wrong dimension, bad or repeated node,
    /// degenerate, inverted, twisted or non-convex.
    pub fn from_cells(
        coords: Vec<f64>,
        kinds: Vec<ElementKind>,
        conn: Vec<u32>,
    ) -> Result<Self, MeshError> {
        Self::build_cells(coords, kinds, conn, false)
    }

    /// Like [`Mesh::from_cells`] but reverses the node order of inverted cells instead
    /// of failing (for imported meshes).
    pub fn from_cells_reoriented(
        coords: Vec<f64>,
        kinds: Vec<ElementKind>,
        conn: Vec<u32>,
    ) -> Result<Self, MeshError> {
        Self::build_cells(coords, kinds, conn, true)
    }

    fn build_cells(
        coords: Vec<f64>,
        kinds: Vec<ElementKind>,
        conn: Vec<u32>,
        reorient: bool,
    ) -> Result<Self, MeshError> {
        if coords.len() % D::D != 0 {
            return Err(MeshError::CoordLength {
                len: coords.len(),
                dim: D::D,
            });
        }
        check_coords(&coords, D::D)?;
        let (cells, simplices) = crate::cells::decompose::<D>(&coords, &kinds, conn, reorient)?;
        let mut mesh = Self::build(coords, simplices, false)?;
        // A mesh of simplex cells only needs no cell table.
        if cells.has_composite() {
            mesh.cells = cells;
        }
        Ok(mesh)
    }

    /// Installs the cell table of a mesh whose elements were built from it.
    pub(crate) fn set_cells(&mut self, cells: Cells) {
        self.cells = cells;
    }

    /// The cell table of a mesh built from Quad4/Hex8 cells ([`Mesh::from_cells`]);
    /// empty when every element is its own simplex cell.
    pub fn cells(&self) -> &Cells {
        &self.cells
    }

    /// Number of cells: the cell table's length, or the element count for a simplex mesh.
    pub fn n_cells(&self) -> usize {
        if self.cells.is_empty() {
            self.n_elements()
        } else {
            self.cells.len()
        }
    }

    /// Kind of cell `c`.
    pub fn cell_kind(&self, c: usize) -> ElementKind {
        if self.cells.is_empty() {
            D::ELEMENT
        } else {
            self.cells.kind(c)
        }
    }

    /// Nodes of cell `c`.
    pub fn cell_nodes(&self, c: usize) -> &[u32] {
        if self.cells.is_empty() {
            self.element(c)
        } else {
            self.cells.nodes(c)
        }
    }

    /// The simplex elements of cell `c`.
    pub fn cell_elements(&self, c: usize) -> std::ops::Range<usize> {
        if self.cells.is_empty() {
            c..c + 1
        } else {
            self.cells.elements(c)
        }
    }

    /// The cell element `e` belongs to.
    pub fn cell_of(&self, e: usize) -> usize {
        if self.cells.is_empty() {
            e
        } else {
            self.cells.cell_of(e)
        }
    }

    /// Centroid of cell `c` (the volume-weighted centroid of its simplices).
    pub fn cell_centroid(&self, c: usize, out: &mut [f64]) {
        let d = D::D;
        out[..d].fill(0.0);
        let (mut total, mut x) = (0.0, [0.0; 3]);
        for e in self.cell_elements(c) {
            let w = self.element_measure(e);
            self.element_centroid(e, &mut x[..d]);
            for k in 0..d {
                out[k] += w * x[k];
            }
            total += w;
        }
        out[..d].iter_mut().for_each(|v| *v /= total);
    }

    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.coords.len() / D::D
    }

    /// Number of elements.
    pub fn n_elements(&self) -> usize {
        self.elements.len() / D::NODES_PER_ELEM
    }

    /// Node coordinates, stride `D` (m).
    pub fn coords(&self) -> &[f64] {
        &self.coords
    }

    /// Coordinates of node `i`.
    pub fn node(&self, i: usize) -> &[f64] {
        &self.coords[i * D::D..(i + 1) * D::D]
    }

    /// Element connectivity, stride `NODES_PER_ELEM`.
    pub fn elements(&self) -> &[u32] {
        &self.elements
    }

    /// Nodes of element `e`.
    pub fn element(&self, e: usize) -> &[u32] {
        &self.elements[e * D::NODES_PER_ELEM..(e + 1) * D::NODES_PER_ELEM]
    }

    /// Faces and adjacency.
    pub fn faces(&self) -> &Faces {
        &self.faces
    }

    /// Nodes of face `f`.
    pub fn face(&self, f: usize) -> &[u32] {
        &self.faces.nodes[f * D::NODES_PER_FACE..(f + 1) * D::NODES_PER_FACE]
    }

    /// Groups.
    pub fn groups(&self) -> &Groups {
        &self.groups
    }

    /// The interfaces (face-joints) and master-node map left by [`crate::split_nodes`];
    /// none for a mesh that was not split.
    pub fn interfaces(&self) -> &Interfaces {
        &self.interfaces
    }

    /// Replaces the interfaces after checking them against this mesh.
    pub(crate) fn set_interfaces(&mut self, mut interfaces: Interfaces) -> Result<(), MeshError> {
        interfaces.check(self)?;
        self.interfaces = interfaces;
        Ok(())
    }

    /// Boundary faces that are not sides of an interface, ascending: the outer boundary
    /// of the body before splitting (all boundary faces of a mesh that was not split).
    pub fn outer_boundary(&self) -> Vec<u32> {
        let mut side = vec![false; self.faces.len()];
        for &f in self.interfaces.faces() {
            side[f as usize] = true;
        }
        self.faces
            .boundary
            .iter()
            .copied()
            .filter(|&f| !side[f as usize])
            .collect()
    }

    /// Gathers the coordinates of element `e` into `x` (`NODES_PER_ELEM * D` values).
    pub fn element_coords(&self, e: usize, x: &mut [f64]) {
        let d = D::D;
        for (a, &n) in self.element(e).iter().enumerate() {
            x[a * d..(a + 1) * d].copy_from_slice(self.node(n as usize));
        }
    }

    /// Area (2D) or volume (3D) of element `e` (m² or m³).
    pub fn element_measure(&self, e: usize) -> f64 {
        let mut x = [0.0; 12];
        self.element_coords(e, &mut x[..D::NODES_PER_ELEM * D::D]);
        D::signed_measure(&x[..D::NODES_PER_ELEM * D::D])
    }

    /// Centroid of element `e` written into `c` (length `D`).
    pub fn element_centroid(&self, e: usize, c: &mut [f64]) {
        centroid::<D>(&self.coords, self.element(e), c);
    }

    /// Centroid of face `f` written into `c` (length `D`).
    pub fn face_centroid(&self, f: usize, c: &mut [f64]) {
        centroid::<D>(&self.coords, self.face(f), c);
    }

    /// Length (2D) or area (3D) of face `f` and its outward unit normal (for the owner).
    pub fn face_measure_normal(&self, f: usize, normal: &mut [f64]) -> f64 {
        let d = D::D;
        let mut x = [0.0; 9];
        for (k, &n) in self.face(f).iter().enumerate() {
            x[k * d..(k + 1) * d].copy_from_slice(self.node(n as usize));
        }
        D::face_measure_normal(&x[..D::NODES_PER_FACE * d], normal)
    }

    /// Axis-aligned bounding box `(min, max)`, each of length `D`.
    pub fn bounding_box(&self) -> (Vec<f64>, Vec<f64>) {
        let d = D::D;
        let mut lo = vec![f64::INFINITY; d];
        let mut hi = vec![f64::NEG_INFINITY; d];
        for p in self.coords.chunks_exact(d) {
            for k in 0..d {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }

    /// Smallest and largest element edge length (m).
    pub fn edge_length_range(&self) -> (f64, f64) {
        let (d, npe) = (D::D, D::NODES_PER_ELEM);
        let mut lo = f64::INFINITY;
        let mut hi = 0.0f64;
        for conn in self.elements.chunks_exact(npe) {
            for a in 0..npe {
                for b in a + 1..npe {
                    let (p, q) = (self.node(conn[a] as usize), self.node(conn[b] as usize));
                    let l = (0..d).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>().sqrt();
                    lo = lo.min(l);
                    hi = hi.max(l);
                }
            }
        }
        (lo, hi)
    }

    /// Adds (or replaces) a node group; indices are sorted and de-duplicated.
    pub fn add_node_group(
        &mut self,
        name: impl Into<String>,
        mut nodes: Vec<u32>,
    ) -> Result<(), MeshError> {
        let name = name.into();
        check_indices("node", &name, &nodes, self.n_nodes())?;
        nodes.sort_unstable();
        nodes.dedup();
        self.groups.nodes.insert(name, nodes);
        Ok(())
    }

    /// Adds (or replaces) an element group.
    pub fn add_element_group(
        &mut self,
        name: impl Into<String>,
        mut elems: Vec<u32>,
    ) -> Result<(), MeshError> {
        let name = name.into();
        check_indices("element", &name, &elems, self.n_elements())?;
        elems.sort_unstable();
        elems.dedup();
        self.groups.elements.insert(name, elems);
        Ok(())
    }

    /// Adds (or replaces) a face group.
    pub fn add_face_group(
        &mut self,
        name: impl Into<String>,
        mut faces: Vec<u32>,
    ) -> Result<(), MeshError> {
        let name = name.into();
        check_indices("face", &name, &faces, self.faces.len())?;
        faces.sort_unstable();
        faces.dedup();
        self.groups.faces.insert(name, faces);
        Ok(())
    }

    /// Adds a node group, an element group and a boundary-face group, all named `name`,
    /// from one geometric range (nodes by position, elements and faces by centroid).
    pub fn add_groups_from_range(&mut self, name: &str, range: &Range) -> Result<(), MeshError> {
        let nodes = self.select_nodes(range)?;
        let elems = self.select_elements(range)?;
        let faces = self.select_boundary_faces(range)?;
        self.add_node_group(name, nodes)?;
        self.add_element_group(name, elems)?;
        self.add_face_group(name, faces)
    }

    fn check_range(
        &self,
        kind: &'static str,
        map: &BTreeMap<String, Vec<u32>>,
        range: &Range,
    ) -> Result<(), MeshError> {
        range.validate(D::D)?;
        let mut names = Vec::new();
        range.group_names(&mut names);
        for n in names {
            if !map.contains_key(n) {
                return Err(MeshError::UnknownGroup {
                    kind,
                    name: n.to_string(),
                });
            }
        }
        Ok(())
    }

    /// Nodes in `range` (by position), ascending.
    pub fn select_nodes(&self, range: &Range) -> Result<Vec<u32>, MeshError> {
        self.check_range("node", &self.groups.nodes, range)?;
        let g = &self.groups.nodes;
        Ok((0..self.n_nodes() as u32)
            .filter(|&i| range.contains(self.node(i as usize), &|name| member(g, name, i)))
            .collect())
    }

    /// Elements in `range` (by centroid), ascending. The simplices of a Quad4/Hex8 cell
    /// are selected together, by the cell's centroid and its first element's groups, so
    /// that a range never cuts a cell.
    pub fn select_elements(&self, range: &Range) -> Result<Vec<u32>, MeshError> {
        self.check_range("element", &self.groups.elements, range)?;
        let g = &self.groups.elements;
        let mut c = [0.0; 3];
        if !self.cells.is_empty() {
            let mut out = Vec::new();
            for cell in 0..self.cells.len() {
                let els = self.cells.elements(cell);
                let first = els.start as u32;
                self.cell_centroid(cell, &mut c[..D::D]);
                if range.contains(&c[..D::D], &|name| member(g, name, first)) {
                    out.extend(els.map(|e| e as u32));
                }
            }
            return Ok(out);
        }
        Ok((0..self.n_elements() as u32)
            .filter(|&e| {
                self.element_centroid(e as usize, &mut c[..D::D]);
                range.contains(&c[..D::D], &|name| member(g, name, e))
            })
            .collect())
    }

    /// Boundary faces in `range` (by centroid), ascending face indices.
    pub fn select_boundary_faces(&self, range: &Range) -> Result<Vec<u32>, MeshError> {
        self.select_faces_in(range, &self.faces.boundary)
    }

    /// All faces (interior and boundary) in `range` (by centroid), ascending.
    pub fn select_faces(&self, range: &Range) -> Result<Vec<u32>, MeshError> {
        let all: Vec<u32> = (0..self.faces.len() as u32).collect();
        self.select_faces_in(range, &all)
    }

    fn select_faces_in(&self, range: &Range, candidates: &[u32]) -> Result<Vec<u32>, MeshError> {
        self.check_range("face", &self.groups.faces, range)?;
        let g = &self.groups.faces;
        let mut c = [0.0; 3];
        Ok(candidates
            .iter()
            .copied()
            .filter(|&f| {
                self.face_centroid(f as usize, &mut c[..D::D]);
                range.contains(&c[..D::D], &|name| member(g, name, f))
            })
            .collect())
    }

    /// Nodes of the given faces, ascending and unique.
    pub fn nodes_of_faces(&self, faces: &[u32]) -> Vec<u32> {
        let mut v: Vec<u32> = faces
            .iter()
            .flat_map(|&f| self.face(f as usize).iter().copied())
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }
}

/// Coordinates finite and at most [`MAX_COORD`] in magnitude.
fn check_coords(coords: &[f64], d: usize) -> Result<(), MeshError> {
    if let Some(i) = coords.iter().position(|v| !v.is_finite()) {
        return Err(MeshError::NonFiniteCoordinate { node: i / d });
    }
    if let Some(i) = coords.iter().position(|v| v.abs() > MAX_COORD) {
        return Err(MeshError::CoordinateTooLarge {
            node: i / d,
            value: coords[i],
        });
    }
    Ok(())
}

fn member(map: &BTreeMap<String, Vec<u32>>, name: &str, i: u32) -> bool {
    map.get(name).is_some_and(|v| v.binary_search(&i).is_ok())
}

fn check_indices(
    kind: &'static str,
    name: &str,
    idx: &[u32],
    count: usize,
) -> Result<(), MeshError> {
    match idx.iter().find(|&&i| i as usize >= count) {
        Some(&index) => Err(MeshError::BadGroupIndex {
            kind,
            name: name.to_string(),
            index,
            count,
        }),
        None => Ok(()),
    }
}

fn centroid<D: Dim>(coords: &[f64], nodes: &[u32], c: &mut [f64]) {
    let d = D::D;
    c[..d].fill(0.0);
    for &n in nodes {
        for k in 0..d {
            c[k] += coords[n as usize * d + k];
        }
    }
    let inv = 1.0 / nodes.len() as f64;
    c[..d].iter_mut().for_each(|v| *v *= inv);
}

fn build_faces<D: Dim>(elements: &[u32]) -> Result<Faces, MeshError> {
    let (npe, npf, nfe) = (D::NODES_PER_ELEM, D::NODES_PER_FACE, D::FACES_PER_ELEM);
    let n_elem = elements.len() / npe;
    let mut map: HashMap<[u32; 3], u32> = HashMap::with_capacity(n_elem * nfe);
    let mut faces = Faces::default();
    for (e, conn) in elements.chunks_exact(npe).enumerate() {
        for f in 0..nfe {
            let ln = D::face_local_nodes(f);
            let mut key = [u32::MAX; 3];
            for (k, &l) in ln.iter().enumerate() {
                key[k] = conn[l];
            }
            key[..npf].sort_unstable();
            match map.get(&key) {
                Some(&fi) => {
                    let fi = fi as usize;
                    if faces.neighbor[fi] != NO_NEIGHBOR {
                        return Err(MeshError::NonManifoldFace {
                            nodes: key[..npf].to_vec(),
                            element: e,
                        });
                    }
                    faces.neighbor[fi] = e as u32;
                }
                None => {
                    map.insert(key, faces.owner.len() as u32);
                    faces.nodes.extend(ln.iter().map(|&l| conn[l]));
                    faces.owner.push(e as u32);
                    faces.owner_local.push(f as u8);
                    faces.neighbor.push(NO_NEIGHBOR);
                }
            }
        }
    }
    faces.boundary = (0..faces.owner.len() as u32)
        .filter(|&f| faces.neighbor[f as usize] == NO_NEIGHBOR)
        .collect();
    Ok(faces)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Dim2, Dim3};

    fn square() -> Mesh<Dim2> {
        // Unit square cut on the diagonal.
        Mesh::new(
            vec![0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0],
            vec![0, 1, 2, 0, 2, 3],
        )
        .unwrap()
    }

    #[test]
    fn faces_and_boundary() {
        let m = square();
        assert_eq!(m.faces().len(), 5);
        assert_eq!(m.faces().boundary.len(), 4);
        let total: f64 = (0..m.n_elements()).map(|e| m.element_measure(e)).sum();
        assert!((total - 1.0).abs() < 1e-15);
    }

    #[test]
    fn inverted_triangle_is_an_error_naming_the_element() {
        let err = Mesh::<Dim2>::new(
            vec![0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0],
            vec![0, 1, 2, 0, 3, 2],
        )
        .unwrap_err();
        assert!(
            matches!(err, MeshError::InvertedElement { element: 1, .. }),
            "{err}"
        );
        assert!(err.to_string().contains("element 1"));
        let fixed = Mesh::<Dim2>::new_reoriented(
            vec![0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0],
            vec![0, 1, 2, 0, 3, 2],
        )
        .unwrap();
        assert!(fixed.element_measure(1) > 0.0);
    }

    #[test]
    fn degenerate_bad_index_dangling() {
        let e = Mesh::<Dim2>::new(vec![0.0, 0.0, 1.0, 0.0, 2.0, 0.0], vec![0, 1, 2]).unwrap_err();
        assert!(matches!(e, MeshError::DegenerateElement { element: 0, .. }));
        let e = Mesh::<Dim2>::new(vec![0.0, 0.0, 1.0, 0.0, 0.0, 1.0], vec![0, 1, 7]).unwrap_err();
        assert!(matches!(
            e,
            MeshError::BadNodeIndex {
                element: 0,
                node: 7,
                ..
            }
        ));
        let e = Mesh::<Dim2>::new(vec![0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 5.0, 5.0], vec![0, 1, 2])
            .unwrap_err();
        assert!(matches!(e, MeshError::DanglingNode { node: 3 }));
        let e =
            Mesh::<Dim2>::new(vec![0.0, 0.0, 1.0, f64::NAN, 0.0, 1.0], vec![0, 1, 2]).unwrap_err();
        assert!(matches!(e, MeshError::NonFiniteCoordinate { node: 1 }));
        let e = Mesh::<Dim2>::new(vec![0.0, 0.0, 1.0], vec![0, 1, 2]).unwrap_err();
        assert!(matches!(e, MeshError::CoordLength { .. }));
    }

    #[test]
    fn deserialisation_checks_like_new() {
        let mut m = square();
        m.add_node_group("left", vec![0, 3]).unwrap();
        let json = serde_json::to_string(&m).unwrap();
        let back: Mesh<Dim2> = serde_json::from_str(&json).unwrap();
        assert_eq!(back.coords(), m.coords());
        assert_eq!(back.faces(), m.faces());
        assert_eq!(back.groups().nodes["left"], vec![0, 3]);
        for (from, to, what) in [
            (
                "\"elements\":[0,1,2,",
                "\"elements\":[0,1,9,",
                "refers to node 9",
            ),
            ("\"elements\":[0,1,2,", "\"elements\":[0,2,1,", "inverted"),
            ("\"owner\":[0,", "\"owner\":[1,", "faces.owner[0]"),
            ("\"left\":[0,3]", "\"left\":[0,7]", "index 7"),
            ("\"coords\":[0.0,0.0,", "\"coords\":[0.0,", "not a multiple"),
        ] {
            assert!(json.contains(from), "{json}");
            let bad = json.replacen(from, to, 1);
            let e = serde_json::from_str::<Mesh<Dim2>>(&bad).unwrap_err();
            assert!(e.to_string().contains(what), "{to}: {e}");
        }
    }

    #[test]
    fn tet_mesh_faces() {
        let coords = vec![
            0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0,
        ];
        let m = Mesh::<Dim3>::new_reoriented(coords, vec![0, 1, 2, 3, 1, 2, 3, 4]).unwrap();
        assert_eq!(m.faces().len(), 7);
        assert_eq!(m.faces().boundary.len(), 6);
        assert!(m.element_measure(1) > 0.0);
    }

    #[test]
    fn ranges_select() {
        let mut m = square();
        let left = m
            .select_nodes(&Range::plane([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], 1e-9))
            .unwrap();
        assert_eq!(left, vec![0, 3]);
        m.add_node_group("left", left).unwrap();
        let sel = m
            .select_nodes(&Range::group("left").or(Range::Ball {
                center: [1.0, 1.0, 0.0],
                radius: 0.1,
            }))
            .unwrap();
        assert_eq!(sel, vec![0, 2, 3]);
        let top = m
            .select_boundary_faces(&Range::rect(-1.0, 0.9, 2.0, 1.1))
            .unwrap();
        assert_eq!(m.nodes_of_faces(&top), vec![2, 3]);
        let custom = m.select_elements(&Range::custom(|x| x[0] > x[1])).unwrap();
        assert_eq!(custom, vec![0]);
        assert!(matches!(
            m.select_nodes(&Range::group("nope")),
            Err(MeshError::UnknownGroup { .. })
        ));
        assert!(m
            .select_nodes(&Range::plane([0.0; 3], [0.0; 3], 1.0))
            .is_err());
        assert!(m.add_node_group("bad", vec![99]).is_err());
    }
}
