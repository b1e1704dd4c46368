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
    compose, compose_plane, plane, principal, principal_lanes, PlanePrincipal, Principal,
    JACOBI_STOP, LANES,
};
use crate::MechError;

mod plane_lanes;
mod surfaces;
use plane_lanes::{shear_first_lanes, LaneSurfaces, PlaneLanes, BLOCK};
use surfaces::{shear_return, FirstTry};
pub use surfaces::{Return, Surfaces};

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
        // Fewer plane candidates than this go one at a time (a lone one would carry seven
        // idle lanes; the threshold is a choice, not tuned by measurement).
        const PLANE_LANES_FROM: usize = 2;
        let stride = stride.max(1);
        // As the default: elements beyond the shortest of the three are left alone.
        let n = inputs.len().min(stresses.len()).min(states.len() / stride);
        let (inputs, stresses) = (&inputs[..n], &mut stresses[..n]);
        // The shear plane's constants once per call when the surfaces are the model's
        // (with softening they are found per element).
        let sp_model = self.surfaces.shear_plane();
        let model_lanes = if SOFT {
            LaneSurfaces::default()
        } else {
            LaneSurfaces::splat(&self.surfaces, &sp_model)
        };
        let mut lanes = PlaneLanes::default();
        let blocks = inputs
            .chunks(BLOCK)
            .zip(stresses.chunks_mut(BLOCK))
            .zip(states.chunks_mut(BLOCK * stride));
        for ((inputs, stresses), states) in blocks {
            // The elastic trials first, with the surfaces of each element's plastic
            // strains (looked up only with softening); those not surely elastic are
            // candidates. Each element's class (0 elastic, 1 plane candidate, 2 other
            // candidate) is found first and the lists built after: a list's length
            // carried from element to element would make each trial wait for the one
            // before.
            let mut surfaces = [Surfaces::default(); BLOCK];
            let mut class = [0u8; BLOCK];
            for (i, (x, s)) in inputs.iter().zip(stresses.iter_mut()).enumerate() {
                let st = &mut states[i * stride..(i + 1) * stride];
                let yields = if SOFT {
                    let f = self.surfaces_at(st[state::SHEAR_STRAIN], st[state::TENSION_STRAIN]);
                    surfaces[i] = f;
                    self.trial_with(&f, x.dstrain, s, st)
                } else {
                    self.trial_with(&self.surfaces, x.dstrain, s, st)
                };
                class[i] = u8::from(yields) * (2 - u8::from(is_plane(s)));
            }
            let f_of = |i: usize| if SOFT { &surfaces[i] } else { &self.surfaces };
            let sp_of = |f: &Surfaces| if SOFT { f.shear_plane() } else { sp_model };
            // Then the candidates: plane ones [`LANES`] at a time where there are enough
            // (closed form, straight onto the shear plane where that is the return,
            // `plane_lanes`), else one at a time; 3D ones wait for their decompositions
            // in lanes. A candidate whose first try is not the shear plane takes the
            // general search without a second first try; the histories of shear-plane
            // returns are written after the run, so that the square roots there overlap
            // (the plane lanes compute their increments themselves).
            let (mut flat, mut nf) = ([0usize; BLOCK], 0);
            let (mut wait, mut n) = ([0usize; BLOCK], 0);
            for (i, &c) in class[..inputs.len()].iter().enumerate() {
                flat[nf] = i;
                nf += usize::from(c == 1);
                wait[n] = i;
                n += usize::from(c == 2);
            }
            let (mut shear, mut ns) = ([(0usize, 0.0f64, 0.0f64); BLOCK], 0);
            let general = |i: usize, p: &PlanePrincipal, stress: &mut Sym6, states: &mut [f64]| {
                if let Some(r) = f_of(i).general_return(&p.values) {
                    *stress = compose_plane(&r.stress, p);
                    record(&r, &mut states[i * stride..]);
                }
            };
            for group in flat[..nf].chunks(LANES) {
                if group.len() < PLANE_LANES_FROM {
                    for &i in group {
                        let (f, p) = (f_of(i), plane(&stresses[i]));
                        match f.shear_first(&p.values, &sp_of(f)) {
                            FirstTry::Elastic => {}
                            FirstTry::Shear(lambda, o) => {
                                stresses[i] = compose_plane(&o, &p);
                                shear[ns] = (i, lambda, f.n_psi);
                                ns += 1;
                            }
                            FirstTry::Other => general(i, &p, &mut stresses[i], states),
                        }
                    }
                    continue;
                }
                if SOFT {
                    let mut ls = LaneSurfaces::default();
                    for (l, &i) in group.iter().enumerate() {
                        ls.set(l, &surfaces[i], &surfaces[i].shear_plane());
                    }
                    shear_first_lanes(stresses, group, &ls, &mut lanes);
                } else {
                    shear_first_lanes(stresses, group, &model_lanes, &mut lanes);
                }
                for (l, &i) in group.iter().enumerate() {
                    let kind = lanes.kind[l];
                    if kind == plane_lanes::SHEAR {
                        stresses[i] = lanes.stress(l);
                        if lanes.yielded[l] > 0.0 {
                            let st = &mut states[i * stride..];
                            st[state::SHEAR_NOW] = 1.0;
                            st[state::SHEAR_PAST] = 1.0;
                            st[state::SHEAR_STRAIN] += lanes.dkappa[l];
                        }
                    } else if kind == plane_lanes::OTHER {
                        // The lanes keep no decomposition: the same one again (rare:
                        // edges, corners, tension).
                        let p = plane(&stresses[i]);
                        general(i, &p, &mut stresses[i], states);
                    }
                }
            }
            // The 3D ones: their decompositions, [`LANES`] at a time where there are
            // enough, then the shear plane at once if it is the return, else the general
            // search.
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
                            if let Some(r) = f.general_return(&p.values) {
                                stresses[i] = compose(&r.stress, &p.axes);
                                record(&r, &mut states[i * stride..]);
                            }
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
    /// the run. Plane (2D) trials take that first try [`LANES`] at a time in one
    /// branch-free kernel (`plane_lanes`), decomposition and recomposition included.
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
