//! One step of the bolts on the CPU: every bolt walked from head to toe (segments, then
//! each node with its grout, re-locating a node that has left its host), in blocks of
//! whole bolts that run in parallel when there are enough of them.

use pcdc_compute::{ComputeError, ForceContext, Kinematics};
use pcdc_mesh::Dim;
use rayon::prelude::*;

use crate::host::{barycentric, min_height};
use crate::material::SegmentState;
use crate::path::PathElement;
use crate::physics::{BoltNode, Bolts, Segment, Span, NONE};

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

/// Velocity of node `n` (m/s; z = 0 in 2D).
fn vel<D: Dim>(kin: &Kinematics<'_, D>, n: u32) -> [f64; 3] {
    let d = D::D;
    let mut v = [0.0; 3];
    v[..d].copy_from_slice(&kin.v[n as usize * d..n as usize * d + d]);
    v
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

/// A bolt node's current host as the walk needs it, next to the node (the path element
/// it names is far away in memory, behind the host index in [`crate::BOLT_ANCHOR`]): a
/// cache, checked against that index before use.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Active {
    /// Path index.
    pub j: u32,
    /// The host's nodes and their indices among the bolt's path nodes.
    pub nodes: [u32; 4],
    pub local: [u32; 4],
}

impl Active {
    pub fn of(j: usize, pe: &PathElement) -> Self {
        Active {
            j: j as u32,
            nodes: pe.nodes,
            local: pe.local,
        }
    }
}

/// Displacement of bolt node `n` relative to its grout point, the material point
/// Σ_q w_q x_q of its host with nodes `host` (weights and offset from `anchor`, see
/// [`crate::BOLT_ANCHOR`]): offset + u_n − Σ_q w_q u_q (m), which is x_n − Σ_q w_q x_q,
/// zero under any rigid motion where the node sits at that point.
pub(crate) fn relative_disp<D: Dim>(
    node: u32,
    host: &[u32; 4],
    anchor: &[f64],
    kin: &Kinematics<'_, D>,
) -> [f64; 3] {
    let d = D::D;
    let mut r = disp(kin, node);
    for k in 0..d {
        r[k] += anchor[d + 2 + k];
    }
    for q in 0..=d {
        let u = disp(kin, host[q]);
        (0..3).for_each(|k| r[k] -= anchor[1 + q] * u[k]);
    }
    r
}

/// A node leaves its host when its grout point is outside it by more than this (in
/// barycentric weight, i.e. a fraction of the element's height)...
pub(crate) const LEAVE: f64 = 0.05;
/// ... and enters a candidate whose smallest weight at the point is at least −`ENTER`
/// (less than `LEAVE`, so that a node on a face does not go back and forth).
pub(crate) const ENTER: f64 = 0.025;
/// The host's heights may shrink by this factor before [`margin`]'s shortcut could miss
/// a node that has left (far beyond the strains of elements in FDEM).
pub(crate) const STRETCH: f64 = 2.0;

/// The distance along the bolt (m) within which a grout point with smallest weight
/// `wmin` in a host of smallest height `h` stays inside it to [`LEAVE`]: each weight
/// changes by at most the distance over the height.
pub(crate) fn margin(wmin: f64, h: f64) -> f64 {
    ((wmin + LEAVE) * h / STRETCH).max(0.0)
}

/// Current positions of a path element's `D + 1` nodes (stride D).
fn element_positions<D: Dim>(pe: &PathElement, kin: &Kinematics<'_, D>) -> [f64; 12] {
    let d = D::D;
    let mut x = [0.0; 12];
    for q in 0..=d {
        let p = kin.position(pe.nodes[q] as usize);
        x[q * d..q * d + d].copy_from_slice(&p[..d]);
    }
    x
}

/// Re-locates bolt node `n` when its grout point, moved along the axis `a` by the
/// relative displacement `delta` (the point x_n − (r − δ a) with `r` its relative
/// displacement), has left its host by more than [`LEAVE`]: the candidate holding that
/// point best (largest smallest weight; the first in path order among equals) becomes the
/// host if it holds it to [`ENTER`], with that point as the new grout point, so that the
/// node's relative displacement becomes r − δ a (the lateral part kept, the axial part
/// moved into the slip by the caller). Returns the new host's path index; `anchor` is
/// updated. `None`: still inside, or no candidate holds it (the node stays with its host).
pub(crate) fn relocate<D: Dim>(
    n: &BoltNode,
    path: &[PathElement],
    anchor: &mut [f64],
    a: &[f64; 3],
    r: &[f64; 3],
    delta: f64,
    kin: &Kinematics<'_, D>,
) -> Option<usize> {
    let d = D::D;
    let own = n.cand[0] as usize + anchor[0] as usize;
    let xn = kin.position(n.node as usize);
    let lateral: [f64; 3] = std::array::from_fn(|k| r[k] - delta * a[k]);
    let p: [f64; 3] = std::array::from_fn(|k| xn[k] - lateral[k]);
    let smallest = |w: &[f64; 4]| w[..=d].iter().cloned().fold(f64::INFINITY, f64::min);
    let x = element_positions(&path[own], kin);
    if smallest(&barycentric(d, &x[..(d + 1) * d], &p[..d])) >= -LEAVE {
        return None;
    }
    let mut best: Option<(f64, usize, [f64; 4], [f64; 12])> = None;
    let first = n.cand[0] as usize;
    for (j, pe) in path[first..n.cand[1] as usize].iter().enumerate() {
        let j = first + j;
        if j == own {
            continue;
        }
        let x = element_positions(pe, kin);
        let w = barycentric(d, &x[..(d + 1) * d], &p[..d]);
        let m = smallest(&w);
        if best.as_ref().is_none_or(|b| m > b.0) {
            best = Some((m, j, w, x));
        }
    }
    let (m, j, w, x) = best.filter(|b| b.0 >= -ENTER)?;
    // The new grout point: offset = (r − δ a) − (u_n − Σ w_q u_q), so that the relative
    // displacement goes on from r − δ a.
    let un = disp(kin, n.node);
    anchor[0] = (j - n.cand[0] as usize) as f64;
    anchor[1..d + 2].copy_from_slice(&w[..=d]);
    let mut v = un;
    for (q, wq) in w.iter().enumerate().take(d + 1) {
        let u = disp(kin, path[j].nodes[q]);
        (0..3).for_each(|k| v[k] -= wq * u[k]);
    }
    for k in 0..d {
        anchor[d + 2 + k] = lateral[k] - v[k];
    }
    anchor[2 * d + 2] = margin(m, min_height(d, &x[..(d + 1) * d]));
    Some(j)
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
pub(crate) const PARALLEL_FROM: usize = 2048;

/// Nodes per work block of a larger set (whole bolts, so a block may hold more): small
/// enough that rayon's stealing balances the threads.
pub(crate) const BLOCK_NODES: usize = 512;

/// Groups whole bolts (given their spans) into work blocks: one below `parallel_from`
/// nodes ([`PARALLEL_FROM`]), else blocks of at least `block_nodes` ([`BLOCK_NODES`];
/// the last may be smaller); returns each block's first bolt.
pub(crate) fn blocks(spans: &[Span], (parallel_from, block_nodes): (usize, usize)) -> Vec<usize> {
    let n_nodes: usize = spans.iter().map(|s| s.nodes).sum();
    let size = if n_nodes < parallel_from {
        usize::MAX
    } else {
        block_nodes
    };
    let mut out = Vec::new();
    let mut held = 0usize;
    for (b, s) in spans.iter().enumerate() {
        if b == 0 || held >= size {
            out.push(b);
            held = 0;
        }
        held += s.nodes;
    }
    out
}

/// A segment's force vector on its end node's side (N: f e with f the axial force plus
/// damping) and its current unit direction e.
type SegmentOut = ([f64; 3], [f64; 3]);

/// What the walk reads besides the kinematics: the path elements, the host stresses
/// (and rotations in 3D).
struct Walk<'a> {
    path: &'a [PathElement],
    stress: &'a [f64],
    rotation: &'a [f64],
}

/// A block of whole bolts and the entries it writes: its segments' axial force, plastic
/// elongation and state, its nodes' grout force, slip, grout point and host, and its
/// bolts' force slots.
struct Block<'a> {
    spans: &'a [Span],
    first_segment: usize,
    segments: &'a [Segment],
    nodes: &'a [BoltNode],
    axial: &'a mut [f64],
    plastic: &'a mut [f64],
    state: &'a mut [f64],
    grout: &'a mut [f64],
    slip: &'a mut [f64],
    anchor: &'a mut [f64],
    host: &'a mut [f64],
    active: &'a mut [Active],
    slots: &'a mut [f64],
}

/// What one bolt node writes: its own slot (D values), its grout force and slip, its
/// grout point ([`crate::BOLT_ANCHOR`]) and host.
struct NodeOut<'a> {
    slot: &'a mut [f64],
    grout: &'a mut f64,
    slip: &'a mut f64,
    anchor: &'a mut [f64],
    host: &'a mut f64,
    active: &'a mut Active,
}

impl Walk<'_> {
    /// Walks every bolt of `b` from head to toe: each segment (axial force, eq. 138-142,
    /// plus damping, eq. 148) with the bar force and axis of the node it starts at, one
    /// node ahead of the grout; then each node with them, whose grout reaction is added
    /// to its host's slots in node order. Each segment is computed once; every entry is
    /// written by one bolt only (deterministic in any block split).
    fn block<D: Dim>(&self, b: Block<'_>, kin: &Kinematics<'_, D>) {
        let d = D::D;
        let alen = crate::anchor_len(d);
        let Block {
            spans,
            first_segment,
            segments,
            nodes,
            axial,
            plastic,
            state,
            grout,
            slip,
            anchor,
            host,
            active,
            mut slots,
        } = b;
        let mut i0 = 0;
        for span in spans {
            let (bolt_slots, rest) = std::mem::take(&mut slots).split_at_mut(span.slots() * d);
            slots = rest;
            let (own, hosts) = bolt_slots.split_at_mut(span.nodes * d);
            hosts.fill(0.0);
            let end = i0 + span.nodes;
            // One node ahead: the next node's segment, bar force and axis are found
            // before this node's grout, which does not need them, so that their chain
            // of roots and divisions runs while the grout's work waits on this node's
            // axis (found one node earlier).
            let mut next: Option<SegmentOut> = None;
            let mut ahead = ([0.0; 3], [0.0; 3]);
            for j in i0..=end {
                let bar = ahead;
                if j < end {
                    let m = &nodes[j];
                    let after = if m.next != NONE {
                        let s = m.next as usize - first_segment;
                        Some(segment(
                            &segments[s],
                            kin,
                            &mut axial[s],
                            &mut plastic[s],
                            &mut state[s],
                        ))
                    } else {
                        None
                    };
                    let before = if m.prev != NONE { next.as_ref() } else { None };
                    ahead = bar_and_axis(before, after.as_ref());
                    next = after;
                }
                if j == i0 {
                    continue;
                }
                let i = j - 1;
                let l = i - i0;
                let out = NodeOut {
                    slot: &mut own[l * d..(l + 1) * d],
                    grout: &mut grout[i],
                    slip: &mut slip[i],
                    anchor: &mut anchor[i * alen..(i + 1) * alen],
                    host: &mut host[i],
                    active: &mut active[i],
                };
                self.node(&nodes[i], bar, kin, out, hosts);
            }
            i0 = end;
        }
    }

    /// One bolt node with its bar force `f` and axis `a` ([`bar_and_axis`]):
    /// re-location if it has left its host, the grout against the host with the host's
    /// confinement, the lateral grout and the face plate; writes its slot, its grout
    /// force, slip, grout point and host, and adds the reaction to its host's nodes'
    /// slots among `hosts` (the slots of its bolt's path nodes).
    #[inline(always)]
    fn node<D: Dim>(
        &self,
        n: &BoltNode,
        (f, a): ([f64; 3], [f64; 3]),
        kin: &Kinematics<'_, D>,
        out: NodeOut<'_>,
        hosts: &mut [f64],
    ) {
        let d = D::D;
        // Against the host's material point where the node is grouted.
        let anchor = out.anchor;
        let active = out.active;
        let j = n.cand[0] as usize + anchor[0] as usize;
        if active.j as usize != j {
            *active = Active::of(j, &self.path[j]);
        }
        let mut r = relative_disp(n.node, &active.nodes, anchor, kin);
        let mut delta = r[0] * a[0] + r[1] * a[1] + r[2] * a[2];
        if delta.abs() > anchor[2 * d + 2] && n.cand[1] - n.cand[0] > 1 {
            if let Some(k) = relocate(n, self.path, anchor, &a, &r, delta, kin) {
                // The axial part of the relative displacement is carried over: the
                // grout's δ, force and slip go on unchanged.
                anchor[2 * d + 3] += delta;
                *active = Active::of(k, &self.path[k]);
                *out.host = self.path[k].element as f64;
                r = relative_disp(n.node, &active.nodes, anchor, kin);
            }
        }
        let lateral: [f64; 3] = {
            let dl = r[0] * a[0] + r[1] * a[1] + r[2] * a[2];
            std::array::from_fn(|k| r[k] - dl * a[k])
        };
        // The node's axial displacement against the rock (along the bolt's path).
        delta = r[0] * a[0] + r[1] * a[1] + r[2] * a[2] + anchor[2 * d + 3];
        // Grout along the axis: bond-slip with the host's confinement.
        let slip = out.slip;
        let mut fs = 0.0;
        let trial = n.k_axial * (delta - *slip);
        if n.k_axial > 0.0 && trial.abs() <= n.cap_unconfined {
            // Elastic under any confinement: the same force and slip as below, exactly.
            fs = trial;
        } else if n.k_axial > 0.0 {
            let pe = &self.path[active.j as usize];
            let e = pe.element as usize;
            let mut rot = [0.0; 9];
            if d == 2 {
                let xc = element_positions(pe, kin);
                rot[..2].copy_from_slice(&rotation_2d(&pe.ref_adj, &xc));
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
        *out.grout = fs;
        // Lateral grout, and the face plate (one-sided, pushes the head back out).
        let mut g: [f64; 3] = std::array::from_fn(|k| fs * a[k] + n.k_normal * lateral[k]);
        if n.c_lateral > 0.0 {
            // Lateral damping on the node's sideways velocity against the rock.
            let mut w = [0.0; 3];
            let vn = vel(kin, n.node);
            for q in 0..=d {
                let vq = vel(kin, active.nodes[q]);
                (0..3).for_each(|k| w[k] += anchor[1 + q] * vq[k]);
            }
            let vr: [f64; 3] = std::array::from_fn(|k| vn[k] - w[k]);
            let va = vr[0] * a[0] + vr[1] * a[1] + vr[2] * a[2];
            (0..3).for_each(|k| g[k] += n.c_lateral * (vr[k] - va * a[k]));
        }
        if n.plate > 0.0 && delta > 0.0 {
            (0..3).for_each(|k| g[k] += n.plate * delta * a[k]);
        }
        for k in 0..d {
            out.slot[k] = f[k] - g[k];
        }
        for q in 0..=d {
            let (w, base) = (anchor[1 + q], active.local[q] as usize * d);
            for (k, gk) in g.iter().enumerate().take(d) {
                hosts[base + k] += w * gk;
            }
        }
    }
}

/// A bolt node's bar force and axis from the segments `prev` and `next` (the node's
/// end of the one, its start of the other): the force +f e as the start of the next
/// segment, −f e as the end of the previous one (fixed order: previous, next), and the
/// axis, the mean of their current directions (normalised).
#[inline(always)]
fn bar_and_axis(prev: Option<&SegmentOut>, next: Option<&SegmentOut>) -> ([f64; 3], [f64; 3]) {
    let mut f = [0.0; 3];
    if let Some((g, _)) = prev {
        (0..3).for_each(|k| f[k] -= g[k]);
    }
    if let Some((g, _)) = next {
        (0..3).for_each(|k| f[k] += g[k]);
    }
    let mut axis = [0.0; 3];
    for (_, e) in [prev, next].into_iter().flatten() {
        (0..3).for_each(|k| axis[k] += e[k]);
    }
    (f, unit(axis).0)
}

/// An elongation (m) below which a segment of reference length `l0` (m) is surely short
/// of the failure strain `failure`: `failure` × `l0` less a relative 1e-12, which covers
/// the roundings of the product and of the strain's division; for a bolt that never
/// breaks (`failure` infinite), `l0` × the largest f64, below which the strain's
/// division cannot overflow to infinity.
pub(crate) fn fail_below(failure: f64, l0: f64) -> f64 {
    (failure * l0).min(l0 * f64::MAX) * (1.0 - 1e-12)
}

/// Whether a segment of reference length `l0` (m) breaks at `elongation` (m, eq. 142):
/// its strain `elongation / l0` reaches `failure`. Below `below` (see
/// `Segment::fail_below`) the answer is no without the division, which then runs only
/// near failure; the answer is that of the division everywhere.
#[inline(always)]
pub(crate) fn reaches_failure(elongation: f64, l0: f64, below: f64, failure: f64) -> bool {
    elongation >= below && elongation / l0 >= failure
}

/// One segment: the axial force in total form from its elongation (eq. 138-142) into
/// `axial`, `plastic`, `state`, plus damping on the relative axial velocity (eq. 148).
#[inline(always)]
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
    // AxialLaw::update with the segment's stiffness kept (the same values).
    let fails =
        broken || reaches_failure(elongation, seg.l0, seg.fail_below, seg.law.failure_strain);
    let (f, up, st) = seg.law.settle(fails, elongation, seg.k, *plastic);
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
    pub(crate) fn walk<D: Dim>(
        &mut self,
        ctx: &mut ForceContext<'_, D>,
    ) -> Result<(), ComputeError> {
        let d = D::D;
        let ids = self.ids.expect("init ran");
        let kin = &ctx.kin;
        // The host's stress (and rotation in 3D) are read in place.
        let fields = [
            ids.axial,
            ids.plastic,
            ids.state,
            ids.grout,
            ids.slip,
            ids.anchor,
            ids.host,
            ids.stress,
        ];
        let (outs, stress, rotation) = if let Some(rot) = ids.rotation {
            let [a, p, st, g, sl, an, h, stress, rot] = ctx.fields.get_many_mut([
                fields[0], fields[1], fields[2], fields[3], fields[4], fields[5], fields[6],
                fields[7], rot,
            ]);
            ([a, p, st, g, sl, an, h], &*stress, &*rot)
        } else {
            let [a, p, st, g, sl, an, h, stress] = ctx.fields.get_many_mut(fields);
            ([a, p, st, g, sl, an, h], &*stress, &[][..])
        };
        let [axial, plastic, state, grout, slip, anchor, host] = outs;
        let walk = Walk {
            path: &self.path,
            stress,
            rotation,
        };
        let whole = Block {
            spans: &self.spans,
            first_segment: 0,
            segments: &self.segments,
            nodes: &self.nodes,
            axial,
            plastic,
            state,
            grout,
            slip,
            anchor,
            host,
            active: &mut self.active,
            slots: ctx.slots,
        };
        if self.blocks.len() <= 1 {
            walk.block(whole, kin);
        } else {
            split_blocks(whole, &self.blocks, d)
                .into_par_iter()
                .for_each(|b| walk.block(b, kin));
        }
        Ok(())
    }
}

/// Cuts `whole` before the blocks' first bolts (`d` dimensions).
fn split_blocks<'a>(mut rest: Block<'a>, blocks: &[usize], d: usize) -> Vec<Block<'a>> {
    let mut out = Vec::with_capacity(blocks.len());
    for w in blocks.windows(2) {
        let (head, tail) = rest.split(w[1] - w[0], d);
        out.push(head);
        rest = tail;
    }
    out.push(rest);
    out
}

impl<'a> Block<'a> {
    /// This block's first `bolts` bolts, and the rest (`d` dimensions).
    fn split(self, bolts: usize, d: usize) -> (Block<'a>, Block<'a>) {
        let (spans, spans_r) = self.spans.split_at(bolts);
        let sum = |f: fn(&Span) -> usize| spans.iter().map(f).sum::<usize>();
        let (n, s) = (sum(|x| x.nodes), sum(|x| x.segments));
        let slots_n = n + sum(|x| x.path_nodes);
        let (axial, axial_r) = self.axial.split_at_mut(s);
        let (plastic, plastic_r) = self.plastic.split_at_mut(s);
        let (state, state_r) = self.state.split_at_mut(s);
        let (grout, grout_r) = self.grout.split_at_mut(n);
        let (slip, slip_r) = self.slip.split_at_mut(n);
        let (anchor, anchor_r) = self.anchor.split_at_mut(n * crate::anchor_len(d));
        let (host, host_r) = self.host.split_at_mut(n);
        let (active, active_r) = self.active.split_at_mut(n);
        let (slots, slots_r) = self.slots.split_at_mut(slots_n * d);
        let (segments, segments_r) = self.segments.split_at(s);
        let (nodes, nodes_r) = self.nodes.split_at(n);
        let head = Block {
            spans,
            first_segment: self.first_segment,
            segments,
            nodes,
            axial,
            plastic,
            state,
            grout,
            slip,
            anchor,
            host,
            active,
            slots,
        };
        let tail = Block {
            spans: spans_r,
            first_segment: self.first_segment + s,
            segments: segments_r,
            nodes: nodes_r,
            axial: axial_r,
            plastic: plastic_r,
            state: state_r,
            grout: grout_r,
            slip: slip_r,
            anchor: anchor_r,
            host: host_r,
            active: active_r,
            slots: slots_r,
        };
        (head, tail)
    }
}

#[cfg(test)]
mod tests {
    use super::{fail_below, reaches_failure};
    use proptest::prelude::*;

    proptest! {
        /// The failure test without the division below `fail_below` answers as the
        /// division does, at and around the threshold (ulps either side).
        #[test]
        fn the_failure_shortcut_answers_as_the_division(
            l0 in 1e-4f64..1e3,
            failure in 1e-6f64..10.0,
            t in -1e-9f64..1e-9,
            ulps in -4i64..=4,
        ) {
            let below = fail_below(failure, l0);
            let edge = failure * l0 * (1.0 + t);
            let e = f64::from_bits((edge.to_bits() as i64 + ulps) as u64);
            for x in [e, edge, failure * l0, -e, 0.0, below, f64::INFINITY, f64::NAN] {
                prop_assert_eq!(reaches_failure(x, l0, below, failure), x / l0 >= failure, "{}", x);
            }
            // A bolt that never breaks.
            let inf = f64::INFINITY;
            let below_inf = fail_below(inf, l0);
            for x in [e, f64::MAX, inf] {
                prop_assert_eq!(reaches_failure(x, l0, below_inf, inf), x / l0 >= inf);
            }
        }
    }
}
