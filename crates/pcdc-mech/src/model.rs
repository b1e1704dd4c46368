//! The `ConstitutiveModel` plugin trait and isotropic linear elasticity (manual
//! 7.2.2-7.2.3).
//!
//! Tensors are passed as 6-component arrays in the order xx, yy, zz, xy, yz, xz with
//! tensor (not engineering) shear strains. In 2D (plane strain) the kinematics pass
//! ε_zz = ε_yz = ε_xz = 0 and keep σ_zz.
//!
//! A model that needs another physics' field (temperature, pore pressure) declares it in
//! [`ConstitutiveModel::coupling`] and reads its value at the element from
//! [`ModelInput::coupling`] in [`ConstitutiveModel::update_with`] (and `coupling[i]` in
//! its WGSL body): see the crate documentation for an example.

use pcdc_compute::FieldKey;
use serde::{Deserialize, Serialize};

use crate::MechError;

/// A symmetric tensor: xx, yy, zz, xy, yz, xz.
pub type Sym6 = [f64; 6];

/// A stress-strain law `σ(t+Δt) = H(σ(t), ε(t+Δt), Δε, history)` (manual eq. 12),
/// evaluated in the element's co-rotated frame so that it needs no objective rates.
pub trait ConstitutiveModel: Send + Sync + std::fmt::Debug {
    /// Model name (for reports).
    fn name(&self) -> &str;
    /// Mass density ρ (kg/m³).
    fn density(&self) -> f64;
    /// Young's modulus E (Pa), used by the critical damping coefficient (eq. 18).
    fn young(&self) -> f64;
    /// P-wave (constrained) modulus M = K + 4G/3 (Pa) of the current tangent, used for the
    /// stable time step and damping ratio.
    fn wave_modulus(&self) -> f64;
    /// Damping factor D_f of eq. 19 (dimensionless, ≥ 0).
    fn damp_factor(&self) -> f64;
    /// Number of history variables per element.
    fn n_state(&self) -> usize {
        0
    }
    /// Initial values of the history variables (default zero).
    fn init_state_into(&self, state: &mut [f64]) {
        state.fill(0.0);
    }
    /// Updates `stress` (in: σ(t), out: σ(t+Δt), Pa) from the total strain `strain` and
    /// its increment `dstrain` over the step; `state` holds [`Self::n_state`] history
    /// variables. The mechanics calls [`Self::update_with`], whose default calls this
    /// method; a model that declares [`Self::coupling`] fields overrides
    /// [`Self::update_with`] and implements this method as its law without coupling
    /// inputs.
    fn update(&self, strain: &Sym6, dstrain: &Sym6, stress: &mut Sym6, state: &mut [f64]);
    /// The coupling fields this model reads in [`Self::update_with`], in the order in
    /// which it receives their values ([`ModelInput::coupling`]), e.g.
    /// `&[names::TEMPERATURE]` for a thermo-elastic model
    /// (`pcdc_compute::names::TEMPERATURE`, K; `PORE_PRESSURE`, Pa). Node and element
    /// fields only; another physics must own each of them (the simulation builder
    /// refuses a field without an owner, [`pcdc_compute::ComputeError::FieldWithoutOwner`]).
    /// The mechanics reads them lagged (the value the field holds when the mechanics'
    /// forces stage runs: this step's when the owner wrote it earlier in the step, else
    /// the previous step's). Default: none, and then nothing is declared, allocated or
    /// gathered.
    fn coupling(&self) -> &[FieldKey] {
        &[]
    }
    /// The update the mechanics calls for every element and step (manual eq. 12):
    /// `stress` in: σ(t), out: σ(t+Δt) (Pa), from the inputs of `input` (strain, strain
    /// increment and the values of the [`Self::coupling`] fields at the element); `state`
    /// holds [`Self::n_state`] history variables. The default ignores the coupling values
    /// and calls [`Self::update`]; a model that reads coupling fields overrides it.
    fn update_with(&self, input: &ModelInput<'_>, stress: &mut Sym6, state: &mut [f64]) {
        self.update(input.strain, input.dstrain, stress, state)
    }
    /// Updates a run of consecutive elements of this model at once: element i has inputs
    /// `inputs[i]`, stress `stresses[i]` (in: σ(t), out: σ(t+Δt), Pa) and history
    /// `states[i * stride..][..stride]` (`stride` ≥ [`Self::n_state`]; the first
    /// [`Self::n_state`] values are the model's). The mechanics calls this method on the
    /// CPU (up to 16 elements at a time), never [`Self::update_with`] directly. The
    /// default calls [`Self::update_with`] for each element in turn; a model overrides it
    /// to work on several elements side by side (e.g. [`crate::MohrCoulomb`] decomposes
    /// its stresses in lanes). An override must give each element what
    /// [`Self::update_with`] gives it. Slices of unequal length are not an error: the
    /// elements beyond the shortest (`states` counted in strides) are left alone.
    fn update_many(
        &self,
        inputs: &[ModelInput<'_>],
        stresses: &mut [Sym6],
        states: &mut [f64],
        stride: usize,
    ) {
        for ((input, stress), state) in inputs
            .iter()
            .zip(stresses.iter_mut())
            .zip(states.chunks_mut(stride.max(1)))
        {
            self.update_with(input, stress, state);
        }
    }
    /// The constant tangent `dσ/dε` as a 6x6 matrix acting on tensor strain components
    /// (`σ_xy = T[3][3] ε_xy`, ...), if the model is linear; enables the direct static solve.
    fn linear_tangent(&self) -> Option<[[f64; 6]; 6]> {
        None
    }
    /// The model for the GPU backend: a WGSL function body and its parameters (see
    /// [`WgslModel`]). `None` (the default) means CPU only: building a GPU simulation
    /// with such a model is an error that names it.
    fn wgsl(&self) -> Option<WgslModel> {
        None
    }
    /// Friction angle of the element's surfaces for contact without a contact law
    /// (degrees; manual table 1, keyword `friction`; default 0).
    fn contact_friction(&self) -> f64 {
        0.0
    }
    /// Contact penalty of the element's surfaces for contact without a contact law (Pa;
    /// manual table 1, keyword `penalty`; default 10 E).
    fn contact_penalty(&self) -> f64 {
        10.0 * self.young()
    }
}

/// What a constitutive model receives for one element in one step, besides its stress
/// and history ([`ConstitutiveModel::update_with`]). Built by the mechanics; new inputs
/// may be added (the struct is `#[non_exhaustive]`), so models keep compiling.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct ModelInput<'a> {
    /// Total strain ε(t+Δt) in the element's co-rotated frame (tensor components, xx,
    /// yy, zz, xy, yz, xz; in 2D plane strain ε_zz = ε_yz = ε_xz = 0).
    pub strain: &'a Sym6,
    /// Strain increment Δε over the step (same layout).
    pub dstrain: &'a Sym6,
    /// The values of the model's [`ConstitutiveModel::coupling`] fields at the element,
    /// in declaration order, each field's components in a row: for a node field the mean
    /// of the element's node values (Σ_a v_a / N, nodes in connectivity order), for an
    /// element field the element's value. Units those of the field (temperature K,
    /// pore pressure Pa). Empty for a model that declares none.
    pub coupling: &'a [f64],
}

impl<'a> ModelInput<'a> {
    /// The inputs of one update (e.g. to call [`ConstitutiveModel::update_with`] in a
    /// test).
    pub fn new(strain: &'a Sym6, dstrain: &'a Sym6, coupling: &'a [f64]) -> Self {
        ModelInput {
            strain,
            dstrain,
            coupling,
        }
    }
}

/// A constitutive model's GPU code, spliced into the element kernel template.
///
/// `body` is the body of
/// `fn (strain: Sym, dstrain: Sym, stress: Sym, state: ptr<function, ModelState>, p: u32) -> Sym`
/// where `Sym = array<Real, 6>` holds xx, yy, zz, xy, yz, xz (tensor shear strains, as
/// on the CPU), `stress` is σ(t), the function returns σ(t+Δt), `(*state)[k]` are the
/// history variables and `param(p, k)` reads `params[k]`.
///
/// When a model of the mechanics declares coupling fields
/// ([`ConstitutiveModel::coupling`]), every model function takes one more parameter,
/// `coupling: Coupling` (`array<Real, N>`, N the largest value count of
/// the models), after `state`: the model's values of [`ModelInput::coupling`], computed
/// as on the CPU (entries beyond the model's own count are zero). Without coupling the
/// parameter does not exist, so only a model that declares coupling fields may read it.
///
/// `Real` is `f64` or `f32` by precision: write literals without suffix (`0.5`, not
/// `0.5f`) and keep to + − × ÷, `sqrt`, `abs`, `min`, `max`, `select` (drivers may lack
/// f64 `exp`/`pow`/`sin`). To match the CPU to rounding, repeat the CPU's operations in
/// the same order.
///
/// A long model may put helper functions in `functions` (module scope, spliced once per
/// key before the model functions; they may call `param` and use `Real` and `Sym`);
/// prefix their names with the model's to keep clear of other models. Most models leave
/// it empty: build with `..Default::default()`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WgslModel {
    /// Identifies the code: models with equal keys must have equal bodies (they share one
    /// WGSL function and differ only in parameters).
    pub key: String,
    /// The WGSL function body.
    pub body: String,
    /// Parameters read with `param(p, k)`.
    pub params: Vec<f64>,
    /// Module-scope WGSL functions the body calls (may be empty).
    pub functions: String,
}

/// Isotropic linear elasticity (manual eq. 20-24), updated incrementally
/// `σ += λ tr(Δε) I + 2μ Δε` so that initial stresses superpose.
///
/// The parameters are private: the constructors, the `with_*` setters and deserialisation
/// share one check, so a model from a file or a struct update cannot bypass it. Checked:
/// E > 0 and finite (Pa); −1 < ν < 0.5, i.e. bulk modulus K and shear modulus G positive
/// (ν < 0 is allowed: auxetic materials exist; ν = 0.5 is incompressible, which explicit
/// elements cannot represent); ρ > 0 and finite (kg/m³); D_f ≥ 0 and finite; friction
/// angle in [0, 90) degrees; contact penalty, when given, > 0 and finite (Pa). Errors name
/// the parameter (with the serialised key, e.g. `poisson`) and its value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawLinearElastic")]
pub struct LinearElastic {
    young: f64,
    poisson: f64,
    density: f64,
    damp_factor: f64,
    friction: f64,
    contact_penalty: Option<f64>,
}

/// The serialised form of [`LinearElastic`] (same keys), checked before it becomes one.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLinearElastic {
    young: f64,
    poisson: f64,
    density: f64,
    #[serde(default)]
    damp_factor: f64,
    #[serde(default)]
    friction: f64,
    #[serde(default)]
    contact_penalty: Option<f64>,
}

impl TryFrom<RawLinearElastic> for LinearElastic {
    type Error = MechError;

    fn try_from(r: RawLinearElastic) -> Result<Self, MechError> {
        let m = LinearElastic {
            young: r.young,
            poisson: r.poisson,
            density: r.density,
            damp_factor: r.damp_factor,
            friction: r.friction,
            contact_penalty: r.contact_penalty,
        };
        m.check()?;
        Ok(m)
    }
}

impl LinearElastic {
    /// From Young's modulus E (Pa), Poisson's ratio ν and density ρ (kg/m³).
    pub fn new(young: f64, poisson: f64, density: f64) -> Result<Self, MechError> {
        let m = LinearElastic {
            young,
            poisson,
            density,
            damp_factor: 0.0,
            friction: 0.0,
            contact_penalty: None,
        };
        m.check()?;
        Ok(m)
    }

    /// From bulk modulus K (Pa), shear modulus G (Pa) and density (manual table 1,
    /// keywords `bulk` and `shear`): E = 9KG/(3K+G), ν = (3K-2G)/(2(3K+G)).
    pub fn from_bulk_shear(bulk: f64, shear: f64, density: f64) -> Result<Self, MechError> {
        if !(bulk > 0.0 && bulk.is_finite()) {
            return Err(MechError::param(
                "bulk modulus K",
                bulk,
                "must be positive and finite",
            ));
        }
        if !(shear > 0.0 && shear.is_finite()) {
            return Err(MechError::param(
                "shear modulus G",
                shear,
                "must be positive and finite",
            ));
        }
        let young = 9.0 * bulk * shear / (3.0 * bulk + shear);
        let poisson = (3.0 * bulk - 2.0 * shear) / (2.0 * (3.0 * bulk + shear));
        Self::new(young, poisson, density)
    }

    /// Sets the damping factor D_f (eq. 19).
    pub fn with_damping(mut self, damp_factor: f64) -> Result<Self, MechError> {
        self.damp_factor = damp_factor;
        self.check()?;
        Ok(self)
    }

    /// Sets the surface friction angle (degrees) and, optionally, the contact penalty
    /// (Pa; default 10 E) that contact uses when no contact law is set (table 1).
    pub fn with_contact(
        mut self,
        friction_deg: f64,
        penalty: Option<f64>,
    ) -> Result<Self, MechError> {
        self.friction = friction_deg;
        self.contact_penalty = penalty;
        self.check()?;
        Ok(self)
    }

    /// Young's modulus E (Pa).
    pub fn young(&self) -> f64 {
        self.young
    }

    /// Poisson's ratio ν (-), in (−1, 0.5).
    pub fn poisson(&self) -> f64 {
        self.poisson
    }

    /// Density ρ (kg/m³).
    pub fn density(&self) -> f64 {
        self.density
    }

    /// Damping factor D_f of eq. 19 (-).
    pub fn damp_factor(&self) -> f64 {
        self.damp_factor
    }

    /// Friction angle of the surfaces for contact without a contact law (degrees).
    pub fn friction(&self) -> f64 {
        self.friction
    }

    /// The contact penalty set with [`Self::with_contact`] (Pa), or `None` for the
    /// default 10 E (see [`ConstitutiveModel::contact_penalty`]).
    pub fn contact_penalty_override(&self) -> Option<f64> {
        self.contact_penalty
    }

    fn check(&self) -> Result<(), MechError> {
        if !(0.0..90.0).contains(&self.friction) {
            return Err(MechError::param(
                "friction angle (friction)",
                self.friction,
                "must lie in [0, 90) degrees",
            ));
        }
        if let Some(p) = self.contact_penalty {
            if !(p > 0.0 && p.is_finite()) {
                return Err(MechError::param(
                    "contact penalty (contact_penalty)",
                    p,
                    "must be positive and finite (Pa)",
                ));
            }
        }
        if !(self.young > 0.0 && self.young.is_finite()) {
            return Err(MechError::param(
                "Young's modulus E (young)",
                self.young,
                "must be positive and finite",
            ));
        }
        if !(self.poisson > -1.0 && self.poisson < 0.5) {
            return Err(MechError::param(
                "Poisson's ratio ν (poisson)",
                self.poisson,
                "must lie in (-1, 0.5) so that the bulk and shear moduli are positive \
                 (ν < 0 is allowed for auxetic materials; 0.5 is incompressible, which \
                 explicit elements cannot represent)",
            ));
        }
        if !(self.density > 0.0 && self.density.is_finite()) {
            return Err(MechError::param(
                "density ρ (density)",
                self.density,
                "must be positive and finite",
            ));
        }
        if !(self.damp_factor >= 0.0 && self.damp_factor.is_finite()) {
            return Err(MechError::param(
                "damping factor D_f (damp_factor)",
                self.damp_factor,
                "must be non-negative and finite",
            ));
        }
        Ok(())
    }

    /// Lamé's first parameter λ = Eν/((1+ν)(1-2ν)) (eq. 23), Pa.
    pub fn lambda(&self) -> f64 {
        self.young * self.poisson / ((1.0 + self.poisson) * (1.0 - 2.0 * self.poisson))
    }

    /// Shear modulus μ = G = E/(2(1+ν)) (eq. 24), Pa.
    pub fn shear(&self) -> f64 {
        self.young / (2.0 * (1.0 + self.poisson))
    }

    /// Bulk modulus K = λ + 2G/3, Pa.
    pub fn bulk(&self) -> f64 {
        self.lambda() + 2.0 * self.shear() / 3.0
    }

    /// σ = λ tr(ε) I + 2μ ε for a strain tensor.
    pub fn stress_of(&self, e: &Sym6) -> Sym6 {
        let mut s = [0.0; 6];
        add_hooke(self.lambda(), 2.0 * self.shear(), e, &mut s);
        s
    }
}

impl ConstitutiveModel for LinearElastic {
    fn name(&self) -> &str {
        "mech-iso-elastic"
    }
    fn density(&self) -> f64 {
        self.density
    }
    fn young(&self) -> f64 {
        self.young
    }
    fn contact_friction(&self) -> f64 {
        self.friction
    }
    fn contact_penalty(&self) -> f64 {
        self.contact_penalty.unwrap_or(10.0 * self.young)
    }
    fn wave_modulus(&self) -> f64 {
        self.lambda() + 2.0 * self.shear()
    }
    fn damp_factor(&self) -> f64 {
        self.damp_factor
    }
    #[inline]
    fn update(&self, _strain: &Sym6, de: &Sym6, stress: &mut Sym6, _state: &mut [f64]) {
        add_hooke(self.lambda(), 2.0 * self.shear(), de, stress);
    }
    fn wgsl(&self) -> Option<WgslModel> {
        Some(WgslModel {
            key: "linear_elastic".into(),
            body: include_str!("shaders/linear_elastic.wgsl").into(),
            params: vec![self.lambda(), self.shear()],
            ..Default::default()
        })
    }
    fn linear_tangent(&self) -> Option<[[f64; 6]; 6]> {
        let (l, m) = (self.lambda(), self.shear());
        let mut t = [[0.0; 6]; 6];
        for i in 0..3 {
            for j in 0..3 {
                t[i][j] = l;
            }
            t[i][i] += 2.0 * m;
            t[i + 3][i + 3] = 2.0 * m;
        }
        Some(t)
    }
}

/// `σ += λ tr(ε) I + 2μ ε` (eq. 20-24) with λ and 2μ given (Pa): [`LinearElastic`]'s
/// update, which the element loop of [`crate::Mechanics`] applies inline with the
/// moduli cached.
#[inline(always)]
pub(crate) fn add_hooke(lambda: f64, two_mu: f64, e: &Sym6, stress: &mut Sym6) {
    let tr = e[0] + e[1] + e[2];
    for k in 0..3 {
        stress[k] += lambda * tr + two_mu * e[k];
    }
    for k in 3..6 {
        stress[k] += two_mu * e[k];
    }
}

/// Double contraction σ:ε of two symmetric tensors.
pub fn double_dot(a: &Sym6, b: &Sym6) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + 2.0 * (a[3] * b[3] + a[4] * b[4] + a[5] * b[5])
}

/// The [`ConstitutiveModel`] methods that a model built on a [`LinearElastic`] field takes
/// from it unchanged: density, Young's modulus, wave modulus, damping factor and the
/// contact surface properties (used by Mohr–Coulomb and Burgers).
macro_rules! delegate_elastic {
    ($field:ident) => {
        fn density(&self) -> f64 {
            self.$field.density()
        }
        fn young(&self) -> f64 {
            self.$field.young()
        }
        fn wave_modulus(&self) -> f64 {
            $crate::model::ConstitutiveModel::wave_modulus(&self.$field)
        }
        fn damp_factor(&self) -> f64 {
            self.$field.damp_factor()
        }
        fn contact_friction(&self) -> f64 {
            self.$field.friction()
        }
        fn contact_penalty(&self) -> f64 {
            self.$field.contact_penalty()
        }
    };
}
pub(crate) use delegate_elastic;
