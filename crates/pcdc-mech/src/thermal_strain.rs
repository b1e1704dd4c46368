//! Thermal stress for any constitutive model (manual 7.6.4, eq. 113 \[CORRECTED\]).
//!
//! [`ThermalStrain`] wraps a model (built-in or a user's) and subtracts the free thermal
//! strain from the strains the model sees:
//!
//! * ε_th = α (T − T_ref) I, α the **linear** expansion coefficient (1/K), T the
//!   element's temperature (the mean of its nodes' `names::TEMPERATURE`, read as a
//!   coupling input), T_ref the stress-free temperature;
//! * the model receives Δε − Δε_th and ε − ε_th (in 2D plane strain the zz component
//!   too: ε_zz = 0 in total, so the mechanical ε_zz = −α ΔT).
//!
//! For linear elasticity this is the digest's corrected eq. 113, Δσ = −3 K α ΔT I
//! (printed Δσ_ij = −α_s K ΔT_s, without δ_ij and the 3); for a plastic or creeping
//! model the thermal strain is not plastic and not creep, which the strain split gives
//! and a stress correction would not. The thermal strain applied so far is one more
//! history variable (the last), so a restart resumes it, and a temperature that starts
//! away from T_ref loads the body in the first step.
//!
//! **α of the wrong order.** Rock's linear α lies between about 1e-6 and 2e-5 1/K. A
//! volumetric coefficient (3α) given as α triples the thermal stress, which no check can
//! see; values with |α| ≥ 1e-3 1/K (per cent, or per mille, given as a fraction) are
//! refused.

use pcdc_compute::{names, FieldKey};

use crate::model::{ConstitutiveModel, ModelInput, Sym6, WgslModel};
use crate::MechError;

/// A constitutive model with thermal strain α (T − T_ref) I (see the module docs).
#[derive(Debug)]
pub struct ThermalStrain<M> {
    inner: M,
    alpha: f64,
    reference: f64,
    keys: Vec<FieldKey>,
    name: String,
}

impl<M: ConstitutiveModel> ThermalStrain<M> {
    /// Wraps `inner` with the linear expansion coefficient α (1/K; |α| < 1e-3) and the
    /// stress-free temperature T_ref (K, or °C if the temperature field is in °C).
    pub fn new(inner: M, alpha: f64, reference_temperature: f64) -> Result<Self, MechError> {
        if !(alpha.is_finite() && alpha.abs() < 1e-3) {
            return Err(MechError::param(
                "linear thermal expansion coefficient α (expansion)",
                alpha,
                "must be finite with |α| < 1e-3 1/K (rock: 1e-6 to 2e-5; a larger value is \
                 probably in per cent or per mille)",
            ));
        }
        if !reference_temperature.is_finite() {
            return Err(MechError::param(
                "reference temperature T_ref",
                reference_temperature,
                "must be finite",
            ));
        }
        let mut keys = vec![names::TEMPERATURE];
        keys.extend_from_slice(inner.coupling());
        if inner.coupling().contains(&names::TEMPERATURE) {
            return Err(MechError::param(
                format!("model '{}'", inner.name()),
                "coupling",
                "already reads the temperature: it models its thermal strain itself",
            ));
        }
        let name = format!("thermal-strain({})", inner.name());
        Ok(ThermalStrain {
            inner,
            alpha,
            reference: reference_temperature,
            keys,
            name,
        })
    }

    /// The wrapped model.
    pub fn inner(&self) -> &M {
        &self.inner
    }
    /// Linear expansion coefficient α (1/K).
    pub fn alpha(&self) -> f64 {
        self.alpha
    }
    /// Stress-free temperature T_ref.
    pub fn reference_temperature(&self) -> f64 {
        self.reference
    }
}

impl<M: ConstitutiveModel> ConstitutiveModel for ThermalStrain<M> {
    fn name(&self) -> &str {
        &self.name
    }
    fn density(&self) -> f64 {
        self.inner.density()
    }
    fn young(&self) -> f64 {
        self.inner.young()
    }
    fn wave_modulus(&self) -> f64 {
        self.inner.wave_modulus()
    }
    fn damp_factor(&self) -> f64 {
        self.inner.damp_factor()
    }
    fn contact_friction(&self) -> f64 {
        self.inner.contact_friction()
    }
    fn contact_penalty(&self) -> f64 {
        self.inner.contact_penalty()
    }
    /// The inner model's history, then the thermal strain applied so far (-).
    fn n_state(&self) -> usize {
        self.inner.n_state() + 1
    }
    fn init_state_into(&self, state: &mut [f64]) {
        let n = self.inner.n_state();
        self.inner.init_state_into(&mut state[..n]);
        state[n] = 0.0;
    }
    fn coupling(&self) -> &[FieldKey] {
        &self.keys
    }
    /// Without coupling inputs the temperature stays at T_ref: the inner law.
    fn update(&self, strain: &Sym6, dstrain: &Sym6, stress: &mut Sym6, state: &mut [f64]) {
        let n = self.inner.n_state();
        self.inner.update(strain, dstrain, stress, &mut state[..n]);
    }
    fn update_with(&self, input: &ModelInput<'_>, stress: &mut Sym6, state: &mut [f64]) {
        let n = self.inner.n_state();
        let th = self.alpha * (input.coupling[0] - self.reference);
        let d = th - state[n];
        state[n] = th;
        let (mut e, mut de) = (*input.strain, *input.dstrain);
        for k in 0..3 {
            e[k] -= th;
            de[k] -= d;
        }
        let inner = ModelInput::new(&e, &de, &input.coupling[1..]);
        self.inner.update_with(&inner, stress, &mut state[..n]);
    }
    /// The thermal strain is a load the linear tangent does not carry: none, so the
    /// direct static solve is not offered.
    fn linear_tangent(&self) -> Option<[[f64; 6]; 6]> {
        None
    }
    /// The inner model's WGSL as a function `thermal_<key>` called with the mechanical
    /// strains, its parameters after α and T_ref, and its coupling values shifted past
    /// the temperature; the same operations as [`Self::update_with`].
    fn wgsl(&self) -> Option<WgslModel> {
        let w = self.inner.wgsl()?;
        let n = self.inner.n_state();
        let m = self.inner.coupling().len();
        let ident: String = w
            .key
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        let fname = format!("thermal_inner_{ident}");
        let functions = format!(
            "{}\nfn {fname}(strain: Sym, dstrain: Sym, stress: Sym, state: ptr<function, ModelState>, coupling: Coupling, p: u32) -> Sym {{\n{}\n}}\n",
            w.functions, w.body
        );
        let body = format!(
            "let th = param(p, 0u) * (coupling[0] - param(p, 1u));
let d = th - (*state)[{n}u];
(*state)[{n}u] = th;
var e = strain;
var de = dstrain;
for (var k = 0u; k < 3u; k = k + 1u) {{
    e[k] = e[k] - th;
    de[k] = de[k] - d;
}}
var c: Coupling;
for (var i = 0u; i < {m}u; i = i + 1u) {{
    c[i] = coupling[i + 1u];
}}
return {fname}(e, de, stress, state, c, p + 2u);"
        );
        let mut params = vec![self.alpha, self.reference];
        params.extend_from_slice(&w.params);
        Some(WgslModel {
            key: format!("thermal__{}", w.key),
            body,
            params,
            functions,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::LinearElastic;
    use proptest::prelude::*;

    proptest! {
        /// Around elasticity the wrapper adds exactly −3Kα ΔT I to C:Δε (eq. 113
        /// corrected), for any strain increment and any temperature path; a free thermal
        /// expansion (Δε = αΔT I) is stress-free; the last history variable is α(T − T_ref).
        #[test]
        fn elastic_thermal_stress_is_minus_3_k_alpha_dt(
            de in proptest::array::uniform6(-1e-4f64..1e-4),
            t1 in -50.0f64..400.0,
            t2 in -50.0f64..400.0,
            alpha in 1e-7f64..2e-5,
        ) {
            let e = LinearElastic::new(30e9, 0.25, 2600.0).unwrap();
            let m = ThermalStrain::new(e.clone(), alpha, 20.0).unwrap();
            let (mut s, mut st) = ([0.0; 6], vec![0.0; 1]);
            m.update_with(&ModelInput::new(&[0.0; 6], &[0.0; 6], &[t1]), &mut s, &mut st);
            let before = s;
            m.update_with(&ModelInput::new(&de, &de, &[t2]), &mut s, &mut st);
            let c = e.stress_of(&de);
            let th = 3.0 * e.bulk() * alpha * (t2 - t1);
            let scale = 3.0 * e.bulk() * 1e-2;
            for k in 0..6 {
                let expect = before[k] + c[k] - if k < 3 { th } else { 0.0 };
                prop_assert!((s[k] - expect).abs() <= 1e-9 * scale, "{k}: {} vs {expect}", s[k]);
            }
            prop_assert!((st[0] - alpha * (t2 - 20.0)).abs() <= 1e-15);
            // Free expansion from T_ref: no stress.
            let (mut s, mut st) = ([0.0; 6], vec![0.0; 1]);
            let free = alpha * (t2 - 20.0);
            let f: Sym6 = [free, free, free, 0.0, 0.0, 0.0];
            m.update_with(&ModelInput::new(&f, &f, &[t2]), &mut s, &mut st);
            prop_assert!(s.iter().all(|v| v.abs() <= 1e-9 * scale), "{s:?}");
        }
    }
}
