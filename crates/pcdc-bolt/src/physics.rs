//! The bolts as one physics: bolt nodes with their own lumped masses, axial bar forces,
//! grout coupling to the host elements, face plates; and [`BoltBoundary`], the
//! conditions on bolt nodes (a physics of its own, whose forces count as applied loads).

use pcdc_compute::{
    names, ComputeError, Entity, EntityKind, EntitySet, FieldId, FieldStore, FieldUse, Fingerprint,
    ForceContext, InitContext, KinematicNodes, Kinematics, Physics, StableStep, VelocityContext,
};
use pcdc_mesh::{Dim, Mesh};
use rayon::prelude::*;

use crate::boundary::{BcKind, BoltBc, BoltNodes, ResolvedBc};
use crate::fields::*;
use crate::host::Locator;
use crate::material::{AxialLaw, SegmentState};
use crate::{Bolt, BoltError, NAME};

/// A segment: its two simulation nodes, reference length and law.
#[derive(Clone, Debug)]
pub(crate) struct Segment {
    pub n: [u32; 2],
    /// Reference vector from node 0 to node 1 (m; z = 0 in 2D).
    pub dx: [f64; 3],
    pub l0: f64,
    pub law: AxialLaw,
    /// Axial damping coefficient (N·s/m).
    pub damping: f64,
}

/// A bolt node: its simulation node, host element and weights, the grout's stiffnesses
/// over its tributary length, its bond factor, neighbouring segments and plate.
#[derive(Clone, Debug)]
pub(crate) struct BoltNode {
    pub node: u32,
    pub bolt: u32,
    pub host: u32,
    pub host_nodes: [u32; 4],
    pub weights: [f64; 4],
    /// 2D: the adjugate of the host's reference edge matrix D_m (dm3, −dm1, −dm2, dm0),
    /// so that D_x adj(D_m) = det(D_m) F gives the host's rotation without a division.
    pub ref_adj: [f64; 4],
    /// K_b,r,s l (N/m), 0 on the free length.
    pub k_axial: f64,
    /// Lateral grout stiffness × l (N/m).
    pub k_normal: f64,
    /// Tributary length over the spacing (m): bond capacity = S_b(σn) × this.
    pub bond_length: f64,
    /// The bond capacity without confinement, S_b(0) × `bond_length` (N): the capacity
    /// never falls below it (S_b grows with σn ≥ 0), so a grout force within it is
    /// elastic whatever the confinement, and the host's stress need not be read.
    pub cap_unconfined: f64,
    /// Bond constants (eq. 146-147): π (D_b + 2 T_g), C_r,g, tan φ_r,g, π D_b, C_b,g,
    /// tan φ_b,g.
    pub bond: [f64; 6],
    /// Segments before and after (u32::MAX: none).
    pub prev: u32,
    pub next: u32,
    /// Face plate stiffness (N/m), 0 without.
    pub plate: f64,
    /// Lumped mass (kg, per unit thickness in 2D).
    pub mass: f64,
}

pub(crate) const NONE: u32 = u32::MAX;

/// Fully grouted rock bolts and cables (manual 7.9): compose after the mechanics (the
/// grout's confinement reads the host elements' stress of the previous step).
///
/// Each bolt adds its nodes to the simulation (physics-owned degrees of freedom with
/// lumped masses ρ_b A_b (L_b0 + L_b1)/2, integrated with the mesh nodes). Per step:
/// the axial force of every segment (eq. 138-142), the grout force at every bolt node
/// against its host element's motion interpolated at the node (eq. 143-147), the
/// reaction to the host's nodes with the same weights (action = reaction exactly), the
/// face plate at the head, and the axial damping (eq. 148). See the crate docs.
#[derive(Clone)]
pub struct Bolts {
    bolts: Vec<Bolt>,
    pub(crate) segments: Vec<Segment>,
    pub(crate) nodes: Vec<BoltNode>,
    /// First bolt-node and segment index of each bolt.
    node_offset: Vec<usize>,
    segment_offset: Vec<usize>,
    ids: Option<Ids>,
    /// Work blocks of whole bolts (first node and first segment of each; see
    /// [`blocks`]): the unit of parallel work.
    blocks: Vec<(usize, usize)>,
    /// [`PARALLEL_FROM`] and [`BLOCK_NODES`] (tests vary them).
    blocking: (usize, usize),
}

#[derive(Clone, Copy, Debug)]
struct Ids {
    axial: FieldId,
    plastic: FieldId,
    state: FieldId,
    grout: FieldId,
    slip: FieldId,
    stress: FieldId,
    rotation: Option<FieldId>,
}

impl Default for Bolts {
    fn default() -> Self {
        Self::new()
    }
}

impl Bolts {
    /// No bolts yet.
    pub fn new() -> Self {
        Bolts {
            bolts: Vec::new(),
            segments: Vec::new(),
            nodes: Vec::new(),
            node_offset: Vec::new(),
            segment_offset: Vec::new(),
            ids: None,
            blocks: Vec::new(),
            blocking: (PARALLEL_FROM, BLOCK_NODES),
        }
    }

    /// Adds a bolt. Errors if another bolt has its name.
    pub fn bolt(mut self, bolt: Bolt) -> Result<Self, BoltError> {
        if self.bolts.iter().any(|b| b.name() == bolt.name()) {
            return Err(BoltError::Geometry {
                bolt: bolt.name().to_string(),
                reason: "another bolt has that name".into(),
            });
        }
        self.bolts.push(bolt);
        Ok(self)
    }

    /// The bolts, in the order added.
    pub fn bolts(&self) -> &[Bolt] {
        &self.bolts
    }

    /// The indices of bolt `b`'s nodes in the set [`BOLT_NODES`] (head first); `None`
    /// when there is no bolt `b`.
    pub fn node_range(&self, b: usize) -> Option<std::ops::Range<usize>> {
        let bolt = self.bolts.get(b)?;
        let first: usize = self.bolts[..b].iter().map(|x| x.points().len()).sum();
        Some(first..first + bolt.points().len())
    }

    /// The indices of bolt `b`'s segments in the set [`BOLT_SEGMENTS`] (head first);
    /// `None` when there is no bolt `b`.
    pub fn segment_range(&self, b: usize) -> Option<std::ops::Range<usize>> {
        let bolt = self.bolts.get(b)?;
        let first: usize = self.bolts[..b].iter().map(|x| x.segments()).sum();
        Some(first..first + bolt.segments())
    }

    /// A boundary physics for bolt nodes of these bolts (compose it after them).
    pub fn boundary(&self) -> BoltBoundary {
        BoltBoundary {
            bolts: self
                .bolts
                .iter()
                .enumerate()
                .map(|(b, x)| {
                    let s = x.material().properties().spacing.unwrap_or(1.0);
                    (x.name().to_string(), self.node_range(b).unwrap_or(0..0), s)
                })
                .collect(),
            items: Vec::new(),
            resolved: Vec::new(),
            accel: None,
        }
    }

    /// Builds segments and nodes (hosts located in the reference mesh).
    fn build<D: Dim>(&mut self, mesh: &Mesh<D>, first: usize) -> Result<(), BoltError> {
        let d = D::D;
        let two_d = d == 2;
        let locator = Locator::new(mesh);
        self.segments.clear();
        self.nodes.clear();
        self.node_offset.clear();
        self.segment_offset.clear();
        let mut node = first as u32;
        for (b, bolt) in self.bolts.iter().enumerate() {
            let props = bolt.material().properties();
            if !two_d && props.spacing.is_some() {
                return Err(BoltError::param(
                    format!("spacing of bolt '{}'", bolt.name()),
                    props.spacing.unwrap_or(1.0),
                    "applies to 2D models only (a 3D model places every bolt)",
                ));
            }
            let eff = bolt.material().effective(two_d);
            let pts = bolt.points();
            let n = pts.len();
            self.node_offset.push(self.nodes.len());
            self.segment_offset.push(self.segments.len());
            let seg0 = self.segments.len() as u32;
            for s in 0..n - 1 {
                self.segments.push(Segment {
                    n: [node + s as u32, node + s as u32 + 1],
                    dx: std::array::from_fn(|k| pts[s + 1][k] - pts[s][k]),
                    l0: bolt.segment_length(s),
                    law: eff.axial,
                    damping: eff.damping,
                });
            }
            let free = bolt.free();
            for (k, pt) in pts.iter().enumerate() {
                let lp = if k > 0 {
                    bolt.segment_length(k - 1)
                } else {
                    0.0
                };
                let ln = if k + 1 < n {
                    bolt.segment_length(k)
                } else {
                    0.0
                };
                let l = 0.5 * (lp + ln);
                let grouted = free <= 0.0 || bolt.arc_length(k) >= free * (1.0 - 1e-9);
                let host =
                    locator
                        .locate(&pt[..d], 1e-9)
                        .ok_or_else(|| BoltError::OutsideMesh {
                            bolt: bolt.name().to_string(),
                            node: k,
                            position: pt[..d].to_vec(),
                        })?;
                let mut host_nodes = [0u32; 4];
                host_nodes[..=d].copy_from_slice(mesh.element(host.element));
                let mut ref_adj = [0.0; 4];
                if two_d {
                    let x = |q: usize| mesh.node(host_nodes[q] as usize);
                    let (x0, x1, x2) = (x(0), x(1), x(2));
                    let dm = [x1[0] - x0[0], x2[0] - x0[0], x1[1] - x0[1], x2[1] - x0[1]];
                    ref_adj = [dm[3], -dm[1], -dm[2], dm[0]];
                }
                let bond = bolt.material().bond_constants();
                self.nodes.push(BoltNode {
                    node: node + k as u32,
                    bolt: b as u32,
                    host: host.element as u32,
                    host_nodes,
                    weights: host.weights,
                    ref_adj,
                    k_axial: if grouted { eff.shear * l } else { 0.0 },
                    k_normal: eff.normal * l,
                    bond_length: l * eff.bond_per_spacing,
                    cap_unconfined: crate::material::bond_strength(&bond, 0.0)
                        * (l * eff.bond_per_spacing),
                    bond,
                    prev: if k > 0 { seg0 + k as u32 - 1 } else { NONE },
                    next: if k + 1 < n { seg0 + k as u32 } else { NONE },
                    plate: if k == 0 {
                        bolt.plate().map_or(0.0, |p| p * eff.bond_per_spacing)
                    } else {
                        0.0
                    },
                    mass: eff.mass_per_length * l,
                });
            }
            node += n as u32;
        }
        Ok(())
    }

    /// Whether segment `s` lies in its bolt's free length (its midpoint does).
    fn segment_is_free(&self, b: usize, local: usize) -> bool {
        let bolt = &self.bolts[b];
        let mid = bolt.arc_length(local) + 0.5 * bolt.segment_length(local);
        mid < bolt.free()
    }
}

/// Confining stress normal to the bolt at its host (Pa, ≥ 0, compression): the mean
/// normal stress over the directions perpendicular to the axis `a` (global), from the
/// host's co-rotated stress `s` (xx, yy, xy in 2D; xx, yy, zz, xy, yz, xz in 3D) and
/// its rotation: in 2D `rot` = r (cos θ, sin θ) with any scale r ≠ 0 (see
/// [`rotation_2d`]; the stress along the axis is quadratic in it and divided by r²), in
/// 3D the mechanics' rotation matrix R (global = R σ Rᵀ).
fn confinement(d: usize, s: &[f64], a: &[f64; 3], rot: &[f64]) -> f64 {
    let (trace, saa) = if d == 2 {
        let (mut c, mut sn) = (rot[0], rot[1]);
        let mut r2 = c * c + sn * sn;
        if r2 <= 0.0 {
            (c, sn, r2) = (1.0, 0.0, 1.0);
        }
        // a_c = Rᵀ a with R = [[c, −s], [s, c]] (times r).
        let ac = [c * a[0] + sn * a[1], -sn * a[0] + c * a[1]];
        (
            s[0] + s[1],
            (ac[0] * ac[0] * s[0] + ac[1] * ac[1] * s[1] + 2.0 * ac[0] * ac[1] * s[2]) / r2,
        )
    } else {
        let ac: [f64; 3] =
            std::array::from_fn(|i| rot[i] * a[0] + rot[3 + i] * a[1] + rot[6 + i] * a[2]);
        (
            s[0] + s[1] + s[2],
            ac[0] * ac[0] * s[0]
                + ac[1] * ac[1] * s[1]
                + ac[2] * ac[2] * s[2]
                + 2.0 * (ac[0] * ac[1] * s[3] + ac[1] * ac[2] * s[4] + ac[0] * ac[2] * s[5]),
        )
    };
    (-(trace - saa) / (d - 1) as f64).max(0.0)
}

/// The rotation of a triangle from its reference to its current positions `xc` (x, y
/// of its three nodes) as r (cos θ, sin θ), θ the polar decomposition's angle of
/// F = D_x D_m⁻¹, scaled by r = det(D_m) |…| (any sign): computed as D_x adj(D_m) with
/// the adjugate `adj` of the reference edge matrix, so without a division (the
/// confinement only needs the direction; this runs for every bolt node every step).
fn rotation_2d(adj: &[f64; 4], xc: &[f64]) -> [f64; 2] {
    let dx = [xc[2] - xc[0], xc[4] - xc[0], xc[3] - xc[1], xc[5] - xc[1]];
    let f = [
        dx[0] * adj[0] + dx[1] * adj[2],
        dx[0] * adj[1] + dx[1] * adj[3],
        dx[2] * adj[0] + dx[3] * adj[2],
        dx[2] * adj[1] + dx[3] * adj[3],
    ];
    [f[0] + f[3], f[2] - f[1]]
}

/// Displacement of node `n` (m; z = 0 in 2D).
fn disp<D: Dim>(kin: &Kinematics<'_, D>, n: u32) -> [f64; 3] {
    let d = D::D;
    let mut u = [0.0; 3];
    u[..d].copy_from_slice(&kin.u[n as usize * d..n as usize * d + d]);
    u
}

/// A segment's current unit direction and elongation L − L₀ (m), the latter as
/// (2 ΔX·Δu + Δu·Δu) / (L + L₀) from the displacements, so that it keeps its digits
/// where L − L₀ from positions would cancel (a stiff bar's force would carry E A / L₀
/// times a rounding of the coordinates).
fn segment_state<D: Dim>(seg: &Segment, kin: &Kinematics<'_, D>) -> ([f64; 3], f64) {
    let (u0, u1) = (disp(kin, seg.n[0]), disp(kin, seg.n[1]));
    let du = [u1[0] - u0[0], u1[1] - u0[1], u1[2] - u0[2]];
    let x = &seg.dx;
    let dv = [x[0] + du[0], x[1] + du[1], x[2] + du[2]];
    let (e, l) = unit(dv);
    let q = 2.0 * (x[0] * du[0] + x[1] * du[1] + x[2] * du[2])
        + (du[0] * du[0] + du[1] * du[1] + du[2] * du[2]);
    (e, q / (l + seg.l0))
}

/// Displacement of bolt node `n` relative to its host's material point,
/// u_n − Σ_q w_q u_q (m): zero under any rigid motion, since the node sat at that point.
fn relative_disp<D: Dim>(n: &BoltNode, kin: &Kinematics<'_, D>) -> [f64; 3] {
    let mut r = disp(kin, n.node);
    for q in 0..=D::D {
        let u = disp(kin, n.host_nodes[q]);
        (0..3).for_each(|k| r[k] -= n.weights[q] * u[k]);
    }
    r
}

fn unit(v: [f64; 3]) -> ([f64; 3], f64) {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if l > 0.0 {
        // One division, not three (per segment and bolt node every step).
        let inv = 1.0 / l;
        ([v[0] * inv, v[1] * inv, v[2] * inv], l)
    } else {
        ([0.0; 3], 0.0)
    }
}

/// Bolt sets with fewer nodes than this run in one block on the calling thread. Measured
/// on the FDEM tunnel bench (880 bolt nodes, about 20 µs of work per step, 2 threads):
/// two halves in parallel were slower than one thread, the fork costing more than the
/// work it shares.
const PARALLEL_FROM: usize = 2048;

/// Nodes per work block of a larger set (whole bolts, so a block may hold more): small
/// enough that rayon's stealing balances the threads.
const BLOCK_NODES: usize = 512;

/// Groups whole bolts (given their first nodes and segments, and the node count) into
/// work blocks: one below `parallel_from` nodes ([`PARALLEL_FROM`]), else blocks of at
/// least `block_nodes` ([`BLOCK_NODES`]; the last may be smaller); returns each block's
/// first node and first segment.
fn blocks(
    node_offset: &[usize],
    segment_offset: &[usize],
    n_nodes: usize,
    (parallel_from, block_nodes): (usize, usize),
) -> Vec<(usize, usize)> {
    let size = if n_nodes < parallel_from {
        usize::MAX
    } else {
        block_nodes
    };
    let mut out: Vec<(usize, usize)> = Vec::new();
    let mut last = None;
    for (&n, &s) in node_offset.iter().zip(segment_offset) {
        if last.is_none_or(|l| n - l >= size) {
            out.push((n, s));
            last = Some(n);
        }
    }
    out
}

/// A segment's force vector on its end node's side (N: f e with f the axial force plus
/// damping) and its current unit direction e.
type SegmentOut = ([f64; 3], [f64; 3]);

/// What the walk reads besides the kinematics: the host stresses (and rotations in 3D).
struct Walk<'a> {
    stress: &'a [f64],
    rotation: &'a [f64],
}

/// A block of whole bolts and the entries it writes: its segments' axial force, plastic
/// elongation and state, its nodes' grout force and slip and force slots.
struct Block<'a> {
    first_segment: usize,
    segments: &'a [Segment],
    nodes: &'a [BoltNode],
    axial: &'a mut [f64],
    plastic: &'a mut [f64],
    state: &'a mut [f64],
    grout: &'a mut [f64],
    slip: &'a mut [f64],
    slots: &'a mut [f64],
}

impl Walk<'_> {
    /// Walks every bolt of `b` from head to toe: at each node, the segment starting
    /// there (axial force, eq. 138-142, plus damping, eq. 148), then the node with the
    /// segments before and after it. Each segment is computed once; every entry is
    /// written by one node or segment only (deterministic in any block split).
    fn block<D: Dim>(&self, b: Block<'_>, kin: &Kinematics<'_, D>) {
        let stride = (D::D + 2) * D::D;
        let mut prev: Option<SegmentOut> = None;
        for (i, n) in b.nodes.iter().enumerate() {
            let next = (n.next != NONE).then(|| {
                let s = n.next as usize - b.first_segment;
                segment(
                    &b.segments[s],
                    kin,
                    &mut b.axial[s],
                    &mut b.plastic[s],
                    &mut b.state[s],
                )
            });
            // A bolt's first node has no previous segment (`prev` then holds the last
            // segment of the bolt before, unused).
            let before = if n.prev != NONE { prev.as_ref() } else { None };
            self.node(
                n,
                before,
                next.as_ref(),
                kin,
                &mut b.slots[i * stride..(i + 1) * stride],
                &mut b.grout[i],
                &mut b.slip[i],
            );
            prev = next;
        }
    }

    /// One bolt node: its bar forces (previous then next segment), the grout against its
    /// host with the host's confinement, the lateral grout and the face plate; writes its
    /// slot and its host's `D + 1` slots (`slots`), its grout force and slip.
    #[allow(clippy::too_many_arguments)]
    fn node<D: Dim>(
        &self,
        n: &BoltNode,
        prev: Option<&SegmentOut>,
        next: Option<&SegmentOut>,
        kin: &Kinematics<'_, D>,
        slots: &mut [f64],
        grout: &mut f64,
        slip: &mut f64,
    ) {
        let d = D::D;
        // Bar forces on the node: +f e as the start of the next segment, −f e as the
        // end of the previous one (fixed order: previous, next).
        let mut f = [0.0; 3];
        if let Some((g, _)) = prev {
            (0..3).for_each(|k| f[k] -= g[k]);
        }
        if let Some((g, _)) = next {
            (0..3).for_each(|k| f[k] += g[k]);
        }
        // Axis at the node: mean of the adjacent segments' current directions.
        let mut axis = [0.0; 3];
        for (_, e) in [prev, next].into_iter().flatten() {
            (0..3).for_each(|k| axis[k] += e[k]);
        }
        let (a, _) = unit(axis);
        // Against the host's material point where the node was grouted.
        let r = relative_disp(n, kin);
        let delta = r[0] * a[0] + r[1] * a[1] + r[2] * a[2];
        // Grout along the axis: bond-slip with the host's confinement.
        let mut fs = 0.0;
        let trial = n.k_axial * (delta - *slip);
        if n.k_axial > 0.0 && trial.abs() <= n.cap_unconfined {
            // Elastic under any confinement: the same force and slip as below, exactly.
            fs = trial;
        } else if n.k_axial > 0.0 {
            let e = n.host as usize;
            let mut rot = [0.0; 9];
            if d == 2 {
                let mut xc = [0.0; 6];
                for q in 0..3 {
                    let p = kin.position(n.host_nodes[q] as usize);
                    xc[2 * q..2 * q + 2].copy_from_slice(&p[..2]);
                }
                rot[..2].copy_from_slice(&rotation_2d(&n.ref_adj, &xc));
            } else {
                rot.copy_from_slice(&self.rotation[9 * e..9 * e + 9]);
            }
            let nsym = D::NSYM;
            let sn = confinement(d, &self.stress[nsym * e..nsym * (e + 1)], &a, &rot);
            let cap = crate::material::bond_strength(&n.bond, sn) * n.bond_length;
            let (force, s) = crate::material::grout_force(delta, *slip, n.k_axial, cap);
            fs = force;
            *slip = s;
        }
        *grout = fs;
        // Lateral grout, and the face plate (one-sided, pushes the head back out).
        let mut g: [f64; 3] =
            std::array::from_fn(|k| fs * a[k] + n.k_normal * (r[k] - delta * a[k]));
        if n.plate > 0.0 && delta > 0.0 {
            (0..3).for_each(|k| g[k] += n.plate * delta * a[k]);
        }
        for k in 0..d {
            slots[k] = f[k] - g[k];
        }
        for q in 0..=d {
            let o = (q + 1) * d;
            for (k, gk) in g.iter().enumerate().take(d) {
                slots[o + k] = n.weights[q] * gk;
            }
        }
    }
}

/// One segment: the axial force in total form from its elongation (eq. 138-142) into
/// `axial`, `plastic`, `state`, plus damping on the relative axial velocity (eq. 148).
fn segment<D: Dim>(
    seg: &Segment,
    kin: &Kinematics<'_, D>,
    axial: &mut f64,
    plastic: &mut f64,
    state: &mut f64,
) -> SegmentOut {
    let d = D::D;
    let (e, elongation) = segment_state(seg, kin);
    let broken = SegmentState::from_value(*state) == SegmentState::Broken;
    let (f, up, st) = seg.law.update(elongation, seg.l0, *plastic, broken);
    *axial = f;
    *plastic = up;
    *state = st as i32 as f64;
    let mut total = f;
    if seg.damping > 0.0 && st != SegmentState::Broken {
        let (a, b) = (seg.n[0] as usize * d, seg.n[1] as usize * d);
        let rel: f64 = (0..d).map(|k| (kin.v[b + k] - kin.v[a + k]) * e[k]).sum();
        total += seg.damping * rel;
    }
    ([total * e[0], total * e[1], total * e[2]], e)
}

impl Bolts {
    /// Every bolt's segments and nodes in one walk per block (see [`Walk::block`]);
    /// blocks run in parallel when there are several.
    fn walk<D: Dim>(&mut self, ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        let d = D::D;
        let ids = self.ids.expect("init ran");
        let kin = &ctx.kin;
        // The host's stress (and rotation in 3D) are read in place.
        let ([axial, plastic, state, grout, slip], stress, rotation) = if let Some(r) = ids.rotation
        {
            let [a, p, st, g, sl, stress, rot] = ctx.fields.get_many_mut([
                ids.axial,
                ids.plastic,
                ids.state,
                ids.grout,
                ids.slip,
                ids.stress,
                r,
            ]);
            ([a, p, st, g, sl], &*stress, &*rot)
        } else {
            let [a, p, st, g, sl, stress] = ctx.fields.get_many_mut([
                ids.axial,
                ids.plastic,
                ids.state,
                ids.grout,
                ids.slip,
                ids.stress,
            ]);
            ([a, p, st, g, sl], &*stress, &[][..])
        };
        let walk = Walk { stress, rotation };
        let whole = Block {
            first_segment: 0,
            segments: &self.segments,
            nodes: &self.nodes,
            axial,
            plastic,
            state,
            grout,
            slip,
            slots: ctx.slots,
        };
        if self.blocks.len() <= 1 {
            walk.block(whole, kin);
        } else {
            split_blocks(whole, &self.blocks, (d + 2) * d)
                .into_par_iter()
                .for_each(|b| walk.block(b, kin));
        }
        Ok(())
    }
}

/// Cuts `whole` at the blocks' first nodes and segments (`stride` slot values per node).
fn split_blocks<'a>(
    mut rest: Block<'a>,
    blocks: &[(usize, usize)],
    stride: usize,
) -> Vec<Block<'a>> {
    let mut out = Vec::with_capacity(blocks.len());
    for w in blocks.windows(2) {
        let (n, s) = (w[1].0 - w[0].0, w[1].1 - w[0].1);
        let (axial, axial_r) = std::mem::take(&mut rest.axial).split_at_mut(s);
        let (plastic, plastic_r) = std::mem::take(&mut rest.plastic).split_at_mut(s);
        let (state, state_r) = std::mem::take(&mut rest.state).split_at_mut(s);
        let (grout, grout_r) = std::mem::take(&mut rest.grout).split_at_mut(n);
        let (slip, slip_r) = std::mem::take(&mut rest.slip).split_at_mut(n);
        let (slots, slots_r) = std::mem::take(&mut rest.slots).split_at_mut(n * stride);
        let (segments, segments_r) = rest.segments.split_at(s);
        let (nodes, nodes_r) = rest.nodes.split_at(n);
        out.push(Block {
            first_segment: w[0].1,
            segments,
            nodes,
            axial,
            plastic,
            state,
            grout,
            slip,
            slots,
        });
        rest = Block {
            first_segment: w[1].1,
            segments: segments_r,
            nodes: nodes_r,
            axial: axial_r,
            plastic: plastic_r,
            state: state_r,
            grout: grout_r,
            slip: slip_r,
            slots: slots_r,
        };
    }
    out.push(rest);
    out
}

impl<D: Dim> Physics<D> for Bolts {
    fn name(&self) -> &str {
        NAME
    }

    fn entity_sets(&self, mesh: &Mesh<D>) -> Vec<EntitySet> {
        // Added nodes are numbered from the mesh's node count (the engine shifts them).
        let first = mesh.n_nodes() as u32;
        let mut seg = Vec::new();
        let mut nodes = Vec::new();
        let mut n = first;
        for b in &self.bolts {
            for s in 0..b.segments() as u32 {
                seg.extend_from_slice(&[n + s, n + s + 1]);
            }
            nodes.extend(n..n + b.points().len() as u32);
            n += b.points().len() as u32;
        }
        vec![
            EntitySet::new(BOLT_SEGMENTS, 2, seg).expect("two nodes per segment"),
            EntitySet::new(BOLT_NODES, 1, nodes).expect("one node per entity"),
        ]
    }

    fn fields(&self, _mesh: &Mesh<D>) -> Vec<FieldUse> {
        let mut f = vec![
            BOLT_AXIAL_FORCE.own::<D>(),
            BOLT_PLASTIC_ELONGATION.own::<D>(),
            BOLT_STATE.own::<D>(),
            BOLT_GROUT_FORCE.own::<D>(),
            BOLT_SLIP.own::<D>(),
            names::STRESS.read_lagged::<D>(),
        ];
        if D::D == 3 {
            f.push(names::ROTATION.read_lagged::<D>());
        }
        f
    }

    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        if self.bolts.is_empty() {
            return Err(ComputeError::param(
                "bolts",
                0,
                "add at least one bolt (Bolts::bolt)",
            ));
        }
        let d = D::D;
        let first = ctx.n_nodes();
        self.build(ctx.mesh, first)?;
        let mut coords = Vec::with_capacity(self.nodes.len() * d);
        for b in &self.bolts {
            for p in b.points() {
                coords.extend_from_slice(&p[..d]);
            }
        }
        let mass: Vec<f64> = self.nodes.iter().map(|n| n.mass).collect();
        let block = ctx.add_nodes(&coords, &mass)?;
        debug_assert_eq!(block.first, first);
        // Slots: per bolt node, the node itself then its host's nodes.
        let mut slot_nodes = Vec::with_capacity(self.nodes.len() * (d + 2));
        for n in &self.nodes {
            slot_nodes.push(n.node);
            slot_nodes.extend_from_slice(&n.host_nodes[..=d]);
        }
        ctx.register_slots(&slot_nodes)?;
        let ids = Ids {
            axial: ctx.fields.id(BOLT_AXIAL_FORCE)?,
            plastic: ctx.fields.id(BOLT_PLASTIC_ELONGATION)?,
            state: ctx.fields.id(BOLT_STATE)?,
            grout: ctx.fields.id(BOLT_GROUT_FORCE)?,
            slip: ctx.fields.id(BOLT_SLIP)?,
            stress: ctx.fields.id(names::STRESS)?,
            rotation: if d == 3 {
                Some(ctx.fields.id(names::ROTATION)?)
            } else {
                None
            },
        };
        // Pretension: the free segments' natural length is shorter by f_pre L0 / EA.
        let mut plastic = vec![0.0; self.segments.len()];
        for (b, bolt) in self.bolts.iter().enumerate() {
            let pre = bolt.material().effective(d == 2).pretension;
            for local in 0..bolt.segments() {
                if pre > 0.0 && self.segment_is_free(b, local) {
                    let s = &self.segments[self.segment_offset[b] + local];
                    plastic[self.segment_offset[b] + local] = -pre * s.l0 / s.law.ea;
                }
            }
        }
        ctx.fields.get_mut(ids.plastic).copy_from_slice(&plastic);
        self.ids = Some(ids);
        self.blocks = blocks(
            &self.node_offset,
            &self.segment_offset,
            self.nodes.len(),
            self.blocking,
        );
        Ok(())
    }

    fn add_mass(&self, _mesh: &Mesh<D>, _f: &FieldStore, mass: &mut [f64], scale: Option<f64>) {
        // Physical masses came with the nodes (InitContext::add_nodes). For static
        // relaxation's mass scaling (critical step `t` everywhere): each bolt node gets
        // m = S t² / 4 with S its Gershgorin row sum, and each host node the row sum the
        // grout adds to it, 2 k w_q (the grout couples it to the bolt node and to the
        // host's other nodes with weights summing to 1). Doubled: Gershgorin's bound is
        // tight for a bar chain's zig-zag mode, and the relaxation's local damping can
        // add up to the force's own magnitude to it (α ≤ 1), which made it diverge.
        let Some(t) = scale else { return };
        let q = 2.0 * t * t / 4.0;
        let d = D::D;
        for n in &self.nodes {
            let k = n.k_axial.max(n.k_normal) + n.plate;
            let mut s = k;
            for seg in [n.prev, n.next] {
                if seg != NONE {
                    let seg = &self.segments[seg as usize];
                    s += 2.0 * seg.law.ea / seg.l0;
                }
            }
            mass[n.node as usize] += s * q;
            for a in 0..=d {
                mass[n.host_nodes[a] as usize] += 2.0 * k * n.weights[a].abs() * q;
            }
        }
    }

    fn stable_step(&self, _kin: &Kinematics<'_, D>, _fields: &FieldStore) -> Option<StableStep> {
        // Gershgorin per bolt node (hosts taken as fixed): ω² ≤ (Σ 2 EA/L₀ + k_grout +
        // k_plate) / m; axial damping lowers the step by √(1 + ζ²) − ζ.
        let mut best: Option<StableStep> = None;
        for (i, n) in self.nodes.iter().enumerate() {
            let (mut k, mut c) = (n.k_axial.max(n.k_normal) + n.plate, 0.0);
            for s in [n.prev, n.next] {
                if s != NONE {
                    let seg = &self.segments[s as usize];
                    k += 2.0 * seg.law.ea / seg.l0;
                    c += 2.0 * seg.damping;
                }
            }
            let omega = (k / n.mass).sqrt();
            let zeta = c / (2.0 * n.mass * omega);
            let dt = 2.0 / omega * ((1.0 + zeta * zeta).sqrt() - zeta);
            if best.as_ref().is_none_or(|b| dt < b.dt) {
                best = Some(StableStep {
                    dt,
                    entity: Entity::new(EntityKind::Other("bolt node"), i),
                    physics: NAME.into(),
                });
            }
        }
        best
    }

    fn writes_all_slots(&self) -> bool {
        true
    }

    fn kinematic_nodes(&self) -> KinematicNodes {
        // No kinematic conditions here (they are `BoltBoundary`'s): the engine keeps its
        // fused node pass.
        KinematicNodes::None
    }

    fn compute_forces(&mut self, ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        // The walk on the backend's pool (its thread count; a parallel iterator outside
        // it runs on rayon's global pool), entered once per step.
        let backend = ctx.backend;
        backend.install(|| self.walk(ctx))
    }

    fn stored_energy(&self, kin: &Kinematics<'_, D>, fields: &FieldStore) -> f64 {
        // Elastic energy of the bars and of the grout springs at the current state.
        let Some(ids) = self.ids else { return 0.0 };
        let axial = fields.get(ids.axial);
        let grout = fields.get(ids.grout);
        let mut e = 0.0;
        for (s, seg) in self.segments.iter().enumerate() {
            e += 0.5 * axial[s] * axial[s] * seg.l0 / seg.law.ea;
        }
        for (i, n) in self.nodes.iter().enumerate() {
            if n.k_axial > 0.0 {
                e += 0.5 * grout[i] * grout[i] / n.k_axial;
            }
            let r = relative_disp(n, kin);
            e += 0.5 * n.k_normal * (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        }
        e
    }

    fn check_fields(&self, fields: &FieldStore) -> Result<(), ComputeError> {
        let Some(ids) = self.ids else { return Ok(()) };
        if let Some(v) = fields
            .get(ids.state)
            .iter()
            .find(|v| !(**v >= 0.0 && **v <= 3.0 && v.fract() == 0.0))
        {
            return Err(ComputeError::SnapshotCorrupt(format!(
                "bolt segment state {v} is not one of 0, 1, 2, 3"
            )));
        }
        Ok(())
    }

    fn fingerprint(&self) -> u64 {
        // The bolts' geometry and properties (Debug prints every value exactly).
        let mut f = Fingerprint::new();
        for b in &self.bolts {
            f = f.debug(b);
        }
        f.finish()
    }

    fn gpu_setup(
        &mut self,
        setup: &mut pcdc_compute::gpu::GpuSetup<'_, D>,
    ) -> Result<(), ComputeError> {
        crate::gpu::bolts(self, setup)
    }

    fn slot_entity(&self, slot: usize) -> Option<String> {
        // Slots per bolt node: the node, then its host's D + 1 nodes.
        let n = self.nodes.get(slot / (D::D + 2))?;
        let b = &self.bolts[n.bolt as usize];
        let k = n.node as usize - self.nodes[self.node_offset[n.bolt as usize]].node as usize;
        Some(format!("bolt '{}' node {k}", b.name()))
    }
}

/// Boundary conditions on bolt nodes (manual 7.9.4, tables 20-21), made by
/// [`Bolts::boundary`] and composed after the bolts. Forces count as applied loads in
/// the energy balance.
pub struct BoltBoundary {
    /// Name, range in the bolt-node set and spacing of every bolt.
    bolts: Vec<(String, std::ops::Range<usize>, f64)>,
    items: Vec<BoltBc>,
    pub(crate) resolved: Vec<ResolvedBc>,
    accel: Option<FieldId>,
}

impl BoltBoundary {
    fn add(
        mut self,
        bolt: &str,
        nodes: BoltNodes,
        kind: BcKind,
        values: [Option<pcdc_compute::TimeValue>; 3],
    ) -> Result<Self, BoltError> {
        let Some((_, range, _)) = self.bolts.iter().find(|(n, _, _)| n == bolt) else {
            return Err(BoltError::Geometry {
                bolt: bolt.to_string(),
                reason: "a boundary condition names a bolt that does not exist".into(),
            });
        };
        for (k, v) in values.iter().enumerate() {
            if let Some(v) = v {
                v.check(&format!("bolt '{bolt}' boundary component {k}"))?;
            }
        }
        let item = BoltBc {
            bolt: bolt.to_string(),
            nodes,
            kind,
            values,
        };
        item.local_nodes(range.len())?;
        self.items.push(item);
        Ok(self)
    }

    /// Prescribed velocity (m/s) per component (`None`: free) on `nodes` of `bolt`.
    pub fn velocity(
        self,
        bolt: &str,
        nodes: BoltNodes,
        values: [Option<pcdc_compute::TimeValue>; 3],
    ) -> Result<Self, BoltError> {
        self.add(bolt, nodes, BcKind::Velocity, values)
    }

    /// Prescribed acceleration (m/s²) per component; the velocity is integrated from
    /// rest.
    pub fn acceleration(
        self,
        bolt: &str,
        nodes: BoltNodes,
        values: [Option<pcdc_compute::TimeValue>; 3],
    ) -> Result<Self, BoltError> {
        self.add(bolt, nodes, BcKind::Acceleration, values)
    }

    /// A force (N, per bolt: divided by the spacing in 2D) on each of `nodes`.
    pub fn force(
        self,
        bolt: &str,
        nodes: BoltNodes,
        values: [Option<pcdc_compute::TimeValue>; 3],
    ) -> Result<Self, BoltError> {
        self.add(bolt, nodes, BcKind::Force, values)
    }

    fn kinematic(&self) -> impl Iterator<Item = &ResolvedBc> {
        self.resolved.iter().filter(|r| r.kind != BcKind::Force)
    }
}

impl<D: Dim> Physics<D> for BoltBoundary {
    fn name(&self) -> &str {
        "bolt boundary"
    }

    fn fields(&self, _mesh: &Mesh<D>) -> Vec<FieldUse> {
        if self.items.iter().any(|i| i.kind == BcKind::Acceleration) {
            vec![BOLT_BC_VELOCITY.own::<D>()]
        } else {
            Vec::new()
        }
    }

    fn init(&mut self, ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
        let set = ctx.entity_set(BOLT_NODES).ok_or_else(|| {
            ComputeError::param(
                "bolt boundary",
                BOLT_NODES,
                "no bolts are composed before it: compose the Bolts it was made from first",
            )
        })?;
        let two_d = D::D == 2;
        self.resolved.clear();
        let mut slot_nodes = Vec::new();
        for item in &self.items {
            let (_, range, spacing) = self
                .bolts
                .iter()
                .find(|(n, _, _)| *n == item.bolt)
                .expect("checked when added");
            if range.end > set.len() {
                return Err(ComputeError::param(
                    "bolt boundary",
                    &item.bolt,
                    "made from other bolts than those composed",
                ));
            }
            let nodes: Vec<(u32, u32)> = item
                .local_nodes(range.len())?
                .into_iter()
                .map(|k| (set.nodes()[range.start + k], (range.start + k) as u32))
                .collect();
            if item.kind == BcKind::Force {
                slot_nodes.extend(nodes.iter().map(|n| n.0));
            }
            self.resolved.push(ResolvedBc {
                kind: item.kind,
                nodes,
                values: item.values.clone(),
                scale: if two_d { 1.0 / spacing } else { 1.0 },
            });
        }
        ctx.register_slots(&slot_nodes)?;
        self.accel = if self.items.iter().any(|i| i.kind == BcKind::Acceleration) {
            Some(ctx.fields.id(BOLT_BC_VELOCITY)?)
        } else {
            None
        };
        Ok(())
    }

    fn compute_forces(&mut self, ctx: &mut ForceContext<'_, D>) -> Result<(), ComputeError> {
        let d = D::D;
        let t = ctx.kin.time;
        let mut slot = 0;
        for r in self.resolved.iter().filter(|r| r.kind == BcKind::Force) {
            for _ in &r.nodes {
                for k in 0..d {
                    ctx.slots[slot * d + k] =
                        r.values[k].as_ref().map_or(0.0, |v| v.at(t)) * r.scale;
                }
                slot += 1;
            }
        }
        Ok(())
    }

    fn writes_all_slots(&self) -> bool {
        true
    }

    fn gpu_setup(
        &mut self,
        setup: &mut pcdc_compute::gpu::GpuSetup<'_, D>,
    ) -> Result<(), ComputeError> {
        crate::gpu::boundary(self, setup)
    }

    fn applies_loads(&self) -> bool {
        true
    }

    fn kinematic_nodes(&self) -> KinematicNodes {
        let nodes: Vec<u32> = self
            .kinematic()
            .flat_map(|r| r.nodes.iter().map(|n| n.0))
            .collect();
        if nodes.is_empty() {
            KinematicNodes::None
        } else {
            KinematicNodes::Nodes(nodes)
        }
    }

    fn apply_kinematics(&mut self, ctx: &mut VelocityContext<'_, D>) {
        // As the mechanical boundary: velocities at the half step, accelerations at the
        // start of the step (`ctx.time` is the end of the step).
        let d = D::D;
        for r in &self.resolved {
            match r.kind {
                BcKind::Force => {}
                BcKind::Velocity => {
                    for &(n, _) in &r.nodes {
                        for k in 0..d {
                            if let Some(v) = &r.values[k] {
                                ctx.v[n as usize * d + k] = v.at(ctx.time - 0.5 * ctx.dt);
                            }
                        }
                    }
                }
                BcKind::Acceleration => {
                    let id = self.accel.expect("declared with accelerations");
                    let acc = ctx.fields.get_mut(id);
                    for &(n, b) in &r.nodes {
                        for k in 0..d {
                            if let Some(v) = &r.values[k] {
                                let w = &mut acc[b as usize * d + k];
                                *w += v.at(ctx.time - ctx.dt) * ctx.dt;
                                ctx.v[n as usize * d + k] = *w;
                            }
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Bolt, BoltMaterial, BoltProperties};
    use pcdc_compute::{Backend, Simulation};
    use pcdc_mech::{LinearElastic, Mechanics};
    use pcdc_mesh::{builders, Dim2, Range};

    #[test]
    fn blocks_hold_whole_bolts_and_start_parallel_work_at_the_threshold() {
        // Bolts of 3, 5, 3, 4 nodes (2, 4, 2, 3 segments).
        let (nodes, segs) = ([0, 3, 8, 11], [0, 2, 6, 8]);
        assert_eq!(blocks(&nodes, &segs, 15, (16, 4)), vec![(0, 0)]);
        assert_eq!(
            blocks(&nodes, &segs, 15, (15, 4)),
            vec![(0, 0), (8, 6)],
            "whole bolts of at least 4 nodes"
        );
        assert_eq!(blocks(&nodes, &segs, 15, (1, 1)).len(), 4);
    }

    /// A plate under gravity with 60 pretensioned, plated bolts, run with `blocking`.
    fn bolted_plate(blocking: (usize, usize)) -> Simulation<Dim2> {
        let mesh = builders::rectangle(0.0, 0.0, 4.0, 1.0, 0.1).unwrap();
        let props = BoltProperties {
            cohesion_rock_grout: 2e3,
            pretension: 4e4,
            ..BoltProperties::steel_rebar(0.02)
        };
        let material = BoltMaterial::new(props).unwrap();
        let mut bolts = Bolts::new();
        for i in 0..60 {
            let x = 0.05 + 3.9 * i as f64 / 59.0;
            let (head, tail) = ([x, 0.97, 0.0], [x + 0.02, 0.1 + 0.01 * i as f64, 0.0]);
            let bolt = Bolt::straight(format!("B{i}"), head, tail, 10, material)
                .unwrap()
                .free_length(0.2)
                .unwrap()
                .face_plate(1e7)
                .unwrap();
            bolts = bolts.bolt(bolt).unwrap();
        }
        bolts.blocking = blocking;
        let rock = LinearElastic::new(2e8, 0.25, 2000.0).unwrap();
        Simulation::builder(mesh, Backend::cpu(2).unwrap())
            .physics(Mechanics::new().material(Range::All, rock))
            .physics(bolts)
            .gravity([0.0, -9.81, 0.0])
            .build()
            .unwrap()
    }

    #[test]
    fn bolts_split_in_blocks_give_the_single_block_result_bit_for_bit() {
        let (mut one, mut split) = (bolted_plate((usize::MAX, 1)), bolted_plate((1, 50)));
        one.run(300).unwrap();
        split.run(300).unwrap();
        assert_eq!(one.state.u, split.state.u);
        for name in [BOLT_AXIAL_FORCE, BOLT_GROUT_FORCE, BOLT_SLIP, BOLT_STATE] {
            assert_eq!(
                one.field(name).unwrap(),
                split.field(name).unwrap(),
                "{name:?}"
            );
        }
        // Something happened: the bolts carry force and the grout has slipped somewhere.
        let axial = one.field(BOLT_AXIAL_FORCE).unwrap();
        assert!(axial.iter().any(|f| f.abs() > 1e3), "{axial:?}");
        assert!(one.field(BOLT_SLIP).unwrap().iter().any(|s| *s != 0.0));
    }
}
