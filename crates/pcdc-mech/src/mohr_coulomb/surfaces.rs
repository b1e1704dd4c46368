//! The yield surfaces of [`super::MohrCoulomb`] in principal stresses and the return
//! mapping onto them (eq. 25–33 and the digest's h-function; see the parent module's
//! documentation): [`Surfaces`], [`Return`], and the shear plane's first try that a run
//! of elements takes straight from its decompositions.

use crate::model::Sym6;

/// The yield planes of the ordered sector σ1 ≤ σ2 ≤ σ3 and the elastic constants of
/// the return mapping (see the [`super`] module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Surfaces {
    /// N_φ (eq. 31).
    pub n_phi: f64,
    /// N_ψ.
    pub n_psi: f64,
    /// 2c √N_φ, the uniaxial compressive strength (Pa).
    pub kc: f64,
    /// Effective tensile strength σ_t (Pa).
    pub st: f64,
    /// α1 = K + 4G/3 (Pa, eq. 26).
    pub a1: f64,
    /// α2 = K − 2G/3 (Pa, eq. 27).
    pub a2: f64,
    /// α_P = √(1 + N_φ²) + N_φ of the h-function ([`Surfaces::h`]).
    pub alpha_p: f64,
}

/// The shear plane's constants of a [`Surfaces`] for its first try
/// ([`Surfaces::shear_first`]): found once for a run of elements with the same surfaces,
/// not per element.
#[derive(Clone, Copy, Debug)]
pub(super) struct ShearPlane {
    /// D∇g₀, the elastic image of the shear plane's flow direction (Pa).
    pub(super) dg: [f64; 3],
    /// ∇f₀·D∇g₀ (Pa).
    pub(super) a: f64,
}

/// √3, for [`Surfaces::surely_elastic`].
const SQRT_3: f64 = 1.732_050_807_568_877_2;

/// What [`Surfaces::shear_first`] found for a trial.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum FirstTry {
    /// Not outside the surface: nothing to do.
    Elastic,
    /// Returned onto the shear plane with this multiplier to these principal stresses;
    /// the history not yet written.
    Shear(f64, [f64; 3]),
    /// Another return: the general path's (nothing done).
    Other,
}

/// Number of yield planes in the ordered sector.
const PLANES: usize = 6;

/// Every set of one, two or three planes as a bit mask (bit k: plane k): singles, pairs
/// and triples, each in increasing mask order.
const SETS: [u8; 41] = sets();

const fn sets() -> [u8; 41] {
    let mut out = [0u8; 41];
    let mut n = 0;
    let mut size = 1;
    while size <= 3 {
        let mut m = 1u8;
        while m < 64 {
            if m.count_ones() == size {
                out[n] = m;
                n += 1;
            }
            m += 1;
        }
        size += 1;
    }
    out
}

/// The sets tried first on the shear side (h ≤ 0): the shear plane, its edges with
/// σ2 = σ3 and σ2 = σ1 (triaxial compression and extension), the shear–tension corner,
/// the tension plane.
const FIRST_SHEAR: [u8; 5] = [0b1, 0b11, 0b101, 0b1001, 0b1000];
/// The sets tried first on the tension side (h > 0): the tension plane, its edge with
/// σ2 = σ_t, the corner, the shear plane, the apex σ1 = σ2 = σ3 = σ_t.
const FIRST_TENSION: [u8; 5] = [0b1000, 0b11000, 0b1001, 0b1, 0b111000];

/// What a return did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Return {
    /// Corrected principal stresses (Pa), on the trial's axes (not re-sorted).
    pub stress: [f64; 3],
    /// Plastic strain increment in principal axes, Σ λ_k ∇g_k (-).
    pub plastic_strain: [f64; 3],
    /// The shear planes' part of `plastic_strain` (-).
    pub shear_strain: [f64; 3],
    /// The multipliers of the shear planes summed (-).
    pub shear: f64,
    /// The multipliers of the tension planes summed (-).
    pub tension: f64,
}

impl Surfaces {
    /// The shear plane's constants for [`Self::shear_first`] (the same operations as
    /// `solve_n` on the shear plane does).
    #[inline(always)]
    pub(super) fn shear_plane(&self) -> ShearPlane {
        let dg = self.elastic(&self.potential_gradient(0));
        ShearPlane {
            dg,
            a: dot(&self.yield_gradient(0), &dg),
        }
    }

    /// Plane k at principal stresses s (ordered sector): 0 the shear plane of eq. 29, 1
    /// and 2 the shear planes of the pyramid's edges (σ2 in place of σ3, of σ1), 3–5
    /// σ3, σ2, σ1 against σ_t.
    #[inline(always)]
    pub fn plane(&self, k: usize, s: &[f64; 3]) -> f64 {
        match k {
            0 => self.n_phi * s[2] - s[0] - self.kc,
            1 => self.n_phi * s[1] - s[0] - self.kc,
            2 => self.n_phi * s[2] - s[1] - self.kc,
            3 => s[2] - self.st,
            4 => s[1] - self.st,
            _ => s[0] - self.st,
        }
    }

    #[inline(always)]
    fn gradient(&self, k: usize, n: f64) -> [f64; 3] {
        match k {
            0 => [-1.0, 0.0, n],
            1 => [-1.0, n, 0.0],
            2 => [0.0, -1.0, n],
            3 => [0.0, 0.0, 1.0],
            4 => [0.0, 1.0, 0.0],
            _ => [1.0, 0.0, 0.0],
        }
    }

    /// ∇f_k (principal components).
    pub fn yield_gradient(&self, k: usize) -> [f64; 3] {
        self.gradient(k, self.n_phi)
    }

    /// ∇g_k, the flow direction (eq. 32–33).
    pub fn potential_gradient(&self, k: usize) -> [f64; 3] {
        self.gradient(k, self.n_psi)
    }

    /// D m: the isotropic elastic matrix in principal axes applied to m (eq. 25).
    pub fn elastic(&self, m: &[f64; 3]) -> [f64; 3] {
        let t = m[0] + m[1] + m[2];
        [
            self.a1 * m[0] + self.a2 * (t - m[0]),
            self.a1 * m[1] + self.a2 * (t - m[1]),
            self.a1 * m[2] + self.a2 * (t - m[2]),
        ]
    }

    /// The composite yield function of any principal stresses, in any order:
    /// max(N_φ σ_max − σ_min − 2c√N_φ, σ_max − σ_t) (Pa). Positive means outside.
    pub fn composite(&self, s: &[f64; 3]) -> f64 {
        let hi = s[0].max(s[1]).max(s[2]);
        let lo = s[0].min(s[1]).min(s[2]);
        (self.n_phi * hi - lo - self.kc).max(hi - self.st)
    }

    /// True when the tensor `t` (xx, yy, zz, xy, yz, xz) lies inside the yield surface by
    /// a bound that needs no principal decomposition, so that elastic elements skip it:
    /// with the mean p and the deviator's eigenvalues s_i (Σ s_i = 0, Σ s_i² = s:s),
    /// s_max ≤ R = √(⅔ s:s) and s_max − s_min ≤ √(2 s:s) = √3 R, hence
    /// N_φ σ_max − σ_min − 2c√N_φ ≤ (N_φ − 1)(p + R) + √3 R − 2c√N_φ and σ_max ≤ p + R.
    /// False means "decompose and check", not "plastic".
    pub fn surely_elastic(&self, t: &Sym6) -> bool {
        // Squared, so that no square root is taken: r ≤ σ_t − p and
        // (N_φ − 1 + √3) r ≤ 2c√N_φ − (N_φ − 1) p, both sides non-negative.
        let p = (t[0] + t[1] + t[2]) * (1.0 / 3.0);
        let (a, b, c) = (t[0] - p, t[1] - p, t[2] - p);
        let ss = a * a + b * b + c * c + 2.0 * (t[3] * t[3] + t[4] * t[4] + t[5] * t[5]);
        let r2 = ss * (2.0 / 3.0);
        let room_t = self.st - p;
        let k = self.n_phi - 1.0 + SQRT_3;
        let room_s = self.kc - (self.n_phi - 1.0) * p;
        room_t >= 0.0 && room_s >= 0.0 && r2 <= room_t * room_t && k * k * r2 <= room_s * room_s
    }

    /// The digest's h-function (shear domain when ≤ 0).
    pub fn h(&self, s: &[f64; 3]) -> f64 {
        let sp = self.st * self.n_phi - self.kc;
        s[2] - self.st + self.alpha_p * (s[0] - sp)
    }

    /// Returns the ordered trial principal stresses `s` (σ1 ≤ σ2 ≤ σ3) to the yield
    /// surface, or `None` when `s` is not outside it. Whether `s` is outside is the
    /// [`Self::composite`] function's answer for values in any order, so that an
    /// unordered `s` outside is returned too (onto the planes its labels name).
    pub fn return_map(&self, s: &[f64; 3]) -> Option<Return> {
        // Nearly every return in compression: the shear plane at the first try, which
        // takes ordered values; others (a caller's, an edge's trial, NaN) are judged by
        // `composite`, which takes any order, in the general search.
        if s[0] <= s[1] && s[1] <= s[2] {
            match self.shear_first(s, &self.shear_plane()) {
                FirstTry::Elastic => return None,
                FirstTry::Shear(lambda, stress) => {
                    return Some(shear_return(lambda, stress, self.n_psi))
                }
                FirstTry::Other => {}
            }
        }
        self.general_return(s)
    }

    /// [`Self::return_map`] after its first try: the search over active sets, for a
    /// caller whose own first try ([`Self::shear_first`]) found `Other`, so that it is
    /// not made twice (the same result as `return_map`, bit for bit).
    pub(super) fn general_return(&self, s: &[f64; 3]) -> Option<Return> {
        let scale = s[0].abs().max(s[2].abs()).max(self.kc).max(self.st);
        if self.composite(s) <= 0.0 {
            return None;
        }
        let tol = 1e-12 * scale.max(f64::MIN_POSITIVE);
        // Active set: start from the plane the h-function picks (shear or tension), add
        // the most violated plane of each result, up to three planes.
        let mut planes = [if self.h(s) <= 0.0 { 0 } else { 3 }, 0, 0];
        let mut n = 1;
        while let Some(r) = self.solve_likely(s, &planes[..n]) {
            if self.composite(&r.stress) <= tol {
                return Some(r);
            }
            if n == 3 {
                break;
            }
            let (mut worst, mut at) = (tol, PLANES);
            for k in (0..PLANES).filter(|k| !planes[..n].contains(k)) {
                let f = self.plane(k, &r.stress);
                if f > worst {
                    (worst, at) = (f, k);
                }
            }
            if at == PLANES {
                break;
            }
            planes[n] = at;
            n += 1;
        }
        // Otherwise the likely sets first, then every set of one, two and three planes;
        // the first admissible set wins, else the least violating.
        let first = if self.h(s) <= 0.0 {
            &FIRST_SHEAR
        } else {
            &FIRST_TENSION
        };
        let mut best: Option<(f64, Return)> = None;
        for &mask in first
            .iter()
            .chain(SETS.iter().filter(|m| !first.contains(m)))
        {
            let mut n = 0;
            for (k, p) in (0..PLANES).filter(|k| mask & (1 << k) != 0).zip(0..) {
                planes[p] = k;
                n += 1;
            }
            let Some(r) = self.solve(s, &planes[..n]) else {
                continue;
            };
            let violation = self.composite(&r.stress);
            if violation <= tol {
                return Some(r);
            }
            if best.is_none_or(|(v, _)| violation < v) {
                best = Some((violation, r));
            }
        }
        best.map(|(_, r)| r)
    }

    /// The first try of [`Self::return_map`] for ordered principal trial stresses `s`
    /// (σ1 ≤ σ2 ≤ σ3, as the decompositions give them; `return_map` checks the order),
    /// with these surfaces' shear-plane constants `sp` ([`Self::shear_plane`]):
    /// not outside the surface, or the return onto the shear plane alone when that is
    /// the result (its multiplier and principal stresses), or neither (`Other`: the
    /// general search). The same operations on the same values as that search's first
    /// solve and checks (bit for bit), with no [`Return`] built, so that a run of
    /// elements ([`super::MohrCoulomb::update_many`]) can take it straight from the trial.
    #[inline(always)]
    pub(super) fn shear_first(&self, s: &[f64; 3], sp: &ShearPlane) -> FirstTry {
        // The composite yield function of ordered values, not outside: no return.
        if self.n_phi * s[2] - s[0] - self.kc <= 0.0 && s[2] - self.st <= 0.0 {
            return FirstTry::Elastic;
        }
        let h = self.h(s);
        if h > 0.0 || h.is_nan() {
            return FirstTry::Other;
        }
        // `solve_n` on the shear plane: the 1×1 system, its pivot test, λ ≥ 0.
        let (dg, a) = (sp.dg, sp.a);
        let singular = a.abs() <= 1e-12 * 0.0f64.max(a.abs());
        let lambda = self.plane(0, s) / a;
        if singular || lambda < 0.0 {
            return FirstTry::Other;
        }
        let o = [
            s[0] - lambda * dg[0],
            s[1] - lambda * dg[1],
            s[2] - lambda * dg[2],
        ];
        // `composite(o) <= tol` with plain comparisons: the same where no value is NaN,
        // and false (the general search) where one is.
        let scale = max2(max2(max2(s[0].abs(), s[2].abs()), self.kc), self.st);
        let tol = 1e-12 * max2(scale, f64::MIN_POSITIVE);
        let (hi, lo) = (max2(max2(o[0], o[1]), o[2]), min2(min2(o[0], o[1]), o[2]));
        if !(self.n_phi * hi - lo - self.kc <= tol && hi - self.st <= tol) {
            return FirstTry::Other;
        }
        FirstTry::Shear(lambda, o)
    }

    /// [`Self::solve`] with the sets nearly every return in compression takes (the
    /// shear plane, then its edge with σ2 = σ3 or σ2 = σ1) in functions of their own
    /// with constant planes, so that the compiler folds their gradients: the same
    /// operations on the same values as the general solve (bit for bit), faster.
    #[inline(always)]
    fn solve_likely(&self, s: &[f64; 3], set: &[usize]) -> Option<Return> {
        match *set {
            [0] => self.solve_shear(s),
            [0, 1] => self.solve_edge::<1>(s),
            [0, 2] => self.solve_edge::<2>(s),
            _ => self.solve(s, set),
        }
    }

    /// [`Self::solve`] on the shear plane alone.
    #[inline(never)]
    fn solve_shear(&self, s: &[f64; 3]) -> Option<Return> {
        self.solve_n(s, &[0])
    }

    /// [`Self::solve`] on the shear plane and plane `K` (1 or 2), in that order.
    #[inline(never)]
    fn solve_edge<const K: usize>(&self, s: &[f64; 3]) -> Option<Return> {
        self.solve_n(s, &[0, K])
    }

    /// The return onto the planes `set` together: λ from f_k(σ* − Σ_j λ_j D∇g_j) = 0;
    /// `None` when a multiplier is negative or the planes are dependent.
    #[inline(never)]
    fn solve(&self, s: &[f64; 3], set: &[usize]) -> Option<Return> {
        // Fixed sizes, so that the loops unroll.
        match *set {
            [a] => self.solve_n(s, &[a]),
            [a, b] => self.solve_n(s, &[a, b]),
            [a, b, c] => self.solve_n(s, &[a, b, c]),
            _ => None,
        }
    }

    #[inline(always)]
    fn solve_n<const N: usize>(&self, s: &[f64; 3], set: &[usize; N]) -> Option<Return> {
        let n = N;
        let mut dg = [[0.0; 3]; 3];
        for (c, &j) in set.iter().enumerate() {
            dg[c] = self.elastic(&self.potential_gradient(j));
        }
        let mut a = [[0.0; 3]; 3];
        let mut b = [0.0; 3];
        for (r, &k) in set.iter().enumerate() {
            let df = self.yield_gradient(k);
            for c in 0..n {
                a[r][c] = dot(&df, &dg[c]);
            }
            b[r] = self.plane(k, s);
        }
        let lambda = solve_small::<N>(&a, &b)?;
        if lambda[..n].iter().any(|&l| l < 0.0) {
            return None;
        }
        let mut out = *s;
        let (mut ep, mut eps) = ([0.0; 3], [0.0; 3]);
        let (mut shear, mut tension) = (0.0, 0.0);
        for (c, &j) in set.iter().enumerate() {
            let g = self.potential_gradient(j);
            for i in 0..3 {
                out[i] -= lambda[c] * dg[c][i];
                ep[i] += lambda[c] * g[i];
                if j < 3 {
                    eps[i] += lambda[c] * g[i];
                }
            }
            if j < 3 {
                shear += lambda[c];
            } else {
                tension += lambda[c];
            }
        }
        Some(Return {
            stress: out,
            plastic_strain: ep,
            shear_strain: eps,
            shear,
            tension,
        })
    }
}

/// The larger of two numbers that are not NaN (one instruction, where `f64::max` also
/// handles NaN).
#[inline(always)]
pub(super) fn max2(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

/// The smaller of two numbers that are not NaN (see [`max2`]).
#[inline(always)]
pub(super) fn min2(a: f64, b: f64) -> f64 {
    if a < b {
        a
    } else {
        b
    }
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Solves the leading n×n block of a x = b (n ≤ 3) by Gaussian elimination with partial
/// pivoting; `None` if singular.
#[inline(always)]
fn solve_small<const N: usize>(a: &[[f64; 3]; 3], b: &[f64; 3]) -> Option<[f64; 3]> {
    let n = N;
    let (mut a, mut b) = (*a, *b);
    let norm = a
        .iter()
        .take(n)
        .flat_map(|r| r.iter().take(n))
        .fold(0.0f64, |m, v| m.max(v.abs()));
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        if a[p][c].abs() <= 1e-12 * norm {
            return None;
        }
        a.swap(c, p);
        b.swap(c, p);
        for r in c + 1..n {
            let f = a[r][c] / a[c][c];
            for k in c..n {
                a[r][k] -= f * a[c][k];
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = [0.0; 3];
    for c in (0..n).rev() {
        let mut v = b[c];
        for k in c + 1..n {
            v -= a[c][k] * x[k];
        }
        x[c] = v / a[c][c];
    }
    Some(x)
}

/// The [`Return`] of a return onto the shear plane alone with multiplier `lambda` to
/// principal stresses `stress` (dilation N_ψ `n_psi`): λ∇g₀ summed from zero as
/// `solve_n` sums it (0 + λ·(−1) is 0 − λ, exactly).
#[inline(always)]
pub(super) fn shear_return(lambda: f64, stress: [f64; 3], n_psi: f64) -> Return {
    let ep = [0.0 - lambda, 0.0 + lambda * 0.0, 0.0 + lambda * n_psi];
    Return {
        stress,
        plastic_strain: ep,
        shear_strain: ep,
        shear: 0.0 + lambda,
        tension: 0.0,
    }
}
