//! Micro-to-macro calibration (issue 19; MatDEM's automatic training, PFC's inverse
//! modelling): the element and joint parameters ("micro") that make a jointed FDEM
//! sample show the elastic moduli and strengths ("macro") measured in the laboratory.
//!
//! # Elasticity of a jointed mesh (closed form)
//!
//! Every interior face carries an intrinsic cohesive joint, a spring of normal stiffness
//! P_n / h and shear stiffness P_t / h (P as multiples of the element modulus E, h the
//! joint's characteristic length, the mean edge of its two elements) in series with the
//! elements. Under a uniform stress σ every joint j of length ℓ_j and unit normal n
//! opens by δ = h (t_n n / P_n + t_s / P_t), t = σ n, and the joints add the strain
//! Σ_j (ℓ_j / A) sym(δ_j ⊗ n_j) to that of the elements (A the sample's area). For
//! σ = σ_yy e_y e_y in plane strain:
//!
//! - ε_yy = σ [(1 − ν²) + a] / E, with a = Σ_j (ℓ_j h_j / A) E (n_y⁴ / P_n + n_x² n_y² / P_t);
//! - ε_xx = σ [−ν (1 + ν) + b] / E, with b = Σ_j (ℓ_j h_j / A) E n_x² n_y² (1 / P_n − 1 / P_t);
//!
//! with P_n = P_overlap in compression and P_open in tension. [`JointCompliance`] holds a
//! and b; [`macro_elasticity`] gives the sample's plane-strain modulus σ/ε_yy and
//! Poisson's ratio −ε_xx/ε_yy, converted to the isotropic E and ν of plane strain
//! (ν = ν'/(1 + ν'), E = E'(1 − ν²)); [`micro_elasticity`] inverts it exactly (a
//! quadratic in ν). The uniform-stress assumption is exact for straight joint families
//! (the structured patterns) and a lower bound of the stiffness on a random mesh, where
//! stress varies from element to element; the calibration's virtual tests correct it.
//!
//! # Calibration ([`calibrate`])
//!
//! Targets: the sample's E and ν, its UCS and its Brazilian tensile strength
//! ([`Targets`]). Each round runs two virtual tests on the unstructured meshes of the
//! chosen size and seed: a UCS test (to just past the peak) giving E, ν (lateral strain
//! over the middle half of the height) and the UCS, and a Brazilian test giving
//! 2P/(πD). The start is closed form: the element E and ν from [`micro_elasticity`],
//! the joints' cohesion from the Mohr-Coulomb UCS 2c cos φ / (1 − sin φ) and their
//! tensile strength equal to the Brazilian target. After each round:
//!
//! - E_element ← E_element · E_target / E_measured: exact, since with penalties in
//!   multiples of E the elastic response is proportional to E;
//! - ν_element ← ν_element + (ν_target − ν_measured) / (dν_sample/dν_element), the
//!   derivative from the closed form (a Newton step on the measured curve);
//! - (ln c, ln T_s) by a Broyden (secant) step on (ln UCS, ln σt): both strengths depend
//!   on both joint strengths (in the 2 mm runs about d ln UCS = 0.66 d ln c + 0.49 d ln
//!   T_s and d ln σt = 0.87 d ln c + 0.17 d ln T_s: the disc fails in shear under the
//!   platens as much as in tension), so one-parameter updates oscillate, and a Jacobian
//!   started as the identity (each strength proportional to "its" parameter) steps the
//!   ratio UCS/σt the wrong way (the measured Jacobian has a negative determinant:
//!   raising T_s against c raises UCS/σt). It starts from [`PRIOR_JACOBIAN`], those
//!   measured sensitivities rounded, is updated from every round whose step exceeds 2 %
//!   (smaller ones are within the tests' scatter of a few per cent), and a step is
//!   capped at a factor 1.6 per parameter.
//!
//! The fracture energies follow the strengths: G_f1 ∝ T_s² and G_f2 ∝ c², which keeps
//! the template's cohesive-zone lengths E G_f / T_s² (its brittleness relative to the
//! elements). Held fixed, the quick start's G_f1 = 0.5 N/m at a T_s of tens of MPa
//! would give a zone of a hundredth of a millimetre, a joint that breaks at its first
//! softening and a strength that depends on the mesh.
//!
//! It stops when E and ν are within 1 % and both strengths within 3 %
//! ([`Settings`]), or after `max_rounds`; the friction angle, penalties and everything
//! else come from the templates unchanged.

use std::time::Instant;

use serde::{Deserialize, Serialize};

use pcdc_compute::Backend;
use pcdc_mesh::{Dim2, Mesh, NO_NEIGHBOR};

use crate::report::SceneError;
use crate::scenes::platen_test::{JointParams, Rock};
use crate::scenes::{brazilian, ucs};

/// The joints' dimensionless compliance sums of a mesh for uniaxial stress along y
/// (see the module docs), in units of 1 / E.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointCompliance {
    /// a: the joints' axial compliance (ε_yy = σ [(1 − ν²) + a] / E).
    pub axial: f64,
    /// b: the joints' lateral compliance (ε_xx = σ [−ν (1 + ν) + b] / E).
    pub lateral: f64,
}

/// The compliance sums of the joints of `mesh` (one body, shared nodes: a joint on
/// every interior face, as the platen tests split it), under compression (P_n =
/// P_overlap).
pub fn joint_compliance(mesh: &Mesh<Dim2>, joints: &JointParams) -> JointCompliance {
    let x = mesh.coords();
    let mean_edge = |e: usize| {
        let t = mesh.element(e);
        (0..3)
            .map(|k| {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                (x[2 * b] - x[2 * a]).hypot(x[2 * b + 1] - x[2 * a + 1])
            })
            .sum::<f64>()
            / 3.0
    };
    let area: f64 = (0..mesh.n_elements())
        .map(|e| mesh.element_measure(e))
        .sum();
    let faces = mesh.faces();
    let (pn, pt) = (joints.penalty_overlap, joints.penalty_shear);
    let (mut a, mut b) = (0.0, 0.0);
    for f in 0..faces.len() {
        if faces.neighbor[f] == NO_NEIGHBOR {
            continue;
        }
        let nodes = mesh.face(f);
        let (p, q) = (nodes[0] as usize, nodes[1] as usize);
        let (dx, dy) = (x[2 * q] - x[2 * p], x[2 * q + 1] - x[2 * p + 1]);
        let len = dx.hypot(dy);
        // Normal (dy, −dx) / len: n_x² = dy² / len², n_y² = dx² / len².
        let (nx2, ny2) = (dy * dy / (len * len), dx * dx / (len * len));
        let h = 0.5 * (mean_edge(faces.owner[f] as usize) + mean_edge(faces.neighbor[f] as usize));
        let w = len * h / area;
        a += w * (ny2 * ny2 / pn + nx2 * ny2 / pt);
        b += w * nx2 * ny2 * (1.0 / pn - 1.0 / pt);
    }
    JointCompliance {
        axial: a,
        lateral: b,
    }
}

/// The isotropic plane-strain E (Pa) and ν that a sample of elements (E, ν) with joints
/// of compliance `c` shows under uniaxial stress along y (module docs).
pub fn macro_elasticity(young: f64, poisson: f64, c: JointCompliance) -> (f64, f64) {
    let axial = (1.0 - poisson * poisson) + c.axial;
    let e_ps = young / axial;
    let nu_ps = (poisson * (1.0 + poisson) - c.lateral) / axial;
    let nu = nu_ps / (1.0 + nu_ps);
    (e_ps * (1.0 - nu * nu), nu)
}

/// The element E (Pa) and ν that give the sample the macro E and ν of the targets
/// through [`macro_elasticity`] (exact inverse). Fails when the element ν would leave
/// [0, 0.49] (joints stiffen no direction, so a target ν below what the joints alone
/// add cannot be reached), naming the closest reachable macro ν.
pub fn micro_elasticity(
    young: f64,
    poisson: f64,
    c: JointCompliance,
) -> Result<(f64, f64), SceneError> {
    let nu_ps = poisson / (1.0 - poisson);
    let e_ps = young / (1.0 - poisson * poisson);
    // ν(1 + ν) − b = ν'((1 − ν²) + a)  ⇔  (1 + ν')ν² + ν − (ν'(1 + a) + b) = 0.
    let q = nu_ps * (1.0 + c.axial) + c.lateral;
    let disc = 1.0 + 4.0 * (1.0 + nu_ps) * q;
    let nu = if disc >= 0.0 {
        (-1.0 + disc.sqrt()) / (2.0 * (1.0 + nu_ps))
    } else {
        f64::NAN
    };
    const RANGE: (f64, f64) = (0.0, 0.49);
    if !(nu >= RANGE.0 && nu <= RANGE.1) {
        let lo = macro_elasticity(young, RANGE.0, c).1;
        let hi = macro_elasticity(young, RANGE.1, c).1;
        return Err(SceneError::Measurement(format!(
            "the target Poisson's ratio {poisson} cannot be reached on this mesh: it needs an element ν of {nu:.3}, outside 0-0.49; the jointed mesh reaches ν from {lo:.3} to {hi:.3}"
        )));
    }
    let young_micro = e_ps * ((1.0 - nu * nu) + c.axial);
    Ok((young_micro, nu))
}

/// The macro properties to reach (SI).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Targets {
    /// Young's modulus of the sample (Pa).
    pub young: f64,
    /// Poisson's ratio of the sample.
    pub poisson: f64,
    /// Uniaxial compressive strength (Pa).
    pub ucs: f64,
    /// Brazilian (indirect) tensile strength 2P/(πD) (Pa).
    pub tensile: f64,
}

impl Targets {
    fn validate(&self) -> Result<(), SceneError> {
        let bad = |what: &str, v: f64, why: &str| {
            Err(SceneError::Measurement(format!(
                "calibration target {what} = {v}: {why}"
            )))
        };
        for (what, v) in [
            ("young", self.young),
            ("ucs", self.ucs),
            ("tensile", self.tensile),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(what, v, "must be finite and positive (Pa)");
            }
        }
        if !(self.poisson > 0.0 && self.poisson < 0.5) {
            return bad("poisson", self.poisson, "must lie in (0, 0.5)");
        }
        if self.ucs <= self.tensile {
            return bad(
                "ucs",
                self.ucs,
                "must exceed the tensile strength (rock: 5-20 times)",
            );
        }
        Ok(())
    }
}

/// How [`calibrate`] runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Element size of both virtual specimens (m).
    pub mesh_size: f64,
    /// Seed of their unstructured meshes (the first, with `meshes` > 1).
    pub seed: u64,
    /// Meshes per round (seeds `seed`, `seed + 1`, ...): each round averages its
    /// measurements over them, so the parameters fit the rock, not one mesh (the UCS
    /// of five 2 mm meshes spreads by 16 %, `docs/validation.md`); each mesh costs a
    /// UCS and a Brazilian test per round.
    pub meshes: u64,
    /// Most rounds (each a UCS and a Brazilian test).
    pub max_rounds: usize,
    /// Accepted relative error of E and ν.
    pub elastic_tol: f64,
    /// Accepted relative error of the UCS and the Brazilian strength.
    pub strength_tol: f64,
}

impl Default for Settings {
    /// 2 mm meshes, seed 0, one mesh per round, at most 6 rounds, 1 % on E and ν, 3 %
    /// on the strengths.
    fn default() -> Self {
        Settings {
            mesh_size: 0.002,
            seed: 0,
            meshes: 1,
            max_rounds: 6,
            elastic_tol: 0.01,
            strength_tol: 0.03,
        }
    }
}

/// One round of virtual tests: the micro parameters tried and what they gave.
#[derive(Clone, Debug)]
pub struct Round {
    /// Element E (Pa) and ν, density and damping.
    pub rock: Rock,
    /// Joint parameters.
    pub joints: JointParams,
    /// Measured E (Pa).
    pub young: f64,
    /// Measured ν.
    pub poisson: f64,
    /// Measured UCS (Pa).
    pub ucs: f64,
    /// Measured Brazilian strength (Pa).
    pub tensile: f64,
    /// Wall time of the round's two tests (s).
    pub wall_s: f64,
}

impl Round {
    /// Relative errors (E, ν, UCS, tensile) against `t`.
    pub fn errors(&self, t: &Targets) -> [f64; 4] {
        [
            self.young / t.young - 1.0,
            self.poisson / t.poisson - 1.0,
            self.ucs / t.ucs - 1.0,
            self.tensile / t.tensile - 1.0,
        ]
    }
}

/// What [`calibrate`] found.
#[derive(Clone, Debug)]
pub struct Calibration {
    /// The targets.
    pub targets: Targets,
    /// Every round, in order; the last is the calibrated one when `converged`, else the
    /// best (smallest largest error relative to its tolerance) is [`Calibration::best`].
    pub rounds: Vec<Round>,
    /// Whether a round met every tolerance.
    pub converged: bool,
    /// Virtual tests run (two per mesh and round).
    pub virtual_tests: usize,
    /// Total wall time (s).
    pub wall_s: f64,
    /// The settings used.
    pub settings: Settings,
}

impl Calibration {
    /// The round that met the tolerances, or the closest one.
    pub fn best(&self) -> &Round {
        let score = |r: &Round| {
            let e = r.errors(&self.targets);
            (e[0].abs() / self.settings.elastic_tol)
                .max(e[1].abs() / self.settings.elastic_tol)
                .max(e[2].abs() / self.settings.strength_tol)
                .max(e[3].abs() / self.settings.strength_tol)
        };
        self.rounds
            .iter()
            .min_by(|a, b| score(a).total_cmp(&score(b)))
            .expect("calibrate runs at least one round")
    }

    /// The calibrated parameters as a TOML fragment for a UCS or Brazilian scene file
    /// (`[rock]` and `[joints]` tables, with the targets and the mesh as comments).
    pub fn toml_fragment(&self) -> String {
        let r = self.best();
        let t = &self.targets;
        let j = &r.joints;
        format!(
            "# Calibrated by `cargo run --release --example calibrate` for the sample targets\n\
             # E = {:.4e} Pa, nu = {}, UCS = {:.4e} Pa, Brazilian tensile strength = {:.4e} Pa\n\
             # on unstructured meshes of {} m, seeds {} to {} (achieved, mean over them: E {:.4e}, nu {:.4}, UCS {:.4e}, tensile {:.4e}).\n\
             [rock]\nyoung = {:.6e}\npoisson = {:.6}\ndensity = {}\ndamping = {}\n\n\
             [joints]\nfriction_deg = {}\ncohesion = {:.6e}\ntensile_strength = {:.6e}\ngf1 = {}\ngf2 = {}\n\
             penalty_normal = {}\npenalty_shear = {}\npenalty_overlap = {}\n",
            t.young, t.poisson, t.ucs, t.tensile,
            self.settings.mesh_size, self.settings.seed, self.settings.seed.saturating_add(self.settings.meshes.max(1) - 1),
            r.young, r.poisson, r.ucs, r.tensile,
            r.rock.young, r.rock.poisson, r.rock.density, r.rock.damping,
            j.friction_deg, j.cohesion, j.tensile_strength, j.gf1, j.gf2,
            j.penalty_normal, j.penalty_shear, j.penalty_overlap,
        )
    }
}

/// Finds element and joint parameters that give `targets` (module docs). The UCS and
/// Brazilian templates give everything else (platens, contact, loading, friction angle,
/// fracture energies, penalties, density, damping); their meshes are replaced by
/// unstructured ones of `settings`. `progress` sees every round.
///
/// Errors: bad targets or settings, a target ν the jointed mesh cannot reach (with the
/// reachable range), or a failed virtual test.
pub fn calibrate(
    backend: &Backend,
    targets: &Targets,
    ucs_template: &ucs::Params,
    brazilian_template: &brazilian::Params,
    settings: &Settings,
    progress: &mut dyn FnMut(usize, &Round),
) -> Result<Calibration, SceneError> {
    targets.validate()?;
    if settings.max_rounds == 0 || settings.meshes == 0 {
        return Err(SceneError::Measurement(
            "calibration: max_rounds and meshes must be at least 1".into(),
        ));
    }
    let start = Instant::now();
    let mut pu = ucs_template.clone();
    pu.sample.pattern = ucs::MeshPattern::Unstructured;
    pu.sample.mesh_size = settings.mesh_size;
    pu.sample.seed = settings.seed;
    pu.elasticity = ucs::Elasticity::Element;
    pu.output.frames = 0;
    // Just past the peak is enough for E, ν and the UCS.
    pu.loading.stop_fraction = pu.loading.stop_fraction.max(0.9);
    let mut pb = brazilian_template.clone();
    pb.disc.pattern = brazilian::DiscPattern::Unstructured;
    pb.disc.mesh_size = settings.mesh_size;
    pb.disc.seed = settings.seed;
    pb.output.frames = 0;
    pb.loading.stop_fraction = pb.loading.stop_fraction.max(0.9);
    // Closed-form start.
    let mesh = ucs::specimen(&pu)?;
    let compliance = joint_compliance(&mesh, &pu.joints);
    let (mut young, mut poisson) = micro_elasticity(targets.young, targets.poisson, compliance)?;
    let phi = pu.joints.friction_deg.to_radians();
    let template = pu.joints.clone();
    let mut joints = pu.joints.clone();
    let scaled = |joints: &mut JointParams, cohesion: f64, tensile: f64| {
        joints.cohesion = cohesion;
        joints.tensile_strength = tensile;
        joints.gf1 = template.gf1 * (tensile / template.tensile_strength).powi(2);
        joints.gf2 = template.gf2 * (cohesion / template.cohesion).powi(2);
    };
    scaled(
        &mut joints,
        targets.ucs * (1.0 - phi.sin()) / (2.0 * phi.cos()),
        targets.tensile,
    );
    let mut rounds: Vec<Round> = Vec::new();
    let mut converged = false;
    let mut jacobian = PRIOR_JACOBIAN;
    for round in 0..settings.max_rounds {
        let t0 = Instant::now();
        let rock = Rock {
            young,
            poisson,
            ..pu.rock.clone()
        };
        pu.rock = rock.clone();
        pu.joints = joints.clone();
        pb.rock = rock.clone();
        pb.joints = joints.clone();
        // The mean over the round's meshes of E, ν, UCS and σt.
        let mut sum = [0.0; 4];
        for k in 0..settings.meshes {
            pu.sample.seed = settings.seed.wrapping_add(k);
            pb.disc.seed = settings.seed.wrapping_add(k);
            let u = ucs::run(backend, &pu, &mut |_| {})?;
            let b = brazilian::run(backend, &pb, &mut |_| {})?;
            // The sample's E from its plane-strain slope with its own ν.
            sum[0] += u.slope * (1.0 - u.poisson * u.poisson);
            sum[1] += u.poisson;
            sum[2] += u.ucs;
            sum[3] += b.tensile_strength;
        }
        let n = settings.meshes as f64;
        let r = Round {
            rock,
            joints: joints.clone(),
            young: sum[0] / n,
            poisson: sum[1] / n,
            ucs: sum[2] / n,
            tensile: sum[3] / n,
            wall_s: t0.elapsed().as_secs_f64(),
        };
        if !(r.young > 0.0 && r.poisson.is_finite() && r.ucs > 0.0 && r.tensile > 0.0) {
            return Err(SceneError::Measurement(format!(
                "calibration round {round}: a virtual test measured nothing usable ({r:?})"
            )));
        }
        progress(round, &r);
        let e = r.errors(targets);
        let done = e[0].abs() <= settings.elastic_tol
            && e[1].abs() <= settings.elastic_tol
            && e[2].abs() <= settings.strength_tol
            && e[3].abs() <= settings.strength_tol;
        // Updates (module docs).
        young *= targets.young / r.young;
        let dnu = 1e-4;
        let slope = (macro_elasticity(young, poisson + dnu, compliance).1
            - macro_elasticity(young, poisson - dnu, compliance).1)
            / (2.0 * dnu);
        poisson = (poisson + (targets.poisson - r.poisson) / slope).clamp(0.0, 0.49);
        let (x, y) = (log_strengths_of_joints(&r), log_strengths(&r));
        if let Some(prev) = rounds.last() {
            broyden_update(
                &mut jacobian,
                sub2(x, log_strengths_of_joints(prev)),
                sub2(y, log_strengths(prev)),
            );
        }
        let goal = [targets.ucs.ln(), targets.tensile.ln()];
        let step = solve2(&jacobian, sub2(goal, y)).unwrap_or_else(|| {
            // A singular secant (noise): start again from the prior.
            jacobian = PRIOR_JACOBIAN;
            sub2(goal, y)
        });
        let cap = 1.6f64.ln();
        let step = step.map(|d| d.clamp(-cap, cap));
        scaled(&mut joints, (x[0] + step[0]).exp(), (x[1] + step[1]).exp());
        rounds.push(r);
        if done {
            converged = true;
            break;
        }
    }
    Ok(Calibration {
        targets: targets.clone(),
        virtual_tests: 2 * settings.meshes as usize * rounds.len(),
        rounds,
        converged,
        wall_s: start.elapsed().as_secs_f64(),
        settings: settings.clone(),
    })
}

/// The starting Jacobian d(ln UCS, ln σt)/d(ln c, ln T_s) of the calibration: the
/// sensitivities measured between rounds of a 2 mm calibration to E = 30 GPa,
/// UCS = 100 MPa, σt = 8 MPa (module docs), rounded.
pub const PRIOR_JACOBIAN: [[f64; 2]; 2] = [[0.7, 0.45], [0.8, 0.2]];

/// (ln c, ln T_s) of a round's joints.
fn log_strengths_of_joints(r: &Round) -> [f64; 2] {
    [r.joints.cohesion.ln(), r.joints.tensile_strength.ln()]
}

/// (ln UCS, ln σt) a round measured.
fn log_strengths(r: &Round) -> [f64; 2] {
    [r.ucs.ln(), r.tensile.ln()]
}

fn sub2(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

/// Broyden's update J += (Δy − J Δx) Δxᵀ / (Δxᵀ Δx); skipped for a step below 2 % (in
/// ln), which the virtual tests' scatter would swamp.
fn broyden_update(j: &mut [[f64; 2]; 2], dx: [f64; 2], dy: [f64; 2]) {
    let n2 = dx[0] * dx[0] + dx[1] * dx[1];
    if n2 < 0.02 * 0.02 {
        return;
    }
    for i in 0..2 {
        let r = dy[i] - (j[i][0] * dx[0] + j[i][1] * dx[1]);
        for k in 0..2 {
            j[i][k] += r * dx[k] / n2;
        }
    }
}

/// Solves J d = r; `None` when J is near singular.
fn solve2(j: &[[f64; 2]; 2], r: [f64; 2]) -> Option<[f64; 2]> {
    let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    let scale = j.iter().flatten().map(|v| v.abs()).fold(0.0, f64::max);
    if det.abs() <= 0.05 * scale * scale || det.is_nan() {
        return None;
    }
    Some([
        (r[0] * j[1][1] - r[1] * j[0][1]) / det,
        (j[0][0] * r[1] - j[1][0] * r[0]) / det,
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::ucs;

    /// The mesh sums reproduce the closed form of the straight joint families of the
    /// structured patterns (whose uniform stress is exact).
    #[test]
    fn mesh_sums_match_the_joint_families() {
        for pattern in [
            ucs::MeshPattern::Equilateral,
            ucs::MeshPattern::SteepCrossed,
        ] {
            let mut p = ucs::Params::reduced();
            p.sample.pattern = pattern;
            p.elasticity = ucs::Elasticity::Element;
            let mesh = ucs::specimen(&p).unwrap();
            let c = joint_compliance(&mesh, &p.joints);
            let (e, nu) = (p.rock.young, p.rock.poisson);
            let from_mesh = (1.0 - nu * nu) / ((1.0 - nu * nu) + c.axial) * e;
            let families = ucs::jointed_modulus(&p);
            // The sides' half triangles differ between the two (a few % of the sums).
            assert!(
                (from_mesh / families - 1.0).abs() < 0.005,
                "{pattern:?}: {from_mesh} vs {families}"
            );
        }
    }

    const IDENTITY: [[f64; 2]; 2] = [[1.0, 0.0], [0.0, 1.0]];

    /// Broyden's method finds the joint strengths of a linear-in-logs model with
    /// cross-coupling like the measured one.
    #[test]
    fn broyden_solves_a_coupled_power_law() {
        let truth = [[0.66, 0.49], [0.87, 0.17]];
        let model = |x: [f64; 2]| {
            [
                truth[0][0] * x[0] + truth[0][1] * x[1],
                truth[1][0] * x[0] + truth[1][1] * x[1],
            ]
        };
        let goal = model([3.0, 2.0]);
        let (mut x, mut j) = ([2.5, 2.5], IDENTITY);
        let mut prev: Option<([f64; 2], [f64; 2])> = None;
        for _ in 0..12 {
            let y = model(x);
            if let Some((px, py)) = prev {
                broyden_update(&mut j, sub2(x, px), sub2(y, py));
            }
            let step = solve2(&j, sub2(goal, y)).unwrap_or_else(|| {
                j = IDENTITY;
                sub2(goal, y)
            });
            prev = Some((x, y));
            x = [
                x[0] + step[0].clamp(-0.47, 0.47),
                x[1] + step[1].clamp(-0.47, 0.47),
            ];
        }
        assert!(
            (x[0] - 3.0).abs() < 1e-6 && (x[1] - 2.0).abs() < 1e-6,
            "{x:?}"
        );
    }

    #[test]
    fn micro_inverts_macro() {
        let c = JointCompliance {
            axial: 0.06,
            lateral: -0.01,
        };
        let (e, nu) = micro_elasticity(30e9, 0.25, c).unwrap();
        let (em, num) = macro_elasticity(e, nu, c);
        assert!((em / 30e9 - 1.0).abs() < 1e-12 && (num - 0.25).abs() < 1e-12);
        assert!(e > 30e9, "{e} {nu}");
        let err = micro_elasticity(
            30e9,
            0.01,
            JointCompliance {
                axial: 0.5,
                lateral: -0.3,
            },
        )
        .unwrap_err();
        assert!(err.to_string().contains("cannot be reached"), "{err}");
    }
}
