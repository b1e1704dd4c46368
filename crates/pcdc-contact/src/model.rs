//! The `ContactModel` plugin trait and the built-in `contact-m-c` law (manual 7.3.2-7.3.3,
//! eq. 59-61, table 8).
//!
//! The contact physics computes, per element pair, the normal force of Munjiza's
//! potential with the model's normal penalty (eq. 52-58); it turns it into a trial
//! normal stress σ_try = |F_n| / h over the contact length h (per unit thickness in 2D;
//! σ_try = |F_n| / h² in 3D) and the relative tangential velocity into a slip increment
//! Δδ = v_t Δt (in 3D Δδ = |v_t| Δt ≥ 0 along the current sliding direction, so the
//! accumulated slip is a scalar along that direction; see the physics docs). The model
//! returns the normal and shear contact stresses and updates the pair's history.

use std::fmt::Debug;

use pcdc_compute::ComputeError;

/// Contact stresses returned by a [`ContactModel`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactStress {
    /// Normal contact stress σ_n (Pa, compressive contact positive, ≥ 0).
    pub normal: f64,
    /// Shear stress τ along the contact tangent (Pa), signed: it opposes the
    /// accumulated slip.
    pub shear: f64,
}

/// A per-pair contact law.
pub trait ContactModel: Send + Sync + Debug {
    /// Name for reports.
    fn name(&self) -> &str;
    /// Normal penalty P_n of the contact potential (Pa).
    fn normal_penalty(&self) -> f64;
    /// Largest tangential (shear) penalty P_t of the law (Pa; τ = P_t δ_s / h before
    /// sliding), used with the normal penalty to bound the stable time step; default 0
    /// (no tangential spring).
    fn shear_penalty(&self) -> f64 {
        0.0
    }
    /// History values per pair (carried across broad-phase rebuilds and snapshots).
    fn n_state(&self) -> usize {
        0
    }
    /// Checks the parameters; errors name the parameter and value.
    fn check(&self) -> Result<(), ComputeError> {
        Ok(())
    }
    /// Checks the law against the mesh (e.g. per-element data of the right length).
    fn check_mesh(&self, n_elements: usize) -> Result<(), ComputeError> {
        let _ = n_elements;
        Ok(())
    }
    /// Contact stresses of a touching pair from the trial normal stress `s_try` (Pa,
    /// positive), the tangential slip increment `dslip` over the step (m; signed along
    /// the tangent in 2D, non-negative along the current sliding direction in 3D) and the
    /// contact length `h` (m); `state` holds [`ContactModel::n_state`] values.
    fn update(&self, s_try: f64, dslip: f64, h: f64, state: &mut [f64]) -> ContactStress;
    /// Normal penalty for the pair of elements `c` (contactor) and `t` (target) (Pa);
    /// default [`ContactModel::normal_penalty`]. Laws whose parameters vary by element
    /// (such as [`SurfaceContact`]) override it, with `normal_penalty` the largest value
    /// (it bounds the stable time step).
    fn pair_penalty(&self, c: usize, t: usize) -> f64 {
        let _ = (c, t);
        self.normal_penalty()
    }
    /// [`ContactModel::update`] for the pair of elements `c` and `t`; default `update`.
    fn update_pair(
        &self,
        c: usize,
        t: usize,
        s_try: f64,
        dslip: f64,
        h: f64,
        state: &mut [f64],
    ) -> ContactStress {
        let _ = (c, t);
        self.update(s_try, dslip, h, state)
    }
    /// The pair has separated: reset its history (default: zero; the GPU kernel always
    /// zeroes it).
    fn separate(&self, state: &mut [f64]) {
        state.fill(0.0);
    }
    /// The law's GPU code (see [`WgslContactModel`]). `None` (the default) means CPU
    /// only: building a GPU simulation with such a law is an error that names it
    /// ([`pcdc_compute::ComputeError::NoGpuKernel`]).
    fn wgsl(&self) -> Option<WgslContactModel> {
        None
    }
}

/// A contact law's GPU code, spliced into the contact kernel template (the counterpart
/// of [`ContactModel::update`]).
///
/// `body` is the body of
///
/// ```text
/// fn (s_try: Real, dslip: Real, h: Real, state: ptr<function, ContactState>, p: u32) -> ContactStress
/// ```
///
/// with `struct ContactStress { normal: Real, shear: Real }`, `ContactState` an
/// `array<Real, NSTATE>` of the pair history ([`ContactModel::n_state`], at least one
/// entry), and the parameters read with `param(p, k)` (k-th entry of `params`). Keep
/// to + − × ÷, sqrt, abs, min, max (drivers may lack f64 `exp`/`pow`); to match the CPU
/// to rounding, repeat the CPU arithmetic in the same order.
#[derive(Clone, Debug, PartialEq)]
pub struct WgslContactModel {
    /// Identifies the code: laws with equal keys must have equal bodies.
    pub key: String,
    /// The WGSL function body.
    pub body: String,
    /// Parameters read with `param(p, k)`.
    pub params: Vec<f64>,
    /// Body of `fn (c: u32, t: u32, p: u32) -> Real`, the pair's normal penalty (Pa), for
    /// laws that override [`ContactModel::pair_penalty`]; `None`: the constant
    /// [`ContactModel::normal_penalty`].
    pub pair_penalty: Option<String>,
}

/// x^b for the damping curve: an integer exponent (the usual case, and the only one the
/// GPU kernel takes) by repeated multiplication, the same operations as the WGSL law.
fn damping_power(x: f64, b: f64) -> f64 {
    if b.fract() == 0.0 && (1.0..=64.0).contains(&b) {
        let mut w = 1.0;
        for _ in 0..b as u32 {
            w *= x;
        }
        w
    } else {
        x.powf(b)
    }
}

/// Coulomb friction with a shear penalty (manual eq. 59-60, eq. 59 corrected).
///
/// **Correction of eq. 59.** The manual prints τ = P_t h |δ_s|, which is not a stress
/// (Pa·m² with P_t in Pa): the tangential stiffness would then scale with h² in whatever
/// length unit the user picked, and the same scene in metres and in millimetres would
/// slide differently. We use the dimensionally consistent
///
/// τ = P_t |δ_s| / h  (until τ reaches tan φ σ_n, eq. 60),
///
/// the same form as the joints' shear penalty (eq. 64, slope 2c/s_p = P_tan/h): P_t is a
/// stress (Pa), comparable to the normal penalty, and δ_s / h a tangential strain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Friction {
    /// Friction angle φ (degrees).
    pub angle_deg: f64,
    /// Shear penalty P_t (Pa): the shear stress grows as P_t |δ_s| / h until it reaches
    /// tan φ σ_n (h the contact length, δ_s the accumulated slip). The manual's default
    /// for the normal penalty, 10 E, is a sensible value here too.
    pub penalty: f64,
}

impl MohrCoulombContact {
    /// [`ContactModel::update`] with tan φ given (`tan_phi`, unused without friction).
    #[inline]
    fn update_with(
        &self,
        tan_phi: f64,
        s_try: f64,
        dslip: f64,
        h: f64,
        state: &mut [f64],
    ) -> ContactStress {
        let normal = match self.damping {
            None => s_try,
            Some(d) => {
                if s_try >= state[1] {
                    state[1] = s_try;
                    state[2] = s_try.min(d.transition);
                    state[2]
                } else {
                    state[2] * damping_power(s_try / state[1], d.exponent)
                }
            }
        };
        let mut shear = 0.0;
        if let Some(fr) = self.friction {
            // eq. 59 (corrected, see [`Friction`]): τ = P_t |δ_s| / h up to tan φ σ_n;
            // eq. 60: δ_s reset to the limit.
            state[0] += dslip;
            let kt = fr.penalty / h;
            let limit = tan_phi * normal;
            let mut t = kt * state[0].abs();
            if t > limit {
                t = limit;
                state[0] = state[0].signum() * limit / kt;
            }
            shear = -state[0].signum() * t;
        }
        ContactStress { normal, shear }
    }
}

/// The built-in law as the contact physics runs it: [`MohrCoulombContact`] with tan φ
/// taken once, not per touching pair (the same value, so the same bits). Its `Debug` is
/// the law's own, so snapshot fingerprints do not change.
pub(crate) struct CachedMohrCoulomb {
    law: MohrCoulombContact,
    tan_phi: f64,
}

impl CachedMohrCoulomb {
    pub(crate) fn new(law: MohrCoulombContact) -> Self {
        let tan_phi = law.friction.map_or(0.0, |f| f.angle_deg.to_radians().tan());
        CachedMohrCoulomb { law, tan_phi }
    }
}

impl Debug for CachedMohrCoulomb {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.law.fmt(f)
    }
}

impl ContactModel for CachedMohrCoulomb {
    fn name(&self) -> &str {
        self.law.name()
    }
    fn normal_penalty(&self) -> f64 {
        self.law.normal_penalty()
    }
    fn shear_penalty(&self) -> f64 {
        self.law.shear_penalty()
    }
    fn n_state(&self) -> usize {
        self.law.n_state()
    }
    fn check(&self) -> Result<(), ComputeError> {
        self.law.check()
    }
    fn update(&self, s_try: f64, dslip: f64, h: f64, state: &mut [f64]) -> ContactStress {
        self.law.update_with(self.tan_phi, s_try, dslip, h, state)
    }
    fn wgsl(&self) -> Option<WgslContactModel> {
        self.law.wgsl()
    }
}

/// Contact damping after An and Tannant (2007), manual eq. 61.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactDamping {
    /// Damping transition stress T (Pa): the loading normal stress is capped at T.
    pub transition: f64,
    /// Damping exponent b (≥ 1): unloading follows σ_max (o_n / o_n,max)^b.
    pub exponent: f64,
}

/// The built-in law `contact-m-c` (table 8): normal penalty, optional Coulomb friction
/// with shear penalty (eq. 59-60) and optional damping (eq. 61).
///
/// History per pair: accumulated slip δ_s (m); with damping also the largest trial
/// normal stress σ_try,max (Pa) and the normal stress held there σ_max (Pa). Without
/// damping the history is δ_s alone ([`ContactModel::n_state`] 1 instead of 3), which
/// keeps the contact fields of a frictional scene a third of the size.
///
/// Damping: the overlap is proportional to the trial stress under the penalty law, so
/// o_n / o_n,max = σ_try / σ_try,max. Loading (σ_try at its maximum so far):
/// σ = min(σ_try, T), remembered as σ_max. Unloading or reloading below the maximum:
/// σ = σ_max (σ_try / σ_try,max)^b. With b = 1 and T above every stress this is the
/// undamped law; b > 1 dissipates energy in each contact cycle. The manual writes T in
/// the unloading branch; starting the power curve from the stress actually reached keeps
/// the force continuous when σ_try stays below T (the two agree once the cap is reached).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MohrCoulombContact {
    /// Normal penalty P_n (Pa); the manual's default is 10 E of the elements.
    pub normal_penalty: f64,
    /// Coulomb friction, if any.
    pub friction: Option<Friction>,
    /// Contact damping, if any.
    pub damping: Option<ContactDamping>,
}

impl ContactModel for MohrCoulombContact {
    fn name(&self) -> &str {
        "contact-m-c"
    }
    fn normal_penalty(&self) -> f64 {
        self.normal_penalty
    }
    fn shear_penalty(&self) -> f64 {
        self.friction.map_or(0.0, |f| f.penalty)
    }
    fn n_state(&self) -> usize {
        if self.damping.is_some() {
            3
        } else {
            1
        }
    }
    fn check(&self) -> Result<(), ComputeError> {
        if !(self.normal_penalty > 0.0 && self.normal_penalty.is_finite()) {
            return Err(ComputeError::param(
                "contact penalty",
                self.normal_penalty,
                "must be positive and finite",
            ));
        }
        if let Some(f) = self.friction {
            if !(0.0..90.0).contains(&f.angle_deg) {
                return Err(ComputeError::param(
                    "contact friction angle",
                    f.angle_deg,
                    "must lie in [0, 90) degrees",
                ));
            }
            if !(f.penalty > 0.0 && f.penalty.is_finite()) {
                return Err(ComputeError::param(
                    "contact shear penalty",
                    f.penalty,
                    "must be positive and finite",
                ));
            }
        }
        if let Some(d) = self.damping {
            if d.transition.is_nan() || d.transition <= 0.0 {
                return Err(ComputeError::param(
                    "contact damping transition stress T",
                    d.transition,
                    "must be positive (Pa)",
                ));
            }
            if !(d.exponent >= 1.0 && d.exponent.is_finite()) {
                return Err(ComputeError::param(
                    "contact damping exponent b",
                    d.exponent,
                    "must be finite and at least 1 (b < 1 would create energy on unloading)",
                ));
            }
        }
        Ok(())
    }
    fn update(&self, s_try: f64, dslip: f64, h: f64, state: &mut [f64]) -> ContactStress {
        let tan_phi = self
            .friction
            .map_or(0.0, |f| f.angle_deg.to_radians().tan());
        self.update_with(tan_phi, s_try, dslip, h, state)
    }
    fn wgsl(&self) -> Option<WgslContactModel> {
        let (fr_on, tan_phi, pt) = match self.friction {
            Some(f) => (1.0, f.angle_deg.to_radians().tan(), f.penalty),
            None => (0.0, 0.0, 0.0),
        };
        let (d_on, t, b) = match self.damping {
            // The GPU law raises to integer powers only (no f64 `pow` on most drivers).
            Some(d) if !(d.exponent.fract() == 0.0 && (1.0..=64.0).contains(&d.exponent)) => {
                return None
            }
            Some(d) => (1.0, d.transition, d.exponent),
            None => (0.0, 0.0, 1.0),
        };
        let body = include_str!("shaders/mohr_coulomb_contact.wgsl");
        // Without damping the history holds δ_s only: drop the damping lines, which
        // index entries 1 and 2.
        let (key, body) = match (body.find("// DAMPING BEGIN"), body.find("// DAMPING END")) {
            (Some(a), Some(b)) if d_on == 0.0 => (
                "contact_m_c_friction",
                format!("{}{}", &body[..a], &body[b..]),
            ),
            _ => ("contact_m_c", body.to_string()),
        };
        Some(WgslContactModel {
            key: key.into(),
            body,
            params: vec![fr_on, tan_phi, pt, d_on, t, b],
            pair_penalty: None,
        })
    }
}

/// Contact without a contact law (manual table 1): every element's surfaces carry a
/// friction angle and a contact penalty (`pcdc_mech::Mechanics::surface_properties`:
/// friction 0 and penalty 10 E unless the material sets them). A pair uses the smaller
/// of its two elements' values for both (the softer, smoother surface governs; the
/// manual does not say how two surfaces combine), with the shear penalty equal to the
/// normal one and no damping: `contact-m-c` with those parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceContact {
    /// Friction angle per element (degrees).
    pub friction_deg: Vec<f64>,
    /// Contact penalty per element (Pa).
    pub penalty: Vec<f64>,
}

impl SurfaceContact {
    /// The `contact-m-c` law of the pair (c, t).
    fn pair_law(&self, c: usize, t: usize) -> MohrCoulombContact {
        let p = self.penalty[c].min(self.penalty[t]);
        MohrCoulombContact {
            normal_penalty: p,
            friction: Some(Friction {
                angle_deg: self.friction_deg[c].min(self.friction_deg[t]),
                penalty: p,
            }),
            damping: None,
        }
    }
}

impl ContactModel for SurfaceContact {
    fn name(&self) -> &str {
        "element-surface contact (table 1)"
    }
    fn normal_penalty(&self) -> f64 {
        self.penalty.iter().fold(0.0, |m, &p| m.max(p))
    }
    fn shear_penalty(&self) -> f64 {
        self.normal_penalty()
    }
    fn n_state(&self) -> usize {
        // δ_s only: the pair law has no damping.
        1
    }
    fn check(&self) -> Result<(), ComputeError> {
        if self.penalty.len() != self.friction_deg.len() {
            return Err(ComputeError::param(
                "surface contact properties",
                format!(
                    "{} friction angles, {} penalties",
                    self.friction_deg.len(),
                    self.penalty.len()
                ),
                "give one friction angle and one penalty per element",
            ));
        }
        for (e, (&phi, &p)) in self.friction_deg.iter().zip(&self.penalty).enumerate() {
            if !(0.0..90.0).contains(&phi) {
                return Err(ComputeError::param(
                    format!("friction angle of element {e}"),
                    phi,
                    "must lie in [0, 90) degrees",
                ));
            }
            if !(p > 0.0 && p.is_finite()) {
                return Err(ComputeError::param(
                    format!("contact penalty of element {e}"),
                    p,
                    "must be positive and finite (Pa)",
                ));
            }
        }
        Ok(())
    }
    fn check_mesh(&self, n_elements: usize) -> Result<(), ComputeError> {
        if self.penalty.len() != n_elements {
            return Err(ComputeError::param(
                "surface contact properties",
                format!("{} elements", self.penalty.len()),
                format!("the mesh has {n_elements} elements: give one value per element"),
            ));
        }
        Ok(())
    }
    fn pair_penalty(&self, c: usize, t: usize) -> f64 {
        self.penalty[c].min(self.penalty[t])
    }
    /// The law of the elements with the smallest friction and penalty (Contact calls
    /// [`ContactModel::update_pair`] instead).
    fn update(&self, s_try: f64, dslip: f64, h: f64, state: &mut [f64]) -> ContactStress {
        let (c, _) = self
            .penalty
            .iter()
            .enumerate()
            .fold(
                (0, f64::INFINITY),
                |b, (e, &p)| if p < b.1 { (e, p) } else { b },
            );
        let f = self
            .friction_deg
            .iter()
            .enumerate()
            .fold(
                (0, f64::INFINITY),
                |b, (e, &p)| if p < b.1 { (e, p) } else { b },
            )
            .0;
        let mut law = self.pair_law(c, c);
        if let Some(fr) = &mut law.friction {
            fr.angle_deg = self.friction_deg[f];
        }
        law.update(s_try, dslip, h, state)
    }
    fn update_pair(
        &self,
        c: usize,
        t: usize,
        s_try: f64,
        dslip: f64,
        h: f64,
        state: &mut [f64],
    ) -> ContactStress {
        self.pair_law(c, t).update(s_try, dslip, h, state)
    }
    fn wgsl(&self) -> Option<WgslContactModel> {
        // Parameters: element count, then tan φ per element, then the penalty per element.
        let ne = self.penalty.len();
        let mut params = Vec::with_capacity(1 + 2 * ne);
        params.push(ne as f64);
        params.extend(self.friction_deg.iter().map(|a| a.to_radians().tan()));
        params.extend_from_slice(&self.penalty);
        Some(WgslContactModel {
            key: "surface_contact".into(),
            body: include_str!("shaders/surface_contact.wgsl").into(),
            params,
            pair_penalty: Some(
                "let ne = u32(param(p, 0u));\nreturn min(param(p, 1u + ne + c), param(p, 1u + ne + t));"
                    .into(),
            ),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn law(phi: f64, t: f64, b: f64) -> MohrCoulombContact {
        MohrCoulombContact {
            normal_penalty: 1e10,
            friction: Some(Friction {
                angle_deg: phi,
                penalty: 1e11,
            }),
            damping: Some(ContactDamping {
                transition: t,
                exponent: b,
            }),
        }
    }

    proptest! {
        /// Damping never raises the normal stress above the trial one or above T; the
        /// shear never exceeds tan φ σ_n and opposes the accumulated slip; b = 1 with T
        /// out of reach is the undamped law.
        #[test]
        fn passive_bounded_and_opposing(steps in proptest::collection::vec((0.0f64..1e7, -1e-4f64..1e-4), 1..40),
                                        phi in 0.0f64..60.0, t in 1e5f64..1e7, b in 1.0f64..5.0, h in 0.01f64..0.1) {
            let m = law(phi, t, b);
            let plain = MohrCoulombContact { damping: Some(ContactDamping { transition: 1e300, exponent: 1.0 }), ..m };
            let (mut st, mut sp) = ([0.0; 3], [0.0; 3]);
            for &(s_try, ds) in &steps {
                let r = m.update(s_try, ds, h, &mut st);
                prop_assert!(r.normal <= s_try * (1.0 + 1e-12) && r.normal <= t && r.normal >= 0.0);
                prop_assert!(r.shear.abs() <= phi.to_radians().tan() * r.normal * (1.0 + 1e-12) + 1e-300);
                prop_assert!(r.shear * st[0] <= 0.0);
                let q = plain.update(s_try, ds, h, &mut sp);
                prop_assert!((q.normal - s_try).abs() <= 1e-12 * s_try);
            }
        }
    }

    #[test]
    fn bad_parameters_are_named() {
        for (m, what) in [
            (law(95.0, 1e6, 2.0), "friction angle"),
            (law(30.0, -1.0, 2.0), "transition"),
            (law(30.0, 1e6, 0.5), "exponent"),
            (
                MohrCoulombContact {
                    normal_penalty: 0.0,
                    friction: None,
                    damping: None,
                },
                "penalty",
            ),
        ] {
            let e = m.check().unwrap_err().to_string();
            assert!(e.contains(what), "{e}");
        }
    }
}
