//! The face-joint physics: joint forces from a [`JointModel`] integrated over each
//! joint face (manual 7.4.1: 3 Gauss points in 2D, 3 or 7 in 3D).
//!
//! Kinematics of a joint: the midplane of its two sides gives the unit normal n (from
//! side A to side B) and the area; at each Gauss point the gap vector
//! δ = Σ N_k (x_B,k − x_A,k) splits into the opening o = δ·n and the slip vector
//! s = δ − o n. In 2D this is done once per joint in its frame (n, t): each node pair's
//! gap is projected on n and t, and at a Gauss point o = Σ N_k g_n,k and the signed slip
//! s_t = Σ N_k g_t,k give s = s_t t and |s| = |s_t| (no square root). The model returns
//! the normal traction σ (positive pulls the sides together) and the shear traction
//! (against the slip); side A receives `A Σ_g w_g N_k (σ n + τ)` and side B the
//! opposite (exact action-reaction).
//!
//! The built-in models ([`IntrinsicCzm`], [`MohrCoulombJoint`]) are called by their
//! concrete type, so their law inlines into the Gauss-point loop; a plugin model is
//! called through its trait object.
//!
//! Fields ([`crate::fields`]): `joint_state` (model history per Gauss point),
//! `joint_damage` (largest D per joint, for output), `broken_face` (1 on both faces of a
//! fully broken joint, on the split mesh's faces: the field contact picks up), and per
//! joint the kinematics other physics read: `joint_opening` (δ̄·n at the face centroid),
//! `joint_sliding` (δ̄ − (δ̄·n) n, D components) and `joint_normal` (n), written by the
//! same kernel, for broken joints too. It reads (lagged) the coupling fields its models
//! ask for ([`JointModel::coupling`]) and passes each model their values at the joint
//! ([`crate::JointInput::coupling`]); when no model asks, it declares and gathers
//! nothing.
//!
//! A broken joint (largest damage 1) transfers no force from the next step on, whatever
//! its model: its faces interact through contact alone. Integrating it further would
//! let an overlap penalty push faces that have separated and moved far apart (the
//! opening of a broken joint's face pair means nothing once the faces have left each
//! other), which injects energy into fragmenting runs.
//!
//! On the GPU backend one kernel (`shaders/joints.wgsl`, one invocation per joint)
//! repeats this arithmetic in the same order, with each model's WGSL body
//! ([`crate::WgslJointModel`]) spliced in; it writes the same slots and fields.

use std::any::Any;
use std::sync::Arc;

use pcdc_compute::coupling::CouplingInputs;
use pcdc_compute::gpu::{splice_models, Access, GpuData, GpuSetup, Kernel, Phase, WGSL_GEOMETRY};
use pcdc_compute::{Backend, FieldKey, FieldUse, KinematicNodes};
use pcdc_compute::{
    ComputeError, FieldId, FieldStore, Fingerprint, ForceContext, InitContext, Kinematics, Physics,
    StableStep,
};
use pcdc_compute::{Entity, EntityKind};
use pcdc_mesh::{Dim, Interfaces, Mesh, Range};
use rayon::prelude::*;

use crate::fields::{
    BROKEN_FACE, JOINT_DAMAGE, JOINT_NORMAL, JOINT_OPENING, JOINT_SLIDING, JOINT_STATE,
};
use crate::model::slip_norm;
use crate::{IntrinsicCzm, JointInput, JointModel, MohrCoulombJoint};

const JOINT_KERNEL: &str = include_str!("shaders/joints.wgsl");
const JOINT_LIBRARY: &str = include_str!("shaders/joint_library.wgsl");

const CHUNK: usize = 256;

/// Declares a per-joint field this physics owns: one value set per joint of the entity
/// set `names::JOINTS` (the mesh's interfaces), `components` values each (`None`: the
/// key's).
fn own_per_joint<D: Dim>(key: FieldKey, _n_joints: usize, components: Option<usize>) -> FieldUse {
    match components {
        Some(c) => key.own_sized::<D>(c),
        None => key.own::<D>(),
    }
}

/// Where [`CohesiveJoints::joint`] writes a joint's published kinematics (`V` = D
/// components per vector).
struct JointOut<'a, const V: usize> {
    /// Normal opening (m).
    opening: &'a mut f64,
    /// Sliding vector (m).
    sliding: &'a mut [f64; V],
    /// Unit normal.
    normal: &'a mut [f64; V],
}

/// A block of consecutive joints' arrays (the slices of the per-joint fields that one
/// task of the joint loop writes), starting at joint `first`.
struct JointBlock<'a> {
    first: usize,
    slots: &'a mut [f64],
    state: &'a mut [f64],
    damage: &'a mut [f64],
    opening: &'a mut [f64],
    sliding: &'a mut [f64],
    normal: &'a mut [f64],
}

/// Gauss points on a joint face: (shape function values, weight as a fraction of the
/// face measure).
fn gauss_rule(d: usize, points: usize) -> Vec<([f64; 3], f64)> {
    if d == 2 {
        let a = (0.6f64).sqrt();
        [(-a, 5.0 / 18.0), (0.0, 8.0 / 18.0), (a, 5.0 / 18.0)]
            .iter()
            .map(|&(xi, w)| ([0.5 * (1.0 - xi), 0.5 * (1.0 + xi), 0.0], w))
            .collect()
    } else if points == 3 {
        let (a, b) = (2.0 / 3.0, 1.0 / 6.0);
        vec![
            ([a, b, b], 1.0 / 3.0),
            ([b, a, b], 1.0 / 3.0),
            ([b, b, a], 1.0 / 3.0),
        ]
    } else {
        let (a1, b1, w1) = (
            0.059_715_871_789_770,
            0.470_142_064_105_115,
            0.132_394_152_788_506,
        );
        let (a2, b2, w2) = (
            0.797_426_985_353_087,
            0.101_286_507_323_456,
            0.125_939_180_544_827,
        );
        vec![
            ([1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0], 0.225),
            ([a1, b1, b1], w1),
            ([b1, a1, b1], w1),
            ([b1, b1, a1], w1),
            ([a2, b2, b2], w2),
            ([b2, a2, b2], w2),
            ([b2, b2, a2], w2),
        ]
    }
}

/// A joint model as the physics holds it: a built-in model by its concrete type, so that
/// its law inlines into the Gauss-point loop (`CohesiveJoints::joint` is generic over
/// the model); any other model behind its trait object, called through the vtable.
#[derive(Clone)]
enum Model {
    Czm(IntrinsicCzm),
    MohrCoulomb(MohrCoulombJoint),
    Plugin(Arc<dyn JointModel>),
}

impl Model {
    /// The built-in models recognised by type; any other is a plugin.
    fn new(model: impl JointModel + 'static) -> Model {
        let any: &dyn Any = &model;
        if let Some(m) = any.downcast_ref::<IntrinsicCzm>() {
            Model::Czm(m.clone())
        } else if let Some(m) = any.downcast_ref::<MohrCoulombJoint>() {
            Model::MohrCoulomb(m.clone())
        } else {
            Model::Plugin(Arc::new(model))
        }
    }

    /// The model as a trait object (for everything outside the joint loop).
    fn get(&self) -> &dyn JointModel {
        match self {
            Model::Czm(m) => m,
            Model::MohrCoulomb(m) => m,
            Model::Plugin(m) => &**m,
        }
    }
}

/// The model's own `Debug` (it enters the physics' fingerprint, which must not depend on
/// how the model is held).
impl std::fmt::Debug for Model {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Debug::fmt(self.get(), f)
    }
}

/// Face-joints with their constitutive models, as a physics: one joint on every
/// interface of the mesh ([`pcdc_mesh::Mesh::interfaces`], made by
/// [`pcdc_mesh::split_nodes`]), in the interfaces' order.
#[derive(Debug)]
pub struct CohesiveJoints {
    /// The mesh's interfaces (copied at init).
    joints: Interfaces,
    assignments: Vec<(Range, Model)>,
    /// Assignments by joint index: (index into `assignments`, joints).
    explicit: Vec<(usize, Vec<u32>)>,
    gauss_3d: usize,
    models: Vec<Model>,
    model_of: Vec<u16>,
    h: Vec<f64>,
    rule: Vec<([f64; 3], f64)>,
    n_state: usize,
    ids: Option<[FieldId; 6]>,
    coupling: CouplingInputs,
}

impl Default for CohesiveJoints {
    fn default() -> Self {
        Self::new()
    }
}

impl CohesiveJoints {
    /// Joints on the interfaces of the simulation's mesh (split with
    /// [`pcdc_mesh::split_nodes`]; a mesh without interfaces has no joints); assign
    /// models with [`CohesiveJoints::model`].
    pub fn new() -> Self {
        CohesiveJoints {
            joints: Interfaces::default(),
            assignments: Vec::new(),
            explicit: Vec::new(),
            gauss_3d: 3,
            models: Vec::new(),
            model_of: Vec::new(),
            h: Vec::new(),
            rule: Vec::new(),
            n_state: 1,
            ids: None,
            coupling: CouplingInputs::default(),
        }
    }

    /// Assigns a joint model to the joints whose midpoint lies in `range`; later
    /// assignments override earlier ones.
    pub fn model(mut self, range: Range, model: impl JointModel + 'static) -> Self {
        self.assignments.push((range, Model::new(model)));
        self
    }

    /// Assigns a joint model to the listed joints (e.g. from
    /// [`crate::joints_on_fractures`]); later assignments override earlier ones.
    pub fn model_for(mut self, joints: Vec<u32>, model: impl JointModel + 'static) -> Self {
        self.explicit.push((self.assignments.len(), joints));
        self.assignments
            .push((Range::custom(|_| false), Model::new(model)));
        self
    }

    /// Gauss points per joint face in 3D: 3 (default) or 7.
    pub fn gauss_points_3d(mut self, n: usize) -> Self {
        self.gauss_3d = n;
        self
    }

    /// History variables per Gauss point: the largest of the assigned models (≥ 1).
    fn assigned_state_len(&self) -> usize {
        self.assignments
            .iter()
            .map(|a| a.1.get().n_state())
            .max()
            .unwrap_or(1)
            .max(1)
    }

    fn state_stride(&self) -> usize {
        self.rule.len() * self.n_state
    }

    /// Fills `values` (stride [`CouplingInputs::stride`] per joint) with every joint's
    /// coupling values in its model's order: the mean of the joint's face nodes (side A,
    /// then side B, summed in that order, then divided by 2 NPF) for a node field, the
    /// mean of its two elements ((0 + v_A) + v_B) / 2 for an element field. The GPU's
    /// `joint_coupling_of` repeats these operations.
    fn gather_coupling<D: Dim>(&self, fields: &FieldStore, values: &mut [f64], backend: &Backend) {
        let (npf, stride) = (D::NODES_PER_FACE, self.coupling.stride);
        let data: Vec<&[f64]> = self
            .coupling
            .fields
            .iter()
            .map(|f| fields.get(f.id))
            .collect();
        backend.install(|| {
            values
                .par_chunks_mut(CHUNK * stride)
                .enumerate()
                .for_each(|(chunk, out)| {
                    for (i, out) in out.chunks_exact_mut(stride).enumerate() {
                        let j = chunk * CHUNK + i;
                        let nodes = self.joints.joint_nodes(j);
                        let elements = &self.joints.elements()[2 * j..2 * j + 2];
                        let mut k = 0;
                        for &u in &self.coupling.of_model[self.model_of[j] as usize] {
                            let (f, v) = (&self.coupling.fields[u], data[u]);
                            let nc = f.components;
                            let (at, count) = if f.node {
                                (nodes, 2 * npf)
                            } else {
                                (elements, 2)
                            };
                            for c in 0..nc {
                                let mut sum = 0.0;
                                for &n in at {
                                    sum += v[n as usize * nc + c];
                                }
                                out[k] = sum / count as f64;
                                k += 1;
                            }
                        }
                    }
                });
        });
    }

    /// The WGSL of the coupling inputs (only with coupling): the `JointCoupling` alias
    /// and `joint_coupling_of(j, r)` (joint `j`, `r` its row in `joint_info`), which
    /// computes every coupling field's values at the joint (the operations of
    /// [`Self::gather_coupling`]) and returns those of the joint's model in its order
    /// (zero beyond its count), through the table `joint_coupling`
    /// ([`CouplingInputs::bind`]). With coupling, a `joint_info` row ends with the
    /// joint's model index and its two elements (A, B).
    fn coupling_wgsl<D: Dim>(&self) -> String {
        let npf = D::NODES_PER_FACE;
        let total: usize = self.coupling.fields.iter().map(|f| f.components).sum();
        let mut src = format!(
            "alias JointCoupling = array<Real, {}u>;\nfn joint_coupling_of(j: u32, r: u32) -> JointCoupling {{\n    var all: array<Real, {total}u>;\n",
            self.coupling.stride
        );
        let mut at = 0;
        for (i, f) in self.coupling.fields.iter().enumerate() {
            let nc = f.components;
            // Row offsets of the nodes (both sides) or of the two elements.
            let (first, count) = if f.node {
                (0, 2 * npf)
            } else {
                (2 * npf + 5, 2)
            };
            src.push_str(&format!(
                "    // '{}'\n    for (var c = 0u; c < {nc}u; c = c + 1u) {{\n        var sum = Real(0.0);\n        for (var a = 0u; a < {count}u; a = a + 1u) {{\n            sum = sum + cpl{i}[joint_info[r + {first}u + a] * {nc}u + c];\n        }}\n        all[{at}u + c] = sum / Real({count}.0);\n    }}\n",
                self.coupling.keys[i]
            ));
            at += nc;
        }
        src.push_str(&format!(
            "    var out: JointCoupling;\n    let m = joint_info[r + {}u];\n    let n = joint_coupling[2u * m];\n    let o = joint_coupling[2u * m + 1u];\n    for (var k = 0u; k < n; k = k + 1u) {{\n        out[k] = all[joint_coupling[o + k]];\n    }}\n    return out;\n}}\n",
            2 * npf + 4
        ));
        src
    }

    /// The joints of `block`: each one's kinematics, forces, state and damage
    /// ([`CohesiveJoints::joint`]) with its model called by type. Iterating the arrays
    /// together as fixed-size vectors leaves one bounds check per block instead of one
    /// per slice per joint.
    fn joint_block<D: Dim, const V: usize, const S: usize, const J: usize>(
        &self,
        block: JointBlock<'_>,
        kin: &Kinematics<'_, D>,
        coupling: &[f64],
        cstride: usize,
    ) {
        let JointBlock {
            first,
            slots,
            state,
            damage,
            opening,
            sliding,
            normal,
        } = block;
        let n = damage.len();
        let nodes = &self.joints.nodes()[first * J..(first + n) * J];
        let (model_of, hs) = (&self.model_of[first..first + n], &self.h[first..first + n]);
        let per_joint = nodes
            .chunks_exact(J)
            .zip(slots.chunks_exact_mut(S))
            .zip(state.chunks_exact_mut(self.state_stride()))
            .zip(damage.iter_mut().zip(opening.iter_mut()))
            .zip(sliding.chunks_exact_mut(V).zip(normal.chunks_exact_mut(V)))
            .zip(model_of.iter().zip(hs));
        for (i, (((((nd, sl), st), (dm, op)), (sd, nm)), (&mo, &h))) in per_joint.enumerate() {
            let nd: &[u32; J] = nd.try_into().expect("chunks of J nodes");
            let sl: &mut [f64; S] = sl.try_into().expect("chunks of S slot values");
            let out: JointOut<'_, V> = JointOut {
                opening: op,
                sliding: sd.try_into().expect("chunks of V values"),
                normal: nm.try_into().expect("chunks of V values"),
            };
            let cv: &[f64] = if cstride == 0 {
                &[]
            } else {
                let j = first + i;
                let len = self.coupling.len_of_model[mo as usize];
                &coupling[j * cstride..j * cstride + len]
            };
            // A broken joint transfers no force; its kinematics are still published.
            let broken = *dm >= 1.0;
            let dmg = match &self.models[mo as usize] {
                Model::Czm(m) => self.joint(nd, h, kin, sl, st, cv, out, broken, m),
                Model::MohrCoulomb(m) => self.joint(nd, h, kin, sl, st, cv, out, broken, m),
                Model::Plugin(m) => self.joint(nd, h, kin, sl, st, cv, out, broken, &**m),
            };
            if let Some(dmg) = dmg {
                *dm = dmg;
            }
        }
    }

    /// Joint `j`'s opening, sliding and normal into `out` and, unless it is `broken`
    /// (then its slots are zeroed and its damage returned unchanged as `None`), its
    /// forces into `slots` (2·NPF·D values), its state update and its damage; its
    /// `model` (a concrete built-in type, inlined, or a trait object) receives the
    /// joint's `coupling` values.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn joint<D: Dim, M: JointModel + ?Sized, const V: usize, const S: usize, const J: usize>(
        &self,
        nodes: &[u32; J],
        h: f64,
        kin: &Kinematics<'_, D>,
        slots: &mut [f64; S],
        state: &mut [f64],
        coupling: &[f64],
        out: JointOut<'_, V>,
        broken: bool,
        model: &M,
    ) -> Option<f64> {
        let (d, npf) = (D::D, D::NODES_PER_FACE);
        let mut mid = [0.0; 9];
        let mut gap = [0.0; 9];
        for k in 0..npf {
            let (xa, xb) = (
                kin.position(nodes[k] as usize),
                kin.position(nodes[npf + k] as usize),
            );
            for c in 0..d {
                mid[k * d + c] = 0.5 * (xa[c] + xb[c]);
                gap[k * d + c] = xb[c] - xa[c];
            }
        }
        let mut n = [0.0; 3];
        let area = D::face_measure_normal(&mid[..npf * d], &mut n[..d]);
        // Published kinematics: the gap at the face centroid (mean of the node-pair
        // gaps) split along the normal.
        let mut g = [0.0; 3];
        for k in 0..npf {
            for c in 0..d {
                g[c] += gap[k * d + c];
            }
        }
        let mut o = 0.0;
        for c in 0..d {
            g[c] /= npf as f64;
            o += g[c] * n[c];
        }
        *out.opening = o;
        for ((sl, nm), (&gc, &nc)) in out
            .sliding
            .iter_mut()
            .zip(out.normal.iter_mut())
            .zip(g.iter().zip(&n))
        {
            *sl = gc - o * nc;
            *nm = nc;
        }
        if broken {
            // No force: contact alone acts between its faces.
            slots.fill(0.0);
            return None;
        }
        // Side A's force per unit area, Σ_g w_g N_k (σ n + τ), summed in registers; scaled
        // by the area and written once, side B's the opposite (exact action-reaction).
        let mut fa = [0.0f64; 9];
        let ns = self.n_state;
        let mut damage = 0.0f64;
        // 2D: the kinematics in the joint's frame (n, t = (−n_y, n_x)), once per joint:
        // each node pair's normal and tangential gap; at a Gauss point the opening and
        // the signed slip s_t are their interpolants, the slip vector s_t t and |s| = |s_t|.
        let tg = [-n[1], n[0]];
        let (mut gn, mut gt) = ([0.0; 2], [0.0; 2]);
        if d == 2 {
            for k in 0..2 {
                gn[k] = gap[2 * k] * n[0] + gap[2 * k + 1] * n[1];
                gt[k] = gap[2 * k] * tg[0] + gap[2 * k + 1] * tg[1];
            }
        }
        let mut point = |shape: &[f64; 3], w: f64, st: &mut [f64]| {
            let mut s = [0.0; 3];
            let (o, slip_norm) = if d == 2 {
                let o = shape[0] * gn[0] + shape[1] * gn[1];
                let st = shape[0] * gt[0] + shape[1] * gt[1];
                s[0] = st * tg[0];
                s[1] = st * tg[1];
                (o, st.abs())
            } else {
                // 3D: δ = Σ N_k gap_k, o = δ·n, s = δ − o n.
                let mut delta = [0.0; 3];
                for k in 0..npf {
                    for c in 0..d {
                        delta[c] += shape[k] * gap[k * d + c];
                    }
                }
                let o: f64 = (0..d).map(|c| delta[c] * n[c]).sum();
                for c in 0..d {
                    s[c] = delta[c] - o * n[c];
                }
                (o, slip_norm(&s[..d]))
            };
            let input = JointInput {
                opening: o,
                slip: &s[..d],
                slip_norm,
                h,
                coupling,
            };
            let t = model.traction_with(&input, st);
            // The largest damage (a comparison: f64::max's NaN handling costs more, and
            // a NaN damage is ignored either way).
            let dg = model.damage(st);
            if dg > damage {
                damage = dg;
            }
            let mut tv = [0.0; 3];
            for c in 0..d {
                tv[c] = t.normal * n[c] + t.shear[c];
            }
            for k in 0..npf {
                let wk = w * shape[k];
                for c in 0..d {
                    fa[k * d + c] += wk * tv[c];
                }
            }
        };
        // 2D: the three points as a fixed-size array, so the loop unrolls and what the
        // inlined model computes from h alone (1/h) is computed once per joint.
        if d == 2 {
            let rule: &[([f64; 3], f64); 3] = self.rule[..].try_into().expect("3 points in 2D");
            for ((shape, w), st) in rule.iter().zip(state.chunks_exact_mut(ns)) {
                point(shape, *w, st);
            }
        } else {
            for ((shape, w), st) in self.rule.iter().zip(state.chunks_exact_mut(ns)) {
                point(shape, *w, st);
            }
        }
        let (side_a, side_b) = slots.split_at_mut(npf * d);
        for ((sa, sb), &f) in side_a.iter_mut().zip(side_b).zip(&fa) {
            let f = area * f;
            *sa = f;
            *sb = -f;
        }
        Some(damage)
    }
}

impl<D: Dim> Physics<D> for CohesiveJoints {
    fn name(&self) -> &str {
        "cohesive joints"
    }

    fn kinematic_nodes(&self) -> KinematicNodes {
        KinematicNodes::None
    }

    fn writes_all_slots(&self) -> bool {
        true
    }

    fn fingerprint(&self) -> u64 {
        // The joints, the resolved models (parameters through Debug), the model of every
        // joint and the integration rule.
        let model_of: Vec<u32> = self.model_of.iter().map(|&m| u32::from(m)).collect();
        Fingerprint::new()
            .u32s(self.joints.nodes())
            .u32s(self.joints.elements())
            .u32s(self.joints.faces())
            .debug(&self.models)
            .u32s(&model_of)
            .u64(self.gauss_3d as u64)
            .finish()
    }

    fn fields(&self, mesh: &Mesh<D>) -> Vec<FieldUse> {
        let points = if D::D == 2 { 3 } else { self.gauss_3d };
        let ns = self.assigned_state_len();
        let nj = mesh.interfaces().len();
        let mut uses = vec![
            own_per_joint::<D>(JOINT_STATE, nj, Some(points * ns)),
            own_per_joint::<D>(JOINT_DAMAGE, nj, None),
            BROKEN_FACE.own::<D>(),
            own_per_joint::<D>(JOINT_OPENING, nj, None),
            own_per_joint::<D>(JOINT_SLIDING, nj, None),
            own_per_joint::<D>(JOINT_NORMAL, nj, None),
        ];
        // Coupling inputs are read lagged: a fluid physics reads the joints' openings
        // (JOINT_OPENING, written here in the forces stage) and so runs after the joints,
        // and a thermal physics is naturally composed after them too; a current-step
        // read would refuse those compositions. The value is the one the field holds
        // when the joints' forces stage runs: at most one explicit step old, the same on
        // both backends.
        uses.extend(
            CouplingInputs::keys(self.assignments.iter().map(|a| a.1.get().coupling()))
                .into_iter()
                .map(|k| k.read_lagged::<D>()),
        );
        uses
    }

    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        let (d, npf) = (D::D, D::NODES_PER_FACE);
        let mesh = ctx.mesh;
        // The mesh checked its interfaces against itself when it was built or read.
        self.joints = mesh.interfaces().clone();
        let nj = self.joints.len();
        let err = |m: String| ComputeError::physics("cohesive joints", m);
        if D::D == 3 && self.gauss_3d != 3 && self.gauss_3d != 7 {
            return Err(ComputeError::param(
                "Gauss points (3D)",
                self.gauss_3d,
                "must be 3 or 7",
            ));
        }
        if nj > 0 && self.assignments.is_empty() {
            return Err(err(
                "no joint model assigned: add CohesiveJoints::model".into()
            ));
        }
        for (_, list) in self.explicit.iter_mut() {
            list.sort_unstable();
            list.dedup();
            if let Some(&bad) = list.iter().find(|&&j| j as usize >= nj) {
                return Err(err(format!("joint {bad} does not exist ({nj} joints)")));
            }
        }
        self.rule = gauss_rule(d, self.gauss_3d);
        self.n_state = self.assigned_state_len();
        self.models = self.assignments.iter().map(|a| a.1.clone()).collect();
        // Model per joint by the midpoint of its side A.
        let mut model_of = vec![u16::MAX; nj];
        let mut mid = vec![0.0; d];
        for j in 0..nj {
            mid.fill(0.0);
            for &n in &self.joints.joint_nodes(j)[..npf] {
                for c in 0..d {
                    mid[c] += mesh.node(n as usize)[c] / npf as f64;
                }
            }
            for (i, (range, _)) in self.assignments.iter().enumerate() {
                let by_index = self.explicit.iter().find(|(k, _)| *k == i);
                let hit = match by_index {
                    Some((_, list)) => list.binary_search(&(j as u32)).is_ok(),
                    None => range.contains_point(&mid).map_err(|e| err(e.to_string()))?,
                };
                if hit {
                    model_of[j] = i as u16;
                }
            }
        }
        if let Some(j) = model_of.iter().position(|&m| m == u16::MAX) {
            return Err(err(format!(
                "joint {j} has no model: no assigned range contains its midpoint"
            )));
        }
        self.model_of = model_of;
        // Characteristic length h: mean edge length of the two adjacent elements.
        let (npe, mut x) = (D::NODES_PER_ELEM, [0.0; 12]);
        let mut mean_edge = |e: usize| {
            mesh.element_coords(e, &mut x[..npe * d]);
            let (mut s, mut c) = (0.0, 0.0);
            for a in 0..npe {
                for b in a + 1..npe {
                    s += (0..d)
                        .map(|k| (x[a * d + k] - x[b * d + k]).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    c += 1.0;
                }
            }
            s / c
        };
        self.h = (0..nj)
            .map(|j| {
                0.5 * (mean_edge(self.joints.elements()[2 * j] as usize)
                    + mean_edge(self.joints.elements()[2 * j + 1] as usize))
            })
            .collect();
        let state = ctx.fields.id(JOINT_STATE)?;
        let ids = [
            state,
            ctx.fields.id(JOINT_DAMAGE)?,
            ctx.fields.id(BROKEN_FACE)?,
            ctx.fields.id(JOINT_OPENING)?,
            ctx.fields.id(JOINT_SLIDING)?,
            ctx.fields.id(JOINT_NORMAL)?,
        ];
        let stride = self.state_stride();
        let st = ctx.fields.get_mut(state);
        let ns = self.n_state;
        for j in 0..nj {
            let m = self.models[self.model_of[j] as usize].get();
            for g in 0..self.rule.len() {
                m.init_state(&mut st[j * stride + g * ns..j * stride + g * ns + m.n_state()]);
            }
        }
        self.ids = Some(ids);
        let models: Vec<(&str, &[FieldKey])> = self
            .models
            .iter()
            .map(|m| (m.get().name(), m.get().coupling()))
            .collect();
        self.coupling =
            CouplingInputs::resolve(&models, ctx.fields, self.joints.len(), "joint model")?;
        ctx.register_slots(self.joints.nodes())?;
        Ok(())
    }

    fn stable_step(&self, kin: &Kinematics<'_, D>, fields: &FieldStore) -> Option<StableStep> {
        let npf = D::NODES_PER_FACE;
        let mut best: Option<(f64, usize)> = None;
        let mut mid = [0.0; 9];
        let mut n = [0.0; 3];
        // A joint to a null element (the null model) is a free face: no stiffness.
        let null = fields
            .id(pcdc_compute::names::ELEMENT_NULL)
            .ok()
            .map(|id| fields.get(id));
        let elements = self.joints.elements();
        for j in 0..self.joints.len() {
            if null.is_some_and(|z| {
                z[elements[2 * j] as usize] != 0.0 || z[elements[2 * j + 1] as usize] != 0.0
            }) {
                continue;
            }
            let nodes = self.joints.joint_nodes(j);
            for k in 0..npf {
                mid[k * D::D..(k + 1) * D::D].copy_from_slice(kin.mesh.node(nodes[k] as usize));
            }
            let area = D::face_measure_normal(&mid[..npf * D::D], &mut n[..D::D]);
            let k_node = self.models[self.model_of[j] as usize]
                .get()
                .max_stiffness(self.h[j])
                * area
                / npf as f64;
            for k in 0..npf {
                let (ma, mb) = (
                    kin.mass[nodes[k] as usize],
                    kin.mass[nodes[npf + k] as usize],
                );
                let omega = (k_node * (1.0 / ma + 1.0 / mb)).sqrt();
                let dt = 2.0 / omega;
                if best.is_none_or(|b| dt < b.0) {
                    best = Some((dt, j));
                }
            }
        }
        best.map(|(dt, j)| StableStep {
            dt,
            entity: Entity::new(EntityKind::Joint, j),
            physics: "cohesive joints".into(),
        })
    }

    fn slot_entity(&self, slot: usize) -> Option<String> {
        Some(format!("joint {}", slot / (2 * D::NODES_PER_FACE)))
    }

    fn compute_forces(&mut self, ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        let [sid, did, bid, oid, lid, nid] = self.ids.expect("init ran");
        let (d, npf) = (D::D, D::NODES_PER_FACE);
        let stride = self.state_stride();
        // Coupling values first (reading other physics' fields), then the joint loop.
        let cstride = self.coupling.stride;
        let mut cvalues = std::mem::take(&mut self.coupling.values);
        if cstride > 0 {
            self.gather_coupling::<D>(ctx.fields, &mut cvalues, ctx.backend);
        }
        let cref = &cvalues;
        let kin = &ctx.kin;
        let [state, damage, opening, sliding, normal] =
            ctx.fields.get_many_mut([sid, did, oid, lid, nid]);
        let slots = &mut *ctx.slots;
        ctx.backend.install(|| {
            slots
                .par_chunks_mut(CHUNK * 2 * npf * d)
                .zip(state.par_chunks_mut(CHUNK * stride))
                .zip(damage.par_chunks_mut(CHUNK))
                .zip(opening.par_chunks_mut(CHUNK))
                .zip(sliding.par_chunks_mut(CHUNK * d))
                .zip(normal.par_chunks_mut(CHUNK * d))
                .enumerate()
                .for_each(
                    |(c, (((((slots, state), damage), opening), sliding), normal))| {
                        let block = JointBlock {
                            first: c * CHUNK,
                            slots,
                            state,
                            damage,
                            opening,
                            sliding,
                            normal,
                        };
                        // The per-joint arrays as fixed-size vectors: V = D components, S =
                        // 2 NPF D slot values, J = 2 NPF nodes.
                        match d {
                            2 => self.joint_block::<D, 2, 8, 4>(block, kin, cref, cstride),
                            _ => self.joint_block::<D, 3, 18, 6>(block, kin, cref, cstride),
                        }
                    },
                )
        });
        self.coupling.values = cvalues;
        let [damage, broken] = ctx.fields.get_many_mut([did, bid]);
        for (j, &dmg) in damage.iter().enumerate() {
            if dmg >= 1.0 {
                broken[self.joints.faces()[2 * j] as usize] = 1.0;
                broken[self.joints.faces()[2 * j + 1] as usize] = 1.0;
            }
        }
        Ok(())
    }

    fn gpu_setup(&mut self, setup: &mut GpuSetup<'_, D>) -> Result<(), ComputeError> {
        let nj = self.joints.len();
        if nj == 0 {
            return Ok(());
        }
        if self.model_of.len() != nj {
            return Err(ComputeError::Gpu(
                "cohesive joints: GPU setup before init".to_string(),
            ));
        }
        let npf = D::NODES_PER_FACE;
        // Real data: Gauss points (N_0, N_1, N_2, w), then the model parameters, then h.
        let mut data = Vec::with_capacity(4 * self.rule.len() + nj);
        for (shape, w) in &self.rule {
            data.extend_from_slice(shape);
            data.push(*w);
        }
        // One WGSL function per distinct model key; parameters per model.
        let mut bodies = Vec::with_capacity(self.models.len());
        for m in self.models.iter().map(Model::get) {
            bodies.push(m.wgsl().ok_or_else(|| ComputeError::NoGpuKernel {
                physics: "cohesive joints".into(),
                reason: format!(
                    "joint model '{}' has no WGSL body (implement JointModel::wgsl)",
                    m.name()
                ),
            })?);
        }
        // With coupling, every model function takes `coupling: JointCoupling` before `p`.
        let coupled = self.coupling.stride > 0;
        let (params, args) = if coupled {
            (
                "o: Real, slip: JointVec, slip_norm: Real, h: Real, state: ptr<function, JointState>, coupling: JointCoupling, p: u32",
                "o, slip, slip_norm, h, state, coupling, p",
            )
        } else {
            (
                "o: Real, slip: JointVec, slip_norm: Real, h: Real, state: ptr<function, JointState>, p: u32",
                "o, slip, slip_norm, h, state, p",
            )
        };
        let splice = splice_models(
            "joint_model",
            params,
            args,
            "JointTraction",
            None,
            bodies.iter().map(|w| (w.key.as_str(), w.body.as_str())),
        );

        let mut model_info = Vec::with_capacity(bodies.len());
        for (w, kind) in bodies.iter().zip(&splice.kinds) {
            model_info.push([*kind, data.len() as u32]);
            data.extend_from_slice(&w.params);
        }
        let h_at = data.len();
        data.extend_from_slice(&self.h);
        // Per joint: side A nodes, side B nodes, faces A and B, model kind, parameter
        // offset; with coupling also the model index and the elements A and B.
        let info_stride = 2 * npf + if coupled { 7 } else { 4 };
        let mut info = Vec::with_capacity(nj * info_stride);
        for j in 0..nj {
            info.extend_from_slice(self.joints.joint_nodes(j));
            info.extend_from_slice(&self.joints.faces()[2 * j..2 * j + 2]);
            info.extend_from_slice(&model_info[self.model_of[j] as usize]);
            if coupled {
                info.push(u32::from(self.model_of[j]));
                info.extend_from_slice(&self.joints.elements()[2 * j..2 * j + 2]);
            }
        }
        let info = setup.upload("joint info", GpuData::U32(info));
        let data = setup.upload("joint data", GpuData::Real(data));
        // The kernel marks the coupling values (computed once per joint) with
        // `/*coupling_values*/` and the model call's argument with `/*coupling*/`;
        // without coupling both marks vanish and the source is unchanged.
        let (coupling_src, template) = if coupled {
            (
                self.coupling_wgsl::<D>(),
                JOINT_KERNEL
                    .replace(
                        "/*coupling_values*/",
                        "\n    let jc = joint_coupling_of(j, r);",
                    )
                    .replace("/*coupling*/", "jc, "),
            )
        } else {
            (
                String::new(),
                JOINT_KERNEL
                    .replace("/*coupling_values*/", "")
                    .replace("/*coupling*/", ""),
            )
        };
        let source = format!(
            "alias JointVec = array<Real, 3>;\nalias JointState = array<Real, NSTATE>;\nstruct JointTraction {{\n    normal: Real,\n    shear: JointVec,\n    damage: Real,\n}}\nfn param(p: u32, k: u32) -> Real {{ return joint_data[p + k]; }}\n{JOINT_LIBRARY}{WGSL_GEOMETRY}{}{coupling_src}{template}",
            splice.source
        );

        let mut kernel = Kernel::new(format!("cohesive joints {}", D::NAME), source, nj)
            .const_u32("D", D::D as u32)
            .const_u32("NPF", npf as u32)
            .const_u32("NGAUSS", self.rule.len() as u32)
            .const_u32("NSTATE", self.n_state as u32)
            .const_u32("INFO", info_stride as u32)
            .const_u32("GAUSS_AT", 0)
            .const_u32("H_AT", h_at as u32)
            .const_u32("SLOT_FIRST", setup.slot_first());
        for (name, v) in crate::model::wgsl_library_constants() {
            kernel = kernel.const_real(&name, v);
        }
        let kernel = kernel
            .bind("coords", setup.coords(), Access::Read)
            .bind("disp", setup.displacement(), Access::Read)
            .bind("joint_info", info, Access::Read)
            .bind("joint_data", data, Access::Read)
            .bind("joint_state", setup.field(JOINT_STATE)?, Access::ReadWrite)
            .bind(
                "joint_damage",
                setup.field(JOINT_DAMAGE)?,
                Access::ReadWrite,
            )
            .bind("broken_face", setup.field(BROKEN_FACE)?, Access::ReadWrite)
            .bind(
                "joint_opening",
                setup.field(JOINT_OPENING)?,
                Access::ReadWrite,
            )
            .bind(
                "joint_sliding",
                setup.field(JOINT_SLIDING)?,
                Access::ReadWrite,
            )
            .bind(
                "joint_normal",
                setup.field(JOINT_NORMAL)?,
                Access::ReadWrite,
            )
            .bind("slots", setup.slots(), Access::ReadWrite);
        let kernel = if coupled {
            self.coupling
                .bind(setup, kernel, "joint_coupling", "joint coupling")?
        } else {
            kernel
        };
        setup.kernel(Phase::Forces, kernel)
    }
}

#[cfg(test)]
mod gpu_tests {
    use super::*;
    use crate::{IntrinsicCzm, IntrinsicCzmParams, MohrCoulombJointParams, Traction};
    use pcdc_compute::gpu::{offline_kernel_sources, validate_wgsl};
    use pcdc_compute::Precision;
    use pcdc_mesh::{builders, split_nodes};

    /// A joint model without a WGSL body (CPU only).
    #[derive(Debug)]
    struct CpuOnly;
    impl JointModel for CpuOnly {
        fn name(&self) -> &str {
            "cpu-only-joint"
        }
        fn n_state(&self) -> usize {
            1
        }
        fn traction(&self, _: f64, _: &[f64], _: f64, _: &mut [f64]) -> Traction {
            Traction::default()
        }
        fn max_stiffness(&self, _: f64) -> f64 {
            1e12
        }
        fn is_broken(&self, _: &[f64]) -> bool {
            false
        }
    }

    fn czm() -> IntrinsicCzm {
        IntrinsicCzmParams {
            friction_deg: 30.0,
            cohesion: 10e6,
            tensile_strength: 2e6,
            gf1: 0.5,
            gf2: 5.0,
            penalty_open: 3e11,
            penalty_shear: 3e11,
            penalty_overlap: 3e12,
        }
        .build()
        .unwrap()
    }

    /// Both built-in models (CZM everywhere, Mohr-Coulomb on one half, a second CZM
    /// with other parameters that shares the first one's WGSL function).
    fn joints(gauss_3d: usize) -> CohesiveJoints {
        let half = Range::HalfSpace {
            point: [0.5, 0.0, 0.0],
            normal: [1.0, 0.0, 0.0],
        };
        let weak = IntrinsicCzmParams {
            friction_deg: 25.0,
            cohesion: 5e6,
            tensile_strength: 1e6,
            gf1: 0.2,
            gf2: 2.0,
            penalty_open: 3e11,
            penalty_shear: 3e11,
            penalty_overlap: 3e12,
        }
        .build()
        .unwrap();
        CohesiveJoints::new()
            .model(Range::All, czm())
            .model(
                half,
                MohrCoulombJointParams {
                    friction_deg: 30.0,
                    cohesion: 0.0,
                    penalty_normal: 3e12,
                    penalty_shear: 3e11,
                }
                .build()
                .unwrap(),
            )
            .model_for(vec![0, 1], weak)
            .gauss_points_3d(gauss_3d)
    }

    #[test]
    fn joint_kernels_validate_with_naga() {
        let m2 = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.25).unwrap();
        let m3 = builders::cuboid([0.0; 3], [1.0; 3], 0.5).unwrap();
        let s2 = split_nodes(&m2, &Range::All).unwrap();
        let s3 = split_nodes(&m3, &Range::All).unwrap();
        for p in [Precision::F64, Precision::F32] {
            let k2 = offline_kernel_sources::<_>(&s2, vec![Box::new(joints(3))], p).unwrap();
            let mut all = k2.clone();
            for g in [3, 7] {
                all.extend(offline_kernel_sources::<_>(&s3, vec![Box::new(joints(g))], p).unwrap());
            }
            let joint_kernels: Vec<_> = all
                .iter()
                .filter(|(l, _)| l.starts_with("cohesive joints"))
                .collect();
            assert_eq!(joint_kernels.len(), 3);
            for (label, src) in &all {
                if let Err(e) = validate_wgsl(src) {
                    panic!("{label} ({}) does not validate:\n{e}", p.name());
                }
            }
            // Two CZMs share one WGSL function; the Mohr-Coulomb joint has its own.
            let (_, src) = joint_kernels[0];
            assert_eq!(src.matches("fn joint_model_").count(), 2, "{src}");
        }
    }

    #[test]
    fn no_joints_no_kernel() {
        let m2 = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
        let j = CohesiveJoints::new();
        let k = offline_kernel_sources::<_>(&m2, vec![Box::new(j)], Precision::F64).unwrap();
        assert!(k.iter().all(|(l, _)| !l.starts_with("cohesive joints")));
    }

    #[test]
    fn joint_model_without_wgsl_is_a_build_error_naming_it() {
        let m2 = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
        let s2 = split_nodes(&m2, &Range::All).unwrap();
        let j = CohesiveJoints::new()
            .model(Range::All, czm())
            .model_for(vec![0], CpuOnly);
        let err = offline_kernel_sources::<_>(&s2, vec![Box::new(j)], Precision::F64).unwrap_err();
        assert!(matches!(err, ComputeError::NoGpuKernel { .. }), "{err:?}");
        let msg = err.to_string();
        assert!(
            msg.contains("cpu-only-joint") && msg.contains("WGSL"),
            "{msg}"
        );
    }
}
