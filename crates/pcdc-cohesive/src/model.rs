//! Joint constitutive models: the `JointModel` plugin trait and the intrinsic cohesive
//! zone model of manual 7.4.1 (eq. 63-73).
//!
//! Sign conventions: the opening `o` (m) is positive when the two joint faces separate
//! and negative when they overlap; the normal traction `σ` (Pa) is positive when it
//! pulls the faces together (cohesion) and negative when it pushes them apart
//! (overlap); the shear traction opposes the slip.

use pcdc_compute::FieldKey;
use serde::{Deserialize, Serialize};

use crate::CohesiveError;

/// Coefficients of the softening function f(D) (eq. 69), as fixed by the manual.
pub const SOFTENING_A: f64 = 0.63;
/// See [`SOFTENING_A`].
pub const SOFTENING_B: f64 = 1.8;
/// See [`SOFTENING_A`].
pub const SOFTENING_C: f64 = 6.0;

/// (A + B − 1) / (A + B): the factor of the exponential in eq. 69.
const SOFTENING_Z0: f64 = (SOFTENING_A + SOFTENING_B - 1.0) / (SOFTENING_A + SOFTENING_B);
/// A + C B: numerator of the exponent in eq. 69 (multiplied by D).
const SOFTENING_X: f64 = SOFTENING_A + SOFTENING_C * SOFTENING_B;
/// (A + B)(1 − A − B): denominator of the exponent in eq. 69.
const SOFTENING_Y: f64 = (SOFTENING_A + SOFTENING_B) * (1.0 - SOFTENING_A - SOFTENING_B);
// f(D) takes (1 − D)^C by multiplications: C must stay 6.
const _: () = assert!(SOFTENING_C == 6.0);

/// Softening function f(D) of eq. 69: f(0) = 1, f(1) = 0, decreasing:
/// f(D) = [1 − (A + B − 1)/(A + B) · exp(D (A + C B) / ((A + B)(1 − A − B)))]
/// · [A (1 − D) + B (1 − D)^C].
///
/// Evaluated with + − × ÷ only ([`portable_exp`], and (1 − D)^6 as ((q²)(q²))q²), the
/// same operations in the same order as the WGSL `softening` of the GPU joint kernel,
/// so that both backends soften identically (f64 drivers often lack `exp`/`pow`).
pub fn softening(d: f64) -> f64 {
    if d <= 0.0 {
        return 1.0;
    }
    if d >= 1.0 {
        return 0.0;
    }
    let z = SOFTENING_Z0 * portable_exp(d * SOFTENING_X / SOFTENING_Y);
    let q = 1.0 - d;
    let q2 = q * q;
    let q6 = q2 * q2 * q2;
    (1.0 - z) * (SOFTENING_A * q + SOFTENING_B * q6)
}

/// ln 2, high part (fdlibm's `ln2HI` = 6.93147180369123816490e-01: its 21 trailing bits
/// are zero, so `k · LN2_HI` is exact for |k| < 2^21).
const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
/// ln 2 − `LN2_HI` (fdlibm's `ln2LO` = 1.90821492927058770002e-10).
const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
/// 1 / ln 2.
const INV_LN2: f64 = std::f64::consts::LOG2_E;
/// Taylor coefficients 1/i! of e^r, i = 0..=13.
const EXP_TAYLOR: [f64; 14] = {
    let mut c = [1.0; 14];
    let mut i = 1;
    while i < 14 {
        c[i] = c[i - 1] / i as f64;
        i += 1;
    }
    c
};

/// e^x with + − × ÷ and an integer conversion only: the argument is clamped to
/// [−708, 709], reduced to x = k ln 2 + r with |r| ≤ ln 2 / 2 (Cody–Waite, two-part
/// ln 2), e^r is a degree-13 Taylor polynomial in Horner form (truncation below 1e-17
/// relative) and 2^k is exact. Within 4e-16 relative of `f64::exp` on the clamp range.
///
/// The WGSL function `portable_exp` of the joint kernel performs the same operations in
/// the same order: GPU drivers often have no f64 `exp` (Vulkan's GLSL.std.450 `Exp` is
/// 32-bit only), and a shared hand-written version keeps CPU and GPU results equal to
/// rounding.
pub fn portable_exp(x: f64) -> f64 {
    let x = x.clamp(-708.0, 709.0);
    let t = x * INV_LN2;
    let k = (t + if t >= 0.0 { 0.5 } else { -0.5 }) as i32;
    let kf = k as f64;
    let r = (x - kf * LN2_HI) - kf * LN2_LO;
    let mut p = EXP_TAYLOR[13];
    for i in (0..13).rev() {
        p = EXP_TAYLOR[i] + r * p;
    }
    // 2^k, k in [-1021, 1023]: a normal power of two, exact.
    p * f64::from_bits(((k + 1023) as u64) << 52)
}

/// Constants the WGSL joint library (`portable_exp`, `softening`) reads, with their
/// WGSL names: passed to the kernel as exact `Real` constants.
pub(crate) fn wgsl_library_constants() -> Vec<(String, f64)> {
    let mut c = vec![
        ("SOFTENING_A".to_string(), SOFTENING_A),
        ("SOFTENING_B".to_string(), SOFTENING_B),
        ("SOFTENING_Z0".to_string(), SOFTENING_Z0),
        ("SOFTENING_X".to_string(), SOFTENING_X),
        ("SOFTENING_Y".to_string(), SOFTENING_Y),
        ("LN2_HI".to_string(), LN2_HI),
        ("LN2_LO".to_string(), LN2_LO),
        ("INV_LN2".to_string(), INV_LN2),
    ];
    for (i, v) in EXP_TAYLOR.iter().enumerate() {
        c.push((format!("EXP_C{i}"), *v));
    }
    c
}

/// ∫₀¹ f(D) dD (composite Simpson, 2000 intervals): the softening work per unit
/// strength and softening length.
pub fn softening_integral() -> f64 {
    let n = 2000;
    let h = 1.0 / n as f64;
    let mut sum = softening(0.0) + softening(1.0);
    for i in 1..n {
        sum += if i % 2 == 1 { 4.0 } else { 2.0 } * softening(i as f64 * h);
    }
    sum * h / 3.0
}

/// How a joint failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum FailureMode {
    /// Not broken.
    Intact,
    /// Opening (mode I).
    Tensile,
    /// Sliding (mode II, with III merged in 3D).
    Shear,
    /// Mixed I-II.
    Mixed,
}

impl FailureMode {
    /// Encoding stored in a joint's state.
    pub fn code(self) -> f64 {
        match self {
            FailureMode::Intact => 0.0,
            FailureMode::Tensile => 1.0,
            FailureMode::Shear => 2.0,
            FailureMode::Mixed => 3.0,
        }
    }

    /// Decodes [`FailureMode::code`].
    pub fn from_code(c: f64) -> Self {
        match c as i32 {
            1 => FailureMode::Tensile,
            2 => FailureMode::Shear,
            3 => FailureMode::Mixed,
            _ => FailureMode::Intact,
        }
    }
}

/// Tractions at a joint integration point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Traction {
    /// Normal traction σ (Pa): positive pulls the faces together, negative pushes apart.
    pub normal: f64,
    /// Shear traction vector (Pa, global components, first `D` used) acting on side A;
    /// side B receives the opposite. A resisting shear points along the slip of B
    /// relative to A.
    pub shear: [f64; 3],
}

impl Traction {
    /// Magnitude of the shear traction (Pa).
    pub fn shear_magnitude(&self) -> f64 {
        self.shear.iter().map(|v| v * v).sum::<f64>().sqrt()
    }
}

/// A joint stress-displacement law evaluated at one integration point.
pub trait JointModel: Send + Sync + std::fmt::Debug {
    /// Model name.
    fn name(&self) -> &str;
    /// History variables per integration point.
    fn n_state(&self) -> usize;
    /// Initial history variables.
    fn init_state(&self, state: &mut [f64]) {
        state.fill(0.0);
    }
    /// Tractions for opening `o` (m) and slip vector `slip` (m; the tangential gap of side
    /// B relative to side A in global components, length `D` or less) at a joint of
    /// characteristic length `h` (m); updates the history in `state`. Once the joint's
    /// largest [`JointModel::damage`] reaches 1 the physics stops calling the model and
    /// the joint transfers no force (contact takes over); a model whose own broken state
    /// still returned a traction would be ignored from then on. The physics calls
    /// [`JointModel::traction_with`], whose default calls this method; a model that
    /// declares [`JointModel::coupling`] fields overrides [`JointModel::traction_with`]
    /// and implements this method as its law without coupling inputs.
    fn traction(&self, o: f64, slip: &[f64], h: f64, state: &mut [f64]) -> Traction;
    /// The coupling fields this model reads in [`JointModel::traction_with`], in the
    /// order in which it receives their values ([`JointInput::coupling`]), e.g.
    /// `&[names::PORE_PRESSURE]` for a joint under fluid pressure
    /// (`pcdc_compute::names`: `TEMPERATURE`, K; `PORE_PRESSURE`, Pa). Node and element
    /// fields only; another physics must own each of them (the simulation builder
    /// refuses a field without an owner,
    /// [`pcdc_compute::ComputeError::FieldWithoutOwner`]). The joints read them lagged
    /// (the value the field holds when the joints' forces stage runs: at most one step
    /// old), since a fluid physics reads the joints' openings and so runs after them.
    /// Default: none, and then nothing is declared, allocated or gathered.
    fn coupling(&self) -> &[FieldKey] {
        &[]
    }
    /// The traction the joint physics asks for at every Gauss point and step: the
    /// arguments of [`JointModel::traction`] and the values of the
    /// [`JointModel::coupling`] fields at the joint, in `input`; updates the history in
    /// `state`. The default ignores the coupling values and calls
    /// [`JointModel::traction`]; a model that reads coupling fields overrides it.
    fn traction_with(&self, input: &JointInput<'_>, state: &mut [f64]) -> Traction {
        self.traction(input.opening, input.slip, input.h, state)
    }
    /// Largest penalty stiffness per unit area (Pa/m) at characteristic length `h`,
    /// for the stable time step.
    fn max_stiffness(&self, h: f64) -> f64;
    /// Whether the state says the joint is fully broken.
    fn is_broken(&self, state: &[f64]) -> bool;
    /// Damage in [0, 1] for output (1 = broken, a discontinuity contact may act on).
    fn damage(&self, state: &[f64]) -> f64 {
        if self.is_broken(state) {
            1.0
        } else {
            0.0
        }
    }
    /// The model's GPU code (a WGSL function body and its parameters, see
    /// [`WgslJointModel`]). `None` (the default) means CPU only: building a GPU
    /// simulation with such a model is an error that names it
    /// ([`pcdc_compute::ComputeError::NoGpuKernel`]).
    fn wgsl(&self) -> Option<WgslJointModel> {
        None
    }
}

/// What a joint model receives at one Gauss point of one joint in one step, besides its
/// history ([`JointModel::traction_with`]). Built by the joint physics; new inputs may
/// be added (the struct is `#[non_exhaustive]`), so models keep compiling.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct JointInput<'a> {
    /// Opening o (m): positive when the faces separate, negative when they overlap.
    pub opening: f64,
    /// Slip vector (m): the tangential gap of side B relative to side A, global
    /// components, length `D`.
    pub slip: &'a [f64],
    /// |slip| (m), computed once by the joint physics (in 2D the slip's signed length
    /// along the joint's tangent, so no square root; in 3D √(s·s)); a model reads it
    /// instead of taking the norm again.
    pub slip_norm: f64,
    /// Characteristic length h of the joint (m): the mean edge length of its two
    /// elements.
    pub h: f64,
    /// The values of the model's [`JointModel::coupling`] fields at the joint (the same
    /// at every Gauss point), in declaration order, each field's components in a row:
    /// for a node field the mean of the joint's face nodes on both sides (Σ v / (2
    /// NPF): side A's nodes, then side B's, in the joint's node order), for an element
    /// field the mean of its two elements (A, then B). Units those of the field
    /// (temperature K, pore pressure Pa). Empty for a model that declares none.
    pub coupling: &'a [f64],
}

impl<'a> JointInput<'a> {
    /// The inputs of one evaluation (e.g. to call [`JointModel::traction_with`] in a
    /// test).
    /// `slip_norm` is √(slip · slip).
    pub fn new(opening: f64, slip: &'a [f64], h: f64, coupling: &'a [f64]) -> Self {
        JointInput {
            opening,
            slip,
            slip_norm: slip_norm(slip),
            h,
            coupling,
        }
    }
}

/// √(s · s): the length of a slip vector.
#[inline]
pub(crate) fn slip_norm(slip: &[f64]) -> f64 {
    slip.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// A joint model's GPU code, spliced into the joint kernel template (the counterpart of
/// `pcdc_mech::WgslModel` for [`JointModel`]).
///
/// `body` is the body of
///
/// ```text
/// fn (o: Real, slip: JointVec, slip_norm: Real, h: Real, state: ptr<function, JointState>, p: u32) -> JointTraction
/// ```
///
/// with the arguments of [`JointModel::traction_with`]: the opening `o` (m), the slip
/// vector `slip` (m, global components; `JointVec = array<Real, 3>`, components `D..3`
/// are zero), its length `slip_norm` (m, [`JointInput::slip_norm`], computed as on the
/// CPU), the characteristic length `h` (m) and the history `(*state)[k]`
/// (`JointState = array<Real, NSTATE>`, NSTATE ≥ [`JointModel::n_state`]: the largest
/// history of the models composed). It returns
///
/// ```text
/// struct JointTraction { normal: Real, shear: JointVec, damage: Real }
/// ```
///
/// `normal` and `shear` as in [`Traction`] (Pa; shear components `D..3` are ignored) and
/// `damage` = [`JointModel::damage`] of the updated state (≥ 1 marks the joint's faces
/// broken). The body may read `param(p, k)` (= `params[k]`), the constant `D` (2 or 3),
/// and call the library functions `portable_exp(x)` ([`portable_exp`]) and
/// `softening(d)` ([`softening`], eq. 69). A fresh `var t: JointTraction;` is all
/// zeros.
///
/// When a joint model of the physics declares coupling fields
/// ([`JointModel::coupling`]), every model function takes one more parameter,
/// `coupling: JointCoupling` (`array<Real, N>`, N the largest value
/// count of the models), after `state`: the model's values of [`JointInput::coupling`],
/// computed as on the CPU (entries beyond the model's own count are zero). Without
/// coupling the parameter does not exist, so only a model that declares coupling fields
/// may read it.
///
/// `Real` is `f64` or `f32` by precision: write literals without suffix, and wrap them
/// in `Real(..)` where a `var` would otherwise default to f32 (`var x = Real(0.0);`).
/// Keep to + − × ÷, `sqrt`, `abs`, `min`, `max`, `select` (drivers may lack f64
/// `exp`/`pow`/`sin`; use `portable_exp`). To match the CPU to rounding, repeat the
/// CPU's operations in the same order, and compute parameters such as tan φ on the host.
#[derive(Clone, Debug, PartialEq)]
pub struct WgslJointModel {
    /// Identifies the code: models with equal keys must have equal bodies (they share
    /// one WGSL function and differ only in parameters).
    pub key: String,
    /// The WGSL function body.
    pub body: String,
    /// Parameters read with `param(p, k)`.
    pub params: Vec<f64>,
}

/// The intrinsic cohesive zone model (manual 7.4.1, table 9, keyword
/// `classic-intrinsic-cohesive-interface`), built from [`IntrinsicCzmParams`].
///
/// The model is immutable: [`IntrinsicCzm::new`] (or [`IntrinsicCzmParams::build`]) and
/// deserialisation share one check (strengths, energies and penalties positive and
/// finite; 0 ≤ φ < 90°) and compute the derived constants (o_p / h, s_p / h, 1 / o_t,
/// 1 / s_t, tan φ) once; the parameters are read back through accessors only, so the
/// derived constants can never be stale. To change a parameter, copy
/// [`IntrinsicCzm::params`], change the field and build again:
///
/// ```
/// # use pcdc_cohesive::{IntrinsicCzm, IntrinsicCzmParams};
/// let params = IntrinsicCzmParams {
///     friction_deg: 30.0,
///     cohesion: 10e6,
///     tensile_strength: 2e6,
///     gf1: 0.5,
///     gf2: 5.0,
///     penalty_open: 300e9,
///     penalty_shear: 300e9,
///     penalty_overlap: 3000e9,
/// };
/// let czm = params.build()?;
/// let weaker = IntrinsicCzmParams { tensile_strength: 1e6, ..czm.params() }.build()?;
/// assert_eq!(weaker.tensile_strength(), 1e6);
/// # Ok::<(), pcdc_cohesive::CohesiveError>(())
/// ```
///
/// The serialised form is [`IntrinsicCzmParams`] (the same keys, unknown keys rejected).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "IntrinsicCzmParams", into = "IntrinsicCzmParams")]
pub struct IntrinsicCzm {
    params: IntrinsicCzmParams,
    /// ∫₀¹ f(D) dD, cached.
    softening_work: f64,
    /// Constants derived from the parameters, cached so that the per-step path
    /// evaluates one division and no trigonometry.
    derived: Derived,
}

/// Parameters of the intrinsic cohesive zone model [`IntrinsicCzm`] (manual 7.4.1,
/// table 9), by name. SI units; `h` below is a joint's characteristic length (m), the
/// size of the elements it joins.
///
/// [`IntrinsicCzmParams::build`] (or [`IntrinsicCzm::new`]) checks them and builds the
/// model. Deserialisable (serde) with exactly these keys: unknown keys are rejected.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntrinsicCzmParams {
    /// Friction angle φ (degrees, 0 ≤ φ < 90) of the Mohr-Coulomb shear strength
    /// τ_max = f(D) c − σ tan φ (eq. 64).
    pub friction_deg: f64,
    /// Cohesion c (Pa, > 0): the shear strength at zero normal stress (eq. 64); sets the
    /// peak slip s_p = 2 h c / P_tan (eq. 66).
    pub cohesion: f64,
    /// Tensile strength T_s (Pa, > 0): the peak normal traction (eq. 63); sets the peak
    /// opening o_p = 2 h T_s / P_open (eq. 65) and the overlap length
    /// o_overlap = 2 h T_s / P_overlap (eq. 67).
    pub tensile_strength: f64,
    /// Mode I fracture energy G_f1 (N/m = J/m², > 0): the work of the opening softening
    /// branch, which sets the softening opening o_t (eq. 70).
    pub gf1: f64,
    /// Mode II fracture energy G_f2 (N/m = J/m², > 0): the cohesive work of the sliding
    /// softening branch, which sets the softening slip s_t (eq. 71).
    pub gf2: f64,
    /// Normal opening penalty P_open (Pa, > 0; the manual suggests 10 E): the initial
    /// normal stiffness P_open / h (eq. 65).
    pub penalty_open: f64,
    /// Shear penalty P_tan (Pa, > 0; typically 10 E): the initial shear stiffness
    /// P_tan / h (eq. 66).
    pub penalty_shear: f64,
    /// Overlap penalty P_overlap (Pa, > 0; typically 10-100 E): the stiffness
    /// P_overlap / h against interpenetration (eq. 63 for o < 0, eq. 67).
    pub penalty_overlap: f64,
}

impl IntrinsicCzmParams {
    /// Checks the parameters and builds the model ([`IntrinsicCzm::new`]).
    ///
    /// # Errors
    ///
    /// [`CohesiveError::InvalidParameter`] naming the first invalid parameter.
    pub fn build(self) -> Result<IntrinsicCzm, CohesiveError> {
        IntrinsicCzm::new(self)
    }
}

impl TryFrom<IntrinsicCzmParams> for IntrinsicCzm {
    type Error = CohesiveError;

    fn try_from(p: IntrinsicCzmParams) -> Result<Self, CohesiveError> {
        IntrinsicCzm::new(p)
    }
}

impl From<IntrinsicCzm> for IntrinsicCzmParams {
    fn from(m: IntrinsicCzm) -> Self {
        m.params
    }
}

/// Constants of [`IntrinsicCzm`] derived once from its parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Derived {
    /// o_p / h = 2 T_s / P_open.
    op_h: f64,
    /// s_p / h = 2 c / P_tan.
    sp_h: f64,
    /// 1 / o_t.
    inv_ot: f64,
    /// 1 / s_t.
    inv_st: f64,
    /// tan φ.
    tan_phi: f64,
    /// h / o_p = P_open / (2 T_s): with 1/h, the pre-peak curve without a division.
    inv_op_h: f64,
    /// h / s_p = P_tan / (2 c).
    inv_sp_h: f64,
}

impl Derived {
    /// The constants of checked parameters `p`, with `softening_work` = ∫₀¹ f(D) dD
    /// (the same operations as [`IntrinsicCzm::softening_opening`] and
    /// [`IntrinsicCzm::softening_slip`]).
    fn new(p: &IntrinsicCzmParams, softening_work: f64) -> Self {
        Derived {
            op_h: 2.0 * p.tensile_strength / p.penalty_open,
            sp_h: 2.0 * p.cohesion / p.penalty_shear,
            inv_ot: 1.0 / (p.gf1 / (p.tensile_strength * softening_work)),
            inv_st: 1.0 / (p.gf2 / (p.cohesion * softening_work)),
            tan_phi: p.friction_deg.to_radians().tan(),
            inv_op_h: p.penalty_open / (2.0 * p.tensile_strength),
            inv_sp_h: p.penalty_shear / (2.0 * p.cohesion),
        }
    }
}

/// State layout of [`IntrinsicCzm`]: damage D, largest opening, largest slip, failure mode.
pub mod czm_state {
    /// Damage D (eq. 68), never decreasing.
    pub const DAMAGE: usize = 0;
    /// Largest opening reached o_u (m).
    pub const MAX_OPENING: usize = 1;
    /// Largest slip reached s_u (m).
    pub const MAX_SLIP: usize = 2;
    /// [`crate::FailureMode::code`].
    pub const MODE: usize = 3;
    /// Number of state variables.
    pub const LEN: usize = 4;
}

impl IntrinsicCzm {
    /// The model with all parameters checked (strengths, energies and penalties
    /// positive and finite; 0 ≤ φ < 90°) and its derived constants computed.
    ///
    /// # Errors
    ///
    /// [`CohesiveError::InvalidParameter`] naming the first invalid parameter.
    pub fn new(params: IntrinsicCzmParams) -> Result<Self, CohesiveError> {
        let IntrinsicCzmParams {
            friction_deg,
            cohesion,
            tensile_strength,
            gf1,
            gf2,
            penalty_open,
            penalty_shear,
            penalty_overlap,
        } = params;
        let positive: [(&'static str, f64); 7] = [
            ("cohesion c", cohesion),
            ("tensile strength Ts", tensile_strength),
            ("Gf1", gf1),
            ("Gf2", gf2),
            ("normal penalty P_open", penalty_open),
            ("shear penalty P_tan", penalty_shear),
            ("overlap penalty P_overlap", penalty_overlap),
        ];
        for (name, value) in positive {
            if !(value > 0.0 && value.is_finite()) {
                return Err(CohesiveError::InvalidParameter {
                    name,
                    value,
                    reason: "must be positive and finite",
                });
            }
        }
        if !(0.0..90.0).contains(&friction_deg) {
            return Err(CohesiveError::InvalidParameter {
                name: "friction angle",
                value: friction_deg,
                reason: "must lie in [0, 90) degrees",
            });
        }
        let softening_work = softening_integral();
        let derived = Derived::new(&params, softening_work);
        Ok(IntrinsicCzm {
            params,
            softening_work,
            derived,
        })
    }

    /// The parameters the model was built from (a copy: change a field and build again
    /// for a different model).
    pub fn params(&self) -> IntrinsicCzmParams {
        self.params
    }

    /// Friction angle φ (degrees).
    pub fn friction_deg(&self) -> f64 {
        self.params.friction_deg
    }

    /// Cohesion c (Pa).
    pub fn cohesion(&self) -> f64 {
        self.params.cohesion
    }

    /// Tensile strength T_s (Pa).
    pub fn tensile_strength(&self) -> f64 {
        self.params.tensile_strength
    }

    /// Mode I fracture energy G_f1 (N/m).
    pub fn gf1(&self) -> f64 {
        self.params.gf1
    }

    /// Mode II fracture energy G_f2 (N/m).
    pub fn gf2(&self) -> f64 {
        self.params.gf2
    }

    /// Normal opening penalty P_open (Pa).
    pub fn penalty_open(&self) -> f64 {
        self.params.penalty_open
    }

    /// Shear penalty P_tan (Pa).
    pub fn penalty_shear(&self) -> f64 {
        self.params.penalty_shear
    }

    /// Overlap penalty P_overlap (Pa).
    pub fn penalty_overlap(&self) -> f64 {
        self.params.penalty_overlap
    }

    /// Peak opening o_p = 2 h T_s / P_open (eq. 65), m.
    pub fn peak_opening(&self, h: f64) -> f64 {
        2.0 * h * self.params.tensile_strength / self.params.penalty_open
    }

    /// Peak slip s_p = 2 h c / P_tan (eq. 66), m.
    pub fn peak_slip(&self, h: f64) -> f64 {
        2.0 * h * self.params.cohesion / self.params.penalty_shear
    }

    /// Characteristic overlap o_overlap = 2 h T_s / P_overlap (eq. 67), m.
    pub fn overlap_length(&self, h: f64) -> f64 {
        2.0 * h * self.params.tensile_strength / self.params.penalty_overlap
    }

    /// Softening opening o_t (m): the opening beyond o_p at which D reaches 1, chosen so
    /// that the softening branch dissipates G_f1 (eq. 70): G_f1 = T_s o_t ∫₀¹ f.
    pub fn softening_opening(&self) -> f64 {
        self.params.gf1 / (self.params.tensile_strength * self.softening_work)
    }

    /// Softening slip s_t (m): the cohesive part of the softening branch dissipates
    /// G_f2 (eq. 71, the residual friction work W_res comes on top).
    pub fn softening_slip(&self) -> f64 {
        self.params.gf2 / (self.params.cohesion * self.softening_work)
    }
}

/// `[2x − x²]` for x in [0, 1]: the pre-peak hardening curve of eq. 63-64.
#[inline]
fn rising(x: f64) -> f64 {
    x * (2.0 - x)
}

impl IntrinsicCzm {
    /// [`JointModel::traction`] with the slip's length `slip` given (the physics
    /// computes it, [`JointInput::slip_norm`]).
    #[inline(always)]
    fn traction_at(
        &self,
        o: f64,
        slip_vec: &[f64],
        slip: f64,
        h: f64,
        state: &mut [f64],
    ) -> Traction {
        use czm_state::*;
        // One bounds check for the four state values (the joints allocate LEN per point).
        let state = state
            .first_chunk_mut::<LEN>()
            .expect("intrinsic CZM state has LEN values");
        let dv = self.derived;
        // 1/h is the same at every Gauss point of a joint (computed once when inlined);
        // with 1/o_p and 1/s_p as products the undamaged path divides by nothing.
        let inv_h = 1.0 / h;
        let (op, sp) = (dv.op_h * h, dv.sp_h * h);
        let (inv_op, inv_sp) = (dv.inv_op_h * inv_h, dv.inv_sp_h * inv_h);
        // Damage (eq. 68), irreversible. Before the peak in both modes nothing is
        // evaluated beyond comparisons: an undamaged joint pays no exp/pow.
        let mut d = state[DAMAGE];
        let ts = self.params.tensile_strength;
        if d == 0.0 && o <= op && slip <= sp && state[MAX_OPENING] <= op && state[MAX_SLIP] <= sp {
            // Undamaged and never past either peak (the state of intact rock, and a
            // branch that predicts well): the general path below with f = 1 and no
            // unloading branch, the sign of the opening chosen by a select rather than a
            // branch (in compressed rock it flips from point to point). Same operations,
            // same bits.
            // Written only when they grow, so the state of a steadily loaded joint
            // stays clean in the cache (no write-back on the large meshes).
            if o > state[MAX_OPENING] {
                state[MAX_OPENING] = o;
            }
            if slip > state[MAX_SLIP] {
                state[MAX_SLIP] = slip;
            }
            let overlap = self.params.penalty_overlap * o * inv_h;
            let rise = rising(o * inv_op) * ts;
            let normal = if o < 0.0 { overlap } else { rise };
            let strength = (-normal * dv.tan_phi + self.params.cohesion).max(0.0);
            let scale = (2.0 - slip * inv_sp) * strength * inv_sp;
            let mut sv = [0.0; 3];
            for (k, v) in slip_vec.iter().enumerate() {
                sv[k] = scale * v;
            }
            return Traction { normal, shear: sv };
        }
        if o > op || slip > sp {
            let dn = ((o - op) * dv.inv_ot).max(0.0);
            let ds = ((slip - sp) * dv.inv_st).max(0.0);
            let trial = (dn * dn + ds * ds).sqrt().min(1.0);
            if trial > d {
                d = trial;
                if d >= 1.0 && state[MODE] == 0.0 {
                    let mode = if ds * ds < 0.1 * dn * dn {
                        FailureMode::Tensile
                    } else if dn * dn < 0.1 * ds * ds {
                        FailureMode::Shear
                    } else {
                        FailureMode::Mixed
                    };
                    state[MODE] = mode.code();
                }
                state[DAMAGE] = d;
            }
        }
        // A broken joint transfers nothing: its faces interact through contact alone
        // (an overlap penalty on faces that have separated and moved apart would push
        // them with the joint's full stiffness from wherever they are).
        if d >= 1.0 {
            return Traction::default();
        }
        let f = if d > 0.0 { softening(d) } else { 1.0 };
        let ou = state[MAX_OPENING].max(o);
        let su = state[MAX_SLIP].max(slip);
        state[MAX_OPENING] = ou;
        state[MAX_SLIP] = su;
        // Normal traction (eq. 63, unloading eq. 72); 2 T_s / o_overlap = P_overlap / h.
        let normal = if o < 0.0 {
            self.params.penalty_overlap * o * inv_h
        } else if ou > op && o < ou {
            f * ts * o / ou
        } else if o <= op {
            rising(o * inv_op) * f * ts
        } else {
            f * ts
        };
        // Shear strength: Mohr-Coulomb with the softened cohesion (eq. 64).
        let strength = (-normal * dv.tan_phi + f * self.params.cohesion).max(0.0);
        // The shear traction is (τ / |s|) s; τ / |s| per branch: unloading τ = strength
        // |s| / s_u, rising τ = x (2 − x) strength with x = |s| / s_p (so τ / |s| = (2 − x)
        // strength / s_p, no division, and finite at |s| = 0), softened τ = strength.
        let scale = if su > sp && slip < su {
            strength / su
        } else if slip <= sp {
            (2.0 - slip * inv_sp) * strength * inv_sp
        } else {
            strength / slip
        };
        let mut sv = [0.0; 3];
        for (k, v) in slip_vec.iter().enumerate() {
            sv[k] = scale * v;
        }
        Traction { normal, shear: sv }
    }
}

impl JointModel for IntrinsicCzm {
    fn name(&self) -> &str {
        "classic-intrinsic-cohesive-interface"
    }

    fn n_state(&self) -> usize {
        czm_state::LEN
    }

    fn traction(&self, o: f64, slip_vec: &[f64], h: f64, state: &mut [f64]) -> Traction {
        self.traction_at(o, slip_vec, slip_norm(slip_vec), h, state)
    }

    // Inlined into the joint loop, which calls the built-in models by type.
    #[inline(always)]
    fn traction_with(&self, input: &JointInput<'_>, state: &mut [f64]) -> Traction {
        self.traction_at(input.opening, input.slip, input.slip_norm, input.h, state)
    }

    fn max_stiffness(&self, h: f64) -> f64 {
        // Initial slopes: 2 T_s / o_p = P_open / h, 2 T_s / o_overlap = P_overlap / h.
        self.params
            .penalty_open
            .max(self.params.penalty_shear)
            .max(self.params.penalty_overlap)
            / h
    }

    fn is_broken(&self, state: &[f64]) -> bool {
        state[czm_state::DAMAGE] >= 1.0
    }

    #[inline(always)]
    fn damage(&self, state: &[f64]) -> f64 {
        state[czm_state::DAMAGE]
    }

    /// Parameters: o_p/h, s_p/h, 1/o_t, 1/s_t, tan φ, T_s (Pa), c (Pa), P_overlap (Pa),
    /// h/o_p, h/s_p.
    fn wgsl(&self) -> Option<WgslJointModel> {
        let dv = self.derived;
        Some(WgslJointModel {
            key: "intrinsic_czm".into(),
            body: include_str!("shaders/intrinsic_czm.wgsl").into(),
            params: vec![
                dv.op_h,
                dv.sp_h,
                dv.inv_ot,
                dv.inv_st,
                dv.tan_phi,
                self.params.tensile_strength,
                self.params.cohesion,
                self.params.penalty_overlap,
                dv.inv_op_h,
                dv.inv_sp_h,
            ],
        })
    }
}

/// A pre-existing fracture (Mohr-Coulomb joint): no tensile strength, a normal penalty
/// against overlap (σ = P_n o / h for o < 0, as the cohesive model's overlap branch),
/// and elastic-perfectly plastic shear with the strength τ_max = c_r − σ tan φ (c_r the
/// residual cohesion, often zero). Shear acts only while the faces touch. The state
/// holds the plastic slip vector (global components), so reversed sliding unloads
/// elastically; large rotations of a sliding joint are not followed by that vector.
///
/// The joint is immutable: [`MohrCoulombJoint::new`] (or
/// [`MohrCoulombJointParams::build`]) and deserialisation share one check, and the
/// parameters are read back through accessors; the serialised form is
/// [`MohrCoulombJointParams`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "MohrCoulombJointParams", into = "MohrCoulombJointParams")]
pub struct MohrCoulombJoint {
    friction_deg: f64,
    cohesion: f64,
    penalty_normal: f64,
    penalty_shear: f64,
    /// tan φ, cached: no trigonometry per evaluation.
    tan_phi: f64,
}

/// Parameters of a [`MohrCoulombJoint`] (a pre-existing fracture, manual keyword
/// `joint-mohr-coulomb`), by name. SI units; `h` is the joint's characteristic length
/// (m). Deserialisable (serde) with exactly these keys: unknown keys are rejected.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MohrCoulombJointParams {
    /// Friction angle φ (degrees, 0 ≤ φ < 90) of the shear strength τ_max = c_r − σ tan φ
    /// (the Mohr-Coulomb criterion of eq. 64 without softening).
    pub friction_deg: f64,
    /// Residual cohesion c_r (Pa, ≥ 0, often 0).
    pub cohesion: f64,
    /// Normal penalty P_n (Pa, > 0): the stiffness P_n / h against overlap (as the
    /// overlap branch of eq. 63).
    pub penalty_normal: f64,
    /// Shear penalty P_t (Pa, > 0): the elastic shear stiffness P_t / h before sliding.
    pub penalty_shear: f64,
}

impl MohrCoulombJointParams {
    /// Checks the parameters and builds the joint ([`MohrCoulombJoint::new`]).
    ///
    /// # Errors
    ///
    /// [`CohesiveError::InvalidParameter`] naming the first invalid parameter.
    pub fn build(self) -> Result<MohrCoulombJoint, CohesiveError> {
        MohrCoulombJoint::new(self)
    }
}

impl TryFrom<MohrCoulombJointParams> for MohrCoulombJoint {
    type Error = CohesiveError;

    fn try_from(p: MohrCoulombJointParams) -> Result<Self, CohesiveError> {
        MohrCoulombJoint::new(p)
    }
}

impl From<MohrCoulombJoint> for MohrCoulombJointParams {
    fn from(m: MohrCoulombJoint) -> Self {
        m.params()
    }
}

impl MohrCoulombJoint {
    /// The joint with its parameters checked (0 ≤ φ < 90°, c_r ≥ 0 and finite,
    /// penalties positive and finite).
    ///
    /// # Errors
    ///
    /// [`CohesiveError::InvalidParameter`] naming the first invalid parameter.
    pub fn new(params: MohrCoulombJointParams) -> Result<Self, CohesiveError> {
        let MohrCoulombJointParams {
            friction_deg,
            cohesion,
            penalty_normal,
            penalty_shear,
        } = params;
        if !(0.0..90.0).contains(&friction_deg) {
            return Err(CohesiveError::InvalidParameter {
                name: "friction angle",
                value: friction_deg,
                reason: "must lie in [0, 90) degrees",
            });
        }
        if !(cohesion >= 0.0 && cohesion.is_finite()) {
            return Err(CohesiveError::InvalidParameter {
                name: "residual cohesion",
                value: cohesion,
                reason: "must be non-negative and finite",
            });
        }
        for (name, value) in [
            ("normal penalty P_n", penalty_normal),
            ("shear penalty P_t", penalty_shear),
        ] {
            if !(value > 0.0 && value.is_finite()) {
                return Err(CohesiveError::InvalidParameter {
                    name,
                    value,
                    reason: "must be positive and finite",
                });
            }
        }
        Ok(MohrCoulombJoint {
            friction_deg,
            cohesion,
            penalty_normal,
            penalty_shear,
            tan_phi: friction_deg.to_radians().tan(),
        })
    }

    /// The parameters the joint was built from.
    pub fn params(&self) -> MohrCoulombJointParams {
        MohrCoulombJointParams {
            friction_deg: self.friction_deg,
            cohesion: self.cohesion,
            penalty_normal: self.penalty_normal,
            penalty_shear: self.penalty_shear,
        }
    }

    /// Friction angle φ (degrees).
    pub fn friction_deg(&self) -> f64 {
        self.friction_deg
    }

    /// Residual cohesion c_r (Pa).
    pub fn cohesion(&self) -> f64 {
        self.cohesion
    }

    /// Normal (overlap) penalty P_n (Pa).
    pub fn penalty_normal(&self) -> f64 {
        self.penalty_normal
    }

    /// Shear penalty P_t (Pa).
    pub fn penalty_shear(&self) -> f64 {
        self.penalty_shear
    }
}

impl JointModel for MohrCoulombJoint {
    fn name(&self) -> &str {
        "joint-mohr-coulomb"
    }

    fn n_state(&self) -> usize {
        3
    }

    // Inlined into the joint loop, which calls the built-in models by type.
    #[inline(always)]
    fn traction(&self, o: f64, slip: &[f64], h: f64, state: &mut [f64]) -> Traction {
        let mut t = Traction::default();
        if o >= 0.0 {
            // Open: no traction; the elastic slip restarts from the current slip.
            for (k, v) in slip.iter().enumerate() {
                state[k] = *v;
            }
            return t;
        }
        t.normal = self.penalty_normal * o / h;
        let strength = (self.cohesion - t.normal * self.tan_phi).max(0.0);
        let kt = self.penalty_shear / h;
        let mut trial = [0.0; 3];
        for (k, v) in slip.iter().enumerate() {
            trial[k] = kt * (v - state[k]);
        }
        let mag = trial.iter().map(|v| v * v).sum::<f64>().sqrt();
        if mag > strength {
            // Plastic sliding: return to the yield surface, move the plastic slip.
            let scale = strength / mag;
            for k in 0..slip.len() {
                trial[k] *= scale;
                state[k] = slip[k] - trial[k] / kt;
            }
        }
        t.shear = trial;
        t
    }

    fn max_stiffness(&self, h: f64) -> f64 {
        self.penalty_normal.max(self.penalty_shear) / h
    }

    fn is_broken(&self, _state: &[f64]) -> bool {
        true
    }

    /// Parameters: P_n (Pa), P_t (Pa), c_r (Pa), tan φ.
    fn wgsl(&self) -> Option<WgslJointModel> {
        Some(WgslJointModel {
            key: "joint_mohr_coulomb".into(),
            body: include_str!("shaders/mohr_coulomb_joint.wgsl").into(),
            params: vec![
                self.penalty_normal,
                self.penalty_shear,
                self.cohesion,
                self.tan_phi,
            ],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const H: f64 = 0.002;

    /// UCS quick-start joints (VALIDATION.md scene 8) with E = 30 GPa.
    const CZM: IntrinsicCzmParams = IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 10e6,
        tensile_strength: 2e6,
        gf1: 0.5,
        gf2: 5.0,
        penalty_open: 300e9,
        penalty_shear: 300e9,
        penalty_overlap: 3000e9,
    };

    fn czm() -> IntrinsicCzm {
        CZM.build().unwrap()
    }

    /// Trapezoidal work ∫ σ do along a monotonic path from `a` to `b` in `n` steps.
    fn work_normal(m: &IntrinsicCzm, state: &mut [f64], a: f64, b: f64, n: usize) -> f64 {
        let mut w = 0.0;
        let mut prev = m.traction(a, &[0.0], H, state).normal;
        for i in 1..=n {
            let o = a + (b - a) * i as f64 / n as f64;
            let t = m.traction(o, &[0.0], H, state).normal;
            w += 0.5 * (prev + t) * (b - a) / n as f64;
            prev = t;
        }
        w
    }

    #[test]
    fn portable_exp_matches_libm() {
        let mut worst = 0.0f64;
        for i in 0..=200_000 {
            let x = -708.0 + 1417.0 * i as f64 / 200_000.0;
            let (a, b) = (portable_exp(x), x.exp());
            worst = worst.max(((a - b) / b).abs());
        }
        for x in [0.0, 1e-300, -1e-300, 0.5, -0.5, 1.0, -3.3] {
            let (a, b) = (portable_exp(x), f64::exp(x));
            worst = worst.max(((a - b) / b).abs());
        }
        assert_eq!(portable_exp(0.0), 1.0);
        assert!(worst < 4e-16, "largest relative error {worst:e}");
    }

    #[test]
    fn softening_agrees_with_the_libm_formula() {
        let (a, b, c) = (SOFTENING_A, SOFTENING_B, SOFTENING_C);
        for i in 1..1000 {
            let d = i as f64 / 1000.0;
            let z = (a + b - 1.0) / (a + b) * (d * (a + c * b) / ((a + b) * (1.0 - a - b))).exp();
            let libm = (1.0 - z) * (a * (1.0 - d) + b * (1.0 - d).powf(c));
            let f = softening(d);
            assert!((f - libm).abs() <= 2e-15, "f({d}) = {f} vs {libm}");
        }
    }

    #[test]
    fn softening_function_ends() {
        assert!((softening(0.0) - 1.0).abs() < 1e-15);
        assert_eq!(softening(1.0), 0.0);
        let mut prev = 1.0;
        for i in 1..=100 {
            let f = softening(i as f64 / 100.0);
            assert!(f <= prev + 1e-15, "f must not increase");
            prev = f;
        }
        let i = softening_integral();
        assert!(i > 0.0 && i < 1.0, "{i}");
    }

    #[test]
    fn mode_one_dissipates_gf1() {
        let m = czm();
        let mut s = [0.0; 4];
        let op = m.peak_opening(H);
        let _ = work_normal(&m, &mut s, 0.0, op, 1000);
        let soft = work_normal(&m, &mut s, op, op + 1.2 * m.softening_opening(), 200_000);
        assert!(
            (soft - m.gf1()).abs() < 0.02 * m.gf1(),
            "softening work {soft} vs Gf1 {}",
            m.gf1()
        );
        assert!(m.is_broken(&s));
        assert_eq!(
            FailureMode::from_code(s[czm_state::MODE]),
            FailureMode::Tensile
        );
    }

    #[test]
    fn mode_two_dissipates_gf2_plus_friction() {
        let m = czm();
        let sigma_n = -1e6; // compression held by an overlap
        let o = sigma_n / (2.0 * m.tensile_strength()) * m.overlap_length(H);
        let mut s = [0.0; 4];
        let (sp, st) = (m.peak_slip(H), m.softening_slip());
        let n = 200_000;
        let (mut w, mut prev) = (0.0, m.traction(o, &[sp], H, &mut s).shear_magnitude());
        for i in 1..=n {
            let slip = sp + 1.2 * st * i as f64 / n as f64;
            let t = m.traction(o, &[slip], H, &mut s).shear_magnitude();
            w += 0.5 * (prev + t) * 1.2 * st / n as f64;
            prev = t;
        }
        // Residual friction acts until D = 1 at slip s_p + s_t; past the break the joint
        // transfers nothing (contact's friction takes over).
        let friction = -sigma_n * m.friction_deg().to_radians().tan() * st;
        let expect = m.gf2() + friction;
        assert!(
            (w - expect).abs() < 0.02 * expect,
            "work {w} vs Gf2 + friction {expect}"
        );
        assert_eq!(
            FailureMode::from_code(s[czm_state::MODE]),
            FailureMode::Shear
        );
    }

    #[test]
    fn traction_continuous_at_the_peak() {
        let m = czm();
        let op = m.peak_opening(H);
        let below = m
            .traction(op * (1.0 - 1e-9), &[0.0], H, &mut [0.0; 4])
            .normal;
        let above = m
            .traction(op * (1.0 + 1e-9), &[0.0], H, &mut [0.0; 4])
            .normal;
        assert!((below - m.tensile_strength()).abs() < 1e-6 * m.tensile_strength());
        assert!((above - m.tensile_strength()).abs() < 1e-6 * m.tensile_strength());
        let sp = m.peak_slip(H);
        let b = m
            .traction(0.0, &[sp * (1.0 - 1e-9)], H, &mut [0.0; 4])
            .shear_magnitude();
        let a = m
            .traction(0.0, &[sp * (1.0 + 1e-9)], H, &mut [0.0; 4])
            .shear_magnitude();
        assert!(
            (a - b).abs() < 1e-6 * m.cohesion() && (a - m.cohesion()).abs() < 1e-6 * m.cohesion()
        );
    }

    #[test]
    fn invalid_parameters() {
        let bad = |p: IntrinsicCzmParams| p.build().unwrap_err().to_string();
        assert!(bad(IntrinsicCzmParams {
            tensile_strength: -2e6,
            ..CZM
        })
        .contains("tensile strength Ts = -2000000"));
        assert!(bad(IntrinsicCzmParams {
            friction_deg: 95.0,
            ..CZM
        })
        .contains("friction angle = 95"));
        assert!(bad(IntrinsicCzmParams { gf1: 0.0, ..CZM }).contains("Gf1 = 0"));
        assert!(bad(IntrinsicCzmParams {
            penalty_open: f64::NAN,
            ..CZM
        })
        .contains("P_open = NaN"));
    }

    /// The stale-cache case: a model rebuilt from its parameters with T_s changed is the
    /// model built directly with that T_s (derived constants included), and its peak
    /// traction is the new T_s. (With a mutable T_s, the peak opening cached at `new`
    /// kept the old T_s: a normal traction of 3.75 MPa where 2.44 MPa was right.)
    #[test]
    fn changing_a_parameter_rebuilds_the_derived_constants() {
        let base = czm();
        let ts = 1.3e6;
        let changed = IntrinsicCzmParams {
            tensile_strength: ts,
            ..base.params()
        }
        .build()
        .unwrap();
        let direct = IntrinsicCzmParams {
            friction_deg: 30.0,
            cohesion: 10e6,
            tensile_strength: ts,
            gf1: 0.5,
            gf2: 5.0,
            penalty_open: 300e9,
            penalty_shear: 300e9,
            penalty_overlap: 3000e9,
        }
        .build()
        .unwrap();
        assert_eq!(changed, direct);
        assert_ne!(changed, base);
        assert_eq!(changed.params(), direct.params());
        assert_eq!(changed.wgsl(), direct.wgsl());
        assert_eq!(changed.tensile_strength(), ts);
        // Past the new peak opening the joint softens from the new T_s, whatever the
        // model it was derived from.
        let o = changed.peak_opening(H);
        let t = changed.traction(o, &[0.0], H, &mut [0.0; 4]).normal;
        assert!((t - ts).abs() <= 1e-9 * ts, "peak traction {t} vs T_s {ts}");
        let t_old = base.traction(o, &[0.0], H, &mut [0.0; 4]).normal;
        assert!((t_old - t).abs() > 0.1 * ts, "{t_old} vs {t}");
    }

    /// Serialisation goes through the parameter struct and back through the check.
    #[test]
    fn serde_round_trip_and_checked_deserialisation() {
        let m = czm();
        let json = serde_json::to_string(&m).unwrap();
        let back: IntrinsicCzm = serde_json::from_str(&json).unwrap();
        assert_eq!(back, m);
        let params: IntrinsicCzmParams = serde_json::from_str(&json).unwrap();
        assert_eq!(params, CZM);
        let bad = json.replace("\"gf2\":5.0", "\"gf2\":-5.0");
        assert_ne!(bad, json);
        let err = serde_json::from_str::<IntrinsicCzm>(&bad).unwrap_err();
        assert!(err.to_string().contains("Gf2 = -5"), "{err}");

        let mc = mc();
        let json = serde_json::to_string(&mc).unwrap();
        assert_eq!(serde_json::from_str::<MohrCoulombJoint>(&json).unwrap(), mc);
        assert_eq!(
            serde_json::from_str::<MohrCoulombJointParams>(&json).unwrap(),
            mc.params()
        );
    }

    fn mc() -> MohrCoulombJoint {
        MohrCoulombJointParams {
            friction_deg: 30.0,
            cohesion: 0.0,
            penalty_normal: 3e12,
            penalty_shear: 3e11,
        }
        .build()
        .unwrap()
    }

    #[test]
    fn mohr_coulomb_joint_has_no_tension_and_slides_at_the_friction_limit() {
        let m = mc();
        let mut s = [0.0; 3];
        assert_eq!(
            m.traction(1e-6, &[1e-6, 0.0], H, &mut s),
            Traction::default()
        );
        let o = -1e-9;
        let sigma = m.penalty_normal() * o / H;
        let t = m.traction(o, &[1e-3, 0.0], H, &mut s);
        let limit = -sigma * 30f64.to_radians().tan();
        assert!((t.normal - sigma).abs() < 1e-9 * sigma.abs());
        assert!(
            (t.shear_magnitude() - limit).abs() < 1e-9 * limit,
            "{t:?} vs {limit}"
        );
        // Reversing the slip a little unloads elastically.
        let back = m.traction(o, &[1e-3 - 1e-12, 0.0], H, &mut s);
        assert!(back.shear_magnitude() < limit);
        assert!(MohrCoulombJointParams {
            cohesion: -1.0,
            ..m.params()
        }
        .build()
        .is_err());
    }

    proptest! {
        /// Friction never exceeds c_r − σ tan φ, and acts along the slip.
        #[test]
        fn mohr_coulomb_bounded(path in proptest::collection::vec((-2.0f64..0.5, -3.0f64..3.0, -3.0f64..3.0), 1..40)) {
            let m = MohrCoulombJointParams { friction_deg: 35.0, cohesion: 1e5, penalty_normal: 3e12, penalty_shear: 3e11 }.build().unwrap();
            let mut s = [0.0; 3];
            for (o, a, b) in path {
                let t = m.traction(o * 1e-9, &[a * 1e-8, b * 1e-8], H, &mut s);
                let strength = (m.cohesion() - t.normal * 35f64.to_radians().tan()).max(0.0);
                prop_assert!(t.shear_magnitude() <= strength * (1.0 + 1e-12) + 1e-9);
                prop_assert!(t.normal <= 0.0);
            }
        }

        /// D never decreases along an arbitrary path, and a broken joint carries no
        /// force at all (no tension, no overlap penalty, no friction), whatever the
        /// opening and slip after the break.
        #[test]
        fn damage_monotone_and_no_tension_after_break(path in proptest::collection::vec((-1.0f64..4.0, 0.0f64..4.0), 1..60)) {
            let m = czm();
            let (op, sp) = (m.peak_opening(H), m.peak_slip(H));
            let scale_o = op + m.softening_opening();
            let scale_s = sp + m.softening_slip();
            let mut s = [0.0; 4];
            let mut d_prev = 0.0;
            for (a, b) in path {
                let t = m.traction(a * scale_o, &[b * scale_s], H, &mut s);
                prop_assert!(s[czm_state::DAMAGE] >= d_prev);
                d_prev = s[czm_state::DAMAGE];
                prop_assert!(t.shear_magnitude() >= 0.0 && t.normal.is_finite());
                if m.is_broken(&s) {
                    prop_assert!(t.normal == 0.0 && t.shear_magnitude() == 0.0,
                        "broken joint transfers {:?}", t);
                }
            }
        }

        /// The response depends on |slip| only: +s and -s give the same tractions.
        #[test]
        fn symmetric_in_slip(o in -1.0f64..3.0, sl in 0.0f64..3.0) {
            let m = czm();
            let (o, sl) = (o * m.peak_opening(H), sl * m.peak_slip(H));
            let a = m.traction(o, &[sl], H, &mut [0.0; 4]);
            let b = m.traction(o, &[-sl], H, &mut [0.0; 4]);
            prop_assert_eq!(a.normal, b.normal);
            prop_assert_eq!(a.shear_magnitude(), b.shear_magnitude());
            prop_assert_eq!(a.shear[0], -b.shear[0]);
        }

        /// After softening to o_u, unloading follows the secant σ(o_u) o / o_u.
        #[test]
        fn unloading_along_the_secant(k in 0.05f64..0.9, back in 0.0f64..1.0) {
            let m = czm();
            let mut s = [0.0; 4];
            let ou = m.peak_opening(H) + k * m.softening_opening();
            let at_u = m.traction(ou, &[0.0], H, &mut s).normal;
            let o = back * ou;
            let t = m.traction(o, &[0.0], H, &mut s).normal;
            prop_assert!((t - at_u * o / ou).abs() <= 1e-9 * m.tensile_strength());
            // Reloading to o_u gives back the same traction (no further damage).
            let again = m.traction(ou, &[0.0], H, &mut s).normal;
            prop_assert!((again - at_u).abs() <= 1e-9 * m.tensile_strength());
        }
    }
}
