//! The arithmetic of one fluid step, per channel and per flow node, on plain slices (the
//! CPU path; the GPU kernels repeat it).
//!
//! **Geometry** (eq. 79), per channel from the current positions of its joint's node
//! pairs: the midplane points m_k = (x_A,k + x_B,k)/2, its measure A (length in 2D, area
//! in 3D) and unit normal n (from side A to side B), the mean normal opening
//! ō = (1/N) Σ_k (x_B,k − x_A,k)·n, the hydraulic aperture δ = clamp(δ⁰ + ō, δ_min,
//! δ_max), the channel volume δ A and the edge weights w of its linear interpolant:
//! in 2D w = 1/A; in 3D, for the edge (i, j) opposite vertex k,
//! w_ij = −A ∇N_i·∇N_j = (m_i − m_k)·(m_j − m_k)/(4A) (the cotangent weights).
//!
//! **Flux** (eq. 74–78, 80–83 with (77), (82) corrected). With the piezometric pressure
//! ψ = p − ρ_f g·x (so that ∇ψ = ρ_f g ∇φ_h, φ_h = z + p/(ρ_f g) the total head of
//! eq. 74, for gravity g = −g e_z), the cubic law q = −(δ³ f(s̄)/(12 μ_d)) ∇ψ (eq. 75,
//! 80) integrated against the interpolant's gradients gives the volume rate from node i
//! to node j of the channel Q_ij = k w_ij (ψ_i − ψ_j), k = δ³ f(s̄)/(12 μ_d), which is
//! the nodal share −(1/N) q·n^(l) s^(l) of eq. 82 summed edge by edge: antisymmetric,
//! so every channel conserves volume exactly. s̄ is the mean saturation of the channel's
//! nodes and f(s) = s²(3 − 2s) (eq. 81).
//!
//! **Storage** (eq. 84–85 in conservative form [CORRECTED: the manual's incremental
//! update conserves mass only to first order in the volume change; this one is exact]).
//! Each flow node keeps its fluid content W (m³ at zero pressure; per unit thickness in
//! 2D); a step adds the net inflow, W ← W + Δt ΣQ (eq. 83), and the node's volume V
//! (half, 2D, or a third, 3D, of each channel's volume) gives pressure and saturation:
//! p = K_f (W/V − 1) and s = 1 when W ≥ V, else p = 0 and s = W/V. To first order this
//! is eq. 84, p ← p + K_f ΔQ Δt / V − K_f ΔV / V̄, and, for a draining node, the
//! mass-conserving form of eq. 85, s ← (s V + ΔQ Δt) / V_new. A node that a step would
//! drain below empty keeps the deficit (W < 0, s = 0) and refills it first, so volume
//! is conserved to rounding in every case.

use crate::model::{saturation_weight, Aperture, LeakOff};

/// Per-channel geometry and its derived constants, rebuilt from the positions once per
/// mechanical step.
#[derive(Clone, Debug, Default)]
pub struct Geometry {
    /// Channel measure A: length (2D, m) or area (3D, m²).
    pub measure: Vec<f64>,
    /// Hydraulic aperture δ (m), eq. 79.
    pub aperture: Vec<f64>,
    /// Edge weights, 3 per channel: 2D (0,1) in slot 0; 3D (0,1), (1,2), (2,0).
    pub weight: Vec<f64>,
    /// Shape-function gradients ∇N_k (1/m), stride `npc * D` (node k, component).
    pub grad: Vec<f64>,
    /// g·m_k at each channel node (m²/s²): ψ_k = p_k − ρ_f g·m_k.
    pub gravity_potential: Vec<f64>,
    /// Flow node volume V (m³; m² per unit thickness in 2D).
    pub node_volume: Vec<f64>,
}

/// The 3D edges (i, j) and their opposite vertex k.
pub const EDGES3: [(usize, usize, usize); 3] = [(0, 1, 2), (1, 2, 0), (2, 0, 1)];

/// The shape of one channel: [`channel_shape`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Shape {
    /// Measure A: length (2D) or area (3D).
    pub measure: f64,
    /// Unit normal of the midplane (side A to side B).
    pub normal: [f64; 3],
    /// Mean normal opening ō (m).
    pub opening: f64,
    /// Edge weights: 2D (0,1) in slot 0; 3D (0,1), (1,2), (2,0).
    pub weight: [f64; 3],
    /// Gradients ∇N_k of the linear interpolant's shape functions (1/m), per node.
    pub grad: [[f64; 3]; 3],
}

/// The shape of one channel from its midplane points `mid` and the pair gaps `gap`
/// (x_B − x_A), `npc` of each. A degenerate channel has zero measure, weights and
/// gradients (it carries no flow and stores nothing).
#[inline]
pub fn channel_shape(npc: usize, mid: &[[f64; 3]; 3], gap: &[[f64; 3]; 3]) -> Shape {
    let mut sh = Shape::default();
    if npc == 2 {
        let (dx, dy) = (mid[1][0] - mid[0][0], mid[1][1] - mid[0][1]);
        let len = (dx * dx + dy * dy).sqrt();
        sh.measure = len;
        if len > 0.0 {
            // One division: the square root and the divisions after it were half of
            // the channel pass (a dependent chain).
            let inv = 1.0 / len;
            sh.normal = [dy * inv, -dx * inv, 0.0];
            sh.weight[0] = inv;
            let t = [dx * (inv * inv), dy * (inv * inv), 0.0];
            sh.grad[0] = [-t[0], -t[1], 0.0];
            sh.grad[1] = t;
        }
    } else {
        let a = sub(mid[1], mid[0]);
        let b = sub(mid[2], mid[0]);
        let c = cross(a, b);
        let twice = dot(c, c).sqrt();
        sh.measure = 0.5 * twice;
        if twice > 0.0 {
            let inv = 1.0 / twice;
            let n = [c[0] * inv, c[1] * inv, c[2] * inv];
            sh.normal = n;
            let half = 0.5 * inv;
            for (e, &(i, j, k)) in EDGES3.iter().enumerate() {
                sh.weight[e] = dot(sub(mid[i], mid[k]), sub(mid[j], mid[k])) * half;
            }
            for k in 0..3 {
                let e = sub(mid[(k + 2) % 3], mid[(k + 1) % 3]);
                let g = cross(n, e);
                sh.grad[k] = [g[0] * inv, g[1] * inv, g[2] * inv];
            }
        }
    }
    for g in gap.iter().take(npc) {
        sh.opening += dot(*g, sh.normal);
    }
    sh.opening /= npc as f64;
    sh
}

/// The area vector A n of a channel from its midplane points (m in 2D, m² in 3D; n the
/// unit normal from side A to side B): (Δy, −Δx) of the segment in 2D, half the cross
/// product in 3D; zero on a degenerate channel. The pressure forces need only this.
#[inline]
pub fn area_normal(npc: usize, mid: &[[f64; 3]; 3]) -> [f64; 3] {
    if npc == 2 {
        return [mid[1][1] - mid[0][1], -(mid[1][0] - mid[0][0]), 0.0];
    }
    let c = cross(sub(mid[1], mid[0]), sub(mid[2], mid[0]));
    [0.5 * c[0], 0.5 * c[1], 0.5 * c[2]]
}

/// The mean flux q = −k ∇ψ of a channel (m²/s: volume per unit time and unit width), with
/// `k` = δ³ f(s̄)/(12 μ_d) (eq. 75, 80).
#[inline]
pub fn channel_flux(npc: usize, k: f64, grad: &[[f64; 3]; 3], psi: &[f64; 3]) -> [f64; 3] {
    let mut q = [0.0; 3];
    for j in 0..npc {
        for d in 0..3 {
            q[d] -= k * psi[j] * grad[j][d];
        }
    }
    q
}

/// Volume shares of one channel over a step of `dt`: `share[k]` is the net volume (m³)
/// flowing into its node `k` (eq. 82 corrected, antisymmetric edge by edge). `psi` are
/// the piezometric pressures of its nodes (Pa), `k_dt` = δ³ Δt/(12 μ_d), `fw` the
/// saturation weights f(s) of its nodes (eq. 81): each edge carries the weight of its
/// upstream node (\[CORRECTED\], see [`upstream_weight`]).
#[inline]
pub fn channel_shares(
    npc: usize,
    k_dt: f64,
    w: &[f64; 3],
    psi: &[f64; 3],
    fw: &[f64; 3],
) -> [f64; 3] {
    let mut share = [0.0; 3];
    if npc == 2 {
        let q = k_dt * w[0] * (psi[0] - psi[1]);
        let q = q * upstream_weight(q, fw[0], fw[1]);
        share[0] = -q;
        share[1] = q;
    } else {
        for (e, &(i, j, _)) in EDGES3.iter().enumerate() {
            let q = k_dt * w[e] * (psi[i] - psi[j]);
            let q = q * upstream_weight(q, fw[i], fw[j]);
            share[i] -= q;
            share[j] += q;
        }
    }
    share
}

/// The saturation weight of an edge's flow `q` from its node i to its node j (before the
/// weight): that of the node it leaves (`f_i` if q > 0, else `f_j`).
/// \[CORRECTED\] The manual weights a channel by the mean saturation of its nodes
/// (eq. 80), which lets a dry node go on draining at half the saturated rate into a wet
/// one below it, below empty, so a free surface never settles (validation scene 10);
/// upstream weighting, the standard for unsaturated flow, stops the outflow of an empty
/// node and is the same for saturated flow.
#[inline]
pub fn upstream_weight(q: f64, f_i: f64, f_j: f64) -> f64 {
    if q > 0.0 {
        f_i
    } else {
        f_j
    }
}

/// δ³ f(s̄)/(12 μ_d) (m³/(Pa·s)): the cubic-law conductivity of a channel of aperture δ
/// whose nodes have mean saturation `s_mean` (eq. 75, 80–81), used for its output flux
/// and leak-off (the volume shares weight each edge upstream, [`channel_shares`]).
#[inline]
pub fn conductivity(delta: f64, s_mean: f64, mu_d: f64) -> f64 {
    delta * delta * delta * saturation_weight(s_mean) / (12.0 * mu_d)
}

/// Volume (m³) a channel of measure `a` that has leaked for `age` = t − t_i loses over
/// the next `dt`: the rate 2 A C_leak / sqrt(t − t_i) (eq. 86, both walls) integrated
/// exactly, before the saturation weight.
#[inline]
pub fn leak_volume(a: f64, c_leak: f64, age: f64, dt: f64) -> f64 {
    let s0 = age.max(0.0).sqrt();
    let s1 = (age + dt).max(0.0).sqrt();
    // ∫ 2 A C / sqrt(τ − t_i) dτ = 4 A C (sqrt(t + dt − t_i) − sqrt(t − t_i)).
    4.0 * a * c_leak * (s1 - s0)
}

/// Pressure and saturation of a node of content `w` and volume `v` (eq. 84–85 in
/// conservative form).
#[inline]
pub fn state_of(w: f64, v: f64, bulk: f64) -> (f64, f64) {
    if w >= v {
        (bulk * (w / v - 1.0), 1.0)
    } else {
        (0.0, (w / v).max(0.0))
    }
}

/// The content of a saturated node of volume `v` at pressure `p` ≥ 0.
#[inline]
pub fn content_at(p: f64, v: f64, bulk: f64) -> f64 {
    v * (1.0 + p / bulk)
}

/// Leak-off of a channel over a step `dt`: the volume per node (none before the channel
/// leaks, `age` < 0).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn leak_per_node(
    leak: &LeakOff,
    npc: usize,
    a: f64,
    p_mean: f64,
    s_mean: f64,
    bulk: f64,
    mu_d: f64,
    age: f64,
    dt: f64,
) -> f64 {
    if age < 0.0 {
        return 0.0;
    }
    let c = leak.coefficient(p_mean, bulk, mu_d);
    saturation_weight(s_mean) * leak_volume(a, c, age, dt) / npc as f64
}

/// The hydraulic aperture of a channel (eq. 79): δ⁰ + ō clamped, or δ⁰ clamped when the
/// flow does not see the solid's motion.
#[inline]
pub fn aperture_of(model: &Aperture, initial: f64, opening: f64, follows_solid: bool) -> f64 {
    model.hydraulic(initial, if follows_solid { opening } else { 0.0 })
}

#[inline]
pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn tri() -> impl Strategy<Value = [[f64; 3]; 3]> {
        prop::array::uniform3(prop::array::uniform3(-1.0f64..1.0))
    }

    proptest! {
        /// Edge weights reproduce the FE matrix A ∇N_i·∇N_j: a linear field's nodal
        /// shares equal −A q·∇N_l, and a constant field gives no flow.
        #[test]
        fn weights_are_the_linear_fe_operator(m in tri(), grad in prop::array::uniform3(-1e3f64..1e3)) {
            let sh = channel_shape(3, &m, &[[0.0; 3]; 3]);
            let (a, n, w) = (sh.measure, sh.normal, sh.weight);
            prop_assume!(a > 1e-3);
            // ψ linear: ψ_k = grad·m_k; its in-plane gradient is grad minus its normal part.
            let psi: [f64; 3] = std::array::from_fn(|k| dot(grad, m[k]));
            let share = channel_shares(3, 1.0, &w, &psi, &[1.0; 3]);
            let gt = sub(grad, [n[0] * dot(grad, n), n[1] * dot(grad, n), n[2] * dot(grad, n)]);
            for l in 0..3 {
                // ∇N_l = n × (m_k − m_j) / (2A) for (l, j, k) counter-clockwise.
                let (j, k) = ((l + 1) % 3, (l + 2) % 3);
                let e = sub(m[k], m[j]);
                let gn = cross(n, e);
                let expect = -dot(gt, gn) / 2.0; // A q·∇N_l with q = −∇ψ, ∇N_l = gn/(2A)
                prop_assert!((sh.grad[l][0] * 2.0 * a - gn[0]).abs() < 1e-9);
                // The flux of the linear field is −∇ψ in the plane.
                let q = channel_flux(3, 1.0, &sh.grad, &psi);
                prop_assert!((0..3).all(|d| (q[d] + gt[d]).abs() <= 1e-9 * (1.0 + gt[d].abs())));
                let scale = 1.0 + dot(grad, grad).sqrt();
                prop_assert!((share[l] - expect).abs() <= 1e-9 * scale, "{l}: {} vs {expect}", share[l]);
            }
            let flat = channel_shares(3, 1.0, &w, &[7.0; 3], &[1.0; 3]);
            prop_assert!(flat.iter().all(|&s| s.abs() < 1e-12));
        }

        /// Shares are antisymmetric: they sum to zero (volume conserved), and a
        /// zero gradient gives zero flux, in 2D and 3D.
        #[test]
        fn shares_conserve_volume(
            m in tri(),
            psi in prop::array::uniform3(-1e6f64..1e6),
            kdt in 0.0f64..1e-3,
            fw in prop::array::uniform3(0.0f64..=1.0),
            dry in 0usize..3,
        ) {
            for npc in [2, 3] {
                let w = channel_shape(npc, &m, &[[0.0; 3]; 3]).weight;
                let s = channel_shares(npc, kdt, &w, &psi, &fw);
                let total: f64 = s.iter().sum();
                let mag: f64 = s.iter().map(|x| x.abs()).sum();
                prop_assert!(total.abs() <= 1e-14 * mag.max(1e-300));
                let zero = channel_shares(npc, kdt, &w, &[psi[0]; 3], &fw);
                prop_assert!(zero.iter().all(|&x| x == 0.0));
                // An empty node (f = 0) gives nothing, whatever the gradient.
                let mut fe = fw;
                fe[dry % npc] = 0.0;
                let e = channel_shares(npc, kdt, &w, &psi, &fe);
                prop_assert!(e[dry % npc] >= 0.0, "empty node lost {}", e[dry % npc]);
                if npc == 2 {
                    // Flux from high to low: node 0 loses when ψ_0 > ψ_1.
                    prop_assert!(s[0] * (psi[0] - psi[1]) <= 0.0);
                    prop_assert_eq!(s[0], -s[1]);
                }
            }
        }

        /// Pressure is never negative and saturation stays in [0, 1]; the content of a
        /// saturated state maps back to its pressure.
        #[test]
        fn state_bounds(w in -1.0f64..3.0, v in 1e-6f64..2.0, k in 1e6f64..1e10) {
            let (p, s) = state_of(w, v, k);
            prop_assert!(p >= 0.0);
            prop_assert!((0.0..=1.0).contains(&s));
            if w >= v {
                prop_assert!((content_at(p, v, k) - w).abs() <= 1e-12 * w.abs());
            }
        }
    }

    #[test]
    fn two_d_shape_and_opening() {
        let mid = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0; 3]];
        // Side B 1 mm beyond side A along the normal (0, -1) of the edge a -> b.
        let gap = [[0.0, -1e-3, 0.0], [0.0, -3e-3, 0.0], [0.0; 3]];
        let sh = channel_shape(2, &mid, &gap);
        assert_eq!(sh.measure, 2.0);
        assert_eq!(sh.normal, [0.0, -1.0, 0.0]);
        assert!((sh.opening - 2e-3).abs() < 1e-15);
        assert_eq!(sh.weight[0], 0.5);
        // Flux of ψ = 0 at node 0, 2 at node 1: −k ∇ψ = −k (1, 0).
        let q = channel_flux(2, 3.0, &sh.grad, &[0.0, 2.0, 0.0]);
        assert_eq!(q, [-3.0, 0.0, 0.0]);
    }

    #[test]
    fn leak_volume_integrates_the_rate() {
        // ∫ 2 A C / sqrt(t − t_i) dt over [1, 2] with t_i = 0.5, by the midpoint rule.
        let (a, c, ti) = (0.3, 1e-4, 0.5);
        let n = 200_000;
        let h = 1.0 / n as f64;
        let num: f64 = (0..n)
            .map(|i| 2.0 * a * c / (1.0 + (i as f64 + 0.5) * h - ti).sqrt() * h)
            .sum();
        assert!((leak_volume(a, c, 1.0 - ti, 1.0) - num).abs() < 1e-12);
        assert_eq!(leak_volume(a, c, 0.0, 0.0), 0.0);
    }
}
