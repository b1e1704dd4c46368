//! The joint kinematics [`CohesiveJoints`] publishes for other physics (opening, sliding,
//! normal: `pcdc_cohesive::fields`) against their closed forms, for two elements with
//! one joint between them moved apart, sheared, pressed together and rotated by
//! prescribed displacements (one force evaluation, CPU; CPU-GPU parity is in
//! `gpu_parity.rs`).
//!
//! With side A held and side B's nodes displaced by d_k, the gap at the face centroid is
//! δ̄ = mean_k d_k; for a joint whose sides still coincide the normal n is that of side
//! A's face (from A to B), the opening o = δ̄·n and the sliding s = δ̄ − o n.

use pcdc_cohesive::{
    CohesiveJoints, IntrinsicCzmParams, JOINT_DAMAGE, JOINT_NORMAL, JOINT_OPENING, JOINT_SLIDING,
};
use pcdc_compute::{
    names, Backend, ComputeError, FieldId, FieldUse, ForceContext, InitContext, Physics, Simulation,
};
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{split_nodes, Dim, Dim2, Dim3, Mesh, Range};
use std::sync::{Arc, Mutex};

/// Tolerance on gaps (m): positions are X + u with |X| ~ 1 m, so a gap carries a few
/// ulps of the coordinates (2.2e-16 m each), whatever its size.
const TOL: f64 = 1e-15;

/// The cohesive joint model of these tests.
fn czm() -> pcdc_cohesive::IntrinsicCzm {
    IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 2e6,
        tensile_strength: 1e6,
        gf1: 0.01,
        gf2: 0.1,
        penalty_open: 3e11,
        penalty_shear: 3e11,
        penalty_overlap: 3e12,
    }
    .build()
    .unwrap()
}

/// Soft elements (their forces do not matter) and a cohesive joint model.
fn sim<D: Dim>(mesh: Mesh<D>) -> Simulation<D> {
    let soft = LinearElastic::new(1e6, 0.25, 2600.0).unwrap();
    let czm = czm();
    Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, soft))
        .physics(CohesiveJoints::new().model(Range::All, czm))
        .build()
        .unwrap()
}

/// Displaces side B's node `k` (of joint 0) by `d(k)` and its element's other nodes by
/// `rest`, leaves side A in place, evaluates the forces once and returns (opening,
/// sliding, normal) of joint 0.
fn evaluate<D: Dim>(
    sim: &mut Simulation<D>,
    d: impl Fn(usize) -> [f64; 3],
    rest: [f64; 3],
) -> (f64, Vec<f64>, Vec<f64>) {
    let dim = D::D;
    let joint = sim.mesh().interfaces().get(0).unwrap();
    let (side_b, elem_b) = (joint.side_b.to_vec(), joint.elements[1] as usize);
    let others: Vec<u32> = sim
        .mesh()
        .element(elem_b)
        .iter()
        .copied()
        .filter(|n| !side_b.contains(n))
        .collect();
    sim.state.u.fill(0.0);
    for (k, &n) in side_b.iter().enumerate() {
        sim.state.u[n as usize * dim..(n as usize + 1) * dim].copy_from_slice(&d(k)[..dim]);
    }
    for n in others {
        sim.state.u[n as usize * dim..(n as usize + 1) * dim].copy_from_slice(&rest[..dim]);
    }
    sim.evaluate_forces().unwrap();
    (
        sim.field(JOINT_OPENING).unwrap()[0],
        sim.field(JOINT_SLIDING).unwrap()[..dim].to_vec(),
        sim.field(JOINT_NORMAL).unwrap()[..dim].to_vec(),
    )
}

fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
}

/// Unit square cut on its diagonal from (0, 0) to (1, 1), both triangles split: one joint.
/// Side A is the lower-right triangle (the face's owner), so n = (−1, 1)/√2 and the
/// tangent t = (1, 1)/√2.
fn square() -> Mesh<Dim2> {
    let m = Mesh::<Dim2>::new(
        vec![0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0],
        vec![0, 1, 2, 0, 2, 3],
    )
    .unwrap();
    let s = split_nodes(&m, &Range::All).unwrap();
    assert_eq!(s.interfaces().len(), 1);
    s
}

#[test]
fn opening_sliding_normal_2d_closed_form() {
    let r = std::f64::consts::FRAC_1_SQRT_2;
    let (n, t) = ([-r, r], [r, r]);
    let mut sim = sim(square());
    let at = |a: f64, b: f64| [a * n[0] + b * t[0], a * n[1] + b * t[1], 0.0];
    // Unloaded: closed, no sliding, the normal already published.
    let (o, s, nn) = evaluate(&mut sim, |_| [0.0; 3], [0.0; 3]);
    assert_eq!(o, 0.0);
    assert_eq!(s, vec![0.0, 0.0]);
    assert!(close(&nn, &n, 1e-15), "{nn:?}");
    // Pulled apart by 1 µm along n and slid by 0.3 µm along t (side B rigidly).
    let (o, s, nn) = evaluate(&mut sim, |_| at(1e-6, 3e-7), at(1e-6, 3e-7));
    assert!((o - 1e-6).abs() <= TOL, "opening {o:e}");
    assert!(close(&s, &[3e-7 * t[0], 3e-7 * t[1]], TOL), "sliding {s:?}");
    // The midplane moved rigidly: same normal.
    assert!(close(&nn, &n, 1e-15), "{nn:?}");
    // Pressed together: negative opening.
    let (o, s, _) = evaluate(&mut sim, |_| at(-2e-7, 0.0), at(-2e-7, 0.0));
    assert!((o + 2e-7).abs() <= TOL, "opening {o:e}");
    assert!(close(&s, &[0.0, 0.0], TOL), "sliding {s:?}");
    // Opened 1 µm at one end and 3 µm at the other (side B rotated about the far
    // corner): the opening is the mean, 2 µm, the normal turns by 2 µm / (2 √2 m).
    let (o, s, nn) = evaluate(
        &mut sim,
        |k| if k == 0 { at(1e-6, 0.0) } else { at(3e-6, 0.0) },
        at(0.0, 0.0),
    );
    let turn = 2e-6 / (2.0 * 2f64.sqrt());
    let n_turned = [n[0] + turn * t[0], n[1] + turn * t[1]];
    let scale = (n_turned[0].powi(2) + n_turned[1].powi(2)).sqrt();
    let n_turned = [n_turned[0] / scale, n_turned[1] / scale];
    assert!(close(&nn, &n_turned, 1e-12), "{nn:?} vs {n_turned:?}");
    let gbar = at(2e-6, 0.0);
    let o_exact = gbar[0] * n_turned[0] + gbar[1] * n_turned[1];
    assert!((o - o_exact).abs() <= TOL, "opening {o:e} vs {o_exact:e}");
    assert!((o - 2e-6).abs() <= TOL, "opening {o:e}");
    let s_exact = [
        gbar[0] - o_exact * n_turned[0],
        gbar[1] - o_exact * n_turned[1],
    ];
    assert!(close(&s, &s_exact, TOL), "{s:?} vs {s_exact:?}");
    // Sliding stays orthogonal to the normal.
    assert!((s[0] * nn[0] + s[1] * nn[1]).abs() <= 1e-21);
}

#[test]
fn broken_joints_still_publish_their_kinematics() {
    let r = std::f64::consts::FRAC_1_SQRT_2;
    let mut sim = sim(square());
    let id = sim.state.fields.id(JOINT_DAMAGE).unwrap();
    sim.state.fields.get_mut(id)[0] = 1.0;
    // Far apart (5 mm along n, 1 mm along t): no joint force, but the kinematics.
    let d = [-5e-3 * r + 1e-3 * r, 5e-3 * r + 1e-3 * r, 0.0];
    let (o, s, _) = evaluate(&mut sim, |_| d, d);
    assert!((o - 5e-3).abs() <= TOL, "opening {o:e}");
    assert!(close(&s, &[1e-3 * r, 1e-3 * r], TOL), "sliding {s:?}");
    assert_eq!(sim.field(JOINT_DAMAGE).unwrap()[0], 1.0);
    // Opened 10 nm (before the peak): the intact joint pulls back, the broken one not.
    let small = [-1e-8 * r, 1e-8 * r, 0.0];
    let (o, _, _) = evaluate(&mut sim, |_| small, small);
    assert!((o - 1e-8).abs() <= TOL, "opening {o:e}");
    let f_broken = sim.evaluate_forces().unwrap().to_vec();
    let mut intact = self::sim(square());
    evaluate(&mut intact, |_| small, small);
    assert!(intact.field(JOINT_DAMAGE).unwrap()[0] < 1.0);
    let f_intact = intact.evaluate_forces().unwrap().to_vec();
    assert_ne!(f_broken, f_intact, "an intact joint pulls back");
}

/// Two tetrahedra on either side of the triangle (0, 0, 0), (1, 0, 0), (0, 1, 0): side A
/// above it (z > 0, the face's owner), so n = (0, 0, −1).
fn two_tets() -> Mesh<Dim3> {
    let coords = vec![
        0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -1.0,
    ];
    let m = Mesh::<Dim3>::new_reoriented(coords, vec![0, 1, 2, 3, 0, 1, 2, 4]).unwrap();
    let s = split_nodes(&m, &Range::All).unwrap();
    assert_eq!(s.interfaces().len(), 1);
    s
}

#[test]
fn opening_sliding_normal_3d_closed_form() {
    let mut sim = sim(two_tets());
    let (_, _, n) = evaluate(&mut sim, |_| [0.0; 3], [0.0; 3]);
    assert!(close(&n, &[0.0, 0.0, -1.0], 1e-15), "{n:?}");
    // Side B moved rigidly by (0.2, -0.1, -0.5) µm: 0.5 µm open, sliding (0.2, -0.1, 0).
    let d = [2e-7, -1e-7, -5e-7];
    let (o, s, n) = evaluate(&mut sim, |_| d, d);
    assert!((o - 5e-7).abs() <= TOL, "opening {o:e}");
    assert!(close(&s, &[2e-7, -1e-7, 0.0], TOL), "sliding {s:?}");
    assert!(close(&n, &[0.0, 0.0, -1.0], 1e-15), "{n:?}");
    // Side B's face opened by 1, 2 and 6 µm at its three nodes: mean 3 µm.
    let (o, s, _) = evaluate(&mut sim, |k| [0.0, 0.0, -[1e-6, 2e-6, 6e-6][k]], [0.0; 3]);
    assert!((o - 3e-6).abs() <= TOL, "opening {o:e}");
    let slide = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    // Tilting the midplane by ~µm/m tilts n by as much: the sliding is second order.
    assert!(slide <= 1e-10, "sliding {s:?}");
}

/// Another physics reading the opening through the shared key (as pcdc-hydro will, with
/// no dependency on pcdc-cohesive): declared as a reader of the current step, it runs
/// after the joints and sees this step's values.
struct OpeningReader {
    id: Option<FieldId>,
    seen: Arc<Mutex<Vec<f64>>>,
}

impl<D: Dim> Physics<D> for OpeningReader {
    fn name(&self) -> &str {
        "opening reader"
    }
    fn fields(&self, _mesh: &Mesh<D>) -> Vec<FieldUse> {
        vec![names::JOINT_OPENING.read::<D>()]
    }
    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        self.id = Some(ctx.fields.id(names::JOINT_OPENING)?);
        Ok(())
    }
    fn compute_forces(&mut self, ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        let id = self.id.expect("init ran");
        *self.seen.lock().unwrap() = ctx.fields.get(id).to_vec();
        Ok(())
    }
}

#[test]
fn another_physics_reads_the_opening_through_the_shared_key() {
    let seen = Arc::new(Mutex::new(Vec::new()));
    let soft = LinearElastic::new(1e6, 0.25, 2600.0).unwrap();
    let czm = czm();
    let mut sim = Simulation::builder(two_tets(), Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, soft))
        .physics(CohesiveJoints::new().model(Range::All, czm))
        .physics(OpeningReader {
            id: None,
            seen: seen.clone(),
        })
        .build()
        .unwrap();
    assert_eq!(JOINT_OPENING, names::JOINT_OPENING);
    let d = [0.0, 0.0, -4e-7];
    let (o, _, _) = evaluate(&mut sim, |_| d, d);
    assert!((o - 4e-7).abs() <= TOL, "opening {o:e}");
    assert_eq!(*seen.lock().unwrap(), vec![o]);
}
