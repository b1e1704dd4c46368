//! Mixed discretisation of Quad4/Hex8 cells (Marti and Cundall 1982, as in FLAC).
//!
//! A Quad4 or Hex8 cell is computed as the simplices it is cut into
//! ([`pcdc_mesh::cells`]). Each simplex keeps its own co-rotated deviatoric strain, but its
//! volumetric strain is replaced by the cell's volume-weighted mean,
//!
//! ```text
//! ε'_e = ε_e + (θ̄ − θ_e)/d · I,   θ_e = tr ε_e,   θ̄ = Σ_k V_k θ_k / Σ_k V_k   (k in the cell)
//! ```
//!
//! (d = 2 in plane strain, where θ = ε_xx + ε_yy, d = 3 in 3D). A mesh of simplices has
//! as many volumetric constraints as elements, about two per node in 2D and five to six
//! per node in 3D against two or three degrees of freedom, and locks when the material
//! becomes incompressible (ν → 0.5, or plastic flow with ψ = 0); the mixed cell has one
//! per cell, about one per node, and does not lock. The deviatoric part stays that of
//! the simplices, which are objective under large rotations as before: the trace of the
//! co-rotated strain is invariant, and in 2D needs no rotation at all
//! (`tr U = |(F₀₀ + F₁₁, F₁₀ − F₀₁)|`). The constitutive model is called per simplex
//! with the mixed strain increment, so every model, plastic or viscous, sees the
//! non-locking strain. The nodal forces are the B̄ forces conjugate to that strain,
//! `f = Σ_e V_e B̄_eᵀ σ_e`, which is each simplex's own force with its pressure replaced
//! by the cell's volume-weighted mean pressure p̄ (a third pass adds
//! `−V_e (p̄ − p_e) R ∇N_a`; p is (σ_xx + σ_yy)/2 in plane strain, tr σ/3 in 3D): so
//! the forces do work on the mixed strain exactly, as FLAC's zones average isotropic
//! stress and strain rate. The linear stiffness is the matching B̄ form
//! `K = Σ_e V_e B̄_eᵀ C B̄_e`.
//!
//! Passes per step: (1) the trace of every mixed-cell element's strain (in 3D with its
//! rotation, stored for pass 2), (2) the element pass with the cell-mean volumetric
//! strain, (3) the pressure correction of the forces. Meshes without Quad4/Hex8 cells
//! run pass 2 alone, unchanged.

use pcdc_mesh::{Dim, Mesh};

/// Per-element cell data of a mesh with Quad4/Hex8 cells.
#[derive(Clone, Debug, Default)]
pub(crate) struct MixedCells {
    /// First element of the element's cell.
    pub first: Vec<u32>,
    /// Number of elements in the element's cell (1 for a simplex cell).
    pub count: Vec<u32>,
    /// The element's share of its cell's volume, V_e / V_cell.
    pub weight: Vec<f64>,
    /// √(nodes per simplex / nodes per cell): the factor on the element's stable step
    /// when its mass is spread over all the cell's nodes (see [`MixedCells::of`]).
    pub dt_factor: Vec<f64>,
}

impl MixedCells {
    /// The cell data of `mesh`, or `None` when it has no Quad4/Hex8 cell.
    ///
    /// A mixed cell lumps its mass equally on its nodes (ρ V_cell / n, the row sums of
    /// the consistent mass of a parallelogram or parallelepiped), not simplex by simplex,
    /// which would load the nodes of a diagonal more. Each simplex then puts only
    /// `V_e / n` at each of its own nodes instead of `V_e / (D + 1)`, so its
    /// element-by-element stable step is scaled by `√((D + 1)/n)` (0.87 for a Quad4,
    /// 0.71 for a Hex8).
    pub fn of<D: Dim>(mesh: &Mesh<D>, volume: &[f64]) -> Option<Self> {
        if !mesh.cells().has_composite() {
            return None;
        }
        let ne = mesh.n_elements();
        let mut m = MixedCells {
            first: vec![0; ne],
            count: vec![0; ne],
            weight: vec![0.0; ne],
            dt_factor: vec![1.0; ne],
        };
        for c in 0..mesh.n_cells() {
            let els = mesh.cell_elements(c);
            let total: f64 = els.clone().map(|e| volume[e]).sum();
            let share = (D::NODES_PER_ELEM as f64 / mesh.cell_nodes(c).len() as f64).sqrt();
            for e in els.clone() {
                m.first[e] = els.start as u32;
                m.count[e] = els.len() as u32;
                m.weight[e] = volume[e] / total;
                m.dt_factor[e] = share;
            }
        }
        Some(m)
    }

    /// Whether element `e` belongs to a cell of several simplices.
    #[inline]
    pub fn is_mixed(&self, e: usize) -> bool {
        self.count[e] > 1
    }

    /// The cell's mean volumetric strain θ̄ from the per-element traces `trace`.
    #[inline]
    pub fn mean(&self, e: usize, trace: &[f64]) -> f64 {
        let f = self.first[e] as usize;
        let mut s = 0.0;
        for k in f..f + self.count[e] as usize {
            s += self.weight[k] * trace[k];
        }
        s
    }
}

/// Trace of the 2D co-rotated strain `U − I` from the displacement gradient `H`:
/// `tr U − 2 = r − 2` with `r = |(2 + H₀₀ + H₁₁, H₁₀ − H₀₁)|`, written without
/// cancellation as `((H₀₀ + H₁₁)(c + 2) + s²)/(r + 2)`.
#[inline]
pub(crate) fn trace_2d(h: &[f64; 4]) -> f64 {
    let t = h[0] + h[3];
    let c = 2.0 + t;
    let s = h[2] - h[1];
    let r = (c * c + s * s).sqrt();
    (t * (c + 2.0) + s * s) / (r + 2.0)
}

/// Adds the B̄ stiffness of the cell whose elements are `els` to `trip`: the strain of
/// element e acting on the cell's nodes is `ε_e(u) + (θ̄(u) − θ_e(u))/d I`, and
/// `K = Σ_e V_e B̄_eᵀ C_e B̄_e`. `grad(e)` gives the element's shape-function gradients
/// (node-major, D per node), `conn(e)` its nodes, `c(e)` its tensor C_ijkl.
#[allow(clippy::type_complexity)]
pub(crate) fn cell_stiffness(
    d: usize,
    els: std::ops::Range<usize>,
    volume: &[f64],
    grad: &dyn Fn(usize) -> [[f64; 3]; 4],
    conn: &dyn Fn(usize) -> Vec<u32>,
    c: &dyn Fn(usize, usize, usize, usize, usize) -> f64,
    trip: &mut Vec<(usize, usize, f64)>,
) {
    // The cell's nodes and the mean divergence operator b̄ over them.
    let mut nodes: Vec<u32> = Vec::new();
    for e in els.clone() {
        for n in conn(e) {
            if !nodes.contains(&n) {
                nodes.push(n);
            }
        }
    }
    let nn = nodes.len();
    let total: f64 = els.clone().map(|e| volume[e]).sum();
    let mut bbar = vec![[0.0; 3]; nn];
    for e in els.clone() {
        let g = grad(e);
        for (a, n) in conn(e).into_iter().enumerate() {
            let p = nodes.iter().position(|&m| m == n).expect("cell node");
            for k in 0..d {
                bbar[p][k] += volume[e] / total * g[a][k];
            }
        }
    }
    for e in els {
        let g = grad(e);
        let en = conn(e);
        // E[p][k] = the element's strain tensor for a unit displacement of cell node p
        // in direction k.
        let mut strain = vec![[[0.0; 3]; 3]; nn * d];
        for p in 0..nn {
            let own = en.iter().position(|&m| m == nodes[p]);
            let ga = own.map_or([0.0; 3], |a| g[a]);
            for k in 0..d {
                let s = &mut strain[p * d + k];
                for i in 0..d {
                    for j in 0..d {
                        let di = if i == k { 1.0 } else { 0.0 };
                        let dj = if j == k { 1.0 } else { 0.0 };
                        s[i][j] = 0.5 * (ga[j] * di + ga[i] * dj);
                    }
                }
                let dvol = (bbar[p][k] - ga[k]) / d as f64;
                for i in 0..d {
                    s[i][i] += dvol;
                }
            }
        }
        for p in 0..nn * d {
            for q in 0..nn * d {
                let mut kv = 0.0;
                for i in 0..d {
                    for j in 0..d {
                        let a = strain[p][i][j];
                        if a == 0.0 {
                            continue;
                        }
                        for k in 0..d {
                            for l in 0..d {
                                kv += a * c(e, i, j, k, l) * strain[q][k][l];
                            }
                        }
                    }
                }
                if kv != 0.0 {
                    trip.push((
                        nodes[p / d] as usize * d + p % d,
                        nodes[q / d] as usize * d + q % d,
                        volume[e] * kv,
                    ));
                }
            }
        }
    }
}
