//! The node passes of a CPU step: gather (each node sums its slots in registration
//! order), central-difference velocity update, kinematic conditions, position update
//! and divergence watchdog.
//!
//! When every composed physics names the nodes its kinematic conditions write
//! ([`Physics::kinematic_nodes`]), one pass gathers, integrates and moves every other
//! node, so the node arrays are read once per step; the named nodes are moved after
//! the kinematic conditions. Otherwise two passes run: gather and velocity update, then
//! (after the kinematic conditions) position update and watchdog. Both give the same
//! bits: each node's arithmetic is the same, in the same order.

use pcdc_mesh::Dim;
use rayon::prelude::*;

use crate::physics::{KinematicNodes, VelocityContext};
use crate::{ComputeError, Physics, Simulation};

/// Nodes per parallel task of the node passes (a per-node rayon item costs more than the
/// node's arithmetic).
const NODE_BLOCK: usize = 2048;

/// The union of the physics' kinematic nodes, sorted and unique, or `None` when one
/// of them may write any node's velocity; a node index out of range is an error naming
/// the physics.
pub(crate) fn kinematic_nodes<D: Dim>(
    physics: &[Box<dyn Physics<D>>],
    n_nodes: usize,
) -> Result<Option<Vec<u32>>, ComputeError> {
    let mut all = Vec::new();
    for p in physics {
        match p.kinematic_nodes() {
            KinematicNodes::None => {}
            KinematicNodes::Any => return Ok(None),
            KinematicNodes::Nodes(list) => {
                if let Some(&bad) = list.iter().find(|&&n| n as usize >= n_nodes) {
                    return Err(ComputeError::physics(
                        p.name(),
                        format!("kinematic node {bad} does not exist ({n_nodes} nodes)"),
                    ));
                }
                all.extend(list);
            }
        }
    }
    all.sort_unstable();
    all.dedup();
    Ok(Some(all))
}

/// The constants of the velocity update.
#[derive(Clone, Copy)]
struct Integrate {
    dt: f64,
    gravity: [f64; 3],
    alpha: f64,
}

/// Node `n`'s slot sum (registration order); `slots` as `N`-vectors.
#[inline(always)]
fn gather_node<const N: usize>(n: usize, ptr: &[u32], idx: &[u32], slots: &[[f64; N]]) -> [f64; N] {
    let mut sum = [0.0; N];
    for &s in &idx[ptr[n] as usize..ptr[n + 1] as usize] {
        let f = &slots[s as usize];
        for k in 0..N {
            sum[k] += f[k];
        }
    }
    sum
}

/// `v += (F + m_phys g − α|F| sign v) dt / m` for one node (`dt / m` once: one division
/// per node).
#[inline(always)]
fn integrate_node<const N: usize>(
    sum: &[f64; N],
    v: &mut [f64; N],
    m: f64,
    m_phys: f64,
    c: Integrate,
) {
    let dtm = c.dt / m;
    for k in 0..N {
        let mut fk = sum[k] + m_phys * c.gravity[k];
        if c.alpha > 0.0 {
            // Local non-viscous damping (Cundall): f -= α |f| sign(v).
            fk -= c.alpha * fk.abs() * v[k].signum() * (v[k] != 0.0) as u8 as f64;
        }
        v[k] += fk * dtm;
    }
}

/// `u += dt v` for one node; `Some(non-finite)` when the node is bad: |u| above the
/// runaway limit (`limit2` its square), or not a number. A non-finite v makes u
/// non-finite (dt > 0), so one comparison, `!(|u|² ≤ limit²)`, catches every bad node.
#[inline(always)]
fn move_node<const N: usize>(u: &mut [f64; N], v: &[f64; N], dt: f64, limit2: f64) -> Option<bool> {
    let mut u2 = 0.0;
    for k in 0..N {
        u[k] += dt * v[k];
        u2 += u[k] * u[k];
    }
    if u2 <= limit2 {
        return None;
    }
    Some(!(0..N).all(|k| u[k].is_finite() && v[k].is_finite()))
}

/// The `N`-vectors of a stride-`N` array (its length a multiple of `N`, as every node
/// array is): bytemuck's checked cast, no copy.
#[inline(always)]
fn vectors<const N: usize>(x: &[f64]) -> &[[f64; N]] {
    bytemuck::cast_slice(x)
}

/// The mutable `N`-vectors of a stride-`N` array.
#[inline(always)]
fn vectors_mut<const N: usize>(x: &mut [f64]) -> &mut [[f64; N]] {
    bytemuck::cast_slice_mut(x)
}

/// The arrays a node pass reads.
struct NodeInputs<'a, const N: usize> {
    ptr: &'a [u32],
    idx: &'a [u32],
    slots: &'a [[f64; N]],
    mass: &'a [f64],
    mass_phys: &'a [f64],
}

/// Gather (into `force`) and, with `integrate`, the velocity update of every node.
fn gather_pass<const N: usize>(
    inp: &NodeInputs<'_, N>,
    force: &mut [f64],
    v: &mut [f64],
    integrate: Option<Integrate>,
) {
    vectors_mut::<N>(force)
        .par_chunks_mut(NODE_BLOCK)
        .zip(vectors_mut::<N>(v).par_chunks_mut(NODE_BLOCK))
        .enumerate()
        .for_each(|(b, (fb, vb))| {
            for (i, (f, v)) in fb.iter_mut().zip(vb).enumerate() {
                let n = b * NODE_BLOCK + i;
                *f = gather_node(n, inp.ptr, inp.idx, inp.slots);
                if let Some(c) = integrate {
                    integrate_node(f, v, inp.mass[n], inp.mass_phys[n], c);
                }
            }
        });
}

/// Position update and watchdog of every node: the first bad node (index, non-finite).
fn move_pass<const N: usize>(
    u: &mut [f64],
    v: &[f64],
    dt: f64,
    limit2: f64,
) -> Option<(usize, bool)> {
    vectors_mut::<N>(u)
        .par_chunks_mut(NODE_BLOCK)
        .zip(vectors::<N>(v).par_chunks(NODE_BLOCK))
        .enumerate()
        .filter_map(|(b, (ub, vb))| {
            // The first bad node of the block (blocks in order: the first overall); every
            // node moves.
            let mut bad = None;
            for (i, (u, v)) in ub.iter_mut().zip(vb).enumerate() {
                if let (None, Some(nf)) = (bad, move_node(u, v, dt, limit2)) {
                    bad = Some((b * NODE_BLOCK + i, nf));
                }
            }
            bad
        })
        .min_by_key(|&(n, _)| n)
}

/// Gather, velocity update and, except at the `held` nodes (sorted), position update
/// and watchdog, in one pass: the first bad node moved (index, non-finite).
fn fused_pass<const N: usize>(
    inp: &NodeInputs<'_, N>,
    held: &[u32],
    force: &mut [f64],
    u: &mut [f64],
    v: &mut [f64],
    c: Integrate,
    limit2: f64,
) -> Option<(usize, bool)> {
    vectors_mut::<N>(force)
        .par_chunks_mut(NODE_BLOCK)
        .zip(vectors_mut::<N>(u).par_chunks_mut(NODE_BLOCK))
        .zip(vectors_mut::<N>(v).par_chunks_mut(NODE_BLOCK))
        .enumerate()
        .filter_map(|(b, ((fb, ub), vb))| {
            let first = b * NODE_BLOCK;
            // The next held node at or after `first`.
            let mut next = held.partition_point(|&h| (h as usize) < first);
            let mut bad = None;
            for (i, ((f, u), v)) in fb.iter_mut().zip(ub).zip(vb).enumerate() {
                let n = first + i;
                *f = gather_node(n, inp.ptr, inp.idx, inp.slots);
                integrate_node(f, v, inp.mass[n], inp.mass_phys[n], c);
                if held.get(next) == Some(&(n as u32)) {
                    next += 1;
                    continue;
                }
                if let (None, Some(nf)) = (bad, move_node(u, v, c.dt, limit2)) {
                    bad = Some((n, nf));
                }
            }
            bad
        })
        .min_by_key(|&(n, _)| n)
}

/// Moves the `held` nodes (sorted), every one of them: the first bad one.
fn move_held<const N: usize>(
    held: &[u32],
    u: &mut [f64],
    v: &[f64],
    dt: f64,
    limit2: f64,
) -> Option<(usize, bool)> {
    let (u, v) = (vectors_mut::<N>(u), vectors::<N>(v));
    let mut bad = None;
    for &n in held {
        let n = n as usize;
        if let (None, Some(nf)) = (bad, move_node(&mut u[n], &v[n], dt, limit2)) {
            bad = Some((n, nf));
        }
    }
    bad
}

/// Runs `$body` with the const `$n` bound to the dimension `$d` (2 or 3).
macro_rules! with_dim {
    ($d:expr, $n:ident => $body:expr) => {
        match $d {
            2 => {
                const $n: usize = 2;
                $body
            }
            _ => {
                const $n: usize = 3;
                $body
            }
        }
    };
}

impl<D: Dim> Simulation<D> {
    fn integrate_constants(&self) -> Integrate {
        Integrate {
            dt: self.dt,
            gravity: self.gravity,
            alpha: self.local_damping,
        }
    }

    /// Each node sums its slots in registration order into the node force; with
    /// `integrate_velocity` the same pass applies the velocity update.
    pub(crate) fn gather(&mut self, integrate_velocity: bool) {
        let c = integrate_velocity.then(|| self.integrate_constants());
        let (force, v) = (&mut self.force, &mut self.state.v);
        let (ptr, idx, slots) = (&self.gather_ptr, &self.gather_idx, &self.slot_forces);
        let (mass, mass_phys) = (&self.mass, &self.mass_phys);
        self.backend.install(|| {
            with_dim!(D::D, N => {
                let inp = NodeInputs::<N> { ptr, idx, slots: vectors::<N>(slots), mass, mass_phys };
                gather_pass(&inp, force, v, c)
            })
        });
    }

    /// Every physics' kinematic conditions on the integrated velocities.
    fn apply_kinematics(&mut self) {
        let t_end = self.state.time + self.dt;
        for p in &mut self.physics {
            let mut ctx = VelocityContext {
                mesh: &self.mesh,
                u: &self.state.u,
                v: &mut self.state.v,
                time: t_end,
                dt: self.dt,
                fields: &mut self.state.fields,
            };
            p.apply_kinematics(&mut ctx);
        }
    }

    /// Ends the step at `bad`, the first bad node (if any).
    fn end_step(&mut self, bad: Option<(usize, bool)>) -> Result<(), ComputeError> {
        self.state.time += self.dt;
        self.state.step += 1;
        if let Some((n, nonfinite)) = bad {
            return Err(self.divergence(self.state.step, self.state.time, n, nonfinite));
        }
        Ok(())
    }

    /// Kinematic conditions, position update and watchdog after the velocity update.
    pub(crate) fn finish_step(&mut self) -> Result<(), ComputeError> {
        self.apply_kinematics();
        let (dt, limit2) = (self.dt, self.runaway * self.runaway);
        let (u, v) = (&mut self.state.u, &self.state.v);
        let bad = self
            .backend
            .install(|| with_dim!(D::D, N => move_pass::<N>(u, v, dt, limit2)));
        self.end_step(bad)
    }

    /// The whole node work of a step in one pass over the nodes, for compositions whose
    /// kinematic conditions name their nodes: gather, velocity update and, except at
    /// those nodes, position update and watchdog; then the kinematic conditions, then
    /// the named nodes move. Each node's arithmetic is that of
    /// [`Simulation::gather`] + [`Simulation::finish_step`].
    pub(crate) fn fused_node_pass(&mut self) -> Result<(), ComputeError> {
        let c = self.integrate_constants();
        let limit2 = self.runaway * self.runaway;
        let held = self.kinematic_nodes.as_deref().expect("fused pass");
        let (force, u, v) = (&mut self.force, &mut self.state.u, &mut self.state.v);
        let (ptr, idx, slots) = (&self.gather_ptr, &self.gather_idx, &self.slot_forces);
        let (mass, mass_phys) = (&self.mass, &self.mass_phys);
        let bad = self.backend.install(|| {
            with_dim!(D::D, N => {
                let inp = NodeInputs::<N> { ptr, idx, slots: vectors::<N>(slots), mass, mass_phys };
                fused_pass(&inp, held, force, u, v, c, limit2)
            })
        });
        self.apply_kinematics();
        let held = self.kinematic_nodes.as_deref().expect("fused pass");
        let (u, v) = (&mut self.state.u, &self.state.v);
        let bad_held = with_dim!(D::D, N => move_held::<N>(held, u, v, c.dt, limit2));
        let bad = match (bad, bad_held) {
            (Some(a), Some(b)) => Some(if a.0 < b.0 { a } else { b }),
            (a, b) => a.or(b),
        };
        self.end_step(bad)
    }
}
