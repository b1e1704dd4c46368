//! Conduction in the solid elements (manual eq. 93–98): the gradients of the linear
//! shape functions, derived once from the reference configuration, and the element
//! pass that turns nodal temperatures into element fluxes and nodal heat rates.

use pcdc_compute::ComputeError;
use pcdc_mesh::{Dim, Mesh};

/// Per-element constants: ∇N_a of every node (stride `npe * d`) and the measure Ω (m²,
/// per unit thickness, or m³).
#[derive(Clone, Debug, Default)]
pub(crate) struct Geometry {
    pub grad: Vec<f64>,
    pub measure: Vec<f64>,
}

impl Geometry {
    /// From the mesh's reference coordinates; errors name a degenerate element.
    pub fn of<D: Dim>(mesh: &Mesh<D>) -> Result<Self, ComputeError> {
        let (d, npe, ne) = (D::D, D::NODES_PER_ELEM, mesh.n_elements());
        let mut grad = vec![0.0; ne * npe * d];
        let mut measure = vec![0.0; ne];
        let mut x = [0.0; 12];
        for e in 0..ne {
            mesh.element_coords(e, &mut x[..npe * d]);
            // J = [x_1 − x_0, …, x_d − x_0] (columns); the rows of J⁻¹ are ∇N_1..∇N_d.
            let mut j = [[0.0; 3]; 3];
            for c in 0..d {
                for r in 0..d {
                    j[r][c] = x[(c + 1) * d + r] - x[r];
                }
            }
            let (inv, det) = invert(&j, d);
            let vol = det.abs() / if d == 2 { 2.0 } else { 6.0 };
            let scale = (0..d)
                .map(|c| (0..d).map(|r| j[r][c] * j[r][c]).sum::<f64>())
                .fold(0.0f64, f64::max);
            // Also refuses a NaN measure (coordinates not finite).
            if vol.is_nan() || vol <= 1e-12 * scale.powf(d as f64 / 2.0) {
                return Err(ComputeError::param(
                    format!("element {e}"),
                    vol,
                    "is degenerate (zero measure): conduction needs a proper simplex",
                ));
            }
            measure[e] = vol;
            let g = &mut grad[e * npe * d..(e + 1) * npe * d];
            for a in 1..npe {
                for k in 0..d {
                    g[a * d + k] = inv[a - 1][k];
                    g[k] -= inv[a - 1][k];
                }
            }
        }
        Ok(Geometry { grad, measure })
    }
}

/// Inverse and determinant of the leading `d × d` block.
fn invert(j: &[[f64; 3]; 3], d: usize) -> ([[f64; 3]; 3], f64) {
    let mut inv = [[0.0; 3]; 3];
    if d == 2 {
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let r = 1.0 / det;
        inv[0] = [j[1][1] * r, -j[0][1] * r, 0.0];
        inv[1] = [-j[1][0] * r, j[0][0] * r, 0.0];
        return (inv, det);
    }
    let c =
        |r0: usize, r1: usize, c0: usize, c1: usize| j[r0][c0] * j[r1][c1] - j[r0][c1] * j[r1][c0];
    let cof = [
        [c(1, 2, 1, 2), -c(1, 2, 0, 2), c(1, 2, 0, 1)],
        [-c(0, 2, 1, 2), c(0, 2, 0, 2), -c(0, 2, 0, 1)],
        [c(0, 1, 1, 2), -c(0, 1, 0, 2), c(0, 1, 0, 1)],
    ];
    let det = j[0][0] * cof[0][0] + j[0][1] * cof[0][1] + j[0][2] * cof[0][2];
    let r = 1.0 / det;
    for a in 0..3 {
        for b in 0..3 {
            inv[a][b] = cof[b][a] * r;
        }
    }
    (inv, det)
}

/// One element's conduction (eq. 95–98): ∇T = Σ_a T_a ∇N_a, q = −k ∇T (written to
/// `flux`), and the heat rate into each node R_a = Ω ∇N_a · q (W; W/m in 2D), written
/// to `rates`. Σ_a R_a = 0 (Σ_a ∇N_a = 0): conduction moves heat, never makes it.
#[inline]
pub(crate) fn element(
    d: usize,
    grad: &[f64],
    measure: f64,
    k: &[[f64; 3]; 3],
    temps: &[f64],
    flux: &mut [f64],
    rates: &mut [f64],
) {
    let mut gt = [0.0; 3];
    for (a, &t) in temps.iter().enumerate() {
        for i in 0..d {
            gt[i] += t * grad[a * d + i];
        }
    }
    let mut q = [0.0; 3];
    for i in 0..d {
        for j in 0..d {
            q[i] -= k[i][j] * gt[j];
        }
    }
    flux.copy_from_slice(&q[..d]);
    for (a, r) in rates.iter_mut().enumerate() {
        let mut s = 0.0;
        for i in 0..d {
            s += grad[a * d + i] * q[i];
        }
        *r = measure * s;
    }
}

/// Row sums Σ_b |K^e_ab| of the element conductance K^e_ab = Ω ∇N_a · k ∇N_b, added
/// to `out[a]` (W/K): the Gershgorin bound of the explicit step.
pub(crate) fn row_sums(d: usize, grad: &[f64], measure: f64, k: &[[f64; 3]; 3], out: &mut [f64]) {
    let npe = out.len();
    for a in 0..npe {
        for b in 0..npe {
            let mut s = 0.0;
            for i in 0..d {
                for j in 0..d {
                    s += grad[a * d + i] * k[i][j] * grad[b * d + j];
                }
            }
            out[a] += (measure * s).abs();
        }
    }
}
