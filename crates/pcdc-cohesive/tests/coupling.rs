//! Coupling inputs of joint models: a model declares the fields it reads
//! (`JointModel::coupling`) and receives their values at the joint in
//! `JointInput::coupling` (node fields: mean over the joint's face nodes on both sides;
//! element fields: mean of its two elements), on the CPU and in its WGSL body.

use pcdc_cohesive::{
    CohesiveJoints, JointInput, JointModel, Traction, WgslJointModel, JOINT_STATE,
};
use pcdc_compute::gpu::{gpu_test_backend, offline_kernel_sources};
use pcdc_compute::{
    names, Backend, Components, ComputeError, FieldKey, FieldUse, ForceContext, InitContext,
    Physics, Place, Precision, Simulation,
};
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, split_nodes, Dim, Interfaces, Mesh, Range};

const E: f64 = 30e9;

/// A test element field, to exercise element-placed coupling.
const SATURATION: FieldKey = FieldKey::new("test_saturation", Place::Element, Components::Fixed(1));

/// A linear joint pushed apart by its coupling fields: σ = P_n o / h − Σ c_i v_i,
/// shear P_t s / h; the history records the last values (state i = v_i). With
/// PORE_PRESSURE and c = 1 the fluid pressure in the joint acts on its faces.
#[derive(Debug)]
struct Pressurised {
    kn: f64,
    kt: f64,
    keys: Vec<FieldKey>,
    coef: Vec<f64>,
}

impl Pressurised {
    fn new(keys: Vec<FieldKey>, coef: Vec<f64>) -> Self {
        Pressurised {
            kn: 10.0 * E,
            kt: 10.0 * E,
            keys,
            coef,
        }
    }
}

impl JointModel for Pressurised {
    fn name(&self) -> &str {
        "test-pressurised-joint"
    }
    fn n_state(&self) -> usize {
        self.keys.len().max(1)
    }
    fn coupling(&self) -> &[FieldKey] {
        &self.keys
    }
    /// The law without coupling (zero pressure).
    fn traction(&self, o: f64, slip: &[f64], h: f64, state: &mut [f64]) -> Traction {
        self.traction_with(&JointInput::new(o, slip, h, &[]), state)
    }
    fn traction_with(&self, input: &JointInput<'_>, state: &mut [f64]) -> Traction {
        let mut load = 0.0;
        for (i, &v) in input.coupling.iter().enumerate() {
            load += self.coef[i] * v;
            state[i] = v;
        }
        let mut t = Traction {
            normal: self.kn * input.opening / input.h - load,
            ..Traction::default()
        };
        for (c, s) in input.slip.iter().enumerate() {
            t.shear[c] = self.kt * s / input.h;
        }
        t
    }
    fn max_stiffness(&self, h: f64) -> f64 {
        self.kn.max(self.kt) / h
    }
    fn is_broken(&self, _state: &[f64]) -> bool {
        false
    }
    fn wgsl(&self) -> Option<WgslJointModel> {
        let n = self.keys.len();
        // `coupling` exists only when a model of the physics declares coupling fields:
        // a model that declares none must not name it.
        let gather = if n == 0 {
            String::new()
        } else {
            format!(
                "for (var i = 0u; i < {n}u; i = i + 1u) {{
    load = load + param(p, 2u + i) * coupling[i];
    (*state)[i] = coupling[i];
}}"
            )
        };
        let body = format!(
            "let kn = param(p, 0u);
let kt = param(p, 1u);
var t: JointTraction;
var load = Real(0.0);
{gather}
t.normal = kn * o / h - load;
for (var c = 0u; c < D; c = c + 1u) {{
    t.shear[c] = kt * slip[c] / h;
}}
return t;"
        );
        let mut params = vec![self.kn, self.kt];
        params.extend_from_slice(&self.coef);
        Some(WgslJointModel {
            key: format!("test_pressurised_{n}"),
            body,
            params,
        })
    }
}

/// A test physics that owns one field and holds it at given values; no forces, no GPU
/// kernel needed.
struct Given {
    name: String,
    key: FieldKey,
    values: Vec<f64>,
}

impl Given {
    /// The field `key` at `f(x, i)` for every node `i` (node key) or element `i` (at its
    /// centroid).
    fn at<D: Dim>(mesh: &Mesh<D>, key: FieldKey, f: impl Fn(&[f64], usize) -> f64) -> Self {
        let values = match key.place() {
            Place::Node => (0..mesh.n_nodes()).map(|n| f(mesh.node(n), n)).collect(),
            _ => (0..mesh.n_elements())
                .map(|e| {
                    let mut c = [0.0; 3];
                    for &n in mesh.element(e) {
                        for (c, x) in c.iter_mut().zip(mesh.node(n as usize)) {
                            *c += x / D::NODES_PER_ELEM as f64;
                        }
                    }
                    f(&c[..D::D], e)
                })
                .collect(),
        };
        Given {
            name: format!("given {}", key.name()),
            key,
            values,
        }
    }
}

impl<D: Dim> Physics<D> for Given {
    fn name(&self) -> &str {
        &self.name
    }
    fn fields(&self, _mesh: &Mesh<D>) -> Vec<FieldUse> {
        vec![self.key.own::<D>()]
    }
    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        let id = ctx.fields.id(self.key)?;
        ctx.fields.get_mut(id).copy_from_slice(&self.values);
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

/// Deterministic pseudo-random numbers in [-1, 1).
fn noise(i: usize) -> f64 {
    let x = (i as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let x = (x ^ (x >> 29)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    ((x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

fn rock() -> LinearElastic {
    LinearElastic::new(E, 0.25, 2600.0).unwrap()
}

/// The owners of temperature, pore pressure (both per node, differing between the two
/// sides of a joint) and the element test field.
fn owners<D: Dim>(mesh: &Mesh<D>) -> [Given; 3] {
    [
        Given::at(mesh, names::TEMPERATURE, |x, n| {
            300.0 + 100.0 * x[0] + 10.0 * noise(n)
        }),
        Given::at(mesh, names::PORE_PRESSURE, |x, n| {
            1e5 * (1.0 + x[1]) * (1.0 + 0.1 * noise(n + 7))
        }),
        Given::at(mesh, SATURATION, |x, e| 0.5 + x[0] * x[1] + 0.01 * noise(e)),
    ]
}

/// Joint `j`'s expected values of the node field `v`: Σ over side A's then side B's
/// nodes, divided by 2 NPF.
fn node_mean(joints: &Interfaces, npf: usize, j: usize, v: &[f64]) -> f64 {
    let mut sum = 0.0;
    for &n in joints.joint_nodes(j) {
        sum += v[n as usize];
    }
    sum / (2 * npf) as f64
}

/// The model receives, at every Gauss point, the joint's values in its declaration
/// order; a model with another list (and one without coupling) shares the gathered
/// fields. Checked through the recorded history, exactly.
fn values_reach_the_model<D: Dim>(mesh: Mesh<D>) {
    let m = split_nodes(&mesh, &Range::All).unwrap();
    let joints = m.interfaces().clone();
    let npf = D::NODES_PER_FACE;
    let [heat, fluid, sat] = owners(&m);
    let all = Pressurised::new(
        vec![names::PORE_PRESSURE, SATURATION, names::TEMPERATURE],
        vec![0.0; 3],
    );
    let one = Pressurised::new(vec![names::TEMPERATURE], vec![0.0]);
    let plain = Pressurised::new(vec![], vec![]);
    let mut sim = Simulation::builder(m.clone(), Backend::cpu(2).unwrap())
        .physics(Mechanics::new().material(Range::All, rock()))
        .physics(
            CohesiveJoints::new()
                .model(Range::All, all)
                .model_for(vec![0, 2], one)
                .model_for(vec![1], plain),
        )
        .physics(heat)
        .physics(fluid)
        .physics(sat)
        .build()
        .unwrap();
    sim.step().unwrap();
    let state = sim.field(JOINT_STATE).unwrap();
    // 3 Gauss points: the 2D rule and the 3D default.
    let ngauss = 3;
    let ns = 3;
    let stride = ngauss * ns;
    let t = sim.field(names::TEMPERATURE).unwrap();
    let p = sim.field(names::PORE_PRESSURE).unwrap();
    let s = sim.field(SATURATION).unwrap();
    for j in 0..joints.len() {
        let (ea, eb) = (
            joints.elements()[2 * j] as usize,
            joints.elements()[2 * j + 1] as usize,
        );
        let expect: Vec<f64> = match j {
            0 | 2 => vec![node_mean(&joints, npf, j, t), 0.0, 0.0],
            1 => vec![0.0; 3],
            _ => vec![
                node_mean(&joints, npf, j, p),
                (0.0 + s[ea] + s[eb]) / 2.0,
                node_mean(&joints, npf, j, t),
            ],
        };
        for g in 0..ngauss {
            let at = j * stride + g * ns;
            assert_eq!(
                &state[at..at + ns],
                &expect[..],
                "joint {j}, Gauss point {g}"
            );
        }
    }
    // The two sides differ: the mean is over both.
    let j = 3;
    let side_a: f64 = joints.joint_nodes(j)[..npf]
        .iter()
        .map(|&n| t[n as usize])
        .sum::<f64>()
        / npf as f64;
    assert_ne!(side_a, node_mean(&joints, npf, j, t));
}

#[test]
fn values_reach_the_model_2d() {
    values_reach_the_model(builders::rectangle(0.0, 0.0, 0.04, 0.02, 0.01).unwrap());
}

#[test]
fn values_reach_the_model_3d() {
    values_reach_the_model(builders::cuboid([0.0; 3], [0.02, 0.01, 0.01], 0.01).unwrap());
}

/// A joint model that reads a field no composed physics owns: the builder's ownership
/// error names the field and the joints.
#[test]
fn missing_owner_is_a_build_error() {
    let mesh = builders::rectangle(0.0, 0.0, 0.04, 0.02, 0.01).unwrap();
    let split = split_nodes(&mesh, &Range::All).unwrap();
    let err = Simulation::builder(split, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock()))
        .physics(CohesiveJoints::new().model(
            Range::All,
            Pressurised::new(vec![names::PORE_PRESSURE], vec![1.0]),
        ))
        .build()
        .err()
        .expect("a joint model reading an unowned field must not build");
    match &err {
        ComputeError::FieldWithoutOwner { field, physics, .. } => {
            assert_eq!(field, "pore_pressure");
            assert_eq!(physics, "cohesive joints");
        }
        other => panic!("expected FieldWithoutOwner, got {other:?}"),
    }
    println!("{err}");
}

/// Joint models that ask for nothing declare nothing, and the joint kernel is the
/// uncoupled one.
#[test]
fn no_coupling_declares_and_gathers_nothing() {
    let mesh = builders::rectangle(0.0, 0.0, 0.04, 0.02, 0.01).unwrap();
    let split = split_nodes(&mesh, &Range::All).unwrap();
    let joints = || CohesiveJoints::new().model(Range::All, Pressurised::new(vec![], vec![]));
    let sim = Simulation::builder(split.clone(), Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock()))
        .physics(joints())
        .build()
        .unwrap();
    let names: Vec<&str> = sim
        .state
        .fields
        .specs()
        .iter()
        .map(|s| s.name.as_str())
        .collect();
    assert_eq!(
        names,
        [
            "stress",
            "strain",
            "stress_zz",
            "model_state",
            "displacement_reset",
            "element_null",
            "joint_state",
            "joint_damage",
            "broken_face",
            "joint_opening",
            "joint_sliding",
            "joint_normal"
        ]
    );
    let src =
        offline_kernel_sources::<_>(&split, vec![Box::new(joints())], Precision::F64).unwrap();
    let joint = &src
        .iter()
        .find(|(l, _)| l.starts_with("cohesive joints"))
        .unwrap()
        .1;
    assert!(!joint.contains("coupling"), "{joint}");
}

/// A fully split block with its bottom fixed, stretched and sheared by an initial
/// velocity field (so that displacements are large against the rounding of positions,
/// as in the joints' parity tests), its joints also pushed apart by pore pressure,
/// temperature and the element field (varying, per node and per element), three joint
/// models with different lists, damped elements; `steps` explicit steps. Returns the
/// displacements and the joint history (the coupling values each joint's model
/// received last).
/// `perturb` scales the initial velocities by 1 + perturb · noise (0 for the compared
/// runs).
fn pressurised<D: Dim>(
    mesh: Mesh<D>,
    backend: Backend,
    steps: u64,
    perturb: f64,
) -> (Vec<f64>, Vec<f64>) {
    let m = split_nodes(&mesh, &Range::All).unwrap();
    let [heat, fluid, sat] = owners(&m);
    let (lo, hi) = m.bounding_box();
    let half = Range::HalfSpace {
        point: [0.5 * (lo[0] + hi[0]), 0.0, 0.0],
        normal: [1.0, 0.0, 0.0],
    };
    let bottom = if D::D == 2 { "bottom" } else { "zmin" };
    let mut sim = Simulation::builder(m, backend)
        .physics(Mechanics::new().material(Range::All, rock().with_damping(0.3).unwrap()))
        .physics(
            CohesiveJoints::new()
                .model(
                    Range::All,
                    Pressurised::new(vec![names::PORE_PRESSURE], vec![20.0]),
                )
                .model(
                    half,
                    Pressurised::new(
                        vec![SATURATION, names::TEMPERATURE, names::PORE_PRESSURE],
                        vec![1e6, 1e4, 10.0],
                    ),
                )
                .model_for(vec![0, 1], Pressurised::new(vec![], vec![])),
        )
        .physics(Boundary::new().fix(Range::group(bottom)))
        .physics(heat)
        .physics(fluid)
        .physics(sat)
        .build()
        .unwrap();
    let (d, len) = (D::D, hi[0] - lo[0]);
    for n in 0..sim.mesh().n_nodes() {
        let r = (sim.mesh().node(n)[0] - 0.5 * (lo[0] + hi[0])) / len;
        sim.state.v[n * d] = 2.0 * r * (1.0 + perturb * noise(n * d));
        sim.state.v[n * d + 1] = 0.5 * r * (1.0 + perturb * noise(n * d + 1));
    }
    sim.run(steps).unwrap();
    let state = sim.field(JOINT_STATE).unwrap().to_vec();
    (sim.state.u.clone(), state)
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let diff = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    diff / scale
}

/// CPU–GPU parity in f64: the coupling values the joint models received (recorded in
/// their history) agree to rounding; the displacements within 1e-12 relative, or four
/// times the drift of a CPU run whose initial velocities are perturbed by 1e-15
/// (relative) where that is larger: as in the joints' parity tests, the conditioning of
/// the scene, not a discrepancy of the kernels.
fn parity<D: Dim>(mesh: Mesh<D>) {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let steps = 200;
    let (u_cpu, s_cpu) = pressurised(mesh.clone(), Backend::cpu(1).unwrap(), steps, 0.0);
    let (u_pert, _) = pressurised(mesh.clone(), Backend::cpu(1).unwrap(), steps, 1e-15);
    let (u_gpu, s_gpu) = pressurised(mesh, gpu.clone(), steps, 0.0);
    let (du, dp, ds) = (
        rel_diff(&u_cpu, &u_gpu),
        rel_diff(&u_cpu, &u_pert),
        rel_diff(&s_cpu, &s_gpu),
    );
    println!(
        "{} f64 pressurised joints on {}: max relative difference displacement {du:.3e} (CPU with a 1e-15 perturbed start: {dp:.3e}), coupling values in the joint history {ds:.3e}",
        D::NAME,
        gpu.as_gpu().expect("a GPU backend").adapter_name()
    );
    assert!(u_cpu.iter().any(|&u| u != 0.0), "the scene must move");
    assert!(ds <= 1e-15, "coupling values differ by {ds:e}");
    let bar = 1e-12f64.max(4.0 * dp);
    assert!(du <= bar, "displacement differs by {du:e} (> {bar:e})");
}

#[test]
fn pressurised_joints_2d_gpu_matches_cpu() {
    parity(builders::rectangle(0.0, 0.0, 0.04, 0.02, 0.005).unwrap());
}

#[test]
fn pressurised_joints_3d_gpu_matches_cpu() {
    parity(builders::cuboid([0.0; 3], [0.02, 0.01, 0.01], 0.005).unwrap());
}
