//! Heat across broken joints whose faces still touch (manual eq. 111–112): a contact
//! conductance h_c (W/(m²·K)) between the node pairs of the joint.
//!
//! Node l of side A receives (1/N) h_c A (T_m − T_l), m its partner on side B, and m the
//! opposite (eq. 112), with A the joint's face measure in the reference configuration
//! and N its nodes per face. \[NOT IN MANUAL: the manual pairs element temperatures
//! (eq. 111, T_i, T_j "of the elements"); the node pairs of the joint are the local form
//! of the same exchange, and exact for a flat crack under a uniform jump.\] The faces
//! touch while the joint's opening o (`names::JOINT_OPENING`, from the cohesive joints)
//! lies in [−L/2, 0] and its sliding |s| (`names::JOINT_SLIDING`) stays below L/2, L the
//! face's size (length in 2D, √A in 3D): an open crack insulates, and faces that slid or
//! passed far from each other do not conduct. Contact between faces that were never
//! joined (fragments meeting elsewhere) carries no heat yet.
//!
//! Explicit: h_c A / N joins each node's Gershgorin row for the stable step.

use pcdc_compute::ComputeError;
use pcdc_mesh::{Dim, Mesh};

/// Per mesh node, its joint node pairs (CSR): joint, partner node, share A/N (m²; m in
/// 2D), and per joint the contact size L.
#[derive(Clone, Debug, Default)]
pub(crate) struct Pairs {
    pub(crate) h: f64,
    pub(crate) ptr: Vec<u32>,
    /// Joint and partner of each entry, interleaved.
    pub(crate) entries: Vec<u32>,
    pub(crate) share: Vec<f64>,
    pub(crate) size: Vec<f64>,
}

/// Measure of the face with `nodes` (length, triangle or fan-triangulated polygon area).
fn face_measure<D: Dim>(mesh: &Mesh<D>, nodes: &[u32]) -> f64 {
    let p = |n: u32| {
        let x = mesh.node(n as usize);
        let mut v = [0.0; 3];
        v[..D::D].copy_from_slice(x);
        v
    };
    if nodes.len() == 2 {
        let (a, b) = (p(nodes[0]), p(nodes[1]));
        return ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt();
    }
    let o = p(nodes[0]);
    let mut area = 0.0;
    for k in 1..nodes.len() - 1 {
        let (a, b) = (p(nodes[k]), p(nodes[k + 1]));
        let (u, v) = (
            [a[0] - o[0], a[1] - o[1], a[2] - o[2]],
            [b[0] - o[0], b[1] - o[1], b[2] - o[2]],
        );
        let c = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        area += 0.5 * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    }
    area
}

/// The pairs of every joint of `mesh`, with conductance `h` (checked: ≥ 0, finite).
pub(crate) fn pairs<D: Dim>(mesh: &Mesh<D>, h: f64) -> Result<Pairs, ComputeError> {
    if !(h >= 0.0 && h.is_finite()) {
        return Err(ComputeError::param(
            "contact conductance h_c",
            h,
            "must be non-negative and finite (W/(m²·K))",
        ));
    }
    let joints = mesh.interfaces();
    let nn = mesh.n_nodes();
    let mut list: Vec<(u32, u32, u32, f64)> = Vec::new();
    let mut size = Vec::with_capacity(joints.len());
    for j in 0..joints.len() {
        let nodes = joints.joint_nodes(j);
        let npf = nodes.len() / 2;
        let a = face_measure(mesh, &nodes[..npf]);
        size.push(if npf == 2 { a } else { a.sqrt() });
        let share = a / npf as f64;
        for k in 0..npf {
            let (na, nb) = (nodes[k], nodes[npf + k]);
            list.push((na, j as u32, nb, share));
            list.push((nb, j as u32, na, share));
        }
    }
    list.sort_by_key(|x| (x.0, x.1, x.2));
    let mut ptr = vec![0u32; nn + 1];
    for e in &list {
        ptr[e.0 as usize + 1] += 1;
    }
    for n in 0..nn {
        ptr[n + 1] += ptr[n];
    }
    let mut entries = Vec::with_capacity(2 * list.len());
    let mut share = Vec::with_capacity(list.len());
    for (_, j, m, s) in list {
        entries.extend_from_slice(&[j, m]);
        share.push(s);
    }
    Ok(Pairs {
        h,
        ptr,
        entries,
        share,
        size,
    })
}

/// Whether the faces of a broken joint touch: opening in [−L/2, 0], sliding below L/2.
#[inline]
pub(crate) fn touching(opening: f64, sliding: &[f64], size: f64) -> bool {
    let s2: f64 = sliding.iter().map(|x| x * x).sum();
    opening <= 0.0 && opening >= -0.5 * size && s2 <= 0.25 * size * size
}

/// Contact heat rate into node `n` (W; W/m in 2D) at temperatures `t`, over its pairs on
/// broken joints whose faces touch, in entry order.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn rate(
    p: &Pairs,
    n: usize,
    dim: usize,
    t: &[f64],
    damage: &[f64],
    opening: &[f64],
    sliding: &[f64],
) -> f64 {
    let mut r = 0.0;
    for e in p.ptr[n] as usize..p.ptr[n + 1] as usize {
        let (j, m) = (p.entries[2 * e] as usize, p.entries[2 * e + 1] as usize);
        if damage[j] >= 1.0 && touching(opening[j], &sliding[j * dim..(j + 1) * dim], p.size[j]) {
            r += p.h * p.share[e] * (t[m] - t[n]);
        }
    }
    r
}

/// Each node's largest contact row, Σ h_c A/N over its pairs (W/K), for the stable step.
pub(crate) fn rows(p: &Pairs, nn: usize) -> Vec<f64> {
    (0..nn)
        .map(|n| {
            (p.ptr[n] as usize..p.ptr[n + 1] as usize)
                .map(|e| p.h * p.share[e])
                .sum()
        })
        .collect()
}
