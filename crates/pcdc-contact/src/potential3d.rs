//! Munjiza's potential contact force between two tetrahedra (manual 7.3.1, eq. 52-58,
//! one dimension up).
//!
//! Each tetrahedron T carries the potential φ_T(x) = 4 min_i λ_i(x) (λ the barycentric
//! coordinates; the 3D form of eq. 58, 4 V_i / V in place of 3 A_i / A): 0 on its
//! boundary, 1 at its centroid, linear in each of the four sub-tetrahedra formed by a
//! face and the centroid (in the sub-tetrahedron of the face opposite vertex k,
//! φ_T = 4 λ_k). The normal contact force between a contactor c and a target t is the
//! penalty p times (eq. 56-57, with the divergence theorem in place of Green's formula)
//!
//! f_c = ∫_{β_c ∩ β_t} (∇φ_c − ∇φ_t) dV = −∮_{∂c ∩ β_t} φ_t n_c dA + ∮_{∂t ∩ β_c} φ_c n_t dA,
//!
//! φ vanishing on each tetrahedron's own boundary, with f_t = −f_c. Each boundary
//! integral is evaluated exactly: every face triangle of one tetrahedron is clipped
//! (Sutherland-Hodgman) by each sub-tetrahedron of the other, where φ is linear; the
//! sub-tetrahedron k is the half-space intersection λ_k ≥ 0, λ_j − λ_k ≥ 0 (j ≠ k), so
//! the clipping planes are level sets of the barycentric coordinates and do not depend
//! on the vertex orientation. The clipped convex polygon is fan-triangulated and each
//! triangle integrated with the three-point edge-midpoint rule, exact for the degree-2
//! integrand (φ linear times a linear face shape function). The load at a quadrature
//! point goes to the face's three nodes with the face's barycentric weights, and its
//! reaction to the other tetrahedron's four nodes with that tetrahedron's barycentric
//! coordinates at the same point, so action equals reaction and their moments balance
//! exactly (to rounding). Outward face normals are taken from the geometry (pointing
//! away from the opposite vertex), so either vertex orientation of the input works.

/// Forces (N) on the four nodes of each tetrahedron of a pair.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairForce3 {
    /// Forces on the contactor's nodes, `[x, y, z]` per node.
    pub contactor: [[f64; 3]; 4],
    /// Forces on the target's nodes.
    pub target: [[f64; 3]; 4],
}

type V3 = [f64; 3];

#[inline]
fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The barycentric coordinates of a tetrahedron as affine functions:
/// λ_i(x) = g_i · (x − p_0) + c_i.
struct Bary {
    p0: V3,
    g: [V3; 4],
}

impl Bary {
    /// `None` for a degenerate (zero-volume) or non-finite tetrahedron.
    fn new(t: &[V3; 4]) -> Option<Self> {
        let (e1, e2, e3) = (sub(t[1], t[0]), sub(t[2], t[0]), sub(t[3], t[0]));
        let (c23, c31, c12) = (cross(e2, e3), cross(e3, e1), cross(e1, e2));
        let det = dot(e1, c23);
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let inv = 1.0 / det;
        let g1 = c23.map(|v| v * inv);
        let g2 = c31.map(|v| v * inv);
        let g3 = c12.map(|v| v * inv);
        let g0 = [
            -(g1[0] + g2[0] + g3[0]),
            -(g1[1] + g2[1] + g3[1]),
            -(g1[2] + g2[2] + g3[2]),
        ];
        Some(Bary {
            p0: t[0],
            g: [g0, g1, g2, g3],
        })
    }

    #[inline]
    fn eval(&self, x: V3) -> [f64; 4] {
        let d = sub(x, self.p0);
        let l1 = dot(self.g[1], d);
        let l2 = dot(self.g[2], d);
        let l3 = dot(self.g[3], d);
        [1.0 - l1 - l2 - l3, l1, l2, l3]
    }
}

/// The potential φ_T(x) = 4 min λ_i of tetrahedron `t` (either orientation) at `x`;
/// 0 outside and for a degenerate tetrahedron. Dimensionless, 1 at the centroid.
pub fn tet_potential(t: &[[f64; 3]; 4], x: [f64; 3]) -> f64 {
    match Bary::new(t) {
        Some(b) => {
            let l = b.eval(x);
            (4.0 * l[0].min(l[1]).min(l[2]).min(l[3])).max(0.0)
        }
        None => 0.0,
    }
}

/// Capacity of a clipped polygon: a triangle cut by seven planes has at most ten
/// vertices; the margin absorbs near-duplicate vertices from rounding.
const CAP: usize = 12;

/// A small convex polygon in 3D with the values of the barycentric coordinates of the
/// target at its vertices carried along (they are affine, so they interpolate exactly
/// like the positions).
#[derive(Clone, Copy)]
struct Poly {
    n: usize,
    x: [V3; CAP],
    l: [[f64; 4]; CAP],
}

impl Poly {
    /// Sutherland-Hodgman: keeps the part where `f(λ) ≥ 0` (`f` affine in λ).
    fn clip(&self, f: impl Fn(&[f64; 4]) -> f64, out: &mut Poly) {
        out.n = 0;
        if self.n == 0 {
            return;
        }
        let mut push = |x: V3, l: [f64; 4]| {
            if out.n < CAP {
                out.x[out.n] = x;
                out.l[out.n] = l;
                out.n += 1;
            }
        };
        let mut prev = self.n - 1;
        let mut fp = f(&self.l[prev]);
        for i in 0..self.n {
            let fi = f(&self.l[i]);
            if (fi >= 0.0) != (fp >= 0.0) {
                // The edge prev -> i crosses the plane.
                let s = fp / (fp - fi);
                let (a, b) = (self.x[prev], self.x[i]);
                let (la, lb) = (self.l[prev], self.l[i]);
                push(
                    std::array::from_fn(|k| a[k] + s * (b[k] - a[k])),
                    std::array::from_fn(|k| la[k] + s * (lb[k] - la[k])),
                );
            }
            if fi >= 0.0 {
                push(self.x[i], self.l[i]);
            }
            prev = i;
            fp = fi;
        }
    }
}

/// Clips `start` by the planes `(j, k)` in turn: keeps λ_j − λ_k ≥ 0 (λ_j ≥ 0 for
/// k = 4), writing alternately into the two buffers. A plane that leaves every vertex
/// inside costs no copy. Returns where the result lies: `None` for `start` itself,
/// `Some(i)` for `bufs[i]`; an empty result has fewer than three vertices.
fn clip_chain(
    start: &Poly,
    planes: impl Iterator<Item = (usize, usize)>,
    bufs: &mut [Poly; 2],
) -> Option<usize> {
    let mut cur: Option<usize> = None;
    for (j, k) in planes {
        let f = move |l: &[f64; 4]| if k < 4 { l[j] - l[k] } else { l[j] };
        let src: &Poly = match cur {
            None => start,
            Some(i) => &bufs[i],
        };
        let (mut any_in, mut all_in) = (false, true);
        for l in &src.l[..src.n] {
            let inside = f(l) >= 0.0;
            any_in |= inside;
            all_in &= inside;
        }
        if all_in {
            continue;
        }
        let dst = match cur {
            None => 0,
            Some(i) => 1 - i,
        };
        if !any_in {
            bufs[dst].n = 0;
            return Some(dst);
        }
        let (lo, hi) = bufs.split_at_mut(1);
        match cur {
            None => start.clip(f, &mut lo[0]),
            Some(0) => lo[0].clip(f, &mut hi[0]),
            Some(_) => hi[0].clip(f, &mut lo[0]),
        }
        cur = Some(dst);
        if bufs[dst].n < 3 {
            return cur;
        }
    }
    cur
}

/// Adds the boundary integral of the faces of `c` inside `t`:
/// −p ∮_{∂c ∩ t} φ_t n_c dA onto `fc`, and its reaction onto `ft`.
fn one_way(c: &[V3; 4], bc: &Bary, bt: &Bary, penalty: f64, fc: &mut [V3; 4], ft: &mut [V3; 4]) {
    let empty = Poly {
        n: 0,
        x: [[0.0; 3]; CAP],
        l: [[0.0; 4]; CAP],
    };
    // Clipping buffers, written alternately (no polygon copies).
    let (mut face, mut wbufs, mut pbufs) = (empty, [empty; 2], [empty; 2]);
    for i in 0..4 {
        // Face opposite vertex i.
        let v = [c[(i + 1) % 4], c[(i + 2) % 4], c[(i + 3) % 4]];
        let lv = v.map(|x| bt.eval(x));
        // Entirely outside one face plane of the target: nothing to integrate.
        if (0..4).any(|j| lv.iter().all(|l| l[j] <= 0.0)) {
            continue;
        }
        let nrm = cross(sub(v[1], v[0]), sub(v[2], v[0]));
        let len = dot(nrm, nrm).sqrt();
        if len == 0.0 || !len.is_finite() {
            continue;
        }
        // Outward: away from the opposite vertex.
        let sign = if dot(nrm, sub(v[0], c[i])) < 0.0 {
            -1.0
        } else {
            1.0
        };
        let n = nrm.map(|x| sign * x / len);
        // The face inside the whole target first (λ_j ≥ 0 for all j) ...
        face.n = 3;
        face.x[..3].copy_from_slice(&v);
        face.l[..3].copy_from_slice(&lv);
        let whole = match clip_chain(&face, (0..4).map(|j| (j, 4)), &mut wbufs) {
            None => &face,
            Some(i) => &wbufs[i],
        };
        if whole.n < 3 {
            continue;
        }
        // Per-node load sums along n over this face: Σ λ_c q and Σ λ_t q.
        let (mut sc, mut st) = ([0.0; 4], [0.0; 4]);
        // ... then in each sub-tetrahedron k (λ_j − λ_k ≥ 0, j ≠ k), where φ_t = 4 λ_k.
        for k in 0..4 {
            let planes = (0..4).filter(move |&j| j != k).map(move |j| (j, k));
            let p = match clip_chain(whole, planes, &mut pbufs) {
                None => whole,
                Some(i) => &pbufs[i],
            };
            if p.n < 3 {
                continue;
            }
            // Fan triangles (q_0, q_m, q_m+1), three edge-midpoint points each.
            for m in 1..p.n - 1 {
                let (x0, x1, x2) = (p.x[0], p.x[m], p.x[m + 1]);
                let ar = cross(sub(x1, x0), sub(x2, x0));
                let area = 0.5 * dot(ar, ar).sqrt();
                if area == 0.0 {
                    continue;
                }
                let (l0, l1, l2) = (p.l[0], p.l[m], p.l[m + 1]);
                let w = penalty * area / 3.0;
                for (xa, xb, la, lb) in [(x0, x1, l0, l1), (x1, x2, l1, l2), (x2, x0, l2, l0)] {
                    let phi = (2.0 * (la[k] + lb[k])).max(0.0);
                    let q = w * phi;
                    // Target barycentrics carried through the clipping; the contactor's
                    // at the same point (the face's three weights, ≈ 0 for vertex i).
                    let lc = bc.eval(std::array::from_fn(|d| 0.5 * (xa[d] + xb[d])));
                    for a in 0..4 {
                        sc[a] += lc[a] * q;
                        st[a] += 0.5 * (la[a] + lb[a]) * q;
                    }
                }
            }
        }
        // The load −q n on the contactor's face, +q n on the target.
        for a in 0..4 {
            for d in 0..3 {
                fc[a][d] -= sc[a] * n[d];
                ft[a][d] += st[a] * n[d];
            }
        }
    }
}

/// The normal contact force between contactor `c` and target `t` (vertex coordinates,
/// m, either orientation) with penalty `penalty` (P_n of eq. 52, Pa): zero when they do
/// not overlap or one is degenerate, equal and opposite on the two tetrahedra otherwise
/// (N per node).
pub fn tet_pair_force(c: &[[f64; 3]; 4], t: &[[f64; 3]; 4], penalty: f64) -> PairForce3 {
    let mut out = PairForce3::default();
    // Cheap rejection on bounding boxes.
    for k in 0..3 {
        let (cmin, cmax) = (
            c.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min),
            c.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max),
        );
        let (tmin, tmax) = (
            t.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min),
            t.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max),
        );
        if cmax <= tmin || tmax <= cmin {
            return out;
        }
    }
    let (Some(bc), Some(bt)) = (Bary::new(c), Bary::new(t)) else {
        return out;
    };
    // Separating face planes: all of one tetrahedron outside a face of the other.
    let lc_of_t = t.map(|x| bc.eval(x));
    let lt_of_c = c.map(|x| bt.eval(x));
    for j in 0..4 {
        if lc_of_t.iter().all(|l| l[j] <= 0.0) || lt_of_c.iter().all(|l| l[j] <= 0.0) {
            return out;
        }
    }
    one_way(c, &bc, &bt, penalty, &mut out.contactor, &mut out.target);
    one_way(t, &bt, &bc, penalty, &mut out.target, &mut out.contactor);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const P: f64 = 1e9;

    fn total(f: &[[f64; 3]; 4]) -> [f64; 3] {
        std::array::from_fn(|d| f.iter().map(|v| v[d]).sum())
    }

    fn rotate(p: V3, a: f64, b: f64, c: f64) -> V3 {
        // z(a) then y(b) then x(c).
        let (sa, ca) = a.sin_cos();
        let (sb, cb) = b.sin_cos();
        let (sc, cc) = c.sin_cos();
        let p = [ca * p[0] - sa * p[1], sa * p[0] + ca * p[1], p[2]];
        let p = [cb * p[0] + sb * p[2], p[1], -sb * p[0] + cb * p[2]];
        [p[0], cc * p[1] - sc * p[2], sc * p[1] + cc * p[2]]
    }

    /// A regular tetrahedron of circumradius `r` around `centre`, rotated; `flip` swaps
    /// two vertices (the other orientation).
    fn tet(centre: V3, r: f64, rot: V3, flip: bool) -> [V3; 4] {
        let s = r / 3f64.sqrt();
        let base = [[s, s, s], [s, -s, -s], [-s, s, -s], [-s, -s, s]];
        let mut t = base.map(|p| {
            let q = rotate(p, rot[0], rot[1], rot[2]);
            [q[0] + centre[0], q[1] + centre[1], q[2] + centre[2]]
        });
        if flip {
            t.swap(0, 1);
        }
        t
    }

    fn volume(t: &[V3; 4]) -> f64 {
        dot(sub(t[1], t[0]), cross(sub(t[2], t[0]), sub(t[3], t[0]))).abs() / 6.0
    }

    #[test]
    fn potential_is_one_at_the_centroid_and_zero_on_faces() {
        let t = tet([0.3, -0.2, 0.1], 1.0, [0.3, 0.2, 0.1], true);
        let g: V3 = std::array::from_fn(|d| 0.25 * t.iter().map(|p| p[d]).sum::<f64>());
        assert!((tet_potential(&t, g) - 1.0).abs() < 1e-12);
        let fc: V3 = std::array::from_fn(|d| (t[0][d] + t[1][d] + t[2][d]) / 3.0);
        assert!(tet_potential(&t, fc).abs() < 1e-12);
        assert_eq!(tet_potential(&t, [10.0, 0.0, 0.0]), 0.0);
    }

    #[test]
    fn apart_gives_zero() {
        let c = tet([0.0, 0.0, 0.0], 1.0, [0.1, 0.2, 0.3], false);
        let t = tet([2.5, 0.0, 0.0], 1.0, [0.4, 0.0, 0.7], false);
        assert_eq!(tet_pair_force(&c, &t, P), PairForce3::default());
        // Boxes overlap but a face plane separates them.
        let t = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let c = [
            [0.6, 0.6, 0.6],
            [0.9, 0.3, 0.3],
            [0.3, 0.9, 0.3],
            [0.3, 0.3, 0.9],
        ];
        assert_eq!(tet_pair_force(&c, &t, P), PairForce3::default());
    }

    #[test]
    fn degenerate_gives_zero() {
        let flat = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
        let t = tet([0.2, 0.2, 0.0], 1.0, [0.0; 3], false);
        assert_eq!(tet_pair_force(&flat, &t, P), PairForce3::default());
        assert_eq!(tet_pair_force(&t, &flat, P), PairForce3::default());
    }

    #[test]
    fn small_contactor_inside_a_sub_tet_feels_minus_p_volume_grad_phi() {
        // A large target and a tiny contactor well inside the sub-tetrahedron of the
        // face z = 0 (opposite vertex 3): ∮ φ_t n dA = ∫ ∇φ_t dV exactly, and there
        // φ_t = 4 λ_3 = 4 z / 10, ∇φ_t = (0, 0, 0.4).
        let big = [
            [0.0, 0.0, 0.0],
            [10.0, 0.0, 0.0],
            [0.0, 10.0, 0.0],
            [0.0, 0.0, 10.0],
        ];
        for (flip_t, flip_c) in [(false, false), (true, false), (false, true), (true, true)] {
            let mut t = big;
            if flip_t {
                t.swap(1, 2);
            }
            let c = tet([3.0, 2.0, 1.0], 0.2, [0.3, 0.5, 0.7], flip_c);
            let v = volume(&c);
            let tol = 1e-9 * P * v;
            let f = tet_pair_force(&c, &t, P);
            let fc = total(&f.contactor);
            let expect = [0.0, 0.0, -P * v * 0.4];
            for d in 0..3 {
                assert!((fc[d] - expect[d]).abs() < tol, "{fc:?} vs {expect:?}");
            }
            // Roles swapped: the big one is the contactor and feels the reaction.
            let g = tet_pair_force(&t, &c, P);
            let ft = total(&g.target);
            for d in 0..3 {
                assert!((ft[d] - expect[d]).abs() < tol, "{ft:?} vs {expect:?}");
            }
        }
    }

    #[test]
    fn flat_overlap_of_two_faces_matches_the_closed_form() {
        // Two tetrahedra with parallel opposite faces (z = 0 face up, z = δ face down)
        // overlapping in a thin slab of thickness δ: with λ linear in z the force is
        // p ∫ (∇φ_c − ∇φ_t) dV over the slab, computed here in closed form for the
        // slab's volume to first order in δ and compared with a finer δ halving.
        let t = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, -1.0],
        ];
        let d = 1e-3;
        let c = [
            [0.0, 0.0, -d],
            [1.0, 0.0, -d],
            [0.0, 1.0, -d],
            [0.0, 0.0, 1.0 - d],
        ];
        // Overlap: the slab -d ≤ z ≤ 0 inside both (the triangle x, y ≥ 0, x + y ≤ 1
        // shrinks linearly with depth in each tet; to first order area 1/2).
        // In t near its top face z = 0 (opposite vertex 3): φ_t = 4 λ_3 = −4 z, ∇φ_t =
        // (0, 0, −4); in c near its bottom face: φ_c = 4 (z + d), ∇φ_c = (0, 0, 4).
        // f_c ≈ p (0.5 d) (8) ẑ = 4 p d ẑ (upwards, away from t).
        let f = tet_pair_force(&c, &t, P);
        let fc = total(&f.contactor);
        let expect = 4.0 * P * d;
        assert!(fc[0].abs() < 1e-6 * expect && fc[1].abs() < 1e-6 * expect);
        assert!(
            (fc[2] - expect).abs() < 1e-2 * expect,
            "{} vs {expect}",
            fc[2]
        );
    }

    proptest! {
        /// Action equals reaction, the pair carries no net moment, and swapping the
        /// roles gives the same forces, for any overlap and either orientation.
        #[test]
        fn action_reaction_moment_and_symmetry(cx in -1.2f64..1.2, cy in -1.2f64..1.2, cz in -1.2f64..1.2,
                                                r1 in 0.3f64..1.2, r2 in 0.3f64..1.2,
                                                a1 in 0.0f64..6.3, b1 in 0.0f64..6.3, c1 in 0.0f64..6.3,
                                                a2 in 0.0f64..6.3, b2 in 0.0f64..6.3, c2 in 0.0f64..6.3,
                                                f1: bool, f2: bool) {
            let c = tet([cx, cy, cz], r1, [a1, b1, c1], f1);
            let t = tet([0.0, 0.0, 0.0], r2, [a2, b2, c2], f2);
            let f = tet_pair_force(&c, &t, P);
            let (fc, ft) = (total(&f.contactor), total(&f.target));
            let scale = P * r1.max(r2).powi(2);
            for d in 0..3 {
                prop_assert!((fc[d] + ft[d]).abs() < 1e-9 * scale, "{:?} {:?}", fc, ft);
            }
            let mut moment = [0.0; 3];
            for a in 0..4 {
                let (mc, mt) = (cross(c[a], f.contactor[a]), cross(t[a], f.target[a]));
                for d in 0..3 {
                    moment[d] += mc[d] + mt[d];
                }
            }
            for d in 0..3 {
                prop_assert!(moment[d].abs() < 1e-9 * scale * 3.0, "moment {:?}", moment);
            }
            let g = tet_pair_force(&t, &c, P);
            for a in 0..4 {
                for d in 0..3 {
                    prop_assert!((g.target[a][d] - f.contactor[a][d]).abs() < 1e-9 * scale);
                    prop_assert!((g.contactor[a][d] - f.target[a][d]).abs() < 1e-9 * scale);
                }
            }
        }

        /// The contactor is pushed away from the target for shallow overlaps: the force
        /// on it has a positive component along the centre-to-centre direction.
        #[test]
        fn repulsive_for_shallow_overlaps(th in 0.0f64..3.15, ph in 0.0f64..6.3, gap in 1.1f64..1.6,
                                          a in 0.0f64..6.3, b in 0.0f64..6.3, c in 0.0f64..6.3, flip: bool) {
            let t = tet([0.0; 3], 1.0, [a, b, c], flip);
            let u = [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()];
            let ct = tet(u.map(|x| gap * x), 1.0, [a + 0.5, b + 0.3, c + 0.2], !flip);
            let f = total(&tet_pair_force(&ct, &t, P).contactor);
            let along = dot(f, u);
            if along.abs() <= 1e-6 * P {
                // Barely or not touching: nothing to compare.
                return Ok(());
            }
            prop_assert!(along > 0.0, "force {:?} not away from the target (u {:?})", f, u);
        }
    }
}
