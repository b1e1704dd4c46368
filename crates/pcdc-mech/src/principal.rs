//! Principal values and axes of a symmetric 3×3 tensor by cyclic Jacobi rotations.
//!
//! Hand-written rather than nalgebra's `SymmetricEigen` because the plastic models'
//! WGSL bodies must repeat the same operations to match the CPU to rounding: Jacobi needs
//! only + − × ÷ and `sqrt`, a fixed sweep order and a fixed stop, all of which WGSL has.
//! In plane strain (xz = yz = 0) only the xy rotation is ever non-trivial, so σzz stays a
//! principal value with axis z exactly.

use crate::model::Sym6;

/// Largest number of Jacobi sweeps; 3×3 tensors reach [`JACOBI_STOP`] in 3–5 sweeps
/// (convergence is quadratic).
const MAX_SWEEPS: usize = 12;

/// The sweeps stop when the squared off-diagonal norm falls to this fraction of the
/// squared diagonal norm (or to zero): off-diagonals below 1e-16 of the diagonal, i.e. f64
/// rounding. The principal values are then exact to rounding (their error is of the
/// order of the squared off-diagonal over the gap) and the axes to 1e-16 over the
/// relative gap. A tighter stop only adds sweeps that change nothing.
pub const JACOBI_STOP: f64 = 1e-32;

/// Principal values `values[0] ≤ values[1] ≤ values[2]` (tension positive: `values[0]`
/// is the most compressive) and unit axes `axes[i]` (a column each) of a symmetric
/// tensor given as xx, yy, zz, xy, yz, xz.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Principal {
    /// Principal values, ascending.
    pub values: [f64; 3],
    /// `axes[i]` is the unit axis of `values[i]` (x, y, z components).
    pub axes: [[f64; 3]; 3],
}

/// Decomposes `t` (xx, yy, zz, xy, yz, xz) into principal values and axes, for
/// components between about 1e-150 and 1e150 in magnitude: the sweeps' stop test and
/// each rotation square them (beyond, the squares overflow or underflow and the sweeps
/// stop early; stresses in Pa or in any engineering unit system are far inside).
pub fn principal(t: &Sym6) -> Principal {
    let mut a = [[t[0], t[3], t[5]], [t[3], t[1], t[4]], [t[5], t[4], t[2]]];
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    // Plane strain (yz = xz = 0): the first sweep's xy rotation is the whole work (the
    // other two rotations meet exact zeros and the next sweep stops), so do only it.
    let sweeps = if t[4] == 0.0 && t[5] == 0.0 {
        rotate(&mut a, &mut v, 0, 1);
        0
    } else {
        MAX_SWEEPS
    };
    for _ in 0..sweeps {
        let off = a[0][1] * a[0][1] + a[1][2] * a[1][2] + a[0][2] * a[0][2];
        let diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if off <= JACOBI_STOP * diag || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (1, 2), (0, 2)] {
            rotate(&mut a, &mut v, p, q);
        }
    }
    ascending([a[0][0], a[1][1], a[2][2]], |k| [v[0][k], v[1][k], v[2][k]])
}

/// The diagonal `d` of a rotated tensor sorted ascending, each value with its axis
/// (`axis(k)`: column k of the accumulated rotation).
#[inline(always)]
fn ascending(d: [f64; 3], axis: impl Fn(usize) -> [f64; 3]) -> Principal {
    let mut idx = [0usize, 1, 2];
    if d[idx[1]] < d[idx[0]] {
        idx.swap(0, 1);
    }
    if d[idx[2]] < d[idx[1]] {
        idx.swap(1, 2);
    }
    if d[idx[1]] < d[idx[0]] {
        idx.swap(0, 1);
    }
    Principal {
        values: [d[idx[0]], d[idx[1]], d[idx[2]]],
        axes: [axis(idx[0]), axis(idx[1]), axis(idx[2])],
    }
}

/// How many tensors [`principal_lanes`] decomposes together.
pub const LANES: usize = 8;

/// A 3×3 matrix of lanes: `m[i][j][l]` is entry (i, j) of lane l.
type LaneMatrix = [[[f64; LANES]; 3]; 3];

/// [`principal`] of [`LANES`] tensors at once, with the same result for each, bit for
/// bit (but for the sign of an entry that is exactly zero, which an idle lane's
/// identity rotation may turn from −0 to +0): the lanes run the same rotations in
/// lockstep, each lane's rotation replaced by the identity where [`principal`] would
/// skip it or has stopped. The point is speed: a rotation is a chain of a root, a division and a
/// root, and one tensor's rotations depend on each other, so one decomposition waits on
/// that chain; four independent chains side by side keep the divider busy and fit in
/// vector registers.
///
/// On x86-64 processors with AVX2 the lanes run in 256-bit vectors (detected at run
/// time; the default build targets baseline x86-64, whose 128-bit vectors hold two
/// lanes): the same operations, without fused multiply-adds, so the same results bit
/// for bit on every processor.
pub fn principal_lanes(ts: &[Sym6; LANES]) -> [Principal; LANES] {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor has AVX2, checked on the line above.
        return unsafe { principal_lanes_avx2(ts) };
    }
    principal_lanes_any(ts)
}

/// [`principal_lanes_any`] compiled for AVX2 (probe: 99 → 71 ns per tensor on an AMD
/// EPYC).
///
/// # Safety
///
/// The processor must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn principal_lanes_avx2(ts: &[Sym6; LANES]) -> [Principal; LANES] {
    principal_lanes_any(ts)
}

/// The body of [`principal_lanes`], inlined into each instruction-set version.
#[inline(always)]
fn principal_lanes_any(ts: &[Sym6; LANES]) -> [Principal; LANES] {
    let mut a: LaneMatrix = [[[0.0; LANES]; 3]; 3];
    let mut v: LaneMatrix = [[[0.0; LANES]; 3]; 3];
    let mut plane = [false; LANES];
    for (l, t) in ts.iter().enumerate() {
        let m = [[t[0], t[3], t[5]], [t[3], t[1], t[4]], [t[5], t[4], t[2]]];
        for i in 0..3 {
            for j in 0..3 {
                a[i][j][l] = m[i][j];
            }
            v[i][i][l] = 1.0;
        }
        plane[l] = t[4] == 0.0 && t[5] == 0.0;
    }
    // Plane lanes: the one xy rotation, as in [`principal`]; the others sweep.
    if plane.iter().any(|&p| p) {
        rotate_lanes(&mut a, &mut v, 0, 1, &plane);
    }
    let mut live = plane.map(|p| !p);
    for _ in 0..MAX_SWEEPS {
        for (l, on) in live.iter_mut().enumerate() {
            let off = a[0][1][l] * a[0][1][l] + a[1][2][l] * a[1][2][l] + a[0][2][l] * a[0][2][l];
            let diag = a[0][0][l] * a[0][0][l] + a[1][1][l] * a[1][1][l] + a[2][2][l] * a[2][2][l];
            if off <= JACOBI_STOP * diag || off == 0.0 {
                *on = false;
            }
        }
        if !live.iter().any(|&on| on) {
            break;
        }
        // Written out, so that each rotation's indices are constants.
        rotate_lanes(&mut a, &mut v, 0, 1, &live);
        rotate_lanes(&mut a, &mut v, 1, 2, &live);
        rotate_lanes(&mut a, &mut v, 0, 2, &live);
    }
    std::array::from_fn(|l| {
        ascending([a[0][0][l], a[1][1][l], a[2][2][l]], |k| {
            [v[0][k][l], v[1][k][l], v[2][k][l]]
        })
    })
}

/// [`rotate`] in every lane where `on` is set, with the same operations; a lane that is
/// off, or whose rotation [`rotate`] skips (a_pq = 0, or underflow), keeps its entries
/// (see [`principal_lanes`] on the sign of zeros).
#[inline(always)]
fn rotate_lanes(a: &mut LaneMatrix, v: &mut LaneMatrix, p: usize, q: usize, on: &[bool; LANES]) {
    let r = 3 - p - q;
    // Per lane: the rotation's t, c, s where it applies, else the identity (t = s = 0,
    // c = 1), which leaves every entry as it is (but a_pq, kept by a select, and the
    // sign of an entry that is exactly zero): a select for every entry costs more.
    let (mut t, mut c, mut s, mut go) = ([0.0; LANES], [0.0; LANES], [0.0; LANES], [false; LANES]);
    for l in 0..LANES {
        let apq = a[p][q][l];
        let d = a[q][q][l] - a[p][p][l];
        let rho = (d * d + 4.0 * apq * apq).sqrt();
        let e = rho + d.abs();
        let tl = 2.0 * apq / e;
        let m = on[l] && apq != 0.0 && e > 0.0;
        let tt = if d >= 0.0 { tl } else { -tl };
        let cc = (e / (2.0 * rho)).sqrt();
        t[l] = if m { tt } else { 0.0 };
        c[l] = if m { cc } else { 1.0 };
        s[l] = if m { tt * cc } else { 0.0 };
        go[l] = m;
    }
    for l in 0..LANES {
        let (app, aqq, apq) = (a[p][p][l], a[q][q][l], a[p][q][l]);
        let (apr, aqr) = (a[p][r][l], a[q][r][l]);
        a[p][p][l] = app - t[l] * apq;
        a[q][q][l] = aqq + t[l] * apq;
        a[p][q][l] = if go[l] { 0.0 } else { apq };
        a[q][p][l] = a[p][q][l];
        a[p][r][l] = c[l] * apr - s[l] * aqr;
        a[r][p][l] = a[p][r][l];
        a[q][r][l] = s[l] * apr + c[l] * aqr;
        a[r][q][l] = a[q][r][l];
        for row in v.iter_mut() {
            let (vp, vq) = (row[p][l], row[q][l]);
            row[p][l] = c[l] * vp - s[l] * vq;
            row[q][l] = s[l] * vp + c[l] * vq;
        }
    }
}

/// One Jacobi rotation zeroing `a[p][q]`. With d = a_qq − a_pp and ρ = √(d² + 4a_pq²),
/// the rotation's tangent is t = sgn(d) 2a_pq / (ρ + |d|) (the smaller root of
/// t² + 2θt − 1 = 0, θ = d / 2a_pq, as in Numerical Recipes) and its cosine
/// c = √((ρ + |d|) / 2ρ) (= 1/√(1 + t²)). Neither cancels, and the chain of slow
/// operations is a root, a division and a root (the θ form takes two roots and three
/// divisions one after another): the rotation is most of a plastic element's step in 3D.
fn rotate(a: &mut [[f64; 3]; 3], v: &mut [[f64; 3]; 3], p: usize, q: usize) {
    let apq = a[p][q];
    if apq == 0.0 {
        return;
    }
    let d = a[q][q] - a[p][p];
    let rho = (d * d + 4.0 * apq * apq).sqrt();
    let e = rho + d.abs();
    if e <= 0.0 {
        // a_pq² underflowed (|a_pq| < 1e-154 with d = 0): nothing to rotate at f64 scale.
        return;
    }
    let t = if d >= 0.0 {
        2.0 * apq / e
    } else {
        -2.0 * apq / e
    };
    let c = (e / (2.0 * rho)).sqrt();
    let s = t * c;
    let r = 3 - p - q; // the third index
    let (app, aqq, apr, aqr) = (a[p][p], a[q][q], a[p][r], a[q][r]);
    a[p][p] = app - t * apq;
    a[q][q] = aqq + t * apq;
    a[p][q] = 0.0;
    a[q][p] = 0.0;
    a[p][r] = c * apr - s * aqr;
    a[r][p] = a[p][r];
    a[q][r] = s * apr + c * aqr;
    a[r][q] = a[q][r];
    for row in v.iter_mut() {
        let (vp, vq) = (row[p], row[q]);
        row[p] = c * vp - s * vq;
        row[q] = s * vp + c * vq;
    }
}

/// Principal values of a plane tensor (yz = xz = 0: plane strain) in closed form, with
/// what [`compose_plane`] needs to rebuild a tensor on the same axes. In the plane the
/// values are c ∓ r, c = (xx + yy)/2, r = √(((xx − yy)/2)² + xy²), the major one on the
/// axis at θ with (cos 2θ, sin 2θ) = ((xx − yy)/2, xy)/r; zz is the third value. The
/// elastic-plastic models take this path in 2D: one square root and one division where
/// [`principal`] rotates and carries a 3×3 frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanePrincipal {
    /// Principal values, ascending (as [`Principal::values`]).
    pub values: [f64; 3],
    /// cos 2θ and sin 2θ of the in-plane major axis; (−1, 0) when the in-plane values are
    /// equal (any axes would do; this is the frame [`principal`] keeps).
    pub cos_sin_2theta: [f64; 2],
    /// Where the in-plane minor value, the in-plane major value and zz sit in `values`.
    pub slots: [usize; 3],
}

/// Decomposes a plane tensor `t` (xx, yy, zz, xy, yz = 0, xz = 0); see [`PlanePrincipal`].
/// The yz and xz components are not read.
pub fn plane(t: &Sym6) -> PlanePrincipal {
    let c = 0.5 * (t[0] + t[1]);
    let d = 0.5 * (t[0] - t[1]);
    let r = (d * d + t[3] * t[3]).sqrt();
    let cos_sin_2theta = if r > 0.0 {
        let inv = 1.0 / r;
        [d * inv, t[3] * inv]
    } else {
        // Major on y, minor on x: the frame [`principal`] leaves (identity, stable order).
        [-1.0, 0.0]
    };
    let (lo, hi, zz) = (c - r, c + r, t[2]);
    let (values, slots) = if zz <= lo {
        ([zz, lo, hi], [1, 2, 0])
    } else if zz >= hi {
        ([lo, hi, zz], [0, 1, 2])
    } else {
        ([lo, zz, hi], [0, 2, 1])
    };
    PlanePrincipal {
        values,
        cos_sin_2theta,
        slots,
    }
}

/// The plane tensor with principal values `values` (ordered as [`PlanePrincipal::values`]
/// was, not re-sorted) on the axes of `p`: the inverse of [`plane`].
pub fn compose_plane(values: &[f64; 3], p: &PlanePrincipal) -> Sym6 {
    let [minor, major, zz] = p.slots;
    let (a, b) = (values[minor], values[major]);
    let c = 0.5 * (a + b);
    let r = 0.5 * (b - a);
    let [cos2, sin2] = p.cos_sin_2theta;
    [c + r * cos2, c - r * cos2, values[zz], r * sin2, 0.0, 0.0]
}

/// The tensor Σ_i `values[i]` axes_i ⊗ axes_i (xx, yy, zz, xy, yz, xz): the inverse of
/// [`principal`] for new principal values on the same axes.
pub fn compose(values: &[f64; 3], axes: &[[f64; 3]; 3]) -> Sym6 {
    let mut t = [0.0; 6];
    for (s, n) in values.iter().zip(axes) {
        t[0] += s * n[0] * n[0];
        t[1] += s * n[1] * n[1];
        t[2] += s * n[2] * n[2];
        t[3] += s * n[0] * n[1];
        t[4] += s * n[1] * n[2];
        t[5] += s * n[0] * n[2];
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, scale: f64) -> bool {
        (a - b).abs() <= 1e-13 * scale
    }

    #[test]
    fn reproduces_the_tensor_and_orders_the_values() {
        let t = [3.0, -2.0, 0.5, 1.25, -0.75, 2.0];
        let p = principal(&t);
        assert!(p.values[0] <= p.values[1] && p.values[1] <= p.values[2]);
        let back = compose(&p.values, &p.axes);
        for k in 0..6 {
            assert!(close(back[k], t[k], 4.0), "{k}: {} vs {}", back[k], t[k]);
        }
        // Trace and orthonormal axes.
        assert!(close(p.values.iter().sum::<f64>(), t[0] + t[1] + t[2], 4.0));
        for i in 0..3 {
            for j in 0..3 {
                let d: f64 = (0..3).map(|k| p.axes[i][k] * p.axes[j][k]).sum();
                assert!(close(d, if i == j { 1.0 } else { 0.0 }, 1.0));
            }
        }
    }

    #[test]
    fn plane_strain_keeps_z_a_principal_axis_exactly() {
        let t = [-5.0, 1.0, -2.0, 3.0, 0.0, 0.0];
        let p = principal(&t);
        let z = p.axes.iter().position(|a| a[2] != 0.0).unwrap();
        assert_eq!(p.axes[z], [0.0, 0.0, 1.0]);
        assert_eq!(p.values[z], -2.0);
        let back = compose(&p.values, &p.axes);
        assert_eq!((back[4], back[5]), (0.0, 0.0));
    }

    #[test]
    fn plane_closed_form_matches_jacobi_and_round_trips() {
        // Every order of zz against the in-plane pair, an in-plane isotropic tensor, and
        // signs of xy and xx − yy.
        let cases = [
            [3.0, -2.0, 0.5, 1.25],
            [3.0, -2.0, -9.0, -1.25],
            [3.0, -2.0, 9.0, 0.0],
            [-2.0, 3.0, 0.0, 4.0],
            [1.5, 1.5, -1.0, 0.0],
            [-1e7, -3e7, -2e7, 5e6],
        ];
        for c in cases {
            let t = [c[0], c[1], c[2], c[3], 0.0, 0.0];
            let sc = 4.0 * c.iter().fold(0.0f64, |m: f64, v: &f64| m.max(v.abs()));
            let p = plane(&t);
            let j = principal(&t);
            for k in 0..3 {
                assert!(
                    close(p.values[k], j.values[k], sc),
                    "{c:?}: {:?} vs {:?}",
                    p.values,
                    j.values
                );
            }
            let back = compose_plane(&p.values, &p);
            for k in 0..6 {
                assert!(
                    close(back[k], t[k], sc),
                    "{c:?} {k}: {} vs {}",
                    back[k],
                    t[k]
                );
            }
            // New values on the same axes: as the Jacobi frame composes them.
            let new = [p.values[0] - 0.25, p.values[1] + 0.5, p.values[2] * 0.5];
            let a = compose_plane(&new, &p);
            let b = compose(&new, &j.axes);
            for k in 0..6 {
                assert!(close(a[k], b[k], sc), "{c:?} {k}: {} vs {}", a[k], b[k]);
            }
        }
    }

    #[test]
    fn round_trips_at_any_scale_and_near_diagonal() {
        // Scales from tiny to large, a nearly diagonal tensor (one rotation of a small
        // angle), and an off-diagonal so small that its square underflows.
        for scale in [1e-140, 1e-3, 1.0, 3e7, 1e140] {
            for t in [
                [3.0, -2.0, 0.5, 1.25, -0.75, 2.0],
                [-33.6, -10.04, -10.03, 1e-4, -5e-4, 2e-6],
                [1.0, 1.0, 1.0, 1e-9, 0.0, 1e-9],
            ] {
                let t = t.map(|v| v * scale);
                let p = principal(&t);
                let back = compose(&p.values, &p.axes);
                let m = t.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for k in 0..6 {
                    assert!(
                        close(back[k], t[k], 4.0 * m),
                        "{scale} {k}: {} vs {}",
                        back[k],
                        t[k]
                    );
                }
            }
        }
        let p = principal(&[2.0, 2.0, 1.0, 1e-170, 0.0, 1e-170]);
        assert!(p.values.iter().all(|v| v.is_finite()));
        assert_eq!(p.values, [1.0, 2.0, 2.0]);
    }

    proptest::proptest! {
        /// Tensors from far off diagonal to nearly diagonal (the small-angle series):
        /// values as nalgebra's eigen-solver gives them, axes orthonormal, and the tensor
        /// rebuilt, all to rounding.
        #[test]
        fn matches_nalgebra_at_every_angle(
            diag in proptest::array::uniform3(-1.0f64..1.0),
            off in proptest::array::uniform3(-1.0f64..1.0),
            tiny in -14i32..1,
            scale in -6i32..9,
        ) {
            let (k, f) = (10f64.powi(scale), 10f64.powi(tiny));
            let t = [diag[0] * k, diag[1] * k, diag[2] * k, off[0] * f * k, off[1] * f * k, off[2] * f * k];
            let p = principal(&t);
            let m = nalgebra::Matrix3::new(t[0], t[3], t[5], t[3], t[1], t[4], t[5], t[4], t[2]);
            let mut ev: Vec<f64> = m.symmetric_eigen().eigenvalues.iter().copied().collect();
            ev.sort_by(f64::total_cmp);
            let sc = 8.0 * t.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for i in 0..3 {
                proptest::prop_assert!(close(p.values[i], ev[i], sc), "{:?} vs {:?}", p.values, ev);
                for j in 0..3 {
                    let d: f64 = (0..3).map(|c| p.axes[i][c] * p.axes[j][c]).sum();
                    let want = if i == j { 1.0 } else { 0.0 };
                    proptest::prop_assert!((d - want).abs() <= 2e-15, "axes {i}, {j}: {d}");
                }
            }
            let back = compose(&p.values, &p.axes);
            for c in 0..6 {
                proptest::prop_assert!(close(back[c], t[c], sc), "{c}: {} vs {}", back[c], t[c]);
            }
        }
    }

    proptest::proptest! {
        /// The lanes give each tensor what [`principal`] gives it, bit for bit: plane and
        /// 3D tensors, diagonal ones and ones of every off-diagonal size side by side;
        /// the AVX2 and the portable build of the lanes alike.
        #[test]
        fn lanes_are_the_one_tensor_decomposition_bit_for_bit(
            ts in proptest::array::uniform8((
                proptest::array::uniform6(-1.0f64..1.0),
                -16i32..1,
                0u8..3,
            )),
        ) {
            let ts = ts.map(|(t, tiny, kind)| {
                let f = 10f64.powi(tiny);
                let mut t = [t[0], t[1], t[2], t[3] * f, t[4] * f, t[5] * f];
                match kind {
                    0 => (t[4], t[5]) = (0.0, 0.0),
                    1 => (t[3], t[4], t[5]) = (0.0, 0.0, 0.0),
                    _ => {}
                }
                t.map(|v| v * 3e7)
            });
            let lanes = principal_lanes(&ts);
            // The portable version too, where the run-time dispatch picks AVX2.
            let portable = principal_lanes_any(&ts);
            for ((t, q), r) in ts.iter().zip(&lanes).zip(&portable) {
                proptest::prop_assert_eq!(q.values.map(f64::to_bits), r.values.map(f64::to_bits));
                proptest::prop_assert_eq!(
                    q.axes.map(|a| a.map(f64::to_bits)),
                    r.axes.map(|a| a.map(f64::to_bits))
                );
                let p = principal(t);
                proptest::prop_assert_eq!(p.values.map(f64::to_bits), q.values.map(f64::to_bits));
                proptest::prop_assert_eq!(
                    p.axes.map(|a| a.map(f64::to_bits)),
                    q.axes.map(|a| a.map(f64::to_bits))
                );
            }
        }
    }

    #[test]
    fn diagonal_and_repeated_values() {
        let p = principal(&[2.0, 2.0, 2.0, 0.0, 0.0, 0.0]);
        assert_eq!(p.values, [2.0; 3]);
        let p = principal(&[1.0, 1.0, 4.0, 0.0, 0.0, 0.0]);
        assert_eq!(p.values, [1.0, 1.0, 4.0]);
    }
}
