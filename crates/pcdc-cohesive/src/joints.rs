//! The face-joint physics: joint forces from a [`JointModel`] integrated over each
//! joint face (manual 7.4.1: 3 Gauss points in 2D, 3 or 7 in 3D).
//!
//! Kinematics of a joint: the midplane of its two sides gives the unit normal n (from
//! side A to side B) and the area; at each Gauss point the gap vector
//! δ = Σ N_k (x_B,k − x_A,k) splits into the opening o = δ·n and the slip vector
//! s = δ − o n. The model returns the normal traction σ (positive pulls the sides
//! together) and the shear magnitude τ (against the slip); side A receives
//! `w A N_k (σ n + τ s/|s|)` and side B the opposite (exact action-reaction).
//!
//! Fields: `joint_state` (model history per Gauss point), `joint_damage` (largest D per
//! joint, for output), and `broken_face` (1 on both faces of a fully broken joint, on
//! the split mesh's faces: the field contact picks up).

use std::sync::Arc;

use pcdc_compute::{
    Backend, ComputeError, FieldId, FieldSpec, FieldStore, ForceContext, InitContext, Kinematics,
    Location, Physics, StableStep,
};
use pcdc_mesh::{Dim, Mesh, Range};
use rayon::prelude::*;

use crate::{JointModel, Joints};

/// Name of the joint history field.
pub const JOINT_STATE: &str = "joint_state";
/// Name of the per-joint damage field (largest D over the Gauss points).
pub const JOINT_DAMAGE: &str = "joint_damage";
/// Name of the face field flagging the faces of broken joints (1 = broken).
pub const BROKEN_FACE: &str = "broken_face";

const CHUNK: usize = 256;

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

/// Face-joints with their constitutive models, as a physics.
#[derive(Debug)]
pub struct CohesiveJoints {
    joints: Joints,
    assignments: Vec<(Range, Arc<dyn JointModel>)>,
    /// Assignments by joint index: (index into `assignments`, joints).
    explicit: Vec<(usize, Vec<u32>)>,
    gauss_3d: usize,
    models: Vec<Arc<dyn JointModel>>,
    model_of: Vec<u16>,
    h: Vec<f64>,
    rule: Vec<([f64; 3], f64)>,
    n_state: usize,
    ids: Option<[FieldId; 3]>,
}

impl CohesiveJoints {
    /// Joints of a split mesh (see [`crate::split_nodes`]); assign models with
    /// [`CohesiveJoints::model`].
    pub fn new(joints: Joints) -> Self {
        CohesiveJoints {
            joints,
            assignments: Vec::new(),
            explicit: Vec::new(),
            gauss_3d: 3,
            models: Vec::new(),
            model_of: Vec::new(),
            h: Vec::new(),
            rule: Vec::new(),
            n_state: 1,
            ids: None,
        }
    }

    /// Assigns a joint model to the joints whose midpoint lies in `range`; later
    /// assignments override earlier ones.
    pub fn model(mut self, range: Range, model: impl JointModel + 'static) -> Self {
        self.assignments.push((range, Arc::new(model)));
        self
    }

    /// Assigns a joint model to the listed joints (e.g. from
    /// [`crate::joints_on_fractures`]); later assignments override earlier ones.
    pub fn model_for(mut self, joints: Vec<u32>, model: impl JointModel + 'static) -> Self {
        self.explicit.push((self.assignments.len(), joints));
        self.assignments
            .push((Range::custom(|_| false), Arc::new(model)));
        self
    }

    /// Gauss points per joint face in 3D: 3 (default) or 7.
    pub fn gauss_points_3d(mut self, n: usize) -> Self {
        self.gauss_3d = n;
        self
    }

    /// The joints.
    pub fn joints(&self) -> &Joints {
        &self.joints
    }

    /// History variables per Gauss point: the largest of the assigned models (≥ 1).
    fn assigned_state_len(&self) -> usize {
        self.assignments
            .iter()
            .map(|a| a.1.n_state())
            .max()
            .unwrap_or(1)
            .max(1)
    }

    fn state_stride(&self) -> usize {
        self.rule.len() * self.n_state
    }

    /// Joint `j`'s forces into `slots` (2·NPF·D values) and its state update.
    fn joint<D: Dim>(
        &self,
        j: usize,
        kin: &Kinematics<'_, D>,
        slots: &mut [f64],
        state: &mut [f64],
    ) -> f64 {
        let (d, npf) = (D::D, D::NODES_PER_FACE);
        let nodes = &self.joints.nodes[j * 2 * npf..(j + 1) * 2 * npf];
        let mut mid = [0.0; 9];
        let mut gap = [0.0; 9];
        for k in 0..npf {
            for c in 0..d {
                let (xa, xb) = (
                    kin.x(nodes[k] as usize, c),
                    kin.x(nodes[npf + k] as usize, c),
                );
                mid[k * d + c] = 0.5 * (xa + xb);
                gap[k * d + c] = xb - xa;
            }
        }
        let mut n = [0.0; 3];
        let area = D::face_measure_normal(&mid[..npf * d], &mut n[..d]);
        slots.fill(0.0);
        let model = &self.models[self.model_of[j] as usize];
        let ns = self.n_state;
        let mut damage = 0.0f64;
        for (g, (shape, w)) in self.rule.iter().enumerate() {
            let mut delta = [0.0; 3];
            for k in 0..npf {
                for c in 0..d {
                    delta[c] += shape[k] * gap[k * d + c];
                }
            }
            let o: f64 = (0..d).map(|c| delta[c] * n[c]).sum();
            let mut s = [0.0; 3];
            for c in 0..d {
                s[c] = delta[c] - o * n[c];
            }
            let st = &mut state[g * ns..(g + 1) * ns];
            let t = model.traction(o, &s[..d], self.h[j], st);
            damage = damage.max(model.damage(st));
            let mut tv = [0.0; 3];
            for c in 0..d {
                tv[c] = t.normal * n[c] + t.shear[c];
            }
            for k in 0..npf {
                let f = w * area * shape[k];
                for c in 0..d {
                    slots[k * d + c] += f * tv[c];
                    slots[(npf + k) * d + c] -= f * tv[c];
                }
            }
        }
        damage
    }
}

impl<D: Dim, B: Backend> Physics<D, B> for CohesiveJoints {
    fn name(&self) -> &str {
        "cohesive joints"
    }

    fn fields(&self, _mesh: &Mesh<D>) -> Vec<FieldSpec> {
        let points = if D::D == 2 { 3 } else { self.gauss_3d };
        let ns = self.assigned_state_len();
        let nj = self.joints.len();
        vec![
            FieldSpec::new(JOINT_STATE, Location::Entities(nj), points * ns),
            FieldSpec::new(JOINT_DAMAGE, Location::Entities(nj), 1),
            FieldSpec::new(BROKEN_FACE, Location::Face, 1),
        ]
    }

    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        let (d, npf) = (D::D, D::NODES_PER_FACE);
        let mesh = ctx.mesh;
        let nj = self.joints.len();
        let err = |m: String| ComputeError::physics("cohesive joints", m);
        if D::D == 3 && self.gauss_3d != 3 && self.gauss_3d != 7 {
            return Err(ComputeError::param(
                "Gauss points (3D)",
                self.gauss_3d,
                "must be 3 or 7",
            ));
        }
        if self.joints.nodes.len() != nj * 2 * npf || self.joints.faces.len() != 2 * nj {
            return Err(err(format!(
                "joint arrays do not fit {} joints of {} nodes per side",
                nj, npf
            )));
        }
        if let Some(&bad) = self
            .joints
            .nodes
            .iter()
            .find(|&&n| n as usize >= mesh.n_nodes())
        {
            return Err(err(format!(
                "joint node {bad} is not a node of the mesh (was the mesh split with split_nodes?)"
            )));
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
            for &n in &self.joints.nodes[j * 2 * npf..j * 2 * npf + npf] {
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
                0.5 * (mean_edge(self.joints.elements[2 * j] as usize)
                    + mean_edge(self.joints.elements[2 * j + 1] as usize))
            })
            .collect();
        let state = ctx.fields.id(JOINT_STATE)?;
        let ids = [
            state,
            ctx.fields.id(JOINT_DAMAGE)?,
            ctx.fields.id(BROKEN_FACE)?,
        ];
        let stride = self.state_stride();
        let st = ctx.fields.get_mut(state);
        let ns = self.n_state;
        for j in 0..nj {
            let m = &self.models[self.model_of[j] as usize];
            for g in 0..self.rule.len() {
                m.init_state(&mut st[j * stride + g * ns..j * stride + g * ns + m.n_state()]);
            }
        }
        self.ids = Some(ids);
        ctx.register_slots(&self.joints.nodes)?;
        Ok(())
    }

    fn stable_step(&self, kin: &Kinematics<'_, D>, _fields: &FieldStore) -> Option<StableStep> {
        let npf = D::NODES_PER_FACE;
        let mut best: Option<(f64, usize)> = None;
        let mut mid = [0.0; 9];
        let mut n = [0.0; 3];
        for j in 0..self.joints.len() {
            let nodes = &self.joints.nodes[j * 2 * npf..(j + 1) * 2 * npf];
            for k in 0..npf {
                mid[k * D::D..(k + 1) * D::D].copy_from_slice(kin.mesh.node(nodes[k] as usize));
            }
            let area = D::face_measure_normal(&mid[..npf * D::D], &mut n[..D::D]);
            let k_node =
                self.models[self.model_of[j] as usize].max_stiffness(self.h[j]) * area / npf as f64;
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
            entity: format!("joint {j}"),
            physics: "cohesive joints".into(),
        })
    }

    fn compute_forces(&self, ctx: &mut ForceContext<'_, D, B>) -> Result<(), ComputeError> {
        let [sid, did, bid] = self.ids.expect("init ran");
        let (d, npf) = (D::D, D::NODES_PER_FACE);
        let stride = self.state_stride();
        let kin = &ctx.kin;
        let [state, damage] = ctx.fields.get_many_mut([sid, did]);
        let slots = &mut *ctx.slots;
        ctx.backend.install(|| {
            slots
                .par_chunks_mut(CHUNK * 2 * npf * d)
                .zip(state.par_chunks_mut(CHUNK * stride))
                .zip(damage.par_chunks_mut(CHUNK))
                .enumerate()
                .for_each(|(c, ((sl, st), dm))| {
                    for i in 0..dm.len() {
                        let j = c * CHUNK + i;
                        dm[i] = self.joint::<D>(
                            j,
                            kin,
                            &mut sl[i * 2 * npf * d..(i + 1) * 2 * npf * d],
                            &mut st[i * stride..(i + 1) * stride],
                        );
                    }
                })
        });
        let [damage, broken] = ctx.fields.get_many_mut([did, bid]);
        for (j, &dmg) in damage.iter().enumerate() {
            if dmg >= 1.0 {
                broken[self.joints.faces[2 * j] as usize] = 1.0;
                broken[self.joints.faces[2 * j + 1] as usize] = 1.0;
            }
        }
        Ok(())
    }
}
