//! CPU–GPU parity of the face-joints: one scene body, instantiated for `Backend::cpu(1)`
//! and the GPU backend (2D edge joints and 3D triangle-face joints with 3 and 7 Gauss
//! points).
//!
//! The scenes: a bar of split elements (every element with its own nodes, a joint on
//! every interior face) is stretched and sheared by an initial velocity field until a
//! band of weak joints softens and breaks, so that the pre-peak, softening, secant
//! unloading, broken and overlap branches of the intrinsic cohesive zone model run (and
//! two models share the kernel); in the fracture scenes a pre-existing Mohr-Coulomb
//! fracture crosses the bar, which is compressed and sheared so that it slides. The
//! elements carry viscous damping; the overlap penalty equals the opening slope
//! P_open/h so that the normal traction is smooth at zero opening.
//!
//! Measured, and compared: displacement (f64: max |Δu| / max |u| ≤ 1e-12), joint damage
//! (absolute), joint history, broken faces (f64: identical), and the joint kinematics
//! published for other physics, read back from the device like every field: opening and
//! sliding (a gap is a difference of positions, so f64 asks them within 4 × the
//! displacement bar × max |u|) and the unit normal (within that over the cell size). Fracture is an unstable
//! process that amplifies any rounding difference, so every test also runs the CPU a
//! second time with its initial velocities perturbed by 1e-15 (relative) and prints how
//! far that run drifts: the GPU difference is of the same size, the conditioning of the
//! scene rather than a discrepancy of the kernels (their forces agree bit for bit on
//! most degrees of freedom: see `joint_forces_agree_to_rounding`). Where the scene is
//! more sensitive than the 1e-12 bar (the sliding fracture), the bar is four times that
//! drift. In f32 the difference is measured and printed. Without a GPU adapter the tests
//! skip (and fail with PCDC_REQUIRE_GPU=1).

use std::sync::Arc;

use pcdc_cohesive::{
    joints_on_fractures, CohesiveJoints, Fracture, IntrinsicCzmParams, JointInput, JointModel,
    MohrCoulombJointParams, Traction, WgslJointModel, BROKEN_FACE, JOINT_DAMAGE, JOINT_NORMAL,
    JOINT_OPENING, JOINT_SLIDING, JOINT_STATE,
};
use pcdc_compute::gpu::gpu_test_backend;
use pcdc_compute::{Backend, Precision, Simulation};
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{builders, split_nodes, Dim, Dim2, Dim3, Mesh, Range};

const E: f64 = 30e9;
/// Cell size of the bars (m).
const CELL: f64 = 0.005;

/// Deterministic pseudo-random numbers in [-1, 1).
fn noise(i: usize) -> f64 {
    let x = (i as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let x = (x ^ (x >> 29)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    ((x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// A scene: initial velocity field, pre-existing fracture, Gauss points, steps.
#[derive(Clone)]
struct Scene {
    /// Velocity along the bar's long axis at its ends (m/s; > 0 stretches).
    pull: f64,
    /// Velocity along x at the ends (m/s), antisymmetric: shears the bar.
    shear: f64,
    /// Pre-existing Mohr-Coulomb fracture.
    fracture: Option<Fracture>,
    /// Gauss points per joint face in 3D.
    gauss_3d: usize,
    /// Explicit steps.
    steps: u64,
    /// Relative perturbation of the initial velocities (0 for the compared runs).
    perturb: f64,
    /// Hide the built-in models' types ([`Opaque`], `Mechanics::material_arc`), so the
    /// physics call them through their trait objects instead of inline.
    opaque: bool,
}

/// A joint model that hides its type: the joint physics calls it through its trait
/// object (the path of a user's plugin), not inline as it calls the built-in models.
#[derive(Debug)]
struct Opaque<M>(M);

impl<M: JointModel> JointModel for Opaque<M> {
    fn name(&self) -> &str {
        self.0.name()
    }
    fn n_state(&self) -> usize {
        self.0.n_state()
    }
    fn init_state(&self, state: &mut [f64]) {
        self.0.init_state(state)
    }
    fn traction(&self, o: f64, slip: &[f64], h: f64, state: &mut [f64]) -> Traction {
        self.0.traction(o, slip, h, state)
    }
    fn traction_with(&self, input: &JointInput<'_>, state: &mut [f64]) -> Traction {
        self.0.traction_with(input, state)
    }
    fn max_stiffness(&self, h: f64) -> f64 {
        self.0.max_stiffness(h)
    }
    fn is_broken(&self, state: &[f64]) -> bool {
        self.0.is_broken(state)
    }
    fn damage(&self, state: &[f64]) -> f64 {
        self.0.damage(state)
    }
    fn wgsl(&self) -> Option<WgslJointModel> {
        self.0.wgsl()
    }
}

/// Stretch with some shear, 400 steps: the weak band softens and breaks.
fn pull() -> Scene {
    Scene {
        pull: 2.0,
        shear: 0.5,
        fracture: None,
        gauss_3d: 3,
        steps: 400,
        perturb: 0.0,
        opaque: false,
    }
}

/// Slight compression and strong shear, 200 steps: the fracture slides (its plastic
/// branch runs), joints of the weak band soften in mixed mode.
fn slide(fracture: Fracture) -> Scene {
    Scene {
        pull: -0.2,
        shear: 2.0,
        fracture: Some(fracture),
        gauss_3d: 3,
        steps: 200,
        perturb: 0.0,
        opaque: false,
    }
}

/// What a run leaves: displacement, joint damage, broken faces, joint history, joint
/// opening, sliding and normal.
struct Outcome {
    u: Vec<f64>,
    damage: Vec<f64>,
    broken: Vec<f64>,
    state: Vec<f64>,
    opening: Vec<f64>,
    sliding: Vec<f64>,
    normal: Vec<f64>,
}

/// The scene body, generic over the backend.
fn run<D: Dim>(mesh: &Mesh<D>, backend: Backend, s: &Scene) -> Outcome {
    let split = split_nodes(mesh, &Range::All).unwrap();
    let (lo, hi) = mesh.bounding_box();
    let axis = D::D - 1;
    let len = hi[axis] - lo[axis];
    // A band of weak joints across the bar at 0.6 of its length (joints whose side-A
    // midpoint lies within a quarter cell of that section).
    let at = lo[axis] + 0.6 * len;
    let (mut below, mut above, mut up, mut down) = ([0.0; 3], [0.0; 3], [0.0; 3], [0.0; 3]);
    below[axis] = at - 0.25 * CELL;
    above[axis] = at + 0.25 * CELL;
    up[axis] = 1.0;
    down[axis] = -1.0;
    let band = Range::And(
        Box::new(Range::HalfSpace {
            point: below,
            normal: up,
        }),
        Box::new(Range::HalfSpace {
            point: above,
            normal: down,
        }),
    );
    // Overlap penalty = opening penalty: the normal traction is smooth at o = 0.
    let strong = IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 8e6,
        tensile_strength: 4e6,
        gf1: 2.0,
        gf2: 20.0,
        penalty_open: 10.0 * E,
        penalty_shear: 10.0 * E,
        penalty_overlap: 10.0 * E,
    }
    .build()
    .unwrap();
    let weak = IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 2e6,
        tensile_strength: 1e6,
        gf1: 0.01,
        gf2: 0.1,
        penalty_open: 10.0 * E,
        penalty_shear: 10.0 * E,
        penalty_overlap: 10.0 * E,
    }
    .build()
    .unwrap();
    let mut joints = if s.opaque {
        CohesiveJoints::new()
            .model(Range::All, Opaque(strong))
            .model(band, Opaque(weak))
    } else {
        CohesiveJoints::new()
            .model(Range::All, strong)
            .model(band, weak)
    }
    .gauss_points_3d(s.gauss_3d);
    if let Some(f) = s.fracture.clone() {
        let on = joints_on_fractures(&split, &[f]).unwrap();
        assert!(!on.is_empty());
        let fracture = MohrCoulombJointParams {
            friction_deg: 30.0,
            cohesion: 0.0,
            penalty_normal: 10.0 * E,
            penalty_shear: 10.0 * E,
        }
        .build()
        .unwrap();
        joints = if s.opaque {
            joints.model_for(on, Opaque(fracture))
        } else {
            joints.model_for(on, fracture)
        };
    }
    let rock = LinearElastic::new(E, 0.25, 2600.0)
        .unwrap()
        .with_damping(0.1)
        .unwrap();
    let mechanics = if s.opaque {
        Mechanics::new().material_arc(Range::All, Arc::new(rock))
    } else {
        Mechanics::new().material(Range::All, rock)
    };
    let mut sim = Simulation::builder(split.clone(), backend)
        .physics(mechanics)
        .physics(joints)
        .build()
        .unwrap();
    // Linear velocity profile along the axis, 5 % noise per original node (copies of a
    // node start together, so the joints start closed and unloaded).
    let d = D::D;
    let x = sim.mesh().coords().to_vec();
    let mid = 0.5 * (lo[axis] + hi[axis]);
    for n in 0..sim.mesh().n_nodes() {
        let m = split.interfaces().master()[n] as usize;
        let xi = (x[n * d + axis] - mid) / (0.5 * len);
        sim.state.v[n * d + axis] = s.pull * xi * (1.0 + 0.05 * noise(m * d + axis));
        sim.state.v[n * d] += s.shear * xi * (1.0 + 0.05 * noise(m * d));
    }
    if s.perturb != 0.0 {
        for (i, v) in sim.state.v.iter_mut().enumerate() {
            *v *= 1.0 + s.perturb * noise(i + 7777);
        }
    }
    sim.run(s.steps).unwrap();
    Outcome {
        u: sim.state.u.clone(),
        damage: sim.field(JOINT_DAMAGE).unwrap().to_vec(),
        broken: sim.field(BROKEN_FACE).unwrap().to_vec(),
        state: sim.field(JOINT_STATE).unwrap().to_vec(),
        opening: sim.field(JOINT_OPENING).unwrap().to_vec(),
        sliding: sim.field(JOINT_SLIDING).unwrap().to_vec(),
        normal: sim.field(JOINT_NORMAL).unwrap().to_vec(),
    }
}

fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// Runs `scene` on the CPU, on the CPU perturbed, and on the GPU; compares and prints.
/// `tol` bounds the relative displacement difference (f64: or four times the perturbed
/// CPU's drift where that is larger); f64 also asks for damage and history within 1e-10
/// and identical broken faces.
fn parity<D: Dim>(name: &str, mesh: Mesh<D>, scene: Scene, precision: Precision, tol: f64) {
    let Some(gpu) = gpu_test_backend(Some(precision)) else {
        return;
    };
    let cpu = run(&mesh, Backend::cpu(1).unwrap(), &scene);
    let perturbed = Scene {
        perturb: 1e-15,
        ..scene.clone()
    };
    let drift = run(&mesh, Backend::cpu(1).unwrap(), &perturbed);
    let reads = gpu.as_gpu().expect("a GPU backend").readbacks();
    let dev = run(&mesh, gpu.clone(), &scene);
    // One read-back for the whole run.
    assert_eq!(
        gpu.as_gpu().expect("a GPU backend").readbacks() - reads,
        1,
        "device reads inside the step loop"
    );
    let n = cpu.damage.len();
    let softening = cpu.damage.iter().filter(|&&d| d > 0.0 && d < 1.0).count();
    let broken = cpu.damage.iter().filter(|&&d| d >= 1.0).count();
    let scale = max_abs(&cpu.u);
    let du = max_diff(&cpu.u, &dev.u) / scale;
    let dp = max_diff(&cpu.u, &drift.u) / scale;
    let dd = max_diff(&cpu.damage, &dev.damage);
    let ds = max_diff(&cpu.state, &dev.state) / max_abs(&cpu.state);
    let faces = cpu.broken.iter().filter(|&&b| b == 1.0).count();
    let flips = cpu
        .broken
        .iter()
        .zip(&dev.broken)
        .filter(|(a, b)| a != b)
        .count();
    let d_open = max_diff(&cpu.opening, &dev.opening);
    let d_slide = max_diff(&cpu.sliding, &dev.sliding);
    let d_normal = max_diff(&cpu.normal, &dev.normal);
    println!(
        "{name} {} {} on {}, {} steps: {n} joints ({softening} softening, {broken} broken, \
         {faces} broken faces); max relative difference displacement {du:.3e} (CPU with \
         1e-15 perturbed start: {dp:.3e}), joint damage (absolute) {dd:.3e}, joint state \
         (relative to max) {ds:.3e}, broken faces that differ {flips}; joint opening \
         {d_open:.3e} m (max {:.3e} m), sliding {d_slide:.3e} m (max {:.3e} m), normal \
         {d_normal:.3e}",
        D::NAME,
        precision.name(),
        gpu.as_gpu().expect("a GPU backend").adapter_name(),
        scene.steps,
        max_abs(&cpu.opening),
        max_abs(&cpu.sliding),
    );
    // The kinematics came back from the device: open joints, unit normals.
    assert!(max_abs(&dev.opening) > 0.0 && max_abs(&dev.sliding) > 0.0);
    for n in dev.normal.chunks_exact(D::D) {
        let len = n.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!((len - 1.0).abs() < 1e-5, "normal {n:?}");
    }
    assert!(softening > 0, "no joint is softening");
    assert!(broken > 0, "no joint broke");
    if precision == Precision::F64 {
        let bar = tol.max(4.0 * dp);
        assert!(du <= bar, "displacement differs by {du:e} (> {bar:e})");
        assert!(dd <= 1e-10, "joint damage differs by {dd:e}");
        assert!(ds <= 1e-10, "joint state differs by {ds:e}");
        assert_eq!(flips, 0, "broken faces differ");
        let gap_bar = 4.0 * bar * scale;
        assert!(
            d_open <= gap_bar,
            "opening differs by {d_open:e} m (> {gap_bar:e})"
        );
        assert!(
            d_slide <= gap_bar,
            "sliding differs by {d_slide:e} m (> {gap_bar:e})"
        );
        let normal_bar = gap_bar / CELL;
        assert!(
            d_normal <= normal_bar,
            "normal differs by {d_normal:e} (> {normal_bar:e})"
        );
    } else {
        assert!(du <= tol, "displacement differs by {du:e} (> {tol:e})");
        assert!(dd <= 0.05, "joint damage differs by {dd:e}");
    }
}

fn bar_2d() -> Mesh<Dim2> {
    builders::rectangle(0.0, 0.0, 0.02, 0.04, CELL).unwrap()
}

fn bar_3d() -> Mesh<Dim3> {
    builders::cuboid([0.0; 3], [0.01, 0.01, 0.02], CELL).unwrap()
}

/// An inclined fracture across the 2D bar.
fn fracture_2d() -> Fracture {
    Fracture::Segment {
        a: [0.0, 0.012],
        b: [0.02, 0.018],
    }
}

/// An inclined fracture across the 3D bar.
fn fracture_3d() -> Fracture {
    Fracture::Disc {
        center: [0.005, 0.005, 0.007],
        normal: [0.3, 0.0, 1.0],
        radius: 0.02,
    }
}

#[test]
fn pull_2d_f64_matches_cpu() {
    parity("pull", bar_2d(), pull(), Precision::F64, 1e-12);
}

#[test]
fn pull_3d_f64_matches_cpu() {
    parity("pull", bar_3d(), pull(), Precision::F64, 1e-12);
}

#[test]
fn pull_3d_seven_gauss_points_f64_matches_cpu() {
    let scene = Scene {
        gauss_3d: 7,
        ..pull()
    };
    parity(
        "pull, 7 Gauss points",
        bar_3d(),
        scene,
        Precision::F64,
        1e-12,
    );
}

#[test]
fn sliding_fracture_2d_f64_matches_cpu() {
    parity(
        "slide",
        bar_2d(),
        slide(fracture_2d()),
        Precision::F64,
        1e-12,
    );
}

#[test]
fn sliding_fracture_3d_f64_matches_cpu() {
    parity(
        "slide",
        bar_3d(),
        slide(fracture_3d()),
        Precision::F64,
        1e-12,
    );
}

#[test]
fn pull_2d_f32_difference_is_measured() {
    parity("pull", bar_2d(), pull(), Precision::F32, 1e-2);
}

#[test]
fn pull_3d_f32_difference_is_measured() {
    parity("pull", bar_3d(), pull(), Precision::F32, 1e-2);
}

/// One force evaluation at a random state (no dynamics to amplify anything): the joint
/// forces of both backends agree to rounding; most agree bit for bit.
#[test]
fn joint_forces_agree_to_rounding() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    /// Forces, damage, and opening, sliding and normal side by side.
    fn forces(backend: Backend, amp: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let split = split_nodes(&bar_2d(), &Range::All).unwrap();
        let czm = IntrinsicCzmParams {
            friction_deg: 30.0,
            cohesion: 2e6,
            tensile_strength: 1e6,
            gf1: 0.01,
            gf2: 0.1,
            penalty_open: 10.0 * E,
            penalty_shear: 10.0 * E,
            penalty_overlap: 100.0 * E,
        }
        .build()
        .unwrap();
        let soft = LinearElastic::new(1.0, 0.25, 2600.0).unwrap();
        let mut sim = Simulation::builder(split, backend)
            .physics(Mechanics::new().material(Range::All, soft))
            .physics(CohesiveJoints::new().model(Range::All, czm))
            .build()
            .unwrap();
        for (i, u) in sim.state.u.iter_mut().enumerate() {
            *u = amp * noise(i);
        }
        let f = sim.evaluate_forces().unwrap().to_vec();
        let kin = [JOINT_OPENING, JOINT_SLIDING, JOINT_NORMAL]
            .iter()
            .flat_map(|name| sim.field(name).unwrap().to_vec())
            .collect();
        (f, sim.field(JOINT_DAMAGE).unwrap().to_vec(), kin)
    }
    // From pre-peak (1e-9 m) to broken (1e-6 m) openings.
    for amp in [1e-9, 1e-8, 1e-7, 1e-6] {
        let (a, da, ka) = forces(Backend::cpu(1).unwrap(), amp);
        let (b, db, kb) = forces(gpu.clone(), amp);
        let exact = a.iter().zip(&b).filter(|(x, y)| x == y).count();
        let rel = max_diff(&a, &b) / max_abs(&a);
        let dd = max_diff(&da, &db);
        println!(
            "amplitude {amp:e} m: force difference {rel:.3e} of the largest, {exact}/{} \
             identical, damage difference {dd:.3e} (max damage {:.3})",
            a.len(),
            max_abs(&da)
        );
        assert!(rel <= 1e-15, "forces differ by {rel:e}");
        assert!(dd <= 1e-14, "damage differs by {dd:e}");
        // Opening, sliding (m) and normal: the gaps carry the rounding of positions
        // (coordinates up to 0.04 m: 7e-18 m per ulp), the normal that of unit vectors.
        let nj = da.len();
        let (dk_gap, dk_normal) = (
            max_diff(&ka[..3 * nj], &kb[..3 * nj]),
            max_diff(&ka[3 * nj..], &kb[3 * nj..]),
        );
        let exact_k = ka.iter().zip(&kb).filter(|(x, y)| x == y).count();
        println!(
            "  opening and sliding difference {dk_gap:.3e} m, normal {dk_normal:.3e}, \
             {exact_k}/{} identical",
            ka.len()
        );
        assert!(
            dk_gap <= 1e-16,
            "opening or sliding differs by {dk_gap:e} m"
        );
        assert!(dk_normal <= 1e-14, "normal differs by {dk_normal:e}");
    }
}

/// The built-in models called inline (by concrete type) and through their trait objects
/// (the plugin path) give the same bits: the static dispatch changes nothing but the
/// speed, in 2D and 3D, for the cohesive law, the fracture law and the elastic law.
fn inline_matches_trait_objects<D: Dim>(mesh: Mesh<D>, fracture: Fracture) {
    for scene in [pull(), slide(fracture)] {
        let inline = run(&mesh, Backend::cpu(1).unwrap(), &scene);
        let opaque = run(
            &mesh,
            Backend::cpu(1).unwrap(),
            &Scene {
                opaque: true,
                ..scene.clone()
            },
        );
        assert!(max_abs(&inline.u) > 0.0 && max_abs(&inline.state) > 0.0);
        assert_eq!(inline.u, opaque.u);
        assert_eq!(inline.state, opaque.state);
        assert_eq!(inline.damage, opaque.damage);
        assert_eq!(inline.broken, opaque.broken);
    }
}

#[test]
fn inline_models_match_trait_objects_2d() {
    inline_matches_trait_objects(bar_2d(), fracture_2d());
}

#[test]
fn inline_models_match_trait_objects_3d() {
    inline_matches_trait_objects(bar_3d(), fracture_3d());
}
