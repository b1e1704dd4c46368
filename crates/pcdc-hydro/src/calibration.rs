//! The intact network calibrated to a rock mass permeability k
//! ([`crate::Hydro::rock_permeability`]).
//!
//! **2D.** The linear finite-element discretisation of Darcy flow on the triangles
//! conducts (k/μ)(cot α + cot β)/2 across each edge (α, β the angles opposite it in its
//! two triangles); an edge's channel has the weight 1/L, so the virtual aperture
//! δ⁰ = (6 k L (cot α + cot β))^⅓ makes the network that discretisation exactly.
//!
//! **3D** \[NOT IN MANUAL\]. A tetrahedron's discretisation conducts
//! C_ij = (k/μ) V (−∇N_i·∇N_j) along each of its six edges, and a face network has only
//! four faces per tetrahedron, so no aperture per face reproduces it (the mean
//! calibration δ⁰ = (18 k (V_A + V_B) / (4 A))^⅓, the permeability of randomly oriented
//! planar channels, missed steady radial flow by 3 % on a fine mesh, and did not converge).
//! Instead each intact channel carries calibrated edge weights ŵ: an edge (i, j) of a
//! tetrahedron lies on two of its faces; each takes half of C_ij, or all of it when the
//! other face carries no calibrated channel (a free surface, an impermeable joint, a
//! pre-existing fracture), and a channel sums the shares of its two tetrahedra:
//! δ_r³ ŵ_ij / 12 = Σ_t share_t k V_t (−∇N_i·∇N_j), δ_r the channel's reference
//! aperture (δ⁰ clamped to [δ_min, δ_max]). Summed over the channels of an edge this is
//! the finite-element conductance (but for the edges on no channel at all, e.g. of a
//! single tetrahedron along an edge of a block, whose conductance the network cannot
//! carry: a loss that shrinks with h² against the cross-section), so the intact network is the discretisation of
//! isotropic Darcy flow on any tetrahedral mesh. As a joint opens, the weights move from
//! ŵ to the channel's own cubic-law weights w: w_eff = w + β (ŵ − w), β = min(1,
//! (δ_r/δ)³), so the conductance δ³ w_eff/12 is the virtual one (scaled by (δ/δ_r)³) up
//! to δ_r and the virtual one plus the cubic law of the extra opening beyond it.

use std::collections::HashMap;

use pcdc_mesh::{Dim, Mesh};

use crate::flow::{cross, dot, sub, EDGES3};
use crate::network::Network;

/// The virtual aperture of joint `j` for rock mass permeability `k`: 2D, the exact one
/// (0 where the cotangent sum is not positive); 3D, the mean one (see the module docs).
pub(crate) fn aperture<D: Dim>(mesh: &Mesh<D>, j: usize, k: f64) -> f64 {
    let joint = mesh.interfaces().get(j).expect("joint of the network");
    let npf = D::NODES_PER_FACE;
    let mut face = [[0.0; 3]; 3];
    for (q, &n) in joint.side_a.iter().enumerate().take(npf) {
        face[q][..D::D].copy_from_slice(mesh.node(n as usize));
    }
    if D::D == 2 {
        let len = ((face[1][0] - face[0][0]).powi(2) + (face[1][1] - face[0][1]).powi(2)).sqrt();
        let mut cot_sum = 0.0;
        for side in 0..2 {
            let e = joint.elements[side] as usize;
            let nodes = mesh.element(e);
            let own: &[u32] = if side == 0 {
                joint.side_a
            } else {
                joint.side_b
            };
            let Some(&r) = nodes.iter().find(|n| !own.contains(n)) else {
                continue;
            };
            let x = mesh.node(r as usize);
            let a = [face[0][0] - x[0], face[0][1] - x[1]];
            let b = [face[1][0] - x[0], face[1][1] - x[1]];
            let cross = (a[0] * b[1] - a[1] * b[0]).abs();
            if cross > 0.0 {
                cot_sum += (a[0] * b[0] + a[1] * b[1]) / cross;
            }
        }
        if cot_sum <= 0.0 {
            return 0.0;
        }
        (6.0 * k * len * cot_sum).cbrt()
    } else {
        let mut n = [0.0; 3];
        let mut flat = [0.0; 9];
        for q in 0..3 {
            flat[q * 3..q * 3 + 3].copy_from_slice(&face[q]);
        }
        let area = D::face_measure_normal(&flat, &mut n[..D::D]);
        let volume = mesh.element_measure(joint.elements[0] as usize)
            + mesh.element_measure(joint.elements[1] as usize);
        if area <= 0.0 {
            return 0.0;
        }
        (18.0 * k * volume / (4.0 * area)).cbrt()
    }
}

/// The calibrated edge weights ŵ of the 3D channels (3 per channel, edges as in
/// [`EDGES3`]), for the channels with a reference aperture `delta_ref[c] > 0` (0 for the
/// others): see the module docs.
pub(crate) fn edge_weights<D: Dim>(
    mesh: &Mesh<D>,
    net: &Network,
    delta_ref: &[f64],
    k: f64,
) -> Vec<f64> {
    let joints = mesh.interfaces();
    let nc = net.n_channels();
    let mut out = vec![0.0; nc * 3];
    if D::D != 3 {
        return out;
    }
    let master = |n: u32| joints.master_of(n);
    let key = |mut t: [u32; 3]| {
        t.sort_unstable();
        t
    };
    // The calibrated channels by the master vertices of their face.
    let mut by_face: HashMap<[u32; 3], u32> = HashMap::with_capacity(nc);
    for (c, &j) in net.joint.iter().enumerate() {
        if delta_ref[c] > 0.0 {
            let a = &joints.joint_nodes(j as usize)[..3];
            by_face.insert(key([master(a[0]), master(a[1]), master(a[2])]), c as u32);
        }
    }
    for (c, &j) in net.joint.iter().enumerate() {
        let dr = delta_ref[c];
        if dr <= 0.0 {
            continue;
        }
        let joint = joints.get(j as usize).expect("joint of the network");
        for side in 0..2 {
            let own = if side == 0 {
                joint.side_a
            } else {
                joint.side_b
            };
            let e = joint.elements[side] as usize;
            let tet = mesh.element(e);
            let Some(&apex) = tet.iter().find(|n| !own.contains(n)) else {
                continue;
            };
            let mut x = [[0.0; 3]; 4];
            for (q, &n) in own.iter().chain(std::iter::once(&apex)).enumerate() {
                x[q].copy_from_slice(mesh.node(n as usize));
            }
            let Some((volume, grad)) = tet_gradients(&x) else {
                continue;
            };
            for (slot, &(i, jj, _)) in EDGES3.iter().enumerate() {
                let other = key([master(own[i]), master(own[jj]), master(apex)]);
                let share = if by_face.contains_key(&other) {
                    0.5
                } else {
                    1.0
                };
                let c_ij = -k * volume * dot(grad[i], grad[jj]);
                out[c * 3 + slot] += share * 12.0 * c_ij / (dr * dr * dr);
            }
        }
    }
    out
}

/// Volume and shape-function gradients of the linear tetrahedron `x`, or `None` when it
/// is degenerate.
fn tet_gradients(x: &[[f64; 3]; 4]) -> Option<(f64, [[f64; 3]; 4])> {
    let e = |a: usize| sub(x[a], x[0]);
    let (a, b, c) = (e(1), e(2), e(3));
    let six_v = dot(a, cross(b, c));
    if six_v == 0.0 || !six_v.is_finite() {
        return None;
    }
    let g1 = scale(cross(b, c), 1.0 / six_v);
    let g2 = scale(cross(c, a), 1.0 / six_v);
    let g3 = scale(cross(a, b), 1.0 / six_v);
    let g0 = [
        -(g1[0] + g2[0] + g3[0]),
        -(g1[1] + g2[1] + g3[1]),
        -(g1[2] + g2[2] + g3[2]),
    ];
    Some((six_v.abs() / 6.0, [g0, g1, g2, g3]))
}

/// The calibrated blend of a channel's weights: w ← w + β (ŵ − w), β = min(1, (δ_r/δ)³)
/// (no change where δ_r = 0: an uncalibrated channel).
#[inline]
pub fn blend(weight: &mut [f64], calibrated: &[f64], delta_ref: f64, delta: f64) {
    if delta_ref <= 0.0 {
        return;
    }
    let r = (delta_ref / delta).min(1.0);
    let beta = r * r * r;
    for (w, &h) in weight.iter_mut().zip(calibrated) {
        *w += beta * (h - *w);
    }
}

#[inline]
fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[cfg(test)]
mod tests {
    use super::*;
    use pcdc_mesh::{builders, split_nodes, Dim3, Range};

    /// The calibrated network passes the finite-element patch test on a distorted
    /// tetrahedral mesh: a linear piezometric field leaves every interior flow node in
    /// balance, and the flow across a mid-plane is k |∇ψ| × area.
    #[test]
    fn calibrated_network_is_darcy_on_distorted_tetrahedra() {
        let base = builders::cuboid([0.0; 3], [1.0, 1.0, 1.0], 0.25).unwrap();
        let mut x = base.coords().to_vec();
        for (n, p) in x.chunks_mut(3).enumerate() {
            let inside = p.iter().all(|&c| c > 1e-9 && c < 1.0 - 1e-9);
            if inside {
                for (d, c) in p.iter_mut().enumerate() {
                    *c += 0.07 * ((n * 7 + d * 3) as f64 * 1.91).sin();
                }
            }
        }
        let mesh: Mesh<Dim3> = Mesh::new(x, base.elements().to_vec()).unwrap();
        let split = split_nodes(&mesh, &Range::All).unwrap();
        let net = Network::build(&split, None, &[]).unwrap();
        let (k, dr) = (1e-14, 1e-5);
        let delta_ref = vec![dr; net.n_channels()];
        let w = edge_weights(&split, &net, &delta_ref, k);
        let flows = |grad: [f64; 3]| {
            let psi: Vec<f64> = (0..net.n_nodes())
                .map(|l| {
                    let p = split.node(net.node_mesh[l] as usize);
                    grad[0] * p[0] + grad[1] * p[1] + grad[2] * p[2]
                })
                .collect();
            let mut net_in = vec![0.0; net.n_nodes()];
            let mut through = 0.0;
            for c in 0..net.n_channels() {
                let f = &net.channel_nodes[c * 3..c * 3 + 3];
                for (e, &(i, j, _)) in EDGES3.iter().enumerate() {
                    let (a, b) = (f[i] as usize, f[j] as usize);
                    let q = dr * dr * dr / 12.0 * w[c * 3 + e] * (psi[a] - psi[b]);
                    net_in[a] -= q;
                    net_in[b] += q;
                    // Flow from the nodes at x < 0.5 to those at x >= 0.5.
                    let xa = split.node(net.node_mesh[a] as usize)[0];
                    let xb = split.node(net.node_mesh[b] as usize)[0];
                    if xa < 0.5 && xb >= 0.5 {
                        through += q;
                    } else if xb < 0.5 && xa >= 0.5 {
                        through -= q;
                    }
                }
            }
            (net_in, through)
        };
        let (net_in, _) = flows([0.3, -1.1, 0.7]);
        let mut interior = 0;
        for l in 0..net.n_nodes() {
            let p = split.node(net.node_mesh[l] as usize);
            if p.iter().all(|&c| c > 1e-9 && c < 1.0 - 1e-9) {
                interior += 1;
                assert!(net_in[l].abs() < 1e-12 * k, "node {l}: {}", net_in[l]);
            }
        }
        assert!(interior > 0);
        // Along x the side faces carry no flow, so the finite-element discharge across
        // any cut between x = 0 and x = 1 is Darcy's, k (−∂ψ/∂x) × 1 m²; the network
        // carries all of it but the conductance of tetrahedron edges on no channel at all
        // (along the block's edges), found here from the network alone.
        let grad = [-0.3, 0.0, 0.0];
        let (_, through) = flows(grad);
        let master = |n: u32| split.interfaces().master_of(n);
        let mut carried = std::collections::HashSet::new();
        for &j in &net.joint {
            let a = &split.interfaces().joint_nodes(j as usize)[..3];
            for (i, jj, _) in EDGES3 {
                let (p, q) = (master(a[i]), master(a[jj]));
                carried.insert((p.min(q), p.max(q)));
            }
        }
        let mut missing = 0.0;
        for e in 0..split.n_elements() {
            let tet = split.element(e);
            let mut x = [[0.0; 3]; 4];
            for (q, &n) in tet.iter().enumerate() {
                x[q].copy_from_slice(split.node(n as usize));
            }
            let (volume, g) = tet_gradients(&x).unwrap();
            for a in 0..4 {
                for b in a + 1..4 {
                    let (p, q) = (master(tet[a]), master(tet[b]));
                    if carried.contains(&(p.min(q), p.max(q))) {
                        continue;
                    }
                    let (xa, xb) = (x[a][0], x[b][0]);
                    let q_ab = -k * volume * dot(g[a], g[b]) * grad[0] * (xa - xb);
                    if xa < 0.5 && xb >= 0.5 {
                        missing += q_ab;
                    } else if xb < 0.5 && xa >= 0.5 {
                        missing -= q_ab;
                    }
                }
            }
        }
        let want = 0.3 * k - missing;
        eprintln!(
            "discharge {through:e}, Darcy {:e}, on no channel {missing:e}",
            0.3 * k
        );
        assert!(missing.abs() < 0.05 * 0.3 * k);
        assert!(
            (through - want).abs() < 1e-9 * want,
            "{through:e} vs {want:e}"
        );
    }

    #[test]
    fn tet_gradients_are_those_of_the_barycentric_coordinates() {
        let x = [
            [0.1, 0.0, 0.2],
            [1.3, 0.1, 0.0],
            [0.2, 0.9, 0.1],
            [0.3, 0.2, 1.1],
        ];
        let (v, g) = tet_gradients(&x).unwrap();
        let six_v = dot(sub(x[1], x[0]), cross(sub(x[2], x[0]), sub(x[3], x[0])));
        assert!((v - six_v.abs() / 6.0).abs() < 1e-15);
        // N_a(x_b) = δ_ab for the linear functions with these gradients.
        for a in 0..4 {
            for b in 0..4 {
                let n = if a == 0 { 1.0 } else { 0.0 } + dot(g[a], sub(x[b], x[0]));
                let want = if a == b { 1.0 } else { 0.0 };
                assert!((n - want).abs() < 1e-12, "N_{a}(x_{b}) = {n}");
            }
        }
    }

    #[test]
    fn blend_moves_from_the_calibrated_to_the_own_weights_as_the_joint_opens() {
        let (own, hat) = ([1.0, 2.0, 3.0], [4.0, 0.0, -1.0]);
        let mut w = own;
        blend(&mut w, &hat, 0.0, 1e-5);
        assert_eq!(w, own, "uncalibrated: untouched");
        for delta in [0.5e-5, 1e-5] {
            let mut w = own;
            blend(&mut w, &hat, 1e-5, delta);
            assert_eq!(w, hat, "at or below δ_r: the calibrated weights");
        }
        let mut w = own;
        blend(&mut w, &hat, 1e-5, 2e-5);
        for e in 0..3 {
            let want = own[e] + (hat[e] - own[e]) / 8.0;
            assert!((w[e] - want).abs() < 1e-15);
        }
    }
}
