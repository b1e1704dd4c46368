//! Objective element kinematics: co-rotated strain of constant-strain simplices.
//!
//! The deformation gradient of a Tri3/Tet4 is `F = D_s D_m⁻¹` (current edge vectors
//! times inverse reference edge vectors). Its polar decomposition `F = R U` splits off
//! the rigid rotation; the strain `ε = U - I` and the strain rate `sym(Rᵀ Ḟ)` are measured
//! in the co-rotated frame, where the constitutive model works. For small rotations this
//! reduces to the manual's averaged small strain (7.2.1 eq. 11); for large rotations it
//! keeps a rigidly spinning body stress-free (objectivity). Nodal forces follow from the
//! first Piola-Kirchhoff stress `P = R σ`: `f_a = -V₀ P ∇N_a` (the large-rotation form of
//! eq. 14).

/// Inverse of the 2D reference edge matrix `D_m = [x₁ − x₀, x₂ − x₀]` (columns) of a
/// triangle with vertex coordinates `x` (6 values), row-major; row j is ∇N_{j+1}.
#[inline]
pub fn dm_inv_2d(x: &[f64]) -> [f64; 4] {
    let (a, b, c, d) = (x[2] - x[0], x[4] - x[0], x[3] - x[1], x[5] - x[1]);
    let det = a * d - b * c;
    [d / det, -b / det, -c / det, a / det]
}

/// Deformation gradient `F = D_s D_m⁻¹` (row-major 2x2) of a triangle with current
/// vertex coordinates `x` (6 values).
#[inline]
pub fn deformation_gradient_2d(x: &[f64; 6], m: &[f64]) -> [f64; 4] {
    let ds = [x[2] - x[0], x[4] - x[0], x[3] - x[1], x[5] - x[1]];
    [
        ds[0] * m[0] + ds[1] * m[2],
        ds[0] * m[1] + ds[1] * m[3],
        ds[2] * m[0] + ds[3] * m[2],
        ds[2] * m[1] + ds[3] * m[3],
    ]
}

/// 2D polar decomposition of `F` (row-major 2x2): returns `(cos θ, sin θ)` of `R`.
#[inline]
pub fn polar_2d(f: &[f64; 4]) -> (f64, f64) {
    let c = f[0] + f[3];
    let s = f[2] - f[1];
    let r = (c * c + s * s).sqrt();
    if r > 0.0 {
        (c / r, s / r)
    } else {
        (1.0, 0.0)
    }
}

/// 2D polar decomposition of `F = I + H` given the displacement gradient `H` (row-major
/// 2x2): returns `(cos θ, sin θ, cos θ − 1)`, the last without cancellation
/// (`cos θ − 1 = −s² / (r (c + r))` for `c ≥ 0`, with `c = 2 + H₀₀ + H₁₁`, `s = H₁₀ − H₀₁`, `r = √(c² + s²)`).
#[inline]
pub fn polar_2d_h(h: &[f64; 4]) -> (f64, f64, f64) {
    let c = 2.0 + (h[0] + h[3]);
    let s = h[2] - h[1];
    let r = (c * c + s * s).sqrt();
    if r > 0.0 {
        // The cancellation-free form needs c ≥ 0; beyond a quarter turn co − 1 has none.
        // One division per element: q = 1 / (r (c + r)) gives 1/r = (c + r) q.
        if c >= 0.0 {
            let q = 1.0 / (r * (c + r));
            let inv_r = (c + r) * q;
            (c * inv_r, s * inv_r, -(s * s) * q)
        } else {
            let inv_r = 1.0 / r;
            let co = c * inv_r;
            (co, s * inv_r, co - 1.0)
        }
    } else {
        (1.0, 0.0, 0.0)
    }
}

/// Determinant of a row-major 3x3 matrix.
#[inline]
pub fn det3(a: &[f64; 9]) -> f64 {
    a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6])
        + a[2] * (a[3] * a[7] - a[4] * a[6])
}

/// Inverse-transpose of a row-major 3x3 matrix (cofactor matrix over determinant).
#[inline]
pub fn inv_transpose3(a: &[f64; 9]) -> [f64; 9] {
    let inv_det = 1.0 / det3(a);
    [
        (a[4] * a[8] - a[5] * a[7]) * inv_det,
        (a[5] * a[6] - a[3] * a[8]) * inv_det,
        (a[3] * a[7] - a[4] * a[6]) * inv_det,
        (a[2] * a[7] - a[1] * a[8]) * inv_det,
        (a[0] * a[8] - a[2] * a[6]) * inv_det,
        (a[1] * a[6] - a[0] * a[7]) * inv_det,
        (a[1] * a[5] - a[2] * a[4]) * inv_det,
        (a[2] * a[3] - a[0] * a[5]) * inv_det,
        (a[0] * a[4] - a[1] * a[3]) * inv_det,
    ]
}

/// Row-major 3x3 product `a b`.
#[inline]
pub fn mul3(a: &[f64; 9], b: &[f64; 9]) -> [f64; 9] {
    let mut c = [0.0; 9];
    for i in 0..3 {
        for j in 0..3 {
            c[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
        }
    }
    c
}

/// Row-major 3x3 product `aᵀ b`.
#[inline]
pub fn mul3_tn(a: &[f64; 9], b: &[f64; 9]) -> [f64; 9] {
    let mut c = [0.0; 9];
    for i in 0..3 {
        for j in 0..3 {
            c[3 * i + j] = a[i] * b[j] + a[3 + i] * b[3 + j] + a[6 + i] * b[6 + j];
        }
    }
    c
}

/// 3D polar decomposition `F = R U` by Higham's Newton iteration `X ← (X + X⁻ᵀ)/2`,
/// warm-started from the previous rotation `r_prev` (iterating on `r_prevᵀ F`, which is
/// close to symmetric, converges in two or three iterations). Returns `R`.
pub fn polar_3d(f: &[f64; 9], r_prev: &[f64; 9]) -> [f64; 9] {
    let mut x = mul3_tn(r_prev, f);
    for _ in 0..40 {
        let it = inv_transpose3(&x);
        let mut next = [0.0; 9];
        let mut change = 0.0f64;
        for k in 0..9 {
            next[k] = 0.5 * (x[k] + it[k]);
            change = change.max((next[k] - x[k]).abs());
        }
        x = next;
        if change <= 1e-15 || !change.is_finite() {
            break;
        }
    }
    mul3(r_prev, &x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn rot(ax: f64, ay: f64, az: f64) -> [f64; 9] {
        let (cx, sx, cy, sy, cz, sz) = (ax.cos(), ax.sin(), ay.cos(), ay.sin(), az.cos(), az.sin());
        let rx = [1.0, 0.0, 0.0, 0.0, cx, -sx, 0.0, sx, cx];
        let ry = [cy, 0.0, sy, 0.0, 1.0, 0.0, -sy, 0.0, cy];
        let rz = [cz, -sz, 0.0, sz, cz, 0.0, 0.0, 0.0, 1.0];
        mul3(&rz, &mul3(&ry, &rx))
    }

    proptest! {
        #[test]
        fn polar_3d_recovers_rotation(ax in -3.1f64..3.1, ay in -1.5f64..1.5, az in -3.1f64..3.1,
                                      s in proptest::array::uniform6(-0.05f64..0.05)) {
            let r = rot(ax, ay, az);
            let u = [1.0 + s[0], s[3], s[5], s[3], 1.0 + s[1], s[4], s[5], s[4], 1.0 + s[2]];
            let f = mul3(&r, &u);
            let id = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
            let got = polar_3d(&f, &id);
            for k in 0..9 {
                prop_assert!((got[k] - r[k]).abs() < 1e-12, "component {} {} vs {}", k, got[k], r[k]);
            }
        }

        #[test]
        fn polar_2d_recovers_rotation(t in -3.1f64..3.1, a in -0.1f64..0.1, b in -0.1f64..0.1, c in -0.1f64..0.1) {
            let (ct, st) = (t.cos(), t.sin());
            let u = [1.0 + a, c, c, 1.0 + b];
            let f = [ct * u[0] - st * u[2], ct * u[1] - st * u[3], st * u[0] + ct * u[2], st * u[1] + ct * u[3]];
            let (cc, ss) = polar_2d(&f);
            prop_assert!((cc - ct).abs() < 1e-12 && (ss - st).abs() < 1e-12);
            let h = [f[0] - 1.0, f[1], f[2], f[3] - 1.0];
            let (ch, sh, cm1) = polar_2d_h(&h);
            prop_assert!((ch - ct).abs() < 1e-12 && (sh - st).abs() < 1e-12);
            prop_assert!((cm1 - (ct - 1.0)).abs() < 1e-12);
        }
    }
}
