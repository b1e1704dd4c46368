//! Mohr–Coulomb elasto-plasticity with a tension cut-off (manual 7.2.4, table 2,
//! `mech-mohr-coulomb`).
//!
//! Principal stresses are ordered σ1 ≤ σ2 ≤ σ3, tension positive (σ1 the most
//! compressive; FLAC's ordering, the only one consistent with eq. 29–30, see the digest).
//! In 2D (plane strain) σzz is one of the three.
//!
//! * **(25)–(28)** elastic trial σ* = σ(t) + C:Δε, computed in Cartesian components and
//!   then decomposed ([`crate::principal`]; in plane strain in closed form,
//!   [`crate::principal::plane`]); in principal axes Δσ_i = α1 Δε_i + α2 Σ_{j≠i}
//!   Δε_j, α1 = K + 4G/3, α2 = K − 2G/3.
//! * **(29)** \[CORRECTED\] shear yield f_s = −σ1 + σ3 N_φ − 2c √N_φ (printed with N_φ where
//!   √N_φ belongs); failure when f_s > 0.
//! * **(30)** tension yield f_t = σ3 − σ_t; **(31)** N_φ = (1 + sin φ)/(1 − sin φ).
//! * **(32)** shear potential g_s = −σ1 + σ3 N_ψ (non-associated, dilation angle ψ ≤ φ);
//!   **(33)** tension potential g_t = σ3 (associated).
//! * **Return mapping** \[NOT IN MANUAL: the manual stops at "correct with the potential"\]
//!   σ^N = σ* − Σ_k λ_k D ∇g_k over an active set of the yield planes of the ordered
//!   sector, λ_k ≥ 0 from f_k(σ^N) = 0 (the planes are linear in principal space, so each
//!   set is one small linear solve, tried as an active set first: the plane the h-function
//!   picks, then the most violated plane of each result added, up to three; a search over
//!   every set is the fallback, so a return is never missed). The planes: the shear plane of eq. 29, the two
//!   shear planes that meet it where σ2 reaches σ3 or σ1 (the edges of the Mohr–Coulomb
//!   pyramid), and σ_i = σ_t for each i. One shear plane alone is the digest's (FLAC's)
//!   formula, λ = F / [α1(1 + N_φ N_ψ) − α2(N_φ + N_ψ)]; σ3 = σ_t alone is its tension
//!   correction; the shear plane with σ3 = σ_t is the shear–tension corner; all three
//!   tension planes the apex of the cut-off. The digest's h-function,
//!   h = σ3 − σ_t + α_P(σ1 − σ_P), α_P = √(1 + N_φ²) + N_φ, σ_P = σ_t N_φ − 2c√N_φ,
//!   orders the first two trials (shear first when h ≤ 0, tension first when h > 0); a
//!   set is taken only if its multipliers are non-negative and the corrected stress lies
//!   on or inside every plane (to rounding), so the result is never outside the yield
//!   surface even where FLAC's single correction would leave σ2 above σ_t or the
//!   principal order broken. Directions are those of the trial stress (isotropy).
//! * **Tension cut-off cap** σ_t ≤ c / tan φ (digest 2.2): beyond it the cut-off would
//!   not meet the shear pyramid, and with it the plastic dissipation σ:Δε^p ≥ 0.
//!
//! * **Softening** \[NOT IN MANUAL: table 2 has constant strengths\] optional
//!   piecewise-linear tables of c, φ, ψ against κ_s and σ_t against κ_t ([`Softening`],
//!   FLAC's strain-softening model), evaluated at the κ the step starts from.
//! * **GPU**: the WGSL body (`shaders/mohr_coulomb.wgsl`, helpers in
//!   `shaders/mohr_coulomb_lib.wgsl`) repeats these operations in the same order; f64
//!   matches the CPU to rounding (`tests/gpu_parity_mohr_coulomb.rs`). Without softening
//!   it needs no trigonometry (N_φ, N_ψ, 2c√N_φ are parameters); with softening it takes
//!   sin from a Taylor series (error < 3e-16 on [0, π/2]), since drivers may lack f64 sin.
//!
//! History per element ([`MohrCoulomb::n_state`], shown in VTU through the
//! `model_state` field): `[0]` shear now, `[1]` shear in the past, `[2]` tension now,
//! `[3]` tension in the past (1 or 0; "now" is this step, "past" any step since the last
//! `reset_element_state`), `[4]` accumulated plastic shear strain κ_s (FLAC's measure,
//! Δκ_s = √(½ Σ_i (Δε_iᵖ − Δεmᵖ)²), Δεmᵖ = (Δε1ᵖ + Δε2ᵖ + Δε3ᵖ)/3 over the shear
//! planes' flow: on the shear plane alone (Δε2ᵖ = 0) exactly FLAC's
//! √(½(Δε1ᵖ − Δεmᵖ)² + ½(Δεmᵖ)² + ½(Δε3ᵖ − Δεmᵖ)²); on an edge it also counts the middle
//! component, which FLAC's form drops),
//! `[5]` accumulated plastic tensile strain κ_t (the tension planes' multipliers summed).

use serde::{Deserialize, Serialize};

use pcdc_compute::Table;

use crate::model::{add_hooke, ConstitutiveModel, LinearElastic, ModelInput, Sym6, WgslModel};
use crate::principal::{
    compose, compose_plane, plane, principal, principal_lanes, Principal, JACOBI_STOP, LANES,
};
use crate::MechError;

/// Number of history variables of [`MohrCoulomb`].
pub const MC_STATE: usize = 6;

/// Index of the flags and strains in a [`MohrCoulomb`] element's history.
pub mod state {
    /// 1 when the element yielded in shear this step.
    pub const SHEAR_NOW: usize = 0;
    /// 1 when the element has yielded in shear since its state was last reset.
    pub const SHEAR_PAST: usize = 1;
    /// 1 when the element yielded in tension this step.
    pub const TENSION_NOW: usize = 2;
    /// 1 when the element has yielded in tension since its state was last reset.
    pub const TENSION_PAST: usize = 3;
    /// Accumulated plastic shear strain κ_s (-).
    pub const SHEAR_STRAIN: usize = 4;
    /// Accumulated plastic tensile strain κ_t (-).
    pub const TENSION_STRAIN: usize = 5;
}

/// Mohr–Coulomb elasto-plastic model with a tension cut-off (manual 7.2.4, table 2).
///
/// Parameters (checked by the constructor and on deserialisation, errors name the
/// parameter): the elastic part as a [`LinearElastic`] (E, ν, ρ, D_f, contact
/// properties); cohesion c ≥ 0 (Pa); friction angle φ in [0, 90) degrees; dilation angle
/// ψ in [0, φ] degrees; tensile strength σ_t ≥ 0 (Pa), capped at c / tan φ when φ > 0
/// ([`MohrCoulomb::tensile_effective`]). With c = σ_t = 0 and φ = 0 the material has no
/// strength at all, which is refused.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawMohrCoulomb")]
pub struct MohrCoulomb {
    elastic: LinearElastic,
    cohesion: f64,
    friction: f64,
    dilation: f64,
    tensile: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    softening: Option<Softening>,
    /// Derived once from the parameters: `update` runs per element per step.
    #[serde(skip_serializing)]
    surfaces: Surfaces,
    /// λ and 2μ of the elastic part (Pa), derived once.
    #[serde(skip_serializing)]
    lame: (f64, f64),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMohrCoulomb {
    elastic: LinearElastic,
    cohesion: f64,
    friction: f64,
    #[serde(default)]
    dilation: f64,
    tensile: f64,
    #[serde(default)]
    softening: Option<Softening>,
}

impl TryFrom<RawMohrCoulomb> for MohrCoulomb {
    type Error = MechError;
    fn try_from(r: RawMohrCoulomb) -> Result<Self, MechError> {
        let m = MohrCoulomb::new(r.elastic, r.cohesion, r.friction, r.dilation, r.tensile)?;
        match r.softening {
            Some(soft) => m.with_softening(soft),
            None => Ok(m),
        }
    }
}

/// Softening (or hardening) of the strength with plastic strain, FLAC's strain-softening
/// Mohr–Coulomb: piecewise-linear tables of cohesion c (Pa), friction angle φ and
/// dilation angle ψ (degrees) against the accumulated plastic shear strain κ_s, and of
/// the tensile strength σ_t (Pa) against the accumulated plastic tensile strain κ_t
/// (both dimensionless; see the module documentation for their increments). A table
/// left `None` keeps the model's constant. Values are constant beyond a table's ends.
///
/// The strengths of a step are those at the element's κ at the start of the step
/// (explicit, as FLAC). At any κ the dilation angle used is min(ψ(κ), φ(κ)) and the
/// tensile strength min(σ_t(κ_t), c(κ_s) / tan φ(κ_s)), so a table may soften φ below ψ
/// or c below the cut-off without leaving the model inconsistent. Checked when set
/// ([`MohrCoulomb::with_softening`]): every c and σ_t point non-negative and finite,
/// every φ and ψ point in [0, 90) degrees, and κ increasing strictly from κ ≥ 0.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Softening {
    /// Cohesion c (Pa) against κ_s.
    #[serde(default)]
    pub cohesion: Option<Table>,
    /// Friction angle φ (degrees) against κ_s.
    #[serde(default)]
    pub friction: Option<Table>,
    /// Dilation angle ψ (degrees) against κ_s.
    #[serde(default)]
    pub dilation: Option<Table>,
    /// Tensile strength σ_t (Pa) against κ_t.
    #[serde(default)]
    pub tensile: Option<Table>,
}

impl Softening {
    fn check(&self) -> Result<(), MechError> {
        let tables = [
            ("cohesion c", &self.cohesion, 0.0, f64::INFINITY),
            ("friction angle φ", &self.friction, 0.0, 90.0),
            ("dilation angle ψ", &self.dilation, 0.0, 90.0),
            ("tensile strength σ_t", &self.tensile, 0.0, f64::INFINITY),
        ];
        for (name, table, lo, hi) in tables {
            let Some(t) = table else { continue };
            for (i, (k, v)) in t.points().enumerate() {
                if k < 0.0 {
                    return Err(MechError::param(
                        format!("softening table of the {name}, point {i}: plastic strain"),
                        k,
                        "must be non-negative",
                    ));
                }
                if !(v >= lo && v < hi) {
                    return Err(MechError::param(
                        format!("softening table of the {name}, point {i}"),
                        v,
                        if hi.is_finite() {
                            format!("must lie in [{lo}, {hi}) degrees")
                        } else {
                            "must be non-negative and finite (Pa)".to_string()
                        },
                    ));
                }
            }
        }
        Ok(())
    }

    /// The tables in the GPU layout: per table its point count, abscissae, values.
    fn wgsl_params(&self, out: &mut Vec<f64>) {
        for t in [
            &self.cohesion,
            &self.friction,
            &self.dilation,
            &self.tensile,
        ] {
            match t {
                Some(t) => {
                    let pts: Vec<(f64, f64)> = t.points().collect();
                    out.push(pts.len() as f64);
                    out.extend(pts.iter().map(|p| p.0));
                    out.extend(pts.iter().map(|p| p.1));
                }
                None => out.push(0.0),
            }
        }
    }
}

impl MohrCoulomb {
    /// From the elastic part, cohesion c (Pa), friction angle φ (degrees), dilation angle
    /// ψ (degrees) and tensile strength σ_t (Pa).
    pub fn new(
        elastic: LinearElastic,
        cohesion: f64,
        friction_deg: f64,
        dilation_deg: f64,
        tensile: f64,
    ) -> Result<Self, MechError> {
        if !(cohesion >= 0.0 && cohesion.is_finite()) {
            return Err(MechError::param(
                "cohesion c (cohesion)",
                cohesion,
                "must be non-negative and finite (Pa)",
            ));
        }
        if !(0.0..90.0).contains(&friction_deg) {
            return Err(MechError::param(
                "friction angle φ (friction)",
                friction_deg,
                "must lie in [0, 90) degrees",
            ));
        }
        if !(dilation_deg >= 0.0 && dilation_deg <= friction_deg) {
            return Err(MechError::param(
                "dilation angle ψ (dilation)",
                dilation_deg,
                format!("must lie in [0, φ = {friction_deg}] degrees"),
            ));
        }
        if !(tensile >= 0.0 && tensile.is_finite()) {
            return Err(MechError::param(
                "tensile strength σ_t (tensile)",
                tensile,
                "must be non-negative and finite (Pa)",
            ));
        }
        if cohesion == 0.0 && friction_deg == 0.0 {
            return Err(MechError::param(
                "cohesion c (cohesion)",
                cohesion,
                "and the friction angle are both zero: the material would have no shear \
                 strength",
            ));
        }
        let lame = (elastic.lambda(), 2.0 * elastic.shear());
        let mut m = MohrCoulomb {
            elastic,
            cohesion,
            friction: friction_deg,
            dilation: dilation_deg,
            tensile,
            softening: None,
            surfaces: Surfaces::default(),
            lame,
        };
        m.surfaces = surfaces_of(&m.elastic, cohesion, friction_deg, dilation_deg, tensile);
        Ok(m)
    }

    /// Adds strength softening (hardening) with plastic strain; errors name the table
    /// and point ([`Softening`]).
    pub fn with_softening(mut self, softening: Softening) -> Result<Self, MechError> {
        softening.check()?;
        self.softening = Some(softening);
        Ok(self)
    }

    /// The softening tables, if any.
    pub fn softening(&self) -> Option<&Softening> {
        self.softening.as_ref()
    }

    /// The surfaces at plastic strains κ_s, κ_t: [`Self::surfaces`] without softening,
    /// else those of the tables' strengths ([`Softening`]).
    pub fn surfaces_at(&self, kappa_s: f64, kappa_t: f64) -> Surfaces {
        let Some(soft) = &self.softening else {
            return self.surfaces;
        };
        let at = |t: &Option<Table>, x: f64, c: f64| t.as_ref().map_or(c, |t| t.eval(x));
        let c = at(&soft.cohesion, kappa_s, self.cohesion);
        let phi = at(&soft.friction, kappa_s, self.friction);
        let psi = at(&soft.dilation, kappa_s, self.dilation).min(phi);
        let st = at(&soft.tensile, kappa_t, self.tensile);
        surfaces_of(&self.elastic, c, phi, psi, st)
    }

    /// The elastic part.
    pub fn elastic(&self) -> &LinearElastic {
        &self.elastic
    }
    /// Cohesion c (Pa).
    pub fn cohesion(&self) -> f64 {
        self.cohesion
    }
    /// Friction angle φ (degrees).
    pub fn friction(&self) -> f64 {
        self.friction
    }
    /// Dilation angle ψ (degrees).
    pub fn dilation(&self) -> f64 {
        self.dilation
    }
    /// Tensile strength σ_t as given (Pa).
    pub fn tensile(&self) -> f64 {
        self.tensile
    }
    /// The tensile strength the model uses (before softening): min(σ_t, c / tan φ) (Pa).
    pub fn tensile_effective(&self) -> f64 {
        tensile_cap(self.cohesion, self.friction, self.tensile)
    }
    /// True when the given σ_t lies above c / tan φ and the model uses the cap instead
    /// ([`Self::tensile_effective`]): check it (or print it) after building a model from
    /// user input, as the cap changes the strength the user asked for.
    pub fn tensile_is_capped(&self) -> bool {
        self.tensile_effective() < self.tensile
    }
    /// Uniaxial compressive strength 2c √N_φ (Pa).
    pub fn ucs(&self) -> f64 {
        2.0 * self.cohesion * n_of(self.friction).sqrt()
    }

    /// The surfaces for the return mapping.
    pub fn surfaces(&self) -> Surfaces {
        self.surfaces
    }
}

/// min(σ_t, c / tan φ) (Pa; φ in degrees).
fn tensile_cap(c: f64, phi_deg: f64, st: f64) -> f64 {
    let phi = phi_deg.to_radians();
    if phi > 0.0 {
        st.min(c / phi.tan())
    } else {
        st
    }
}

/// The surfaces of strengths c (Pa), φ, ψ (degrees), σ_t (Pa) on an elastic part.
fn surfaces_of(e: &LinearElastic, c: f64, phi: f64, psi: f64, st: f64) -> Surfaces {
    let (g, k) = (e.shear(), e.bulk());
    let n_phi = n_of(phi);
    Surfaces {
        n_phi,
        n_psi: n_of(psi),
        kc: 2.0 * c * n_phi.sqrt(),
        st: tensile_cap(c, phi, st),
        a1: k + 4.0 * g / 3.0,
        a2: k - 2.0 * g / 3.0,
        alpha_p: (1.0 + n_phi * n_phi).sqrt() + n_phi,
    }
}

/// N = (1 + sin a)/(1 − sin a) of an angle in degrees (eq. 31).
fn n_of(deg: f64) -> f64 {
    let s = deg.to_radians().sin();
    (1.0 + s) / (1.0 - s)
}

/// The yield planes of the ordered sector σ1 ≤ σ2 ≤ σ3 and the elastic constants of
/// the return mapping (see the module documentation).
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
struct ShearPlane {
    /// D∇g₀, the elastic image of the shear plane's flow direction (Pa).
    dg: [f64; 3],
    /// ∇f₀·D∇g₀ (Pa).
    a: f64,
}

/// √3, for [`Surfaces::surely_elastic`].
const SQRT_3: f64 = 1.732_050_807_568_877_2;

/// What [`Surfaces::shear_first`] found for a trial.
#[derive(Clone, Copy, Debug, PartialEq)]
enum FirstTry {
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
    fn shear_plane(&self) -> ShearPlane {
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
    /// elements ([`MohrCoulomb::update_many`]) can take it straight from the trial.
    #[inline(always)]
    fn shear_first(&self, s: &[f64; 3], sp: &ShearPlane) -> FirstTry {
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
fn max2(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

/// The smaller of two numbers that are not NaN (see [`max2`]).
#[inline(always)]
fn min2(a: f64, b: f64) -> f64 {
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

/// True when a tensor is plane (yz = xz = 0): plane strain, whose principal stresses
/// come in closed form.
fn is_plane(t: &Sym6) -> bool {
    t[4] == 0.0 && t[5] == 0.0
}

impl MohrCoulomb {
    /// The elastic trial σ + D Δε in `stress` and the step's flags cleared; false when
    /// the trial is surely elastic against the element's surfaces `f`
    /// ([`Surfaces::surely_elastic`]): then `stress` is the new stress.
    #[inline(always)]
    fn trial_with(&self, f: &Surfaces, de: &Sym6, stress: &mut Sym6, st: &mut [f64]) -> bool {
        add_hooke(self.lame.0, self.lame.1, de, stress);
        st[state::SHEAR_NOW] = 0.0;
        st[state::TENSION_NOW] = 0.0;
        !f.surely_elastic(stress)
    }

    /// Returns a plane trial stress to the surfaces (closed-form principal stresses).
    fn plastic_plane(&self, surfaces: &Surfaces, stress: &mut Sym6, st: &mut [f64]) {
        let p = plane(stress);
        if let Some(r) = surfaces.return_map(&p.values) {
            *stress = compose_plane(&r.stress, &p);
            record(&r, st);
        }
    }

    /// Returns a trial stress with principal decomposition `p` to the surfaces.
    fn plastic(&self, surfaces: &Surfaces, p: &Principal, stress: &mut Sym6, st: &mut [f64]) {
        if let Some(r) = surfaces.return_map(&p.values) {
            *stress = compose(&r.stress, &p.axes);
            record(&r, st);
        }
    }

    /// [`ConstitutiveModel::update_many`] with (`SOFT`) or without softening.
    fn update_run<const SOFT: bool>(
        &self,
        inputs: &[ModelInput<'_>],
        stresses: &mut [Sym6],
        states: &mut [f64],
        stride: usize,
    ) {
        const BLOCK: usize = 2 * LANES;
        let stride = stride.max(1);
        // As the default: elements beyond the shortest of the three are left alone.
        let n = inputs.len().min(stresses.len()).min(states.len() / stride);
        let (inputs, stresses) = (&inputs[..n], &mut stresses[..n]);
        let blocks = inputs
            .chunks(BLOCK)
            .zip(stresses.chunks_mut(BLOCK))
            .zip(states.chunks_mut(BLOCK * stride));
        for ((inputs, stresses), states) in blocks {
            // The elastic trials first, with the surfaces of each element's plastic
            // strains (looked up only with softening); those not surely elastic are
            // candidates.
            let mut surfaces = [Surfaces::default(); BLOCK];
            let (mut cand, mut nc) = ([0usize; BLOCK], 0);
            for (i, (x, s)) in inputs.iter().zip(stresses.iter_mut()).enumerate() {
                let st = &mut states[i * stride..(i + 1) * stride];
                let yields = if SOFT {
                    let f = self.surfaces_at(st[state::SHEAR_STRAIN], st[state::TENSION_STRAIN]);
                    surfaces[i] = f;
                    self.trial_with(&f, x.dstrain, s, st)
                } else {
                    self.trial_with(&self.surfaces, x.dstrain, s, st)
                };
                cand[nc] = i;
                nc += usize::from(yields);
            }
            let f_of = |i: usize| if SOFT { &surfaces[i] } else { &self.surfaces };
            // The shear plane's constants once for the run when the surfaces are the
            // model's, else per element.
            let sp_model = self.surfaces.shear_plane();
            let sp_of = |f: &Surfaces| if SOFT { f.shear_plane() } else { sp_model };
            // Then the candidates: plane ones straight onto the shear plane where that is
            // the return (histories written after the run, so that the square roots
            // there overlap); the others wait for the general return, plane ones (closed
            // form) and 3D ones (Jacobi) apart.
            let (mut plane_wait, mut wait) = ([0usize; BLOCK], [0usize; BLOCK]);
            let (mut np, mut n) = (0, 0);
            let (mut shear, mut ns) = ([(0usize, 0.0f64, 0.0f64); BLOCK], 0);
            for &i in &cand[..nc] {
                let s = &mut stresses[i];
                if !is_plane(s) {
                    wait[n] = i;
                    n += 1;
                    continue;
                }
                let (f, p) = (f_of(i), plane(s));
                match f.shear_first(&p.values, &sp_of(f)) {
                    FirstTry::Elastic => continue,
                    FirstTry::Shear(lambda, o) => {
                        *s = compose_plane(&o, &p);
                        shear[ns] = (i, lambda, f.n_psi);
                        ns += 1;
                        continue;
                    }
                    FirstTry::Other => {}
                }
                plane_wait[np] = i;
                np += 1;
            }
            for &i in &plane_wait[..np] {
                let st = &mut states[i * stride..];
                self.plastic_plane(f_of(i), &mut stresses[i], st);
            }
            // The 3D ones: their decompositions, [`LANES`] at a time where there are
            // enough, then with constant surfaces the shear plane at once if it is the
            // return, else the general return.
            for group in wait[..n].chunks(LANES) {
                let ps: [Principal; LANES] = if group.len() <= 2 {
                    let none = Principal {
                        values: [0.0; 3],
                        axes: [[0.0; 3]; 3],
                    };
                    std::array::from_fn(|l| group.get(l).map_or(none, |&i| principal(&stresses[i])))
                } else {
                    // Unused lanes get a zero tensor, which needs no rotation.
                    let ts =
                        std::array::from_fn(|l| group.get(l).map_or([0.0; 6], |&i| stresses[i]));
                    principal_lanes(&ts)
                };
                for (&i, p) in group.iter().zip(&ps) {
                    let f = f_of(i);
                    match f.shear_first(&p.values, &sp_of(f)) {
                        FirstTry::Elastic => {}
                        FirstTry::Shear(lambda, o) => {
                            stresses[i] = compose(&o, &p.axes);
                            shear[ns] = (i, lambda, f.n_psi);
                            ns += 1;
                        }
                        FirstTry::Other => {
                            let st = &mut states[i * stride..];
                            self.plastic(f, p, &mut stresses[i], st);
                        }
                    }
                }
            }
            for &(i, lambda, n_psi) in &shear[..ns] {
                record(
                    &shear_return(lambda, [0.0; 3], n_psi),
                    &mut states[i * stride..],
                );
            }
        }
    }
}

/// The [`Return`] of a return onto the shear plane alone with multiplier `lambda` to
/// principal stresses `stress` (dilation N_ψ `n_psi`): λ∇g₀ summed from zero as
/// `solve_n` sums it (0 + λ·(−1) is 0 − λ, exactly).
#[inline(always)]
fn shear_return(lambda: f64, stress: [f64; 3], n_psi: f64) -> Return {
    let ep = [0.0 - lambda, 0.0 + lambda * 0.0, 0.0 + lambda * n_psi];
    Return {
        stress,
        plastic_strain: ep,
        shear_strain: ep,
        shear: 0.0 + lambda,
        tension: 0.0,
    }
}

/// Writes what a return did to the element's history: the flags, and the plastic shear
/// and tensile strains.
fn record(r: &Return, st: &mut [f64]) {
    if r.shear > 0.0 {
        st[state::SHEAR_NOW] = 1.0;
        st[state::SHEAR_PAST] = 1.0;
        // FLAC's shear hardening parameter from the shear planes' plastic strain, in its
        // symmetric form (all three components: on an edge the middle one is not zero).
        let ep = r.shear_strain;
        let m = (ep[0] + ep[1] + ep[2]) * (1.0 / 3.0);
        let (a, b, c) = (ep[0] - m, ep[1] - m, ep[2] - m);
        st[state::SHEAR_STRAIN] += (0.5 * (a * a + b * b + c * c)).sqrt();
    }
    if r.tension > 0.0 {
        st[state::TENSION_NOW] = 1.0;
        st[state::TENSION_PAST] = 1.0;
        st[state::TENSION_STRAIN] += r.tension;
    }
}

impl ConstitutiveModel for MohrCoulomb {
    fn name(&self) -> &str {
        "mech-mohr-coulomb"
    }
    crate::model::delegate_elastic!(elastic);
    fn n_state(&self) -> usize {
        MC_STATE
    }
    fn update(&self, _strain: &Sym6, de: &Sym6, stress: &mut Sym6, st: &mut [f64]) {
        let surfaces = self.surfaces_at(st[state::SHEAR_STRAIN], st[state::TENSION_STRAIN]);
        if !self.trial_with(&surfaces, de, stress, st) {
            return;
        }
        // Plane strain in closed form, else Jacobi (the same values to rounding).
        if is_plane(stress) {
            self.plastic_plane(&surfaces, stress, st);
        } else {
            let p = principal(stress);
            self.plastic(&surfaces, &p, stress, st);
        }
    }
    /// As [`MohrCoulomb::update`] for each element, bit for bit, with the 3D principal
    /// decompositions of the elements that need one done [`LANES`] at a time
    /// ([`principal_lanes`]): one Jacobi decomposition is a chain of dependent roots and
    /// divisions, and several side by side cost little more than one. A return that
    /// ends on the shear plane at the first try is taken straight from the
    /// decomposition (`Surfaces::shear_first`, the first step of
    /// [`Surfaces::return_map`]), and the histories of those returns are written after
    /// the run.
    fn update_many(
        &self,
        inputs: &[ModelInput<'_>],
        stresses: &mut [Sym6],
        states: &mut [f64],
        stride: usize,
    ) {
        // One build per case, so that without softening nothing of it is in the loops.
        match self.softening {
            None => self.update_run::<false>(inputs, stresses, states, stride),
            Some(_) => self.update_run::<true>(inputs, stresses, states, stride),
        }
    }

    fn wgsl(&self) -> Option<WgslModel> {
        let f = &self.surfaces;
        let mut params = vec![
            self.lame.0,
            self.lame.1,
            f.a1,
            f.a2,
            f.n_phi,
            f.n_psi,
            f.kc,
            f.st,
            JACOBI_STOP,
            f64::MIN_POSITIVE,
            f64::from(u8::from(self.softening.is_some())),
            self.cohesion,
            self.friction,
            self.dilation,
            self.tensile,
            f.alpha_p,
        ];
        match &self.softening {
            Some(soft) => soft.wgsl_params(&mut params),
            None => params.extend([0.0; 4]),
        }
        Some(WgslModel {
            key: "mohr_coulomb".into(),
            body: include_str!("shaders/mohr_coulomb.wgsl").into(),
            params,
            functions: include_str!("shaders/mohr_coulomb_lib.wgsl").into(),
        })
    }
}
