//! The shear plane's first try for [`LANES`] plane-strain trials side by side: the
//! closed-form decomposition ([`crate::principal::plane`]), [`Surfaces::shear_first`],
//! [`crate::principal::compose_plane`] and the plastic shear strain of the history,
//! written without branches so that the lanes fill vector registers. Nearly every
//! plastic triangle of a step takes this path; one at a time it is a chain of a root,
//! two divisions and another root with little else to overlap.
//!
//! Every lane makes the operations the one-element path makes, in the same order (both
//! sides of each choice computed and one kept), so the results are the same bit for bit
//! (`update_many_is_the_one_element_update_bit_for_bit` and
//! `plane_runs_of_every_class_match_the_one_element_update` check it).

use super::surfaces::{max2, min2, ShearPlane, Surfaces};
use crate::model::Sym6;
use crate::principal::LANES;

/// The constants of the surfaces each lane is judged against.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct LaneSurfaces {
    n_phi: [f64; LANES],
    n_psi: [f64; LANES],
    kc: [f64; LANES],
    st: [f64; LANES],
    alpha_p: [f64; LANES],
    dg: [[f64; LANES]; 3],
    a: [f64; LANES],
}

impl LaneSurfaces {
    /// Every lane with the surfaces `f` (shear-plane constants `sp`).
    #[inline(always)]
    pub(super) fn splat(f: &Surfaces, sp: &ShearPlane) -> Self {
        Self {
            n_phi: [f.n_phi; LANES],
            n_psi: [f.n_psi; LANES],
            kc: [f.kc; LANES],
            st: [f.st; LANES],
            alpha_p: [f.alpha_p; LANES],
            dg: sp.dg.map(|g| [g; LANES]),
            a: [sp.a; LANES],
        }
    }

    /// Lane `l` with the surfaces `f` (shear-plane constants `sp`).
    #[inline(always)]
    pub(super) fn set(&mut self, l: usize, f: &Surfaces, sp: &ShearPlane) {
        self.n_phi[l] = f.n_phi;
        self.n_psi[l] = f.n_psi;
        self.kc[l] = f.kc;
        self.st[l] = f.st;
        self.alpha_p[l] = f.alpha_p;
        for k in 0..3 {
            self.dg[k][l] = sp.dg[k];
        }
        self.a[l] = sp.a;
    }
}

/// What the first try found in each lane, lanes as columns (f64 throughout, so that
/// the lanes' loop is one vector loop).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct PlaneLanes {
    /// [`ELASTIC`], [`SHEAR`] or [`OTHER`] (see `FirstTry`).
    pub(super) kind: [f64; LANES],
    /// The returned stress of a [`SHEAR`] lane: xx, yy, zz, xy (yz = xz = 0).
    pub(super) stress: [[f64; LANES]; 4],
    /// 1 where a [`SHEAR`] lane's multiplier is positive (its history is written).
    pub(super) yielded: [f64; LANES],
    /// A [`SHEAR`] lane's plastic shear strain increment Δκ_s.
    pub(super) dkappa: [f64; LANES],
}

impl PlaneLanes {
    /// Lane `l`'s returned stress as a tensor.
    #[inline(always)]
    pub(super) fn stress(&self, l: usize) -> Sym6 {
        let s = &self.stress;
        [s[0][l], s[1][l], s[2][l], s[3][l], 0.0, 0.0]
    }
}

/// Not outside the surface.
pub(super) const ELASTIC: f64 = 0.0;
/// Returned onto the shear plane.
pub(super) const SHEAR: f64 = 1.0;
/// Another return: the general search.
pub(super) const OTHER: f64 = 2.0;

/// The first try of the plane trial stresses `stresses[i]`, `i` in `group` (at most
/// [`LANES`]; lane `l` is `group[l]`), against the surfaces `f`, into `out`.
pub(super) fn shear_first_lanes(
    stresses: &[Sym6],
    group: &[usize],
    f: &LaneSurfaces,
    out: &mut PlaneLanes,
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor has AVX2, checked on the line above.
        return unsafe { shear_first_lanes_avx2(stresses, group, f, out) };
    }
    shear_first_lanes_any(stresses, group, f, out)
}

/// [`shear_first_lanes_any`] compiled for AVX2 (the same operations, no fused
/// multiply-adds: the same results on every processor).
///
/// # Safety
///
/// The processor must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn shear_first_lanes_avx2(
    stresses: &[Sym6],
    group: &[usize],
    f: &LaneSurfaces,
    out: &mut PlaneLanes,
) {
    shear_first_lanes_any(stresses, group, f, out)
}

/// The body of [`shear_first_lanes`], inlined into each instruction-set version.
#[inline(always)]
fn shear_first_lanes_any(
    stresses: &[Sym6],
    group: &[usize],
    f: &LaneSurfaces,
    out: &mut PlaneLanes,
) {
    // Lanes as columns, so that each line below is one vector operation; unused lanes
    // get a zero tensor (their results are not read).
    let col = |k: usize| -> [f64; LANES] {
        std::array::from_fn(|l| group.get(l).map_or(0.0, |&i| stresses[i][k]))
    };
    let (xx, yy, zz, xy) = (col(0), col(1), col(2), col(3));
    for l in 0..LANES {
        // `principal::plane`.
        let c = 0.5 * (xx[l] + yy[l]);
        let d = 0.5 * (xx[l] - yy[l]);
        let r = (d * d + xy[l] * xy[l]).sqrt();
        let inv = 1.0 / r;
        let (cos2, sin2) = if r > 0.0 {
            (d * inv, xy[l] * inv)
        } else {
            (-1.0, 0.0)
        };
        let (lo, hi, z) = (c - r, c + r, zz[l]);
        let below = z <= lo;
        let above = !below & (z >= hi);
        let s0 = if below { z } else { lo };
        let s1 = if below {
            lo
        } else if above {
            hi
        } else {
            z
        };
        let s2 = if above { z } else { hi };
        // `Surfaces::shear_first`.
        let (n_phi, kc, st, a) = (f.n_phi[l], f.kc[l], f.st[l], f.a[l]);
        let f0 = n_phi * s2 - s0 - kc;
        let elastic = (f0 <= 0.0) & (s2 - st <= 0.0);
        let h = s2 - st + f.alpha_p[l] * (s0 - (st * n_phi - kc));
        let singular = a.abs() <= 1e-12 * 0.0f64.max(a.abs());
        let lambda = f0 / a;
        let o0 = s0 - lambda * f.dg[0][l];
        let o1 = s1 - lambda * f.dg[1][l];
        let o2 = s2 - lambda * f.dg[2][l];
        let scale = max2(max2(max2(s0.abs(), s2.abs()), kc), st);
        let tol = 1e-12 * max2(scale, f64::MIN_POSITIVE);
        let (ohi, olo) = (max2(max2(o0, o1), o2), min2(min2(o0, o1), o2));
        let on = (n_phi * ohi - olo - kc <= tol) & (ohi - st <= tol);
        // `lambda >= 0.0` where the one-element path has `!(lambda < 0.0)`: they differ
        // only for a NaN λ, whose stresses are NaN and fail `on` in both.
        let shear = (h <= 0.0) & !singular & (lambda >= 0.0) & on;
        out.kind[l] = if elastic {
            ELASTIC
        } else if shear {
            SHEAR
        } else {
            OTHER
        };
        // `compose_plane` on the slots of the decomposition.
        let ma = if below { o1 } else { o0 };
        let mb = if above { o1 } else { o2 };
        let mz = if below {
            o0
        } else if above {
            o2
        } else {
            o1
        };
        let (cc, rr) = (0.5 * (ma + mb), 0.5 * (mb - ma));
        out.stress[0][l] = cc + rr * cos2;
        out.stress[1][l] = cc - rr * cos2;
        out.stress[2][l] = mz;
        out.stress[3][l] = rr * sin2;
        // `record` of `shear_return(lambda, ..)`.
        let ep = [0.0 - lambda, 0.0 + lambda * 0.0, 0.0 + lambda * f.n_psi[l]];
        let m = (ep[0] + ep[1] + ep[2]) * (1.0 / 3.0);
        let (a, b, c) = (ep[0] - m, ep[1] - m, ep[2] - m);
        out.dkappa[l] = (0.5 * (a * a + b * b + c * c)).sqrt();
        out.yielded[l] = if 0.0 + lambda > 0.0 { 1.0 } else { 0.0 };
    }
}

/// Elements in one pass of the run update: two groups of lanes.
pub(super) const BLOCK: usize = 2 * LANES;
