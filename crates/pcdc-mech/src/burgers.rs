//! Burgers creep (manual 7.2.5, table 3, `mech-burgers`): a Kelvin body (G_K ∥ η_K) in
//! series with a Maxwell body (G_M, η_M) for the deviatoric stress; the mean stress is
//! elastic with bulk modulus K.
//!
//! * **(34)–(42)** the 1-D bodies and their Crank–Nicolson (trapezoidal) discretisation;
//!   **(43)–(46)** the update solved for the new force; **(47)–(48)** \[CORRECTED\]
//!   X = 1/G_M + Δt/(2η_M) + Δt/(2Aη_K), Y = 1/G_M − Δt/(2η_M) − Δt/(2Aη_K) (printed with
//!   K_M where the Maxwell spring G_M belongs, see the digest §3.1).
//! * **Tensor form** \[NOT IN MANUAL, FLAC's Burgers, digest §3.2\]: with the deviatoric
//!   stress S, the deviatoric strain e and the Kelvin strain e^K (tensor components),
//!   G → 2G and η → 2η:
//!   A = 1 + G_K Δt/(2η_K), B = 1 − G_K Δt/(2η_K),
//!   X = 1/(2G_M) + Δt/(4η_M) + Δt/(4Aη_K), Y = 1/(2G_M) − Δt/(4η_M) − Δt/(4Aη_K),
//!   S^N = [Δe + Y S^O − (B/A − 1) e^K,O] / X,
//!   e^K,N = [B e^K,O + Δt/(4η_K) (S^N + S^O)] / A,
//!   σ_m^N = σ_m^O + K Δε_v.
//!
//! **Creep time** \[NOT IN MANUAL: the manual hints at a static mode with its own time
//! unit\]: the dashpots do not advance with the inertial step (microseconds against days)
//! but with a creep step Δt_c of a [`CreepClock`] (a physics that owns the element field
//! [`CREEP_CLOCK`]): [`creep_step`] advances the clock by Δt_c and relaxes the model to
//! equilibrium ([`pcdc_compute::Simulation::relax`]). All mechanical steps of one creep
//! step share its start state (S^O, e^K,O and the strain at its start): the stress is
//! S^N of the strain reached so far, so the equilibrium found is the Crank–Nicolson
//! update of the whole creep step (second-order accurate in Δt_c, shown by the `creep`
//! scene), and repeated force evaluations within a step are idempotent. The step is
//! committed (e^K,N, the new start) at the first force evaluation after it. Outside creep
//! steps (Δt_c = 0) the model is elastic with K and G_M, the instantaneous moduli.
//!
//! The creep step is capped at a fraction of the shortest relaxation time of the
//! clock's models, min(η_M/G_M, η_K/G_K) ([`CreepClock::new`]), the accuracy limit of
//! FLAC-style practice (the scheme itself is unconditionally stable).
//!
//! History per element ([`BURGERS_STATE`] values, in VTU as `model_state_k`):
//! `[0..6]` e^K (xx, yy, zz, xy, yz, xz; tensor components), `[6..12]` S^O, `[12..18]`
//! the strain at the creep step's start, `[18]` the clock's step index then, `[19]` the
//! Δt_c last used (s), `[20]` 1 once the start state is set.

use pcdc_compute::{
    Components, ComputeError, FieldKey, ForceContext, InitContext, Physics, Place, Simulation,
    StaticOptions, StaticReport,
};
use pcdc_mesh::Dim;
use serde::{Deserialize, Serialize};

use crate::model::{ConstitutiveModel, LinearElastic, ModelInput, Sym6, WgslModel};
use crate::MechError;

/// Number of history variables of [`Burgers`].
pub const BURGERS_STATE: usize = 21;

/// The creep clock per element: `[0]` the creep step index, `[1]` the creep step Δt_c in
/// effect (s; 0 outside creep steps), `[2]` the creep time (s), `[3]` the largest Δt_c
/// allowed (s). Owner: [`CreepClock`]; read by [`Burgers`] as a coupling input.
pub const CREEP_CLOCK: FieldKey =
    FieldKey::new("creep_clock", Place::Element, Components::Fixed(4));

/// The Burgers creep model (manual 7.2.5, table 3; see the module documentation).
///
/// Parameters (checked by the constructor and on deserialisation; errors name them):
/// the instantaneous elastic part as a [`LinearElastic`] whose E and ν give the bulk
/// modulus K and the Maxwell shear modulus G_M (the digest's reading of table 3's
/// "E, ν equivalent to the moduli pair"; use [`LinearElastic::from_bulk_shear`] to give
/// K and G_M), the Kelvin shear modulus G_K > 0 (Pa), the Kelvin viscosity η_K > 0 and
/// the Maxwell viscosity η_M > 0 (Pa·s), and optional initial Kelvin strains (tensor
/// components, xx, yy, zz, xy, yz, xz; their trace must be zero, as the Kelvin body is
/// deviatoric).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawBurgers")]
pub struct Burgers {
    elastic: LinearElastic,
    kelvin_shear: f64,
    kelvin_viscosity: f64,
    maxwell_viscosity: f64,
    kelvin_strain: Sym6,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBurgers {
    elastic: LinearElastic,
    kelvin_shear: f64,
    kelvin_viscosity: f64,
    maxwell_viscosity: f64,
    #[serde(default)]
    kelvin_strain: Sym6,
}

impl TryFrom<RawBurgers> for Burgers {
    type Error = MechError;
    fn try_from(r: RawBurgers) -> Result<Self, MechError> {
        Burgers::new(
            r.elastic,
            r.kelvin_shear,
            r.kelvin_viscosity,
            r.maxwell_viscosity,
        )?
        .with_kelvin_strain(r.kelvin_strain)
    }
}

impl Burgers {
    /// From the instantaneous elastic part (K, G_M), the Kelvin shear modulus G_K (Pa)
    /// and the Kelvin and Maxwell viscosities η_K, η_M (Pa·s).
    pub fn new(
        elastic: LinearElastic,
        kelvin_shear: f64,
        kelvin_viscosity: f64,
        maxwell_viscosity: f64,
    ) -> Result<Self, MechError> {
        let positive = |name: &str, v: f64, unit: &str| {
            if v > 0.0 && v.is_finite() {
                Ok(())
            } else {
                Err(MechError::param(
                    name,
                    v,
                    format!("must be positive and finite ({unit})"),
                ))
            }
        };
        positive(
            "Kelvin shear modulus G_K (kelvin_shear)",
            kelvin_shear,
            "Pa",
        )?;
        positive(
            "Kelvin viscosity η_K (kelvin_viscosity)",
            kelvin_viscosity,
            "Pa·s",
        )?;
        positive(
            "Maxwell viscosity η_M (maxwell_viscosity)",
            maxwell_viscosity,
            "Pa·s",
        )?;
        Ok(Burgers {
            elastic,
            kelvin_shear,
            kelvin_viscosity,
            maxwell_viscosity,
            kelvin_strain: [0.0; 6],
        })
    }

    /// Sets the initial Kelvin strains (tensor components; trace zero to rounding, e.g.
    /// e^K = S0 / (2 G_K) for a Kelvin body fully developed under an initial deviator S0).
    pub fn with_kelvin_strain(mut self, e: Sym6) -> Result<Self, MechError> {
        let scale = e.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if e.iter().any(|v| !v.is_finite()) || (e[0] + e[1] + e[2]).abs() > 1e-12 * scale {
            return Err(MechError::param(
                "initial Kelvin strain (kelvin_strain)",
                format!("{e:?}"),
                "must be finite with zero trace (the Kelvin body is deviatoric)",
            ));
        }
        self.kelvin_strain = e;
        Ok(self)
    }

    /// The instantaneous elastic part (K and G_M).
    pub fn elastic(&self) -> &LinearElastic {
        &self.elastic
    }
    /// Maxwell shear modulus G_M (Pa).
    pub fn maxwell_shear(&self) -> f64 {
        self.elastic.shear()
    }
    /// Kelvin shear modulus G_K (Pa).
    pub fn kelvin_shear(&self) -> f64 {
        self.kelvin_shear
    }
    /// Kelvin viscosity η_K (Pa·s).
    pub fn kelvin_viscosity(&self) -> f64 {
        self.kelvin_viscosity
    }
    /// Maxwell viscosity η_M (Pa·s).
    pub fn maxwell_viscosity(&self) -> f64 {
        self.maxwell_viscosity
    }
    /// The shortest relaxation time min(η_M/G_M, η_K/G_K) (s).
    pub fn relaxation_time(&self) -> f64 {
        (self.maxwell_viscosity / self.maxwell_shear())
            .min(self.kelvin_viscosity / self.kelvin_shear)
    }

    /// The deviatoric strain under a constant deviatoric stress s applied at t = 0 from
    /// rest (closed form of the Burgers body): e(t) = s/(2G_M) + s t/(2η_M) +
    /// s/(2G_K) (1 − exp(−G_K t/η_K)).
    pub fn creep_strain(&self, s: f64, t: f64) -> f64 {
        let (gm, gk) = (self.maxwell_shear(), self.kelvin_shear);
        s / (2.0 * gm)
            + s * t / (2.0 * self.maxwell_viscosity)
            + s / (2.0 * gk) * (1.0 - (-gk * t / self.kelvin_viscosity).exp())
    }

    /// The coefficients A, B, X, Y of a creep step dt (s).
    fn coefficients(&self, dt: f64) -> [f64; 4] {
        let (gm, gk) = (self.maxwell_shear(), self.kelvin_shear);
        let (ek, em) = (self.kelvin_viscosity, self.maxwell_viscosity);
        let a = 1.0 + gk * dt / (2.0 * ek);
        let b = 1.0 - gk * dt / (2.0 * ek);
        let x = 1.0 / (2.0 * gm) + dt / (4.0 * em) + dt / (4.0 * a * ek);
        let y = 1.0 / (2.0 * gm) - dt / (4.0 * em) - dt / (4.0 * a * ek);
        [a, b, x, y]
    }
}

/// Index of the values in a [`Burgers`] element's history.
pub mod state {
    /// First of the six Kelvin strains e^K.
    pub const KELVIN: usize = 0;
    /// First of the six deviatoric stresses S^O at the creep step's start (Pa).
    pub const START_STRESS: usize = 6;
    /// First of the six strains at the creep step's start.
    pub const START_STRAIN: usize = 12;
    /// The creep clock's step index at the start.
    pub const STEP: usize = 18;
    /// The creep step Δt_c last used (s).
    pub const DT: usize = 19;
    /// 1 once the start state is set.
    pub const READY: usize = 20;
}

fn deviator(t: &Sym6) -> (f64, Sym6) {
    let m = (t[0] + t[1] + t[2]) * (1.0 / 3.0);
    (m, [t[0] - m, t[1] - m, t[2] - m, t[3], t[4], t[5]])
}

impl ConstitutiveModel for Burgers {
    fn name(&self) -> &str {
        "mech-burgers"
    }
    crate::model::delegate_elastic!(elastic);
    fn n_state(&self) -> usize {
        BURGERS_STATE
    }
    fn init_state_into(&self, st: &mut [f64]) {
        st.fill(0.0);
        st[state::KELVIN..state::KELVIN + 6].copy_from_slice(&self.kelvin_strain);
    }
    fn coupling(&self) -> &[FieldKey] {
        &[CREEP_CLOCK]
    }
    /// Without clock values: no creep step in effect (elastic with K and G_M).
    fn update(&self, strain: &Sym6, dstrain: &Sym6, stress: &mut Sym6, st: &mut [f64]) {
        let clock = [st[state::STEP], 0.0];
        self.step(strain, dstrain, &clock, stress, st);
    }
    fn update_with(&self, input: &ModelInput<'_>, stress: &mut Sym6, st: &mut [f64]) {
        self.step(input.strain, input.dstrain, input.coupling, stress, st);
    }
    fn wgsl(&self) -> Option<WgslModel> {
        Some(WgslModel {
            key: "burgers".into(),
            body: include_str!("shaders/burgers.wgsl").into(),
            params: vec![
                self.elastic.bulk(),
                self.maxwell_shear(),
                self.kelvin_shear,
                self.kelvin_viscosity,
                self.maxwell_viscosity,
            ],
            ..Default::default()
        })
    }
}

impl Burgers {
    /// One update with the clock values `[step index, Δt_c, ..]`.
    fn step(&self, strain: &Sym6, de: &Sym6, clock: &[f64], stress: &mut Sym6, st: &mut [f64]) {
        let (index, dt) = (clock[0], clock[1]);
        let (mean, dev) = deviator(stress);
        let start = |st: &mut [f64], dev: &Sym6| {
            st[state::START_STRESS..state::START_STRESS + 6].copy_from_slice(dev);
            for k in 0..6 {
                st[state::START_STRAIN + k] = strain[k] - de[k];
            }
            st[state::STEP] = index;
            st[state::READY] = 1.0;
        };
        if st[state::READY] == 0.0 {
            start(st, &dev);
        } else if index != st[state::STEP] {
            // Commit the finished creep step: its last stress is σ(t).
            let [a, b, _, _] = self.coefficients(st[state::DT]);
            let c = st[state::DT] / (4.0 * self.kelvin_viscosity);
            for k in 0..6 {
                let s0 = st[state::START_STRESS + k];
                st[state::KELVIN + k] = (b * st[state::KELVIN + k] + c * (dev[k] + s0)) / a;
            }
            start(st, &dev);
        }
        let [a, b, x, y] = self.coefficients(dt);
        let mut e = [0.0; 6];
        for k in 0..6 {
            e[k] = strain[k] - st[state::START_STRAIN + k];
        }
        let (_, e) = deviator(&e);
        let mean = mean + self.elastic.bulk() * (de[0] + de[1] + de[2]);
        for k in 0..6 {
            let s = (e[k] + y * st[state::START_STRESS + k]
                - (b / a - 1.0) * st[state::KELVIN + k])
                / x;
            stress[k] = s + if k < 3 { mean } else { 0.0 };
        }
        st[state::DT] = dt;
    }
}

/// The creep clock: owns [`CREEP_CLOCK`], which [`Burgers`] reads. No forces and no
/// kernels; [`creep_step`] and [`creep_time`] drive and read it.
#[derive(Clone, Debug)]
pub struct CreepClock {
    max_dt: f64,
}

impl CreepClock {
    /// A clock whose creep step may not exceed `fraction` of the shortest relaxation
    /// time of `models` ([`Burgers::relaxation_time`]); `fraction` in (0, 1], e.g. 0.1.
    pub fn new(models: &[&Burgers], fraction: f64) -> Result<Self, MechError> {
        if !(fraction > 0.0 && fraction <= 1.0) {
            return Err(MechError::param(
                "creep step fraction",
                fraction,
                "must lie in (0, 1] (of the shortest relaxation time)",
            ));
        }
        let t = models
            .iter()
            .map(|m| m.relaxation_time())
            .fold(f64::INFINITY, f64::min);
        Ok(CreepClock {
            max_dt: fraction * t,
        })
    }

    /// The largest creep step (s).
    pub fn max_dt(&self) -> f64 {
        self.max_dt
    }
}

impl<D: Dim> Physics<D> for CreepClock {
    fn name(&self) -> &str {
        "creep clock"
    }
    fn fields(&self, _mesh: &pcdc_mesh::Mesh<D>) -> Vec<pcdc_compute::FieldUse> {
        vec![CREEP_CLOCK.own::<D>()]
    }
    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        let id = ctx.fields.id(CREEP_CLOCK)?;
        for c in ctx.fields.get_mut(id).chunks_exact_mut(4) {
            c.copy_from_slice(&[0.0, 0.0, 0.0, self.max_dt]);
        }
        Ok(())
    }
    fn compute_forces(&mut self, _ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        Ok(())
    }
    fn gpu_setup(
        &mut self,
        _setup: &mut pcdc_compute::gpu::GpuSetup<'_, D>,
    ) -> Result<(), ComputeError> {
        Ok(())
    }
}

/// One creep step: advances the clock by `dt` (s; at most the clock's cap) and relaxes
/// the model to equilibrium under `opts` (the relaxation's pseudo time does not advance
/// the simulation time). Returns the relaxation report. Errors when `dt` is not positive
/// or above the cap (naming both), or without a [`CreepClock`].
pub fn creep_step<D: Dim>(
    sim: &mut Simulation<D>,
    dt: f64,
    opts: &StaticOptions,
) -> Result<StaticReport, MechError> {
    let id = sim.state.fields.id(CREEP_CLOCK)?;
    let clock = sim.state.fields.get_mut(id);
    let cap = clock.get(3).copied().unwrap_or(f64::INFINITY);
    if !(dt > 0.0 && dt <= cap) {
        return Err(MechError::param(
            "creep step Δt_c",
            dt,
            format!("must be positive and at most {cap:e} s (the clock's fraction of the shortest relaxation time)"),
        ));
    }
    for c in clock.chunks_exact_mut(4) {
        c[0] += 1.0;
        c[1] = dt;
    }
    let report = sim.relax(opts)?;
    // End the creep step: the next force evaluation commits it (e^K) and the model is
    // elastic until the next creep step.
    let clock = sim.state.fields.get_mut(id);
    for c in clock.chunks_exact_mut(4) {
        c[0] += 1.0;
        c[1] = 0.0;
        c[2] += dt;
    }
    Ok(report)
}

/// The creep time (s): the sum of the creep steps taken.
pub fn creep_time<D: Dim>(sim: &Simulation<D>) -> Result<f64, MechError> {
    Ok(sim.field(CREEP_CLOCK)?.get(2).copied().unwrap_or(0.0))
}
