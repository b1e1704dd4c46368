//! Cells: the elements a user meshes with (Tri3, Quad4 in 2D; Tet4, Hex8 in 3D) and the
//! simplices they are computed on.
//!
//! The computational elements of a [`Mesh`](crate::Mesh) are simplices. A Quad4 is cut
//! into two triangles along its shorter diagonal; a Hex8 into five or six tetrahedra
//! whose face diagonals follow the *lowest node index* rule (every quadrilateral face is
//! cut through its node of lowest index), so that the cuts of two hexahedra sharing a
//! face always match and the tetrahedra form a conforming mesh whatever the node
//! numbering (Dompierre et al. 1999, *How to subdivide pyramids, prisms and hexahedra
//! into tetrahedra*). The simplices of a cell are consecutive elements; the mechanics
//! couples them by the mixed discretisation of Marti and Cundall (1982) — the deviatoric
//! strain is each simplex's own, the volumetric strain the cell's volume-weighted mean —
//! so that the cell does not lock under incompressible plastic flow, as FLAC's zones do.
//! The FDEM node split keeps a cell whole: joints go on cell faces, never inside a cell.
//!
//! Cell checks name the cell: wrong node count or dimension, repeated nodes, a
//! degenerate cell, an inverted one (all corner Jacobians negative: the node order is
//! reversed), a twisted or non-convex one (corner Jacobians of both signs).

use crate::{Dim, ElementKind, MeshError, DEGENERATE_REL};

/// The cells of a mesh built from Quad4/Hex8 (or mixed) cells: their kinds, nodes and the
/// consecutive simplex elements each is cut into.
///
/// A mesh built from simplices only has no cell table ([`Cells::is_empty`]); every
/// element is then its own cell.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Cells {
    kinds: Vec<ElementKind>,
    nodes: Vec<u32>,
    first_element: Vec<u32>,
    #[serde(skip)]
    node_start: Vec<u32>,
    #[serde(skip)]
    cell_of: Vec<u32>,
}

impl Cells {
    /// Number of cells (0 for a simplex-only mesh, which has no cell table).
    pub fn len(&self) -> usize {
        self.kinds.len()
    }

    /// Whether there is no cell table (every element is its own simplex cell).
    pub fn is_empty(&self) -> bool {
        self.kinds.is_empty()
    }

    /// Kind of cell `c`.
    pub fn kind(&self, c: usize) -> ElementKind {
        self.kinds[c]
    }

    /// Kinds of all cells.
    pub fn kinds(&self) -> &[ElementKind] {
        &self.kinds
    }

    /// Nodes of cell `c`, in the order of its kind.
    pub fn nodes(&self, c: usize) -> &[u32] {
        &self.nodes[self.node_start[c] as usize..self.node_start[c + 1] as usize]
    }

    /// All cell nodes, concatenated in cell order.
    pub fn all_nodes(&self) -> &[u32] {
        &self.nodes
    }

    /// The simplex elements of cell `c`.
    pub fn elements(&self, c: usize) -> std::ops::Range<usize> {
        self.first_element[c] as usize..self.first_element[c + 1] as usize
    }

    /// The cell element `e` belongs to.
    pub fn cell_of(&self, e: usize) -> usize {
        self.cell_of[e] as usize
    }

    /// Whether some cell is cut into more than one simplex (a Quad4 or Hex8).
    pub fn has_composite(&self) -> bool {
        self.kinds.iter().any(|k| !k.is_simplex())
    }

    /// Checks a deserialised cell table against the mesh's simplices `elements` and
    /// `coords` and fills in the derived indices: every cell valid as
    /// [`crate::Mesh::from_cells`] checks it, its elements consecutive, using only its
    /// nodes and filling its measure.
    pub(crate) fn checked<D: Dim>(
        mut self,
        coords: &[f64],
        elements: &[u32],
    ) -> Result<Cells, MeshError> {
        let bad = |m: String| Err(MeshError::Inconsistent(format!("cells: {m}")));
        let npe = D::NODES_PER_ELEM;
        let ne = elements.len() / npe;
        let nc = self.kinds.len();
        let fe = &self.first_element;
        if fe.len() != nc + 1
            || fe[0] != 0
            || fe[nc] as usize != ne
            || fe.windows(2).any(|w| w[1] <= w[0])
        {
            return bad(format!(
                "first_element must rise strictly from 0 to the {ne} elements over {nc} cells"
            ));
        }
        let (decomposed, simplices) =
            decompose::<D>(coords, &self.kinds, self.nodes.clone(), false)?;
        self.node_start = decomposed.node_start.clone();
        self.cell_of = Vec::with_capacity(ne);
        let d = D::D;
        let measure = |conn: &[u32]| {
            let mut x = [0.0; 12];
            for (a, &n) in conn.iter().enumerate() {
                x[a * d..(a + 1) * d]
                    .copy_from_slice(&coords[n as usize * d..(n as usize + 1) * d]);
            }
            D::signed_measure(&x[..npe * d])
        };
        for c in 0..nc {
            let nodes = &self.nodes[self.node_start[c] as usize..self.node_start[c + 1] as usize];
            let own = &elements[fe[c] as usize * npe..fe[c + 1] as usize * npe];
            if let Some(n) = own.iter().find(|n| !nodes.contains(n)) {
                return bad(format!(
                    "an element of cell {c} uses node {n}, not a node of the cell"
                ));
            }
            let cut = decomposed.elements(c);
            let want: f64 = simplices[cut.start * npe..cut.end * npe]
                .chunks_exact(npe)
                .map(measure)
                .sum();
            let got: f64 = own.chunks_exact(npe).map(measure).sum();
            if (got - want).abs() > 1e-9 * want.abs() {
                return bad(format!(
                    "the elements of cell {c} measure {got:e}, the cell {want:e}"
                ));
            }
            self.cell_of
                .extend(std::iter::repeat_n(c as u32, (fe[c + 1] - fe[c]) as usize));
        }
        Ok(self)
    }

    /// Renumbers the nodes (`map[old] = new`) of a cell table already decomposed.
    pub(crate) fn with_nodes(&self, nodes: Vec<u32>) -> Cells {
        Cells {
            nodes,
            ..self.clone()
        }
    }
}

/// Builds the cell table and the simplex connectivity of the cells `kinds` with nodes
/// `conn` (concatenated, each cell's nodes in the order of its kind). `coords` must have
/// passed the coordinate checks. With `reorient`, inverted cells have their node order
/// reversed instead of failing.
pub(crate) fn decompose<D: Dim>(
    coords: &[f64],
    kinds: &[ElementKind],
    mut conn: Vec<u32>,
    reorient: bool,
) -> Result<(Cells, Vec<u32>), MeshError> {
    let d = D::D;
    let n_nodes = coords.len() / d;
    let total: usize = kinds.iter().map(|k| k.n_nodes()).sum();
    if total != conn.len() {
        return Err(MeshError::Inconsistent(format!(
            "the {} cells need {total} node indices, but {} are given",
            kinds.len(),
            conn.len()
        )));
    }
    if kinds.is_empty() {
        return Err(MeshError::Empty);
    }
    let mut node_start = Vec::with_capacity(kinds.len() + 1);
    let mut first_element = Vec::with_capacity(kinds.len() + 1);
    let mut simplices: Vec<u32> = Vec::with_capacity(conn.len() * 3);
    let mut start = 0usize;
    for (c, &kind) in kinds.iter().enumerate() {
        let bad = |reason: String| MeshError::BadCell {
            cell: c,
            kind,
            reason,
        };
        if kind.dim() != d {
            return Err(bad(format!("is a {}D cell in a {d}D mesh", kind.dim())));
        }
        let nodes = &mut conn[start..start + kind.n_nodes()];
        for (a, &n) in nodes.iter().enumerate() {
            if n as usize >= n_nodes {
                return Err(bad(format!(
                    "refers to node {n}, but the mesh has {n_nodes} nodes"
                )));
            }
            if nodes[..a].contains(&n) {
                return Err(bad(format!("repeats node {n}")));
            }
        }
        let x = |n: u32| &coords[n as usize * d..(n as usize + 1) * d];
        let longest = nodes
            .iter()
            .flat_map(|&a| nodes.iter().map(move |&b| (a, b)))
            .map(|(a, b)| dist(x(a), x(b)))
            .fold(0.0f64, f64::max);
        let threshold = DEGENERATE_REL * longest.powi(d as i32);
        let corners = corner_measures(kind, nodes, coords, d);
        let (pos, neg) = (
            corners.iter().filter(|&&m| m > threshold).count(),
            corners.iter().filter(|&&m| m < -threshold).count(),
        );
        if neg == corners.len() {
            if !reorient {
                return Err(bad(
                    "is inverted (its corner Jacobians are all negative): list its nodes \
                     counter-clockwise (Quad4, Tri3) or with the bottom face counter-clockwise \
                     seen from the top (Hex8, Tet4)"
                        .into(),
                ));
            }
            reverse(kind, nodes);
        } else if pos != corners.len() {
            let worst = corners.iter().copied().fold(f64::INFINITY, f64::min);
            return Err(bad(if neg == 0 {
                format!(
                    "is degenerate (smallest corner {} {worst:e}, below {threshold:e})",
                    if d == 2 { "area" } else { "volume" }
                )
            } else {
                format!(
                    "is twisted or non-convex: its corner Jacobians have both signs \
                     (smallest {worst:e}); check the node order and the shape"
                )
            }));
        }
        node_start.push(start as u32);
        first_element.push((simplices.len() / D::NODES_PER_ELEM) as u32);
        let nodes = &conn[start..start + kind.n_nodes()];
        let from = simplices.len();
        split_cell(kind, nodes, coords, &mut simplices);
        // Each simplex has the orientation it has in the reference cell (the unit square
        // or cube); one that is flipped or flat in the real cell means a twisted cell,
        // which the corner Jacobians alone miss for a hexahedron whose top face is turned.
        for s in simplices[from..].chunks_exact_mut(D::NODES_PER_ELEM) {
            let (mut xs, mut xr) = ([0.0; 12], [0.0; 12]);
            for (a, &n) in s.iter().enumerate() {
                xs[a * d..(a + 1) * d].copy_from_slice(x(n));
                let l = nodes.iter().position(|&m| m == n).expect("a cell node");
                xr[a * d..(a + 1) * d].copy_from_slice(&reference_point(kind, l)[..d]);
            }
            let npe = D::NODES_PER_ELEM;
            let sign = D::signed_measure(&xr[..npe * d]).signum();
            let m = sign * D::signed_measure(&xs[..npe * d]);
            if m.is_nan() || m <= threshold {
                return Err(bad(format!(
                    "is twisted or degenerate: one of its {} has {} {m:e} (below {threshold:e})",
                    if d == 2 { "triangles" } else { "tetrahedra" },
                    if d == 2 { "area" } else { "volume" }
                )));
            }
            if sign < 0.0 {
                s.swap(0, 1);
            }
        }
        start += kind.n_nodes();
    }
    node_start.push(start as u32);
    let n_elem = simplices.len() / D::NODES_PER_ELEM;
    first_element.push(n_elem as u32);
    if n_elem > u32::MAX as usize {
        return Err(MeshError::Inconsistent(
            "too many elements for 32-bit indices".into(),
        ));
    }
    let mut cell_of = Vec::with_capacity(n_elem);
    for c in 0..kinds.len() {
        cell_of.extend(std::iter::repeat_n(
            c as u32,
            (first_element[c + 1] - first_element[c]) as usize,
        ));
    }
    Ok((
        Cells {
            kinds: kinds.to_vec(),
            nodes: conn,
            node_start,
            first_element,
            cell_of,
        },
        simplices,
    ))
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (p - q) * (p - q))
        .sum::<f64>()
        .sqrt()
}

/// Corner of a Hex8 in Gmsh order as (x, y, z) bits of the unit cube.
const HEX_BITS: [u8; 8] = [0b000, 0b001, 0b011, 0b010, 0b100, 0b101, 0b111, 0b110];

/// Local Hex8 node at cube bits `b` (bit 0 x, bit 1 y, bit 2 z).
fn hex_local(b: u8) -> usize {
    HEX_BITS.iter().position(|&h| h == b).expect("3 bits")
}

/// Local node `l` of a reference cell: the unit square or cube, or the unit simplex.
fn reference_point(kind: ElementKind, l: usize) -> [f64; 3] {
    match kind {
        ElementKind::Tri3 | ElementKind::Tet4 => {
            let mut p = [0.0; 3];
            if l > 0 {
                p[l - 1] = 1.0;
            }
            p
        }
        ElementKind::Quad4 | ElementKind::Hex8 => {
            let b = HEX_BITS[l];
            [(b & 1) as f64, ((b >> 1) & 1) as f64, ((b >> 2) & 1) as f64]
        }
    }
}

/// Signed corner measures: for a Quad4 the areas of the four corner triangles, for a
/// Hex8 the volumes of the eight corner tetrahedra (each corner with its three
/// neighbours, signed so that a well-shaped cell gives all positive), for a simplex its
/// measure.
fn corner_measures(kind: ElementKind, nodes: &[u32], coords: &[f64], d: usize) -> Vec<f64> {
    let x = |l: usize| &coords[nodes[l] as usize * d..(nodes[l] as usize + 1) * d];
    let tri = |a: usize, b: usize, c: usize| {
        let (p, q, r) = (x(a), x(b), x(c));
        0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (r[0] - p[0]) * (q[1] - p[1]))
    };
    let tet = |a: usize, b: usize, c: usize, e: usize| {
        let (p, q, r, s) = (x(a), x(b), x(c), x(e));
        let u = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
        let v = [r[0] - p[0], r[1] - p[1], r[2] - p[2]];
        let w = [s[0] - p[0], s[1] - p[1], s[2] - p[2]];
        (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
            + u[2] * (v[0] * w[1] - v[1] * w[0]))
            / 6.0
    };
    match kind {
        ElementKind::Tri3 => vec![tri(0, 1, 2)],
        ElementKind::Tet4 => vec![tet(0, 1, 2, 3)],
        ElementKind::Quad4 => vec![tri(3, 0, 1), tri(0, 1, 2), tri(1, 2, 3), tri(2, 3, 0)],
        ElementKind::Hex8 => (0..8)
            .map(|l| {
                let b = HEX_BITS[l];
                let v = tet(l, hex_local(b ^ 1), hex_local(b ^ 2), hex_local(b ^ 4));
                // Each reflected axis flips the corner frame's handedness.
                if b.count_ones() % 2 == 0 {
                    v
                } else {
                    -v
                }
            })
            .collect(),
    }
}

/// Reverses the orientation of a cell's node list.
fn reverse(kind: ElementKind, nodes: &mut [u32]) {
    match kind {
        ElementKind::Tri3 | ElementKind::Tet4 => nodes.swap(0, 1),
        ElementKind::Quad4 => nodes.swap(1, 3),
        ElementKind::Hex8 => {
            for k in 0..4 {
                nodes.swap(k, k + 4);
            }
        }
    }
}

/// Appends the simplices of one cell (global node indices, orientation fixed later).
fn split_cell(kind: ElementKind, n: &[u32], coords: &[f64], out: &mut Vec<u32>) {
    match kind {
        ElementKind::Tri3 | ElementKind::Tet4 => out.extend_from_slice(n),
        ElementKind::Quad4 => {
            let x = |l: usize| &coords[n[l] as usize * 2..n[l] as usize * 2 + 2];
            // The shorter diagonal gives the better-shaped triangles.
            if dist(x(0), x(2)) <= dist(x(1), x(3)) {
                out.extend_from_slice(&[n[0], n[1], n[2], n[0], n[2], n[3]]);
            } else {
                out.extend_from_slice(&[n[0], n[1], n[3], n[1], n[2], n[3]]);
            }
        }
        ElementKind::Hex8 => split_hex(n, out),
    }
}

/// Cuts a hexahedron into tetrahedra whose face diagonals pass through each face's node
/// of lowest index. With `v` the lowest node of the hexahedron and `w` its opposite: if
/// some face away from `v` has its diagonal through `w`, two prisms along that face's
/// axis, three tetrahedra each; otherwise the five-tetrahedron cut whose central
/// tetrahedron contains `v`.
fn split_hex(n: &[u32], out: &mut Vec<u32>) {
    let v_local = (0..8).min_by_key(|&l| n[l]).expect("8 nodes");
    let vb = HEX_BITS[v_local];
    // Global node at the cube point `p` of a frame with v at the origin.
    let at = |p: u8| n[hex_local(p ^ vb)];
    let face_min = |axis: u8| {
        // The face away from v normal to `axis`: points with that bit set.
        (0u8..8)
            .filter(|p| p & axis != 0)
            .min_by_key(|&p| at(p))
            .expect("4 points")
    };
    let axis = [1u8, 2, 4]
        .into_iter()
        .find(|&a| matches!(face_min(a), p if p == 7 || p == a));
    match axis {
        None => {
            // Central tetrahedron v, and the three points two steps from v; corners at the
            // three neighbours of v and at w.
            let (a, b, c) = (at(0b011), at(0b101), at(0b110));
            out.extend_from_slice(&[at(0), a, b, c]);
            out.extend_from_slice(&[at(0b001), at(0), a, b]);
            out.extend_from_slice(&[at(0b010), at(0), a, c]);
            out.extend_from_slice(&[at(0b100), at(0), b, c]);
            out.extend_from_slice(&[at(0b111), a, b, c]);
        }
        Some(a0) => {
            // Axes (a0, a1, a2) cyclic; the cutting plane holds v, w and v + e_a0.
            let a1 = if a0 == 4 { 1 } else { a0 << 1 };
            let a2 = if a1 == 4 { 1 } else { a1 << 1 };
            let pt = |i: u8, j: u8, k: u8| at((i * a0) | (j * a1) | (k * a2));
            // Prism (bottom triangle at i = 0, top at i = 1, matching vertices).
            for tri in [[(0, 0), (1, 0), (1, 1)], [(0, 0), (1, 1), (0, 1)]] {
                let bottom = tri.map(|(j, k)| pt(0, j, k));
                let top = tri.map(|(j, k)| pt(1, j, k));
                split_prism(bottom, top, out);
            }
        }
    }
}

/// Cuts a prism (bottom triangle `b`, top `t`, `b[i]`–`t[i]` its vertical edges) into
/// three tetrahedra with every quadrilateral face cut through its lowest node.
fn split_prism(mut b: [u32; 3], mut t: [u32; 3], out: &mut Vec<u32>) {
    let lowest = *b.iter().chain(&t).min().expect("6 nodes");
    if t.contains(&lowest) {
        std::mem::swap(&mut b, &mut t);
    }
    let r = b.iter().position(|&x| x == lowest).expect("on the bottom");
    b.rotate_left(r);
    t.rotate_left(r);
    // Faces through a = b[0] are cut through it: tetrahedron (a, top triangle), then the
    // pyramid (apex a, base b1 b2 t2 t1) cut along the base quad's lowest node.
    let [a, b1, b2] = b;
    let [_, t1, t2] = t;
    out.extend_from_slice(&[a, t[0], t1, t2]);
    let base_min = *[b1, b2, t1, t2].iter().min().expect("4 nodes");
    if base_min == b1 || base_min == t2 {
        out.extend_from_slice(&[a, b1, b2, t2, a, b1, t2, t1]);
    } else {
        out.extend_from_slice(&[a, b1, b2, t1, a, b2, t2, t1]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Dim3;
    use std::collections::HashSet;

    fn cube(perm: &[u32; 8]) -> (Vec<f64>, Vec<u32>) {
        let mut coords = vec![0.0; 24];
        for (l, &b) in HEX_BITS.iter().enumerate() {
            let g = perm[l] as usize;
            coords[3 * g] = (b & 1) as f64;
            coords[3 * g + 1] = ((b >> 1) & 1) as f64;
            coords[3 * g + 2] = ((b >> 2) & 1) as f64;
        }
        (coords, perm.to_vec())
    }

    /// Diagonal (as a sorted node pair) of each quadrilateral face, from the tetrahedra.
    fn face_diagonals(tets: &[u32], hex: &[u32]) -> Vec<(u32, u32)> {
        const FACES: [[usize; 4]; 6] = [
            [0, 1, 2, 3],
            [4, 5, 6, 7],
            [0, 1, 5, 4],
            [1, 2, 6, 5],
            [2, 3, 7, 6],
            [3, 0, 4, 7],
        ];
        let mut edges = HashSet::new();
        for t in tets.chunks_exact(4) {
            for i in 0..4 {
                for j in i + 1..4 {
                    edges.insert((t[i].min(t[j]), t[i].max(t[j])));
                }
            }
        }
        FACES
            .iter()
            .map(|f| {
                let (p, q) = ((hex[f[0]], hex[f[2]]), (hex[f[1]], hex[f[3]]));
                let (p, q) = ((p.0.min(p.1), p.0.max(p.1)), (q.0.min(q.1), q.0.max(q.1)));
                assert!(
                    edges.contains(&p) != edges.contains(&q),
                    "face {f:?} must be cut by exactly one diagonal"
                );
                if edges.contains(&p) {
                    p
                } else {
                    q
                }
            })
            .collect()
    }

    /// Every numbering of the cube's nodes (a sample of all 8! by a fixed stride) gives
    /// tetrahedra that fill the cube, all positive, with each face cut through its lowest
    /// node (the rule that makes neighbouring cells conform).
    #[test]
    fn hex_cut_fills_the_cube_and_follows_the_lowest_node_rule() {
        let mut perms = Vec::new();
        let mut p: Vec<u32> = (0..8).collect();
        permutations(&mut p, 0, &mut perms);
        assert_eq!(perms.len(), 40320);
        let mut counts = [0usize; 7];
        for perm in perms.iter().step_by(7) {
            let perm: [u32; 8] = perm.as_slice().try_into().unwrap();
            let (coords, conn) = cube(&perm);
            let (cells, tets) =
                decompose::<Dim3>(&coords, &[ElementKind::Hex8], conn.clone(), false).unwrap();
            assert_eq!(cells.elements(0).end, tets.len() / 4);
            counts[tets.len() / 4] += 1;
            let mut vol = 0.0;
            for t in tets.chunks_exact(4) {
                let m = corner_measures(ElementKind::Tet4, t, &coords, 3)[0];
                assert!(m > 1e-12, "{perm:?}: tetrahedron {t:?} has volume {m}");
                vol += m;
            }
            assert!((vol - 1.0).abs() < 1e-12, "{perm:?}: volume {vol}");
            for (f, (a, b)) in face_diagonals(&tets, &conn).into_iter().enumerate() {
                const FACES: [[usize; 4]; 6] = [
                    [0, 1, 2, 3],
                    [4, 5, 6, 7],
                    [0, 1, 5, 4],
                    [1, 2, 6, 5],
                    [2, 3, 7, 6],
                    [3, 0, 4, 7],
                ];
                let lowest = FACES[f].iter().map(|&l| conn[l]).min().unwrap();
                assert!(
                    a == lowest || b == lowest,
                    "{perm:?}: face {f} cut by {a}-{b}"
                );
            }
        }
        assert!(
            counts[5] > 0 && counts[6] > 0,
            "both cuts occur: {counts:?}"
        );
    }

    fn permutations(p: &mut Vec<u32>, k: usize, out: &mut Vec<Vec<u32>>) {
        if k == p.len() {
            out.push(p.clone());
            return;
        }
        for i in k..p.len() {
            p.swap(k, i);
            permutations(p, k + 1, out);
            p.swap(k, i);
        }
    }
}
