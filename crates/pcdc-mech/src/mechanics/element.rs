//! One element's step, in two halves: the co-rotated strain and the trial inputs of its
//! constitutive model ([`Mechanics::trial_2d`], [`Mechanics::trial_3d`]), then, from the
//! model's new stress, the stress fields and the nodal forces ([`Mechanics::forces_2d`],
//! [`Mechanics::forces_3d`]). The built-in elastic law runs the halves back to back per
//! element; any other model gets a run of elements at once between them
//! ([`crate::ConstitutiveModel::update_many`]), so that a model can work on several
//! elements side by side (the Mohr–Coulomb decomposition does).

use pcdc_mesh::Dim;

use super::{Mechanics, StepInputs};
use crate::kinematics::{mul3, mul3_tn, polar_2d_h, polar_3d};
use crate::mixed::trace_2d;
use crate::model::{add_hooke, ModelInput, Sym6};

/// Most elements handed to a model at once ([`crate::ConstitutiveModel::update_many`]).
const BATCH: usize = 16;

/// What the first half of an element's step leaves for the model and the second half,
/// besides σ(t). Written in place: a triangle writes only the entries that can be
/// non-zero (xx, yy, xy; cos θ, sin θ), so a buffer of them, zeroed once, is not
/// zero-filled again per element.
#[derive(Clone, Copy, Debug, Default)]
struct Trial {
    /// Total co-rotated strain ε(t+Δt).
    eps: Sym6,
    /// Its increment over the step.
    de: Sym6,
    /// The element rotation: cos θ, sin θ in 2D; R (row-major) in 3D.
    rot: [f64; 9],
}

/// A node's d components from a flat array.
#[inline(always)]
fn node2(x: &[f64], n: usize) -> [f64; 2] {
    [x[n], x[n + 1]]
}

impl Mechanics {
    /// The first half of a triangle's step: H = [u₁ − u₀, u₂ − u₀] D_m⁻¹, its polar
    /// rotation, the co-rotated strain (written to `strain`: xx, yy, xy) and the trial
    /// inputs into `t` (its zz, yz, xz strains and 3D rotation entries left as they
    /// are: zero); `szz` is σzz (plane strain), `theta` a mixed cell's mean volumetric
    /// strain.
    #[inline(always)]
    fn trial_2d(
        &self,
        e: usize,
        inp: &StepInputs<'_>,
        strain: &mut [f64],
        theta: Option<f64>,
        t: &mut Trial,
    ) {
        let c = &inp.conn[3 * e..3 * e + 3];
        let (n0, n1, n2) = (c[0] as usize * 2, c[1] as usize * 2, c[2] as usize * 2);
        let m = &self.geo.dm_inv[4 * e..4 * e + 4];
        // Displacement gradient H = ∂u/∂X = [u₁ − u₀, u₂ − u₀] D_m⁻¹ and F = I + H: built
        // from displacement differences, not from current positions, so that small
        // strains keep their digits (x = X + u would round u to the ulp of X).
        let (u0, u1, u2) = (node2(inp.u, n0), node2(inp.u, n1), node2(inp.u, n2));
        let (d0, d1, d2, d3) = (u1[0] - u0[0], u2[0] - u0[0], u1[1] - u0[1], u2[1] - u0[1]);
        let h = [
            d0 * m[0] + d1 * m[2],
            d0 * m[1] + d1 * m[3],
            d2 * m[0] + d3 * m[2],
            d2 * m[1] + d3 * m[3],
        ];
        let (co, si, cm1) = polar_2d_h(&h);
        // ε = U − I with U = Rᵀ(I + H), written without the cancellation of U − I:
        // U₀₀ − 1 = (cos θ − 1) + cos θ H₀₀ + sin θ H₁₀, U₁₁ − 1 = (cos θ − 1) + cos θ H₁₁ − sin θ H₀₁,
        // U₀₁ + U₁₀ = cos θ (H₀₁ + H₁₀) + sin θ (H₁₁ − H₀₀).
        let mut eps = [
            cm1 + co * h[0] + si * h[2],
            cm1 + co * h[3] - si * h[1],
            0.5 * (co * (h[1] + h[2]) + si * (h[3] - h[0])),
        ];
        // Mixed cell: the cell's mean volumetric strain replaces the element's.
        if let Some(mean) = theta {
            let corr = 0.5 * (mean - trace_2d(&h));
            eps[0] += corr;
            eps[1] += corr;
        }
        let de = [eps[0] - strain[0], eps[1] - strain[1], eps[2] - strain[2]];
        strain.copy_from_slice(&eps);
        (t.eps[0], t.eps[1], t.eps[3]) = (eps[0], eps[1], eps[2]);
        (t.de[0], t.de[1], t.de[3]) = (de[0], de[1], de[2]);
        (t.rot[0], t.rot[1]) = (co, si);
    }

    /// The second half of a triangle's step: stores σ(t+Δt) `sig` (xx, yy, xy in
    /// `stress`, σzz in `szz`), adds the viscous stress (eq. 17–19) and writes the three
    /// nodal forces −V P ∇N to `slots`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn forces_2d(
        &self,
        e: usize,
        inp: &StepInputs<'_>,
        slots: &mut [f64],
        stress: &mut [f64],
        szz: &mut f64,
        sig: &Sym6,
        rot: &[f64; 9],
        visc: Option<f64>,
    ) {
        stress.copy_from_slice(&[sig[0], sig[1], sig[3]]);
        *szz = sig[2];
        let (co, si) = (rot[0], rot[1]);
        let m = &self.geo.dm_inv[4 * e..4 * e + 4];
        let (mut sxx, mut syy, mut sxy) = (sig[0], sig[1], sig[3]);
        if let Some(cv) = visc {
            let c = &inp.conn[3 * e..3 * e + 3];
            let (n0, n1, n2) = (c[0] as usize * 2, c[1] as usize * 2, c[2] as usize * 2);
            let (v0, v1, v2) = (node2(inp.v, n0), node2(inp.v, n1), node2(inp.v, n2));
            let dv = [v1[0] - v0[0], v2[0] - v0[0], v1[1] - v0[1], v2[1] - v0[1]];
            let fd = [
                dv[0] * m[0] + dv[1] * m[2],
                dv[0] * m[1] + dv[1] * m[3],
                dv[2] * m[0] + dv[3] * m[2],
                dv[2] * m[1] + dv[3] * m[3],
            ];
            let r00 = co * fd[0] + si * fd[2];
            let r01 = co * fd[1] + si * fd[3];
            let r10 = -si * fd[0] + co * fd[2];
            let r11 = -si * fd[1] + co * fd[3];
            // eq. 17-19: σ_v = D_f C ε̇ with C = 2 L √(ρE)
            sxx += cv * r00;
            syy += cv * r11;
            sxy += cv * 0.5 * (r01 + r10);
        }
        // P = R σ
        let p00 = co * sxx - si * sxy;
        let p01 = co * sxy - si * syy;
        let p10 = si * sxx + co * sxy;
        let p11 = si * sxy + co * syy;
        let vol = self.geo.volume[e];
        let g1 = [m[0], m[1]];
        let g2 = [m[2], m[3]];
        let f1 = [
            -vol * (p00 * g1[0] + p01 * g1[1]),
            -vol * (p10 * g1[0] + p11 * g1[1]),
        ];
        let f2 = [
            -vol * (p00 * g2[0] + p01 * g2[1]),
            -vol * (p10 * g2[0] + p11 * g2[1]),
        ];
        slots.copy_from_slice(&[
            -(f1[0] + f2[0]),
            -(f1[1] + f2[1]),
            f1[0],
            f1[1],
            f2[0],
            f2[1],
        ]);
    }

    /// The first half of a tetrahedron's step: F = I + [u_j − u₀] D_m⁻¹, its polar
    /// rotation (kept in `rot` for the next step's Newton start; a mixed cell's comes
    /// from the trace pass), the co-rotated strain (written to `strain`) and the trial
    /// inputs.
    #[inline(always)]
    fn trial_3d(
        &self,
        e: usize,
        inp: &StepInputs<'_>,
        strain: &mut [f64],
        rot: &mut [f64],
        theta: Option<f64>,
        t: &mut Trial,
    ) {
        let c = &inp.conn[4 * e..4 * e + 4];
        let n: [usize; 4] = [
            c[0] as usize * 3,
            c[1] as usize * 3,
            c[2] as usize * 3,
            c[3] as usize * 3,
        ];
        let m: &[f64] = &self.geo.dm_inv[9 * e..9 * e + 9];
        // F = I + H with H = [u_j − u₀] D_m⁻¹ from displacement differences (see 2D).
        let mut du = [0.0; 9];
        for i in 0..3 {
            let o = inp.u[n[0] + i];
            for j in 0..3 {
                du[3 * i + j] = inp.u[n[j + 1] + i] - o;
            }
        }
        let mm: [f64; 9] = m.try_into().expect("9 values");
        let mut f = mul3(&du, &mm);
        f[0] += 1.0;
        f[4] += 1.0;
        f[8] += 1.0;
        let r_prev: [f64; 9] = (&*rot).try_into().expect("9 values");
        // A mixed cell's elements found their rotation in the trace pass of this step.
        let r = if theta.is_some() {
            r_prev
        } else {
            polar_3d(&f, &r_prev)
        };
        rot.copy_from_slice(&r);
        let u = mul3_tn(&r, &f);
        let mut eps: Sym6 = [
            u[0] - 1.0,
            u[4] - 1.0,
            u[8] - 1.0,
            0.5 * (u[1] + u[3]),
            0.5 * (u[5] + u[7]),
            0.5 * (u[2] + u[6]),
        ];
        if let Some(mean) = theta {
            let corr = (mean - (eps[0] + eps[1] + eps[2])) / 3.0;
            eps[0] += corr;
            eps[1] += corr;
            eps[2] += corr;
        }
        let mut de = [0.0; 6];
        for k in 0..6 {
            de[k] = eps[k] - strain[k];
        }
        strain.copy_from_slice(&eps);
        *t = Trial { eps, de, rot: r };
    }

    /// The second half of a tetrahedron's step: stores σ(t+Δt) `sig` in `stress`, adds
    /// the viscous stress (eq. 17–19) and writes the four nodal forces to `slots`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn forces_3d(
        &self,
        e: usize,
        inp: &StepInputs<'_>,
        slots: &mut [f64],
        stress: &mut [f64],
        sig: &Sym6,
        r: &[f64; 9],
        visc: Option<f64>,
    ) {
        stress.copy_from_slice(sig);
        let mm: [f64; 9] = self.geo.dm_inv[9 * e..9 * e + 9]
            .try_into()
            .expect("9 values");
        let mut sig = *sig;
        if let Some(cv) = visc {
            let c = &inp.conn[4 * e..4 * e + 4];
            let n: [usize; 4] = [
                c[0] as usize * 3,
                c[1] as usize * 3,
                c[2] as usize * 3,
                c[3] as usize * 3,
            ];
            let mut dv = [0.0; 9];
            for i in 0..3 {
                let o = inp.v[n[0] + i];
                for j in 0..3 {
                    dv[3 * i + j] = inp.v[n[j + 1] + i] - o;
                }
            }
            let fd = mul3(&dv, &mm);
            let rd = mul3_tn(r, &fd);
            sig[0] += cv * rd[0];
            sig[1] += cv * rd[4];
            sig[2] += cv * rd[8];
            sig[3] += cv * 0.5 * (rd[1] + rd[3]);
            sig[4] += cv * 0.5 * (rd[5] + rd[7]);
            sig[5] += cv * 0.5 * (rd[2] + rd[6]);
        }
        let s = [
            sig[0], sig[3], sig[5], sig[3], sig[1], sig[4], sig[5], sig[4], sig[2],
        ];
        let pk = mul3(r, &s);
        let vol = self.geo.volume[e];
        let mut f0 = [0.0; 3];
        for a in 0..3 {
            for i in 0..3 {
                let fa = -vol
                    * (pk[3 * i] * mm[3 * a]
                        + pk[3 * i + 1] * mm[3 * a + 1]
                        + pk[3 * i + 2] * mm[3 * a + 2]);
                slots[3 * (a + 1) + i] = fa;
                f0[i] -= fa;
            }
        }
        slots[..3].copy_from_slice(&f0);
    }
}

/// σ(t) of an element as a tensor from its stress entries `s` (xx, yy, xy in 2D, with
/// σzz the first of its extra entries `x`; six in 3D).
#[inline(always)]
fn sigma<D: Dim>(s: &[f64], x: &[f64]) -> Sym6 {
    if D::D == 2 {
        [s[0], s[1], x[0], s[2], 0.0, 0.0]
    } else {
        [s[0], s[1], s[2], s[3], s[4], s[5]]
    }
}

impl Mechanics {
    /// A mixed cell's mean volumetric strain at element `e`, if `e` is in one.
    #[inline(always)]
    fn theta(&self, e: usize, trace: &[f64]) -> Option<f64> {
        self.mixed
            .as_ref()
            .filter(|mx| mx.is_mixed(e))
            .map(|mx| mx.mean(e, trace))
    }

    /// The viscous coefficient D_f C of element `e` when damping is on (eq. 18–19).
    #[inline(always)]
    fn visc(&self, e: usize, inp: &StepInputs<'_>) -> Option<f64> {
        let k = &self.consts[self.material[e] as usize];
        (inp.damping && k.damp2 > 0.0).then(|| self.viscous_coefficient(e))
    }

    /// The elements of one chunk (from element `first`; outputs as chunk slices) when
    /// every material is the built-in elastic law, inline, one element at a time.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn elastic_chunk<D: Dim>(
        &self,
        first: usize,
        inp: &StepInputs<'_>,
        sl: &mut [f64],
        st: &mut [f64],
        ep: &mut [f64],
        ex: &mut [f64],
        null: &[f64],
        trace: &[f64],
    ) {
        let (d, npe, nsym) = (D::D, D::NODES_PER_ELEM, D::NSYM);
        let nx = if d == 2 { 1 } else { 9 };
        // Each element's outputs as exact chunks: no bounds check per value.
        let per_element = sl
            .chunks_exact_mut(npe * d)
            .zip(st.chunks_exact_mut(nsym))
            .zip(ep.chunks_exact_mut(nsym))
            .zip(ex.chunks_exact_mut(nx));
        for (i, (((sl, st), ep), ex)) in per_element.enumerate() {
            let e = first + i;
            // A null element carries no force (manual 7.2.8).
            if null[e] != 0.0 {
                sl.fill(0.0);
                continue;
            }
            let lame = self.consts[self.material[e] as usize]
                .elastic
                .expect("elastic_chunk runs only when every material is the inline law");
            self.elastic_element::<D>(e, inp, sl, st, ep, ex, trace, lame);
        }
    }

    /// One element with the inline elastic law (Lamé λ, 2μ in `lame`), halves back to
    /// back; the slices are the element's own.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn elastic_element<D: Dim>(
        &self,
        e: usize,
        inp: &StepInputs<'_>,
        sl: &mut [f64],
        st: &mut [f64],
        ep: &mut [f64],
        ex: &mut [f64],
        trace: &[f64],
        (l, m2): (f64, f64),
    ) {
        let (visc, theta) = (self.visc(e, inp), self.theta(e, trace));
        let mut t = Trial::default();
        let mut sig = sigma::<D>(st, ex);
        if D::D == 2 {
            self.trial_2d(e, inp, ep, theta, &mut t);
            add_hooke(l, m2, &t.de, &mut sig);
            self.forces_2d(e, inp, sl, st, &mut ex[0], &sig, &t.rot, visc);
        } else {
            self.trial_3d(e, inp, ep, ex, theta, &mut t);
            add_hooke(l, m2, &t.de, &mut sig);
            self.forces_3d(e, inp, sl, st, &sig, &t.rot, visc);
        }
    }

    /// The elements of one chunk with any materials: the inline elastic law one element
    /// at a time, any other model a run of up to [`BATCH`] consecutive live elements of
    /// its material at once (trial halves, [`crate::ConstitutiveModel::update_many`],
    /// force halves). `coupling(e)` gives element e's coupling values.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn model_chunk<'c, D: Dim>(
        &self,
        first: usize,
        inp: &StepInputs<'_>,
        sl: &mut [f64],
        st: &mut [f64],
        ep: &mut [f64],
        ex: &mut [f64],
        ms: &mut [f64],
        null: &[f64],
        trace: &[f64],
        coupling: impl Fn(usize) -> &'c [f64],
    ) {
        let (d, npe, nsym) = (D::D, D::NODES_PER_ELEM, D::NSYM);
        let (nf, nx) = (npe * d, if d == 2 { 1 } else { 9 });
        let (ns, len) = (self.n_state.max(1), st.len() / nsym);
        // Buffers for the chunk's runs, zeroed once per chunk, not per run or element.
        let mut trials = [Trial::default(); BATCH];
        let mut sigs = [[0.0; 6]; BATCH];
        let mut i = 0;
        while i < len {
            let e = first + i;
            if null[e] != 0.0 {
                sl[i * nf..(i + 1) * nf].fill(0.0);
                i += 1;
                continue;
            }
            let mi = self.material[e] as usize;
            // The inline elastic law: this element alone, halves back to back.
            if let Some(lame) = self.consts[mi].elastic {
                self.elastic_element::<D>(
                    e,
                    inp,
                    &mut sl[i * nf..(i + 1) * nf],
                    &mut st[i * nsym..(i + 1) * nsym],
                    &mut ep[i * nsym..(i + 1) * nsym],
                    &mut ex[i * nx..(i + 1) * nx],
                    trace,
                    lame,
                );
                i += 1;
                continue;
            }
            // The run of live elements of this material that the model gets at once.
            let mut j = i + 1;
            while j < len
                && j - i < BATCH
                && null[first + j] == 0.0
                && self.material[first + j] as usize == mi
            {
                j += 1;
            }
            let n = j - i;
            for (b, t) in trials[..n].iter_mut().enumerate() {
                let (e, a) = (first + i + b, i + b);
                let theta = self.theta(e, trace);
                let (s, p) = (
                    &st[a * nsym..(a + 1) * nsym],
                    &mut ep[a * nsym..(a + 1) * nsym],
                );
                let x = &mut ex[a * nx..(a + 1) * nx];
                sigs[b] = sigma::<D>(s, x);
                if d == 2 {
                    self.trial_2d(e, inp, p, theta, t);
                } else {
                    self.trial_3d(e, inp, p, x, theta, t);
                }
            }
            // A plain loop, not `array::from_fn`: its closure was not inlined, and each
            // input went through the stack twice (a sixth of a run's time for a model
            // as light as Hooke's law).
            let mut inputs = [ModelInput::new(&trials[0].eps, &trials[0].de, &[]); BATCH];
            for (b, (input, t)) in inputs.iter_mut().zip(&trials[..n]).enumerate() {
                *input = ModelInput::new(&t.eps, &t.de, coupling(first + i + b));
            }
            self.models[mi].update_many(&inputs[..n], &mut sigs[..n], &mut ms[i * ns..j * ns], ns);
            for b in 0..n {
                let (e, a) = (first + i + b, i + b);
                let (f, s) = (
                    &mut sl[a * nf..(a + 1) * nf],
                    &mut st[a * nsym..(a + 1) * nsym],
                );
                let visc = self.visc(e, inp);
                if d == 2 {
                    self.forces_2d(e, inp, f, s, &mut ex[a], &sigs[b], &trials[b].rot, visc);
                } else {
                    self.forces_3d(e, inp, f, s, &sigs[b], &trials[b].rot, visc);
                }
            }
            i = j;
        }
    }
}
